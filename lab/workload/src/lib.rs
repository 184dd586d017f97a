//! What the measurements share, on the host and on the target (`no_std`): the
//! benchmark's samples ([`samples`]), the operations and models it measures
//! ([`Operation`], [`Model`]: the benchmark image prints their names, `cargo xtask
//! bench` reads them back), and the Hamrock & Brewe baseline ([`hamrock_brewe`]).
//! Used by the benchmark image (`lab/harness/`), the host benchmark (`benches/host.rs`)
//! and `cargo xtask bench`.
#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]

pub mod hamrock_brewe;
pub mod samples;

/// What a benchmark row estimates with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Model {
    /// The f64 reference (`misalign::reference`).
    Reference,
    /// The f32 core (`misalign::float`).
    F32,
    /// The fixed-point core (`misalign::fixed`).
    Fixed,
    /// The Hamrock & Brewe baseline ([`hamrock_brewe`]).
    HamrockBrewe,
}

/// What a benchmark row measures: a whole estimate or one kernel or table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Operation {
    /// The full per-sample estimate of elliptic contact (d/b, regime, F, phi0).
    Estimate,
    /// The same for line contact.
    EstimateLine,
    /// The f32 table g(theta).
    TableG,
    /// The f32 table theta(g).
    TableThetaOfG,
    /// The f32 cube root kernel.
    KernelCbrt,
    /// libm's `cbrtf`, for comparison.
    KernelLibmCbrtf,
    /// The f32 inverse square root kernel.
    KernelInvSqrt,
    /// libm's `sqrtf`, for comparison.
    KernelLibmSqrtf,
    /// The f32 F/(mu P) of eq (21).
    KernelAxialForce,
    /// The fixed-point log2.
    KernelLog2,
    /// The fixed-point exp2.
    KernelExp2,
    /// The Q8.24 table log2 g(log2 theta).
    TableLogG,
    /// The inverse mu from (P, phi, F), elliptic contact.
    InverseMu,
    /// The inverse phi from (P, F), elliptic contact.
    InversePhi,
    /// The inverse mu, line contact.
    InverseMuLine,
    /// The inverse phi, line contact.
    InversePhiLine,
    /// The condition monitor's whole per-sample pipeline (`Monitor::process`:
    /// conditioning, estimate, states, wear, trend) over the built-in scenario.
    Monitor,
    /// The same with spike rejection off: what the Hampel test costs is the difference.
    MonitorNoSpikes,
    /// The same with smoothing off.
    MonitorNoSmoothing,
    /// The same with the trend (time to critical) off.
    MonitorNoTrend,
    /// The same with every conditioning stage (spikes, smoothing, stuck and gap
    /// checks) and the trend off: sensor range checks, estimate, states, wear, statistics.
    MonitorBare,
}

impl Model {
    /// Every model, in the order of the tables.
    pub const ALL: [Model; 4] = [
        Model::Reference,
        Model::F32,
        Model::Fixed,
        Model::HamrockBrewe,
    ];

    /// The name in the benchmark's log, CSV and tables.
    pub const fn name(self) -> &'static str {
        match self {
            Model::Reference => "reference",
            Model::F32 => "f32",
            Model::Fixed => "fixed",
            Model::HamrockBrewe => "hamrock-brewe",
        }
    }

    /// The model of `name` ([`Model::name`]).
    pub fn from_name(name: &str) -> Option<Model> {
        Model::ALL.into_iter().find(|m| m.name() == name)
    }
}

impl Operation {
    /// Every operation, in the order the benchmark image measures them.
    pub const ALL: [Operation; 21] = [
        Operation::Estimate,
        Operation::EstimateLine,
        Operation::TableG,
        Operation::TableThetaOfG,
        Operation::KernelCbrt,
        Operation::KernelLibmCbrtf,
        Operation::KernelInvSqrt,
        Operation::KernelLibmSqrtf,
        Operation::KernelAxialForce,
        Operation::KernelLog2,
        Operation::KernelExp2,
        Operation::TableLogG,
        Operation::InverseMu,
        Operation::InversePhi,
        Operation::InverseMuLine,
        Operation::InversePhiLine,
        Operation::Monitor,
        Operation::MonitorNoSpikes,
        Operation::MonitorNoSmoothing,
        Operation::MonitorNoTrend,
        Operation::MonitorBare,
    ];

    /// The name in the benchmark's log, CSV and tables.
    pub const fn name(self) -> &'static str {
        match self {
            Operation::Estimate => "estimate",
            Operation::EstimateLine => "estimate:line",
            Operation::TableG => "table:g",
            Operation::TableThetaOfG => "table:theta_of_g",
            Operation::KernelCbrt => "kernel:cbrt",
            Operation::KernelLibmCbrtf => "kernel:libm_cbrtf",
            Operation::KernelInvSqrt => "kernel:inv_sqrt",
            Operation::KernelLibmSqrtf => "kernel:libm_sqrtf",
            Operation::KernelAxialForce => "kernel:axial_force",
            Operation::KernelLog2 => "kernel:log2",
            Operation::KernelExp2 => "kernel:exp2",
            Operation::TableLogG => "table:log_g",
            Operation::InverseMu => "inverse:mu",
            Operation::InversePhi => "inverse:phi",
            Operation::InverseMuLine => "inverse:mu:line",
            Operation::InversePhiLine => "inverse:phi:line",
            Operation::Monitor => "monitor",
            Operation::MonitorNoSpikes => "monitor:no_spikes",
            Operation::MonitorNoSmoothing => "monitor:no_smoothing",
            Operation::MonitorNoTrend => "monitor:no_trend",
            Operation::MonitorBare => "monitor:bare",
        }
    }

    /// The operation of `name` ([`Operation::name`]).
    pub fn from_name(name: &str) -> Option<Operation> {
        Operation::ALL.into_iter().find(|o| o.name() == name)
    }

    /// The monitor's pipeline with one stage or more switched off (its profile), and
    /// the configuration it runs with: `Monitor`'s default with that stage off.
    pub const fn is_monitor(self) -> bool {
        matches!(
            self,
            Operation::Monitor
                | Operation::MonitorNoSpikes
                | Operation::MonitorNoSmoothing
                | Operation::MonitorNoTrend
                | Operation::MonitorBare
        )
    }

    /// A whole per-sample estimate (not a kernel or a table).
    pub const fn is_estimate(self) -> bool {
        matches!(self, Operation::Estimate | Operation::EstimateLine)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_read_back() {
        for m in Model::ALL {
            assert_eq!(Model::from_name(m.name()), Some(m));
        }
        for o in Operation::ALL {
            assert_eq!(Operation::from_name(o.name()), Some(o));
        }
        assert_eq!(Operation::from_name("estimate:plane"), None);
    }
}
