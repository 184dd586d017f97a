//! The normal problem (paper section 5): the Hertz contact ellipse, eqs (2)-(7).

use super::carlson::carlson_rd;
use super::chain::chain;
use super::solve::increasing_root;
use core::f64::consts::{FRAC_PI_2, PI};

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

/// `tan^2(theta/2)` as a function of `k'`: the ratio of eqs (5) and (6), in
/// Carlson's form `R_D(0, k'^2, 1) / R_D(0, 1, k'^2)`, increasing from 0 to 1.
fn tan_half_theta_squared(kprime: f64) -> f64 {
    let k2 = kprime * kprime;
    carlson_rd(0.0, k2, 1.0) / carlson_rd(0.0, 1.0, k2)
}

/// The ellipse shape at a given `k'` in (0, 1]: theta from the ratio of eqs (5)-(6),
/// m from eq (5) as `m^3 = 2 R_D(0, k'^2, 1) / (3 pi sin^2(theta/2))`, `n = k' m`.
pub fn shape_from_kprime(kprime: f64) -> EllipseShape {
    let k2 = kprime * kprime;
    let rd1 = carlson_rd(0.0, k2, 1.0);
    let rd2 = carlson_rd(0.0, 1.0, k2);
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

/// g at the theta below which the asymptotics replace the exact path (1e-100).
pub fn small_theta_g_limit() -> f64 {
    small_theta_shape(ASYMPTOTIC_BELOW).g()
}

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
    let guess = libm::fmin(small_theta_shape(libm::fmin(theta, 0.1)).kprime, 1.0);
    let kprime =
        increasing_root(|k| tan_half_theta_squared(k) - target, guess, 0.0, 1.0).unwrap_or(1.0);
    let k2 = kprime * kprime;
    let rd1 = carlson_rd(0.0, k2, 1.0);
    let s = libm::sin(0.5 * theta);
    let m = libm::cbrt(2.0 * rd1 / (3.0 * PI * s * s));
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
    // Small theta: g ~ theta^(2/3) (8/pi^2)^(1/3) Lam^(1/6); start from Lam ~ 10.
    let theta_guess = libm::pow(g / (0.932 * 1.47), 1.5);
    let guess = libm::fmin(small_theta_shape(libm::fmin(theta_guess, 0.1)).kprime, 1.0);
    let kprime = increasing_root(|k| shape_from_kprime(k).g() - g, guess, 0.0, 1.0)?;
    let shape = shape_from_kprime(kprime);
    // The root in k' is exact to an ulp; take m, n at that theta by the forward path
    // so that the solve and the forward evaluation agree.
    ellipse_shape(libm::fmin(shape.theta, FRAC_PI_2))
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
