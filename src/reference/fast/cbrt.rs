//! The cube root of a positive normal f64 without a division, for d/b from `(d/b)^3`.
//!
//! `y ~ x^(-1/3)` from the exponent bits (`C - bits/3` on the high 32 bits, which a
//! SIMD lane divides by 3 as a multiply: `|1 - x y^3| < 0.106`), then
//! two corrections by the series `(1 - d)^(-1/3) = 1 + d/3 + 2d^2/9 + 14d^3/81 + ...`
//! with `d = 1 - x y^3`: through `d^5` (leaves `|d| < 1e-6`), then through `d^2` (leaves
//! below 1e-19); the root is `x y^2`.
//!
//! Error: within 2.5 `f64::EPSILON` (relative) of `libm::cbrt`, itself within 0.667 ulp
//! of the exact root (asserted below over the whole normal range): the roundings in
//! `x y^3` and `x y^2`.
//! Cost: a 32-bit integer division by 3 (a multiply), 20 multiply-adds, no division,
//! no call and no branch (libm's cbrt takes two divisions).

/// `x^(1/3)` for positive normal `x` (elsewhere meaningless).
#[inline(always)]
pub fn cbrt(x: f64) -> f64 {
    // y = x^(-1/3) to 11%: the exponent and mantissa bits divided by -3 about 1.
    let mut y = seed(x);
    let d = 1.0 - x * (y * y * y);
    let series = 1.0 + d * (C[1] + d * (C[2] + d * (C[3] + d * (C[4] + d * C[5]))));
    y *= series;
    let d = 1.0 - x * (y * y * y);
    y += y * (d * (C[1] + d * C[2]));
    (x * y) * y
}

/// `C - bits(x)/3` (high words) is x^(-1/3) to within `|1 - x y^3| < 0.106` (the
/// constant chosen for the least such bound; asserted below).
const MAGIC: u32 = 0x553e_e000;

/// The first guess: the high word of x's bits divided by 3, below `MAGIC`.
#[inline(always)]
fn seed(x: f64) -> f64 {
    let high = (x.to_bits() >> 32) as u32;
    f64::from_bits(u64::from(MAGIC.wrapping_sub(high / 3)) << 32)
}

/// The series' coefficients: `(1/3)_j / j!`.
const C: [f64; 6] = [
    1.0,
    1.0 / 3.0,
    2.0 / 9.0,
    14.0 / 81.0,
    35.0 / 243.0,
    91.0 / 729.0,
];

#[cfg(test)]
mod tests {
    use super::*;

    fn ulps(a: f64, b: f64) -> f64 {
        libm::fabs(a - b) / (f64::EPSILON * libm::fabs(b))
    }

    /// xorshift64*, uniform bits.
    fn rng(seed: u64) -> impl FnMut() -> u64 {
        let mut s = seed;
        move || {
            s ^= s >> 12;
            s ^= s << 25;
            s ^= s >> 27;
            s.wrapping_mul(0x2545_f491_4f6c_dd1d)
        }
    }

    #[test]
    fn seed_within_its_bound() {
        let mut next = rng(7);
        // Three octaves: the bits divided by 3 repeat with the exponent modulo 3.
        for i in 0..300_000 {
            let x = f64::from_bits(next() >> 12 | 0x3ff0_0000_0000_0000) * [1.0, 2.0, 4.0][i % 3];
            let y = seed(x);
            assert!(libm::fabs(1.0 - x * y * y * y) < 0.106, "x={x}");
        }
    }

    #[test]
    fn within_its_bound_of_libm_over_the_normal_range() {
        let mut next = rng(11);
        let mut worst: f64 = 0.0;
        for i in 0..1_000_000u64 {
            // Random exponent over the whole normal range, random mantissa; and every
            // binade's edges.
            let bits = match i % 4 {
                0 => (next() % (2046u64 << 52)) + (1u64 << 52),
                1 => (1 + i / 4 % 2046) << 52,
                2 => ((2 + i / 4 % 2045) << 52) - 1,
                _ => 0x3ff0_0000_0000_0000 | (next() >> 12),
            };
            let x = f64::from_bits(bits);
            if !x.is_normal() {
                continue;
            }
            let (got, want) = (cbrt(x), libm::cbrt(x));
            assert!(got.is_normal(), "x={x:e}");
            worst = worst.max(ulps(got, want));
        }
        assert!(worst <= 2.5, "worst {worst} ulps");
        let tiny = f64::MIN_POSITIVE;
        assert!(ulps(cbrt(tiny), libm::cbrt(tiny)) <= 2.5);
        assert!(ulps(cbrt(f64::MAX), libm::cbrt(f64::MAX)) <= 2.5);
    }
}
