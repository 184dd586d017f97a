//! Inverses of the axial-force kernel ([`super::axial_force`]) for the f32 inverse
//! estimates: the slip ratio `s = d/b` from `r = F/(mu P)` (the misalignment inverse)
//! and from `q = F/(K P) = f(s)/s` (the friction inverse, `K = mu d/b`). Both solve the
//! kernel's own pieces by Newton steps on its polynomials, so that forward then inverse
//! in f32 is consistent to a few ulps:
//!
//! - `s < 1/2`: `f = s p(s)`; `f/s = p(s)` is nearly linear, `f` concave, so Newton
//!   from the left converges monotonically.
//! - `s >= 1/2`: `1 - f = u^5 q(u)`, `u = sqrt(1 - s)`. The steps run in u, where the
//!   order-5/2 contact of eq (21) with 1 at gross slip is factored out; the start is
//!   `u0 = (y / q(0))^(1/5)` (a bit-level fifth root with Newton steps), within 1.2 % of
//!   the root since q varies by less than that over `u <= 1/sqrt 2`.

use crate::float::tables::{AXIAL_FORCE_HIGH, AXIAL_FORCE_LOW};

/// Maximum relative error of [`slip_ratio_of_force_ratio`] against the f64 inverse of
/// eq (21), times `s f'(s) / f(s)` (the conditioning: an error of f alone moves s by
/// that), over r in [2^-126, 1), and of [`slip_ratio_of_force_over_slip`] divided by
/// its conditioning `h / (h - f')`, `h = f/s`: measured 1.9e-7 and 2.0e-7 (every
/// 6464th f32 r, 20 000 q; `cargo test --lib axial_force_inverse`). One Newton step
/// fewer on any piece gives 1e-6 to 1e-5.
pub const SLIP_RATIO_MAX_REL_ERROR: f32 = 3e-7;

/// `p(s)` and `p'(s)` of a polynomial, lowest power first.
#[inline(always)]
fn horner_slope<const N: usize>(c: &[f32; N], x: f32) -> (f32, f32) {
    let mut acc = c[N - 1];
    let mut slope = 0.0;
    let mut k = N - 1;
    while k > 0 {
        k -= 1;
        slope = slope * x + acc;
        acc = acc * x + c[k];
    }
    (acc, slope)
}

/// `1 - f` and its derivative in u on the high piece: `D(u) = u^5 q(u)`,
/// `D'(u) = u^4 (5 q + u q')`.
#[inline(always)]
fn high_piece(u: f32) -> (f32, f32) {
    let (q, dq) = horner_slope(&AXIAL_FORCE_HIGH, u);
    let u2 = u * u;
    let u4 = u2 * u2;
    (u4 * u * q, u4 * (5.0 * q + u * dq))
}

/// `y^(1/5)` for `y` in (0, 1/2], from the bits (`bits / 5` plus the bias) and three
/// Newton steps `t <- (4 t + y / t^4) / 5`.
#[inline(always)]
fn fifth_root(y: f32) -> f32 {
    let mut t = f32::from_bits(0x3f80_0000 / 5 * 4 + y.to_bits() / 5);
    for _ in 0..3 {
        let t2 = t * t;
        t = 0.8 * t + 0.2 * y / (t2 * t2);
    }
    t
}

/// `u` on the high piece where `D(u) = y` (`y = 1 - f` in (0, 1 - f(1/2)]).
#[inline(always)]
fn high_root(y: f32) -> f32 {
    // q(0) = 4 sqrt 2 / 5: u0 = (y / q(0))^(1/5).
    let mut u = fifth_root(y) * 0.975_620_8;
    for _ in 0..2 {
        let (d, slope) = high_piece(u);
        u -= (d - y) / slope;
    }
    u
}

/// `f(1/2)` of the kernel: the force ratio where the two pieces meet.
#[inline(always)]
fn force_ratio_at_half() -> f32 {
    0.5 * horner_slope(&AXIAL_FORCE_LOW, 0.5).0
}

/// The slip ratio s in (0, 1) with `axial_force_ratio(s) = r`, for `r` in (0, 1);
/// 0 for `r <= 0` or NaN, 1 for `r >= 1`.
#[inline]
pub fn slip_ratio_of_force_ratio(r: f32) -> f32 {
    if r.is_nan() || r <= 0.0 {
        return 0.0;
    }
    if r >= 1.0 {
        return 1.0;
    }
    if r < force_ratio_at_half() {
        // f = s p(s), concave: Newton from the left, after one fixed-point step.
        let mut s = r / horner_slope(&AXIAL_FORCE_LOW, r * 0.424_413_2).0; // 4 / (3 pi)
        for _ in 0..3 {
            let (p, dp) = horner_slope(&AXIAL_FORCE_LOW, s);
            s -= (s * p - r) / (p + s * dp);
        }
        s
    } else {
        let u = high_root(1.0 - r); // exact: r >= 1/2
        1.0 - u * u
    }
}

/// `f'(s)`, the slope of the kernel's F/(mu P) in s, for s in [0, 1] (0 at and above 1).
#[inline]
pub fn force_ratio_slope(s: f32) -> f32 {
    if s >= 1.0 {
        return 0.0;
    }
    if s < 0.5 {
        let (p, dp) = horner_slope(&AXIAL_FORCE_LOW, s);
        p + s * dp
    } else {
        // df/ds = D'(u) / (2 u), u = sqrt(1 - s).
        let u = crate::float::kernels::sqrt::sqrt(1.0 - s);
        let (q, dq) = horner_slope(&AXIAL_FORCE_HIGH, u);
        0.5 * u * u * u * (5.0 * q + u * dq)
    }
}

/// The limit of `f(s)/s` as `s -> 0` in the kernel: `p(0)`, which is 3 pi / 4 to f32.
pub fn force_over_slip_limit() -> f32 {
    AXIAL_FORCE_LOW[0]
}

/// The slip ratio s in (0, 1] with `f(s)/s = q` for `q` in (1, [`force_over_slip_limit`]);
/// 1 for `q <= 1`, 0 for `q` at or above the limit (no finite mu: the no-slip limit).
#[inline]
pub fn slip_ratio_of_force_over_slip(q: f32) -> f32 {
    if q.is_nan() || q >= force_over_slip_limit() {
        return 0.0;
    }
    if q <= 1.0 {
        return 1.0;
    }
    let (p_half, _) = horner_slope(&AXIAL_FORCE_LOW, 0.5);
    if q > p_half {
        // f/s = p(s), nearly linear: p(s) ~ 3 pi / 4 - 3 s / 2.
        let mut s = (force_over_slip_limit() - q) * (2.0 / 3.0);
        for _ in 0..2 {
            let (p, dp) = horner_slope(&AXIAL_FORCE_LOW, s);
            s -= (p - q) / dp;
        }
        s
    } else {
        // H(u) = (1 - D(u)) / (1 - u^2) = q, from u0 with H ~ 1 + u^2.
        let mut u = crate::float::kernels::sqrt::sqrt(0.8 * (q - 1.0));
        for _ in 0..3 {
            let (d, dd) = high_piece(u);
            let w = 1.0 - u * u;
            let h = (1.0 - d) / w;
            let slope = (2.0 * u * h - dd) / w;
            u -= (h - q) / slope;
            u = u.clamp(0.0, core::f32::consts::FRAC_1_SQRT_2);
        }
        1.0 - u * u
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::float::kernels::axial_force::axial_force_ratio;
    use crate::reference::tangential;

    /// The f64 inverse of eq (21) by bisection (independent of the kernel).
    fn slip_of(r: f64, over_slip: bool) -> f64 {
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            let f = tangential::axial_force_ratio(mid);
            let v = if over_slip { f / mid } else { f };
            if (v < r) != over_slip {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    #[test]
    fn slip_ratio_from_force_ratio_sweep() {
        let mut worst = 0.0f64;
        for bits in (f32::MIN_POSITIVE.to_bits()..1.0f32.to_bits()).step_by(64 * 101) {
            let r = f32::from_bits(bits);
            let s = slip_ratio_of_force_ratio(r) as f64;
            let want = slip_of(r as f64, false);
            let cond = want * tangential::axial_force_ratio_slope(want) / r as f64;
            worst = worst.max((s / want - 1.0).abs() * cond);
            // And the kernel round trip: f(s) = r to a few ulps.
            let back = axial_force_ratio(s as f32);
            assert!((back / r - 1.0).abs() < 4e-7, "r {r} s {s} back {back}");
        }
        println!("slip_ratio_of_force_ratio worst {worst:.3e}");
        assert!(worst <= SLIP_RATIO_MAX_REL_ERROR as f64, "{worst:e}");
    }

    #[test]
    fn slip_ratio_from_force_over_slip_sweep() {
        let limit = force_over_slip_limit();
        let mut worst = 0.0f64;
        let n = 20_000;
        for k in 1..n {
            let q = 1.0 + (limit - 1.0) * k as f32 / n as f32;
            let s = slip_ratio_of_force_over_slip(q) as f64;
            let want = slip_of(q as f64, true);
            // Conditioning: d ln s / d ln q = h / (s h') with h' = (f' - h) / s.
            let f = tangential::axial_force_ratio(want);
            let slope = tangential::axial_force_ratio_slope(want);
            let cond = (f / want) / (f / want - slope);
            worst = worst.max((s / want - 1.0).abs() / cond);
        }
        println!("slip_ratio_of_force_over_slip worst {worst:.3e}");
        assert!(worst <= SLIP_RATIO_MAX_REL_ERROR as f64, "{worst:e}");
    }

    #[test]
    fn slope_matches_eq_21() {
        for k in 0..1000 {
            let s = k as f64 / 1000.0;
            let got = force_ratio_slope(s as f32) as f64;
            let want = tangential::axial_force_ratio_slope(s);
            assert!(
                (got - want).abs() < 2e-4 * want.max(1e-3),
                "s {s}: {got} {want}"
            );
        }
    }

    #[test]
    fn ends() {
        assert_eq!(slip_ratio_of_force_ratio(f32::NAN), 0.0);
        assert_eq!(slip_ratio_of_force_ratio(0.0), 0.0);
        assert_eq!(slip_ratio_of_force_ratio(1.0), 1.0);
        assert_eq!(slip_ratio_of_force_over_slip(1.0), 1.0);
        assert_eq!(slip_ratio_of_force_over_slip(f32::NAN), 0.0);
        assert_eq!(slip_ratio_of_force_over_slip(3.0), 0.0);
    }
}
