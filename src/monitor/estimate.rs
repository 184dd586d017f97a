//! The estimate stage: the [`Estimator`] at the conditioned sample, its answer checked
//! (finite d/b and F, or a fault: never carried on as NaN) and made the reading (the
//! measured F in place of the estimated one where the sample carries it). Its state
//! is the monitor's latest reading.

use super::conditioning::Conditioned;
use super::events::{FaultCause, Reading};
use super::order::{finite, nan};
use crate::Estimator;

/// The reading of the conditioned sample `at`, with the measured axial force
/// `measured` (N) if the sample has one; [`FaultCause::Estimator`] when the estimator
/// refuses the sample or answers a NaN d/b or a non-finite F.
#[inline(always)]
pub(crate) fn estimate<E: Estimator>(
    estimator: &E,
    at: &Conditioned,
    measured: Option<f32>,
) -> Result<Reading, FaultCause> {
    let e = estimator
        .estimate_si(at.load, at.phi)
        .map_err(|_| FaultCause::Estimator)?;
    // The cores answer finite d/b for a running load; anything else is refused,
    // never carried on as NaN.
    if nan(e.slip_ratio) || !finite(e.axial_force) {
        return Err(FaultCause::Estimator);
    }
    Ok(Reading {
        load: at.load,
        phi: at.phi,
        slip_ratio: e.slip_ratio,
        axial_force: measured.unwrap_or(e.axial_force),
        critical_angle: e.critical_angle.filter(|&c| finite(c)),
        margin: e.margin.filter(|&m| finite(m)),
    })
}
