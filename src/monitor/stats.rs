//! Statistics: time and energy per state, extremes, counters of everything refused.

use super::events::FaultCause;
use super::wear::EnergySum;

/// Sensor faults counted by cause.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
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

    /// All faults.
    pub fn total(&self) -> u64 {
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
        .iter()
        .map(|&c| u64::from(c))
        .sum()
    }
}

/// What the monitor has seen since it started (or since the state it was restored
/// from). Per-state arrays are indexed by [`RiskState::index`](super::RiskState::index).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Statistics {
    /// Samples offered.
    pub samples: u64,
    /// Samples with the previous sample's timestamp, ignored.
    pub repeated_timestamps: u32,
    /// Spikes replaced by the window's median (load and angle).
    pub spikes: u32,
    /// Samples counted as sensor faults, by cause.
    pub faults: FaultCounts,
    /// Events dropped from the full queue (the oldest each time).
    pub events_dropped: u32,
    /// Time in each state (ms): each step between samples counts for the state held.
    pub time_in_state_ms: [u64; 5],
    /// Energy dissipated in each state (J): F phi V integrated (section 7).
    pub energy: [EnergySum; 5],
    /// Highest d/b of a valid running sample (0 before one).
    pub max_slip_ratio: f32,
    /// Highest |F| of a valid running sample (N).
    pub max_axial_force: f32,
    /// Lowest margin phi0 - |phi| (rad).
    pub min_margin: Option<f32>,
}

impl Statistics {
    /// Total dissipated energy (J), all states.
    pub fn total_energy(&self) -> f64 {
        self.energy.iter().map(EnergySum::total).sum()
    }
}
