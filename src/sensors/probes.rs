//! The misalignment phi from two axial displacement probes a known axial span apart on
//! one roller: `phi = atan2(d1 - d2 - zero_offset, span)`, the zero offset taken in a
//! known-aligned state, each probe's range and linearity checked.

use super::{
    Adc, CalibrationError, FaultDetector, RawLimits, SensorFault, SensorId, mean_raw, require,
};

/// What a probe's data sheet promises: its linear measuring range and its linearity.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ProbeSpec {
    /// The lowest displacement of the linear range, m.
    pub min_m: f32,
    /// The highest displacement of the linear range, m.
    pub max_m: f32,
    /// The largest deviation from the straight line inside the range, m (e.g. 0.5 % of
    /// a 2 mm range: 10e-6 m).
    pub linearity_m: f32,
}

impl ProbeSpec {
    fn validate(&self) -> Result<(), CalibrationError> {
        let ok = self.min_m.is_finite()
            && self.max_m.is_finite()
            && self.min_m < self.max_m
            && self.linearity_m >= 0.0
            && self.linearity_m.is_finite();
        require(ok)
    }
}

/// One probe's calibration: `d = (raw - zero_counts) * metres_per_count`, valid on the
/// spec's range. Plain and `Copy`, to be stored.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ProbeCalibration {
    /// The raw code at displacement 0, counts.
    pub zero_counts: f32,
    /// The scale, m per count (negative when the probe reads the other way).
    pub metres_per_count: f32,
    /// The probe's range and linearity.
    pub spec: ProbeSpec,
}

impl ProbeCalibration {
    /// The straight line through two points (raw code, displacement in m), taken with
    /// a gauge block or micrometer at two ends of the range.
    pub fn two_point(
        a: (f32, f32),
        b: (f32, f32),
        spec: ProbeSpec,
    ) -> Result<Self, CalibrationError> {
        spec.validate()?;
        if !(a.0.is_finite() && a.1.is_finite() && b.0.is_finite() && b.1.is_finite()) {
            return Err(CalibrationError::Value);
        }
        if a.0 == b.0 || a.1 == b.1 {
            return Err(CalibrationError::Degenerate);
        }
        let metres_per_count = (b.1 - a.1) / (b.0 - a.0);
        let cal = ProbeCalibration {
            zero_counts: a.0 - a.1 / metres_per_count,
            metres_per_count,
            spec,
        };
        cal.validate()?;
        Ok(cal)
    }

    /// Checks a calibration built by hand or put back from storage.
    pub fn validate(&self) -> Result<(), CalibrationError> {
        self.spec.validate()?;
        let s = self.metres_per_count;
        if !s.is_finite() || s == 0.0 {
            return Err(CalibrationError::Scale);
        }
        if !self.zero_counts.is_finite() {
            return Err(CalibrationError::Value);
        }
        Ok(())
    }

    /// The displacement of a raw code, m (not range-checked).
    pub fn metres(&self, raw: i32) -> f32 {
        (raw as f32 - self.zero_counts) * self.metres_per_count
    }

    /// The raw code of a displacement (the inverse, for simulations), rounded and
    /// clamped to `i32`.
    pub fn counts_for(&self, metres: f32) -> i32 {
        libm::roundf(metres / self.metres_per_count + self.zero_counts) as i32
    }

    /// The largest deviation, m, of the points (raw code, true displacement in m) from
    /// this calibration's line; a non-finite point counts as infinite.
    pub fn linearity_error(&self, points: &[(f32, f32)]) -> f32 {
        points.iter().fold(0.0f32, |worst, &(raw, d)| {
            let dev = libm::fabsf((raw - self.zero_counts) * self.metres_per_count - d);
            if dev.is_finite() {
                worst.max(dev)
            } else {
                f32::INFINITY
            }
        })
    }

    /// Checks the probe against its linearity limit at these points (raw code, true
    /// displacement in m), e.g. gauge blocks across the range: the largest deviation,
    /// or [`CalibrationError::Nonlinear`] above `spec.linearity_m`.
    pub fn check_linearity(&self, points: &[(f32, f32)]) -> Result<f32, CalibrationError> {
        let worst = self.linearity_error(points);
        if worst <= self.spec.linearity_m {
            Ok(worst)
        } else {
            Err(CalibrationError::Nonlinear)
        }
    }
}

/// The calibration of a misalignment measurement: both probes, their axial span and
/// the zero offset taken in a known-aligned state. Plain and `Copy`, to be stored.
///
/// The angle's uncertainty from the probes' linearity is about
/// `2 * linearity_m / span_m` rad: a wider span measures finer angles.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MisalignmentCalibration {
    /// Probe 1 (displacement d1).
    pub probe1: ProbeCalibration,
    /// Probe 2 (displacement d2).
    pub probe2: ProbeCalibration,
    /// The axial distance between the two probes' measuring points, m.
    pub span_m: f32,
    /// `d1 - d2` in the known-aligned state, m (0 until zeroed).
    pub zero_offset_m: f32,
}

impl MisalignmentCalibration {
    /// Checks a calibration built by hand or put back from storage.
    pub fn validate(&self) -> Result<(), CalibrationError> {
        self.probe1.validate()?;
        self.probe2.validate()?;
        if !(self.span_m > 0.0 && self.span_m.is_finite() && self.zero_offset_m.is_finite()) {
            return Err(CalibrationError::Value);
        }
        Ok(())
    }

    /// phi, rad, from the two displacements, m: `atan2(d1 - d2 - zero_offset, span)`,
    /// in (-pi/2, pi/2).
    pub fn phi(&self, d1_m: f32, d2_m: f32) -> f32 {
        libm::atan2f(d1_m - d2_m - self.zero_offset_m, self.span_m)
    }
}

/// One misalignment reading: the angle and the displacements it came from.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MisalignmentReading {
    /// Misalignment phi, rad.
    pub phi_rad: f32,
    /// Displacement at probe 1, m.
    pub d1_m: f32,
    /// Displacement at probe 2, m.
    pub d2_m: f32,
}

/// Two displacement probes on two channels of one [`Adc`] (e.g. A0 and A1 of an
/// ADS1115): misalignment readings with both probes' faults detected.
#[derive(Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Misalignment<A: Adc> {
    adc: A,
    channels: (A::Channel, A::Channel),
    calibration: MisalignmentCalibration,
    detectors: (FaultDetector, FaultDetector),
}

impl<A: Adc> Misalignment<A> {
    /// The probes on `channels` (probe 1, probe 2) of `adc`, with this calibration
    /// (checked) and these raw limits for both.
    pub fn new(
        adc: A,
        channels: (A::Channel, A::Channel),
        calibration: MisalignmentCalibration,
        limits: RawLimits,
    ) -> Result<Self, CalibrationError> {
        calibration.validate()?;
        Ok(Misalignment {
            adc,
            channels,
            calibration,
            detectors: (
                FaultDetector::new(SensorId::Probe1, limits),
                FaultDetector::new(SensorId::Probe2, limits),
            ),
        })
    }

    /// One reading: both probes read and checked (raw faults, then each probe's linear
    /// range), then phi. Both are always read, so that both count their faults; the
    /// first fault (probe 1's, then probe 2's) is returned.
    pub fn read(&mut self) -> Result<MisalignmentReading, SensorFault> {
        let cal = self.calibration;
        let d1 = probe_read(
            &mut self.adc,
            self.channels.0,
            &mut self.detectors.0,
            &cal.probe1,
        );
        let d2 = probe_read(
            &mut self.adc,
            self.channels.1,
            &mut self.detectors.1,
            &cal.probe2,
        );
        let (d1_m, d2_m) = (d1?, d2?);
        Ok(MisalignmentReading {
            phi_rad: cal.phi(d1_m, d2_m),
            d1_m,
            d2_m,
        })
    }

    /// The mean raw codes of `n` readings of each probe (every reading checked; a fault
    /// ends it): the raw points of an on-site probe calibration, counts.
    pub fn mean_raw(&mut self, n: u16) -> Result<(f32, f32), CalibrationError> {
        let r1 = mean_raw(&mut self.adc, self.channels.0, &mut self.detectors.0, n)?;
        let r2 = mean_raw(&mut self.adc, self.channels.1, &mut self.detectors.1, n)?;
        Ok((r1, r2))
    }

    /// Zero-offset calibration, in a known-aligned state: the mean of `n` readings of
    /// `d1 - d2` becomes the offset, so that phi reads 0 there. Both probes must be
    /// inside their ranges. Returns the new calibration (to be stored).
    pub fn zero(&mut self, n: u16) -> Result<MisalignmentCalibration, CalibrationError> {
        if n == 0 {
            return Err(CalibrationError::NoReadings);
        }
        let mut sum = 0.0f64;
        for _ in 0..n {
            let r = self.read()?;
            sum += f64::from(r.d1_m) - f64::from(r.d2_m);
        }
        let offset = (sum / f64::from(n)) as f32;
        self.calibration.zero_offset_m = offset;
        Ok(self.calibration)
    }

    /// The calibration in use.
    pub fn calibration(&self) -> MisalignmentCalibration {
        self.calibration
    }

    /// Puts a stored calibration back (checked first; on an error the old one stays).
    pub fn set_calibration(
        &mut self,
        calibration: MisalignmentCalibration,
    ) -> Result<(), CalibrationError> {
        calibration.validate()?;
        self.calibration = calibration;
        Ok(())
    }

    /// The fault detectors of probe 1 and probe 2.
    pub fn detectors(&self) -> (&FaultDetector, &FaultDetector) {
        (&self.detectors.0, &self.detectors.1)
    }

    /// The ADC.
    pub fn adc_mut(&mut self) -> &mut A {
        &mut self.adc
    }

    /// Gives the ADC back.
    pub fn release(self) -> A {
        self.adc
    }
}

fn probe_read<A: Adc>(
    adc: &mut A,
    channel: A::Channel,
    detector: &mut FaultDetector,
    cal: &ProbeCalibration,
) -> Result<f32, SensorFault> {
    let raw = detector.raw(adc.read(channel))?;
    detector.value(cal.metres(raw), cal.spec.min_m, cal.spec.max_m)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SPEC: ProbeSpec = ProbeSpec {
        min_m: 0.0,
        max_m: 2e-3,
        linearity_m: 5e-6,
    };

    #[test]
    fn two_point_line_inverse_and_linearity() {
        // 0 mm at 1000 counts, 2 mm at 21000 counts: 1e-7 m per count.
        let p = ProbeCalibration::two_point((1000.0, 0.0), (21000.0, 2e-3), SPEC).unwrap();
        assert!((p.metres_per_count - 1e-7).abs() < 1e-13);
        assert!((p.metres(11000) - 1e-3).abs() < 1e-9);
        assert_eq!(p.counts_for(1e-3), 11000);
        // A mid point 3 um off the line passes a 5 um limit, 8 um off does not.
        assert!(p.check_linearity(&[(11030.0, 1e-3)]).unwrap() < 3.1e-6);
        assert_eq!(
            p.check_linearity(&[(11080.0, 1e-3)]),
            Err(CalibrationError::Nonlinear)
        );
        assert_eq!(
            p.check_linearity(&[(f32::NAN, 1e-3)]),
            Err(CalibrationError::Nonlinear)
        );
        assert_eq!(p.check_linearity(&[]), Ok(0.0));
    }

    #[test]
    fn refused_probe_calibrations() {
        use CalibrationError as E;
        let two = |a, b, s| ProbeCalibration::two_point(a, b, s).map(|_| ());
        assert_eq!(two((5.0, 0.0), (5.0, 1e-3), SPEC), Err(E::Degenerate));
        assert_eq!(two((5.0, 1e-3), (6.0, 1e-3), SPEC), Err(E::Degenerate));
        assert_eq!(two((f32::NAN, 0.0), (6.0, 1e-3), SPEC), Err(E::Value));
        let inverted = ProbeSpec {
            min_m: 1.0,
            max_m: 0.0,
            ..SPEC
        };
        assert_eq!(two((5.0, 0.0), (6.0, 1e-3), inverted), Err(E::Value));
        let negative = ProbeSpec {
            linearity_m: -1.0,
            ..SPEC
        };
        assert_eq!(two((5.0, 0.0), (6.0, 1e-3), negative), Err(E::Value));
        assert_eq!(two((0.0, 0.0), (1e-38, 1e30), SPEC), Err(E::Scale));
    }

    #[test]
    fn phi_is_atan2_of_the_difference_over_the_span() {
        let p = ProbeCalibration::two_point((0.0, 0.0), (1e4, 1e-3), SPEC).unwrap();
        let mut cal = MisalignmentCalibration {
            probe1: p,
            probe2: p,
            span_m: 0.5,
            zero_offset_m: 0.0,
        };
        assert_eq!(cal.phi(1e-3, 1e-3), 0.0);
        let phi = cal.phi(1.1e-3, 1e-3);
        assert!((phi - libm::atanf(1e-4 / 0.5)).abs() < 1e-9, "{phi}");
        cal.zero_offset_m = 1e-4;
        assert!(cal.phi(1.1e-3, 1e-3).abs() < 1e-9);
        for bad in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            let c = MisalignmentCalibration { span_m: bad, ..cal };
            assert_eq!(c.validate(), Err(CalibrationError::Value));
        }
    }
}
