//! Line contact (paper section 8): a cylinder on a plane, or two long rollers with
//! the effective radius of eq (31). Loads are per unit length (N/m).

use super::chain::chain;
use core::f64::consts::PI;

pub(super) const SQRT_PI: f64 = 1.772_453_850_905_516;

/// Half-width of the contact strip `b = sqrt(4 P (1 - nu) R / (pi G))` (eq 22), m.
pub fn half_width(load: f64, nu: f64, g_modulus: f64, radius: f64) -> f64 {
    let s = libm::sqrt;
    chain(
        &[2.0, s(load), s(1.0 - nu), s(radius)],
        &[SQRT_PI, s(g_modulus)],
    )
}

/// Peak pressure `p0 = 2 P / (pi b) = sqrt(P G / (pi (1 - nu) R))`, Pa (0 at P = 0).
pub fn peak_pressure(load: f64, nu: f64, g_modulus: f64, radius: f64) -> f64 {
    let s = libm::sqrt;
    chain(&[s(load), s(g_modulus)], &[SQRT_PI, s(1.0 - nu), s(radius)])
}

/// Non-dimensional load `P* = P / ((1 - nu) G R)` (eq 24).
pub fn nondimensional_load(load: f64, nu: f64, g_modulus: f64, radius: f64) -> f64 {
    chain(&[load], &[1.0 - nu, g_modulus, radius])
}

/// Critical non-dimensional load `P0* = pi phi^2 / (4 mu^2)` (eq 25).
pub fn critical_nondimensional_load(phi: f64, mu: f64) -> f64 {
    let x = libm::fabs(phi);
    chain(&[PI, x, x], &[4.0, mu, mu])
}

/// Slip ratio `d/b = (P0*/P*)^(1/2) = (|phi| / (2 mu)) sqrt(pi (1 - nu) G R / P)`
/// (eq 23). 0 when phi = 0; +inf when P = 0 and phi != 0.
pub fn slip_ratio(load: f64, nu: f64, g_modulus: f64, radius: f64, mu: f64, phi: f64) -> f64 {
    let phi = libm::fabs(phi);
    if phi == 0.0 {
        return 0.0;
    }
    let s = libm::sqrt;
    chain(
        &[phi, SQRT_PI, s(1.0 - nu), s(g_modulus), s(radius)],
        &[2.0, mu, s(load)],
    )
}

/// `F / (mu P) = 2 s - s^2` for `s < 1` (eq 27), 1 at and above (eq 29).
pub fn axial_force_ratio(s: f64) -> f64 {
    if s >= 1.0 {
        1.0
    } else {
        libm::fmax(s, 0.0) * (2.0 - s)
    }
}

/// Critical angle `phi0 = 2 mu sqrt(P / (pi G (1 - nu) R))` (eq 28), rad.
pub fn critical_angle(load: f64, nu: f64, g_modulus: f64, radius: f64, mu: f64) -> f64 {
    let s = libm::sqrt;
    chain(
        &[2.0, mu, s(load)],
        &[SQRT_PI, s(g_modulus), s(1.0 - nu), s(radius)],
    )
}

/// Axial traction `X(y)` (Pa) of eq (26) across the strip of half-width b, with
/// `scale = mu p0 = 2 mu P/(pi b)` signed like phi and slip distance `d`.
pub fn traction(scale: f64, b: f64, d: f64, y: f64) -> f64 {
    let v = 1.0 - (y / b) * (y / b);
    if v <= 0.0 {
        return 0.0;
    }
    let mut t = libm::sqrt(v);
    if b > d {
        let u = (y - d) / (b - d);
        if u * u < 1.0 {
            t -= (1.0 - d / b) * libm::sqrt(1.0 - u * u); // eq (26b)
        }
    }
    scale * t
}
