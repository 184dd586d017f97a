//! The square root of a positive normal f64 by multiplications only, so that a loop of
//! rows that takes one stays a loop the compiler can run in SIMD lanes (libm's `sqrt`
//! is an inline `sqrtsd` on x86, which no loop vectorises).
//!
//! `y ~ x^(-1/2)` from the exponent bits (`C - bits/2`, `|1 - x y^2| < 0.07`), three
//! Newton steps `y (3/2 - (x/2) y^2)` (relative error 3.5e-2 -> 1.8e-3 -> 4.7e-6 ->
//! 3.3e-11), then `s = x y` and one Newton step on s itself, `s + (y/2)(x - s^2)`
//! (below 1e-21 before rounding).
//!
//! Error: within 1 ulp of the exact root (libm's correctly rounded `sqrt` or its
//! neighbour; asserted below over the whole normal range). Cost: 15 multiply-adds, a
//! shift, no division, no branch.

/// `C - bits(x)/2` is x^(-1/2) to within `|1 - x y^2| < 0.07`.
const MAGIC: u64 = 0x5fe6_eb50_c7b5_37a9;

/// `x^(1/2)` for positive normal `x` (elsewhere meaningless).
#[inline(always)]
pub fn sqrt(x: f64) -> f64 {
    let mut y = f64::from_bits(MAGIC.wrapping_sub(x.to_bits() >> 1));
    let half = 0.5 * x;
    y *= 1.5 - (half * y) * y;
    y *= 1.5 - (half * y) * y;
    y *= 1.5 - (half * y) * y;
    let s = x * y;
    s + (0.5 * y) * (x - s * s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn within_an_ulp_over_the_normal_range() {
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        for i in 0..2_000_000u64 {
            s ^= s >> 12;
            s ^= s << 25;
            s ^= s >> 27;
            // Random bits over every normal exponent, and each binade's edges.
            let bits = match i % 3 {
                0 => (s % (2046 << 52)) + (1 << 52),
                1 => (1 + i / 3 % 2046) << 52,
                _ => ((2 + i / 3 % 2045) << 52) - 1,
            };
            let x = f64::from_bits(bits);
            let (got, want) = (sqrt(x), libm::sqrt(x));
            let ulp = f64::from_bits(want.to_bits() + 1) - want;
            assert!(libm::fabs(got - want) <= ulp, "x={x:e}: {got:e} {want:e}");
        }
    }
}
