//! The monitor's whole state as one plain `Copy` value of fixed size, to take out
//! and put back (persistence across resets): each stage's state, its buffers as lists.

use super::Monitor;
use super::checks::Checks;
use super::clock::Clock;
use super::config::{Config, ConfigError, SPIKE_WINDOW_CAPACITY, TREND_CAPACITY};
use super::energy::Energy;
use super::events::{EVENT_CAPACITY, Event, EventKind, Reading};
use super::friction::FrictionStatus;
use super::risk::{Alarm, RiskState};
use super::statistics::Statistics;
use super::trend::{TrendInterval, TrendPoint};
use crate::Estimator;

/// A fixed-capacity list as plain data: the first `len` of `items`, oldest first.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Saved<T, const N: usize> {
    /// The items; those past `len` are unused.
    pub(crate) items: [T; N],
    /// How many are used (values above `N` are read as `N`).
    pub(crate) len: u8,
}

impl<T: Copy, const N: usize> Saved<T, N> {
    fn from_iter(fill: T, it: impl Iterator<Item = T>) -> Self {
        let mut items = [fill; N];
        let mut len = 0u8;
        for (slot, x) in items.iter_mut().zip(it) {
            *slot = x;
            len = len.saturating_add(1); // at most N, below 256
        }
        Saved { items, len }
    }

    /// The items used.
    fn as_slice(&self) -> &[T] {
        self.items
            .get(..usize::from(self.len).min(N))
            .unwrap_or(&[])
    }

    fn iter(&self) -> impl Iterator<Item = T> + '_ {
        self.as_slice().iter().copied()
    }
}

pub(crate) const NO_EVENT: Event = Event {
    seq: 0,
    time_ms: 0,
    elapsed_ms: 0,
    kind: EventKind::StateChange {
        from: RiskState::Stopped,
        to: RiskState::Stopped,
        fault: None,
    },
    reading: Reading {
        load: 0.0,
        phi: 0.0,
        slip_ratio: 0.0,
        axial_force: 0.0,
        critical_angle: None,
        margin: None,
    },
};

/// The monitor's whole state: a plain `Copy` value of fixed size with no references,
/// to store (its byte format is its `storage::Checkpoint` implementation, feature
/// `sequential-storage`) and to put back with [`Monitor::restore`] or
/// [`Monitor::resume`]. Undelivered events are part of it. Its parts are the
/// monitor's working state, not API: read it through the accessors below.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MonitorState {
    pub(crate) clock: Clock,
    pub(crate) alarm: Alarm,
    /// The conditioning's smoothed load (N) and angle (rad).
    pub(crate) smoothed: Option<[f32; 2]>,
    pub(crate) checks: Checks,
    pub(crate) trend_interval: TrendInterval,
    pub(crate) time_to_critical_s: Option<f32>,
    pub(crate) approaching_armed: bool,
    pub(crate) next_seq: u32,
    pub(crate) reading: Option<Reading>,
    pub(crate) energy: Energy,
    pub(crate) stats: Statistics,
    pub(crate) friction: FrictionStatus,
    /// The spike filter's load window (N).
    pub(crate) load_window: Saved<f32, SPIKE_WINDOW_CAPACITY>,
    /// The spike filter's angle window (rad).
    pub(crate) angle_window: Saved<f32, SPIKE_WINDOW_CAPACITY>,
    /// The trend's points.
    pub(crate) trend: Saved<TrendPoint, TREND_CAPACITY>,
    /// Undelivered events.
    pub(crate) events: Saved<Event, EVENT_CAPACITY>,
}

impl MonitorState {
    /// The reported state ([`Monitor::state`]).
    pub fn state(&self) -> RiskState {
        self.alarm.state
    }

    /// Monotonic time since the first sample (ms; [`Monitor::elapsed_ms`]).
    pub fn elapsed_ms(&self) -> u64 {
        self.clock.elapsed_ms
    }

    /// The last accepted raw timestamp (ms, the node's wrapping counter), `None` before
    /// the first sample.
    pub fn last_time_ms(&self) -> Option<u32> {
        self.clock.last_time_ms
    }

    /// The statistics ([`Monitor::statistics`]).
    pub fn statistics(&self) -> &Statistics {
        &self.stats
    }

    /// The friction tracker ([`Monitor::friction_status`]).
    pub fn friction_status(&self) -> &FrictionStatus {
        &self.friction
    }

    /// The last valid running reading ([`Monitor::reading`]).
    pub fn reading(&self) -> Option<Reading> {
        self.reading
    }

    /// The latest time to critical (s; [`Monitor::time_to_critical`]).
    pub fn time_to_critical(&self) -> Option<f32> {
        self.time_to_critical_s
    }

    /// The next event's sequence number ([`Monitor::next_event_seq`]).
    pub fn next_event_seq(&self) -> u32 {
        self.next_seq
    }

    /// Undelivered events, oldest first ([`Monitor::pop_event`] delivers them).
    pub fn events(&self) -> &[Event] {
        self.events.as_slice()
    }

    /// The trend's points, oldest first: the mean margin (rad) per interval.
    pub fn trend_points(&self) -> &[TrendPoint] {
        self.trend.as_slice()
    }
}

impl<E: Estimator> Monitor<E> {
    /// The whole state as a plain value.
    pub fn snapshot(&self) -> MonitorState {
        let [load_window, angle_window] = &self.conditioning.windows;
        MonitorState {
            clock: self.clock,
            alarm: self.alarm,
            smoothed: self.conditioning.smoothed,
            checks: self.checks,
            trend_interval: self.trend.interval,
            time_to_critical_s: self.trend.time_to_critical_s,
            approaching_armed: self.events.approaching_armed,
            next_seq: self.events.next_seq,
            reading: self.reading,
            energy: self.energy,
            stats: self.stats,
            friction: self.friction,
            load_window: Saved::from_iter(0.0, load_window.iter()),
            angle_window: Saved::from_iter(0.0, angle_window.iter()),
            trend: Saved::from_iter(TrendPoint::default(), self.trend.points.iter().copied()),
            events: Saved::from_iter(NO_EVENT, self.events.queue.iter().copied()),
        }
    }

    /// A monitor over `estimator` and `config` that goes on from `state`.
    ///
    /// # Errors
    /// The [`ConfigError`] of an inconsistent configuration.
    pub fn restore(
        estimator: E,
        config: Config,
        state: &MonitorState,
    ) -> Result<Self, ConfigError> {
        let mut m = Monitor::new(estimator, config)?;
        m.resume(state);
        Ok(m)
    }

    /// Goes on from `state` (a snapshot of a monitor with this configuration) in
    /// place of whatever this monitor held: [`restore`](Self::restore) without a
    /// second monitor on the stack. With `storage::Store::restore_into` (feature
    /// `sequential-storage`) a node restores its state at start-up holding one monitor
    /// and one state.
    pub fn resume(&mut self, state: &MonitorState) {
        self.clock = state.clock;
        self.alarm = state.alarm;
        self.conditioning.smoothed = state.smoothed;
        self.checks = state.checks;
        self.trend.interval = state.trend_interval;
        self.trend.time_to_critical_s = state.time_to_critical_s;
        self.events.approaching_armed = state.approaching_armed;
        self.events.next_seq = state.next_seq;
        self.reading = state.reading;
        self.energy = state.energy;
        self.stats = state.stats;
        self.friction = state.friction;
        // The buffers were filled from at most their own capacity: the pushes fit.
        let n = self
            .config
            .spikes
            .map_or(SPIKE_WINDOW_CAPACITY, |s| usize::from(s.window));
        for (window, saved) in self
            .conditioning
            .windows
            .iter_mut()
            .zip([&state.load_window, &state.angle_window])
        {
            window.clear();
            for x in saved.iter() {
                window.push_back(x, n);
            }
        }
        self.trend.points.clear();
        for p in state.trend.iter() {
            let _ = self.trend.points.push_back(p);
        }
        self.events.queue.clear();
        for e in state.events.iter() {
            let _ = self.events.queue.push_back(e);
        }
    }
}

/// The state of a monitor that has seen no sample (what [`Monitor::new`] starts
/// from): a place to restore a checkpoint into.
impl Default for MonitorState {
    fn default() -> Self {
        MonitorState {
            clock: Clock::new(),
            alarm: Alarm::new(),
            smoothed: None,
            checks: Checks::new(),
            trend_interval: TrendInterval {
                start_ms: 0,
                sum: 0.0,
                count: 0,
            },
            time_to_critical_s: None,
            approaching_armed: true,
            next_seq: 0,
            reading: None,
            energy: Energy { step_j: 0.0 },
            stats: Statistics::new(),
            friction: FrictionStatus::new(),
            load_window: Saved::from_iter(0.0, core::iter::empty()),
            angle_window: Saved::from_iter(0.0, core::iter::empty()),
            trend: Saved::from_iter(TrendPoint::default(), core::iter::empty()),
            events: Saved::from_iter(NO_EVENT, core::iter::empty()),
        }
    }
}

/// The RAM budget of the monitor's state with the default capacities: the snapshot
/// ([`MonitorState`]) and the live monitor without its estimator and its configuration
/// (the [`Config`] and the limits and levels formed from it once) both fit, on every
/// target (checked when the crate compiles).
pub const STATE_BUDGET_BYTES: usize = 1024;
const _: () = assert!(core::mem::size_of::<MonitorState>() <= STATE_BUDGET_BYTES);
const _: () =
    assert!(core::mem::size_of::<Monitor<()>>() - super::CONFIGURATION_BYTES <= STATE_BUDGET_BYTES);

#[cfg(test)]
mod tests {
    use super::*;

    /// The two sizes the budget bounds (`cargo test --lib monitor::state --
    /// --nocapture`).
    #[test]
    fn state_fits_its_budget() {
        let snapshot = core::mem::size_of::<MonitorState>();
        let live = core::mem::size_of::<Monitor<()>>() - super::super::CONFIGURATION_BYTES;
        std::println!(
            "snapshot {snapshot} bytes, live monitor {live} bytes besides its configuration"
        );
        assert!(snapshot <= STATE_BUDGET_BYTES && live <= STATE_BUDGET_BYTES);
    }
}
