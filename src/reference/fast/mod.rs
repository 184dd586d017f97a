//! The reference's answer at a fraction of its cost, for the batch: the same equations
//! to the same exactness (within a few ulps of the reference, which is itself within
//! 1.1e-15 of the 50-digit data), over the practical domain, the reference itself
//! answering every other row.
//!
//! Where the reference solves for k' from a generic seed (several Newton steps, each a
//! Carlson R_D pair of about 15 square roots), this path starts from an f64 table good
//! to 1e-9 (seeds.rs, fitted to the reference by `cargo xtask tables`; its format in
//! table.rs) and takes one Newton step, with K - E and E - k'^2 K from their series
//! about k' = 0 (series.rs, exact up to k' = 0.032; their ln k' from a table made at
//! compile time, ln.rs) and theta from a short atan series
//! (atan.rs); the step's own error is below 1e-18 (point.rs). The shape at theta is
//! shape.rs, theta0 at a load critical.rs; d/b comes from `(d/b)^3` by a cube root
//! without a division (cbrt.rs), phi0 from `g(theta0)^3 = (c target)^3`, proportional
//! to P, with no cube root. Each file
//! states its error bound and cost; each is tested against the reference or the
//! 50-digit data.
//!
//! Domain: theta and theta0 in [2^-40, 2^-3) (k' below 0.032), the scene's theta
//! relation eq (4) (small angle), an elliptic or section-9 model choice; every
//! intermediate product a normal f64; and no answer within 1e-12 (relative) of a
//! threshold the reference decides on (gross slip at d/b = 1, the flags' limits, 2a =
//! length), so that every decision is the reference's. Elsewhere [`Prepared::new`] or
//! [`Prepared::estimate`] answer `None` and the caller asks the reference.
//!
//! Error: d/b, F and phi0 within 3e-15 of the reference (asserted by
//! tests/reference_fast.rs over the 50-digit data, 200 000 benchmark rows and 200 000
//! random scenes); regime, model and flags the reference's. Cost:
//! `misalign._misalign.reference_cost` in the Python package times it beside the
//! reference's pieces (docs/measurements-python.md).

mod atan;
mod cbrt;
mod critical;
mod ln;
mod point;
mod series;
mod shape;
internal! {
    /// The generated seed tables.
    #[rustfmt::skip]
    mod seeds;
}
internal! {
    /// The seed tables' format.
    mod table;
}

#[cfg(feature = "_internals")]
#[doc(hidden)]
pub use critical::theta_of_g_cubed;
#[cfg(feature = "_internals")]
#[doc(hidden)]
pub use shape::shape;

use critical::thetas_of_g_cubed;
use shape::{Shape, shapes};

use super::chain::chain;
use super::{
    ANGLE_LIMIT, ContactModel, Line, MODEL_SWITCH_BAND, ModelChoice, PRESSURE_LIMIT, Regime,
    SLENDER_LIMIT, Validity, hertz_scale, line, tangential,
};
use crate::{Scene, ThetaRelation};
use core::f64::consts::{FRAC_PI_2, PI};

/// Answers this close (relative) to a threshold the reference decides on go to the
/// reference: both are within 1e-14 of the exact value, so beyond it they decide alike.
const DECISION_GUARD: f64 = 1e-12;

/// A scene prepared for the fast path.
#[derive(Debug, Clone, Copy)]
pub struct Prepared {
    scene: Scene,
    choice: ModelChoice,
    /// c of eq (4), theta = c |phi|, and 1/c.
    c: f64,
    inverse_c: f64,
    /// `2 mu PRESSURE_LIMIT`: p0 / G above the limit where |phi| > this d/b.
    pressure_per_slip: f64,
    /// `(pi G v^2 / (3 mu))^3`: `(d/b)^3 = this (m n)^3 |phi|^3 / P` (eq 15).
    slip_cubed: f64,
    /// `(c 3 mu / pi)^3 / (G h^2 R^2)`, h = 1.5 (1 - nu): `g(theta0)^3 = this P` (eqs
    /// 15, 18 with d/b = 1).
    g_cubed_per_load: f64,
    /// `8 v^3 / length^3`: `(2a / length)^3 = this m^3 P` (section 9).
    ratio_cubed_per_load: Option<f64>,
}

/// One row's answer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Answer {
    /// The ellipse (sections 5-7).
    Elliptic(Elliptic),
    /// Line contact with P / length (section 9), by [`line()`](super::line()).
    Line(Line),
}

/// The elliptic answer: what the batch returns without its details.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Elliptic {
    /// d/b (eqs 15, 16).
    pub slip_ratio: f64,
    /// F (N), signed like phi (eq 21).
    pub axial_force: f64,
    /// phi0 (rad) at the row's load (eqs 18, 30).
    pub critical_angle: f64,
    /// theta0 (rad).
    pub critical_theta: f64,
    /// k' = b/a at the row's theta.
    pub kprime: f64,
    /// Partial or gross slip.
    pub regime: Regime,
    /// As the reference's.
    pub validity: Validity,
}

/// `[f(0), .., f(N - 1)]` by a plain loop, which inlines `f` (`core::array::from_fn`
/// left the stages' closures as calls, one a row).
#[inline(always)]
fn each<T: Copy + Default, const N: usize>(mut f: impl FnMut(usize) -> T) -> [T; N] {
    let mut out = [T::default(); N];
    for (i, x) in out.iter_mut().enumerate() {
        *x = f(i);
    }
    out
}

/// `x` is not within [`DECISION_GUARD`] of `limit`.
#[inline(always)]
fn clear_of(x: f64, limit: f64) -> bool {
    libm::fabs(x - limit) > DECISION_GUARD * limit
}

impl Prepared {
    /// The scene prepared, or `None` where the fast path does not apply (a plane, the
    /// exact theta relation, forced line contact, constants out of range).
    pub fn new(scene: &Scene, choice: ModelChoice) -> Option<Prepared> {
        if choice == ModelChoice::Line
            || scene.is_plane()
            || scene.theta_relation() != ThetaRelation::SmallAngle
        {
            return None;
        }
        let c = scene.radius_factor();
        let (g, mu) = (scene.shear_modulus(), scene.friction());
        let v = hertz_scale(scene);
        let slip = chain(&[PI, g, v, v], &[3.0, mu]);
        let h = 1.5 * (1.0 - scene.poisson_ratio());
        let r = scene.effective_radius();
        let k = 3.0 * mu / PI;
        let prepared = Prepared {
            scene: *scene,
            choice,
            c,
            inverse_c: 1.0 / c,
            pressure_per_slip: 2.0 * mu * PRESSURE_LIMIT,
            slip_cubed: slip * slip * slip,
            g_cubed_per_load: chain(&[c, c, c, k, k, k], &[g, h, h, r, r]),
            ratio_cubed_per_load: scene.length().map(|l| chain(&[8.0, v, v, v], &[l, l, l])),
        };
        let normal = c.is_normal()
            && prepared.inverse_c.is_normal()
            && prepared.slip_cubed.is_normal()
            && prepared.g_cubed_per_load.is_normal()
            && prepared.ratio_cubed_per_load.is_none_or(f64::is_normal);
        normal.then_some(prepared)
    }

    /// The reference's answer at load P (N) and misalignment phi (rad, signed), or
    /// `None` outside the domain (module docs): then the reference answers, also for
    /// refused input.
    #[inline]
    pub fn estimate(&self, load: f64, phi: f64) -> Option<Answer> {
        let [a] = self.estimate_rows(&[load], &[phi]);
        a
    }

    /// [`Prepared::estimate`] of N rows, each stage for all of them before the next, so
    /// that their latency chains (logarithm, series, divisions, cube root, arc cosine)
    /// run side by side: the same numbers, bit for bit, in less time a row.
    #[inline]
    pub fn estimate_rows<const N: usize>(
        &self,
        load: &[f64; N],
        phi: &[f64; N],
    ) -> [Option<Answer>; N] {
        // Refused input (the reference's errors) and the table's misses alike: None.
        let theta: [f64; N] = each(|i| {
            let abs_phi = libm::fabs(phi[i]);
            if load[i] > 0.0 && load[i] < f64::INFINITY && abs_phi <= FRAC_PI_2 {
                self.c * abs_phi
            } else {
                f64::NAN
            }
        });
        let shapes = shapes(&theta);
        let g_cubed: [f64; N] = each(|i| self.g_cubed_per_load * load[i]);
        let theta0 = thetas_of_g_cubed(&g_cubed);
        // d/b and F/(mu P) each in a pass of its own, the branches and decisions after.
        let s: [f64; N] = each(|i| match shapes[i] {
            Some(shape) => cbrt::cbrt(self.slip_cubed_of(load[i], phi[i], shape)),
            None => f64::NAN,
        });
        let force: [f64; N] = each(|i| tangential::axial_force_ratio(s[i]));
        each(|i| self.finish(load[i], phi[i], shapes[i]?, theta0[i]?, s[i], force[i]))
    }

    /// `(d/b)^3` (eq 15), NaN unless each partial product is normal (else the
    /// reference's chain is needed).
    #[inline(always)]
    fn slip_cubed_of(&self, load: f64, phi: f64, shape: Shape) -> f64 {
        let abs_phi = libm::fabs(phi);
        let x = self.slip_cubed * shape.mn_cubed;
        let y = x * (abs_phi * abs_phi * abs_phi);
        let s3 = y / load;
        if x.is_normal() && y.is_normal() && s3.is_normal() {
            s3
        } else {
            f64::NAN
        }
    }

    /// The row's answer from its shape, theta0, d/b `s` (NaN where the reference must
    /// answer) and `force = F/(mu P)` at `s`.
    #[inline(always)]
    fn finish(
        &self,
        load: f64,
        phi: f64,
        shape: Shape,
        theta0: f64,
        s: f64,
        force: f64,
    ) -> Option<Answer> {
        if s.is_nan() {
            return None;
        }
        let abs_phi = libm::fabs(phi);
        let phi0 = theta0 * self.inverse_c;
        // p0 = 3 P^(1/3) / (2 pi m n v^2), so p0 / G = |phi| / (2 mu (d/b)) (eq 15):
        // p0 / G > PRESSURE_LIMIT where |phi| > PRESSURE_LIMIT 2 mu (d/b).
        let pressure = self.pressure_per_slip * s;
        // Within the guard of pi/2 the reference may find no critical angle (phi0 not
        // an angle between two axes) where this one finds one: the reference answers.
        if !(phi0 <= FRAC_PI_2
            && clear_of(phi0, FRAC_PI_2)
            && clear_of(s, 1.0)
            && clear_of(phi0, ANGLE_LIMIT)
            && clear_of(abs_phi, pressure)
            && clear_of(shape.kprime * SLENDER_LIMIT, 1.0))
        {
            return None;
        }
        let (longer, near) = match self.ratio_cubed_per_load {
            None => (false, false),
            Some(k) => {
                let r3 = k * shape.m_cubed() * load;
                let (lo, hi) = (1.0 / MODEL_SWITCH_BAND, MODEL_SWITCH_BAND);
                let (lo3, hi3) = (lo * lo * lo, hi * hi * hi);
                if !(r3.is_normal() && clear_of(r3, 1.0) && clear_of(r3, lo3) && clear_of(r3, hi3))
                {
                    return None;
                }
                (r3 > 1.0, (lo3..=hi3).contains(&r3))
            }
        };
        if longer && self.choice.model(true) == ContactModel::Line {
            let mut l = line(&self.scene, load / self.scene.length()?, phi).ok()?;
            l.validity.near_model_switch = near;
            return Some(Answer::Line(l));
        }
        let mu = self.scene.friction();
        Some(Answer::Elliptic(Elliptic {
            slip_ratio: s,
            axial_force: libm::copysign(mu * (load * force), phi),
            critical_angle: phi0,
            critical_theta: theta0,
            kprime: shape.kprime,
            regime: Regime::of(s),
            validity: Validity {
                large_angle: abs_phi > ANGLE_LIMIT || phi0 > ANGLE_LIMIT,
                high_pressure: abs_phi > pressure,
                longer_than_rollers: longer,
                near_model_switch: near,
                round_ellipse: shape.kprime * SLENDER_LIMIT > 1.0,
            },
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::atan::T2_MAX;
    use super::seeds::{KPRIME_OF_THETA, KPRIME_SQUARED_OF_G_CUBED};
    use super::series::KPRIME_MAX;

    /// Every seed lies where the series are exact: k' <= KPRIME_MAX, and the theta of
    /// the point, `tan^2(theta/2) <= tan^2(1/16)`, within T2_MAX.
    #[test]
    fn seeds_stay_in_the_series_domain() {
        let top = libm::tan(1.0 / 16.0);
        assert!(top * top < T2_MAX);
        for i in 0..=4000 {
            let theta = libm::ldexp(1.0, -40) * libm::pow(2.0, 37.0 * i as f64 / 4000.0);
            if let Some(k) = KPRIME_OF_THETA.eval(theta.min(0.124_999)) {
                assert!(k > 0.0 && k < KPRIME_MAX, "theta={theta}: {k}");
            }
            let y = libm::ldexp(1.0, -77) * libm::pow(2.0, 71.0 * i as f64 / 4000.0);
            if let Some(p) = KPRIME_SQUARED_OF_G_CUBED.eval(y) {
                assert!(p > 0.0 && p < KPRIME_MAX * KPRIME_MAX, "g^3={y}: {p}");
            }
        }
        // The theta at the top of the theta table: t^2 = tan^2(1/16) (below T2_MAX).
        assert!(KPRIME_OF_THETA.eval(0.125).is_none());
    }
}
