//! One point along k' (eqs 5-6) from [`series`](super::series): theta, `(m n)^3` and
//! their slopes in `w = ln k'`, for the one Newton step of [`shape`](super::shape) and
//! [`critical`](super::critical).
//!
//! With `A = K - E`, `B = E - k'^2 K`, `p = k'^2`, `k^2 = 1 - p` (DLMF 19.4.1 gives
//! `dA/dw = -(B + pA)/k^2`, `dB/dw = -p(A + B)/k^2`):
//!
//! ```text
//! tan^2(theta/2) = p A / B                        d ln tan^2 / dw = 2 + (p A^2 - B^2)/(k^2 A B)
//! (m n)^3 = 4 (pA + B)^2 / (pi^2 k^4 k')          d ln(m n) / dw = (pA - B) / (3 (pA + B))
//! theta = 2 atan(t)                               d ln theta / dw = t (d ln t^2/dw) / ((1 + t^2) theta)
//! ```
//!
//! (`m^3 = 2 (pA + B) / (pi k^2 p)` is eq 5 with `sin^2(theta/2) = pA / (pA + B)`.)
//! Error: theta and `(m n)^3` within 4 ulps given exact k' (series, one logarithm,
//! a square root and a few products); the slopes to 1e-15, far more than a step of
//! 1e-9 needs. Cost: one logarithm, the series, one square root, four divisions.

use super::atan::atan_ratio;
use super::series::differences;
use core::f64::consts::PI;

/// The quantities at one k'.
#[derive(Debug, Clone, Copy)]
pub struct Point {
    /// theta (rad).
    pub theta: f64,
    /// `(m n)^3`.
    pub mn_cubed: f64,
    /// `d ln theta / d ln k'`.
    pub theta_slope: f64,
    /// `d ln(m n) / d ln k'`.
    pub mn_slope: f64,
    /// `m^3 = 2 (pA + B) / (pi k^2 p)`.
    pub m_cubed: f64,
}

impl Point {
    /// The point at `kprime` in (0, [`KPRIME_MAX`](super::series::KPRIME_MAX)], with
    /// `p = kprime^2` as the caller has it (rounded either way: the point is p's).
    #[inline(always)]
    pub fn at(kprime: f64, p: f64) -> Point {
        let k2 = 1.0 - p;
        let (a, b) = differences(p, -0.5 * libm::log(p));
        let pa = p * a;
        let t2 = pa / b;
        let t = libm::sqrt(t2);
        let theta = 2.0 * t * atan_ratio(t2);
        let sum = pa + b;
        let tan_slope = 2.0 + (pa * a - b * b) / (k2 * a * b);
        let m_cubed = 2.0 * sum / (PI * k2 * p);
        Point {
            theta,
            mn_cubed: (4.0 / (PI * PI)) * (sum * sum) / ((k2 * k2) * kprime),
            theta_slope: t * tan_slope / ((1.0 + t2) * theta),
            mn_slope: (pa - b) / (3.0 * sum),
            m_cubed,
        }
    }
}

/// Largest `|u|` given to [`ln_near_one`].
pub const U_MAX: f64 = 9.536_743_164_062_5e-7; // 2^-20

/// `ln(1 + u)` for `|u| < U_MAX` (the seeds' misses): `u - u^2/2`, error below
/// `|u|^3 / 3 < 1e-19 |u|`.
#[inline(always)]
pub fn ln_near_one(u: f64) -> f64 {
    u - 0.5 * (u * u)
}

/// Largest Newton step in `ln k'` taken as the last: the next would be below
/// `step^2 < 1e-18` (the functions solved have `|F''/(2F')| < 1`, held by the reference's
/// tests), and the quantities carried over it to first order are as close.
pub const STEP_MAX: f64 = 9.313_225_746_154_785e-10; // 2^-30
