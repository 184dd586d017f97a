//! The monitor's whole state as one plain `Copy` value of fixed size, to take out
//! and put back (persistence across resets).

use super::config::{Config, ConfigError, SPIKE_WINDOW_CAPACITY, TREND_CAPACITY};
use super::events::{EVENT_CAPACITY, Event, EventKind, Reading};
use super::friction::FrictionStatus;
use super::{
    Alarm, Clock, Monitor, RiskState, Statistics, StuckTracker, TrendInterval, TrendPoint,
};
use crate::Estimator;

/// Everything of the monitor but its buffers.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Status {
    /// The clock.
    pub clock: Clock,
    /// The state machine.
    pub alarm: Alarm,
    /// Smoothed load (N) and angle (rad), `None` after a restart of the conditioning.
    pub smoothed: Option<[f32; 2]>,
    /// Stuck tracking of load and angle.
    pub stuck: [StuckTracker; 2],
    /// The trend's current interval.
    pub trend_interval: TrendInterval,
    /// The latest time to critical (s).
    pub time_to_critical_s: Option<f32>,
    /// Whether the next fall below the horizon raises an `Approaching` event.
    pub approaching_armed: bool,
    /// The next event's sequence number.
    pub next_seq: u32,
    /// The last valid running reading.
    pub reading: Option<Reading>,
    /// Energy of the current sample's step (J), added once its state is known.
    pub energy_step: f32,
    /// Counters, extremes, time and energy per state.
    pub stats: Statistics,
    /// Friction tracking: the filtered mu, its baseline, the change state.
    pub friction: FrictionStatus,
}

impl Status {
    pub(crate) const fn new() -> Self {
        Status {
            clock: Clock {
                last_time_ms: None,
                elapsed_ms: 0,
            },
            alarm: Alarm::new(),
            smoothed: None,
            stuck: [StuckTracker {
                bits: 0,
                since_ms: 0,
            }; 2],
            trend_interval: TrendInterval {
                start_ms: 0,
                sum: 0.0,
                count: 0,
            },
            time_to_critical_s: None,
            approaching_armed: true,
            next_seq: 0,
            reading: None,
            energy_step: 0.0,
            stats: Statistics {
                samples: 0,
                repeated_timestamps: 0,
                spikes: 0,
                faults: super::FaultCounts {
                    non_finite: 0,
                    out_of_range: 0,
                    stuck: 0,
                    gap: 0,
                    time_backwards: 0,
                    driver: 0,
                    estimator: 0,
                    sensor: 0,
                },
                events_dropped: 0,
                time_in_state_ms: [0; 5],
                energy: [super::EnergySum {
                    sum: 0.0,
                    compensation: 0.0,
                }; 5],
                max_slip_ratio: 0.0,
                max_axial_force: 0.0,
                min_margin: None,
            },
            friction: FrictionStatus::new(),
        }
    }
}

/// A fixed-capacity list as plain data: the first `len` of `items`, oldest first.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Saved<T, const N: usize> {
    /// The items; those past `len` are unused.
    pub items: [T; N],
    /// How many are used (values above `N` are read as `N`).
    pub len: u8,
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

    fn iter(&self) -> impl Iterator<Item = T> + '_ {
        self.items
            .iter()
            .copied()
            .take(usize::from(self.len).min(N))
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
/// to store and to put back with [`Monitor::restore`]. Undelivered events are part of
/// it.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MonitorState {
    /// Everything but the buffers.
    pub status: Status,
    /// The spike filter's load window (N).
    pub load_window: Saved<f32, SPIKE_WINDOW_CAPACITY>,
    /// The spike filter's angle window (rad).
    pub angle_window: Saved<f32, SPIKE_WINDOW_CAPACITY>,
    /// The trend's points.
    pub trend: Saved<TrendPoint, TREND_CAPACITY>,
    /// Undelivered events.
    pub events: Saved<Event, EVENT_CAPACITY>,
}

impl<E: Estimator> Monitor<E> {
    /// The whole state as a plain value.
    pub fn snapshot(&self) -> MonitorState {
        MonitorState {
            status: self.status,
            load_window: Saved::from_iter(0.0, self.windows[0].iter()),
            angle_window: Saved::from_iter(0.0, self.windows[1].iter()),
            trend: Saved::from_iter(TrendPoint::default(), self.trend.iter().copied()),
            events: Saved::from_iter(NO_EVENT, self.events.iter().copied()),
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
        self.status = state.status;
        // The buffers were filled from at most their own capacity: the pushes fit.
        let n = self
            .config
            .spikes
            .map_or(SPIKE_WINDOW_CAPACITY, |s| usize::from(s.window));
        for (window, saved) in self
            .windows
            .iter_mut()
            .zip([&state.load_window, &state.angle_window])
        {
            window.clear();
            for x in saved.iter() {
                window.push_back(x, n);
            }
        }
        self.trend.clear();
        for p in state.trend.iter() {
            let _ = self.trend.push_back(p);
        }
        self.events.clear();
        for e in state.events.iter() {
            let _ = self.events.push_back(e);
        }
    }
}

/// The state of a monitor that has seen no sample (what [`Monitor::new`] starts
/// from): a place to restore a checkpoint into.
impl Default for MonitorState {
    fn default() -> Self {
        MonitorState {
            status: Status::new(),
            load_window: Saved::from_iter(0.0, core::iter::empty()),
            angle_window: Saved::from_iter(0.0, core::iter::empty()),
            trend: Saved::from_iter(TrendPoint::default(), core::iter::empty()),
            events: Saved::from_iter(NO_EVENT, core::iter::empty()),
        }
    }
}

/// Issue 10's RAM budget of the monitor's state with the default capacities: the
/// snapshot ([`MonitorState`]) and the live monitor without its estimator and its
/// configuration (the [`Config`] and the limits and levels formed from it once) both
/// fit, on every target (checked when the crate compiles).
pub const STATE_BUDGET_BYTES: usize = 1024;
const _: () = assert!(core::mem::size_of::<MonitorState>() <= STATE_BUDGET_BYTES);
const _: () =
    assert!(core::mem::size_of::<Monitor<()>>() - super::CONFIGURATION_BYTES <= STATE_BUDGET_BYTES);

#[cfg(test)]
mod tests {
    use super::*;

    /// The two sizes the budget bounds, as the README gives them (`cargo test --lib
    /// monitor::state -- --nocapture`).
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
