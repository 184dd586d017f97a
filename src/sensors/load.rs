//! The load P from a bridge load cell: tare, two-point calibration with a known weight,
//! the calibrated range checked.

use super::hx711::Hx711Channel;
use super::{Adc, CalibrationError, FaultDetector, RawLimits, SensorFault, SensorId, mean_raw};

/// Standard gravity, m/s^2 (the weight of a test mass where the local g is not known;
/// g varies by 0.5 % over the Earth, so use the local value for better than that).
pub const STANDARD_GRAVITY: f32 = 9.80665;

/// The weight in N of a test mass of `mass_kg` kg under gravity `g` m/s^2.
pub fn weight_newtons(mass_kg: f32, g: f32) -> Result<f32, CalibrationError> {
    let w = mass_kg * g;
    if mass_kg > 0.0 && g > 0.0 && w.is_finite() {
        Ok(w)
    } else {
        Err(CalibrationError::Value)
    }
}

/// A load cell's calibration: `P = (raw - zero_counts) * newtons_per_count`, valid on
/// `min_newtons ..= max_newtons`. Plain and `Copy`, to be stored and put back
/// ([`validate`](Self::validate) it then).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LoadCalibration<C> {
    /// The ADC channel and gain the calibration was made with.
    pub channel: C,
    /// The raw code at zero load (tare), counts.
    pub zero_counts: f32,
    /// The scale, N per count (negative for a bridge wired the other way round).
    pub newtons_per_count: f32,
    /// The lowest load the cell is calibrated for, N.
    pub min_newtons: f32,
    /// The highest load the cell is calibrated for, N.
    pub max_newtons: f32,
}

impl<C> LoadCalibration<C> {
    /// The calibration from two points: `zero_counts` with the cell unloaded,
    /// `known_counts` with a known weight of `known_newtons` N on it. The calibrated
    /// range is `-capacity_n ..= capacity_n` (the cell's rated capacity, N).
    pub fn two_point(
        channel: C,
        zero_counts: f32,
        known_counts: f32,
        known_newtons: f32,
        capacity_n: f32,
    ) -> Result<Self, CalibrationError> {
        if !(zero_counts.is_finite() && known_counts.is_finite()) {
            return Err(CalibrationError::Value);
        }
        if !(known_newtons > 0.0 && known_newtons.is_finite()) {
            return Err(CalibrationError::Value);
        }
        if known_counts == zero_counts {
            return Err(CalibrationError::Degenerate);
        }
        let cal = LoadCalibration {
            channel,
            zero_counts,
            newtons_per_count: known_newtons / (known_counts - zero_counts),
            min_newtons: -capacity_n,
            max_newtons: capacity_n,
        };
        cal.validate()?;
        Ok(cal)
    }

    /// Checks a calibration built by hand or put back from storage: finite values, a
    /// non-zero scale, a range with `min < max`.
    pub fn validate(&self) -> Result<(), CalibrationError> {
        let s = self.newtons_per_count;
        if !s.is_finite() || s == 0.0 {
            return Err(CalibrationError::Scale);
        }
        let (lo, hi) = (self.min_newtons, self.max_newtons);
        if !(self.zero_counts.is_finite() && lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(CalibrationError::Value);
        }
        Ok(())
    }

    /// The same scale with a new zero (tare), counts.
    pub fn with_zero(self, zero_counts: f32) -> Self {
        LoadCalibration {
            zero_counts,
            ..self
        }
    }

    /// The load of a raw code, N (not range-checked).
    pub fn newtons(&self, raw: i32) -> f32 {
        (raw as f32 - self.zero_counts) * self.newtons_per_count
    }

    /// The raw code of a load of `newtons` N (the inverse, for simulations and
    /// checks), rounded and clamped to `i32`.
    pub fn counts_for(&self, newtons: f32) -> i32 {
        // `as` saturates and maps NaN to 0.
        libm::roundf(newtons / self.newtons_per_count + self.zero_counts) as i32
    }
}

impl LoadCalibration<Hx711Channel> {
    /// A nominal calibration from the load cell's data sheet, to start from before the
    /// first tare and two-point calibration: rated output `mv_per_v` (mV per V of
    /// excitation at `capacity_n` N). The HX711 is ratiometric (the bridge is excited
    /// from its AVDD and its input range is +-0.5 AVDD / gain), so full capacity gives
    /// `mv_per_v * 1e-3 * 2 * gain * 2^23` counts whatever AVDD is.
    pub fn from_rated_output(
        channel: Hx711Channel,
        mv_per_v: f32,
        capacity_n: f32,
    ) -> Result<Self, CalibrationError> {
        if !(mv_per_v > 0.0 && mv_per_v.is_finite() && capacity_n > 0.0) {
            return Err(CalibrationError::Value);
        }
        let gain = match channel {
            Hx711Channel::A128 => 128.0,
            Hx711Channel::A64 => 64.0,
            Hx711Channel::B32 => 32.0,
        };
        let full_counts = mv_per_v * 1e-3 * 2.0 * gain * 8_388_608.0;
        LoadCalibration::two_point(channel, 0.0, full_counts, capacity_n, capacity_n)
    }
}

/// A load cell on any [`Adc`] (an [`Hx711`](super::Hx711) as a rule): calibrated
/// readings in N with their faults detected.
#[derive(Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LoadCell<A: Adc> {
    adc: A,
    calibration: LoadCalibration<A::Channel>,
    detector: FaultDetector,
}

impl<A: Adc> LoadCell<A> {
    /// The load cell on `adc` with this calibration (checked) and these raw limits
    /// ([`RawLimits::new`]`(adc.rails())` for the defaults).
    pub fn new(
        adc: A,
        calibration: LoadCalibration<A::Channel>,
        limits: RawLimits,
    ) -> Result<Self, CalibrationError> {
        calibration.validate()?;
        Ok(LoadCell {
            adc,
            calibration,
            detector: FaultDetector::new(SensorId::Load, limits),
        })
    }

    /// One load reading, N: the raw code checked (disconnected, bus, saturated, jump,
    /// stuck), converted, and checked against the calibrated range.
    pub fn read(&mut self) -> Result<f32, SensorFault> {
        let raw = self.detector.raw(self.adc.read(self.calibration.channel))?;
        let cal = &self.calibration;
        self.detector
            .value(cal.newtons(raw), cal.min_newtons, cal.max_newtons)
    }

    /// The mean raw code of `n` readings (each checked; a fault ends it), counts.
    pub fn mean_raw(&mut self, n: u16) -> Result<f32, CalibrationError> {
        mean_raw(
            &mut self.adc,
            self.calibration.channel,
            &mut self.detector,
            n,
        )
    }

    /// Tare: with the cell unloaded, the mean of `n` readings becomes the zero. The
    /// scale stays. Returns the new calibration (to be stored).
    pub fn tare(&mut self, n: u16) -> Result<LoadCalibration<A::Channel>, CalibrationError> {
        let zero = self.mean_raw(n)?;
        self.calibration = self.calibration.with_zero(zero);
        Ok(self.calibration)
    }

    /// The second point of a two-point calibration: with the known weight
    /// `known_newtons` N on the cell, the mean of `n` readings against the zero
    /// `zero_counts` measured unloaded (by [`mean_raw`](Self::mean_raw)) gives the
    /// scale; the calibrated range is `-capacity_n ..= capacity_n`. Returns the new
    /// calibration (to be stored); on an error the old one stays.
    pub fn calibrate(
        &mut self,
        zero_counts: f32,
        known_newtons: f32,
        capacity_n: f32,
        n: u16,
    ) -> Result<LoadCalibration<A::Channel>, CalibrationError> {
        let known = self.mean_raw(n)?;
        let cal = LoadCalibration::two_point(
            self.calibration.channel,
            zero_counts,
            known,
            known_newtons,
            capacity_n,
        )?;
        self.calibration = cal;
        Ok(cal)
    }

    /// The calibration in use.
    pub fn calibration(&self) -> LoadCalibration<A::Channel> {
        self.calibration
    }

    /// Puts a stored calibration back (checked first; on an error the old one stays).
    pub fn set_calibration(
        &mut self,
        calibration: LoadCalibration<A::Channel>,
    ) -> Result<(), CalibrationError> {
        calibration.validate()?;
        self.calibration = calibration;
        Ok(())
    }

    /// The fault detector (its counts, its limits).
    pub fn detector(&self) -> &FaultDetector {
        &self.detector
    }

    /// The ADC, e.g. to power it down.
    pub fn adc_mut(&mut self) -> &mut A {
        &mut self.adc
    }

    /// Gives the ADC back.
    pub fn release(self) -> A {
        self.adc
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_point_line_and_its_inverse() {
        let cal = LoadCalibration::two_point((), 1000.0, 21000.0, 200.0, 5000.0).unwrap();
        assert_eq!(cal.newtons_per_count, 0.01);
        assert_eq!(cal.newtons(1000), 0.0);
        assert_eq!(cal.newtons(21000), 200.0);
        assert_eq!(cal.newtons(-9000), -100.0);
        assert_eq!(cal.counts_for(200.0), 21000);
        assert_eq!((cal.min_newtons, cal.max_newtons), (-5000.0, 5000.0));
        let tared = cal.with_zero(1500.0);
        assert_eq!(tared.newtons(1500), 0.0);
        assert_eq!(tared.newtons_per_count, cal.newtons_per_count);
    }

    #[test]
    fn refused_calibrations() {
        use CalibrationError as E;
        let two = |z, k, w, c| LoadCalibration::two_point((), z, k, w, c).map(|_| ());
        assert_eq!(two(5.0, 5.0, 10.0, 100.0), Err(E::Degenerate));
        assert_eq!(two(f32::NAN, 5.0, 10.0, 100.0), Err(E::Value));
        assert_eq!(two(0.0, f32::INFINITY, 10.0, 100.0), Err(E::Value));
        assert_eq!(two(0.0, 5.0, 0.0, 100.0), Err(E::Value));
        assert_eq!(two(0.0, 5.0, -1.0, 100.0), Err(E::Value));
        assert_eq!(two(0.0, 5.0, 10.0, 0.0), Err(E::Value));
        assert_eq!(two(0.0, 5.0, 10.0, f32::NAN), Err(E::Value));
        // 1 N over 1e-30 counts: the scale overflows f32.
        assert_eq!(two(0.0, 1e-30, f32::MAX, 100.0), Err(E::Scale));
        assert_eq!(weight_newtons(10.0, STANDARD_GRAVITY), Ok(98.0665));
        assert_eq!(weight_newtons(0.0, STANDARD_GRAVITY), Err(E::Value));
        assert_eq!(weight_newtons(f32::MAX, 10.0), Err(E::Value));
    }

    #[test]
    fn rated_output_of_a_2_mv_per_v_cell() {
        // 2 mV/V at gain 128: 2e-3 * 2 * 128 * 2^23 = 4294967.3 counts at 1 kN (f32
        // rounding of the scale: within a count).
        let cal = LoadCalibration::from_rated_output(Hx711Channel::A128, 2.0, 1000.0).unwrap();
        assert!((cal.counts_for(1000.0) - 4_294_967).abs() <= 1);
        let b = LoadCalibration::from_rated_output(Hx711Channel::B32, 2.0, 1000.0).unwrap();
        assert!((b.counts_for(1000.0) - 1_073_742).abs() <= 1);
        assert!(LoadCalibration::from_rated_output(Hx711Channel::A64, 0.0, 1.0).is_err());
    }
}
