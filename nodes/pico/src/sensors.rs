//! The node's sensors at the Pico's pins, through the library's drivers: the load cell
//! on an HX711 (`Hx711` over two GPIOs), the two displacement probes on an ADS1115
//! over I2C0 (`ads1x1x`, `Misalignment`), the tachometer's pulses counted by PWM slice
//! 3 on its B input (`Tachometer`), and the pulse interface's line monitor. Sampled on
//! the RP2040's timer at the committed period (`config_sample_period`), each sample
//! stamped with its scheduled time, through the committed calibration
//! ([`Sensors::settings`]); waits inside a read sleep (`Sleep`).

use crate::board;
use crate::sleep::{Sleep, sleep_until};
use embassy_rp::gpio::{Input, Output};
use embassy_rp::i2c::{Blocking, I2c};
use embassy_rp::peripherals::I2C0;
use embassy_rp::pwm::Pwm;
use embassy_time::Instant;
use misalign::monitor::{FaultKind, Sample, SensorFault, SensorId};
use misalign::sensors::ads1x1x::{Ads1115, Ads1115Channel};
use misalign::sensors::{
    CalibrationError, Hx711, LoadCell, Misalignment, RawLimits, SensorSample, Tachometer,
};

type Cell = LoadCell<Hx711<Input<'static>, Output<'static>, Sleep>>;
type Probes = Misalignment<Ads1115<I2c<'static, I2C0, Blocking>, Sleep>>;

/// The sensors and the sampling schedule.
pub struct Sensors {
    cell: Cell,
    probes: Probes,
    tachometer: Tachometer,
    pulses: Pwm<'static>,
    line_ok: Input<'static>,
    /// The pulse count extended past the counter's 16 bits.
    count: u32,
    last_counter: u16,
    /// When the next sample is due (µs of the timer).
    due_us: u64,
    /// The sampling period (µs).
    period_us: u64,
}

impl Sensors {
    /// The sensors on their pins, calibrated with `settings` (`board::calibration`);
    /// the first sample a period from now.
    pub fn new(
        dout: Input<'static>,
        sck: Output<'static>,
        i2c: I2c<'static, I2C0, Blocking>,
        pulses: Pwm<'static>,
        line_ok: Input<'static>,
        settings: &board::SensorSettings,
    ) -> Result<Self, CalibrationError> {
        let cal = board::calibration(settings)?;
        let hx = Hx711::new(dout, sck, Sleep, board::HX711_TIMEOUT)
            .map_err(|_| CalibrationError::Value)?;
        let cell = LoadCell::new(hx, cal.load, RawLimits::new(hx711_rails()))?;
        let mut driver = ads1x1x::Ads1x1x::new_ads1115(i2c, ads1x1x::TargetAddr::default());
        // Not set here (an unplugged ADS1115): its next one-shot conversion carries the
        // driver's settings all the same (`read` writes the whole configuration).
        let _ = driver.set_full_scale_range(full_scale_range(board::ADS1115_FULL_SCALE_V));
        let _ = driver.set_data_rate(data_rate(board::ADS1115_SPS));
        let adc = Ads1115::new(driver, Sleep, board::ADS1115_TIMEOUT);
        let probes = Misalignment::new(
            adc,
            (Ads1115Channel::A0, Ads1115Channel::A1),
            cal.misalignment,
            RawLimits::new(misalign::sensors::Rails {
                min: i16::MIN.into(),
                max: i16::MAX.into(),
            }),
        )?;
        let last_counter = pulses.counter();
        let speed = cal.speed.ok_or(CalibrationError::Value)?;
        let period_us = u64::from(settings.sample_period_ms) * 1000;
        Ok(Sensors {
            cell,
            probes,
            tachometer: Tachometer::new(speed)?,
            pulses,
            line_ok,
            count: 0,
            last_counter,
            due_us: Instant::now().as_micros() + period_us,
            period_us,
        })
    }

    /// The settings in force changed (a commit, the committed image at boot): the
    /// drivers recalibrated, the next sample at the old period's time and the new
    /// period from then on. On an error (the drivers refuse it) nothing changes.
    pub fn settings(&mut self, settings: &board::SensorSettings) -> Result<(), CalibrationError> {
        let cal = board::calibration(settings)?;
        let speed = cal.speed.ok_or(CalibrationError::Value)?;
        let tachometer = if speed == self.tachometer.calibration() {
            None
        } else {
            Some(Tachometer::new(speed)?)
        };
        self.cell.set_calibration(cal.load)?;
        self.probes.set_calibration(cal.misalignment)?;
        if let Some(t) = tachometer {
            self.tachometer = t;
        }
        self.period_us = u64::from(settings.sample_period_ms) * 1000;
        Ok(())
    }

    /// When the next sample is due (µs).
    pub fn due_us(&self) -> u64 {
        self.due_us
    }

    /// The sample due now, if one is: stamped with its scheduled time (ms, the u32
    /// counter the monitor takes); a period missed is skipped, not made up.
    pub fn sample(&mut self) -> Option<Sample> {
        let now = Instant::now().as_micros();
        if now < self.due_us {
            return None;
        }
        let at = self.due_us;
        let period = self.period_us;
        self.due_us += period * ((now - at) / period + 1);
        let time_ms = (at / 1000) as u32;
        // The tachometer first: its count at the scheduled time.
        let speed = self.speed(now as u32);
        let load = self.cell.read();
        let phi = self.probes.read().map(|r| r.phi_rad);
        Some(Sample::from_sensors(
            time_ms,
            &SensorSample::new(load, phi, speed),
        ))
    }

    /// The rolling speed since the last sample; a fault when the pulse interface
    /// reports its line broken (the pulse input low: `Disconnected`) or shorted
    /// (held high: `Stuck`).
    fn speed(&mut self, now_us: u32) -> Option<Result<f32, SensorFault>> {
        let counter = self.pulses.counter();
        self.count = self
            .count
            .wrapping_add(u32::from(counter.wrapping_sub(self.last_counter)));
        self.last_counter = counter;
        if self.line_ok.is_low() {
            // The pulse input's level, read through SIO whatever its function.
            let high = embassy_rp::pac::SIO.gpio_in(0).read() & (1 << 7) != 0;
            let kind = if high {
                FaultKind::Stuck
            } else {
                FaultKind::Disconnected
            };
            return Some(Err(SensorFault {
                sensor: SensorId::Speed,
                kind,
            }));
        }
        self.tachometer.update(self.count, now_us).transpose()
    }
}

/// The ADS1115's data rate: the slowest at least `sps`.
fn data_rate(sps: u32) -> ads1x1x::DataRate16Bit {
    use ads1x1x::DataRate16Bit as D;
    match sps {
        0..=8 => D::Sps8,
        9..=16 => D::Sps16,
        17..=32 => D::Sps32,
        33..=64 => D::Sps64,
        65..=128 => D::Sps128,
        129..=250 => D::Sps250,
        251..=475 => D::Sps475,
        _ => D::Sps860,
    }
}

/// The ADS1115's range for a full scale (V): the smallest that holds it.
fn full_scale_range(volts: f32) -> ads1x1x::FullScaleRange {
    use ads1x1x::FullScaleRange as R;
    match volts {
        v if v > 4.096 => R::Within6_144V,
        v if v > 2.048 => R::Within4_096V,
        v if v > 1.024 => R::Within2_048V,
        v if v > 0.512 => R::Within1_024V,
        v if v > 0.256 => R::Within0_512V,
        _ => R::Within0_256V,
    }
}

/// The HX711's rails (24-bit two's complement).
fn hx711_rails() -> misalign::sensors::Rails {
    misalign::sensors::Rails {
        min: -(1 << 23),
        max: (1 << 23) - 1,
    }
}

/// Sleeps until the next sample is due or `until_us`, whichever is first, unless
/// `pending` says a byte came.
pub fn idle(due_us: u64, until_us: u64, pending: &mut dyn FnMut() -> bool) {
    sleep_until(due_us.min(until_us), pending);
}
