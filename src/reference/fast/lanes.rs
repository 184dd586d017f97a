//! The fast path over N rows side by side, each stage a loop over the rows without a
//! branch (a row's decisions are masks, its table reads indexed once), so that the
//! compiler runs the stages in SIMD lanes; a row the fast path cannot answer is marked
//! and left to the caller. One scene for every row, or a scene per row
//! ([`SceneLanes`]): a scene's constants are a few products and divisions
//! ([`Constants::of`]), formed in lanes too.

use super::cbrt::cbrt;
use super::critical::theta_lane;
use super::force::axial_force_ratio;
use super::shape::shape_lane;
use crate::reference::{
    ANGLE_LIMIT, MODEL_SWITCH_BAND, ModelChoice, PRESSURE_LIMIT, SLENDER_LIMIT,
};
use core::f64::consts::{FRAC_PI_2, PI};

/// Answers this close (relative) to a threshold the reference decides on go to the
/// reference: both are within 1e-14 of the exact value, so beyond it they decide alike.
pub(super) const DECISION_GUARD: f64 = 1e-12;

/// `x` is not within [`DECISION_GUARD`] of `limit` (false for NaN).
#[inline(always)]
fn clear_of(x: f64, limit: f64) -> bool {
    (x - limit).abs() > DECISION_GUARD * limit
}

/// A positive normal number (false for NaN, 0, infinities and subnormals).
#[inline(always)]
pub(crate) fn positive_normal(x: f64) -> bool {
    (f64::MIN_POSITIVE..f64::INFINITY).contains(&x)
}

/// A scene's constants of the fast path.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Constants {
    /// c of eq (4), theta = c |phi|, and 1/c.
    pub c: f64,
    /// `1 / c`.
    pub inverse_c: f64,
    /// mu.
    pub friction: f64,
    /// `2 mu PRESSURE_LIMIT`: p0 / G above the limit where |phi| > this d/b.
    pub pressure_per_slip: f64,
    /// `(pi G v^2 / (3 mu))^3`: `(d/b)^3 = this (m n)^3 |phi|^3 / P` (eq 15).
    pub slip_cubed: f64,
    /// `(c 3 mu / pi)^3 / (G h^2 R^2)`, h = 1.5 (1 - nu): `g(theta0)^3 = this P` (eqs
    /// 15, 18 with d/b = 1).
    pub g_cubed_per_load: f64,
    /// `8 v^3 / length^3`: `(2a / length)^3 = this m^3 P` (section 9); 0 without a length.
    pub ratio_cubed_per_load: f64,
}

impl Constants {
    /// The constants of the scene R1, R2 (m), G (Pa), nu, mu and length (m; `None`
    /// without one), and whether every one and every product formed on the way is a
    /// positive normal number (else they are not to be used: the reference answers).
    /// With `v^3 = h R / G` (`v` the Hertz scale, `L = v P^(1/3)`) no cube root is
    /// taken: `(d/b)^3`'s constant is `pi^3 G (h R)^2 / (27 mu^3)`, `g(theta0)^3`'s is c^3
    /// over it. The scene's own checks ([`Scene::new`](crate::Scene::new)) are the
    /// caller's. Cost: one square root, six divisions; no branch.
    #[inline(always)]
    pub fn of(r1: f64, r2: f64, g: f64, nu: f64, mu: f64, length: Option<f64>) -> (Self, bool) {
        let (small, large) = (r1.min(r2), r1.max(r2));
        // c = 2 sqrt(R1 R2) / (R1 + R2) = 2 q / (1 + q^2), q^2 = small / large;
        // R = R1 R2 / (R1 + R2) = small / (1 + q^2) (eqs 4, 31).
        let ratio = small / large;
        let q = super::sqrt::sqrt(ratio);
        let inverse_sum = 1.0 / (1.0 + ratio);
        let c = 2.0 * q * inverse_sum;
        let hr = 1.5 * (1.0 - nu) * (small * inverse_sum);
        let mu3 = mu * mu * mu;
        let g_hr2 = (PI * PI * PI / 27.0) * g * (hr * hr);
        let slip_cubed = g_hr2 / mu3;
        let c3 = c * c * c;
        let g_cubed_per_load = c3 / slip_cubed;
        let (l3, has_length) = match length {
            Some(l) => (l * l * l, true),
            None => (1.0, false),
        };
        let ratio_cubed = 8.0 * hr / (g * l3);
        let constants = Constants {
            c,
            inverse_c: 1.0 / c,
            friction: mu,
            pressure_per_slip: 2.0 * mu * PRESSURE_LIMIT,
            slip_cubed,
            g_cubed_per_load,
            ratio_cubed_per_load: if has_length { ratio_cubed } else { 0.0 },
        };
        let normal = positive_normal(ratio)
            & positive_normal(q)
            & positive_normal(c)
            & positive_normal(constants.inverse_c)
            & positive_normal(hr)
            & positive_normal(mu3)
            & positive_normal(hr * hr)
            & positive_normal(g_hr2)
            & positive_normal(slip_cubed)
            & positive_normal(c3)
            & positive_normal(g_cubed_per_load)
            & (!has_length | (positive_normal(l3) & positive_normal(ratio_cubed)));
        (constants, normal)
    }
}

/// The scene of each lane: one for all ([`Constants`]) or one a lane ([`PerLane`]).
pub trait SceneLanes {
    /// The constants of lane `i`.
    fn lane(&self, i: usize) -> Constants;
}

impl SceneLanes for Constants {
    #[inline(always)]
    fn lane(&self, _: usize) -> Constants {
        *self
    }
}

/// A scene per lane, each constant a column (so that a lane's constants load as a
/// vector).
#[derive(Debug, Clone, Copy)]
pub struct PerLane<const N: usize> {
    /// [`Constants::c`] of each lane.
    pub c: [f64; N],
    /// [`Constants::inverse_c`].
    pub inverse_c: [f64; N],
    /// [`Constants::friction`].
    pub friction: [f64; N],
    /// [`Constants::pressure_per_slip`].
    pub pressure_per_slip: [f64; N],
    /// [`Constants::slip_cubed`].
    pub slip_cubed: [f64; N],
    /// [`Constants::g_cubed_per_load`].
    pub g_cubed_per_load: [f64; N],
    /// [`Constants::ratio_cubed_per_load`].
    pub ratio_cubed_per_load: [f64; N],
}

impl<const N: usize> SceneLanes for PerLane<N> {
    #[inline(always)]
    fn lane(&self, i: usize) -> Constants {
        Constants {
            c: self.c[i],
            inverse_c: self.inverse_c[i],
            friction: self.friction[i],
            pressure_per_slip: self.pressure_per_slip[i],
            slip_cubed: self.slip_cubed[i],
            g_cubed_per_load: self.g_cubed_per_load[i],
            ratio_cubed_per_load: self.ratio_cubed_per_load[i],
        }
    }
}

/// N rows' answers.
#[derive(Debug, Clone, Copy)]
pub struct Rows<const N: usize> {
    /// d/b (eqs 15, 16).
    pub slip_ratio: [f64; N],
    /// F (N), signed like phi (eq 21).
    pub axial_force: [f64; N],
    /// phi0 (rad) at the row's load (eqs 18, 30).
    pub critical_angle: [f64; N],
    /// theta0 (rad).
    pub critical_theta: [f64; N],
    /// k' = b/a at the row's theta.
    pub kprime: [f64; N],
    /// The ellipse answered the row: the numbers above and the flags below are the
    /// reference's.
    pub elliptic: [bool; N],
    /// Section 9 takes line contact for the row (the numbers above are not its; the
    /// caller answers it with [`line`](crate::reference::line())).
    pub line: [bool; N],
    /// The flags of [`Validity`](crate::reference::Validity), where answered.
    pub large_angle: [bool; N],
    /// See `large_angle`.
    pub high_pressure: [bool; N],
    /// See `large_angle`.
    pub longer_than_rollers: [bool; N],
    /// See `large_angle`.
    pub near_model_switch: [bool; N],
    /// See `large_angle`.
    pub round_ellipse: [bool; N],
}

/// The fast path over N rows of load P (N) and misalignment phi (rad, signed), the
/// scene of each lane from `scenes` (every lane's constants valid: [`Constants::of`]),
/// with a length where `length` (then [`Constants::ratio_cubed_per_load`] is the
/// lane's), the model chosen by `choice` (not forced line contact, which the fast path
/// never takes). A row outside the domain (module docs), refused input among them, is
/// neither `elliptic` nor `line`.
#[inline(always)]
pub fn rows<S: SceneLanes, const N: usize>(
    scenes: &S,
    choice: ModelChoice,
    length: bool,
    load: &[f64; N],
    phi: &[f64; N],
) -> Rows<N> {
    let mut ok = [false; N];
    let mut abs_phi = [0.0; N];
    let mut theta = [0.0; N];
    // The sample's checks (the reference's errors answer elsewhere) and theta (eq 4).
    for i in 0..N {
        let a = phi[i].abs();
        ok[i] = (load[i] > 0.0) & (load[i] < f64::INFINITY) & (a <= FRAC_PI_2);
        abs_phi[i] = a;
        theta[i] = scenes.lane(i).c * a;
    }
    // The shape at theta and theta0 at the load (eq 18 with d/b = 1).
    let mut kprime = [0.0; N];
    let mut mn_cubed = [0.0; N];
    let mut m_cubed = [0.0; N];
    for i in 0..N {
        let (shape, inside) = shape_lane(theta[i]);
        ok[i] &= inside;
        kprime[i] = shape.kprime;
        mn_cubed[i] = shape.mn_cubed;
        if length {
            m_cubed[i] = shape.m_cubed();
        }
    }
    let mut theta0 = [0.0; N];
    for i in 0..N {
        let (t, inside) = theta_lane(scenes.lane(i).g_cubed_per_load * load[i]);
        ok[i] &= inside;
        theta0[i] = t;
    }
    // d/b = ((d/b)^3)^(1/3) (eq 15), each partial product normal (else the reference's
    // chain is needed).
    let mut s = [0.0; N];
    for i in 0..N {
        let x = scenes.lane(i).slip_cubed * mn_cubed[i];
        let y = x * (abs_phi[i] * abs_phi[i] * abs_phi[i]);
        let s3 = y / load[i];
        ok[i] &= positive_normal(x) & positive_normal(y) & positive_normal(s3);
        s[i] = cbrt(s3);
    }
    // F / (mu P) (eq 21).
    let mut force = [0.0; N];
    for i in 0..N {
        force[i] = axial_force_ratio(s[i]);
    }
    // The decisions, each clear of its threshold, and the answers.
    let mut out = Rows {
        slip_ratio: s,
        axial_force: [0.0; N],
        critical_angle: [0.0; N],
        critical_theta: theta0,
        kprime,
        elliptic: [false; N],
        line: [false; N],
        large_angle: [false; N],
        high_pressure: [false; N],
        longer_than_rollers: [false; N],
        near_model_switch: [false; N],
        round_ellipse: [false; N],
    };
    let (lo, hi) = (1.0 / MODEL_SWITCH_BAND, MODEL_SWITCH_BAND);
    let (lo3, hi3) = (lo * lo * lo, hi * hi * hi);
    let line_when_longer = choice == ModelChoice::Section9;
    for i in 0..N {
        let k = scenes.lane(i);
        let phi0 = theta0[i] * k.inverse_c;
        // p0 = 3 P^(1/3) / (2 pi m n v^2), so p0 / G = |phi| / (2 mu (d/b)) (eq 15):
        // p0 / G > PRESSURE_LIMIT where |phi| > PRESSURE_LIMIT 2 mu (d/b).
        let pressure = k.pressure_per_slip * s[i];
        // Within the guard of pi/2 the reference may find no critical angle (phi0 not
        // an angle between two axes) where this one finds one: the reference answers.
        let mut clear = (phi0 <= FRAC_PI_2)
            & clear_of(phi0, FRAC_PI_2)
            & clear_of(s[i], 1.0)
            & clear_of(phi0, ANGLE_LIMIT)
            & clear_of(abs_phi[i], pressure)
            & clear_of(kprime[i] * SLENDER_LIMIT, 1.0);
        let (mut longer, mut near) = (false, false);
        if length {
            let r3 = k.ratio_cubed_per_load * m_cubed[i] * load[i];
            clear &=
                positive_normal(r3) & clear_of(r3, 1.0) & clear_of(r3, lo3) & clear_of(r3, hi3);
            longer = r3 > 1.0;
            near = (r3 >= lo3) & (r3 <= hi3);
        }
        let answered = ok[i] & clear;
        let line = longer & line_when_longer;
        out.elliptic[i] = answered & !line;
        out.line[i] = answered & line;
        out.axial_force[i] = (k.friction * (load[i] * force[i])).copysign(phi[i]);
        out.critical_angle[i] = phi0;
        out.large_angle[i] = (abs_phi[i] > ANGLE_LIMIT) | (phi0 > ANGLE_LIMIT);
        out.high_pressure[i] = abs_phi[i] > pressure;
        out.longer_than_rollers[i] = longer;
        out.near_model_switch[i] = near;
        out.round_ellipse[i] = kprime[i] * SLENDER_LIMIT > 1.0;
    }
    out
}
