//! Octave tables: a function of x > 0 stored as one polynomial per octave of x,
//! in the local variable `u = mantissa(x)` in [1, 2), taken from the bits as they
//! are. The octave comes from the exponent bits: no logarithm, no search, no
//! division. The tables
//! themselves are generated from the f64 reference (`cargo xtask tables`, src/float/tables.rs).

/// Degree of the polynomial per octave.
pub const DEGREE: usize = 6;

/// One octave's coefficients, lowest power first, padded to 8 so that a row is 32
/// bytes and its address one shift (the pad is never read).
pub type Row = [f32; 8];

/// A function tabulated from `2^first_exponent` up to `2^(first_exponent + rows)`,
/// each octave a polynomial of degree [`DEGREE`].
#[derive(Debug, Clone, Copy)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct OctaveTable<'a> {
    /// Biased exponent bits of the first octave (`first_exponent + 127`).
    first_row: u32,
    coeffs: &'a [Row],
}

impl<'a> OctaveTable<'a> {
    /// The table whose first row is the octave `[2^first_exponent, 2^(first_exponent + 1))`
    /// (an exponent of f32, -126 to 127; another one gives a table that holds no f32).
    pub const fn new(first_exponent: i32, coeffs: &'a [Row]) -> Self {
        OctaveTable {
            first_row: first_exponent.wrapping_add(127) as u32,
            coeffs,
        }
    }

    /// The value at `x`, or `None` when x is outside the table (below, above, negative,
    /// NaN or infinite: their exponent bits fall outside the rows).
    #[inline(always)]
    pub fn eval(&self, x: f32) -> Option<f32> {
        let bits = x.to_bits();
        let c = self
            .coeffs
            .get((bits >> 23).wrapping_sub(self.first_row) as usize)?;
        let u = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000); // mantissa in [1, 2)
        let mut acc = c[DEGREE];
        let mut k = DEGREE;
        while k > 0 {
            k -= 1;
            acc = acc * u + c[k];
        }
        Some(acc)
    }

    /// Unbiased exponent of the first octave.
    pub fn first_exponent(&self) -> i32 {
        (self.first_row as i32).wrapping_sub(127) // the inverse of `new`
    }

    /// Smallest x in the table, `2^first_exponent`.
    pub fn lower(&self) -> f32 {
        libm::ldexpf(1.0, self.first_exponent())
    }

    /// x below this are above the table, `2^(first_exponent + rows)`.
    pub fn upper(&self) -> f32 {
        let rows = i32::try_from(self.coeffs.len()).unwrap_or(i32::MAX);
        libm::ldexpf(1.0, self.first_exponent().saturating_add(rows))
    }
}

/// Copies rows `skip .. skip + K` of a generated coefficient array into a smaller one,
/// at compile time: a firmware whose scene declares a narrower range of misalignment
/// links only those rows (see [`Tables`](super::Tables)).
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
