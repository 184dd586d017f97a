//! f64 seed tables: a function of x > 0 as one polynomial per segment of an octave of
//! x (2^S segments an octave), found from x's bits (exponent and the mantissa's first S
//! bits: no logarithm, no search), evaluated by Horner in the local variable
//! `tau in [-1, 1)` across the segment. The tables (src/reference/fast/seeds.rs) are
//! fitted to the f64 reference by `cargo xtask tables`; they only start a Newton step,
//! so their error (stated in seeds.rs) needs to be small, not an ulp.

/// Degree of each segment's polynomial.
pub const DEGREE: usize = 6;

/// Coefficients per segment, padded to 8 (64 bytes: a segment is one cache line).
pub const WIDTH: usize = 8;

/// One segment's coefficients, lowest power of tau first.
pub type Segment = [f64; WIDTH];

/// A function tabulated from `2^first_exponent` on, `2^S` segments an octave.
#[derive(Debug, Clone, Copy)]
pub struct Table<'a, const S: u32> {
    /// The first segment's bits: the biased exponent and the mantissa's first S bits.
    first_segment: u64,
    segments: &'a [Segment],
}

/// `1.0`'s bits.
const ONE_BITS: u64 = 0x3ff0_0000_0000_0000;

impl<'a, const S: u32> Table<'a, S> {
    /// The table whose first segment starts at `2^first_exponent` (a normal f64
    /// exponent).
    pub const fn new(first_exponent: i32, segments: &'a [Segment]) -> Self {
        Table {
            first_segment: ((first_exponent + 1023) as u64) << S,
            segments,
        }
    }

    /// The value at x, or `None` outside the table (below, above, negative, NaN or
    /// infinite: their bits fall outside the segments).
    #[inline(always)]
    pub fn eval(&self, x: f64) -> Option<f64> {
        let (value, inside) = self.eval_lane(x);
        inside.then_some(value)
    }

    /// The value at x and whether x is inside the table, without a branch (a SIMD
    /// lane's form of [`Table::eval`]): outside it, the first segment's polynomial
    /// at some tau, a number to be ignored.
    #[inline(always)]
    pub fn eval_lane(&self, x: f64) -> (f64, bool) {
        let bits = x.to_bits();
        let index = (bits >> (52 - S)).wrapping_sub(self.first_segment);
        let inside = index < self.segments.len() as u64;
        let c = self
            .segments
            .get(if inside { index as usize } else { 0 })
            .unwrap_or(&[0.0; WIDTH]);
        // The mantissa's bits below the segment's, as u in [1, 2): tau = 2u - 3.
        let low = (bits << S) & 0x000f_ffff_ffff_ffff;
        let tau = 2.0 * f64::from_bits(low | ONE_BITS) - 3.0;
        let mut acc = c[DEGREE];
        let mut j = DEGREE;
        while j > 0 {
            j -= 1;
            acc = acc * tau + c[j];
        }
        (acc, inside)
    }
}

/// The x of local coordinate `tau` in segment `index` of a table from
/// `2^first_exponent` (the generator's and the tests' inverse of [`Table::eval`]'s split).
pub fn x_of(first_exponent: i32, segments_log2: u32, index: usize, tau: f64) -> f64 {
    let per = 1usize << segments_log2;
    let e = first_exponent + (index / per) as i32;
    let j = (index % per) as f64;
    libm::ldexp(1.0 + (j + 0.5 * (tau + 1.0)) / per as f64, e)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segments_and_local_variable_follow_the_bits() {
        // A table of the identity on each segment: c0 = the segment's index, c1 = 1/16.
        let mut segs = [[0.0; WIDTH]; 12];
        for (i, s) in segs.iter_mut().enumerate() {
            s[0] = i as f64;
            s[1] = 1.0 / 16.0;
        }
        let t: Table<'_, 2> = Table::new(-3, &segs);
        for index in 0..12 {
            for &tau in &[-1.0, -0.5, 0.0, 0.75] {
                let x = x_of(-3, 2, index, tau);
                assert_eq!(t.eval(x), Some(index as f64 + tau / 16.0), "{index} {tau}");
            }
        }
        assert_eq!(t.eval(0.1249), None);
        assert_eq!(t.eval(1.0), None);
        assert_eq!(t.eval(-0.2), None);
        assert_eq!(t.eval(f64::NAN), None);
        assert_eq!(t.eval(f64::INFINITY), None);
    }
}
