//! [`par_estimate`]: a batch split into chunks over rayon's threads.

use super::{Inputs, Mismatch, Model, Outputs, estimate, rows};

/// Rows per chunk: enough that a chunk's scene preparation and rayon's hand-over cost
/// little beside its estimates.
const CHUNK: usize = 8192;

/// [`estimate`] with the rows split into chunks over rayon's thread pool; the same
/// numbers as on one thread (each row is computed alone).
///
/// # Errors
/// As [`estimate`].
pub fn par_estimate(
    inputs: &Inputs<'_>,
    outputs: &mut Outputs<'_>,
    model: Model,
) -> Result<usize, Mismatch> {
    let n = rows(inputs, outputs)?;
    let whole = Outputs {
        slip_ratio: &mut *outputs.slip_ratio,
        axial_force: &mut *outputs.axial_force,
        critical_angle: &mut *outputs.critical_angle,
        regime: &mut *outputs.regime,
        model: &mut *outputs.model,
        flags: &mut *outputs.flags,
        status: &mut *outputs.status,
        details: outputs.details.as_mut().map(|d| super::Details {
            theta: &mut *d.theta,
            kprime: &mut *d.kprime,
            m: &mut *d.m,
            n: &mut *d.n,
            a: &mut *d.a,
            b: &mut *d.b,
            p0: &mut *d.p0,
            d: &mut *d.d,
            pstar: &mut *d.pstar,
            p0star: &mut *d.p0star,
            theta0: &mut *d.theta0,
            radius: &mut *d.radius,
        }),
    };
    Ok(split(*inputs, whole, n, model))
}

fn split(inputs: Inputs<'_>, mut outputs: Outputs<'_>, n: usize, model: Model) -> usize {
    if n <= CHUNK {
        // The lengths were checked once for the whole batch.
        return estimate(&inputs, &mut outputs, model).unwrap_or(0);
    }
    let mid = n / 2;
    let (ia, ib) = inputs.split_at(mid);
    let (oa, ob) = outputs.split_at_mut(mid);
    let (a, b) = rayon::join(
        || split(ia, oa, mid, model),
        || split(ib, ob, n - mid, model),
    );
    a + b
}
