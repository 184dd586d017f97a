//! Uniform tables in Q8.24: a function sampled at spacing `2^-k` of a Q8.24 argument,
//! evaluated by quadratic interpolation through three nodes (Newton's forward
//! differences). Only 32-bit integer multiplies (one `MULS` each on a Cortex-M0):
//! the one product that would overflow is split in 16-bit halves.

/// One Q8.24 unit: 1.0.
pub const ONE: i32 = 1 << 24;

/// `(a * t) >> 16` for `0 <= t < 2^16`, exactly (floor), without a 64-bit product.
#[inline(always)]
pub fn mul_q16(a: i32, t: u32) -> i32 {
    let hi = (a >> 16).wrapping_mul(t as i32);
    let lo = ((a as u32 & 0xffff).wrapping_mul(t) >> 16) as i32;
    hi.wrapping_add(lo)
}

/// A function tabulated at `start + i 2^-spacing_log2` (Q8.24), `i = 0 .. len`.
#[derive(Debug, Clone, Copy)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct UniformTable<'a> {
    /// Argument of `values[0]`, Q8.24.
    pub start: i32,
    /// The spacing is `2^-spacing_log2`, between 0 and 8.
    pub spacing_log2: u32,
    /// Values in Q8.24. Each segment reads the node after it too, so the table holds
    /// two nodes past its domain; second differences stay below 2^17 (the generator
    /// checks both).
    pub values: &'a [i32],
}

impl UniformTable<'_> {
    /// The interpolated value at `x` (Q8.24), or `None` outside the table.
    #[inline(always)]
    pub fn eval(&self, x: i32) -> Option<i32> {
        // Below the start the difference wraps to a huge index: None like above.
        let dx = x.wrapping_sub(self.start) as u32;
        let shift = 24 - self.spacing_log2;
        let i = (dx >> shift) as usize;
        let v = self.values.get(i..i + 3)?;
        // The position in the segment, `shift` bits: t in Q16 and the bits below it.
        let position = dx & ((1 << shift) - 1);
        let t = position >> (shift - 16);
        let below = (position & ((1 << (shift - 16)) - 1)) as i32;
        let d1 = v[1].wrapping_sub(v[0]);
        let d2 = v[2].wrapping_sub(v[1]).wrapping_sub(d1);
        // d1 t exactly to the last bit of x: the Q16 part plus the bits below it.
        let linear = mul_q16(d1, t).wrapping_add(d1.wrapping_mul(below) >> shift);
        // t (t - 1) / 2 in Q16, from t/2 in Q15 (products stay below 2^30).
        let u = (t >> 1) as i32;
        let tt = u.wrapping_mul(u.wrapping_sub(32768)) >> 15;
        // |d2| < 2^17 (the generator checks) and |tt| < 2^14: the product fits i32.
        Some(
            v[0].wrapping_add(linear)
                .wrapping_add(d2.wrapping_mul(tt) >> 16),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mul_q16_is_exact() {
        for &a in &[
            0,
            1,
            -1,
            12345678,
            -12345678,
            i32::MAX,
            i32::MIN + 1,
            1 << 24,
        ] {
            for &t in &[0u32, 1, 32768, 65535, 40000] {
                let want = ((a as i64 * t as i64) >> 16) as i32;
                assert_eq!(mul_q16(a, t), want, "{a} {t}");
            }
        }
    }

    #[test]
    fn quadratics_are_reproduced() {
        // f(x) = x^2 / 64 tabulated at spacing 1/4 from -1 (second differences 2^15).
        let f = |x: f64| x * x / 64.0;
        let values: std::vec::Vec<i32> = (0..12)
            .map(|i| (f(-1.0 + i as f64 / 4.0) * ONE as f64).round() as i32)
            .collect();
        let table = UniformTable {
            start: -ONE,
            spacing_log2: 2,
            values: &values,
        };
        for k in 0..200 {
            let x = -1.0 + k as f64 * 0.0125;
            let got = table.eval((x * ONE as f64) as i32).unwrap() as f64 / ONE as f64;
            assert!((got - f(x)).abs() < 2e-7, "{x}: {got}");
        }
        assert_eq!(table.eval(-ONE - 1), None);
        assert_eq!(table.eval(2 * ONE), None);
    }
}
