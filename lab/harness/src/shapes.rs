//! The table shapes that `cargo xtask shapes` weighs, as evaluators of any shape:
//! written like the library's own (`misalign::float::octave::OctaveTable::eval`,
//! `misalign::fixed::uniform::UniformTable::eval` and the fixed-point core's two-table
//! `lookup`), so that the shape the library ships, evaluated here, is the library's
//! kernel instruction for instruction, and every other shape differs from it only in
//! its shape.
//!
//! This file is compiled twice: into the harness's `shapes` image (Cortex-M: the
//! instructions) and into xtask (`#[path]`, on the host: the error against the f64
//! reference), so that the error is measured on the arithmetic the target runs (f32
//! with a rounding after each operation, as Rust never fuses them; integers). It uses
//! `core` and `misalign` only.

use misalign::fixed::uniform::{UniformTable, mul_q16};

/// An octave table of any shape: `2^M` segments per octave of x, on each a polynomial
/// of degree `D` (Horner), in rows of `W` coefficients (`D + 1` padded to a power of
/// two, so that a row's address is one shift, as the library's 8 for degree 6), in the
/// variable `u`, the segment's own mantissa in [1, 2) taken from the bits (`T = false`,
/// the library's choice), or `t = u - 1` in [0, 1) (`T = true`: one subtraction more,
/// better conditioned coefficients).
///
/// `Octaves::<0, 6, 8, false>` is `OctaveTable::eval` (the shift by `M = 0` folds away).
#[derive(Debug, Clone, Copy)]
pub struct Octaves<'a, const M: u32, const D: usize, const W: usize, const T: bool> {
    /// `(first_exponent + 127) << M`: the first segment's index in the bits.
    first_row: u32,
    coeffs: &'a [[f32; W]],
}

impl<'a, const M: u32, const D: usize, const W: usize, const T: bool> Octaves<'a, M, D, W, T> {
    /// The table whose first segment starts at `2^first_exponent`.
    pub const fn new(first_exponent: i32, coeffs: &'a [[f32; W]]) -> Self {
        const { assert!(D < W && M <= 8) };
        Octaves {
            first_row: (first_exponent.wrapping_add(127) as u32) << M,
            coeffs,
        }
    }

    /// The value at `x`, or `None` outside the table (as the library's).
    #[inline(always)]
    pub fn eval(&self, x: f32) -> Option<f32> {
        let bits = x.to_bits();
        let c = self
            .coeffs
            .get((bits >> (23 - M)).wrapping_sub(self.first_row) as usize)?;
        // The bits below the segment index, as a mantissa in [1, 2).
        let u = f32::from_bits(((bits << M) & 0x007f_ffff) | 0x3f80_0000);
        let u = if T { u - 1.0 } else { u };
        let mut acc = c[D];
        let mut k = D;
        while k > 0 {
            k -= 1;
            acc = acc * u + c[k];
        }
        Some(acc)
    }
}

/// A uniform Q8.24 table like the library's [`UniformTable`], with linear
/// interpolation between two nodes instead of quadratic through three: the same index,
/// the same position `t` in Q16 (rounded or truncated by the same rule), one multiply
/// (`mul_q16`) instead of three.
#[derive(Debug, Clone, Copy)]
pub struct Linear<'a> {
    /// Argument of `values[0]`, Q8.24.
    pub start: i32,
    /// The spacing is `2^-spacing_log2`, between 0 and 8.
    pub spacing_log2: u32,
    /// Values in Q8.24, one node past the domain.
    pub values: &'a [i32],
}

impl Linear<'_> {
    /// The interpolated value at `x` (Q8.24), or `None` outside the table.
    #[inline(always)]
    pub fn eval(&self, x: i32) -> Option<i32> {
        let dx = x.wrapping_sub(self.start) as u32;
        let shift = 24 - self.spacing_log2;
        let i = (dx >> shift) as usize;
        let v = self.values.get(i..i + 2)?;
        let position = dx & ((1 << shift) - 1);
        let half = if shift > 18 { 1 << (shift - 17) } else { 0 };
        let t = (position + half) >> (shift - 16);
        Some(v[0].wrapping_add(mul_q16(v[1].wrapping_sub(v[0]), t)))
    }
}

/// A uniform table of either interpolation, for [`lookup`].
pub trait Uniform {
    /// Argument of the first node, Q8.24.
    fn start(&self) -> i32;
    /// The interpolated value, or `None` outside.
    fn eval(&self, x: i32) -> Option<i32>;
}

impl Uniform for UniformTable<'_> {
    #[inline(always)]
    fn start(&self) -> i32 {
        self.start
    }
    #[inline(always)]
    fn eval(&self, x: i32) -> Option<i32> {
        UniformTable::eval(self, x)
    }
}

impl Uniform for Linear<'_> {
    #[inline(always)]
    fn start(&self) -> i32 {
        self.start
    }
    #[inline(always)]
    fn eval(&self, x: i32) -> Option<i32> {
        Linear::eval(self, x)
    }
}

/// Two tables that follow each other, coarse below `high.start()` and fine above: the
/// fixed-point core's `lookup` (src/fixed/elliptic.rs), each branch evaluating its own
/// table so that each one's spacing folds into immediates.
#[inline(always)]
pub fn lookup<U: Uniform>(low: &U, high: &U, x: i32) -> Option<i32> {
    if x < high.start() {
        low.eval(x)
    } else {
        high.eval(x)
    }
}
