//! Order and finiteness of f32 values as the per-sample path compares them: by their
//! bits where floats are soft (a soft-float comparison costs some ten times an integer
//! one on a Cortex-M0), by the FPU where there is one (`eabihf`); the same answers
//! either way. Imports nothing from the monitor: every stage uses it.

/// A finite value's order key: its bits, negative ones with all but the sign bit
/// flipped, so that keys compare as signed integers exactly as the values do (-0 just
/// below 0). Its own inverse.
#[inline(always)]
pub(crate) fn key(x: f32) -> i32 {
    let i = x.to_bits() as i32;
    i ^ (((i >> 31) as u32) >> 1) as i32
}

/// The value of an order key.
#[inline(always)]
pub(crate) fn value(k: i32) -> f32 {
    f32::from_bits(key(f32::from_bits(k as u32)) as u32)
}

/// `a >= b` for values that are not NaN: the FPU's comparison where there is one
/// (`eabihf`), else integers ([`order`]), some ten times cheaper than a soft-float
/// comparison on a Cortex-M0. The same answer either way, -0 equal to 0 included.
#[inline(always)]
pub(crate) fn ge(a: f32, b: f32) -> bool {
    #[cfg(target_abi = "eabihf")]
    {
        a >= b
    }
    #[cfg(not(target_abi = "eabihf"))]
    {
        order(a) >= order(b)
    }
}

/// Whether `x` is finite, by its bits: an integer comparison on every core (`f32`'s
/// own test is a soft-float comparison without an FPU).
#[inline(always)]
pub(crate) fn finite(x: f32) -> bool {
    x.to_bits() & 0x7fff_ffff <= f32::MAX.to_bits()
}

/// Whether `x` is NaN, by its bits.
#[inline(always)]
pub(crate) fn nan(x: f32) -> bool {
    x.to_bits() & 0x7fff_ffff > f32::INFINITY.to_bits()
}

/// Whether `x` is above zero, by its bits (a NaN with the sign bit clear counts; the
/// callers pass none).
#[inline(always)]
pub(crate) fn positive(x: f32) -> bool {
    x.to_bits() as i32 > 0
}

/// A value's place in the float order as an i32, -0 equal to 0: the non-negative
/// ones are their bits, a negative one `i32::MIN - bits`. A NaN lands above +inf or
/// below -inf, by its sign.
#[cfg_attr(target_abi = "eabihf", allow(dead_code))]
#[inline(always)]
pub(crate) fn order(x: f32) -> i32 {
    let i = x.to_bits() as i32;
    if i < 0 { i32::MIN.wrapping_sub(i) } else { i }
}

/// A value as the target compares it fastest.
#[cfg(target_abi = "eabihf")]
type Ordered = f32;
#[cfg(not(target_abi = "eabihf"))]
type Ordered = i32;

#[inline(always)]
fn ordered(x: f32) -> Ordered {
    #[cfg(target_abi = "eabihf")]
    {
        x
    }
    #[cfg(not(target_abi = "eabihf"))]
    {
        order(x)
    }
}

/// A closed range `[lo, hi]` of f32 (ends not NaN) as the per-sample checks compare
/// it: the FPU's comparisons where there is one (`eabihf`), else the ends' order keys
/// ([`order`]), formed once. A NaN is outside.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Range {
    lo: Ordered,
    hi: Ordered,
}

impl Range {
    pub(crate) fn new(lo: f32, hi: f32) -> Self {
        Range {
            lo: ordered(lo),
            hi: ordered(hi),
        }
    }

    #[inline(always)]
    pub(crate) fn contains(&self, x: f32) -> bool {
        let x = ordered(x);
        x >= self.lo && x <= self.hi
    }
}

/// A lower limit (not NaN): whether a value reaches it, as [`ge`] answers.
#[derive(Debug, Clone, Copy)]
pub(crate) struct AtLeast(Ordered);

impl AtLeast {
    pub(crate) fn new(limit: f32) -> Self {
        AtLeast(ordered(limit))
    }

    #[inline(always)]
    pub(crate) fn reached(&self, x: f32) -> bool {
        ordered(x) >= self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_order_as_the_values_and_invert() {
        let xs = [
            f32::MIN,
            -1e30,
            -2.0,
            -1.0,
            -1e-30,
            -1e-45,
            -0.0,
            0.0,
            1e-45,
            1e-38,
            0.5,
            1.0,
            3.0,
            f32::MAX,
        ];
        for a in xs {
            for b in xs {
                // The float order, with -0 just below 0.
                let below_zero = a == b && a.is_sign_negative() && b.is_sign_positive();
                assert_eq!(key(a) < key(b), a < b || below_zero, "{a} {b}");
                assert_eq!(value(key(a)).to_bits(), a.to_bits(), "{a}");
                assert_eq!(ge(a, b), a >= b, "{a} {b}");
                assert_eq!(order(a) >= order(b), a >= b, "{a} {b}");
                assert!(finite(a) && !nan(a));
                assert_eq!(positive(a), a > 0.0, "{a}");
                assert_eq!(
                    Range::new(b, 1.0).contains(a),
                    b <= a && a <= 1.0,
                    "{a} {b}"
                );
                assert_eq!(AtLeast::new(b).reached(a), a >= b, "{a} {b}");
            }
            assert!(!finite(f32::INFINITY) && !finite(f32::NEG_INFINITY));
            assert!(!nan(f32::INFINITY) && !nan(f32::NEG_INFINITY));
            // A NaN of either sign is outside every finite range.
            for nan_value in [f32::NAN, -f32::NAN] {
                assert!(
                    order(nan_value) > order(f32::INFINITY)
                        || order(nan_value) < order(f32::NEG_INFINITY)
                );
                assert!(!Range::new(f32::NEG_INFINITY, f32::INFINITY).contains(nan_value));
                assert!(!finite(nan_value) && nan(nan_value));
            }
        }
    }
}
