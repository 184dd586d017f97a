//! Inverse cube root `x^(-1/3)` for f32: a bit-level first guess and three Newton
//! steps, no division, no library call (`libm::cbrtf` costs about 1580 instructions on
//! the Cortex-M4F because it works in soft f64). The slip ratio needs `P^(-1/3)`
//! (eq 16) and the critical angle `P^(1/3) = P (P^(-1/3))^2` (eq 18).

/// Maximum relative error of [`inv_cbrt`] over all positive finite f32 (measured by
/// the exhaustive test below over [1, 8), which covers every input: the kernel is
/// exact under scaling by 8 for normal inputs; subnormal inputs are scaled first).
pub const INV_CBRT_MAX_REL_ERROR: f32 = 1.0e-7;

/// First guess: the bits of x^(-1/3) are about `K - bits(x)/3` (3.4 % off at most).
const MAGIC: u32 = 0x54a2_32a0;

/// Inputs below this are scaled by 2^24 first, so that `x/3` stays normal and the
/// kernel stays exact under scaling by 8.
const SCALE_BELOW: f32 = 7.523_164e-37; // 2^-120

/// `x^(-1/3)` for positive finite `x` (including subnormals); +inf for 0. Other
/// inputs (negative, NaN, inf) give an unspecified finite or NaN value: callers check.
#[inline(always)]
pub fn inv_cbrt(x: f32) -> f32 {
    if x < SCALE_BELOW {
        if x == 0.0 {
            return f32::INFINITY;
        }
        // Scale by 2^24 (exact), then x^(-1/3) gains a factor 2^8.
        return inv_cbrt_normal(x * 16_777_216.0) * 256.0;
    }
    inv_cbrt_normal(x)
}

#[inline(always)]
fn inv_cbrt_normal(x: f32) -> f32 {
    let mut y = f32::from_bits(MAGIC.wrapping_sub(x.to_bits() / 3));
    let third = x * (1.0 / 3.0);
    // Newton for y^-3 = x: y <- y (4/3 - (x/3) y^3); error e -> about 2 e^2. The
    // product is formed as (x y)(y y) so that no factor leaves the normal range.
    for _ in 0..2 {
        y *= 4.0 / 3.0 - (third * y) * (y * y);
    }
    // Last step as a correction, so that its rounding is that of a small term.
    let e = 1.0 - (x * y) * (y * y);
    y + y * e * (1.0 / 3.0)
}

/// `x^(1/3)` for non-negative finite x, from the inverse: `x (x^(-1/3))^2`.
#[inline(always)]
pub fn cbrt(x: f32) -> f32 {
    if x == 0.0 {
        return 0.0;
    }
    let r = inv_cbrt(x);
    x * r * r
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel_err(x: f32) -> f64 {
        let want = 1.0 / libm::cbrt(x as f64);
        (inv_cbrt(x) as f64 / want - 1.0).abs()
    }

    /// Every f32 in [1, 8): three octaves, one full period of the scale symmetry.
    #[test]
    fn exhaustive_over_one_period() {
        let (lo, hi) = (1.0f32.to_bits(), 8.0f32.to_bits());
        let worst = (lo..hi)
            .map(|b| rel_err(f32::from_bits(b)))
            .fold(0.0, f64::max);
        println!("inv_cbrt worst relative error {worst:.3e}");
        assert!(worst <= INV_CBRT_MAX_REL_ERROR as f64, "{worst:e}");
    }

    #[test]
    fn scale_symmetry_and_extremes() {
        for x in [1.7f32, 3.3, 7.9] {
            for k in -40..=40 {
                let s = libm::powf(8.0, k as f32);
                if (x * s).is_normal() {
                    assert_eq!(
                        inv_cbrt(x * s),
                        inv_cbrt(x) / libm::powf(2.0, k as f32),
                        "{x} {k}"
                    );
                }
            }
        }
        for x in [f32::MIN_POSITIVE, 1e-40, 1e-45, f32::MAX, 1e38] {
            assert!(
                rel_err(x) <= INV_CBRT_MAX_REL_ERROR as f64,
                "{x:e}: {:e}",
                rel_err(x)
            );
        }
        assert_eq!(inv_cbrt(0.0), f32::INFINITY);
        assert_eq!(cbrt(0.0), 0.0);
        assert!((cbrt(27.0) - 3.0).abs() <= 3.0 * 2.0 * f32::EPSILON);
    }
}
