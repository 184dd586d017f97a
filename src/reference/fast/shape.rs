//! k' and `(m n)^3` at a given theta (eqs 5-6): a seed from
//! [`KPRIME_OF_THETA`](super::seeds::KPRIME_OF_THETA), one evaluation
//! ([`Point`](super::point::Point)) and one Newton step in `ln k'` on `ln(theta(k')/theta)`,
//! the results carried over the step to first order.
//!
//! Domain: theta in [2^-40, 2^-3) (outside, `None`: the reference answers). Error: k'
//! and `m n` within 6 ulps of the reference's values (tests/data/vectors_mn.csv: the
//! 50-digit ones); the step's own error is below 1e-18 (`None` where a seed misses by
//! more than [`STEP_MAX`](super::point::STEP_MAX), which the tables never do).
//! Cost: one seed (a table segment, degree 6), one point, two divisions.

use super::point::{Point, STEP_MAX, U_MAX, ln_near_one};
use super::seeds::KPRIME_OF_THETA;

/// The ellipse's shape at theta.
#[derive(Debug, Clone, Copy)]
pub struct Shape {
    /// k' = n/m.
    pub kprime: f64,
    /// `(m n)^3`.
    pub mn_cubed: f64,
    /// `m^3`.
    pub m_cubed: f64,
}

/// The shape at theta in the domain, else `None`.
#[inline(always)]
pub fn shape(theta: f64) -> Option<Shape> {
    let seed = KPRIME_OF_THETA.eval(theta)?;
    let at = Point::at(seed, seed * seed);
    let u = at.theta / theta - 1.0;
    let dw = -ln_near_one(u) / at.theta_slope;
    if !(libm::fabs(u) < U_MAX && libm::fabs(dw) < STEP_MAX) {
        return None;
    }
    // ln m = (ln(m n) - w) / 2.
    Some(Shape {
        kprime: seed + seed * (dw + 0.5 * dw * dw),
        mn_cubed: at.mn_cubed * (1.0 + 3.0 * at.mn_slope * dw),
        m_cubed: at.m_cubed * (1.0 + 1.5 * (at.mn_slope - 1.0) * dw),
    })
}
