//! Sensor faults: which sensor, what kind, how many; and the detector that finds them
//! in raw codes and physical values.

use super::{AdcError, Rails};
// Defined beside the monitor, which names them in its events without the `sensors`
// feature; re-exported here.
pub use crate::sensor_fault::{FaultKind, SensorFault, SensorId};

/// How many faults of each kind one sensor has had (saturating counters).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SensorFaultCounts {
    /// [`FaultKind::Disconnected`].
    pub disconnected: u32,
    /// [`FaultKind::Bus`].
    pub bus: u32,
    /// [`FaultKind::Saturated`].
    pub saturated: u32,
    /// [`FaultKind::Stuck`].
    pub stuck: u32,
    /// [`FaultKind::Jump`].
    pub jump: u32,
    /// [`FaultKind::OutOfRange`].
    pub out_of_range: u32,
}

impl SensorFaultCounts {
    fn slot(&mut self, kind: FaultKind) -> &mut u32 {
        match kind {
            FaultKind::Disconnected => &mut self.disconnected,
            FaultKind::Bus => &mut self.bus,
            FaultKind::Saturated => &mut self.saturated,
            FaultKind::Stuck => &mut self.stuck,
            FaultKind::Jump => &mut self.jump,
            FaultKind::OutOfRange => &mut self.out_of_range,
        }
    }

    /// Counts one fault of `kind`.
    pub fn record(&mut self, kind: FaultKind) {
        let slot = self.slot(kind);
        *slot = slot.saturating_add(1);
    }

    /// The count of `kind`.
    pub fn get(&self, kind: FaultKind) -> u32 {
        let mut copy = *self;
        *copy.slot(kind)
    }

    /// All faults of every kind (saturating).
    pub fn total(&self) -> u32 {
        FaultKind::ALL
            .iter()
            .fold(0u32, |sum, &kind| sum.saturating_add(self.get(kind)))
    }
}

/// The limits a raw code is checked against.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RawLimits {
    /// The ADC's rails: a code at either is [`FaultKind::Saturated`].
    pub rails: Rails,
    /// This many identical codes in a row are [`FaultKind::Stuck`] (0 or 1: never). Set
    /// it where the noise of the signal chain makes a repeat this long implausible.
    pub stuck_after: u16,
    /// A step larger than this many codes between two readings is a
    /// [`FaultKind::Jump`] (`u32::MAX`: never).
    pub max_step: u32,
}

impl RawLimits {
    /// The defaults for an ADC with these rails: stuck after 8 identical codes, a jump
    /// above half the full scale.
    pub const fn new(rails: Rails) -> RawLimits {
        RawLimits {
            rails,
            stuck_after: 8,
            max_step: rails.span() / 2,
        }
    }
}

/// Finds and counts the faults of one sensor in its raw codes and calibrated values.
///
/// It keeps the last code and how often it repeated, so it sees stuck values and
/// jumps; every fault it returns is counted in [`counts`](Self::counts). A constant
/// garbage code inside the rails and the calibrated range (a bus reading all ones that
/// happens to map to a plausible value) cannot be told from a steady signal until it
/// has repeated `stuck_after` times: that many readings is the detection delay.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FaultDetector {
    sensor: SensorId,
    limits: RawLimits,
    last: Option<i32>,
    repeats: u16,
    counts: SensorFaultCounts,
}

impl FaultDetector {
    /// A detector for `sensor` with these limits.
    pub const fn new(sensor: SensorId, limits: RawLimits) -> FaultDetector {
        FaultDetector {
            sensor,
            limits,
            last: None,
            repeats: 0,
            counts: SensorFaultCounts {
                disconnected: 0,
                bus: 0,
                saturated: 0,
                stuck: 0,
                jump: 0,
                out_of_range: 0,
            },
        }
    }

    /// The sensor it watches.
    pub const fn sensor(&self) -> SensorId {
        self.sensor
    }

    /// Its limits.
    pub const fn limits(&self) -> RawLimits {
        self.limits
    }

    /// The faults counted so far.
    pub const fn counts(&self) -> SensorFaultCounts {
        self.counts
    }

    /// Counts a fault of `kind` and returns it.
    pub fn fault(&mut self, kind: FaultKind) -> SensorFault {
        self.counts.record(kind);
        SensorFault {
            sensor: self.sensor,
            kind,
        }
    }

    /// Forgets the code history (after a sensor was replaced or reconnected); the
    /// counts stay.
    pub fn forget(&mut self) {
        self.last = None;
        self.repeats = 0;
    }

    /// Checks one ADC result: a timeout is [`FaultKind::Disconnected`], a bus error
    /// [`FaultKind::Bus`], a code at a rail [`FaultKind::Saturated`], then a step over
    /// `max_step` [`FaultKind::Jump`], then `stuck_after` equal codes
    /// [`FaultKind::Stuck`]. Otherwise the code.
    pub fn raw<E>(&mut self, result: Result<i32, AdcError<E>>) -> Result<i32, SensorFault> {
        let raw = match result {
            Ok(raw) => raw,
            Err(AdcError::Timeout) => return Err(self.fault(FaultKind::Disconnected)),
            Err(AdcError::Bus(_)) => return Err(self.fault(FaultKind::Bus)),
        };
        let previous = self.last.replace(raw);
        self.repeats = match previous {
            Some(p) if p == raw => self.repeats.saturating_add(1),
            _ => 1,
        };
        if self.limits.rails.is_saturated(raw) {
            return Err(self.fault(FaultKind::Saturated));
        }
        if let Some(p) = previous
            && p.abs_diff(raw) > self.limits.max_step
        {
            return Err(self.fault(FaultKind::Jump));
        }
        if self.limits.stuck_after > 1 && self.repeats >= self.limits.stuck_after {
            return Err(self.fault(FaultKind::Stuck));
        }
        Ok(raw)
    }

    /// Checks a calibrated value against the calibrated range `min ..= max` (SI units):
    /// outside it, or not finite, it is [`FaultKind::OutOfRange`].
    pub fn value(&mut self, value: f32, min: f32, max: f32) -> Result<f32, SensorFault> {
        if value.is_finite() && min <= value && value <= max {
            Ok(value)
        } else {
            Err(self.fault(FaultKind::OutOfRange))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn detector(stuck_after: u16) -> FaultDetector {
        let rails = Rails::signed_bits(16).unwrap();
        FaultDetector::new(
            SensorId::Probe1,
            RawLimits {
                stuck_after,
                ..RawLimits::new(rails)
            },
        )
    }

    #[test]
    fn counts_every_kind_in_its_own_field() {
        let mut counts = SensorFaultCounts::default();
        for (i, &kind) in FaultKind::ALL.iter().enumerate() {
            for _ in 0..=i {
                counts.record(kind);
            }
        }
        for (i, &kind) in FaultKind::ALL.iter().enumerate() {
            assert_eq!(counts.get(kind), i as u32 + 1, "{kind:?}");
        }
        assert_eq!(counts.total(), 21);
        let mut full = SensorFaultCounts {
            stuck: u32::MAX,
            ..SensorFaultCounts::default()
        };
        full.record(FaultKind::Stuck);
        assert_eq!(full.stuck, u32::MAX);
    }

    #[test]
    fn noise_passes_and_a_repeat_below_the_limit_passes() {
        let mut d = detector(4);
        for raw in [100, 101, 101, 101, 99, 100] {
            assert_eq!(d.raw::<()>(Ok(raw)), Ok(raw));
        }
        assert_eq!(d.counts().total(), 0);
    }

    #[test]
    fn stuck_after_the_limit_and_clears_on_change() {
        let mut d = detector(3);
        assert!(d.raw::<()>(Ok(7)).is_ok());
        assert!(d.raw::<()>(Ok(7)).is_ok());
        let f = d.raw::<()>(Ok(7)).unwrap_err();
        assert_eq!(f.kind, FaultKind::Stuck);
        assert_eq!(f.sensor, SensorId::Probe1);
        assert_eq!(d.raw::<()>(Ok(8)), Ok(8));
        assert_eq!(d.counts().stuck, 1);
    }

    #[test]
    fn stuck_disabled_by_zero_or_one() {
        for limit in [0, 1] {
            let mut d = detector(limit);
            for _ in 0..100 {
                assert_eq!(d.raw::<()>(Ok(5)), Ok(5));
            }
        }
    }

    #[test]
    fn rails_jumps_and_range() {
        let mut d = detector(8);
        assert_eq!(
            d.raw::<()>(Ok(i16::MAX.into())).unwrap_err().kind,
            FaultKind::Saturated
        );
        assert_eq!(
            d.raw::<()>(Ok(i16::MIN.into())).unwrap_err().kind,
            FaultKind::Saturated
        );
        // Beyond the rails (an ADC driver that returned a wider code) is saturated too.
        assert_eq!(
            d.raw::<()>(Ok(i32::MIN)).unwrap_err().kind,
            FaultKind::Saturated
        );
        // From the rail to -20000, then by 40000 codes to +20000: both more than half
        // the full scale.
        assert_eq!(d.raw::<()>(Ok(-20_000)).unwrap_err().kind, FaultKind::Jump);
        assert_eq!(d.raw::<()>(Ok(20_000)).unwrap_err().kind, FaultKind::Jump);
        assert_eq!(d.raw::<()>(Ok(20_001)), Ok(20_001));
        assert_eq!(
            d.raw(Err(AdcError::<()>::Timeout)).unwrap_err().kind,
            FaultKind::Disconnected
        );
        assert_eq!(
            d.raw(Err(AdcError::Bus(()))).unwrap_err().kind,
            FaultKind::Bus
        );
        assert_eq!(d.value(1.0, 0.0, 2.0), Ok(1.0));
        for bad in [-0.1, 2.1, f32::NAN, f32::INFINITY] {
            assert_eq!(
                d.value(bad, 0.0, 2.0).unwrap_err().kind,
                FaultKind::OutOfRange
            );
        }
        let c = d.counts();
        assert_eq!(
            (c.saturated, c.jump, c.disconnected, c.bus, c.out_of_range),
            (3, 2, 1, 1, 4)
        );
    }

    #[test]
    fn rails_of_widths() {
        assert_eq!(
            Rails::signed_bits(24),
            Some(Rails {
                min: -8_388_608,
                max: 8_388_607
            })
        );
        assert_eq!(
            Rails::signed_bits(32),
            Some(Rails {
                min: i32::MIN,
                max: i32::MAX
            })
        );
        assert_eq!(Rails::signed_bits(32).unwrap().span(), u32::MAX);
        assert_eq!(Rails::signed_bits(1), None);
        assert_eq!(Rails::signed_bits(33), None);
    }
}
