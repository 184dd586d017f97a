//! The checks stage: whether a sample can be trusted (a sensor's or driver's report,
//! every value finite and in its range, no value stuck, no gap) and whether the
//! machine runs. Its state: since when each raw value of load and angle is unchanged.

use super::config::Config;
use super::events::FaultCause;
use super::order::{AtLeast, Range, finite};
use super::sample::{Channel, Sample};

/// The configuration's limits as the per-sample checks compare them, formed once.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Limits {
    load: Range,
    angle: Range,
    speed: Range,
    force: Range,
    stop_load: AtLeast,
    stop_speed: AtLeast,
    nominal_speed: f32,
    /// The gap (ms); `u32::MAX`, never exceeded, when off.
    gap_ms: u32,
    stuck_ms: u32,
}

impl Limits {
    pub(crate) fn new(config: &Config) -> Self {
        Limits {
            load: Range::new(config.load_min, config.load_max),
            angle: Range::new(-config.angle_max, config.angle_max),
            speed: Range::new(0.0, config.speed_max),
            force: Range::new(-config.force_max, config.force_max),
            stop_load: AtLeast::new(config.stop_load),
            stop_speed: AtLeast::new(config.stop_speed),
            nominal_speed: config.nominal_speed,
            gap_ms: if config.gap_ms > 0 {
                config.gap_ms
            } else {
                u32::MAX
            },
            stuck_ms: config.stuck_ms,
        }
    }

    /// Whether load and angle values are within the accepted ranges (N, rad): what the
    /// conditioning's windows and smoothing can hold, made of accepted values only.
    pub(crate) fn accepts(
        &self,
        loads: impl IntoIterator<Item = f32>,
        angles: impl IntoIterator<Item = f32>,
    ) -> bool {
        loads.into_iter().all(|x| self.load.contains(x))
            && angles.into_iter().all(|x| self.angle.contains(x))
    }

    /// The first fault of a sample that failed the checks at speed `speed`: a
    /// sensor's report, a driver's, then load, angle, speed and axial force, each
    /// non-finite or out of range.
    #[cold]
    #[inline(never)]
    fn cause(&self, sample: &Sample, speed: f32) -> FaultCause {
        if let Some(f) = sample.sensor_fault {
            return FaultCause::Sensor(f);
        }
        if let Some(c) = sample.driver_fault {
            return FaultCause::Driver(c);
        }
        let force = sample.axial_force.unwrap_or(0.0);
        let checks = [
            (sample.load, &self.load, Channel::Load),
            (sample.phi, &self.angle, Channel::Angle),
            (speed, &self.speed, Channel::Speed),
            (force, &self.force, Channel::AxialForce),
        ];
        for (x, range, channel) in checks {
            if !range.contains(x) {
                return if finite(x) {
                    FaultCause::OutOfRange(channel)
                } else {
                    FaultCause::NonFinite(channel)
                };
            }
        }
        // Not reached: the sample failed one of the checks above.
        FaultCause::Estimator
    }
}

/// Stuck-value tracking of one channel: the raw bits and since when they are unchanged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct StuckTracker {
    /// Bits of the last raw value.
    pub(crate) bits: u32,
    /// Monotonic time (ms) since which the value is unchanged.
    pub(crate) since_ms: u64,
}

impl StuckTracker {
    /// Whether the raw value `x` has been unchanged for longer than `limit_ms` at
    /// monotonic time `now_ms`. `reset` restarts the tracking (the machine stands).
    pub(crate) fn stuck(&mut self, x: f32, now_ms: u64, limit_ms: u32, reset: bool) -> bool {
        let bits = x.to_bits();
        if reset || bits != self.bits {
            self.bits = bits;
            self.since_ms = now_ms;
            return false;
        }
        limit_ms > 0 && now_ms.saturating_sub(self.since_ms) > u64::from(limit_ms)
    }
}

/// What the checks found: the sample's fault, if any, its speed (m/s; the nominal one
/// when it has none), and whether the machine runs.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Checked {
    pub(crate) fault: Option<FaultCause>,
    pub(crate) speed: f32,
    pub(crate) running: bool,
}

/// The stage's state: stuck tracking of load and angle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Checks {
    pub(crate) stuck: [StuckTracker; 2],
}

impl Checks {
    pub(crate) const fn new() -> Self {
        Checks {
            stuck: [StuckTracker {
                bits: 0,
                since_ms: 0,
            }; 2],
        }
    }

    /// Checks `sample` after a step of `dt_ms` at monotonic time `now` (ms); `fault` is
    /// the clock's (time backwards), which wins over the sensor checks but not over a
    /// gap. The first fault found wins.
    #[inline(always)]
    pub(crate) fn check(
        &mut self,
        limits: &Limits,
        sample: &Sample,
        dt_ms: u32,
        now: u64,
        mut fault: Option<FaultCause>,
    ) -> Checked {
        if dt_ms > limits.gap_ms {
            fault = Some(FaultCause::Gap);
        }
        // Sensor checks: one pass of comparisons on the usual path; which check
        // failed is found only for a faulty sample.
        let speed = sample.speed.unwrap_or(limits.nominal_speed);
        let valid = sample.sensor_fault.is_none()
            && sample.driver_fault.is_none()
            && limits.load.contains(sample.load)
            && limits.angle.contains(sample.phi)
            && limits.speed.contains(speed)
            && sample.axial_force.is_none_or(|f| limits.force.contains(f));
        if !valid && fault.is_none() {
            fault = Some(limits.cause(sample, speed));
        }
        let running = limits.stop_load.reached(sample.load) && limits.stop_speed.reached(speed);
        if fault.is_none() && limits.stuck_ms > 0 {
            let (limit, reset) = (limits.stuck_ms, !running);
            let load_stuck = self.stuck[0].stuck(sample.load, now, limit, reset);
            let angle_stuck = self.stuck[1].stuck(sample.phi, now, limit, reset);
            if load_stuck {
                fault = Some(FaultCause::Stuck(Channel::Load));
            } else if angle_stuck {
                fault = Some(FaultCause::Stuck(Channel::Angle));
            }
        }
        Checked {
            fault,
            speed,
            running,
        }
    }
}
