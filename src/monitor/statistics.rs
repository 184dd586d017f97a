//! The statistics: what the stages counted and integrated (time and energy per state,
//! extremes of the readings, counters of everything refused), read through accessors.

use super::energy::EnergySum;
use super::events::{FaultCause, Reading};
use super::order::ge;
use super::risk::RiskState;

/// Sensor faults counted by cause (saturating counters).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub struct FaultCounts {
    /// Non-finite values.
    pub non_finite: u32,
    /// Values outside the configured range.
    pub out_of_range: u32,
    /// Stuck values.
    pub stuck: u32,
    /// Gaps between samples.
    pub gap: u32,
    /// Timestamps going backwards.
    pub time_backwards: u32,
    /// Faults a driver reported.
    pub driver: u32,
    /// Samples the estimator refused.
    pub estimator: u32,
    /// Faults the sensors' own detection reported (the events name the sensor; the
    /// sensors count their faults per kind themselves).
    pub sensor: u32,
}

impl FaultCounts {
    /// No fault counted.
    pub(crate) const ZERO: FaultCounts = FaultCounts {
        non_finite: 0,
        out_of_range: 0,
        stuck: 0,
        gap: 0,
        time_backwards: 0,
        driver: 0,
        estimator: 0,
        sensor: 0,
    };

    /// Counts one fault (saturating).
    pub(crate) fn count(&mut self, cause: FaultCause) {
        let c = match cause {
            FaultCause::NonFinite(_) => &mut self.non_finite,
            FaultCause::OutOfRange(_) => &mut self.out_of_range,
            FaultCause::Stuck(_) => &mut self.stuck,
            FaultCause::Gap => &mut self.gap,
            FaultCause::TimeBackwards => &mut self.time_backwards,
            FaultCause::Driver(_) => &mut self.driver,
            FaultCause::Estimator => &mut self.estimator,
            FaultCause::Sensor(_) => &mut self.sensor,
        };
        *c = c.saturating_add(1);
    }

    /// The causes' names, in the order of [`FaultCounts::by_cause`] (the order of the
    /// checkpoint record, the Modbus registers and the PC tools' columns).
    pub const CAUSES: [&'static str; 8] = [
        "non_finite",
        "out_of_range",
        "stuck",
        "gap",
        "time_backwards",
        "driver",
        "estimator",
        "sensor",
    ];

    /// The counts in the order of [`FaultCounts::CAUSES`].
    pub fn by_cause(&self) -> [u32; 8] {
        [
            self.non_finite,
            self.out_of_range,
            self.stuck,
            self.gap,
            self.time_backwards,
            self.driver,
            self.estimator,
            self.sensor,
        ]
    }

    /// All faults.
    pub fn total(&self) -> u64 {
        self.by_cause().iter().map(|&c| u64::from(c)).sum()
    }
}

/// What the monitor has seen since it started (or since the state it was restored
/// from): [`Monitor::statistics`](super::Monitor::statistics).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Statistics {
    pub(crate) samples: u64,
    pub(crate) repeated_timestamps: u32,
    pub(crate) spikes: u32,
    pub(crate) faults: FaultCounts,
    pub(crate) events_dropped: u32,
    /// Per state, by [`RiskState::index`].
    pub(crate) time_in_state_ms: [u64; 5],
    pub(crate) energy: [EnergySum; 5],
    pub(crate) max_slip_ratio: f32,
    pub(crate) max_axial_force: f32,
    pub(crate) min_margin: Option<f32>,
}

impl Statistics {
    /// Nothing seen yet.
    pub(crate) const fn new() -> Self {
        Statistics {
            samples: 0,
            repeated_timestamps: 0,
            spikes: 0,
            faults: FaultCounts::ZERO,
            events_dropped: 0,
            time_in_state_ms: [0; 5],
            energy: [EnergySum {
                sum: 0.0,
                compensation: 0.0,
            }; 5],
            max_slip_ratio: 0.0,
            max_axial_force: 0.0,
            min_margin: None,
        }
    }

    /// Samples offered to the monitor (every call of `process`, repeated timestamps
    /// and faults included).
    pub fn samples(&self) -> u64 {
        self.samples
    }

    /// Samples with the previous sample's timestamp, ignored.
    pub fn repeated_timestamps(&self) -> u32 {
        self.repeated_timestamps
    }

    /// Spikes replaced by their window's median (load and angle).
    pub fn spikes(&self) -> u32 {
        self.spikes
    }

    /// Samples counted as sensor faults, by cause.
    pub fn faults(&self) -> &FaultCounts {
        &self.faults
    }

    /// Events dropped from the full queue (the oldest each time).
    pub fn events_dropped(&self) -> u32 {
        self.events_dropped
    }

    /// Time spent in `state` (ms): each step between samples counts for the state
    /// held during it.
    pub fn time_in_state_ms(&self, state: RiskState) -> u64 {
        self.time_in_state_ms
            .get(state.index())
            .copied()
            .unwrap_or(0)
    }

    /// Energy dissipated in `state` (J): F phi V integrated over time (section 7).
    pub fn energy_j(&self, state: RiskState) -> f64 {
        self.energy.get(state.index()).map_or(0.0, EnergySum::total)
    }

    /// Total dissipated energy (J), all states.
    pub fn total_energy(&self) -> f64 {
        self.energy.iter().map(EnergySum::total).sum()
    }

    /// Highest d/b of a valid running sample (0 before one).
    pub fn max_slip_ratio(&self) -> f32 {
        self.max_slip_ratio
    }

    /// Highest |F| of a valid running sample (N; 0 before one).
    pub fn max_axial_force(&self) -> f32 {
        self.max_axial_force
    }

    /// Lowest margin phi0 - |phi| of a valid running sample (rad), `None` before one
    /// with a margin.
    pub fn min_margin(&self) -> Option<f32> {
        self.min_margin
    }

    /// One sample offered.
    #[inline(always)]
    pub(crate) fn count_sample(&mut self) {
        // The u64 counters and times add without saturating: at one sample a
        // microsecond, or in milliseconds, they cannot wrap in 500 000 years.
        self.samples = self.samples.wrapping_add(1);
    }

    /// One sample with the previous timestamp.
    pub(crate) fn count_repeated(&mut self) {
        let r = &mut self.repeated_timestamps;
        *r = r.saturating_add(1);
    }

    /// A step of `dt_ms` in the state `held` during it.
    #[inline(always)]
    pub(crate) fn add_time(&mut self, held: RiskState, dt_ms: u32) {
        if let Some(t) = self.time_in_state_ms.get_mut(held.index()) {
            *t = t.wrapping_add(u64::from(dt_ms));
        }
    }

    /// One spike replaced.
    #[inline(always)]
    pub(crate) fn count_spike(&mut self) {
        self.spikes = self.spikes.saturating_add(1);
    }

    /// One sample refused for `cause`.
    pub(crate) fn count_fault(&mut self, cause: FaultCause) {
        self.faults.count(cause);
    }

    /// One event dropped from the full queue.
    pub(crate) fn count_dropped_event(&mut self) {
        let d = &mut self.events_dropped;
        *d = d.saturating_add(1);
    }

    /// The extremes with a valid running sample's reading (d/b not NaN).
    #[inline(always)]
    pub(crate) fn note_reading(&mut self, r: &Reading) {
        // Comparisons, not `max`/`min` (a libm call each on some targets).
        if !ge(self.max_slip_ratio, r.slip_ratio) {
            self.max_slip_ratio = r.slip_ratio;
        }
        let force = r.axial_force.abs();
        if !ge(self.max_axial_force, force) {
            self.max_axial_force = force;
        }
        if let Some(m) = r.margin
            && self.min_margin.is_none_or(|x| !ge(m, x))
        {
            self.min_margin = Some(m);
        }
    }

    /// Energy `j` (J) dissipated in `state`.
    #[inline(always)]
    pub(crate) fn add_energy(&mut self, state: RiskState, j: f32) {
        if let Some(sum) = self.energy.get_mut(state.index()) {
            sum.add(j);
        }
    }
}
