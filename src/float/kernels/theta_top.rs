//! theta(g) on the top octave of the inverse table, g in [1, pi/2] (theta from 0.93 to
//! pi/2, where theta(g) bends the most and the table's two segments per octave fall
//! short): its own table of four segments, in the same local variable.

use crate::float::octave::{CENTER, horner};
use crate::float::tables::THETA_OF_G_TOP;

/// theta(g) for g in [1, pi/2] (its fourth segment, from 1.75 up, is never read).
#[inline]
pub fn theta_of_g_top(g: f32) -> f32 {
    let bits = g.to_bits();
    // g in [1, 2): the exponent bits are 127's, the mantissa's first two bits the segment.
    let c = &THETA_OF_G_TOP[((bits >> 21) & 3) as usize];
    horner(c, f32::from_bits(bits | 0x3f80_0000) - CENTER as f32)
}
