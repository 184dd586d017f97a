//! k' and `(m n)^3` at a given theta (eqs 5-6): a seed from
//! [`KPRIME_OF_THETA`](super::seeds::KPRIME_OF_THETA), one evaluation
//! ([`Point`](super::point::Point)) and one Newton step in `ln k'` on `ln(theta(k')/theta)`,
//! the results carried over the step to first order.
//!
//! Domain: theta in [2^-40, 2^-3) (outside, `None`: the reference answers). Error: k'
//! and `m n` within 1.5e-15 of the 50-digit values (asserted by tests/reference_fast.rs
//! over tests/data/vectors_mn.csv); the step's own error is below 1e-18 (`None` where a seed
//! misses by more than [`STEP_MAX`](super::point::STEP_MAX), which the tables never do).
//! Cost: one seed (a table segment, degree 6), one point, one division; no branch.

use super::point::{Point, STEP_MAX, U_MAX, ln_near_one};
use super::seeds::KPRIME_OF_THETA;

/// The ellipse's shape at theta.
#[derive(Debug, Clone, Copy)]
pub struct Shape {
    /// k' = n/m.
    pub kprime: f64,
    /// `(m n)^3`.
    pub mn_cubed: f64,
    /// The point evaluated and the step from it, for [`Shape::m_cubed`].
    at: Point,
    dw: f64,
}

impl Shape {
    /// `m^3` (one division more).
    #[inline(always)]
    pub fn m_cubed(&self) -> f64 {
        self.at.m_cubed(self.dw)
    }
}

/// The shape at theta in the domain, else `None`.
#[cfg(any(test, feature = "_internals"))]
#[inline(always)]
pub fn shape(theta: f64) -> Option<Shape> {
    let (s, inside) = shape_lane(theta);
    inside.then_some(s)
}

/// The shape at theta and whether theta is in the domain, without a branch (a SIMD
/// lane's form of [`shape`]; outside the domain, numbers to be ignored).
#[inline(always)]
pub fn shape_lane(theta: f64) -> (Shape, bool) {
    let (seed, inside) = KPRIME_OF_THETA.eval_lane(theta);
    let at = Point::at(seed, seed * seed);
    // u = theta(k')/theta - 1 and the step -ln(1 + u) / (d ln theta / dw) by one division.
    let z = 1.0 / (theta * at.theta_num);
    let u = (at.theta - theta) * at.theta_num * z;
    let dw = -ln_near_one(u) * at.theta_den * theta * z;
    let converged = u.abs() < U_MAX && dw.abs() < STEP_MAX;
    let shape = Shape {
        kprime: seed + seed * (dw + 0.5 * dw * dw),
        mn_cubed: at.mn_cubed + at.mn_cubed_slope * dw,
        at,
        dw,
    };
    (shape, inside & converged)
}
