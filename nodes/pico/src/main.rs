//! The monitoring node on a Raspberry Pi Pico (RP2040, Cortex-M0+), the board a user
//! flashes (docs/pico.md: pins, parts, power, putting the image on a board): the load
//! cell on an HX711, two displacement probes on an ADS1115, a tachometer's pulses
//! (`sensors.rs`), sampled on the RP2040's timer at the committed period (100 ms until
//! one is; the HX711 at 80 samples a second, the ADS1115 at 860) through the committed
//! calibration, and sleeping between
//! samples and requests (`sleep.rs`); Modbus RTU over RS-485 on UART0 with the
//! transceiver's driver enable (`board.rs`: the pins and the line in one place); its
//! state, committed configuration and events on its own QSPI flash (`flash.rs`), in
//! regions memory.x reserves; the watchdog armed. The defmt log goes over RTT (a debug
//! probe, `probe-rs run`).
//!
//! The node is the QEMU images' (`nodes/firmware`), compiled in unchanged: the same
//! estimator built the same way (`node.rs`: the fixed-point core, as on every core
//! without an FPU), the same Modbus loop (`serve.rs`), the same storage (`persist.rs`).
//! Until the site's scene is committed over the bus (docs/modbus.md) it serves only and
//! reports "not commissioned"; from then on it monitors its sensors, across resets. Built with
//! `MISALIGN_MODBUS_EXTERNAL=1` (tests only) it monitors the samples a master writes.
#![no_std]
#![no_main]

mod board;
mod flash;
mod sensors;
mod sleep;

use defmt_rtt as _;
use embassy_rp::bind_interrupts;
use embassy_rp::gpio::{Input, Level, Output, Pull};
use embassy_rp::interrupt::InterruptExt;
use embassy_rp::peripherals::UART0;
use embassy_rp::pwm::{self, Pwm};
use embassy_rp::uart::{BufferedInterruptHandler, BufferedUart, Config};
use embassy_rp::watchdog::Watchdog;
use embassy_time::{Duration, Instant};
use embedded_hal::digital::OutputPin;
use embedded_io::{ErrorType, Read, ReadReady, Write};
use misalign::monitor::Sample;
use panic_probe as _;

// The node's code, as the QEMU images compile it (its scenario run and its simulated
// sensors are theirs only).
#[allow(dead_code)]
#[path = "../../firmware/node.rs"]
mod node;
#[path = "../../firmware/persist.rs"]
mod persist;
#[allow(dead_code)] // The f32 model name is the FPU images'.
#[path = "../../firmware/serve.rs"]
mod serve;

/// The model name (function 43/14).
const MODEL: &str = "fixed-point core (fixed::FixedAuto), the site's scene committed over the bus";

bind_interrupts!(struct Irqs {
    UART0_IRQ => BufferedInterruptHandler<UART0>;
});

/// A half-duplex RS-485 line: any UART implementing `embedded-io`, and the
/// transceiver's driver-enable pin, raised from the first byte of an answer until its
/// last stop bit has left. `idle` says whether the UART's transmitter has sent that
/// (`flush` empties the HAL's buffer; the shift register is the HAL's own business).
/// `drain` moves bytes still in the UART's own FIFO into the HAL's buffer: the
/// PL011 raises its RX interrupt only at a FIFO level (embassy-rp sets 28 bytes, 2.4
/// ms of the line at 115200 baud) or 32 bit times after the last byte, so without it
/// a frame's end of silence would be judged on bytes the node has not seen.
pub struct Rs485<U, D> {
    uart: U,
    driver_enable: D,
    idle: fn(&U) -> bool,
    drain: fn(),
}

impl<U: ErrorType, D> ErrorType for Rs485<U, D> {
    type Error = U::Error;
}

impl<U: ReadReady, D> ReadReady for Rs485<U, D> {
    fn read_ready(&mut self) -> Result<bool, U::Error> {
        if !self.uart.read_ready()? {
            (self.drain)();
        }
        self.uart.read_ready()
    }
}

impl<U: Read, D> Read for Rs485<U, D> {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, U::Error> {
        self.uart.read(buf)
    }
}

impl<U: Write, D: OutputPin> Write for Rs485<U, D> {
    fn write(&mut self, buf: &[u8]) -> Result<usize, U::Error> {
        // This HAL's pins cannot fail (`Infallible`); another's error would leave the
        // driver off and the master without an answer, which it retries.
        let _ = self.driver_enable.set_high();
        self.uart.write(buf)
    }

    fn flush(&mut self) -> Result<(), U::Error> {
        let flushed = self.uart.flush();
        while flushed.is_ok() && !(self.idle)(&self.uart) {}
        let _ = self.driver_enable.set_low();
        flushed
    }
}

/// The Pico as the node's board: its sensors, its sleep, its watchdog.
struct Pico {
    sensors: Option<sensors::Sensors>,
    watchdog: Watchdog,
}

impl serve::Board for Pico {
    const SENSORS: bool = true;

    fn sample(&mut self) -> Option<Sample> {
        self.sensors.as_mut()?.sample()
    }

    fn idle(&mut self, wait: u32, pending: &mut dyn FnMut() -> bool) {
        let until = Instant::now().as_micros() + u64::from(wait);
        let due = self
            .sensors
            .as_ref()
            .map_or(until, sensors::Sensors::due_us);
        sensors::idle(due, until, pending);
    }

    fn alive(&mut self) {
        self.watchdog
            .feed(Duration::from_millis(board::WATCHDOG_MS));
    }

    fn sensors(&mut self, settings: &board::SensorSettings) {
        defmt::println!(
            "sensors: sample period {=u32} ms, load zero {=f32} scale {=f32} N/count, probes zero {=f32} {=f32} scale {=f32} {=f32} m/count span {=f32} m, tachometer {=u32} pulses/rev radius {=f32} m",
            settings.sample_period_ms,
            settings.load_zero_counts,
            settings.load_newtons_per_count,
            settings.probe1_zero_counts,
            settings.probe2_zero_counts,
            settings.probe1_metres_per_count,
            settings.probe2_metres_per_count,
            settings.probe_span_m,
            settings.tacho_pulses_per_rev,
            settings.tacho_radius_m
        );
        if let Some(s) = self.sensors.as_mut()
            && let Err(e) = s.settings(settings)
        {
            defmt::error!("sensors: the drivers refused the calibration: {}", e);
        }
    }
}

#[cortex_m_rt::entry]
fn main() -> ! {
    let p = embassy_rp::init(Default::default());
    let mut watchdog = Watchdog::new(p.WATCHDOG);
    watchdog.start(Duration::from_millis(board::WATCHDOG_MS));
    sleep::init();
    let mut config = Config::default();
    config.baudrate = board::LINE.baud;
    // The RX buffer holds 44 ms of the line: a sample's reads never overflow it.
    let (mut tx_buffer, mut rx_buffer) = ([0u8; 256], [0u8; 512]);
    let uart = BufferedUart::new(
        p.UART0,
        p.PIN_0,
        p.PIN_1,
        Irqs,
        &mut tx_buffer,
        &mut rx_buffer,
        config,
    );
    let mut line = Rs485 {
        uart,
        driver_enable: Output::new(p.PIN_2, Level::Low),
        idle: |u: &BufferedUart| !u.busy(),
        drain: || {
            if !embassy_rp::pac::UART0.uartfr().read().rxfe() {
                // The HAL's handler empties the FIFO into its buffer whatever raised it.
                embassy_rp::interrupt::UART0_IRQ.pend();
            }
        },
    };
    let mut i2c_config = embassy_rp::i2c::Config::default();
    i2c_config.frequency = 400_000;
    let i2c = embassy_rp::i2c::I2c::new_blocking(p.I2C0, p.PIN_5, p.PIN_4, i2c_config);
    let pulses = Pwm::new_input(
        p.PWM_SLICE3,
        p.PIN_7,
        Pull::Down,
        pwm::InputMode::RisingEdge,
        pwm::Config::default(),
    );
    let sensors = sensors::Sensors::new(
        Input::new(p.PIN_10, Pull::Up),
        Output::new(p.PIN_11, Level::Low),
        i2c,
        pulses,
        Input::new(p.PIN_6, Pull::Down),
        &board::SensorSettings::DEFAULT,
    );
    if let Err(e) = &sensors {
        defmt::error!("node: the sensors' calibration refused: {}", e);
    }
    let mut pico = Pico {
        sensors: sensors.ok(),
        watchdog,
    };
    // The unit id and line settings in force are the server's (committed, or the
    // build's), logged once it has restored them; the UART runs the build's baud.
    defmt::println!(
        "modbus: RS-485 on UART0 at {=u32} baud 8N1, driver enable GP2",
        board::LINE.baud
    );
    let served = node::fixed_core().map(|core| {
        let clock = serve::LineClock {
            ticks: || Instant::now().as_micros() as u32,
            silence: misalign::modbus::silence_us(board::LINE.baud),
            // Microseconds.
            per_ms: 1000,
        };
        serve::node(core, MODEL, &mut line, clock, &mut pico)
    });
    match served {
        Ok(_) => defmt::error!("node: the monitor refused its configuration"),
        Err(e) => defmt::error!("node: cannot prepare the scenario's scene: {}", e),
    }
    // The watchdog, no longer fed, restarts the node.
    loop {
        cortex_m::asm::wfi();
    }
}
