//! Uniform tables in Q8.24: a function sampled at spacing `2^-k` of a Q8.24 argument,
//! evaluated by quadratic interpolation through three nodes (Newton's forward
//! differences). Only 32-bit integer multiplies (one `MULS` each on a Cortex-M0):
//! the one product that would overflow is split in 16-bit halves.

/// One Q8.24 unit: 1.0.
pub const ONE: i32 = 1 << 24;

/// `(a * t) >> 16` for `0 <= t <= 2^16`, exactly (floor), without a 64-bit product.
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
    /// two nodes past its domain; second differences stay below 2^16 (the generator
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
        // The position in the segment, `shift` bits, rounded to t in Q16 (t = 2^16 at
        // a segment's end is its next node: both terms below stay exact). With at most
        // two bits below t (spacing 2^-6 and finer: log2's and exp2's tables) it is
        // truncated instead: log2 keeps its excess below half a unit and exp2 its
        // mantissa below 2^25 (an f32 mantissa never carries into the exponent).
        let position = dx & ((1 << shift) - 1);
        let half = if shift > 18 { 1 << (shift - 17) } else { 0 };
        let t = (position + half) >> (shift - 16);
        let d1 = v[1].wrapping_sub(v[0]);
        let d2 = v[2].wrapping_sub(v[1]).wrapping_sub(d1);
        // Newton's form as v0 + t (d1 + (t - 1) d2 / 2): (t - 1) d2 / 2 from t/2 in
        // Q15 ((t/2 - 1/2) d2 in Q16; |d2| < 2^16, the generator checks, and
        // |t/2 - 1/2| <= 2^15: the product fits i32), then one product by t split in
        // 16-bit halves. Three multiplies.
        let u = (t >> 1) as i32;
        let inner = d1.wrapping_add(u.wrapping_sub(32768).wrapping_mul(d2) >> 16);
        // t to 2^-17 of a segment (2^-16 when truncated): the bits of x below it move
        // the value by at most |d1| 2^-17 (the generator's check measures it).
        Some(v[0].wrapping_add(mul_q16(inner, t)))
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
            // t rounded to Q16: within |d1| 2^-17 (2 units here) and one rounding.
            assert!((got - f(x)).abs() < 2.5e-7, "{x}: {got}");
        }
        assert_eq!(table.eval(-ONE - 1), None);
        assert_eq!(table.eval(2 * ONE), None);
    }
}
