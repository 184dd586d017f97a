//! Octave tables: a function of x > 0 stored as one polynomial per octave of x,
//! in the local variable `u = mantissa(x) - 3/2` in [-1/2, 1/2). The octave comes
//! from the exponent bits: no logarithm, no search, no division. The tables
//! themselves are generated from the f64 reference (`cargo xtask tables`, src/tables.rs).

/// A function tabulated from `2^first_exponent` up to `2^(first_exponent + len)`,
/// each octave a polynomial of degree `C - 1` (coefficients lowest first).
#[derive(Debug, Clone, Copy)]
pub struct OctaveTable<'a, const C: usize> {
    /// Unbiased exponent of the first octave.
    pub first_exponent: i32,
    /// One row of coefficients per octave.
    pub coeffs: &'a [[f32; C]],
}

impl<const C: usize> OctaveTable<'_, C> {
    /// The value at `x`, or `None` when x is outside the table (below, above, negative,
    /// NaN or infinite: their exponent bits fall outside the rows).
    #[inline(always)]
    pub fn eval(&self, x: f32) -> Option<f32> {
        let bits = x.to_bits();
        let row = (bits >> 23).wrapping_sub((self.first_exponent + 127) as u32) as usize;
        let c = self.coeffs.get(row)?;
        let u = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000) - 1.5;
        let mut acc = c[C - 1];
        let mut k = C - 1;
        while k > 0 {
            k -= 1;
            acc = acc * u + c[k];
        }
        Some(acc)
    }

    /// Smallest x in the table, `2^first_exponent`.
    pub fn lower(&self) -> f32 {
        libm::ldexpf(1.0, self.first_exponent)
    }

    /// x below this are above the table, `2^(first_exponent + rows)`.
    pub fn upper(&self) -> f32 {
        libm::ldexpf(1.0, self.first_exponent + self.coeffs.len() as i32)
    }
}

/// Copies rows `skip .. skip + K` of a generated coefficient array into a smaller one,
/// at compile time: a firmware whose scene declares a narrower range of misalignment
/// links only those rows (see `tables`).
pub const fn narrow_rows<const C: usize, const N: usize, const K: usize>(
    rows: &[[f32; C]; N],
    skip: usize,
) -> [[f32; C]; K] {
    let mut out = [[0.0; C]; K];
    let mut i = 0;
    while i < K {
        out[i] = rows[skip + i];
        i += 1;
    }
    out
}
