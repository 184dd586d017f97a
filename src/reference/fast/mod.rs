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

mod acos;
mod atan;
mod cbrt;
mod critical;
mod force;
mod lanes;
mod ln;
mod point;
mod series;
mod shape;
mod sqrt;
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

pub use lanes::{Constants, PerLane, Rows, SceneLanes, rows};
pub(crate) use sqrt::sqrt;

use super::{Line, ModelChoice, Regime, Validity, line};
use crate::{Scene, ThetaRelation};

/// A scene prepared for the fast path.
#[derive(Debug, Clone, Copy)]
pub struct Prepared {
    scene: Scene,
    choice: ModelChoice,
    constants: Constants,
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
        let (constants, normal) = Constants::of(
            scene.r1(),
            scene.r2(),
            scene.shear_modulus(),
            scene.poisson_ratio(),
            scene.friction(),
            scene.length(),
        );
        normal.then_some(Prepared {
            scene: *scene,
            choice,
            constants,
        })
    }

    /// The scene's constants (what [`rows`] takes).
    pub fn constants(&self) -> &Constants {
        &self.constants
    }

    /// The reference's answer at load P (N) and misalignment phi (rad, signed), or
    /// `None` outside the domain (module docs): then the reference answers, also for
    /// refused input.
    #[inline]
    pub fn estimate(&self, load: f64, phi: f64) -> Option<Answer> {
        let [a] = self.estimate_rows(&[load], &[phi]);
        a
    }

    /// [`Prepared::estimate`] of N rows, each stage for all of them before the next
    /// ([`rows`]): the same numbers, bit for bit, in less time a row.
    #[inline]
    pub fn estimate_rows<const N: usize>(
        &self,
        load: &[f64; N],
        phi: &[f64; N],
    ) -> [Option<Answer>; N] {
        let length = self.scene.length();
        let r = rows(&self.constants, self.choice, length.is_some(), load, phi);
        let mut out = [None; N];
        for (i, answer) in out.iter_mut().enumerate() {
            let validity = Validity {
                large_angle: r.large_angle[i],
                high_pressure: r.high_pressure[i],
                longer_than_rollers: r.longer_than_rollers[i],
                near_model_switch: r.near_model_switch[i],
                round_ellipse: r.round_ellipse[i],
            };
            if r.elliptic[i] {
                *answer = Some(Answer::Elliptic(Elliptic {
                    slip_ratio: r.slip_ratio[i],
                    axial_force: r.axial_force[i],
                    critical_angle: r.critical_angle[i],
                    critical_theta: r.critical_theta[i],
                    kprime: r.kprime[i],
                    regime: Regime::of(r.slip_ratio[i]),
                    validity,
                }));
            } else if r.line[i]
                && let Some(l) = length
                && let Ok(mut l) = line(&self.scene, load[i] / l, phi[i])
            {
                l.validity.near_model_switch = validity.near_model_switch;
                *answer = Some(Answer::Line(l));
            }
        }
        out
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
