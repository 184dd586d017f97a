//! Root finding for the reference: bracket an increasing function by doubling,
//! then Brent's method. Used for k' from theta (eqs 5-6) and for the critical
//! angle (eq 18 with d/b = 1).

/// Largest number of function evaluations one solve may spend; Brent needs about
/// ten on these smooth functions, bracketing at most ~2100 doublings of f64 range.
const MAX_EVALUATIONS: usize = 2400;

/// The `x` in `(lo_limit, hi_limit]` with `f(x) = 0`, for `f` increasing there,
/// starting the search at `guess`. `None` when `f(hi_limit) < 0` (no root below
/// the limit) or when `f` is NaN somewhere on the way.
pub(crate) fn increasing_root(
    f: impl Fn(f64) -> f64,
    guess: f64,
    lo_limit: f64,
    hi_limit: f64,
) -> Option<f64> {
    let mut hi = if guess > lo_limit && guess <= hi_limit {
        guess
    } else {
        hi_limit
    };
    let mut f_hi = f(hi);
    let mut evaluations: usize = 1;
    // Grow upwards until f(hi) >= 0.
    while f_hi < 0.0 {
        if hi >= hi_limit {
            return None;
        }
        hi = libm::fmin(2.0 * hi, hi_limit);
        f_hi = f(hi);
        evaluations = evaluations.saturating_add(1); // at most ~2100 doublings of a double
    }
    if f_hi == 0.0 {
        return Some(hi);
    }
    // Shrink downwards until f(lo) <= 0.
    let mut lo = hi;
    let mut f_lo = f_hi;
    while f_lo > 0.0 {
        hi = lo;
        f_hi = f_lo;
        lo *= 0.5;
        if lo <= lo_limit || evaluations > MAX_EVALUATIONS {
            return None;
        }
        f_lo = f(lo);
        evaluations = evaluations.saturating_add(1);
    }
    if f_lo.is_nan() || f_hi.is_nan() {
        return None;
    }
    Some(brent(f, lo, hi, f_lo, f_hi))
}

/// Brent's method (zeroin) on a bracket with `fa <= 0 <= fb`, to the last ulp.
fn brent(f: impl Fn(f64) -> f64, a: f64, b: f64, fa: f64, fb: f64) -> f64 {
    let (mut a, mut b, mut fa, mut fb) = (a, b, fa, fb);
    let (mut c, mut fc) = (a, fa);
    let mut d = b - a;
    let mut e = d;
    for _ in 0..MAX_EVALUATIONS {
        if (fb > 0.0 && fc > 0.0) || (fb < 0.0 && fc < 0.0) {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if libm::fabs(fc) < libm::fabs(fb) {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol = 2.0 * f64::EPSILON * libm::fabs(b);
        let xm = 0.5 * (c - b);
        if libm::fabs(xm) <= tol || fb == 0.0 {
            return b;
        }
        if libm::fabs(e) >= tol && libm::fabs(fa) > libm::fabs(fb) {
            // Inverse quadratic interpolation, or secant when only two points.
            let s = fb / fa;
            let (mut p, mut q) = if a == c {
                (2.0 * xm * s, 1.0 - s)
            } else {
                let q = fa / fc;
                let r = fb / fc;
                (
                    s * (2.0 * xm * q * (q - r) - (b - a) * (r - 1.0)),
                    (q - 1.0) * (r - 1.0) * (s - 1.0),
                )
            };
            if p > 0.0 {
                q = -q;
            } else {
                p = -p;
            }
            if 2.0 * p < libm::fmin(3.0 * xm * q - libm::fabs(tol * q), libm::fabs(e * q)) {
                e = d;
                d = p / q;
            } else {
                d = xm;
                e = d;
            }
        } else {
            d = xm;
            e = d;
        }
        a = b;
        fa = fb;
        b += if libm::fabs(d) > tol {
            d
        } else {
            libm::copysign(tol, xm)
        };
        fb = f(b);
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_roots_to_the_last_ulps() {
        let r = increasing_root(|x| x * x * x - 2.0, 1e-3, 0.0, 10.0).unwrap();
        assert!((r / libm::cbrt(2.0) - 1.0).abs() < 4.0 * f64::EPSILON);
        let r = increasing_root(|x| libm::log(x) + 300.0, 1.0, 0.0, 1.0).unwrap();
        assert!((r / libm::exp(-300.0) - 1.0).abs() < 1e-13);
    }

    #[test]
    fn says_when_there_is_no_root() {
        assert_eq!(increasing_root(|x| x - 5.0, 1.0, 0.0, 2.0), None);
        assert_eq!(increasing_root(|_| f64::NAN, 1.0, 0.0, 2.0), None);
    }
}
