//! Below the tables (theta < 2^-32 for g, theta < 2^-40 for 1/m, g < 2^-27 for theta(g))
//! the reference README's small-theta asymptotics are exact in f32 (their error falls
//! like theta^2: 3.4e-8 at 1e-3; what is left is f32's rounding, within 5e-7):
//! `g = (8/pi^2)^(1/3) Lam^(1/6) theta^(2/3)`, `m = (8 Lam / (pi theta^2))^(1/3)`,
//! `Lam = ln(8 sqrt(Lam) / theta) - 1`. This path is rare (phi of a nanoradian or
//! less) and uses libm's `logf` for Lam: a few hundred instructions.

use super::cbrt;
use super::sqrt;

// One copy each of what the asymptotics call, out of line: this path is rare and its
// flash counts in the estimator's budget (`cargo xtask firmware`).
#[inline(never)]
fn ln(x: f32) -> f32 {
    libm::logf(x)
}
use cbrt::cbrt_cold as cbrt;
#[inline(never)]
fn sqrt(x: f32) -> f32 {
    sqrt::sqrt(x)
}

/// `(8/pi^2)^(1/3)`.
const G_SCALE: f32 = 0.932_388_1;
/// `(8/pi)^(1/3)`.
const M_SCALE: f32 = 1.365_568_2;
/// `ln 8 - 1`.
const LN8_MINUS_1: f32 = 1.079_441_5;

/// `Lam` from `ln theta` by fixed-point iteration (contraction 1/(2 Lam) < 0.02).
#[inline(never)]
fn lambda(ln_theta: f32) -> f32 {
    let mut lam = LN8_MINUS_1 - ln_theta;
    for _ in 0..4 {
        lam = LN8_MINUS_1 + 0.5 * ln(lam) - ln_theta;
    }
    lam
}

/// `theta^(2/3)` for positive theta (subnormals too) without leaving the normal range:
/// split off a power of 8, exactly.
#[inline(never)]
fn two_thirds_power(theta: f32) -> f32 {
    let (mut x, mut k) = (theta, 0i32);
    if x < f32::MIN_POSITIVE {
        x *= 16_777_216.0; // 2^24
        k = -24;
    }
    // The biased exponent is below 2^8 and k is 0 or -24: no operation here can wrap.
    let e = ((x.to_bits() >> 23) as i32)
        .wrapping_sub(127)
        .div_euclid(3)
        .wrapping_mul(3);
    let mantissa = libm::ldexpf(x, e.wrapping_neg()); // in [1, 8)
    libm::ldexpf(
        cbrt(mantissa * mantissa),
        e.wrapping_add(k).wrapping_mul(2) / 3,
    )
}

/// `g(theta) = m n theta` for `0 < theta < 2^-40`, subnormals included.
pub fn g_small(theta: f32) -> f32 {
    let lam = lambda(ln(theta));
    G_SCALE * sqrt(cbrt(lam)) * two_thirds_power(theta)
}

/// `1/m(theta)` for `0 < theta < 2^-40`.
pub fn inv_m_small(theta: f32) -> f32 {
    let lam = lambda(ln(theta));
    two_thirds_power(theta) / (cbrt(lam) * M_SCALE)
}

/// The theta with `g(theta) = g`, for `0 < g < 2^-27`.
pub fn theta_small(g: f32) -> f32 {
    // theta ~ (g/2)^(3/2) underflows f32 below this; the iteration would meet log(0).
    if g < 7.888_609e-31 {
        return 0.0; // 2^-100
    }
    // theta = q^(3/2), q = g / (G_SCALE Lam^(1/6)); Lam depends on theta only by its log.
    let mut theta = 0.0;
    let mut ln_theta = 1.5 * ln(g / (G_SCALE * 1.7));
    for _ in 0..4 {
        let lam = lambda(ln_theta);
        let q = g / (G_SCALE * sqrt(cbrt(lam)));
        theta = q * sqrt(q);
        ln_theta = 1.5 * ln(q);
    }
    theta
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::normal;

    #[test]
    fn matches_the_reference_below_the_tables() {
        for theta in [1e-44f32, 1e-40, 1e-30, 1e-20, 1e-13, 9e-13, 1e-11, 2.3e-10] {
            let s = normal::ellipse_shape(theta as f64).unwrap();
            let e = (g_small(theta) as f64 / s.g() - 1.0).abs();
            assert!(e < 5e-7, "g at {theta:e}: {e:e}");
            let e = (inv_m_small(theta) as f64 * s.m - 1.0).abs();
            assert!(e < 5e-7, "1/m at {theta:e}: {e:e}");
            if theta > 1e-30 {
                let back = theta_small(s.g() as f32) as f64;
                assert!(
                    (back / theta as f64 - 1.0).abs() < 1e-6,
                    "theta of g at {theta:e}"
                );
            }
        }
    }
}
