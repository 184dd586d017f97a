//! Products and quotients of many factors without intermediate overflow or underflow:
//! mantissas and exponents are carried apart (frexp), so that a valid but extreme
//! scene (a subnormal radius, a shear modulus of 1e300 Pa) gives the true result or
//! its limit, never 0/0 or inf/inf. In the normal range the roundings are those of the
//! plain expression evaluated left to right.

/// `num[0] num[1] ... / (den[0] den[1] ...)`.
pub(crate) fn chain(num: &[f64], den: &[f64]) -> f64 {
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
    libm::ldexp(m, e)
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
}
