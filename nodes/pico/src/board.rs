//! The board in one place: the pins, the RS-485 line's settings, what the build fixes
//! of the sensors (docs/pico.md draws the same table for the technician).
//!
//! | signal | Pico pin | to |
//! |---|---|---|
//! | UART0 TX | GP0 | RS-485 transceiver DI |
//! | UART0 RX | GP1 | transceiver RO |
//! | driver enable | GP2 | transceiver DE and /RE (high while the node sends) |
//! | I2C0 SDA, SCL | GP4, GP5 | ADS1115 (address 0x48), 4.7 kOhm pull-ups |
//! | tachometer line OK | GP6 | the pulse interface's line monitor (high: OK), pull-down |
//! | tachometer pulses | GP7 | PWM slice 3, channel B, counting rising edges |
//! | HX711 DOUT | GP10 | input with pull-up |
//! | HX711 PD_SCK | GP11 | push-pull output |
//! | line recovery | GP22 | input with pull-up; a jumper to GND (pin 28) at power-on: the default line settings for that power-on |

use misalign::sensors::{CalibrationError, Hx711Channel, ProbeSpec, SensorCalibration, Timeout};

/// The UART runs the line settings in force (docs/modbus.md, Line settings: the
/// committed ones, the documented defaults until some are), set by `line`; from reset
/// until the node has restored them, the defaults.
pub use misalign::modbus::{LineSettings, Parity};

/// The PL011's baud rate divisor for `baud` from `clk_peri` (Hz): clk_peri / (16
/// baud) in sixty-fourths, rounded, as its integer part (UARTIBRD, 1 to 65535) and its
/// fraction (UARTFBRD); 19200 baud from 125 MHz: 406 + 58/64 (19199.8 baud).
pub fn divisor(clk_peri: u32, baud: u32) -> (u32, u32) {
    let sixty_fourths = (8 * u64::from(clk_peri) / u64::from(baud.max(1))).div_ceil(2);
    match sixty_fourths >> 6 {
        0 => (1, 0),
        65_535.. => (65_535, 0),
        ibrd => (ibrd as u32, (sixty_fourths & 63) as u32),
    }
}

/// The sampling period and the sensors' calibration are commissioned over the bus
/// (`config_sample_period`, `config_load_zero`, ... in docs/modbus.md) and kept on
/// flash; until a site's are committed the node runs the library's
/// `SensorSettings::DEFAULT`, the data sheets' values of the parts below: 10 samples a
/// second; the load cell 2 mV/V, 20 kN, on the HX711's channel A at gain 128; each
/// probe 4-20 mA over 0 to 2 mm through a 150 Ohm shunt (0.6 to 3.0 V), read at
/// +-4.096 V (4800 codes at 0 mm, 24000 at 2 mm), the two 0.4 m apart; a 1024-line
/// encoder on the measured roller's shaft (radius 50 mm), 10 m/s at most. The HX711
/// converts at 80 samples a second (its RATE pin high) and the ADS1115 at 860, so that
/// at the default period each sample takes a conversion at most 12.5 ms old and its
/// reads hold the Modbus loop up for at most that long plus two of the ADS1115's 1.2 ms.
pub use misalign::modbus::SensorSettings;

/// The watchdog's timeout (ms): longer than any pass of the node's loop (a sample
/// whose HX711 never becomes ready waits 50 ms; a sector erase 400 ms at most).
pub const WATCHDOG_MS: u64 = 2_000;

/// The HX711's bounded wait at 80 samples/s.
pub const HX711_TIMEOUT: Timeout = Timeout::HX711_80SPS;
/// The ADS1115's data rate (samples/s) and its bounded wait: 1.16 ms a conversion,
/// checked every 250 µs for 4 ms.
pub const ADS1115_SPS: u32 = 860;
pub const ADS1115_TIMEOUT: Timeout = Timeout {
    polls: 16,
    interval_us: 250,
};
/// The ADS1115's full-scale range (V): +-4.096 V, 8000 codes a volt.
pub const ADS1115_FULL_SCALE_V: f32 = 4.096;

/// The HX711's channel and gain the load cell is wired to (the build's: not
/// commissioned).
pub const LOAD_CHANNEL: Hx711Channel = Hx711Channel::A128;

/// Each probe's range and linearity (its data sheet: 0 to 2 mm, linear to 4 µm).
pub const PROBE_SPEC: ProbeSpec = ProbeSpec {
    min_m: 0.0,
    max_m: 2e-3,
    linearity_m: 4e-6,
};

/// The sensors' calibration of the settings in force, checked.
pub fn calibration(settings: &SensorSettings) -> Result<SensorCalibration, CalibrationError> {
    settings.calibration(LOAD_CHANNEL, PROBE_SPEC)
}
