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

use misalign::sensors::{CalibrationError, Hx711Channel, ProbeSpec, SensorCalibration, Timeout};

/// The UART's baud rate as built (8 data bits, no parity, 1 stop bit: embassy-rp's
/// defaults); the unit id and the line settings the server reports are commissioned
/// (docs/modbus.md, Line settings).
pub struct Line {
    pub baud: u32,
}

/// The UART as built: 115200 baud 8N1.
pub const LINE: Line = Line { baud: 115_200 };

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
