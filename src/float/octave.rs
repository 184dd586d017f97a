//! Octave tables: a function of x > 0 stored as one polynomial per half octave of x,
//! in the local variable `t = u - 3/2`, u the mantissa of x in [1, 2) taken from the
//! bits as they are (so t in [-1/2, 1/2), each half octave one half of it). The segment
//! comes from the exponent bits and the mantissa's first bit: no logarithm, no search,
//! no division. The tables themselves are generated from the f64 reference (`cargo
//! xtask tables`, src/float/tables.rs).

/// Degree of the polynomial per segment.
pub const DEGREE: usize = 5;

/// log2 of the segments per octave: two, the mantissa's first bit.
pub const SEGMENTS_LOG2: u32 = 1;

/// The local variable is the mantissa minus this: centred, so that Horner's terms do
/// not cancel (in the mantissa itself a degree-6 polynomial lost 3e-7 to rounding).
pub const CENTER: f64 = 1.5;

/// Coefficients per segment, compact: the degree's, 24 bytes (a segment's address is
/// then two instructions on a Cortex-M).
pub const COMPACT: usize = DEGREE + 1;

/// Coefficients per segment, wide: padded to 8 (the pad is never read), 32 bytes, so
/// that a segment's address is one shift. The inverse table theta(g), the smaller one,
/// is stored so: one instruction fewer per sample for 448 bytes.
pub const WIDE: usize = 8;

/// One segment's coefficients, lowest power first, in `N` floats ([`COMPACT`] or
/// [`WIDE`]).
pub type Segment<const N: usize = COMPACT> = [f32; N];

/// One octave's coefficients: its two segments, the lower half first.
pub type Row<const N: usize = COMPACT> = [Segment<N>; 1 << SEGMENTS_LOG2];

/// A function tabulated from `2^first_exponent` up to `2^(first_exponent + rows)`,
/// each half octave a polynomial of degree [`DEGREE`], its segments `N` floats apart.
#[derive(Debug, Clone, Copy)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct OctaveTable<'a, const N: usize = COMPACT> {
    /// Biased exponent bits and the first mantissa bit of the first segment
    /// (`(first_exponent + 127) * 2`).
    first_segment: u32,
    segments: &'a [Segment<N>],
}

impl<'a, const N: usize> OctaveTable<'a, N> {
    /// The table whose first row is the octave `[2^first_exponent, 2^(first_exponent + 1))`
    /// (a normal exponent of f32, -126 to 127; another one gives a table that holds no
    /// f32).
    /// Every function tabulated here lives below 2 (theta and g below pi/2): rows from
    /// 2^1 up are dropped, so that a row's argument has its exponent bits below 128 and
    /// its mantissa is one OR away.
    pub const fn new(first_exponent: i32, rows: &'a [Row<N>]) -> Self {
        const { assert!(N > DEGREE, "a segment holds the degree's coefficients") };
        // Rows below 2^1: 1 - first_exponent of them (none from 2^1 up, and none at all
        // from below f32's exponents: no table holds 0 or a subnormal).
        let below_two = if first_exponent >= 1 || first_exponent < -126 {
            0
        } else {
            (1i64 - first_exponent as i64) as usize
        };
        let rows = if rows.len() > below_two {
            rows.split_at(below_two).0
        } else {
            rows
        };
        OctaveTable {
            first_segment: (first_exponent.wrapping_add(127) as u32) << SEGMENTS_LOG2,
            segments: rows.as_flattened(),
        }
    }

    /// The value at `x`, or `None` when x is outside the table (below, above, negative,
    /// NaN or infinite: their exponent bits fall outside the rows).
    #[inline(always)]
    pub fn eval(&self, x: f32) -> Option<f32> {
        let bits = x.to_bits();
        let c = self
            .segments
            .get((bits >> (23 - SEGMENTS_LOG2)).wrapping_sub(self.first_segment) as usize)?;
        // Mantissa in [1, 2): x < 2 on every row, so its exponent bits are 0111_1111 or
        // fewer ones, and setting them to 127 is one OR.
        Some(horner(
            c,
            f32::from_bits(bits | 0x3f80_0000) - CENTER as f32,
        ))
    }

    /// Unbiased exponent of the first octave.
    pub fn first_exponent(&self) -> i32 {
        ((self.first_segment >> SEGMENTS_LOG2) as i32).wrapping_sub(127) // the inverse of `new`
    }

    /// Smallest x in the table, `2^first_exponent`.
    pub fn lower(&self) -> f32 {
        libm::ldexpf(1.0, self.first_exponent())
    }

    /// x below this are above the table, `2^(first_exponent + rows)`.
    pub fn upper(&self) -> f32 {
        let rows = i32::try_from(self.segments.len() >> SEGMENTS_LOG2).unwrap_or(i32::MAX);
        libm::ldexpf(1.0, self.first_exponent().saturating_add(rows))
    }
}

/// A segment's polynomial of degree [`DEGREE`] at t, by Horner.
#[inline(always)]
pub(crate) fn horner<const N: usize>(c: &Segment<N>, t: f32) -> f32 {
    const { assert!(N > DEGREE, "a segment holds the degree's coefficients") };
    let mut acc = c[DEGREE];
    let mut k = DEGREE;
    while k > 0 {
        k -= 1;
        acc = acc * t + c[k];
    }
    acc
}

/// Copies rows `skip .. skip + K` of a generated coefficient array into a smaller one,
/// at compile time: a firmware whose scene declares a narrower range of misalignment
/// links only those rows (see [`Tables`](super::Tables)).
pub const fn narrow_rows<const C: usize, const N: usize, const K: usize>(
    rows: &[Row<C>; N],
    skip: usize,
) -> [Row<C>; K] {
    let mut out = [[[0.0; C]; 1 << SEGMENTS_LOG2]; K];
    let mut i = 0;
    while i < K {
        out[i] = rows[skip + i];
        i += 1;
    }
    out
}
