//! `F / (mu P)` of eq (21) at d/b = s, as
//! [`tangential::axial_force_ratio`](crate::reference::tangential::axial_force_ratio)
//! forms it (nothing cancels: `s^4 (3 + s^2) / (4 (1 + (1 + s^2/2) sqrt(1 - s^2)))`
//! plus `(3 s / 2) acos(s)`, at most 1), without a branch or a call: the square root
//! of sqrt.rs, the arc cosine of acos.rs; 1 in gross slip (s >= 1).
//!
//! Error: within 1e-15 (relative) of the reference's, 4.5e-16 measured (asserted below
//! over s from 2^-60 to 1; where s is small, F / (mu P) ~ 3 pi s / 4 carries acos's
//! error). Cost: a square root, one division, the arc cosine.

use super::acos::acos;
use super::sqrt::sqrt;

/// `F / (mu P)` for `s = d/b > 0` (elsewhere meaningless).
#[inline(always)]
pub fn axial_force_ratio(s: f64) -> f64 {
    // Partial slip's numbers at min(s, 1/2) in gross slip (then not used), so that
    // every lane's square root has a positive normal argument.
    let partial = s < 1.0;
    let x = if partial { s } else { 0.5 };
    let x2 = x * x;
    let root = sqrt((1.0 - x) * (1.0 + x));
    let first = x2 * x2 * (3.0 + x2) / (4.0 * (1.0 + (1.0 + 0.5 * x2) * root));
    let ratio = (first + 1.5 * x * acos(x, root)).min(1.0);
    if partial { ratio } else { 1.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::tangential;

    #[test]
    fn is_the_references_within_1e_15() {
        let mut worst: f64 = 0.0;
        for k in 1..=1_000_000 {
            let s = if k % 2 == 0 {
                k as f64 / 1e6
            } else {
                libm::pow(2.0, -60.0 * k as f64 / 1e6)
            };
            let (got, want) = (axial_force_ratio(s), tangential::axial_force_ratio(s));
            worst = worst.max(libm::fabs(got - want) / want.min(1.0));
        }
        assert!(worst < 1e-15, "{worst:e}");
        for s in [1.0, 1.0 + f64::EPSILON, 2.0, 1e300, f64::INFINITY] {
            assert_eq!(axial_force_ratio(s), 1.0);
        }
    }
}
