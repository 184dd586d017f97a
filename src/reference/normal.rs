//! The normal problem (paper section 5): the Hertz contact ellipse, eqs (2)-(7).

use super::carlson::carlson_rd_pair;
use super::chain::chain;
use super::solve::{Root, Sample, log_newton};
use core::f64::consts::{FRAC_PI_2, LN_2, PI};

/// Below this theta the small-theta asymptotics (reference README) are exact in
/// f64 (their relative error falls like theta^2: 3.4e-8 at 1e-3, so < 1e-200 here),
/// and `k'^2` would underflow in the exact path.
const ASYMPTOTIC_BELOW: f64 = 1e-100;

/// The shape of the contact ellipse at auxiliary angle theta: `k' = n/m` and the
/// coefficients m, n of eqs (2)-(3) with the erratum of READING-NOTES.md
/// (`a = m L`, `b = n L`, `L^3 = 3 P (1 - nu) R1 R2 / (2 G (R1 + R2))`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct EllipseShape {
    /// Auxiliary angle theta (rad), eq (4).
    pub theta: f64,
    /// Complementary modulus `k' = n/m = b/a`, in [0, 1].
    pub kprime: f64,
    /// Coefficient m of the semi-axis along the rollers, `a = m L`; +inf at theta = 0.
    pub m: f64,
    /// Coefficient n of the semi-axis along the rolling direction, `b = n L`; 0 at theta = 0.
    pub n: f64,
}

impl EllipseShape {
    /// `m n`, which sets the contact area `pi a b = pi m n L^2`; +inf at theta = 0.
    pub fn mn(&self) -> f64 {
        if self.theta == 0.0 {
            f64::INFINITY
        } else {
            self.m * self.n
        }
    }

    /// `g = m n theta`, which alone sets the slip ratio (eq 16) and `P0*` (eq 18);
    /// 0 at theta = 0 (where it falls like theta^(2/3)).
    pub fn g(&self) -> f64 {
        if self.theta == 0.0 {
            0.0
        } else {
            self.m * self.n * self.theta
        }
    }
}

/// Below this `k^2 = 1 - k'^2` the quotient `D = (R_D1 - R_D2) / k^2` of the slopes
/// cancels (its error is about `eps / k^2`) and its series is used instead.
const SERIES_BELOW: f64 = 2e-4;

/// One evaluation along k' of the ratio of eqs (5)-(6): `R_D1 = R_D(0, k'^2, 1)`,
/// `R_D2 = R_D(0, 1, k'^2)` (so `K - E = k^2 R_D1 / 3`, `E - k'^2 K = k^2 k'^2 R_D2 / 3`,
/// DLMF 19.25.1) and their slopes.
///
/// The slopes follow from `dK/dk' = -(E - k'^2 K)/(k^2 k')` and
/// `dE/dk' = k' (K - E)/k^2` (DLMF 19.4.1 with `dk/dk' = -k'/k`): with
/// `D = (R_D1 - R_D2) / k^2`,
///
/// ```text
/// d R_D1 / dk' = k' D,    d R_D2 / dk' = -(D + 3 R_D2) / k',
/// ```
///
/// and near `k' = 1`, from the series of K and E in `k^2` (DLMF 19.5.1-2),
/// `D = (3 pi / 2)(-3/8 - 15 k^2/32 - 525 k^4/1024 + O(k^6))`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Point {
    /// `k'`.
    pub kprime: f64,
    /// `R_D(0, k'^2, 1)`.
    pub rd1: f64,
    /// `R_D(0, 1, k'^2)`.
    pub rd2: f64,
    /// `D = (R_D1 - R_D2) / k^2`.
    pub d: f64,
    /// Bound on the relative error of `d`.
    pub d_error: f64,
}

impl Point {
    /// The evaluation at `k'` in (0, 1].
    pub fn at(kprime: f64) -> Point {
        let (rd1, rd2) = carlson_rd_pair(kprime * kprime);
        let k2 = (1.0 - kprime) * (1.0 + kprime);
        let (d, d_error) = if k2 < SERIES_BELOW {
            let series = -0.375 - k2 * (15.0 / 32.0 + k2 * (525.0 / 1024.0));
            (1.5 * PI * series, 1e-11)
        } else {
            let diff = rd1 - rd2;
            (
                diff / k2,
                8.0 * f64::EPSILON * (rd1 + rd2) / libm::fabs(diff),
            )
        };
        Point {
            kprime,
            rd1,
            rd2,
            d,
            d_error,
        }
    }

    /// `tan^2(theta/2) = R_D1 / R_D2` (the ratio of eqs 5 and 6), increasing from 0 to 1.
    pub fn tan_half_squared(&self) -> f64 {
        self.rd1 / self.rd2
    }

    /// theta = `2 atan(sqrt(R_D1 / R_D2))`.
    pub fn theta(&self) -> f64 {
        2.0 * libm::atan(libm::sqrt(self.rd1 / self.rd2))
    }

    /// `d ln tan^2(theta/2) / d ln k' = k'^2 D / R_D1 + (D + 3 R_D2) / R_D2`, and a bound on
    /// its relative error.
    pub fn tan_half_squared_slope(&self) -> (f64, f64) {
        let k2p = self.kprime * self.kprime;
        let from_d = self.d * (k2p / self.rd1 + 1.0 / self.rd2);
        let slope = from_d + 3.0;
        let error = libm::fabs(from_d) * self.d_error / slope + 8.0 * f64::EPSILON;
        (slope, error)
    }

    /// `d ln theta / d ln k' = t (d ln t^2 / d ln k') / ((1 + t^2) theta)`,
    /// `t = tan(theta/2)`, at `theta = self.theta()`, and its error bound.
    pub fn theta_slope(&self, theta: f64) -> (f64, f64) {
        let (slope, error) = self.tan_half_squared_slope();
        let t2 = self.tan_half_squared();
        (libm::sqrt(t2) * slope / ((1.0 + t2) * theta), error)
    }

    /// `m n = k' m^2` with `m^3 = 2 (R_D1 + R_D2) / (3 pi)` (eq 5 with
    /// `sin^2(theta/2) = R_D1 / (R_D1 + R_D2)`).
    pub fn mn(&self) -> f64 {
        let m = libm::cbrt(2.0 * (self.rd1 + self.rd2) / (3.0 * PI));
        self.kprime * m * m
    }

    /// `ln(m n q)`, by the cube `(m n q)^3 = (k' M)^2 (k' q^3)`, `M = m^3`, which needs
    /// no cube root (its two factors stay in range for k' down to 1e-102 and
    /// `q ~ 1/(m n)`), or by [`Point::mn`] where the cube leaves the normal range.
    pub fn ln_mn_ratio(&self, q: f64) -> f64 {
        let km = self.kprime * (2.0 * (self.rd1 + self.rd2) / (3.0 * PI));
        let cube = km * km * (self.kprime * (q * q * q));
        if cube.is_normal() {
            ln_ratio(cube) / 3.0
        } else {
            ln_ratio(self.mn() * q)
        }
    }

    /// `d ln(m n) / d ln k' = 1 - (2/3)(R_D1 + 2 R_D2) / (R_D1 + R_D2)`: from the slopes
    /// above, `k' d(R_D1 + R_D2)/dk' = -k^2 D - 3 R_D2 = -(R_D1 + 2 R_D2)`.
    pub fn mn_slope(&self) -> f64 {
        1.0 - (2.0 / 3.0) * (self.rd1 + 2.0 * self.rd2) / (self.rd1 + self.rd2)
    }
}

/// `ln(x / target)` with the slope and error bound of `ln x`, as the solver wants it.
fn log_ratio_sample<T>(x: f64, target: f64, slope: (f64, f64), at: T) -> Option<Sample<T>> {
    Some(Sample {
        value: ln_ratio(x / target),
        slope: slope.0,
        slope_error: slope.1,
        curvature: 1.0,
        at,
    })
}

/// `ln r`; near the root, `r = 1 + u` with `|u| < 1e-3`, by its series to `u^4`
/// (relative error below `u^4 / 5 < 2e-13`: it scales a Newton step, not the root).
fn ln_ratio(r: f64) -> f64 {
    let u = r - 1.0;
    if libm::fabs(u) < 1e-3 {
        u * (1.0 - u * (0.5 - u * (1.0 / 3.0 - 0.25 * u)))
    } else {
        libm::log(r)
    }
}

/// The coefficient `c` of `tan^2(theta/2) = k'^2 Lam (1 + c k'^2)` at small k', with
/// `Lam = ln(4/k') - 1`, from `K = L + (k'^2/4)(L - 1)` and `E = 1 + (k'^2/2)(L - 1/2)`,
/// `L = Lam + 1` (DLMF 19.12.1-2): `c = L/2 + 1/4 - L / (4 Lam)`.
fn small_kprime_c(lam: f64) -> f64 {
    let l = lam + 1.0;
    0.5 * l + 0.25 - l / (4.0 * lam)
}

/// The root of `h(Lam) = Lam - a ln(Lam) - b(Lam) - m = 0` for `Lam = ln(4/k') - 1 > 1`
/// (the small-k' expansions below), `b` a small correction whose slope is neglected.
/// From `Lam0 = m + a ln(m) (1 + a/m)` (the expansion of the root in `1/m`, error about
/// `a^3 ln(m)^2 / (2 m^2)`, 3e-3 at m = 10) one Halley step (`h'' = a / Lam^2`) leaves
/// about `(a / Lam^3) e^3`, below 1e-10 relative; Newton steps follow only while the
/// error a step leaves may exceed 1e-11 relative. One logarithm for the start and one a
/// step (two in all where the start is that close).
/// `None` where `m` is too small for the expansions (k' > 0.3).
fn solve_lambda(a: f64, m: f64, b: impl Fn(f64) -> f64) -> Option<f64> {
    if m.is_nan() || m <= 1.5 {
        return None;
    }
    let mut lam = m + a * libm::log(m) * (1.0 + a / m);
    for i in 0..8 {
        let h = lam - a * libm::log(lam) - b(lam) - m;
        let slope = 1.0 - a / lam;
        let curvature = a / (lam * lam);
        // The error a step leaves: about `(a / Lam^3) step^3` after Halley's,
        // `(a / (2 Lam^2)) step^2` after Newton's.
        let (step, left) = if i == 0 {
            let step = 2.0 * h * slope / (2.0 * slope * slope - h * curvature);
            (step, curvature / lam * step * step * step.abs())
        } else {
            let step = h / slope;
            (step, 0.5 * curvature * step * step)
        };
        lam -= step;
        if lam.is_nan() || lam <= 1.0 {
            return None;
        }
        if left < 1e-11 * lam {
            break;
        }
    }
    Some(lam)
}

/// A seed `k'` for `tan^2(theta/2) = t2`: `t2 = k'^2 Lam (1 + c k'^2)`, that is
/// `Lam - ln(Lam)/2 - ln(1 + c k'^2)/2 = ln(4/t) - 1` with `k'^2 ~ t2/Lam` in the
/// correction (relative error about `k'^4 L^2`). Where the expansion is no guide,
/// `t / sqrt(max(ln(4/t) - 1, 1/4))` (at most 1).
fn seed_for_tan_half_squared(t2: f64) -> f64 {
    let m = 2.0 * LN_2 - 1.0 - 0.5 * libm::log(t2);
    let correction = |lam: f64| t2 / lam * small_kprime_c(lam);
    // ln(1 + x) by its series below 1e-3 (error below x^4/4 < 3e-13).
    let log1p = |x: f64| {
        if x < 1e-3 {
            x * (1.0 - x * (0.5 - x / 3.0))
        } else {
            libm::log1p(x)
        }
    };
    match solve_lambda(0.5, m, |lam| 0.5 * log1p(correction(lam))) {
        Some(lam) => libm::sqrt(t2 / (lam * (1.0 + correction(lam)))),
        None => libm::fmin(libm::sqrt(t2 / libm::fmax(m, 0.25)), 1.0),
    }
}

/// `(32 / pi^2)^(1/3)`, held by a test.
const CBRT_32_OVER_PI_SQUARED: f64 = 1.480_073_936_614_712_4;

/// A seed `k'` for `g = m n theta` (eqs 5-6): with E and tan(theta/2) to order k'^2,
/// `ln g = ln c0 + (2/3) w + ln(Lam)/2 + k'^2 ((2/3)(L/2 - 1/4) + c/2 - Lam/3)`,
/// `w = ln k' = ln 4 - 1 - Lam`, `c0 = (32/pi^2)^(1/3)`: solved for Lam with the
/// correction's `k'^2` at leading order, `k' = (g / (c0 sqrt(Lam)))^(3/2)`.
pub(crate) fn seed_for_g(g: f64) -> f64 {
    let c0 = CBRT_32_OVER_PI_SQUARED;
    let leading = |lam: f64| {
        let q = g / (c0 * libm::sqrt(lam));
        q * q * q
    };
    let correction = |lam: f64| {
        let l = lam + 1.0;
        let x = (2.0 / 3.0) * (0.5 * l - 0.25) + 0.5 * small_kprime_c(lam) - lam / 3.0;
        leading(lam) * x
    };
    let m = 2.0 * LN_2 - 1.0 - 1.5 * libm::log(g / c0);
    match solve_lambda(0.75, m, |lam| 1.5 * correction(lam)) {
        Some(lam) => {
            let x = correction(lam);
            let q = g * (1.0 - x * (1.0 - 0.5 * x)) / (c0 * libm::sqrt(lam));
            q * libm::sqrt(q)
        }
        None => libm::fmin(libm::pow(g / c0, 1.5), 1.0),
    }
}

/// The `k'` in (0, `kprime_max`] where `m n phi(theta) = target` for an increasing
/// `phi(theta)` given with its derivative `phi_slope(theta) = d ln phi / d ln theta` and
/// a curvature bound (see [`super::solve`]), from `seed`; the root and theta there.
/// `None` when `m n phi` stays below `target` up to `kprime_max`.
pub(crate) fn kprime_for_mn_phi(
    target: f64,
    phi: impl Fn(f64) -> (f64, f64, f64),
    seed: f64,
    kprime_max: f64,
) -> Option<(f64, f64)> {
    let root = log_newton(
        |k| {
            let p = Point::at(k);
            let theta = p.theta();
            let (ph, ph_slope, curvature) = phi(theta);
            let (theta_slope, error) = p.theta_slope(theta);
            Some(Sample {
                value: p.ln_mn_ratio(ph / target),
                slope: p.mn_slope() + ph_slope * theta_slope,
                slope_error: error,
                curvature,
                at: (theta, theta_slope),
            })
        },
        seed,
        kprime_max,
    )?;
    let (theta, theta_slope) = root.sample.at;
    Some((root.x, theta + theta * theta_slope * root.dw))
}

/// The ellipse shape at a given `k'` in (0, 1]: theta from the ratio of eqs (5)-(6),
/// m from eq (5) as `m^3 = 2 R_D(0, k'^2, 1) / (3 pi sin^2(theta/2))`, `n = k' m`.
pub fn shape_from_kprime(kprime: f64) -> EllipseShape {
    let k2 = kprime * kprime;
    let (rd1, rd2) = carlson_rd_pair(k2);
    let theta = 2.0 * libm::atan(libm::sqrt(rd1 / rd2));
    // sin^2(theta/2) = t^2 / (1 + t^2) with t^2 = rd1/rd2, no trigonometry needed.
    let sin2 = rd1 / (rd1 + rd2);
    let m = libm::cbrt(2.0 * rd1 / (3.0 * PI * sin2));
    EllipseShape {
        theta,
        kprime,
        m,
        n: kprime * m,
    }
}

/// `Lam = ln(4/k') - 1` at small theta, the root of `Lam = ln(8 sqrt(Lam)/theta) - 1`.
/// Written with `ln 8 - ln theta`, so that subnormal theta does not overflow `8/theta`.
fn small_theta_lambda(theta: f64) -> f64 {
    let ln8_over_theta = core::f64::consts::LN_2 * 3.0 - libm::log(theta);
    let mut lam = ln8_over_theta;
    for _ in 0..64 {
        let next = ln8_over_theta + 0.5 * libm::log(lam) - 1.0;
        if libm::fabs(next - lam) <= 1e-16 * lam {
            return next;
        }
        lam = next;
    }
    lam
}

/// Small-theta asymptotics of the reference README: `k' ~ theta/(2 sqrt Lam)`,
/// `m ~ (8 Lam/(pi theta^2))^(1/3)`, `n ~ (theta/(pi sqrt Lam))^(1/3)`.
/// Powers of theta are taken as powers of `cbrt(theta)`, so that theta down to the
/// smallest subnormal gives finite m (about 1e216) and non-zero n.
pub fn small_theta_shape(theta: f64) -> EllipseShape {
    let lam = small_theta_lambda(theta);
    let root_lam = libm::sqrt(lam);
    let cbrt_theta = libm::cbrt(theta);
    EllipseShape {
        theta,
        kprime: theta / (2.0 * root_lam),
        m: libm::cbrt(8.0 * lam / PI) / (cbrt_theta * cbrt_theta),
        n: libm::cbrt(1.0 / (PI * root_lam)) * cbrt_theta,
    }
}

/// The theta with `g(theta) = g` by the small-theta asymptotics, for g below
/// [`small_theta_g_limit`]: `theta = (g / ((8/pi^2)^(1/3) Lam^(1/6)))^(3/2)`, with Lam
/// (which depends on theta only through its logarithm) by fixed-point iteration.
pub fn small_theta_for_g(g: f64) -> f64 {
    let scale = libm::cbrt(8.0 / (PI * PI));
    let mut theta = libm::pow(g / scale, 1.5);
    for _ in 0..64 {
        let next = libm::pow(
            g / (scale * libm::pow(small_theta_lambda(theta), 1.0 / 6.0)),
            1.5,
        );
        if libm::fabs(next - theta) <= 1e-16 * theta {
            return next;
        }
        theta = next;
    }
    theta
}

/// g at the theta below which the asymptotics replace the exact path (1e-100):
/// `small_theta_shape(1e-100).g()`, held by a test (it is asked on every estimate).
pub fn small_theta_g_limit() -> f64 {
    SMALL_THETA_G_LIMIT
}

/// `small_theta_shape(ASYMPTOTIC_BELOW).g()`.
const SMALL_THETA_G_LIMIT: f64 = 4.986_774_454_203_209e-67;

/// m(theta), n(theta) and `k'` for theta in [0, pi/2], eqs (5)-(6), to a few ulps.
/// At theta = 0 the ellipse is an infinite strip: `k' = 0`, `m = inf`, `n = 0`.
/// `None` for theta outside [0, pi/2] or NaN.
pub fn ellipse_shape(theta: f64) -> Option<EllipseShape> {
    if !(0.0..=FRAC_PI_2).contains(&theta) {
        return None;
    }
    if theta == 0.0 {
        return Some(EllipseShape {
            theta,
            kprime: 0.0,
            m: f64::INFINITY,
            n: 0.0,
        });
    }
    if theta < ASYMPTOTIC_BELOW {
        return Some(small_theta_shape(theta));
    }
    let t = libm::tan(0.5 * theta);
    let target = t * t;
    let root: Option<Root<Point>> = log_newton(
        |k| {
            let p = Point::at(k);
            log_ratio_sample(p.tan_half_squared(), target, p.tan_half_squared_slope(), p)
        },
        seed_for_tan_half_squared(target),
        1.0,
    );
    // tan^2(theta/2) <= 1 = its value at k' = 1: a root exists; 1 is the limit.
    let (kprime, rd1) = root.map_or_else(
        || (1.0, Point::at(1.0).rd1),
        |r| {
            let p = r.sample.at;
            // R_D1 carried over the last step: d R_D1 / d ln k' = k'^2 D.
            (r.x, p.rd1 + p.kprime * p.kprime * p.d * r.dw)
        },
    );
    // m from eq (5) with sin^2(theta/2) = t^2 / (1 + t^2).
    let m = libm::cbrt(2.0 * rd1 * (1.0 + target) / (3.0 * PI * target));
    Some(EllipseShape {
        theta,
        kprime,
        m,
        n: kprime * m,
    })
}

/// The theta in [0, pi/2] at which `g(theta) = m n theta` equals `g`, or `None`
/// when `g > pi/2 = g(pi/2)` (no such theta) or `g` is NaN or negative.
pub fn theta_for_g(g: f64) -> Option<EllipseShape> {
    if !(0.0..=FRAC_PI_2).contains(&g) {
        return None;
    }
    if g == 0.0 {
        return ellipse_shape(0.0);
    }
    if g < small_theta_g_limit() {
        return Some(small_theta_shape(small_theta_for_g(g)));
    }
    let theta = kprime_for_mn_phi(g, |theta| (theta, 1.0, 1.0), seed_for_g(g), 1.0)
        .map_or(FRAC_PI_2, |(_, theta)| theta);
    // Take m, n at that theta by the forward path so that the solve and the forward
    // evaluation agree.
    ellipse_shape(libm::fmin(theta, FRAC_PI_2))
}

/// Semi-axes `(a, b)` (m) for load `load` (N) given the scene's Hertz scale
/// `v = (L^3/P)^(1/3)`, `L^3/P = 3 (1 - nu) R / (2 G)`, `R = R1 R2/(R1 + R2)`.
pub fn semi_axes(shape: &EllipseShape, hertz_scale: f64, load: f64) -> (f64, f64) {
    let cbrt_load = libm::cbrt(load);
    let a = if cbrt_load == 0.0 {
        0.0
    } else {
        chain(&[shape.m, hertz_scale, cbrt_load], &[])
    };
    (a, chain(&[shape.n, hertz_scale, cbrt_load], &[]))
}

/// Peak pressure `p0 = p(0, 0) = 3 P / (2 pi a b)` (eq 7), written as
/// `3 P^(1/3) / (2 pi m n v^2)` so that P = 0 gives 0 and theta = 0 gives 0.
pub fn peak_pressure(shape: &EllipseShape, hertz_scale: f64, load: f64) -> f64 {
    let v = hertz_scale;
    chain(&[3.0, libm::cbrt(load)], &[2.0, PI, shape.mn(), v, v])
}

/// Hertz pressure `p(x, y)` (Pa) of eq (7) inside the ellipse, 0 outside.
pub fn pressure(p0: f64, a: f64, b: f64, x: f64, y: f64) -> f64 {
    let inside = 1.0 - (x / a) * (x / a) - (y / b) * (y / b);
    if inside > 0.0 {
        p0 * libm::sqrt(inside)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `(ln tan^2(theta/2), ln theta, ln(m n))` at `w = ln k'`.
    fn logs(w: f64) -> [f64; 3] {
        let p = Point::at(libm::exp(w));
        [
            libm::log(p.tan_half_squared()),
            libm::log(p.theta()),
            libm::log(p.mn()),
        ]
    }

    fn kprimes() -> impl Iterator<Item = f64> {
        (0..=40)
            .map(|i| libm::pow(10.0, -12.0 + 12.0 * i as f64 / 40.0))
            .chain([0.3, 0.9, 0.99, 0.999, 1.0 - 1e-5, 1.0 - 1e-7])
    }

    #[test]
    fn slopes_are_the_derivatives() {
        // Central differences in w = ln k' (error ~ h^2 + eps/h ~ 1e-10).
        let h = 1e-5;
        for k in kprimes() {
            let w = libm::log(k);
            let (up, down) = (logs(w + h), logs(w - h));
            let p = Point::at(k);
            let theta = p.theta();
            let analytic = [
                p.tan_half_squared_slope().0,
                p.theta_slope(theta).0,
                p.mn_slope(),
            ];
            let mid = logs(w);
            for q in 0..3 {
                let fd = (up[q] - down[q]) / (2.0 * h);
                let scale = libm::fmax(libm::fabs(analytic[q]), 1.0);
                assert!(
                    (fd - analytic[q]).abs() < 1e-8 * scale,
                    "k'={k} quantity {q}: {fd} {}",
                    analytic[q]
                );
                // The solver's curvature bound: |F''/(2F')| <= 1 for ln t^2 and
                // ln g = ln(m n) + ln theta.
                let second = |i: usize| (up[i] - 2.0 * mid[i] + down[i]) / (h * h);
                if q == 0 {
                    assert!(second(0).abs() / (2.0 * analytic[0]) < 1.0, "k'={k}");
                }
                if q == 2 {
                    let g_slope = analytic[1] + analytic[2];
                    let g_second = second(1) + second(2);
                    assert!(g_second.abs() / (2.0 * g_slope) < 1.0, "k'={k}");
                }
            }
        }
    }

    #[test]
    fn slope_series_meets_the_difference() {
        // D from its series at k^2 just below SERIES_BELOW, and from the difference just above.
        let below = Point::at(libm::sqrt(1.0 - 0.999 * SERIES_BELOW));
        let above = Point::at(libm::sqrt(1.0 - 1.001 * SERIES_BELOW));
        assert!((below.d / above.d - 1.0).abs() < 1e-6);
        assert!(below.d_error < 1e-10 && above.d_error < 1e-10);
        // At k' = 1: D = -9 pi / 16.
        assert!((Point::at(1.0).d / (-9.0 * PI / 16.0) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn small_theta_g_limit_is_the_asymptotic_g() {
        assert_eq!(
            small_theta_g_limit(),
            small_theta_shape(ASYMPTOTIC_BELOW).g()
        );
    }

    #[test]
    fn seeds_are_close() {
        for i in 0..=30 {
            let theta = libm::pow(10.0, -12.0 + 10.0 * i as f64 / 30.0);
            let exact = ellipse_shape(theta).unwrap();
            let t = libm::tan(0.5 * theta);
            let by_t = seed_for_tan_half_squared(t * t) / exact.kprime - 1.0;
            let by_g = seed_for_g(exact.g()) / exact.kprime - 1.0;
            // The neglected terms are O(k'^4 L^2), k' ~ theta / (2 sqrt(L - 1)); the
            // iteration for Lam stops within 1e-10.
            let bound = 1e-10 + libm::pow(theta, 4.0);
            assert!(by_t.abs() < bound, "theta={theta}: {by_t}");
            assert!(by_g.abs() < bound, "theta={theta}: {by_g}");
        }
    }
}
