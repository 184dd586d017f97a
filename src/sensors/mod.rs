//! Sensors on embedded-hal 1.0: the load P from a load cell, the misalignment phi from
//! two displacement probes and the rolling speed V from a tachometer, calibrated, with
//! the faults real sensors have detected and counted (feature `sensors`).
//!
//! Wiring and the calibration procedure a technician follows on site: docs/SENSORS.md.
//!
//! | quantity | sensor | type | unit |
//! |---|---|---|---|
//! | load P | bridge load cell on an HX711 (two GPIO pins and a delay) | [`LoadCell`] over [`Hx711`] | N |
//! | misalignment phi | two axial displacement probes a span apart, any ADC ([`Adc`]) | [`Misalignment`] | rad (probes in m) |
//! | speed V (optional) | tachometer or encoder pulses over a time base | [`Tachometer`] | m/s |
//!
//! Every reading is either a value in SI units or a [`SensorFault`] naming the sensor
//! ([`SensorId`]) and the reason ([`FaultKind`]): disconnected (no data ready within the
//! bounded wait), a bus or pin error, saturated (a raw code at the ADC's rail), stuck
//! (identical raw codes where noise is expected), a jump (a raw step larger than a
//! physical signal can make between two readings, e.g. the full scale) and out of the
//! calibrated physical range. Each sensor counts its faults per kind
//! ([`SensorFaultCounts`]). Nothing here panics or waits without bound, whatever the pins and
//! the bus return. [`SensorSample`] gathers one sample for a condition monitor: load,
//! angle, optional speed and the first fault, if any (a faulty sample is a sensor fault,
//! never a measurement).
//!
//! Calibrations are plain `Copy` values ([`LoadCalibration`], [`ProbeCalibration`],
//! [`MisalignmentCalibration`], [`SpeedCalibration`], the whole node's
//! [`SensorCalibration`]) so that they can be stored and put back.
//!
//! # Crates weighed, and what was chosen
//!
//! - **`hx711` 0.7** (embedded-hal 1.0): its constructor resets the chip and then waits
//!   for the first conversion with `nb::block!`, as do `enable` and `reset`: with the
//!   chip unplugged (DOUT held high) the node hangs in `Hx711::new`, before any
//!   timeout of ours could run, and there is no way to build its driver without that
//!   wait. Its `MIN_VALUE` is also +2^23 instead of -2^23. It cannot be wrapped into a
//!   driver that never hangs, so this module has its own small bit-banged driver
//!   ([`Hx711`]: readiness polled a bounded number of times, channel and gain set by the
//!   25th to 27th clock pulse, the conversion that still carries the previous gain
//!   discarded).
//! - **`loadcell` 0.3**: `unwrap()`s every pin operation (a pin error is a panic) and its
//!   `tare` busy-waits `while !is_ready()` without bound; not usable under "no panic,
//!   no hang".
//! - **`ads1x1x` 0.3** (embedded-hal 1.0, maintained): a sound ADS1013/4/5/1113/4/5
//!   driver whose one-shot `read` is non-blocking (`nb::WouldBlock` while converting).
//!   It is wrapped, not forked: the `sensors::ads1x1x` module (feature
//!   `ads1x1x`) adapts it to this module's [`Adc`] trait with a bounded wait.
//!
//! embedded-hal 1.0 has no ADC trait (it was dropped from 1.0), hence the small [`Adc`]
//! trait here: one bounded, blocking read of a raw code on a channel, plus the ADC's
//! rails. [`Hx711`] implements it too, so that the load cell and the probes share one
//! fault detector ([`FaultDetector`]).
//!
//! The simulated chips that replay a trace through the same traits are in `sim`
//! (feature `_sim`, semver-exempt).

#[cfg(feature = "ads1x1x")]
pub mod ads1x1x;
mod calibration;
mod fault;
mod hx711;
mod load;
mod probes;
#[cfg(feature = "_sim")]
pub mod sim;
mod speed;

pub use calibration::SensorCalibration;
pub use fault::{FaultDetector, FaultKind, RawLimits, SensorFault, SensorFaultCounts, SensorId};
pub use hx711::{Hx711, Hx711Channel, PinError};
pub use load::{LoadCalibration, LoadCell, STANDARD_GRAVITY, weight_newtons};
pub use probes::{
    Misalignment, MisalignmentCalibration, MisalignmentReading, ProbeCalibration, ProbeSpec,
};
pub use speed::{SpeedCalibration, Tachometer, rolling_speed};

use core::fmt;

/// An ADC as this module needs it (embedded-hal 1.0 has no ADC trait): a bounded,
/// blocking read of one raw code on a channel.
///
/// An implementation must return within a bounded time: it polls for a finished
/// conversion at most a fixed number of times ([`Timeout`]) and then returns
/// [`AdcError::Timeout`]. It never panics.
pub trait Adc {
    /// The ADC's input selection (channel, gain, mux setting).
    type Channel: Copy + PartialEq;
    /// The bus or pin error of the underlying hardware.
    type Error;

    /// The lowest and highest raw code the ADC can give (its rails).
    fn rails(&self) -> Rails;

    /// One conversion on `channel`, as a raw two's-complement code in
    /// `rails().min ..= rails().max`.
    fn read(&mut self, channel: Self::Channel) -> Result<i32, AdcError<Self::Error>>;
}

/// Why an [`Adc`] read gave no code.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum AdcError<E> {
    /// No conversion was ready within the bounded wait (a disconnected chip or probe).
    Timeout,
    /// The bus or a pin reported an error.
    Bus(E),
}

impl<E: fmt::Debug> fmt::Display for AdcError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AdcError::Timeout => f.write_str("no conversion ready within the timeout"),
            AdcError::Bus(e) => write!(f, "bus or pin error: {e:?}"),
        }
    }
}

/// The bus's error `E` need only be `Debug` (as embedded-hal's error traits ask).
impl<E: fmt::Debug> core::error::Error for AdcError<E> {}

/// The lowest and the highest raw code of an ADC: a code at either is saturated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Rails {
    /// The lowest code (negative full scale).
    pub min: i32,
    /// The highest code (positive full scale).
    pub max: i32,
}

impl Rails {
    /// The rails of a two's-complement ADC of `bits` bits (2 to 32): -2^(bits-1) and
    /// 2^(bits-1) - 1. `None` for a width outside 2..=32.
    pub const fn signed_bits(bits: u32) -> Option<Rails> {
        if bits < 2 || bits > 32 {
            return None;
        }
        let max = ((1u64 << (bits - 1)) - 1) as i32;
        Some(Rails { min: -max - 1, max })
    }

    /// The full scale, `max - min`, in codes.
    pub const fn span(&self) -> u32 {
        self.max.abs_diff(self.min)
    }

    /// Whether `raw` is at or beyond a rail.
    pub const fn is_saturated(&self, raw: i32) -> bool {
        raw <= self.min || raw >= self.max
    }
}

/// The bounded wait for a conversion: at most `polls` readiness checks, `interval_us`
/// microseconds apart (the longest wait is `polls * interval_us` µs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Timeout {
    /// How many times readiness is checked before giving up (at least 1 is used).
    pub polls: u32,
    /// The delay between two checks, µs.
    pub interval_us: u32,
}

impl Timeout {
    /// For an HX711 at 10 samples/s (100 ms a conversion, 400 ms to settle after a
    /// reset): 500 checks 1 ms apart.
    pub const HX711_10SPS: Timeout = Timeout {
        polls: 500,
        interval_us: 1000,
    };
    /// For an HX711 at 80 samples/s (RATE pin high; 12.5 ms a conversion, 50 ms to
    /// settle): 100 checks 500 µs apart.
    pub const HX711_80SPS: Timeout = Timeout {
        polls: 100,
        interval_us: 500,
    };
    /// For an ADS1115 at its default 128 samples/s (7.8 ms a conversion): 40 checks
    /// 500 µs apart.
    pub const ADS1115_128SPS: Timeout = Timeout {
        polls: 40,
        interval_us: 500,
    };
}

/// One sample for a condition monitor: the load P (N), the misalignment phi (rad), the
/// rolling speed V (m/s) if measured, and the first sensor fault, if any.
///
/// When `fault` is `Some`, the faulty quantity holds 0 and is not a measurement: the
/// sample must go to the monitor's sensor-fault state, never to the slip estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SensorSample {
    /// Load P, N (0 when the load cell is faulty).
    pub load_n: f32,
    /// Misalignment phi, rad (0 when a probe is faulty).
    pub phi_rad: f32,
    /// Rolling speed V, m/s, when a tachometer is fitted and has a value.
    pub speed_m_s: Option<f32>,
    /// The first fault of this sample, in the order load, probes, speed.
    pub fault: Option<SensorFault>,
}

impl SensorSample {
    /// Gathers one sample from the three readings (speed `None`: no tachometer, or no
    /// speed yet).
    pub fn new(
        load: Result<f32, SensorFault>,
        phi: Result<f32, SensorFault>,
        speed: Option<Result<f32, SensorFault>>,
    ) -> SensorSample {
        let mut fault = None;
        let mut take = |r: Result<f32, SensorFault>| match r {
            Ok(v) => v,
            Err(f) => {
                fault = fault.or(Some(f));
                0.0
            }
        };
        let load_n = take(load);
        let phi_rad = take(phi);
        let speed_m_s = speed.map(&mut take);
        SensorSample {
            load_n,
            phi_rad,
            speed_m_s,
            fault,
        }
    }

    /// Whether every quantity of the sample is a measurement (no fault).
    pub fn is_valid(&self) -> bool {
        self.fault.is_none()
    }
}

/// Why a calibration was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum CalibrationError {
    /// A given value (weight, displacement, span, radius, range) is not finite, or not
    /// positive where it must be.
    Value,
    /// The two calibration points have the same raw code (or the same physical value):
    /// no scale follows from them.
    Degenerate,
    /// The scale that follows is not finite or is zero.
    Scale,
    /// A probe deviates from its straight line by more than its linearity limit.
    Nonlinear,
    /// Averaging was asked for zero readings.
    NoReadings,
    /// A reading taken for the calibration was a sensor fault.
    Sensor(SensorFault),
}

impl fmt::Display for CalibrationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            CalibrationError::Value => "calibration value not finite or not positive",
            CalibrationError::Degenerate => "the two calibration points coincide: no scale follows",
            CalibrationError::Scale => "the calibration scale is zero or not finite",
            CalibrationError::Nonlinear => "probe outside its linearity limit",
            CalibrationError::NoReadings => "averaging over zero readings",
            CalibrationError::Sensor(fault) => return write!(f, "during calibration: {fault}"),
        })
    }
}

/// `Ok` if `ok`, else [`CalibrationError::Value`].
pub(crate) fn require(ok: bool) -> Result<(), CalibrationError> {
    if ok {
        Ok(())
    } else {
        Err(CalibrationError::Value)
    }
}

impl From<SensorFault> for CalibrationError {
    fn from(fault: SensorFault) -> Self {
        CalibrationError::Sensor(fault)
    }
}

impl core::error::Error for CalibrationError {}

/// The mean of `n` raw codes of one channel, each checked by `detector` (any fault ends
/// the average with that fault): what tare and calibration take, so that noise averages
/// out. The sum is kept in an `i64`, so no `n` overflows it.
pub(crate) fn mean_raw<A: Adc>(
    adc: &mut A,
    channel: A::Channel,
    detector: &mut FaultDetector,
    n: u16,
) -> Result<f32, CalibrationError> {
    if n == 0 {
        return Err(CalibrationError::NoReadings);
    }
    let mut sum: i64 = 0;
    for _ in 0..n {
        sum += i64::from(detector.raw(adc.read(channel))?);
    }
    Ok((sum as f64 / f64::from(n)) as f32)
}
