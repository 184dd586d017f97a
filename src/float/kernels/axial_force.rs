//! The axial-force curve of eq (21), `F/(mu P)` as a function of the slip ratio
//! `s = d/b`, in f32, in two pieces fitted to the f64 reference (`cargo xtask tables`):
//!
//! - `s < 1/2`: `s p(s)`, p a polynomial (eq 21 is analytic there; factoring out s keeps
//!   the relative error small as s -> 0, where F ~ 3 pi s / 4);
//! - `s >= 1/2`: `1 - u^5 q(u)`, `u = sqrt(1 - s)`, q a polynomial. Near gross slip
//!   `1 - F/(mu P)` behaves like `(4 sqrt 2 / 5)(1 - s)^(5/2)`, which no polynomial in s
//!   follows; with that branch point factored out what is left is analytic, and
//!   `1 - s` is exact there.

use crate::float::tables::{AXIAL_FORCE_HIGH, AXIAL_FORCE_LOW};

/// Maximum relative error of [`axial_force_ratio`] against eq (21) in f64, over all
/// f32 s with a normal result (s >= 2^-126): 1.967e-7 measured over every one of them
/// (`MISALIGN_SWEEP_STEP=1 cargo test --lib axial_force`); `cargo test` checks every 16th.
pub const AXIAL_FORCE_MAX_REL_ERROR: f32 = 2.0e-7;

/// `F / (mu P)` for slip ratio `s`: eq (21) for `0 < s < 1`, 1 for `s >= 1`
/// (eqs 21 and 29 meet there with two continuous derivatives), 0 for `s <= 0` or NaN.
#[inline(always)]
pub fn axial_force_ratio(s: f32) -> f32 {
    if s >= 1.0 {
        return 1.0;
    }
    if s.is_nan() || s <= 0.0 {
        return 0.0;
    }
    axial_force_ratio_nonnegative(s)
}

/// [`axial_force_ratio`] for `s >= 0` (d/b as the estimators form it: never negative or
/// NaN), without the checks for what cannot come.
#[inline(always)]
pub(crate) fn axial_force_ratio_nonnegative(s: f32) -> f32 {
    if s >= 1.0 {
        return 1.0;
    }
    axial_force_ratio_partial(s)
}

/// [`axial_force_ratio`] for `0 <= s < 1` (partial slip).
#[inline(always)]
pub(crate) fn axial_force_ratio_partial(s: f32) -> f32 {
    // s < 1/2 on the bits (s >= 0).
    if s.to_bits() < 0.5f32.to_bits() {
        s * horner(&AXIAL_FORCE_LOW, s)
    } else {
        let v = 1.0 - s; // exact (Sterbenz)
        let u = sqrt_below_half(v);
        1.0 - v * v * u * horner(&AXIAL_FORCE_HIGH, u)
    }
}

/// `limit * F/(mu P)` for `0 <= s < 1` (partial slip), `limit` = +-mu P: as
/// [`axial_force_ratio_partial`], near gross slip as `limit - limit (1 - F/(mu P))`
/// (no 1 to subtract from: one constant fewer on the per-sample path).
#[inline(always)]
pub(crate) fn axial_force_partial(limit: f32, s: f32) -> f32 {
    if s.to_bits() < 0.5f32.to_bits() {
        limit * (s * horner(&AXIAL_FORCE_LOW, s))
    } else {
        let v = 1.0 - s; // exact (Sterbenz)
        let u = sqrt_below_half(v);
        limit - limit * (v * v * u * horner(&AXIAL_FORCE_HIGH, u))
    }
}

/// `sqrt(v)` for v in [2^-24, 1/2] (1 - s on the upper piece): a bit-level first guess
/// (4 % off at most) and two Heron steps `y <- (y^2 + v) / (2 y)`, within 3.2e-7 (every
/// f32 there; it enters F/(mu P) times (1 - F/(mu P)) / F/(mu P) <= 0.24, which
/// [`AXIAL_FORCE_MAX_REL_ERROR`] includes).
#[inline(always)]
fn sqrt_below_half(v: f32) -> f32 {
    let mut y = f32::from_bits((v.to_bits() >> 1) + 0x1fbb_8000);
    y = (y * y + v) / (y + y);
    (y * y + v) / (y + y)
}

#[inline(always)]
fn horner<const N: usize>(c: &[f32; N], x: f32) -> f32 {
    let mut acc = c[N - 1];
    let mut k = N - 1;
    while k > 0 {
        k -= 1;
        acc = acc * x + c[k];
    }
    acc
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::tangential;

    fn rel_err(s: f32) -> f64 {
        let want = tangential::axial_force_ratio(s as f64);
        (axial_force_ratio(s) as f64 / want - 1.0).abs()
    }

    /// Every 16th f32 by default; `MISALIGN_SWEEP_STEP=1` for all of them.
    #[test]
    fn sweep_over_the_unit_interval() {
        let step = std::env::var("MISALIGN_SWEEP_STEP")
            .ok()
            .and_then(|s| s.parse().ok());
        const STEP_DEFAULT: usize = 16;
        let step_by = step.unwrap_or(STEP_DEFAULT);
        let (lo, hi) = (f32::MIN_POSITIVE.to_bits(), 1.0f32.to_bits());
        let worst = (lo..hi)
            .step_by(step_by)
            .map(|b| rel_err(f32::from_bits(b)))
            .fold(0.0, f64::max);
        println!("axial_force_ratio worst relative error {worst:.3e}");
        assert!(worst <= AXIAL_FORCE_MAX_REL_ERROR as f64, "{worst:e}");
    }

    #[test]
    fn ends_and_bad_input() {
        assert_eq!(axial_force_ratio(1.0), 1.0);
        assert_eq!(axial_force_ratio(2.0), 1.0);
        assert_eq!(axial_force_ratio(f32::INFINITY), 1.0);
        assert_eq!(axial_force_ratio(0.0), 0.0);
        assert_eq!(axial_force_ratio(-1.0), 0.0);
        assert_eq!(axial_force_ratio(f32::NAN), 0.0);
        let below = axial_force_ratio(1.0 - f32::EPSILON / 2.0);
        assert!(below <= 1.0 && below > 1.0 - 1e-7);
    }
}
