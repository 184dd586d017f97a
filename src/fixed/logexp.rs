//! Base-2 logarithm of an integer and exponential of a Q8.24 logarithm, for the
//! fixed-point core's logarithmic number system: products, quotients and cube roots
//! become additions, shifts and a division by 3.

use super::uniform::ONE;
use super::tables::{EXP2_FRACTION, LOG2_MANTISSA};

/// Maximum error of [`log2_u32`] in log2 units (the relative error of the number it
/// stands for is 0.69 times this), over every u32: the table part is measured over
/// all 2^24 fractions it can see, plus 8.6e-8 for the bits below them (test below).
pub const LOG2_MAX_ERROR: f64 = 3.9e-7;

/// [`log2_u32`] exceeds `log2(x)` by at most this, in Q8.24 units (2^-24), over every
/// u32: the table part's largest excess over all 2^24 fractions is 0.497 (test below),
/// and dropping the bits below them only lowers the result.
pub const LOG2_MAX_EXCESS: f64 = 0.5;

/// Maximum relative error of the Q8.24 exp2 (`exp2_fixed`) before the final
/// truncation to an integer, over all 2^24 Q8.24 fractions (test below).
pub const EXP2_MAX_REL_ERROR: f64 = 3.4e-7;

/// `log2(x)` in Q8.24 for `x >= 1` (`x = 0` gives `i32::MIN`, standing for -inf).
#[inline(always)]
pub fn log2_u32(x: u32) -> i32 {
    if x == 0 {
        return i32::MIN;
    }
    let (lz, normalized) = normalize(x);
    // The bits below the leading one, as a Q0.32 fraction, then Q8.24.
    let fraction = (normalized << 1) >> 8;
    // The table covers [0, 1): the default is never taken. The octave (lz <= 31 for
    // x > 0) plus a mantissa in [0, 2^24] stays below 2^29: no wrap.
    let mantissa = LOG2_MANTISSA.eval(fraction as i32).unwrap_or_default();
    ((31 - lz as i32) << 24).wrapping_add(mantissa)
}

/// [`log2_u32`] for `x >= 1`, without its test for 0 (`x = 0` gives an unspecified
/// value, never a panic): for counts that a scene's range already holds at 1 or above.
#[inline(always)]
pub(crate) fn log2_positive(x: u32) -> i32 {
    // As `normalize`, with the shift wrapping: 0 shifts by 32 where `CLZ` gives it.
    #[cfg(all(target_arch = "arm", not(target_has_atomic = "32")))]
    let (lz, normalized) = normalize_by_search(x);
    #[cfg(not(all(target_arch = "arm", not(target_has_atomic = "32"))))]
    let (lz, normalized) = {
        let lz = x.leading_zeros();
        (lz, x.wrapping_shl(lz))
    };
    let fraction = (normalized << 1) >> 8;
    let mantissa = LOG2_MANTISSA.eval(fraction as i32).unwrap_or_default();
    // lz <= 32 (32 for x = 0 only): the subtraction cannot wrap.
    (31 - lz as i32).wrapping_shl(24).wrapping_add(mantissa)
}

/// `x / 3` for non-negative x, exactly, by shifts (a Cortex-M0 has no divider).
/// `(lz, x << lz)` for x > 0, lz its leading zeros: one `CLZ` where the core has
/// it; on ARMv6-M (the Cortex-M0; the Arm target without compare-and-swap atomics)
/// [`normalize_by_search`], since `leading_zeros` would call `__clzsi2` there.
#[inline(always)]
fn normalize(x: u32) -> (u32, u32) {
    #[cfg(all(target_arch = "arm", not(target_has_atomic = "32")))]
    return normalize_by_search(x);
    #[cfg(not(all(target_arch = "arm", not(target_has_atomic = "32"))))]
    {
        let lz = x.leading_zeros();
        (lz, x << lz)
    }
}

/// [`normalize`] without `CLZ`: the bits below the leading one all set, then a de
/// Bruijn multiply and a 32-byte table give its position (about 16 instructions on
/// the Cortex-M0, without branches, against about 30 for `__clzsi2`). Tested on the
/// host against `leading_zeros`.
#[cfg_attr(
    not(all(target_arch = "arm", not(target_has_atomic = "32"))),
    allow(dead_code)
)]
#[inline(always)]
fn normalize_by_search(x: u32) -> (u32, u32) {
    /// Leading zeros `31 - k` of `2^(k+1) - 1`, at `(that * 0x07c4_acdd) >> 27`.
    const LZ: [u8; 32] = [
        31, 22, 30, 21, 18, 10, 29, 2, 20, 17, 15, 13, 9, 6, 28, 1, 23, 19, 11, 3, 16, 14, 7,
        24, 12, 4, 8, 25, 5, 26, 27, 0,
    ];
    let mut v = x;
    v |= v >> 1;
    v |= v >> 2;
    v |= v >> 4;
    v |= v >> 8;
    v |= v >> 16;
    let lz = LZ[(v.wrapping_mul(0x07c4_acdd) >> 27) as usize] as u32;
    // lz <= 31: the shift cannot overflow (wrapping only drops the check).
    (lz, x.wrapping_shl(lz))
}

#[inline(always)]
pub fn div3(x: i32) -> i32 {
    let x = x as u32;
    // Hacker's Delight divu3: q ~ x * 0.010101...b, then one correction. The partial
    // sums only truncate, so q <= x / 3 and r = x - 3q is small and non-negative: no
    // operation wraps (the wrapping forms only drop the overflow checks).
    let mut q = (x >> 2).wrapping_add(x >> 4);
    q = q.wrapping_add(q >> 4);
    q = q.wrapping_add(q >> 8);
    q = q.wrapping_add(q >> 16);
    let r = x.wrapping_sub(q.wrapping_mul(3));
    q.wrapping_add(r.wrapping_mul(11) >> 5) as i32
}

/// `2^l` (l in Q8.24) as an unsigned fixed-point number with `frac_bits` fraction
/// bits, truncated; saturates at `u32::MAX`, flushes to 0 below its resolution.
#[inline(always)]
pub fn exp2_fixed(l: i32, frac_bits: u32) -> u32 {
    if l == i32::MIN {
        return 0;
    }
    exp2_finite(l, frac_bits)
}

/// [`exp2_fixed`] for an `l` that is a difference of finite logarithms, never
/// `i32::MIN` (the stand-in for log2 0): the same value without that test.
#[inline(always)]
pub(crate) fn exp2_finite(l: i32, frac_bits: u32) -> u32 {
    let k = l >> 24; // floor
    let mantissa = match EXP2_FRACTION.eval(l & (ONE - 1)) {
        Some(v) => v as u32, // 2^f in Q8.24, in [2^24, 2^25)
        None => ONE as u32,  // unreachable: the table covers [0, 1)
    };
    // k in [-128, 127]; frac_bits beyond 2^8 saturates like any large shift.
    let shift = k.wrapping_add(frac_bits.min(256) as i32).wrapping_sub(24);
    if shift >= 7 {
        u32::MAX
    } else if shift >= 0 {
        mantissa << shift
    } else if shift > -26 {
        mantissa >> -shift
    } else {
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log2_exhaustive_over_its_fractions_and_sampled_everywhere() {
        // The table sees the 24 bits below the leading one: the octave [2^24, 2^25)
        // holds every such fraction exactly. Larger x lose bits below those 24, which
        // moves log2 by less than 2^-24 / ln 2 = 8.6e-8.
        let err = |x: u32| (log2_u32(x) as f64 / ONE as f64 - (x as f64).log2()).abs();
        let table = ((1u32 << 24)..(1u32 << 25)).map(err).fold(0.0, f64::max);
        let excess = ((1u32 << 24)..(1u32 << 25))
            .map(|x| log2_u32(x) as f64 - (x as f64).log2() * ONE as f64)
            .fold(f64::MIN, f64::max);
        println!("log2_u32 largest excess {excess:.3} units");
        assert!(excess <= LOG2_MAX_EXCESS, "{excess}");
        println!("log2_u32 worst table error {table:.3e}");
        assert!(table + 8.6e-8 <= LOG2_MAX_ERROR, "{table:e}");
        let sampled = (1u32..=u32::MAX)
            .step_by(9973)
            .chain([1, 2, 3, u32::MAX])
            .map(err)
            .fold(0.0, f64::max);
        assert!(sampled <= LOG2_MAX_ERROR, "{sampled:e}");
        assert_eq!(log2_u32(0), i32::MIN);
        assert_eq!(log2_u32(1), 0);
        assert_eq!(log2_u32(1 << 20), 20 << 24);
    }

    #[test]
    fn normalize_by_search_counts_leading_zeros() {
        for x in (1u32..=u32::MAX)
            .step_by(7919)
            .chain((0..32).map(|k| 1 << k))
            .chain((1..32).map(|k| (1 << k) - 1))
            .chain([u32::MAX])
        {
            let lz = x.leading_zeros();
            assert_eq!(normalize_by_search(x), (lz, x << lz), "{x}");
        }
    }

    #[test]
    fn div3_is_exact() {
        for x in (0..i32::MAX)
            .step_by(7919)
            .chain([0, 1, 2, 3, 4, i32::MAX, i32::MAX - 1])
        {
            assert_eq!(div3(x), x / 3, "{x}");
        }
    }

    #[test]
    fn exp2_relative_error() {
        let mut worst: f64 = 0.0;
        for f in 0..ONE {
            // 2^(5 + f) with 24 fraction bits keeps 29 significant bits.
            let l = 5 * ONE + f;
            let got = exp2_fixed(l, 24) as f64 / ONE as f64;
            let want = (l as f64 / ONE as f64).exp2();
            worst = worst.max((got / want - 1.0).abs());
        }
        println!("exp2_fixed worst relative error {worst:.3e}");
        assert!(worst <= EXP2_MAX_REL_ERROR, "{worst:e}");
        assert_eq!(exp2_fixed(40 * ONE, 0), u32::MAX);
        assert_eq!(exp2_fixed(-40 * ONE, 0), 0);
        assert_eq!(exp2_fixed(i32::MIN, 10), 0);
        assert_eq!(exp2_fixed(3 * ONE, 0), 8);
    }
}
