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
//! theta = 2 atan(t) = 2 t R(t^2)                  d ln theta / dw = (d ln t^2/dw) / (2 (1 + t^2) R)
//! m^3 = 2 (pA + B) / (pi k^2 p)                   d ln m / dw = (d ln(m n)/dw - 1) / 2
//! ```
//!
//! (`m^3` is eq 5 with `sin^2(theta/2) = pA / (pA + B)`.) The slopes are kept as
//! fractions, so that a Newton step and what it carries cost one division.
//! Error: theta and `(m n)^3` a few roundings from exact given the point (the series,
//! one logarithm (ln.rs), a square root (sqrt.rs) and a few products); the slopes to
//! 1e-15, far more than a step of 1e-9 needs. Cost: one logarithm (a table read, no
//! division), the series, one square root, two divisions; no branch.

use super::atan::atan_ratio;
use super::ln::ln;
use super::series::differences;
use super::sqrt::sqrt;
use core::f64::consts::PI;

/// The quantities at one k'.
#[derive(Debug, Clone, Copy)]
pub struct Point {
    /// theta (rad).
    pub theta: f64,
    /// `(m n)^3`.
    pub mn_cubed: f64,
    /// `d ln theta / d ln k' = theta_num / theta_den`.
    pub theta_num: f64,
    /// See `theta_num`.
    pub theta_den: f64,
    /// `d (m n)^3 / d ln k' = 3 (m n)^3 d ln(m n) / d ln k'`.
    pub mn_cubed_slope: f64,
    /// `d ln(m n) / d ln k' = mn_num / mn_den`.
    pub mn_num: f64,
    /// See `mn_num`.
    pub mn_den: f64,
    /// `k^2 p`, `pA + B`: `m^3` and its slope ([`Point::m_cubed`]).
    k2p: f64,
    sum: f64,
}

impl Point {
    /// The point at `kprime` in (0, [`KPRIME_MAX`](super::series::KPRIME_MAX)], with
    /// `p = kprime^2` as the caller has it (rounded either way: the point is p's).
    #[inline(always)]
    pub fn at(kprime: f64, p: f64) -> Point {
        let k2 = 1.0 - p;
        let (a, b) = differences(p, -0.5 * ln(p));
        let pa = p * a;
        let t2 = pa / b;
        let r = atan_ratio(t2);
        let theta = 2.0 * sqrt(t2) * r;
        let sum = pa + b;
        let kab = k2 * a * b;
        // (m n)^3 = q sum^2, and its slope 3 (m n)^3 (pA - B)/(3 sum) = q sum (pA - B).
        let q = (4.0 / (PI * PI)) / ((k2 * k2) * kprime);
        Point {
            theta,
            mn_cubed: q * (sum * sum),
            theta_num: 2.0 * kab + (pa * a - b * b),
            theta_den: 2.0 * kab * ((1.0 + t2) * r),
            mn_cubed_slope: q * sum * (pa - b),
            mn_num: pa - b,
            mn_den: 3.0 * sum,
            k2p: k2 * p,
            sum,
        }
    }

    /// `m^3` at the point moved by `dw` in `ln k'` (to first order): one division.
    #[inline(always)]
    pub fn m_cubed(&self, dw: f64) -> f64 {
        let r = 1.0 / (PI * self.k2p);
        // d m^3 / dw = 3 m^3 (d ln(m n)/dw - 1)/2 = (pA - B - 3 (pA + B)) / (pi k^2 p).
        2.0 * self.sum * r + (self.mn_num - self.mn_den) * r * dw
    }
}

/// `ln(1 + u)` for `|u| < 2^-28` (the seeds' misses): `u - u^2/2`, error below
/// `|u|^3 / 3 < 2e-26`.
#[inline(always)]
pub fn ln_near_one(u: f64) -> f64 {
    u - 0.5 * (u * u)
}

/// Largest Newton step in `ln k'` taken as the last: the next would be below
/// `step^2 < 1e-18` (the functions solved have `|F''/(2F')| < 1`, held by the reference's
/// tests), and the quantities carried over it to first order are as close. A step this
/// small also bounds the seed's miss `u` (|u| < 2^-28 with the slopes above 1/4).
pub const STEP_MAX: f64 = 9.313_225_746_154_785e-10; // 2^-30

/// Largest `|u|` given to [`ln_near_one`].
pub const U_MAX: f64 = 3.725_290_298_461_914e-9; // 2^-28
