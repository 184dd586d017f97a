//! Inverse square root `x^(-1/2)` for f32: a bit-level first guess and three Newton
//! steps. `libm::sqrtf` costs about 52 instructions on the Cortex-M4F (software);
//! `micromath`'s is fast but about 5 % off. Used by the axial-force kernel
//! (`u = sqrt(1 - d/b)`) and by line contact (eqs 23, 28).

/// Maximum relative error of [`inv_sqrt`] over all positive finite f32 (exhaustive
/// test over [1, 4), which covers every input: the kernel is exact under scaling by 4
/// down to 2^-120, and scales smaller inputs up by 2^24 first).
pub const INV_SQRT_MAX_REL_ERROR: f32 = 1.0e-7;

/// First guess: the bits of x^(-1/2) are about `K - bits(x)/2` (3.4 % off at most).
const MAGIC: u32 = 0x5f37_6430;

/// Inputs below this are scaled by 2^24 first, so that `x/2` stays normal and the
/// kernel stays exact under scaling by 4.
const SCALE_BELOW: f32 = 7.523_164e-37; // 2^-120

/// `x^(-1/2)` for positive finite `x`, subnormals included (+inf for 0).
#[inline(always)]
pub fn inv_sqrt(x: f32) -> f32 {
    if x < SCALE_BELOW {
        if x == 0.0 {
            return f32::INFINITY;
        }
        return inv_sqrt_normal(x * 16_777_216.0) * 4096.0;
    }
    inv_sqrt_normal(x)
}

/// `x^(-1/2)` for `x >= 2^-120`: the per-sample path where the caller knows its range.
#[inline(always)]
pub(crate) fn inv_sqrt_normal(x: f32) -> f32 {
    let mut y = f32::from_bits(MAGIC.wrapping_sub(x.to_bits() >> 1));
    let half = 0.5 * x;
    // Newton: y <- y (3/2 - (x/2) y^2), formed as ((x/2) y) y to stay normal.
    for _ in 0..2 {
        y *= 1.5 - (half * y) * y;
    }
    y + y * (0.5 - (half * y) * y)
}

/// `sqrt(x)` for non-negative finite x, as `x x^(-1/2)`.
#[inline(always)]
pub fn sqrt(x: f32) -> f32 {
    if x == 0.0 { 0.0 } else { x * inv_sqrt(x) }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel_err(x: f32) -> f64 {
        let want = 1.0 / libm::sqrt(x as f64);
        (inv_sqrt(x) as f64 / want - 1.0).abs()
    }

    /// Every f32 in [1, 4): one full period of the scale symmetry.
    #[test]
    fn exhaustive_over_one_period() {
        let (lo, hi) = (1.0f32.to_bits(), 4.0f32.to_bits());
        let worst = (lo..hi)
            .map(|b| rel_err(f32::from_bits(b)))
            .fold(0.0, f64::max);
        println!("inv_sqrt worst relative error {worst:.3e}");
        assert!(worst <= INV_SQRT_MAX_REL_ERROR as f64, "{worst:e}");
    }

    #[test]
    fn scale_symmetry_and_extremes() {
        for x in [1.3f32, 2.9] {
            for k in -60..=60 {
                let s = libm::powf(4.0, k as f32);
                if (x * s).is_normal() {
                    assert_eq!(inv_sqrt(x * s), inv_sqrt(x) / libm::powf(2.0, k as f32));
                }
            }
        }
        for x in [f32::MIN_POSITIVE, f32::MAX] {
            assert!(rel_err(x) <= INV_SQRT_MAX_REL_ERROR as f64);
        }
        assert_eq!(sqrt(0.0), 0.0);
    }
}
