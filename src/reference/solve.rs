//! Root finding for the reference: Newton's method in `w = ln x` for a function that
//! increases with `x` on `(0, hi]`, with its analytic slope, kept inside a bracket so
//! that it cannot diverge. Used for k' from theta (eqs 5-6), k' from `g = m n theta`
//! and the critical angle (eq 18 with d/b = 1); Brent's method on a bracket
//! ([`increasing_root`]) for the inverses' one-dimensional solves in d/b.
//!
//! The functions solved are logarithms of ratios, `F = ln(q(x)/target)`, nearly linear
//! in `w` (`ln tan^2(theta/2)` has slope `2 - 1/(ln(4/k') - 1)` at small k', 3/2 at
//! k' = 1), so a good seed converges in one or two steps. Once a Newton step `dw` is so
//! small that the next one would be below 2^-60 (`|dw| (c |dw| + e) < 2^-60`, with `c`
//! a bound on `|F''/(2 F')|` and `e` the relative error of the slope), the step is taken
//! without evaluating `F` again: the caller gets the last evaluation and `dw`, and
//! carries its quantities over the step to first order (their second-order error is
//! below `|dw|^2 < 1e-18`).

/// Largest number of evaluations of one solve: bisecting `ln x` over the whole f64
/// range down to an ulp takes about 64; Newton from the seeds takes 1 to 4.
const MAX_EVALUATIONS: usize = 200;

/// A step is taken without a further evaluation when its predicted error is below this.
const ACCEPT: f64 = 8.673_617_379_884_035e-19; // 2^-60

/// One evaluation of `F` at `x`, with what the caller wants to keep.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Sample<T> {
    /// `F(x)`.
    pub value: f64,
    /// `dF/dw = x dF/dx`.
    pub slope: f64,
    /// Bound on the relative error of `slope`.
    pub slope_error: f64,
    /// Bound on `|F''(w) / (2 F'(w))|` near `x`.
    pub curvature: f64,
    /// The caller's quantities at `x`.
    pub at: T,
}

/// The root: `x = from (1 + expm1(dw))`, where `from` is the last point evaluated,
/// `sample` its evaluation and `dw` the final Newton step in `ln x` (0 when the root is
/// the point evaluated).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Root<T> {
    /// The root.
    pub x: f64,
    /// The last Newton step, `ln(x / from)`.
    pub dw: f64,
    /// The evaluation at `from`.
    pub sample: Sample<T>,
}

/// The `x` in `(0, hi_limit]` with `F(x) = 0`, for `F` increasing in `x`, starting from
/// `seed`. `None` when `F(hi_limit) < 0` (no root up to the limit) or `F` is NaN
/// (`f` returns `None`) on the way.
pub(crate) fn log_newton<T: Copy>(
    mut f: impl FnMut(f64) -> Option<Sample<T>>,
    seed: f64,
    hi_limit: f64,
) -> Option<Root<T>> {
    if hi_limit.is_nan() || hi_limit <= 0.0 {
        return None;
    }
    // (lo, hi): F(lo) < 0 < F(hi); lo = 0 until a point below the root is seen,
    // hi = hi_limit unchecked until F(hi_limit) is known to be positive.
    let (mut lo, mut hi) = (0.0, hi_limit);
    let mut hi_known = false;
    let mut x = if seed > 0.0 && seed <= hi_limit {
        seed
    } else {
        hi_limit
    };
    for _ in 0..MAX_EVALUATIONS {
        #[cfg(test)]
        super::cost::count_evaluation();
        let s = f(x)?;
        if s.value.is_nan() || s.slope.is_nan() {
            return None;
        }
        if s.value == 0.0 {
            return Some(Root {
                x,
                dw: 0.0,
                sample: s,
            });
        }
        if s.value < 0.0 {
            if x >= hi_limit {
                return None;
            }
            lo = x;
        } else {
            hi = x;
            hi_known = true;
        }
        let newton = if s.slope > 0.0 && s.slope.is_finite() {
            // Bounded so that a wild slope cannot throw x out of f64 range.
            (-s.value / s.slope).clamp(-64.0, 64.0)
        } else {
            f64::NAN
        };
        let next = x + x * expm1(newton);
        // The slope's and F's own relative errors (F's series, `ln_ratio`, 2e-13) scale
        // the step alike.
        let predicted =
            libm::fabs(newton) * (s.curvature * libm::fabs(newton) + s.slope_error + 2e-13);
        if predicted < ACCEPT || next == x {
            // The step's error is far below an ulp (or the step is): a root found at
            // `x` by noise in F may round `next` onto or past the bracket's end, kept
            // at its upper end (k' <= 1).
            return Some(Root {
                x: next.min(hi),
                dw: newton,
                sample: s,
            });
        }
        if next > lo && next < hi {
            x = next;
        } else if next >= hi && !hi_known {
            x = hi_limit; // the root may lie beyond every point seen: try the limit
        } else if lo > 0.0 {
            // Bisect in ln x; done when the bracket is two ulps wide.
            let mid = libm::sqrt(lo) * libm::sqrt(hi);
            if !(mid > lo && mid < hi) {
                return Some(Root {
                    x,
                    dw: 0.0,
                    sample: s,
                });
            }
            x = mid;
        } else {
            x = hi * (1.0 / 65536.0);
        }
    }
    None
}

/// `e^x - 1`; below 1e-3 by its series to `x^4` (relative error below `x^4/120 < 1e-14`,
/// on a step that is itself a correction), which is what the last steps take.
fn expm1(x: f64) -> f64 {
    if x.abs() < 1e-3 {
        x * (1.0 + x * (0.5 + x * (1.0 / 6.0 + x * (1.0 / 24.0))))
    } else {
        libm::expm1(x)
    }
}

/// Largest number of function evaluations one bracketed solve may spend; Brent needs
/// about ten on these smooth functions, bracketing at most ~2100 doublings of f64 range.
const MAX_BRENT_EVALUATIONS: usize = 2400;

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
        if lo <= lo_limit || evaluations > MAX_BRENT_EVALUATIONS {
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
    for _ in 0..MAX_BRENT_EVALUATIONS {
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

    fn sample(value: f64, slope: f64) -> Option<Sample<()>> {
        Some(Sample {
            value,
            slope,
            slope_error: 0.0,
            curvature: 1.0,
            at: (),
        })
    }

    #[test]
    fn finds_roots_to_the_last_ulps() {
        // x^3 = 2 as ln(x^3 / 2): slope 3 in ln x.
        let r = log_newton(|x| sample(libm::log(x * x * x / 2.0), 3.0), 1e-3, 10.0).unwrap();
        assert!((r.x / libm::cbrt(2.0) - 1.0).abs() < 2.0 * f64::EPSILON);
        // ln(x) + 300 = 0 in ln x: linear, one step from anywhere.
        let r = log_newton(|x| sample(libm::log(x) + 300.0, 1.0), 1.0, 1.0).unwrap();
        assert!((r.x / libm::exp(-300.0) - 1.0).abs() < 1e-13);
        // A wrong slope (half the true one) still converges, inside the bracket.
        let r = log_newton(|x| sample(libm::log(x / 0.3), 0.5), 1e-9, 1.0).unwrap();
        assert!((r.x / 0.3 - 1.0).abs() < 2.0 * f64::EPSILON);
    }

    #[test]
    fn says_when_there_is_no_root() {
        assert!(log_newton(|x| sample(x - 5.0, x), 1.0, 2.0).is_none());
        assert!(log_newton(|_| sample(f64::NAN, 1.0), 1.0, 2.0).is_none());
        assert!(log_newton(|_| None::<Sample<()>>, 1.0, 2.0).is_none());
    }
}
