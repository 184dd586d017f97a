//! Risk states with the alarm conventions of ISA-18.2 / IEC 62682: thresholds with a
//! clearing deadband, on-delay, off-delay (minimum dwell), start-up inhibit; a sensor
//! fault is a state of its own and never reported as slip. The stage's state: the
//! state machine ([`Alarm`]).

use super::config::{Config, Thresholds};
use super::order::ge;

/// The roller pair's state as the monitor reports it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RiskState {
    /// Load or speed below the stop thresholds: no alarm, no wear.
    Stopped,
    /// Running with part of the contact sticking, below the warning.
    Normal,
    /// Warning: microslip over most of the contact (d/b at the warning threshold or the
    /// margin to the critical angle small).
    Microslip,
    /// Alarm: gross slip (d/b at the alarm threshold, or no margin left).
    GrossSlip,
    /// The sensors cannot be trusted (non-finite, out of range, stuck, gap, time
    /// backwards, a driver's report, a sample the estimator refused).
    SensorFault,
}

impl RiskState {
    /// Every state, in the order of [`RiskState::index`].
    pub const ALL: [RiskState; 5] = [
        RiskState::Stopped,
        RiskState::Normal,
        RiskState::Microslip,
        RiskState::GrossSlip,
        RiskState::SensorFault,
    ];

    /// The state's index in per-state arrays (0 to 4, the order of [`RiskState::ALL`]).
    pub const fn index(self) -> usize {
        self as usize
    }

    /// A short lower-case name: `stopped`, `normal`, `microslip`, `gross_slip`,
    /// `sensor_fault`.
    pub const fn as_str(self) -> &'static str {
        match self {
            RiskState::Stopped => "stopped",
            RiskState::Normal => "normal",
            RiskState::Microslip => "microslip",
            RiskState::GrossSlip => "gross_slip",
            RiskState::SensorFault => "sensor_fault",
        }
    }

    /// Severity order: Stopped < Normal < Microslip < GrossSlip < SensorFault. A step
    /// up waits the on-delay (a start, Stopped to Normal, none), a step down the
    /// off-delay, a sensor fault the fault delay.
    const fn rank(self) -> u8 {
        self as u8
    }
}

/// The thresholds on one scale growing with risk (d/b, or minus the margin), with
/// their clearing levels less the deadband, formed once for a monitor: the per-sample
/// test only compares.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Levels {
    on_margin: bool,
    warning: f32,
    alarm: f32,
    warning_clear: f32,
    alarm_clear: f32,
}

impl Levels {
    pub(crate) fn new(thresholds: &Thresholds) -> Self {
        let (on_margin, warning, alarm, deadband) = match *thresholds {
            Thresholds::SlipRatio {
                warning,
                alarm,
                deadband,
            } => (false, warning, alarm, deadband),
            Thresholds::Margin {
                warning,
                alarm,
                deadband,
            } => (true, -warning, -alarm, deadband),
        };
        Levels {
            on_margin,
            warning,
            alarm,
            warning_clear: warning - deadband,
            alarm_clear: alarm - deadband,
        }
    }
}

/// The slip level a valid sample asks for, from its d/b or margin, with the deadband
/// on clearing: a level already reached (or passed) holds until the value falls below
/// its threshold less the deadband.
#[inline(always)]
pub(crate) fn slip_level(
    levels: &Levels,
    slip_ratio: f32,
    margin: Option<f32>,
    current: RiskState,
) -> RiskState {
    // No critical angle at this load (elliptic contact at very high load) means no
    // gross slip: -inf.
    let x = if levels.on_margin {
        margin.map_or(f32::NEG_INFINITY, |m| -m)
    } else {
        slip_ratio
    };
    let held = |state: RiskState| current == state || current.rank() > state.rank();
    let gross =
        ge(x, levels.alarm) || (current == RiskState::GrossSlip && ge(x, levels.alarm_clear));
    let micro = ge(x, levels.warning)
        || (held(RiskState::Microslip)
            && current != RiskState::SensorFault
            && ge(x, levels.warning_clear));
    if gross {
        RiskState::GrossSlip
    } else if micro {
        RiskState::Microslip
    } else {
        RiskState::Normal
    }
}

/// The state machine: the current state, since when, and the pending candidate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Alarm {
    /// The reported state.
    pub(crate) state: RiskState,
    /// Monotonic time (ms) the state was entered.
    pub(crate) since_ms: u64,
    /// The state pending and the time (ms) since which every candidate has been it
    /// or beyond it on its side of the reported state (a fault: a fault); see
    /// [`Alarm::offer`].
    pub(crate) pending: Option<(RiskState, u64)>,
    /// Monotonic time (ms) the machine last started (its first running sample since
    /// the monitor started or since the state was `Stopped`): the start-up inhibit runs
    /// from here.
    pub(crate) started_ms: Option<u64>,
}

impl Alarm {
    /// The machine at rest before the first sample.
    pub(crate) const fn new() -> Self {
        Alarm {
            state: RiskState::Stopped,
            since_ms: 0,
            pending: None,
            started_ms: None,
        }
    }

    /// The delay (ms) a candidate must hold before the state moves from `from` to `to`.
    pub(crate) fn delay_ms(config: &Config, from: RiskState, to: RiskState) -> u32 {
        if to == RiskState::SensorFault {
            config.fault_delay_ms
        } else if from == RiskState::Stopped && to == RiskState::Normal {
            // A start is no alarm (the start-up inhibit guards what follows); chatter
            // at the stop load is bounded by the off-delay back to `Stopped`.
            0
        } else if to.rank() > from.rank() {
            config.on_delay_ms
        } else {
            config.off_delay_ms
        }
    }

    /// The level a valid running sample with d/b `slip_ratio` and margin `margin`
    /// (rad) asks for at `now_ms`: its slip level from the reported state, `Normal`
    /// during the start-up inhibit.
    #[inline(always)]
    pub(crate) fn level(
        &self,
        config: &Config,
        levels: &Levels,
        slip_ratio: f32,
        margin: Option<f32>,
        now_ms: u64,
    ) -> RiskState {
        if self.inhibited(config, now_ms) {
            RiskState::Normal
        } else {
            slip_level(levels, slip_ratio, margin, self.state)
        }
    }

    /// Whether the start-up inhibit suppresses warnings and alarms at `now_ms`.
    pub(crate) fn inhibited(&self, config: &Config, now_ms: u64) -> bool {
        self.started_ms
            .is_none_or(|s| now_ms.saturating_sub(s) < u64::from(config.inhibit_ms))
    }

    /// Notes a running sample at `now_ms`: the first since the monitor started or
    /// since the state was `Stopped` starts the start-up inhibit. A stop that is not
    /// reported (shorter than the off-delay) does not restart it, so that a dip of
    /// the load never clears an alarm through the inhibit.
    pub(crate) fn note_running(&mut self, now_ms: u64) {
        if self.started_ms.is_none() {
            self.started_ms = Some(now_ms);
        }
    }

    /// Offers this sample's candidate state at `now_ms`; returns `Some(previous)` when
    /// the state changes.
    ///
    /// Each state is entered only once candidates for it have stood for its own delay,
    /// counted from the first of them: the pending state is the *nearest* one (to the
    /// reported state) of an unbroken run of candidates on one side of it, and the
    /// run's start is its time. A more severe candidate in the run keeps the pending
    /// state (its own run has not lasted the delay; after the nearer state is entered
    /// it waits its own), a less severe one on the same side takes its place and keeps
    /// the start (it has stood since then). A sensor fault is a kind of its own, never
    /// a slip level: a fault candidate breaks a slip run and a slip candidate a fault
    /// run, so that neither lends the other its age. The reported state as candidate
    /// breaks every run.
    pub(crate) fn offer(
        &mut self,
        config: &Config,
        candidate: RiskState,
        now_ms: u64,
    ) -> Option<RiskState> {
        if candidate == self.state {
            self.pending = None;
            return None;
        }
        // The run a candidate belongs to: a fault, or a slip level above or below the
        // reported state (from `SensorFault`, every slip level is below).
        let rank = self.state.rank();
        let run = |s: RiskState| {
            if s == RiskState::SensorFault {
                2u8
            } else {
                u8::from(s.rank() > rank)
            }
        };
        let (candidate, since) = match self.pending {
            Some((p, t)) if run(p) == run(candidate) => {
                // The nearer of the two to the reported state has stood since `t`.
                let nearer = if (p.rank() > rank) == (candidate.rank() > p.rank()) {
                    p
                } else {
                    candidate
                };
                (nearer, t)
            }
            _ => (candidate, now_ms),
        };
        self.pending = Some((candidate, since));
        let age = now_ms.saturating_sub(since);
        let candidate = if age >= u64::from(Self::delay_ms(config, self.state, candidate)) {
            candidate
        } else if self.state == RiskState::Stopped && run(candidate) == 1 {
            // A running candidate is a start, which waits nothing: `Normal` now, the
            // raised state its own on-delay from here.
            RiskState::Normal
        } else {
            return None;
        };
        let previous = self.state;
        self.state = candidate;
        if candidate == RiskState::Stopped {
            // The next start runs the start-up inhibit again.
            self.started_ms = None;
        }
        self.since_ms = now_ms;
        self.pending = None;
        Some(previous)
    }
}
