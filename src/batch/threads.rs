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
    par_estimate_with(inputs, outputs, model, &estimate)
}

/// One chunk's rows on one thread: [`estimate`] or a build of it for the CPU at hand
/// (`estimate_avx2`, where the CPU has AVX2).
pub type Leaf = dyn Fn(&Inputs<'_>, &mut Outputs<'_>, Model) -> Result<usize, Mismatch> + Sync;

/// [`par_estimate`] with each chunk computed by `leaf`.
///
/// # Errors
/// As [`estimate`].
pub fn par_estimate_with(
    inputs: &Inputs<'_>,
    outputs: &mut Outputs<'_>,
    model: Model,
    leaf: &Leaf,
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
    Ok(split(*inputs, whole, n, model, leaf))
}

fn split(
    inputs: Inputs<'_>,
    mut outputs: Outputs<'_>,
    n: usize,
    model: Model,
    leaf: &Leaf,
) -> usize {
    if n <= CHUNK {
        // The lengths were checked once for the whole batch.
        return leaf(&inputs, &mut outputs, model).unwrap_or(0);
    }
    let mid = n / 2;
    let (ia, ib) = inputs.split_at(mid);
    let (oa, ob) = outputs.split_at_mut(mid);
    let (a, b) = rayon::join(
        || split(ia, oa, mid, model, leaf),
        || split(ib, ob, n - mid, model, leaf),
    );
    a + b
}
