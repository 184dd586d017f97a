//! The tangential problem (paper sections 6-7): traction, stick and slip zones,
//! slip ratio, critical load and axial force, eqs (8)-(21) and (30).

use super::chain::chain;
use core::f64::consts::PI;

/// Whether part of the contact still sticks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Regime {
    /// `d/b < 1`: a stick zone at the leading edge, microslip over the rest.
    Partial,
    /// `d/b >= 1`: slip over the whole contact; the axial force saturates at mu P.
    Gross,
}

impl Regime {
    /// The regime of slip ratio `s = d/b`; `s = 1` counts as gross slip.
    pub fn of(slip_ratio: f64) -> Self {
        if slip_ratio < 1.0 {
            Regime::Partial
        } else {
            Regime::Gross
        }
    }

    /// `"partial"` or `"gross"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Regime::Partial => "partial",
            Regime::Gross => "gross",
        }
    }
}

/// Slip ratio `d/b = pi G a b |phi| / (3 mu P)` (eq 15), written with the scene's
/// Hertz scale `v = (L^3/P)^(1/3)` as `pi G m n v^2 |phi| / (3 mu P^(1/3))`.
/// Defined limits: 0 when phi = 0 (no misalignment, no slip), +inf when P = 0 and
/// phi != 0 (an unloaded contact slips).
pub fn slip_ratio(g_modulus: f64, mu: f64, mn: f64, hertz_scale: f64, load: f64, phi: f64) -> f64 {
    let phi = libm::fabs(phi);
    if phi == 0.0 {
        return 0.0;
    }
    let v = hertz_scale;
    chain(
        &[PI, g_modulus, mn, v, v, phi],
        &[3.0, mu, libm::cbrt(load)],
    )
}

/// `F / (mu P)` as a function of `s = d/b`: eq (21) for `s < 1`, 1 for `s >= 1`
/// (eq 21 reaches 1 at `s = 1` with zero first and second derivatives).
///
/// Eq (21) is rearranged so that nothing cancels: `1 - (1 + s^2/2) sqrt(1 - s^2)`
/// equals `s^4 (3 + s^2) / (4 (1 + (1 + s^2/2) sqrt(1 - s^2)))`, and the other term
/// `(3 s / 2) acos(s)` is positive; the series `3 pi s/4 - 3 s^2/2 + s^4/8 + ...`
/// and the limit `1 - (4 sqrt 2 / 5)(1 - s)^(5/2)` follow to the last ulps.
pub fn axial_force_ratio(s: f64) -> f64 {
    if s >= 1.0 {
        return 1.0;
    }
    if s <= 0.0 {
        return 0.0;
    }
    let s2 = s * s;
    let root = libm::sqrt((1.0 - s) * (1.0 + s));
    let first = s2 * s2 * (3.0 + s2) / (4.0 * (1.0 + (1.0 + 0.5 * s2) * root));
    // Eq (21) is below 1 for s < 1 by (4 sqrt 2 / 5)(1 - s)^(5/2); once that is below an
    // ulp the sum can round one ulp above 1: F never exceeds mu P.
    libm::fmin(first + 1.5 * s * libm::acos(s), 1.0)
}

/// `d(F/(mu P))/ds = (3/2) (acos s - s sqrt(1 - s^2))` for `s < 1`, 0 beyond.
pub fn axial_force_ratio_slope(s: f64) -> f64 {
    if s >= 1.0 {
        return 0.0;
    }
    let s = libm::fmax(s, 0.0);
    1.5 * (libm::acos(s) - s * libm::sqrt((1.0 - s) * (1.0 + s)))
}

/// Non-dimensional load `P* = 2 P / ((1 - nu)^2 G (R1 + R2) sqrt(R1 R2))` (eq 17).
pub fn nondimensional_load(load: f64, nu: f64, g_modulus: f64, r1: f64, r2: f64) -> f64 {
    let one_nu = 1.0 - nu;
    chain(
        &[load],
        &[
            one_nu,
            one_nu,
            g_modulus,
            half_sum(r1, r2),
            libm::sqrt(r1),
            libm::sqrt(r2),
        ],
    )
}

/// `(R1 + R2) / 2` without overflow (R1 = R2 = f64::MAX) and exact for subnormal radii.
pub fn half_sum(r1: f64, r2: f64) -> f64 {
    let sum = r1 + r2;
    if sum.is_finite() {
        0.5 * sum
    } else {
        0.5 * r1 + 0.5 * r2
    }
}

/// Critical non-dimensional load `P0* = (pi m n theta)^3 / (48 mu^3)` (eq 18),
/// given `g = m n theta`.
pub fn critical_nondimensional_load(g: f64, mu: f64) -> f64 {
    chain(&[PI, g, PI, g, PI, g], &[48.0, mu, mu, mu])
}

/// Axial traction `X(x, y)` (Pa) of eqs (11), (13), (14) on an ellipse of semi-axes
/// a (along the rollers, x) and b (rolling direction, y), with `scale = mu p0` signed
/// like phi and slip distance `d = (d/b) b`. The stick zone is `(y - d)^2 < (c - d)^2`
/// with `c(x) = b sqrt(1 - x^2/a^2)` (eq 10); 0 outside the contact.
pub fn elliptic_traction(scale: f64, a: f64, b: f64, d: f64, x: f64, y: f64) -> f64 {
    let ex = 1.0 - (x / a) * (x / a);
    let inside = ex - (y / b) * (y / b);
    if ex <= 0.0 || inside <= 0.0 {
        return 0.0;
    }
    let c = b * libm::sqrt(ex);
    let mut t = libm::sqrt(inside);
    if c > d {
        let u = (y - d) / (c - d);
        if u * u < 1.0 {
            t -= (c - d) / b * libm::sqrt(1.0 - u * u); // eq (11b) with A = (c - d)/b (eq 13)
        }
    }
    scale * t
}

/// The stick zone across the rolling direction at axial position x: `y` from
/// `2d - c(x)` to `c(x)` (the leading edge; eqs 10, 11, 14), or `None` where the
/// whole section slips (`c(x) <= d`) or x lies outside the ellipse.
pub fn elliptic_stick_zone(a: f64, b: f64, d: f64, x: f64) -> Option<(f64, f64)> {
    let ex = 1.0 - (x / a) * (x / a);
    if ex <= 0.0 {
        return None;
    }
    let c = b * libm::sqrt(ex);
    if c > d { Some((2.0 * d - c, c)) } else { None }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axial_force_ratio_small_s_series() {
        for &s in &[1e-12, 1e-8, 1e-4, 1e-3] {
            let s2: f64 = s * s;
            let series = 3.0 * PI * s / 4.0 - 1.5 * s2 + s2 * s2 / 8.0 + s2 * s2 * s2 / 80.0;
            let r = axial_force_ratio(s);
            assert!((r / series - 1.0).abs() < 1e-15, "s={s} {r} {series}");
        }
    }

    #[test]
    fn axial_force_ratio_near_gross_slip() {
        // 1 - F/(mu P) ~ (4 sqrt 2 / 5)(1 - s)^(5/2); next term is O((1-s)^(7/2)).
        for &e in &[1e-3, 1e-4, 1e-5] {
            let s: f64 = 1.0 - e;
            let lead = 4.0 * libm::sqrt(2.0) / 5.0 * libm::pow(e, 2.5);
            let got = 1.0 - axial_force_ratio(s);
            // Next term O(e) relative; F/(mu P) itself is rounded to ~eps absolute.
            assert!(
                (got - lead).abs() < 2.0 * e * lead + 4.0 * f64::EPSILON,
                "e={e} {got} {lead}"
            );
        }
    }

    #[test]
    fn slope_is_the_derivative() {
        for &s in &[0.01, 0.3, 0.7, 0.99] {
            let h = 1e-6;
            let fd = (axial_force_ratio(s + h) - axial_force_ratio(s - h)) / (2.0 * h);
            assert!((fd - axial_force_ratio_slope(s)).abs() < 1e-8);
        }
    }
}
