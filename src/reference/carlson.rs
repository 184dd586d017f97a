//! Carlson's symmetric elliptic integral of the second kind, R_D.
//!
//! The paper's equations (5)-(6) need `K - E` and `E - k'^2 K` for complementary
//! moduli `k'` from 1e-150 to 1. Written in Legendre form they cancel (the parameter
//! `1 - k'^2` rounds to 1 at small `k'`); in Carlson's form they do not (DLMF 19.25.1):
//!
//! ```text
//! K - E        = (k^2 / 3)       R_D(0, k'^2, 1)
//! E - k'^2 K   = (k^2 k'^2 / 3)  R_D(0, 1, k'^2)
//! ```

/// `R_D(x, y, z) = 3/2 ∫_0^∞ dt / ((t+x)^(1/2) (t+y)^(1/2) (t+z)^(3/2))` for
/// `x, y >= 0` (at most one zero) and `z > 0`, by the duplication theorem and
/// Carlson's fifth-order series (DLMF 19.36.2). Relative error a few ulps. The
/// reference itself takes the pair (below); this one is the tests' and tooling's.
#[cfg(any(test, feature = "_internals"))]
pub fn carlson_rd(x: f64, y: f64, z: f64) -> f64 {
    #[cfg(test)]
    super::cost::count_rd();
    let (x0, y0) = (x, y);
    let mut x = x;
    let mut y = y;
    let mut z = z;
    let a0 = (x + y + 3.0 * z) / 5.0;
    let mut a = a0;
    // The series' truncation error is about 4^-6m times the initial spread to the
    // sixth power; stop once the scaled spread is below 2^-9 (error < 1e-17).
    let spread = libm::fmax(
        libm::fmax(libm::fabs(a0 - x), libm::fabs(a0 - y)),
        libm::fabs(a0 - z),
    );
    let mut sum = 0.0;
    let mut scale = 1.0; // 4^-m
    // 40 duplications shrink any spread by 4^40; the cap only guards NaN input.
    for _ in 0..40 {
        if spread * scale < libm::fabs(a) / 512.0 {
            break;
        }
        let (sx, sy, sz) = (libm::sqrt(x), libm::sqrt(y), libm::sqrt(z));
        let lambda = sx * sy + sx * sz + sy * sz;
        sum += scale / (sz * (z + lambda));
        scale *= 0.25;
        x = (x + lambda) * 0.25;
        y = (y + lambda) * 0.25;
        z = (z + lambda) * 0.25;
        a = (a + lambda) * 0.25;
    }
    series(a0 - x0, a0 - y0, scale, a) + 3.0 * sum
}

/// Carlson's fifth-order series (DLMF 19.36.2) after the duplications: `dx = A0 - x0`,
/// `dy = A0 - y0`, `scale = 4^-m`, `a = A_m`; the duplications' sum is added by the caller.
fn series(dx: f64, dy: f64, scale: f64, a: f64) -> f64 {
    let xx = dx * scale / a;
    let yy = dy * scale / a;
    let zz = -(xx + yy) / 3.0;
    let xy = xx * yy;
    let z2 = zz * zz;
    let e2 = xy - 6.0 * z2;
    let e3 = (3.0 * xy - 8.0 * z2) * zz;
    let e4 = 3.0 * (xy - z2) * z2;
    let e5 = xy * z2 * zz;
    let series = 1.0 - 3.0 * e2 / 14.0 + e3 / 6.0 + 9.0 * e2 * e2 / 88.0
        - 3.0 * e4 / 22.0
        - 9.0 * e2 * e3 / 52.0
        + 3.0 * e5 / 26.0;
    scale * series / (a * libm::sqrt(a))
}

/// `(R_D(0, y, 1), R_D(0, 1, y))` for `y = k'^2` in (0, 1], in one loop: the duplication
/// (DLMF 19.26.20) moves the three arguments alike whichever of them is R_D's third, so
/// the two integrals share their square roots and differ only in the sum's terms and the
/// final series. Each stops as [`carlson_rd`] does (the loop runs until both would);
/// relative error a few ulps.
pub(crate) fn carlson_rd_pair(y: f64) -> (f64, f64) {
    #[cfg(test)]
    super::cost::count_rd_pair();
    let a10 = (y + 3.0) / 5.0; // A0 of R_D(0, y, 1)
    let a20 = (1.0 + 3.0 * y) / 5.0; // A0 of R_D(0, 1, y)
    // max |A0 - x0|: for y in (0, 1], A0 itself and max(A0, 1 - A0).
    let spread1 = a10.max((a10 - y).abs()).max((a10 - 1.0).abs());
    let spread2 = a20.max((a20 - y).abs()).max((a20 - 1.0).abs());
    // The first duplication (always needed: the spreads are at least 0.4), at
    // (0, y, 1): lambda = sqrt(y).
    let sy = libm::sqrt(y);
    let mut sum1 = 1.0 / (1.0 + sy);
    let mut sum2 = 1.0 / (sy * (y + sy));
    let mut scale = 0.25; // 4^-m
    let (mut x, mut yv, mut z) = (sy * 0.25, (y + sy) * 0.25, (1.0 + sy) * 0.25);
    let (mut a1, mut a2) = ((a10 + sy) * 0.25, (a20 + sy) * 0.25);
    // 40 duplications shrink any spread by 4^40; the cap only guards NaN input.
    for _ in 1..40 {
        if spread1 * scale < a1.abs() / 512.0 && spread2 * scale < a2.abs() / 512.0 {
            break;
        }
        let (sx, sy, sz) = (libm::sqrt(x), libm::sqrt(yv), libm::sqrt(z));
        let lambda = sx * sy + sx * sz + sy * sz;
        sum1 += scale / (sz * (z + lambda));
        sum2 += scale / (sy * (yv + lambda));
        scale *= 0.25;
        x = (x + lambda) * 0.25;
        yv = (yv + lambda) * 0.25;
        z = (z + lambda) * 0.25;
        a1 = (a1 + lambda) * 0.25;
        a2 = (a2 + lambda) * 0.25;
    }
    (
        series(a10, a10 - y, scale, a1) + 3.0 * sum1,
        series(a20, a20 - 1.0, scale, a2) + 3.0 * sum2,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pair_is_the_two_calls() {
        for &y in &[1e-300, 1e-30, 1e-8, 0.01, 0.3, 0.9, 1.0 - 1e-12, 1.0] {
            let (p1, p2) = carlson_rd_pair(y);
            let (r1, r2) = (carlson_rd(0.0, y, 1.0), carlson_rd(0.0, 1.0, y));
            assert!(
                (p1 / r1 - 1.0).abs() < 4.0 * f64::EPSILON,
                "y={y} {p1} {r1}"
            );
            assert!(
                (p2 / r2 - 1.0).abs() < 4.0 * f64::EPSILON,
                "y={y} {p2} {r2}"
            );
        }
        let (p1, p2) = carlson_rd_pair(1.0);
        assert_eq!(p1, p2);
    }

    #[test]
    fn closed_forms() {
        // R_D(0, 1, 1) = 3 pi / 4; R_D(x, x, x) = x^(-3/2).
        let pi = core::f64::consts::PI;
        assert!((carlson_rd(0.0, 1.0, 1.0) / (0.75 * pi) - 1.0).abs() < 4e-16);
        assert!((carlson_rd(4.0, 4.0, 4.0) / 0.125 - 1.0).abs() < 4e-16);
        // Carlson (1995), table of test values (14 digits published).
        assert!((carlson_rd(0.0, 2.0, 1.0) / 1.797_210_352_103_4 - 1.0).abs() < 1e-13);
        assert!((carlson_rd(2.0, 3.0, 4.0) / 0.165_105_272_942_61 - 1.0).abs() < 1e-13);
    }
}
