//! `1/x` in f32 without a division: a bit-pattern estimate refined by Newton's
//! iteration `y (2 - x y)`, four multiply-subtract steps. On a core without an FPU a
//! division routine (`__divsf3`, 528 bytes of flash on a Cortex-M0) is linked by the
//! first `/` on f32; the monitor's and the fixed-point core's few divisions (once per
//! scene, per time step change, per trend interval) go through this instead, so that a
//! monitoring node fits 16 KiB.
//!
//! Error: at most 1 ulp of the exact `1/x` for positive normal `x` below 2^126 (the
//! test below measures every exponent over 2^15 mantissas); `a * recip(b)` is then
//! within 2 ulp of `a / b`.

/// `1/x` for `x` in [2^-126, 2^126); `+inf` below (0 and subnormals too), 0 at and
/// above 2^126, NaN for negative or NaN `x`.
pub(crate) fn recip(x: f32) -> f32 {
    let bits = x.to_bits();
    if bits < 0x0080_0000 {
        return f32::INFINITY;
    }
    if bits >= 0x7e80_0000 {
        return if bits <= 0x7f80_0000 { 0.0 } else { f32::NAN };
    }
    // Within 12 % of 1/x: the exponent negated and the mantissa mirrored.
    let mut y = f32::from_bits(0x7ef3_11c7_u32.wrapping_sub(bits));
    for _ in 0..4 {
        y *= 2.0 - x * y;
    }
    y
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The worst error in ulps of the correctly rounded 1/x, over every exponent and
    /// 2^15 mantissas each (every 256th of the 2^23).
    #[test]
    fn within_one_ulp() {
        let mut worst = 0u32;
        for exponent in 1..253u32 {
            for m in (0..1u32 << 23).step_by(256) {
                let x = f32::from_bits(exponent << 23 | m);
                let exact = (1.0 / f64::from(x)) as f32;
                let got = recip(x);
                let ulps = got.to_bits().abs_diff(exact.to_bits());
                worst = worst.max(ulps);
            }
        }
        std::println!("recip: worst {worst} ulp");
        assert!(worst <= 1, "{worst} ulp");
    }

    #[test]
    fn outside_its_range() {
        assert_eq!(recip(0.0), f32::INFINITY);
        assert_eq!(recip(1e-40), f32::INFINITY);
        assert_eq!(recip(f32::MAX), 0.0);
        assert_eq!(recip(f32::INFINITY), 0.0);
        assert!(recip(-1.0).is_nan());
        assert!(recip(f32::NAN).is_nan());
    }
}
