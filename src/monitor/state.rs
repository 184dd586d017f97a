//! The monitor's whole state as one plain `Copy` value of fixed size, to take out
//! and put back (persistence across resets): each stage's state, its buffers as lists.

use super::checks::Checks;
use super::clock::Clock;
use super::config::{SPIKE_WINDOW_CAPACITY, TREND_CAPACITY};
use super::energy::Energy;
use super::events::{EVENT_CAPACITY, Event, EventKind, Reading};
use super::friction::FrictionStatus;
use super::risk::{Alarm, RiskState};
use super::statistics::Statistics;
use super::trend::{TrendInterval, TrendPoint};

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
    pub(crate) fn from_iter(fill: T, it: impl Iterator<Item = T>) -> Self {
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

    pub(crate) fn iter(&self) -> impl Iterator<Item = T> + '_ {
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
/// `sequential-storage`) and to put back with
/// [`Monitor::restore`](super::Monitor::restore) or
/// [`Monitor::resume`](super::Monitor::resume). Undelivered events are part of it.
/// Its parts are the monitor's working state, not API: read it through the accessors
/// below, which answer as the monitor's own did when it was taken.
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
    /// The reported state.
    pub fn state(&self) -> RiskState {
        self.alarm.state
    }

    /// Monotonic time since the first sample (ms).
    pub fn elapsed_ms(&self) -> u64 {
        self.clock.elapsed_ms
    }

    /// The last accepted raw timestamp (ms, the node's wrapping counter), `None` before
    /// the first sample.
    pub fn last_time_ms(&self) -> Option<u32> {
        self.clock.last_time_ms
    }

    /// What the monitor had counted and integrated.
    pub fn statistics(&self) -> &Statistics {
        &self.stats
    }

    /// The friction tracker.
    pub fn friction_status(&self) -> &FrictionStatus {
        &self.friction
    }

    /// The last valid running reading.
    pub fn reading(&self) -> Option<Reading> {
        self.reading
    }

    /// The latest time to critical (s).
    pub fn time_to_critical(&self) -> Option<f32> {
        self.time_to_critical_s
    }

    /// The sequence number of the next event.
    pub fn next_event_seq(&self) -> u32 {
        self.next_seq
    }

    /// Undelivered events, oldest first.
    pub fn events(&self) -> &[Event] {
        self.events.as_slice()
    }

    /// The trend's points, oldest first: the mean margin (rad) per interval.
    pub fn trend_points(&self) -> &[TrendPoint] {
        self.trend.as_slice()
    }
}

/// The state of a monitor that has seen no sample (what
/// [`Monitor::new`](super::Monitor::new) starts from): a place to restore a checkpoint
/// into.
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
/// both fit, on every target (checked when the crate compiles).
pub const STATE_BUDGET_BYTES: usize = 1024;
const _: () = assert!(core::mem::size_of::<MonitorState>() <= STATE_BUDGET_BYTES);

#[cfg(test)]
mod tests {
    use super::super::{CONFIGURATION_BYTES, Monitor};
    use super::*;

    /// The two sizes the budget bounds (`cargo test --lib monitor::state --
    /// --nocapture`).
    #[test]
    fn state_fits_its_budget() {
        let snapshot = core::mem::size_of::<MonitorState>();
        let live = core::mem::size_of::<Monitor<()>>() - CONFIGURATION_BYTES;
        std::println!(
            "snapshot {snapshot} bytes, live monitor {live} bytes besides its configuration"
        );
        assert!(snapshot <= STATE_BUDGET_BYTES && live <= STATE_BUDGET_BYTES);
    }
}
