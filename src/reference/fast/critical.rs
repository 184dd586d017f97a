//! theta0 where `g(theta) = m n theta` takes a given value (eq 18 with d/b = 1: the
//! critical angle), from `g^3`: a seed from
//! [`KPRIME_SQUARED_OF_G_CUBED`](super::seeds::KPRIME_SQUARED_OF_G_CUBED), one evaluation
//! ([`Point`](super::point::Point)) and one Newton step in `ln k'` on
//! `ln(g(k')^3 / g^3) / 3`, theta carried over the step to first order.
//!
//! Domain: `g^3` in the table's range (theta0 from about 2^-40 to 2^-3; outside,
//! `None`: the reference answers). Error: theta0 within 1.5e-15 of the 50-digit values
//! (asserted by tests/reference_fast.rs); the step's own error below 1e-18. Cost: one
//! seed, a square root, one point, one division; no branch.

use super::point::{Point, STEP_MAX, U_MAX, ln_near_one};
use super::seeds::KPRIME_SQUARED_OF_G_CUBED;
use super::sqrt::sqrt;

/// theta0 (rad) with `g(theta0)^3 = g_cubed`, in the domain, else `None`.
#[cfg(any(test, feature = "_internals"))]
#[inline(always)]
pub fn theta_of_g_cubed(g_cubed: f64) -> Option<f64> {
    let (t, inside) = theta_lane(g_cubed);
    inside.then_some(t)
}

/// [`theta_of_g_cubed`] and whether `g_cubed` is in the domain, without a branch (a SIMD
/// lane's form; outside the domain, a number to be ignored).
#[inline(always)]
pub fn theta_lane(g_cubed: f64) -> (f64, bool) {
    let (p, inside) = KPRIME_SQUARED_OF_G_CUBED.eval_lane(g_cubed);
    let at = Point::at(sqrt(p), p);
    let theta = at.theta;
    let g3 = at.mn_cubed * (theta * theta * theta);
    // d ln g / dw = theta_num/theta_den + mn_num/mn_den = num / den; u = g3/g_cubed - 1,
    // the step -ln(1 + u) / (3 num/den) and theta's change over it by one division.
    let num = at.theta_num * at.mn_den + at.mn_num * at.theta_den;
    let den = at.theta_den * at.mn_den;
    let z = 1.0 / (g_cubed * num);
    let u = (g3 - g_cubed) * num * z;
    let step = -ln_near_one(u) * g_cubed * z * (1.0 / 3.0);
    let dw = step * den;
    let converged = u.abs() < U_MAX && dw.abs() < STEP_MAX;
    // d ln theta = (theta_num / theta_den) dw = theta_num mn_den step.
    let theta0 = theta + theta * (at.theta_num * at.mn_den * step);
    (theta0, inside & converged)
}
