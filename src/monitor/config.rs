//! The monitor's configuration: one value, validated when the monitor is built. Every
//! stage reads it; it imports nothing from the monitor but `order`'s comparisons.

use super::order::{finite, ge};
use core::fmt;

/// Capacity of the spike filter's window (samples).
pub const SPIKE_WINDOW_CAPACITY: usize = 7;
/// Capacity of the trend buffer (points).
pub const TREND_CAPACITY: usize = 16;

/// How credible the trend's fit must be to give a time to critical: its slope (the
/// margin's drift, rad/s) at least this many of its standard errors below zero, which
/// is the fit's R^2 at least k^2 / (n - 2 + k^2) over n points (0.39 over the 16 of
/// the default window). With 16 points and independent residuals, a margin that does
/// not drift passes about once in 200 fits (Student's t, 14 degrees of freedom).
pub const TREND_SLOPE_STANDARD_ERRORS: f32 = 3.0;

/// What the warning and alarm thresholds are set on.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Thresholds {
    /// On the slip ratio d/b (eq 16; eq 23 for line contact): the warning (microslip
    /// over most of the contact) at `warning`, the alarm (gross slip) at `alarm`; a
    /// raised state clears only below its threshold minus `deadband`.
    SlipRatio {
        /// d/b at which `Microslip` is raised (default 0.8).
        warning: f32,
        /// d/b at which `GrossSlip` is raised (default 1.0).
        alarm: f32,
        /// Clearing deadband in d/b (default 0.05).
        deadband: f32,
    },
    /// On the margin `phi0 - |phi|` to the critical angle (rad): the warning when the
    /// margin is at or below `warning`, the alarm at or below `alarm` (0: gross slip);
    /// a raised state clears only above its threshold plus `deadband`.
    Margin {
        /// Margin (rad) at which `Microslip` is raised.
        warning: f32,
        /// Margin (rad) at which `GrossSlip` is raised.
        alarm: f32,
        /// Clearing deadband (rad).
        deadband: f32,
    },
}

impl Thresholds {
    /// From its kind as records and registers store it (0 on the slip ratio, 1 on the
    /// margin) and its three values; `None` for another kind.
    #[cfg(any(feature = "sequential-storage", feature = "modbus"))]
    pub(crate) const fn from_kind(
        kind: u32,
        warning: f32,
        alarm: f32,
        deadband: f32,
    ) -> Option<Self> {
        match kind {
            0 => Some(Thresholds::SlipRatio {
                warning,
                alarm,
                deadband,
            }),
            1 => Some(Thresholds::Margin {
                warning,
                alarm,
                deadband,
            }),
            _ => None,
        }
    }
}

/// Spike rejection: a Hampel test over the last `window` values of load and angle.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SpikeFilter {
    /// Window length (samples, 3 to [`SPIKE_WINDOW_CAPACITY`]).
    pub window: u8,
    /// A value is a spike when it is further than `k` scaled median absolute
    /// deviations (1.4826 MAD) plus the floor from the window's median.
    pub k: f32,
    /// Absolute floor of the load test (N): noise below it is never a spike.
    pub load_floor: f32,
    /// Absolute floor of the angle test (rad).
    pub angle_floor: f32,
}

/// Time to critical: the least-squares trend of the margin.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TrendConfig {
    /// One trend point (the mean margin) every this many ms.
    pub interval_ms: u32,
    /// Points in the fit (3 to [`TREND_CAPACITY`]): the window is
    /// `points * interval_ms`.
    pub points: u8,
    /// An `Approaching` event when the time to critical falls below this (s).
    pub horizon_s: f32,
}

/// The monitor's configuration (SI units; times in ms). [`Config::default`] suits the
/// demo scene: two steel rollers of 50 mm radius, G = 79.3 GPa, nu = 0.3, mu = 0.3,
/// loaded with about 1 to 5 kN, sampled about once a second, whose load varies over
/// tens of minutes (the trend's window, 80 min, spans such a cycle).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    /// Warning and alarm thresholds with their deadband.
    pub thresholds: Thresholds,
    /// On-delay: a more severe slip state must be asked for by every sample for this
    /// long before it is entered (ms), counted from the first sample that asks for it
    /// or for a state beyond it; a start (`Stopped` to `Normal`) is entered at once.
    /// A sensor fault's time never counts toward it.
    pub on_delay_ms: u32,
    /// Off-delay: a less severe state (or the end of a sensor fault) must be asked for
    /// this long before it is entered (ms), counted the same way; the minimum dwell in
    /// a raised state.
    pub off_delay_ms: u32,
    /// Delay before a sensor fault is reported (ms; 0: at once), counted from the
    /// first of an unbroken run of faulted samples. Slip's time never counts toward
    /// it, nor its toward slip.
    pub fault_delay_ms: u32,
    /// Start-up inhibit: no warning or alarm for this long after the machine starts
    /// (first sample or leaving `Stopped`) (ms).
    pub inhibit_ms: u32,
    /// Below this load (N) the machine stands: `Stopped`, no alarm, no wear. > 0.
    pub stop_load: f32,
    /// Below this measured speed (m/s) the machine stands.
    pub stop_speed: f32,
    /// Rolling speed (m/s) for the wear integral when the sample has none.
    pub nominal_speed: f32,
    /// Lowest accepted load (N; a load cell reads a little below zero at rest).
    pub load_min: f32,
    /// Highest accepted load (N).
    pub load_max: f32,
    /// Highest accepted |phi| (rad).
    pub angle_max: f32,
    /// Highest accepted speed (m/s).
    pub speed_max: f32,
    /// Highest accepted |F| of a measured axial force (N).
    pub force_max: f32,
    /// Spike rejection; `None`: off.
    pub spikes: Option<SpikeFilter>,
    /// Time constant (s) of the exponential smoothing of load and angle, whose
    /// weight `1 - exp(-dt / tau)` follows the real time step; 0: off.
    pub smoothing_tau_s: f32,
    /// A raw load or angle exactly unchanged while running for longer than this is a
    /// stuck sensor (ms); 0: off.
    pub stuck_ms: u32,
    /// A step between samples longer than this is a gap (dropout) (ms); 0: off.
    pub gap_ms: u32,
    /// Time to critical; `None`: off.
    pub trend: Option<TrendConfig>,
    /// Friction tracking from a measured axial force (f32 scenes, through
    /// [`Monitor::process_with_friction`](super::Monitor::process_with_friction));
    /// `None`: off.
    pub friction: Option<FrictionConfig>,
}

/// How mu is tracked: which answers count, the filter, the baseline and the band.
/// Times in ms or s as named; mu is dimensionless.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrictionConfig {
    /// An exact mu counts only when its sensitivity `d ln mu / d ln F` is at most this
    /// (> 0): near the no-slip limit a small error in F is a large one in mu. (Lower
    /// bounds, where F saturates in gross slip, and inconsistent answers never count.)
    pub sensitivity_max: f32,
    /// Time constant (s, > 0) of the exponential filter of mu, whose weight
    /// `1 - exp(-dt / tau)` follows the time step of the sample, like the smoothing of
    /// load and angle.
    pub tau_s: f32,
    /// The baseline is captured once the machine has run this long (ms, from its start,
    /// as the start-up inhibit) ...
    pub baseline_after_ms: u32,
    /// ... and at least this many estimates were accepted (>= 1).
    pub baseline_after_estimates: u32,
    /// The relative band around the baseline (> 0): a change is raised when
    /// `|mu / baseline - 1| > band`.
    pub band: f32,
    /// The change clears when `|mu / baseline - 1| < band - deadband` (0 <= deadband <
    /// band).
    pub deadband: f32,
    /// Raising and clearing wait until the filtered mu has stayed on the other side for
    /// this long (ms), counted over the accepted samples' time steps.
    pub delay_ms: u32,
}

impl Default for FrictionConfig {
    /// For the demo scene sampled about once a second: exact answers with a
    /// sensitivity up to 10, a 60 s filter, the baseline after 10 minutes of running
    /// and 100 accepted estimates, a band of 20 % with 5 % deadband, 60 s delay.
    fn default() -> Self {
        FrictionConfig {
            sensitivity_max: 10.0,
            tau_s: 60.0,
            baseline_after_ms: 600_000,
            baseline_after_estimates: 100,
            band: 0.2,
            deadband: 0.05,
            delay_ms: 60_000,
        }
    }
}

impl FrictionConfig {
    /// Whether the values are consistent (see the fields).
    #[inline(always)]
    pub(crate) fn is_valid(&self) -> bool {
        positive(self.sensitivity_max)
            && positive(self.tau_s)
            && self.baseline_after_estimates >= 1
            && positive(self.band)
            && non_negative(self.deadband)
            && below(self.deadband, self.band)
    }
}

impl Default for Config {
    fn default() -> Self {
        Config {
            thresholds: Thresholds::SlipRatio {
                warning: 0.8,
                alarm: 1.0,
                deadband: 0.05,
            },
            on_delay_ms: 5_000,
            off_delay_ms: 30_000,
            fault_delay_ms: 0,
            inhibit_ms: 60_000,
            stop_load: 100.0,
            stop_speed: 0.1,
            nominal_speed: 2.0,
            load_min: -200.0,
            load_max: 50_000.0,
            angle_max: 0.05,
            speed_max: 50.0,
            force_max: 50_000.0,
            spikes: Some(SpikeFilter {
                window: 7,
                k: 4.0,
                load_floor: 100.0,
                angle_floor: 2e-5,
            }),
            smoothing_tau_s: 3.0,
            stuck_ms: 120_000,
            gap_ms: 10_000,
            trend: Some(TrendConfig {
                interval_ms: 300_000,
                points: 16,
                horizon_s: 3_600.0,
            }),
            friction: Some(FrictionConfig::default()),
        }
    }
}

/// Why a configuration was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum ConfigError {
    /// A threshold is not finite (or a d/b threshold not positive).
    Threshold,
    /// The warning is not before the alarm (d/b: warning >= alarm; margin:
    /// warning <= alarm).
    WarningAboveAlarm,
    /// The deadband is negative, not finite, or so wide that a warning would never
    /// clear (at least the warning threshold itself on d/b).
    Deadband,
    /// The stop load is not positive and finite, or the stop speed negative.
    Stop,
    /// The nominal speed is not positive and finite.
    NominalSpeed,
    /// An accepted range is empty or not finite.
    Range,
    /// The spike window is outside 3..=[`SPIKE_WINDOW_CAPACITY`], or its k or floors
    /// are not positive and finite.
    SpikeWindow,
    /// The smoothing time constant is negative or not finite.
    Smoothing,
    /// The trend has a zero interval, points outside 3..=[`TREND_CAPACITY`], or a
    /// horizon that is not positive and finite.
    Trend,
    /// Friction tracking with a sensitivity cap, time constant or band that is not
    /// positive and finite, a deadband outside `0..band`, or a baseline after no
    /// estimate.
    Friction,
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ConfigError::Threshold => "thresholds must be finite (d/b thresholds positive)",
            ConfigError::WarningAboveAlarm => "the warning threshold must come before the alarm",
            ConfigError::Deadband => "deadband must be finite, >= 0 and below the warning",
            ConfigError::Stop => "stop load must be > 0 and stop speed >= 0, finite",
            ConfigError::NominalSpeed => "nominal speed must be finite and > 0",
            ConfigError::Range => "accepted ranges must be finite and non-empty",
            ConfigError::SpikeWindow => "spike window must be 3..=7 with k, floors > 0",
            ConfigError::Smoothing => "smoothing time constant must be finite and >= 0",
            ConfigError::Trend => "trend needs interval > 0, 3..=16 points, horizon > 0",
            ConfigError::Friction => {
                "friction needs sensitivity cap, tau, band > 0, 0 <= deadband < band, >= 1 estimate"
            }
        })
    }
}

impl core::error::Error for ConfigError {}

// The checks compare by the bits where floats are soft (`order`): a node without an
// FPU links no soft-float comparison for them. Each operand is finite where two are
// compared (checked first), so that the order's answer is the float comparison's.

/// Finite and above zero.
#[inline(always)]
fn positive(x: f32) -> bool {
    finite(x) && !ge(0.0, x)
}

/// Finite and at least zero (-0 included).
#[inline(always)]
fn non_negative(x: f32) -> bool {
    finite(x) && ge(x, 0.0)
}

/// `a < b` for values that are not NaN.
#[inline(always)]
fn below(a: f32, b: f32) -> bool {
    !ge(a, b)
}

impl Config {
    /// Checks that the configuration is consistent.
    ///
    /// # Errors
    /// The first [`ConfigError`] found.
    pub fn validate(&self) -> Result<(), ConfigError> {
        match self.thresholds {
            Thresholds::SlipRatio {
                warning,
                alarm,
                deadband,
            } => {
                if !(positive(warning) && positive(alarm)) {
                    return Err(ConfigError::Threshold);
                }
                if ge(warning, alarm) {
                    return Err(ConfigError::WarningAboveAlarm);
                }
                if !(non_negative(deadband) && below(deadband, warning)) {
                    return Err(ConfigError::Deadband);
                }
            }
            Thresholds::Margin {
                warning,
                alarm,
                deadband,
            } => {
                if !(finite(warning) && finite(alarm)) {
                    return Err(ConfigError::Threshold);
                }
                if ge(alarm, warning) {
                    return Err(ConfigError::WarningAboveAlarm);
                }
                if !non_negative(deadband) {
                    return Err(ConfigError::Deadband);
                }
            }
        }
        if !(positive(self.stop_load) && non_negative(self.stop_speed)) {
            return Err(ConfigError::Stop);
        }
        if !positive(self.nominal_speed) {
            return Err(ConfigError::NominalSpeed);
        }
        let range_ok = finite(self.load_min)
            && finite(self.load_max)
            && below(self.load_min, self.load_max)
            && below(self.stop_load, self.load_max)
            && positive(self.angle_max)
            && positive(self.speed_max)
            && positive(self.force_max);
        if !range_ok {
            return Err(ConfigError::Range);
        }
        if let Some(s) = self.spikes {
            let window_ok = (3..=SPIKE_WINDOW_CAPACITY).contains(&usize::from(s.window));
            if !(window_ok && positive(s.k) && positive(s.load_floor) && positive(s.angle_floor)) {
                return Err(ConfigError::SpikeWindow);
            }
        }
        if !non_negative(self.smoothing_tau_s) {
            return Err(ConfigError::Smoothing);
        }
        if let Some(t) = self.trend {
            let points_ok = (3..=TREND_CAPACITY).contains(&usize::from(t.points));
            if !(t.interval_ms > 0 && points_ok && positive(t.horizon_s)) {
                return Err(ConfigError::Trend);
            }
        }
        if let Some(f) = &self.friction
            && !f.is_valid()
        {
            return Err(ConfigError::Friction);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The checks as float comparisons (what `validate` compares by the bits).
    fn validate_by_floats(c: &Config) -> Result<(), ConfigError> {
        let positive = |x: f32| x.is_finite() && x > 0.0;
        let non_negative = |x: f32| x.is_finite() && x >= 0.0;
        match c.thresholds {
            Thresholds::SlipRatio {
                warning,
                alarm,
                deadband,
            } => {
                if !(positive(warning) && positive(alarm)) {
                    return Err(ConfigError::Threshold);
                }
                if warning >= alarm {
                    return Err(ConfigError::WarningAboveAlarm);
                }
                if !(non_negative(deadband) && deadband < warning) {
                    return Err(ConfigError::Deadband);
                }
            }
            Thresholds::Margin {
                warning,
                alarm,
                deadband,
            } => {
                if !(warning.is_finite() && alarm.is_finite()) {
                    return Err(ConfigError::Threshold);
                }
                if warning <= alarm {
                    return Err(ConfigError::WarningAboveAlarm);
                }
                if !non_negative(deadband) {
                    return Err(ConfigError::Deadband);
                }
            }
        }
        if !(positive(c.stop_load) && non_negative(c.stop_speed)) {
            return Err(ConfigError::Stop);
        }
        if !positive(c.nominal_speed) {
            return Err(ConfigError::NominalSpeed);
        }
        if !(c.load_min.is_finite()
            && c.load_max.is_finite()
            && c.load_min < c.load_max
            && c.load_max > c.stop_load
            && positive(c.angle_max)
            && positive(c.speed_max)
            && positive(c.force_max))
        {
            return Err(ConfigError::Range);
        }
        if let Some(s) = c.spikes
            && !((3..=7).contains(&s.window)
                && positive(s.k)
                && positive(s.load_floor)
                && positive(s.angle_floor))
        {
            return Err(ConfigError::SpikeWindow);
        }
        if !non_negative(c.smoothing_tau_s) {
            return Err(ConfigError::Smoothing);
        }
        if let Some(t) = c.trend
            && !(t.interval_ms > 0 && (3..=16).contains(&t.points) && positive(t.horizon_s))
        {
            return Err(ConfigError::Trend);
        }
        if let Some(f) = c.friction
            && !(positive(f.sensitivity_max)
                && positive(f.tau_s)
                && f.baseline_after_estimates >= 1
                && positive(f.band)
                && non_negative(f.deadband)
                && f.deadband < f.band)
        {
            return Err(ConfigError::Friction);
        }
        Ok(())
    }

    /// Every f32 of the configuration, set to each of the values where float and bit
    /// comparisons could part (zeros of both signs, NaN of both signs, infinities,
    /// subnormals, the extremes), alone and paired with each other f32 compared with
    /// it, from the defaults under both kinds of thresholds: the same answer as the
    /// float comparisons.
    #[test]
    fn validate_compares_as_floats_do() {
        let edges = [
            0.0,
            -0.0,
            f32::NAN,
            -f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::from_bits(1),
            -f32::from_bits(1),
            f32::MIN_POSITIVE,
            f32::MAX,
            f32::MIN,
            0.05,
            0.8,
            1.0,
            -1.0,
            2e3,
        ];
        type Set = fn(&mut Config, f32);
        fn thresholds(c: &mut Config, i: usize, x: f32) {
            let (Thresholds::SlipRatio {
                warning,
                alarm,
                deadband,
            }
            | Thresholds::Margin {
                warning,
                alarm,
                deadband,
            }) = &mut c.thresholds;
            *[warning, alarm, deadband].into_iter().nth(i).unwrap() = x;
        }
        let fields: [Set; 21] = [
            |c, x| thresholds(c, 0, x),
            |c, x| thresholds(c, 1, x),
            |c, x| thresholds(c, 2, x),
            |c, x| c.stop_load = x,
            |c, x| c.stop_speed = x,
            |c, x| c.nominal_speed = x,
            |c, x| c.load_min = x,
            |c, x| c.load_max = x,
            |c, x| c.angle_max = x,
            |c, x| c.speed_max = x,
            |c, x| c.force_max = x,
            |c, x| c.smoothing_tau_s = x,
            |c, x| c.spikes.as_mut().unwrap().k = x,
            |c, x| c.spikes.as_mut().unwrap().load_floor = x,
            |c, x| c.spikes.as_mut().unwrap().angle_floor = x,
            |c, x| c.trend.as_mut().unwrap().horizon_s = x,
            |c, x| c.friction.as_mut().unwrap().sensitivity_max = x,
            |c, x| c.friction.as_mut().unwrap().tau_s = x,
            |c, x| c.friction.as_mut().unwrap().band = x,
            |c, x| c.friction.as_mut().unwrap().deadband = x,
            |c, _| c.friction = None,
        ];
        // The fields compared with each other (indices into `fields`).
        let pairs = [(0, 1), (0, 2), (3, 7), (6, 7), (18, 19)];
        let d = Config {
            friction: Some(FrictionConfig::default()),
            ..Config::default()
        };
        let margin = Config {
            thresholds: Thresholds::Margin {
                warning: 1e-4,
                alarm: 0.0,
                deadband: 1e-5,
            },
            ..d
        };
        let mut checked = 0;
        for base in [d, margin] {
            assert_eq!(base.validate(), Ok(()));
            for set in fields {
                for x in edges {
                    let mut c = base;
                    set(&mut c, x);
                    assert_eq!(c.validate(), validate_by_floats(&c), "{c:?}");
                    checked += 1;
                }
            }
            for (i, j) in pairs {
                for x in edges {
                    for y in edges {
                        let mut c = base;
                        fields[i](&mut c, x);
                        fields[j](&mut c, y);
                        assert_eq!(c.validate(), validate_by_floats(&c), "{c:?}");
                        checked += 1;
                    }
                }
            }
        }
        assert_eq!(checked, 2 * (21 + 5 * 16) * 16);
    }
}
