//! The Modbus monitoring node on a Raspberry Pi Pico (RP2040, Cortex-M0+) with an
//! RS-485 transceiver (a MAX3485 or the like): UART0 on GP0 (TX, to DI) and GP1 (RX,
//! from RO), 115200 baud 8N1, the transceiver's DE and /RE together on GP2 (high while
//! the node sends); 3.5 character times of silence (the RP2040's timer) end a frame.
//! The defmt log goes over RTT (a debug probe, `probe-rs run`).
//!
//! The node is the QEMU images' (`nodes/firmware`): the same estimator built the
//! same way (`node.rs`: the fixed-point core, as on every core without an FPU), the
//! same Modbus loop (`serve.rs`: `Server::poll` over the `embedded-io` traits),
//! compiled in here unchanged. Only the UART differs: embassy-rp's buffered UART, and
//! the driver-enable pin through embedded-hal's `OutputPin` ([`Rs485`]). Built with
//! `MISALIGN_MODBUS_EXTERNAL=1` it monitors the samples a PLC writes over the bus
//! (`docs/modbus.md`); without, it monitors the built-in scenario and serves its end,
//! as the QEMU images do.
#![no_std]
#![no_main]

use defmt_rtt as _;
use embassy_rp::bind_interrupts;
use embassy_rp::gpio::{Level, Output};
use embassy_rp::peripherals::UART0;
use embassy_rp::uart::{BufferedInterruptHandler, BufferedUart, Config};
use embedded_hal::digital::OutputPin;
use embedded_io::{ErrorType, Read, ReadReady, Write};
use panic_probe as _;

// The node's code, as the QEMU images compile it (its scenario run and its sensors
// are theirs only).
#[allow(dead_code)]
#[path = "../../firmware/node.rs"]
mod node;
#[allow(dead_code)] // The f32 model name is the FPU images'.
#[path = "../../firmware/serve.rs"]
mod serve;

const BAUD: u32 = 115_200;

bind_interrupts!(struct Irqs {
    UART0_IRQ => BufferedInterruptHandler<UART0>;
});

/// A half-duplex RS-485 line: any UART implementing `embedded-io`, and the
/// transceiver's driver-enable pin, raised from the first byte of an answer until its
/// last stop bit has left. `idle` says whether the UART's transmitter has sent that
/// (`flush` empties the HAL's buffer; the shift register is the HAL's own business).
pub struct Rs485<U, D> {
    uart: U,
    driver_enable: D,
    idle: fn(&U) -> bool,
}

impl<U: ErrorType, D> ErrorType for Rs485<U, D> {
    type Error = U::Error;
}

impl<U: ReadReady, D> ReadReady for Rs485<U, D> {
    fn read_ready(&mut self) -> Result<bool, U::Error> {
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

#[cortex_m_rt::entry]
fn main() -> ! {
    let p = embassy_rp::init(Default::default());
    let mut config = Config::default();
    config.baudrate = BAUD;
    let (mut tx_buffer, mut rx_buffer) = ([0u8; 256], [0u8; 256]);
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
    };
    let served = node::fixed_core().map(|core| {
        let clock = serve::LineClock {
            ticks: || embassy_time::Instant::now().as_micros() as u32,
            silence: misalign::modbus::silence_us(BAUD),
            // Microseconds.
            per_ms: 1000,
        };
        serve::node(core, serve::MODEL_FIXED, &mut line, clock)
    });
    match served {
        Ok(_) => defmt::error!("node: the monitor refused its configuration"),
        Err(e) => defmt::error!("node: cannot prepare the scenario's scene: {}", e),
    }
    loop {
        core::hint::spin_loop();
    }
}
