//! Inverse estimates in f32, per sample: the friction coefficient mu from a measured
//! axial force F at known load P and misalignment phi, and the misalignment from F at
//! known P and mu. Same answers as the reference ([`crate::reference::inverse`], whose
//! docs give the shape of the forward map), from the same prepared scene as the forward
//! estimate and no further tables:
//!
//! - mu: `K = mu d/b` from the forward path (`g(theta)` table, eq 16), then s from
//!   `f(s)/s = F/(K P)` by Newton steps on the axial-force kernel's polynomials
//!   (the kernel `float::kernels::axial_force_inverse`), `mu = K / s`; line contact in closed
//!   form (`mu = K / (2 - F/(K P))`, eqs 23, 27).
//! - phi: s from `f(s) = F/(mu P)` by the same kernel inverse, then eq (16) solved for
//!   `g = s P^(1/3) / A` and theta from the inverse table `theta(g)` that the critical
//!   angle already uses (eq 18); line contact `phi = s phi0` (eqs 23, 27, 28).
//!
//! Newton steps on the existing tables rather than new inverse tables: the kernel
//! inverse is within 2e-7 of the f64 inverse (times its conditioning) with no new table
//! bytes, and `theta(g)` is the table the forward path links anyway; new tables were
//! not built, as this leaves nothing for them to gain in accuracy. Cost: `cargo xtask
//! bench` measures the inverses beside the forward estimate on every Cortex-M core
//! (instructions per call, docs/measurements.md).
//!
//! Error bound (tested in tests/inverse.rs over the public reference scenes, inputs
//! rounded to f32, forward in f32 then inverse in f32): mu and phi within 2e-6 relative
//! of the true values, times the sensitivity where it exceeds 1, wherever the
//! sensitivity is below 1e3; measured 4.3e-7. The phi-inverse's sensitivity agrees
//! with the reference's to 1e-4 times max(1, S) (measured 2.0e-5; it takes
//! `d ln g / d ln theta` by a difference of the g table, and S ~ 1/f'(s) is steep in s
//! near gross slip).
//!
//! Saturation: an answer is `Exact` only where the inputs, read as f32, determine it.
//! Where F / (mu P) as the core forms it lies within [`ROUNDING_BELOW_SATURATION`] of
//! 1 (or [`ROUNDING_ABOVE_SATURATION`] above), F cannot be told from mu P and the
//! phi-inverse answers `AtLeast` phi0, as the reference does at F = mu P; where
//! F / (K P) lies within [`SATURATION_ULPS`] of the no-slip limit, the mu-inverse
//! answers `AtLeast` the mu at the band's edge. Each band is the sum of the roundings
//! of the quantity as the core forms it (their docs).
//!
//! Section 9: [`Auto`] chooses the model per sample. mu's inverse is the chosen
//! model's (phi is known); phi's solves both models and keeps each answer only where
//! the choice takes its model.
//!
//! The fixed-point core ([`crate::fixed`]) has no inverse yet. In its logarithmic
//! number system the inverse needs new log-domain tables (log s of log r, and of
//! log(f/s)), generated and drift-tested like its forward tables, and the differences
//! `1 - r`, `2 - q` near saturation, which that number system forms only through a
//! difference (Gauss-logarithm) table whose error grows as they cancel; that is more
//! than the fixed-point core has tables for. An FPU-less node (Cortex-M0, M3) can call these f32
//! inverses in software floating point.

use super::{Auto, EllipticScene, LineScene, check};
use crate::Error;
use crate::float::kernels::axial_force_inverse::{
    force_over_slip_limit, force_ratio_slope, slip_ratio_of_force_over_slip,
    slip_ratio_of_force_ratio,
};
use crate::float::kernels::sqrt::{inv_sqrt, sqrt};
use crate::reference::ContactModel;
use crate::reference::inverse::{Inconsistency, Inverse, angle_trivial, friction_trivial};
use core::f32::consts::FRAC_PI_2;

/// Relative distance below the no-slip limit of F(mu) (`F / (K P)` at its largest,
/// eq 16 with s -> 0) within which F counts as the limit: the answer is then only
/// `AtLeast` mu, as the inputs at f32 do not tell it from the limit. The bound of q =
/// F / (K P) as the core forms it, in units u = 2^-24 (half an f32 ulp): F, P rounded
/// to f32 and F / P (3 u), q's division (1 u), g(theta) from its table (within 3 u)
/// at theta = c |phi| (c, phi and the product: 3 u, times d ln g / d ln theta <= 1),
/// g0 = cbrt(B^3 P) (the hot cube root's bound and the cube's 3 u / 3), g / g0 and mu
/// times it (2 u): within 16 u = 8 eps (the test `saturation_bands_cover_the_rounding`
/// sums it and holds the g table to its 3 u). Line contact's K (inv_sqrt's bound and
/// four products) stays below it too.
pub const SATURATION_ULPS: f32 = 8.0 * f32::EPSILON;

/// An F up to this far (relative) above mu P counts as mu P (the rounding of mu P
/// and of F from inputs rounded to f32); further above, F is inconsistent.
pub const ROUNDING_ABOVE_SATURATION: f32 = 4.0 * f32::EPSILON;

/// An F down to this far (relative) below mu P counts as mu P in the phi-inverses:
/// the answer is `AtLeast` phi0 (gross slip), as the reference answers at F = mu P,
/// since the inputs at f32 cannot tell F from mu P there. F / (mu P) as the core
/// forms it is off the exact inputs' ratio by five roundings at most (F, P and mu
/// read as f32, mu P, the quotient: 5 u = 2.5 eps, u = 2^-24); this is 4 eps, as
/// [`ROUNDING_ABOVE_SATURATION`] on the other side. Below it, the answer is `Exact`
/// with its sensitivity, which near saturation is large (1e3 and more): phi moves by
/// the sensitivity times F's relative error.
pub const ROUNDING_BELOW_SATURATION: f32 = 4.0 * f32::EPSILON;

/// Relative step of the difference that gives `d ln g / d ln theta`.
const LOG_STEP: f32 = 1.0 / 64.0;

/// Input checks of the inverses: the forward checks, and F finite.
#[inline(always)]
fn check_force(load: f32, phi: f32, force: f32) -> Result<(), Error> {
    check(load, phi)?;
    if !force.is_finite() {
        return Err(Error::Force);
    }
    Ok(())
}

/// The cases decided before the model (F = 0, P = 0, phi = 0, signs), as the reference.
#[inline(always)]
fn friction_decided(load: f32, phi: f32, force: f32) -> Option<Inverse<f32>> {
    friction_trivial(load, phi, force)
}

#[inline(always)]
fn angle_decided(load: f32, force: f32, zero_angle_sensitivity: f32) -> Option<Inverse<f32>> {
    angle_trivial(load, force, zero_angle_sensitivity)
}

/// mu from `r = F / P` and `K = mu d/b`, given s from `q = r / K` and the slope of
/// `f(s)/s`'s numerator; `limit` is `f(s)/s` at s = 0.
#[inline(always)]
fn friction_from_ratio(
    r: f32,
    k: f32,
    limit: f32,
    slip_of: impl Fn(f32) -> f32,
    slope: impl Fn(f32) -> f32,
) -> Inverse<f32> {
    if r <= k {
        // Gross slip: F = mu P (eqs 21, 29, 27).
        return bounded(r, 1.0);
    }
    let q = r / k;
    if q.is_nan() || q > limit * (1.0 + SATURATION_ULPS) {
        return Inverse::Inconsistent(Inconsistency::AboveModel);
    }
    let saturation = limit * (1.0 - SATURATION_ULPS);
    if q >= saturation {
        return Inverse::AtLeast {
            value: (k / slip_of(saturation)).min(f32::MAX),
        };
    }
    let s = slip_of(q);
    // S = 1 / (1 - s f'/f) = h / (h - f'), h = f/s = q.
    bounded(k / s, q / (q - slope(s)))
}

/// An exact mu, or `AtLeast` the largest f32 where mu overflows.
#[inline(always)]
fn bounded(mu: f32, sensitivity: f32) -> Inverse<f32> {
    if mu.is_finite() {
        Inverse::Exact {
            value: mu,
            sensitivity,
        }
    } else {
        Inverse::AtLeast { value: f32::MAX }
    }
}

/// `answer` with its value signed like `force`.
#[inline(always)]
fn signed(answer: Inverse<f32>, force: f32) -> Inverse<f32> {
    match answer {
        Inverse::Exact { value, sensitivity } => Inverse::Exact {
            value: value.copysign(force),
            sensitivity,
        },
        Inverse::AtLeast { value } => Inverse::AtLeast {
            value: value.copysign(force),
        },
        other => other,
    }
}

impl EllipticScene<'_> {
    /// The friction coefficient mu from load `load` (N), misalignment `phi` (rad,
    /// signed) and measured axial force `force` (N), elliptic contact (eqs 15, 16, 21).
    /// The friction the scene was prepared with is not read.
    ///
    /// # Errors
    /// As [`EllipticScene::estimate`], and [`Error::Force`] for a NaN or infinite F.
    pub fn friction_from_axial_force(
        &self,
        load: f32,
        phi: f32,
        force: f32,
    ) -> Result<Inverse<f32>, Error> {
        check_force(load, phi, force)?;
        let theta = self.radius_factor * phi.abs();
        if theta > FRAC_PI_2 {
            return Err(Error::Angle);
        }
        if let Some(answer) = friction_decided(load, phi, force) {
            return Ok(answer);
        }
        let g = self.g_of_theta(theta)?;
        // K = mu d/b = (A mu) g P^(-1/3) (eq 16), A mu independent of mu: mu times d/b
        // formed as the forward estimate has it, g / g0.
        let k = self.friction * (g / self.critical_g(load));
        Ok(friction_from_ratio(
            force.abs() / load,
            k,
            force_over_slip_limit(),
            slip_ratio_of_force_over_slip,
            force_ratio_slope,
        ))
    }

    /// The misalignment phi (rad, signed like F) from load `load` (N) and measured
    /// axial force `force` (N), with the scene's mu, elliptic contact.
    ///
    /// # Errors
    /// [`Error::Load`], [`Error::Force`]; [`Error::OutOfRange`] for a theta outside
    /// narrowed tables.
    pub fn angle_from_axial_force(&self, load: f32, force: f32) -> Result<Inverse<f32>, Error> {
        check_force(load, 0.0, force)?;
        if let Some(answer) = angle_decided(load, force, 1.5) {
            return Ok(answer);
        }
        let saturated = self.friction * (load * 1.0); // mu P, formed as the forward path
        let abs_force = force.abs();
        if abs_force > saturated * (1.0 + ROUNDING_ABOVE_SATURATION) {
            return Ok(Inverse::Inconsistent(Inconsistency::AboveModel));
        }
        // eq (16): g = s P^(1/3) / A = s g0, g0 formed as the forward estimate has it.
        let g_per_slip = self.critical_g(load);
        let answer = if abs_force >= saturated * (1.0 - ROUNDING_BELOW_SATURATION) {
            // Gross slip: only |phi| >= phi0 (eq 18 at d/b = 1); none within a right
            // angle: F stays below mu P.
            match self.critical_angle_of(g_per_slip)? {
                Some(phi0) => Inverse::AtLeast { value: phi0 },
                None => Inverse::Inconsistent(Inconsistency::AboveModel),
            }
        } else {
            let r = abs_force / saturated;
            let s = slip_ratio_of_force_ratio(r);
            if s == 0.0 {
                // F/(mu P) underflows f32: phi too (it falls like F^(3/2)), as at F = 0.
                return Ok(signed(
                    Inverse::Exact {
                        value: 0.0,
                        sensitivity: 1.5,
                    },
                    force,
                ));
            }
            match self
                .theta_of_g(g_per_slip * s)?
                .filter(|theta| (theta * self.inv_radius_factor).to_bits() <= FRAC_PI_2.to_bits())
            {
                Some(theta) => Inverse::Exact {
                    value: theta * self.inv_radius_factor,
                    // S = f / (s f' E), E = d ln g / d ln theta (eq 16).
                    sensitivity: r / (s * force_ratio_slope(s) * self.log_slope_of_g(theta)),
                },
                None => Inverse::Inconsistent(Inconsistency::AboveModel),
            }
        };
        Ok(signed(answer, force))
    }

    /// `d ln g / d ln theta` from the g table by a central difference; 2/3 (the
    /// small-theta limit) where the table does not reach.
    fn log_slope_of_g(&self, theta: f32) -> f32 {
        let up = self.g_of_theta(theta * (1.0 + LOG_STEP));
        let down = self.g_of_theta(theta * (1.0 - LOG_STEP));
        match (up, down, self.g_of_theta(theta)) {
            (Ok(a), Ok(b), Ok(g)) if g > 0.0 => (a - b) / (2.0 * LOG_STEP * g),
            _ => 2.0 / 3.0,
        }
    }
}

impl LineScene {
    /// The friction coefficient mu from load `load` (N/m, or N with a length),
    /// misalignment `phi` (rad, signed) and axial force `force` (same unit per length as
    /// the load), line contact: `mu = F/P` in gross slip, else `K / (2 - F/(K P))`,
    /// `K = mu d/b` (eqs 23, 27). The friction the scene was prepared with is not read.
    ///
    /// # Errors
    /// As [`LineScene::estimate`], and [`Error::Force`] for a NaN or infinite F.
    pub fn friction_from_axial_force(
        &self,
        load: f32,
        phi: f32,
        force: f32,
    ) -> Result<Inverse<f32>, Error> {
        check_force(load, phi, force)?;
        if phi.abs() > FRAC_PI_2 {
            return Err(Error::Angle);
        }
        if let Some(answer) = friction_decided(load, phi, force) {
            return Ok(answer);
        }
        let k = self.slip_gain * self.friction * phi.abs() * inv_sqrt(load); // eq (23)
        Ok(friction_from_ratio(
            force.abs() / load,
            k,
            2.0,
            |q| 2.0 - q,                                   // eq (27) over s: 2 - s = q
            |s| if s < 1.0 { 2.0 - 2.0 * s } else { 0.0 }, // d(2 s - s^2)/ds
        ))
    }

    /// The misalignment phi (rad, signed like F) from load `load` (N/m, or N with a
    /// length) and axial force `force`, with the scene's mu: `s = r / (1 + sqrt(1 - r))`,
    /// `r = F/(mu P)` (eq 27), `phi = s phi0` (eqs 23, 28).
    ///
    /// # Errors
    /// [`Error::Load`], [`Error::Force`]; [`Error::OutOfRange`] for a load outside
    /// [`LineScene::load_range`], as [`LineScene::estimate`].
    pub fn angle_from_axial_force(&self, load: f32, force: f32) -> Result<Inverse<f32>, Error> {
        check_force(load, 0.0, force)?;
        if let Some(answer) = angle_decided(load, force, 1.0) {
            return Ok(answer);
        }
        // Refused as the forward estimate refuses it: outside the load range, phi0 or
        // mu P leaves f32 (phi0 = inf times s = 0 would give a NaN).
        if !self.accepts(load) {
            return Err(Error::OutOfRange);
        }
        let saturated = self.friction * (load * 1.0);
        let abs_force = force.abs();
        if abs_force > saturated * (1.0 + ROUNDING_ABOVE_SATURATION) {
            return Ok(Inverse::Inconsistent(Inconsistency::AboveModel));
        }
        let phi0 = self.critical_gain * (load * inv_sqrt(load)); // eq (28)
        let answer = if abs_force >= saturated * (1.0 - ROUNDING_BELOW_SATURATION) {
            match super::line::within_right_angle(phi0) {
                Some(phi0) => Inverse::AtLeast { value: phi0 },
                None => Inverse::Inconsistent(Inconsistency::AboveModel),
            }
        } else {
            let r = abs_force / saturated;
            let s = r / (1.0 + sqrt(1.0 - r));
            let phi = s * phi0;
            if phi > FRAC_PI_2 {
                Inverse::Inconsistent(Inconsistency::AboveModel)
            } else {
                Inverse::Exact {
                    value: phi,
                    sensitivity: (2.0 - s) / (2.0 * (1.0 - s)),
                }
            }
        };
        Ok(signed(answer, force))
    }
}

impl Auto {
    /// mu from (P, phi, F) by the model section 9 (or the scene's forced choice) takes
    /// for this sample (see [`EllipticScene`] and [`LineScene`] for units); suits a
    /// monitor that tracks mu per sample.
    ///
    /// # Errors
    /// As the chosen scene's `friction_from_axial_force`.
    pub fn friction_from_axial_force(
        &self,
        load: f32,
        phi: f32,
        force: f32,
    ) -> Result<Inverse<f32>, Error> {
        Auto::checked(load, phi)?;
        match (self.choose(load, phi).0, &self.elliptic, &self.line) {
            (ContactModel::Elliptic, Some(e), _) => e.friction_from_axial_force(load, phi, force),
            (_, _, Some(l)) => l.friction_from_axial_force(load, phi, force),
            _ => Err(Error::OutOfRange), // not reached: see `Auto::estimate`
        }
    }

    /// phi from (P, F). The model depends on the unknown phi, so both are solved and
    /// each answer counts only where the choice would take its model, as
    /// `reference::inverse::angle_estimate`: both count gives `at_least` the smaller,
    /// neither `inconsistent` (the switch jumps over F).
    ///
    /// # Errors
    /// As the scenes' `angle_from_axial_force`.
    pub fn angle_from_axial_force(&self, load: f32, force: f32) -> Result<Inverse<f32>, Error> {
        let elliptic = match &self.elliptic {
            Some(e) => Some(e.angle_from_axial_force(load, force)?),
            None => None,
        };
        let line = match &self.line {
            Some(l) => Some(l.angle_from_axial_force(load, force)?),
            None => None,
        };
        let picks = |answer: &Option<Inverse<f32>>, model: ContactModel| match answer {
            Some(Inverse::Exact { value, .. } | Inverse::AtLeast { value }) => {
                self.choose(load, *value).0 == model
            }
            _ => false,
        };
        // A saturated ellipse holds for every phi >= phi0 that the choice gives the
        // ellipse. The ellipse is shortest at the largest phi (below pi/2, theta <= pi/2
        // by eq 4), so the choice takes it above phi0 iff it takes it there.
        let elliptic_somewhere_above = match (&elliptic, &self.elliptic) {
            (Some(Inverse::AtLeast { .. }), Some(e)) => {
                let phi_max = FRAC_PI_2.next_down().min(FRAC_PI_2 * e.inv_radius_factor);
                self.choose(load, phi_max).0 == ContactModel::Elliptic
            }
            _ => false,
        };
        Ok(
            match (
                picks(&elliptic, ContactModel::Elliptic) || elliptic_somewhere_above,
                picks(&line, ContactModel::Line),
            ) {
                (true, false) => {
                    elliptic.unwrap_or(Inverse::Inconsistent(Inconsistency::AboveModel))
                }
                (false, true) => line.unwrap_or(Inverse::Inconsistent(Inconsistency::AboveModel)),
                (true, true) => {
                    let e = elliptic.and_then(|a| a.value()).unwrap_or(0.0);
                    let l = line.and_then(|a| a.value()).unwrap_or(0.0);
                    Inverse::AtLeast {
                        value: if e.abs() < l.abs() { e } else { l },
                    }
                }
                (false, false) => match (elliptic, line) {
                    (Some(a @ Inverse::Inconsistent(_)), None | Some(Inverse::Inconsistent(_)))
                    | (None, Some(a @ Inverse::Inconsistent(_))) => a,
                    _ => Inverse::Inconsistent(Inconsistency::BetweenModels),
                },
            },
        )
    }
}

/// The inverses above through the trait a condition monitor is generic over (each
/// call resolves to the scene's own method).
macro_rules! friction_inverse {
    ($($scene:ty),*) => {$(
        impl crate::FrictionInverse for $scene {
            fn friction_from_axial_force(
                &self,
                load: f32,
                phi: f32,
                force: f32,
            ) -> Result<Inverse<f32>, Error> {
                <$scene>::friction_from_axial_force(self, load, phi, force)
            }
        }
    )*};
}
friction_inverse!(EllipticScene<'_>, LineScene, Auto);

#[cfg(test)]
mod tests {
    use super::{ROUNDING_ABOVE_SATURATION, ROUNDING_BELOW_SATURATION, SATURATION_ULPS};
    use crate::float::kernels::cbrt::CBRT_HOT_MAX_REL_ERROR;
    use crate::float::kernels::sqrt::INV_SQRT_MAX_REL_ERROR;
    use crate::float::tables::G_OF_THETA;

    /// The bands hold the roundings their docs list, in u = 2^-24; the g table's part
    /// is measured here against the reference over its whole range.
    #[test]
    fn saturation_bands_cover_the_rounding() {
        let u = 2f64.powi(-24);
        let mut g_error = 0.0f64;
        for i in 0..20_000 {
            // theta from 2^-32 up to pi/2, log-spaced, as the f32 the table reads.
            let x = (i as f64 / 20_000.0) * (32.0 + core::f64::consts::FRAC_PI_2.log2());
            let theta = 2f64.powf(-32.0 + x) as f32;
            let want = crate::reference::normal::ellipse_shape(theta as f64)
                .unwrap()
                .g();
            let got = G_OF_THETA.eval(theta).unwrap() as f64;
            g_error = g_error.max((got / want - 1.0).abs());
        }
        assert!(g_error <= 3.0 * u, "g table {}", g_error / u);
        let cbrt = CBRT_HOT_MAX_REL_ERROR as f64 / u;
        let elliptic = 3.0 + 1.0 + 3.0 + 3.0 + cbrt + 1.0 + 2.0;
        let line = 3.0 + 1.0 + INV_SQRT_MAX_REL_ERROR as f64 / u + 4.0;
        let band = SATURATION_ULPS as f64 / u;
        assert!(elliptic <= band && line <= band, "{elliptic} {line} {band}");
        // F / (mu P): F, P, mu read as f32, mu P, the quotient.
        assert!(5.0 <= ROUNDING_BELOW_SATURATION as f64 / u);
        assert_eq!(ROUNDING_BELOW_SATURATION, ROUNDING_ABOVE_SATURATION);
    }
}
