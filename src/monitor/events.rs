//! The events stage: every state change, `Approaching` warning and friction change,
//! numbered, in a fixed-capacity queue that drops the oldest when full and counts what
//! it dropped. Its state: the queue, the next sequence number, whether the
//! `Approaching` warning is armed.

use super::config::TrendConfig;
use super::order::ge;
use super::risk::RiskState;
use crate::sensor_fault::SensorFault;
use core::fmt;
use heapless::Deque;

/// Capacity of the event queue.
pub const EVENT_CAPACITY: usize = 6;

/// Why the sensors were not trusted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FaultCause {
    /// A value is NaN or infinite.
    NonFinite(super::Channel),
    /// A value is outside the configured range.
    OutOfRange(super::Channel),
    /// A raw value unchanged for longer than configured.
    Stuck(super::Channel),
    /// No sample for longer than configured.
    Gap,
    /// The timestamp went backwards (a counter reset, not a wrap).
    TimeBackwards,
    /// A sensor driver reported a fault on the channel.
    Driver(super::Channel),
    /// The estimator refused the sample (outside the prepared scene's range).
    Estimator,
    /// A sensor's own fault detection refused its reading: the sensor (load cell,
    /// probe 1 or 2, tachometer) and the reason (disconnected, bus error, saturated,
    /// stuck, a jump, out of the calibrated range). Never a slip alarm.
    Sensor(SensorFault),
}

impl fmt::Display for FaultCause {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let channel = |c: &super::Channel| match c {
            super::Channel::Load => "load",
            super::Channel::Angle => "angle",
            super::Channel::Speed => "speed",
            super::Channel::AxialForce => "axial force",
        };
        match self {
            FaultCause::NonFinite(c) => write!(f, "{}: not finite", channel(c)),
            FaultCause::OutOfRange(c) => write!(f, "{}: out of the accepted range", channel(c)),
            FaultCause::Stuck(c) => write!(f, "{}: stuck", channel(c)),
            FaultCause::Gap => f.write_str("gap: no sample for too long"),
            FaultCause::TimeBackwards => f.write_str("timestamp went backwards"),
            FaultCause::Driver(c) => write!(f, "{}: the driver reported a fault", channel(c)),
            FaultCause::Estimator => f.write_str("the estimator refused the sample"),
            FaultCause::Sensor(s) => write!(f, "{s}"),
        }
    }
}

/// The values behind an event: the last valid estimate (for a `SensorFault` event,
/// the one before the fault; all zero when there was none yet). SI units.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Reading {
    /// Conditioned load P (N).
    pub load: f32,
    /// Conditioned misalignment phi (rad).
    pub phi: f32,
    /// Slip ratio d/b (eq 16; eq 23 for line contact).
    pub slip_ratio: f32,
    /// Axial force F (N; eq 21, 27, 29), measured when the sample carries one.
    pub axial_force: f32,
    /// Critical angle phi0 at this load (rad), if one exists.
    pub critical_angle: Option<f32>,
    /// Margin `phi0 - |phi|` (rad).
    pub margin: Option<f32>,
}

/// What happened.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum EventKind {
    /// The state changed.
    StateChange {
        /// The state left.
        from: RiskState,
        /// The state entered.
        to: RiskState,
        /// For a change to `SensorFault`, the fault that caused it.
        fault: Option<FaultCause>,
    },
    /// Gross slip predicted: the trend's fit of the margin is above zero at its newest
    /// point, falls by at least
    /// [`TREND_SLOPE_STANDARD_ERRORS`](super::TREND_SLOPE_STANDARD_ERRORS) of its
    /// standard errors, and crosses zero ahead of this sample sooner than the
    /// configured horizon, while the contact still sticks (`Normal` or `Microslip`).
    Approaching {
        /// Estimated time until gross slip at the current drift (s), from this
        /// sample: the fit's time to critical less the time since the fit.
        time_to_critical_s: f32,
    },
    /// The filtered friction coefficient left the band around its baseline
    /// (`changed`), or came back within it (`!changed`): lubrication or contamination.
    /// The baseline is [`Monitor::friction_baseline`](super::Monitor::friction_baseline).
    Friction {
        /// The filtered mu.
        mu: f32,
        /// Whether the change is raised (false: cleared).
        changed: bool,
    },
    /// The node's fieldbus link, not the machine: raised by the application's
    /// fieldbus server ([`Monitor::raise_fieldbus`](super::Monitor::raise_fieldbus)),
    /// numbered and kept with the monitor's own events; its reading is the monitor's
    /// last.
    Fieldbus(FieldbusEvent),
}

/// What happened on the fieldbus link ([`EventKind::Fieldbus`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FieldbusEvent {
    /// A change of the line settings went back to the settings before it: no master
    /// confirmed it within its window.
    LineReverted,
    /// No request for this node within the bus timeout: the master is lost.
    MasterLost,
    /// A request for this node came after the master was lost.
    MasterBack,
}

impl FieldbusEvent {
    /// Its name in an events file (the monitor example's `--events` kind column).
    pub const fn as_str(self) -> &'static str {
        match self {
            FieldbusEvent::LineReverted => "line_reverted",
            FieldbusEvent::MasterLost => "master_lost",
            FieldbusEvent::MasterBack => "master_back",
        }
    }
}

/// One event. Sequence numbers are consecutive from 0, so a consumer sees a dropped
/// event as a gap; [`Statistics::events_dropped`](super::Statistics::events_dropped)
/// counts them.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Event {
    /// Sequence number (consecutive, from 0).
    pub seq: u32,
    /// The sample's raw timestamp (ms, the node's wrapping counter).
    pub time_ms: u32,
    /// Monotonic time since the first sample (ms).
    pub elapsed_ms: u64,
    /// What happened.
    pub kind: EventKind,
    /// The values that caused it.
    pub reading: Reading,
}

/// The queue: a heapless deque; full, it drops its oldest event (the newest say what
/// holds now; the sequence gap and the counter say what was lost).
pub(crate) type EventQueue = Deque<Event, EVENT_CAPACITY>;

/// The stage's state.
#[derive(Debug, Clone)]
pub(crate) struct Events {
    /// Undelivered events, oldest first.
    pub(crate) queue: EventQueue,
    /// The next event's sequence number.
    pub(crate) next_seq: u32,
    /// Whether the next fall of the time to critical below the horizon raises an
    /// `Approaching` event.
    pub(crate) approaching_armed: bool,
}

impl Events {
    pub(crate) const fn new() -> Self {
        Events {
            queue: EventQueue::new(),
            next_seq: 0,
            approaching_armed: true,
        }
    }

    /// Whether the `Approaching` warning is due, at the time to critical
    /// `time_to_critical_s` (s) of the trend `trend`, fitted `fit_age_s()` seconds ago,
    /// with the state `state` reported: once when it falls below the horizon while the
    /// contact still sticks and the fit's crossing still lies ahead; re-armed above 1.5
    /// horizons. Returns the time left until the crossing, to report.
    #[inline(always)]
    pub(crate) fn approaching(
        &mut self,
        trend: Option<TrendConfig>,
        time_to_critical_s: Option<f32>,
        fit_age_s: impl FnOnce() -> f32,
        state: RiskState,
    ) -> Option<f32> {
        if time_to_critical_s.is_none() && self.approaching_armed {
            return None;
        }
        self.approaching_check(trend?, time_to_critical_s, fit_age_s, state)
    }

    fn approaching_check(
        &mut self,
        tc: TrendConfig,
        time_to_critical_s: Option<f32>,
        fit_age_s: impl FnOnce() -> f32,
        state: RiskState,
    ) -> Option<f32> {
        match time_to_critical_s {
            Some(t) if !ge(t, tc.horizon_s) => {
                let live = matches!(state, RiskState::Normal | RiskState::Microslip);
                if self.approaching_armed && live {
                    // The fit predicts from its newest point: a crossing that has
                    // passed since predicts nothing (the warning stays armed).
                    let left = t - fit_age_s();
                    if ge(0.0, left) {
                        return None;
                    }
                    self.approaching_armed = false;
                    return Some(left);
                }
            }
            Some(t) if !ge(t, 1.5 * tc.horizon_s) => {}
            _ => self.approaching_armed = true,
        }
        None
    }

    /// Appends the event `kind` of the sample stamped `time_ms` at monotonic time
    /// `elapsed_ms`, with the latest reading; full, the queue drops its oldest.
    /// Returns whether it dropped one.
    pub(crate) fn emit(
        &mut self,
        kind: EventKind,
        time_ms: u32,
        elapsed_ms: u64,
        reading: Option<Reading>,
    ) -> bool {
        let event = Event {
            seq: self.next_seq,
            time_ms,
            elapsed_ms,
            kind,
            reading: reading.unwrap_or_default(),
        };
        self.next_seq = self.next_seq.wrapping_add(1);
        let dropped = self.queue.is_full();
        if dropped {
            self.queue.pop_front();
        }
        // Not full after the pop above.
        let _ = self.queue.push_back(event);
        dropped
    }
}
