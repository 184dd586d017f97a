//! `ln x` for the series' `ln(1/k')` without a division (libm's `log` takes one), by
//! a table of 128 points made at compile time.
//!
//! `x = 2^k z` with z in `[0.6875, 1.375)`; the top 7 bits of z's mantissa (from
//! 0.6875 on) pick `c_i`, the table holds `1/c_i` and `ln c_i`; then `r = z/c_i - 1`
//! (`|r| < 2^-8`) and `ln x = k ln 2 + ln c_i + ln(1 + r)`, the last by its series
//! through `r^7` (the first term left out below `2^-64/8`). `ln c_i` comes from
//! `2 atanh((c - 1)/(c + 1))` summed at compile time to within 2 ulps of itself.
//!
//! Domain: the series' `p = k'^2` below `2^-9` (`ln p < -6.2`: nothing cancels in the
//! sum). Error: within 1.5 `f64::EPSILON` (relative) of libm's `log` there (asserted
//! below over `2^-100` to `2^-9`). Cost: a table read (16 bytes), 11 multiply-adds, no
//! division and no call.

/// Table points, and the bits where the first segment starts (`0.6875`).
const N: usize = 128;
const OFF: u64 = 0x3fe6_0000_0000_0000;

/// ln 2 split: `LN2_HI` has 32 significant bits, so `k LN2_HI` is exact.
const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);

/// `(1/c_i, ln c_i)` with `c_i` the middle of segment i, `ln c_i` exactly `-ln(1/c_i)`
/// of the stored reciprocal.
const TABLE: [(f64, f64); N] = table();

const fn table() -> [(f64, f64); N] {
    let mut t = [(0.0, 0.0); N];
    let mut i = 0;
    while i < N {
        // Segment i: z from the bits OFF + i 2^45 to those of i + 1 (an octave boundary
        // at 1.0 halves the step below it).
        let lo = f64::from_bits(OFF + ((i as u64) << 45));
        let hi = f64::from_bits(OFF + ((i as u64 + 1) << 45));
        let inverse = 2.0 / (lo + hi);
        t[i] = (inverse, -ln_by_atanh(inverse));
        i += 1;
    }
    t
}

/// `ln y` for y in [0.7, 1.5] by `2 atanh(u)`, `u = (y - 1)/(y + 1)`, `|u| < 0.21`:
/// 24 terms (the rest below `u^49 < 1e-33`).
const fn ln_by_atanh(y: f64) -> f64 {
    let u = (y - 1.0) / (y + 1.0);
    let u2 = u * u;
    let mut sum = 0.0;
    let mut j = 24;
    while j > 0 {
        j -= 1;
        sum = sum * u2 + 1.0 / (2 * j + 1) as f64;
    }
    2.0 * u * sum
}

/// `ln x` for positive normal `x` (elsewhere meaningless).
#[inline(always)]
pub fn ln(x: f64) -> f64 {
    let bits = x.to_bits();
    let tmp = bits.wrapping_sub(OFF);
    let i = ((tmp >> 45) % N as u64) as usize;
    let k = ((tmp as i64) >> 52) as f64;
    let z = f64::from_bits(bits.wrapping_sub(tmp & (0xfff << 52)));
    let (inverse, ln_c) = TABLE[i];
    let r = z * inverse - 1.0;
    let r2 = r * r;
    // ln(1 + r) - r through r^7, in pairs.
    let tail = r2
        * ((-0.5 + r * (1.0 / 3.0))
            + r2 * ((-0.25 + r * 0.2) + r2 * (-1.0 / 6.0 + r * (1.0 / 7.0))));
    (k * LN2_HI + ln_c) + (r + (tail + k * LN2_LO))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ln2_split() {
        assert_eq!(LN2_HI.to_bits() & 0x1f_ffff, 0);
        assert_eq!(LN2_HI + LN2_LO, core::f64::consts::LN_2);
    }

    #[test]
    fn within_its_bound_of_libm() {
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        let mut worst: f64 = 0.0;
        for i in 0..2_000_000u64 {
            s ^= s >> 12;
            s ^= s << 25;
            s ^= s >> 27;
            // p from 2^-100 to 2^-9 at random, and every segment at 2^-10 to 2^-9.
            let bits = match i % 2 {
                0 => 0x3f60_0000_0000_0000 - ((s >> 12) % (91 << 52)),
                _ => OFF - (10 << 52) + ((i / 2 % N as u64) << 45) + (s >> 20),
            };
            let x = f64::from_bits(bits);
            let (got, want) = (ln(x), libm::log(x));
            worst = worst.max(libm::fabs(got - want) / (f64::EPSILON * libm::fabs(want)));
        }
        assert!(worst <= 1.5, "worst {worst}");
    }
}
