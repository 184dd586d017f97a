//! Products and quotients of many factors without intermediate overflow or underflow:
//! mantissas and exponents are carried apart (frexp), so that a valid but extreme
//! scene (a subnormal radius, a shear modulus of 1e300 Pa) gives the true result or
//! its limit, never 0/0 or inf/inf. In the normal range the roundings are those of the
//! plain expression evaluated left to right.

/// `num[0] num[1] ... / (den[0] den[1] ...)`.
pub(crate) fn chain(num: &[f64], den: &[f64]) -> f64 {
    plain(num, den).unwrap_or_else(|| scaled(num, den))
}

/// The plain expression, left to right, when every partial result is a normal number:
/// then each rounding is that of [`scaled`], which forms the same exact products and
/// quotients scaled by powers of two (a zero, infinite or NaN factor makes a partial
/// result that is not normal). At a fraction of the cost: no frexp per factor.
/// `None` otherwise.
fn plain(num: &[f64], den: &[f64]) -> Option<f64> {
    let mut p = 1.0f64;
    for &x in num {
        p *= x;
        if !p.is_normal() {
            return None;
        }
    }
    for &x in den {
        p /= x;
        if !p.is_normal() {
            return None;
        }
    }
    Some(p)
}

/// The product with mantissas and exponents carried apart.
fn scaled(num: &[f64], den: &[f64]) -> f64 {
    let (m, e) = parts(num, den);
    libm::ldexp(m, e)
}

/// `(num[0] ... / (den[0] ...))^(1/3)`, the product formed as [`chain`] forms it and its
/// exponent divided by 3 exactly, so that a product beyond the f64 range whose cube
/// root is inside it gives that root.
pub(crate) fn chain_cbrt(num: &[f64], den: &[f64]) -> f64 {
    match plain(num, den) {
        Some(p) => libm::cbrt(p),
        None => {
            let (m, e) = parts(num, den);
            let (q, r) = (e.div_euclid(3), e.rem_euclid(3));
            libm::ldexp(libm::cbrt(libm::ldexp(m, r)), q)
        }
    }
}

/// The product as a mantissa in [0.5, 1) (or 0, inf, NaN) and a binary exponent.
fn parts(num: &[f64], den: &[f64]) -> (f64, i32) {
    let mut m = 1.0f64;
    let mut e = 0i32;
    for &x in num {
        let (mx, ex) = libm::frexp(x);
        let (mm, em) = libm::frexp(m * mx);
        m = mm;
        e = e.saturating_add(ex).saturating_add(em);
    }
    for &x in den {
        let (mx, ex) = libm::frexp(x);
        let (mm, em) = libm::frexp(m / mx);
        m = mm;
        e = e.saturating_add(em).saturating_sub(ex);
    }
    (m, e)
}

#[cfg(test)]
mod tests {
    use super::chain;

    #[test]
    fn survives_what_plain_arithmetic_does_not() {
        // (1e-200 * 1e-200) / (1e-300 * 1e-100) = 1: the plain form is 0/0.
        assert!((chain(&[1e-200, 1e-200], &[1e-300, 1e-100]) - 1.0).abs() < 1e-15);
        // 1e600 / 1e600: the plain form is inf/inf.
        assert!((chain(&[1e300, 1e300], &[1e200, 1e200, 1e200]) - 1.0).abs() < 1e-14);
        assert_eq!(chain(&[1e300, 1e300], &[1.0]), f64::INFINITY);
        assert_eq!(chain(&[1e-300, 1e-300], &[1.0]), 0.0);
        assert_eq!(chain(&[0.0, 5.0], &[2.0]), 0.0);
        let plain = 3.0 * 7.0 / 11.0 * 13.0;
        assert!((chain(&[3.0, 7.0, 13.0], &[11.0]) / plain - 1.0).abs() < 3e-16);
    }

    #[test]
    fn the_plain_path_rounds_as_the_scaled_one() {
        // Normal factors and partial results: the two paths agree to the bit.
        let mut x = 0.123_456_789_f64;
        for _ in 0..2000 {
            let f: [f64; 4] = core::array::from_fn(|i| {
                x = libm::fmod(x * 7919.0 + 0.618_033_988_75 * (i + 1) as f64, 1.0);
                libm::exp2(200.0 * (x - 0.5)) * (1.0 + x)
            });
            let (num, den) = (&f[..3], &f[3..]);
            assert_eq!(super::plain(num, den), Some(super::scaled(num, den)));
        }
        // A partial result that leaves the normal range takes the scaled path.
        assert_eq!(super::plain(&[1e-200, 1e-200], &[1e-300]), None);
        // Subnormal factors with normal partial results round alike too.
        let tiny = 3e-310;
        assert_eq!(
            super::plain(&[1e200, tiny], &[7.0]),
            Some(super::scaled(&[1e200, tiny], &[7.0]))
        );
    }

    #[test]
    fn cube_root_of_a_chain() {
        // (1e300)^3 / 1 is beyond f64; its cube root is not.
        let r = super::chain_cbrt(&[1e300, 1e300, 1e300], &[1.0]);
        assert!((r / 1e300 - 1.0).abs() < 4e-16);
        let r = super::chain_cbrt(&[1e-300, 1e-300], &[1e300, 8.0]);
        assert!((r / 5e-301 - 1.0).abs() < 4e-16, "{r}");
        assert_eq!(super::chain_cbrt(&[0.0, 2.0], &[1.0]), 0.0);
        let r = super::chain_cbrt(&[3.0, 9.0], &[1.0]);
        assert_eq!(r, libm::cbrt(27.0));
    }
}
