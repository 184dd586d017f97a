//! The rolling speed V from tachometer or encoder pulses over a time base.

use core::f32::consts::PI;

use super::{CalibrationError, FaultKind, SensorFault, SensorFaultCounts, SensorId, require};

/// `V = 2 pi r pulses / (pulses_per_rev * dt)`: the surface speed, m/s, of a roller of
/// radius `radius_m` m that gave `pulses` pulses of a `pulses_per_rev` encoder in
/// `dt_s` s. `None` for a zero or non-finite time, a zero pulse count per revolution, or
/// a result that is not finite.
pub fn rolling_speed(pulses: u32, pulses_per_rev: u32, radius_m: f32, dt_s: f32) -> Option<f32> {
    if pulses_per_rev == 0 || dt_s.is_nan() || dt_s <= 0.0 {
        return None;
    }
    // f32 throughout (no soft f64 on a Cortex-M0 per sample); the counts of one
    // interval are far below 2^24, where f32 is exact.
    let revs_per_s = pulses as f32 / pulses_per_rev as f32 / dt_s;
    let v = 2.0 * PI * radius_m * revs_per_s;
    v.is_finite().then_some(v)
}

/// A tachometer's calibration. Plain and `Copy`, to be stored.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SpeedCalibration {
    /// Pulses per revolution of the roller the tachometer sees (marks on the shaft,
    /// encoder lines times the counter's edge multiplication).
    pub pulses_per_rev: u32,
    /// The radius of that roller at its surface, m.
    pub radius_m: f32,
    /// The highest plausible surface speed, m/s: above it the speed is out of range.
    pub max_speed_m_s: f32,
}

impl SpeedCalibration {
    /// Checks the values: pulses per revolution at least 1, radius and top speed finite
    /// and positive.
    pub fn validate(&self) -> Result<(), CalibrationError> {
        let ok = self.pulses_per_rev > 0
            && self.radius_m > 0.0
            && self.radius_m.is_finite()
            && self.max_speed_m_s > 0.0
            && self.max_speed_m_s.is_finite();
        require(ok)
    }
}

/// The speed from a free-running pulse counter (a timer in counter mode, a `u32` that
/// wraps) read at times from a free-running microsecond clock (a `u32` that wraps every
/// 71.6 min): both differences are taken wrapping, so a wrap is not a jump.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Tachometer {
    calibration: SpeedCalibration,
    last: Option<(u32, u32)>,
    counts: SensorFaultCounts,
}

impl Tachometer {
    /// A tachometer with this calibration (checked).
    pub fn new(calibration: SpeedCalibration) -> Result<Self, CalibrationError> {
        calibration.validate()?;
        Ok(Tachometer {
            calibration,
            last: None,
            counts: SensorFaultCounts::default(),
        })
    }

    /// The speed, m/s, since the previous update, from the counter value `pulses` at
    /// `now_us`. `Ok(None)` on the first update and when no time has passed (the
    /// previous point is kept then). A speed above the calibrated maximum (a counter
    /// that ran backwards reads as a huge forward count) is
    /// [`FaultKind::OutOfRange`].
    pub fn update(&mut self, pulses: u32, now_us: u32) -> Result<Option<f32>, SensorFault> {
        let Some((p0, t0)) = self.last else {
            self.last = Some((pulses, now_us));
            return Ok(None);
        };
        let dt_us = now_us.wrapping_sub(t0);
        if dt_us == 0 {
            return Ok(None);
        }
        self.last = Some((pulses, now_us));
        let cal = &self.calibration;
        let dt_s = dt_us as f32 * 1e-6;
        match rolling_speed(
            pulses.wrapping_sub(p0),
            cal.pulses_per_rev,
            cal.radius_m,
            dt_s,
        ) {
            Some(v) if v <= cal.max_speed_m_s => Ok(Some(v)),
            _ => {
                self.counts.record(FaultKind::OutOfRange);
                Err(SensorFault {
                    sensor: SensorId::Speed,
                    kind: FaultKind::OutOfRange,
                })
            }
        }
    }

    /// The calibration in use.
    pub fn calibration(&self) -> SpeedCalibration {
        self.calibration
    }

    /// The faults counted so far.
    pub fn counts(&self) -> SensorFaultCounts {
        self.counts
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speed_of_a_known_rotation() {
        // 100 pulses/rev, 10 revolutions in 2 s, r = 0.1 m: 5 rev/s, V = pi m/s.
        let v = rolling_speed(1000, 100, 0.1, 2.0).unwrap();
        assert!((v - PI).abs() < 1e-6, "{v}");
        assert_eq!(rolling_speed(0, 100, 0.1, 2.0), Some(0.0));
        assert_eq!(rolling_speed(1, 0, 0.1, 2.0), None);
        assert_eq!(rolling_speed(1, 1, 0.1, 0.0), None);
        assert_eq!(rolling_speed(1, 1, 0.1, f32::NAN), None);
        assert_eq!(rolling_speed(u32::MAX, 1, f32::MAX, 1e-30), None);
    }

    #[test]
    fn refused_calibrations() {
        let ok = SpeedCalibration {
            pulses_per_rev: 60,
            radius_m: 0.05,
            max_speed_m_s: 20.0,
        };
        assert!(Tachometer::new(ok).is_ok());
        for bad in [
            SpeedCalibration {
                pulses_per_rev: 0,
                ..ok
            },
            SpeedCalibration {
                radius_m: 0.0,
                ..ok
            },
            SpeedCalibration {
                radius_m: f32::NAN,
                ..ok
            },
            SpeedCalibration {
                max_speed_m_s: f32::INFINITY,
                ..ok
            },
        ] {
            assert_eq!(Tachometer::new(bad), Err(CalibrationError::Value));
        }
    }
}
