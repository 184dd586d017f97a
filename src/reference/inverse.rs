//! Inverse estimates in f64: the friction coefficient mu from a measured axial force F
//! at known load P and misalignment phi, and the misalignment phi from F at known P
//! and mu. The answer says when the inverse is ill-posed instead of giving a wrong
//! number ([`Inverse`]).
//!
//! ```
//! use misalign::{reference, Scene};
//! use misalign::reference::inverse::{self, Inverse};
//!
//! let scene = Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3)?;
//! // Forward: 1 kN, 0.2 mrad (partial slip), then back from the axial force.
//! let f = reference::elliptic(&scene, 1e3, 2e-4)?.axial_force;
//! let answer = inverse::friction_elliptic(&scene, 1e3, 2e-4, f)?;
//! assert_eq!(answer.bound_str(), "exact");
//! let (mu, sensitivity) = (answer.value().unwrap(), answer.sensitivity().unwrap());
//! assert!((mu / 0.3 - 1.0).abs() < 1e-12 && sensitivity > 1.0);
//! let phi = inverse::angle_elliptic(&scene, 1e3, f)?.value().unwrap();
//! assert!((phi / 2e-4 - 1.0).abs() < 1e-12);
//! // Gross slip: F = mu P says only phi >= phi0.
//! let f = reference::elliptic(&scene, 1e3, 1e-3)?.axial_force;
//! assert!(matches!(inverse::angle_elliptic(&scene, 1e3, f)?, Inverse::AtLeast { .. }));
//! # Ok::<(), misalign::Error>(())
//! ```
//!
//! # Shape of the forward map
//! Write `s = d/b` and `f(s) = F / (mu P)`: eq (21) for the ellipse, `2 s - s^2`
//! (eq 27) for line contact, 1 for `s >= 1` (eqs 21, 29). Both `f` are increasing
//! and concave on `[0, 1]` (eq 21: `f' = (3/2)(acos s - s sqrt(1 - s^2)) > 0`,
//! `f'' = -3 sqrt(1 - s^2) < 0`), so `f(s)/s` falls from `f'(0)` to 1.
//!
//! - **F against |phi|** (P, mu fixed): `s` grows with |phi| (eq 16: `s` is
//!   proportional to `g(theta) = m n theta`, increasing in theta; eq 23: `s` is
//!   proportional to |phi|), so F grows with |phi| up to the critical angle phi0
//!   (`s = 1`, eqs 18, 28) and stays at `mu P` beyond. A measured F equal to mu P
//!   only says `|phi| >= phi0` ([`Inverse::AtLeast`]), and so does an F up to
//!   [`ROUNDING_ABOVE_SATURATION`] above it (the rounding of mu P); F further above
//!   mu P is inconsistent.
//!   For the ellipse at a load so high that no theta <= pi/2 reaches `s = 1`, the
//!   largest F is `mu P f(s(pi/2)) < mu P`.
//! - **F against mu** (P, phi fixed): `s = K / mu` with `K = mu d/b` independent of mu
//!   (eq 15: `K = pi G a b |phi| / (3 P)`; eq 23: `K = (|phi|/2) sqrt(pi (1 - nu) G R / P)`),
//!   so `F = mu P f(K/mu) = K P f(s)/s`, which grows with mu (as `f(s)/s` falls with s).
//!   For `mu <= K` the contact slips everywhere and `F = mu P`, so `mu = F/P` exactly.
//!   As `mu -> inf` the contact stops slipping (`s -> 0`) and F tends to the finite
//!   limit `K P f'(0)`: `(3 pi / 4) K P = pi^2 G a b |phi| / 4` for the ellipse and
//!   `2 K P = |phi| sqrt(pi (1 - nu) G R P)` for line contact; no mu reaches it. An F
//!   within rounding of that limit only bounds mu from below, an F above it is
//!   inconsistent.
//! - The sensitivity `S = d ln(answer) / d ln F` turns a relative uncertainty of F into
//!   one of the answer. For mu: `S = 1 / (1 - s f'(s)/f(s))`: 1 in gross slip, growing
//!   like `pi / (2 s)` as `s -> 0`. For phi: `S = f(s) / (s f'(s) E)` with
//!   `E = d ln g / d ln phi` (1 for line contact, 2/3 as theta -> 0 for the ellipse):
//!   it grows without bound as `s -> 1`, where `1 - f ~ (4 sqrt 2 / 5)(1 - s)^(5/2)`.
//!
//! A caller whose F carries a tolerance turns it into one of the answer with the
//! sensitivity; near the saturation (large S) it should read the answer as a bound.
//!
//! Section 9 ([`friction_estimate`], [`angle_estimate`]): the model follows the
//! ellipse's length 2a, which depends on P and phi but not on mu; so the mu-inverse
//! uses the model [`super::estimate`] chooses at (P, phi). For the phi-inverse both
//! models are tried, each answer kept only where [`super::estimate`] would choose its
//! model; two answers (the map is not monotone across the switch) give the smaller as
//! a lower bound.

use super::chain::chain;
use super::line::SQRT_PI;
use super::{ContactModel, line as strip, solve, tangential};
use crate::{Error, Scene, ThetaRelation};
use core::f64::consts::{FRAC_PI_2, PI};

/// Why a measured axial force fits no state of the model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Inconsistency {
    /// |F| above the largest force the model gives at these inputs (mu P for the
    /// phi-inverse, the no-slip limit for the mu-inverse).
    AboveModel,
    /// F has the sign opposite to phi (F acts along the misalignment, section 7).
    OppositeSign,
    /// F non-zero at zero load: an unloaded contact carries no traction.
    ZeroLoad,
    /// F non-zero at phi = 0: aligned rollers generate no axial force.
    NoMisalignment,
    /// Section 9: the model choice jumps over this F (no phi on either side of the
    /// switch between line and elliptic contact gives it).
    BetweenModels,
}

impl Inconsistency {
    /// A short machine-readable name (`above_model`, `opposite_sign`, ...).
    pub fn as_str(self) -> &'static str {
        match self {
            Inconsistency::AboveModel => "above_model",
            Inconsistency::OppositeSign => "opposite_sign",
            Inconsistency::ZeroLoad => "zero_load",
            Inconsistency::NoMisalignment => "no_misalignment",
            Inconsistency::BetweenModels => "between_models",
        }
    }
}

/// The answer of an inverse: which case holds, with what it can say. `T` is `f64` here
/// and `f32` in [`crate::float`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Inverse<T> {
    /// The unique answer, with its sensitivity `d ln(value) / d ln F` (>= 0; +inf where
    /// the forward map is flat).
    Exact {
        /// The answer: mu, or phi (rad) signed like F.
        value: T,
        /// Relative change of the answer per relative change of F.
        sensitivity: T,
    },
    /// F does not fix the answer: it is at least `value` (mu, or |phi| in rad signed
    /// like F). Said where the forward map saturates.
    AtLeast {
        /// The lower bound.
        value: T,
    },
    /// No state of the model gives this F.
    Inconsistent(Inconsistency),
}

impl<T: Copy> Inverse<T> {
    /// The value (exact or bound), `None` when inconsistent.
    pub fn value(&self) -> Option<T> {
        match *self {
            Inverse::Exact { value, .. } | Inverse::AtLeast { value } => Some(value),
            Inverse::Inconsistent(_) => None,
        }
    }
    /// The sensitivity of an exact answer.
    pub fn sensitivity(&self) -> Option<T> {
        match *self {
            Inverse::Exact { sensitivity, .. } => Some(sensitivity),
            _ => None,
        }
    }
    /// The same answer with its numbers converted by `f` (e.g. f64 to f32).
    pub fn map<U>(self, f: impl Fn(T) -> U) -> Inverse<U> {
        match self {
            Inverse::Exact { value, sensitivity } => Inverse::Exact {
                value: f(value),
                sensitivity: f(sensitivity),
            },
            Inverse::AtLeast { value } => Inverse::AtLeast { value: f(value) },
            Inverse::Inconsistent(why) => Inverse::Inconsistent(why),
        }
    }
    /// `exact`, `at_least` or `inconsistent` (the CSV column `bound`).
    pub fn bound_str(&self) -> &'static str {
        match self {
            Inverse::Exact { .. } => "exact",
            Inverse::AtLeast { .. } => "at_least",
            Inverse::Inconsistent(_) => "inconsistent",
        }
    }
}

/// The two float types the inverses are written for (the f32 core shares the cases
/// decided before the model with the reference).
pub(crate) trait Real: Copy + PartialOrd {
    const ZERO: Self;
    const ONE: Self;
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
}

impl Real for f32 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
}

/// Relative distance below the no-slip limit of F(mu) within which F is taken as the
/// limit itself (the forward map's rounding there is a few ulps): the mu-inverse then
/// says only `AtLeast`.
const SATURATION_ULPS: f64 = 8.0 * f64::EPSILON;

/// An F up to this far (relative) above mu P counts as mu P, the saturation: the
/// rounding of mu P itself, formed from rounded inputs in another order. Further
/// above, F is inconsistent.
pub const ROUNDING_ABOVE_SATURATION: f64 = 4.0 * f64::EPSILON;

/// Checks shared by all inverses: typed errors for undefined input.
fn check(load: f64, phi: f64, force: f64) -> Result<(), Error> {
    super::check_sample(load, phi)?;
    if !force.is_finite() {
        return Err(Error::Force);
    }
    Ok(())
}

/// The cases every mu-inverse shares before the model: `Some(answer)` when F = 0 or
/// P = 0 or phi = 0 decide it.
pub(crate) fn friction_trivial<T: Real>(load: T, phi: T, force: T) -> Option<Inverse<T>> {
    if force == T::ZERO {
        // F = 0 at P = 0 or phi = 0 holds for every mu: mu >= 0 is all it says. With
        // P, phi > 0 it is the frictionless limit of gross slip, mu = F/P = 0.
        return Some(if load == T::ZERO || phi == T::ZERO {
            Inverse::AtLeast { value: T::ZERO }
        } else {
            Inverse::Exact {
                value: T::ZERO,
                sensitivity: T::ONE,
            }
        });
    }
    if load == T::ZERO {
        return Some(Inverse::Inconsistent(Inconsistency::ZeroLoad));
    }
    if phi == T::ZERO {
        return Some(Inverse::Inconsistent(Inconsistency::NoMisalignment));
    }
    if (force > T::ZERO) != (phi > T::ZERO) {
        return Some(Inverse::Inconsistent(Inconsistency::OppositeSign));
    }
    None
}

/// mu from `q = F / (K P)` (`K = mu d/b`) and `F / P`, given `f(s)/s` of the model,
/// its limit `f'(0)` and the closed form of s where it exists.
fn friction_from_ratio(
    force_per_load: f64,
    k: f64,
    ratio_over_s: impl Fn(f64) -> f64,
    slope: impl Fn(f64) -> f64,
    no_slip_limit: f64,
) -> Inverse<f64> {
    // Gross slip (mu <= K, s >= 1): F = mu P, eqs (21), (29).
    if force_per_load <= k {
        return friction_bounded(force_per_load, 1.0);
    }
    let q = force_per_load / k;
    if q > no_slip_limit * (1.0 + SATURATION_ULPS) {
        return Inverse::Inconsistent(Inconsistency::AboveModel);
    }
    // f(s)/s - q falls with s: solve q - f(s)/s = 0, increasing, for s in (0, 1].
    let target = libm::fmin(q, no_slip_limit * (1.0 - SATURATION_ULPS));
    let Some(s) = solve::increasing_root(|s| target - ratio_over_s(s), 0.5, 0.0, 1.0) else {
        // q in (1, limit) always has a root; none means q was NaN (not reachable).
        return Inverse::Inconsistent(Inconsistency::AboveModel);
    };
    let mu = k / s;
    if q >= no_slip_limit * (1.0 - SATURATION_ULPS) {
        return Inverse::AtLeast {
            value: libm::fmin(mu, f64::MAX),
        };
    }
    let f = ratio_over_s(s) * s;
    friction_bounded(mu, 1.0 / (1.0 - s * slope(s) / f))
}

/// An exact mu, or `AtLeast` the largest f64 where mu overflows (F/P above 1.8e308).
fn friction_bounded(mu: f64, sensitivity: f64) -> Inverse<f64> {
    if mu.is_finite() {
        Inverse::Exact {
            value: mu,
            sensitivity,
        }
    } else {
        Inverse::AtLeast { value: f64::MAX }
    }
}

/// eq (21) divided by s, exact at small s (`f(s)/s -> 3 pi / 4`).
fn elliptic_ratio_over_s(s: f64) -> f64 {
    if s == 0.0 {
        0.75 * PI
    } else {
        tangential::axial_force_ratio(s) / s
    }
}

/// The friction coefficient mu for the elliptic contact (sections 5-7) from load
/// `load` (N), misalignment `phi` (rad, signed) and measured axial force `force` (N).
/// The scene's own friction is not read: pass any scene of the installation.
///
/// # Errors
/// [`Error::Load`], [`Error::Angle`] as the forward solution, [`Error::Force`] for a
/// NaN or infinite F, [`Error::PlaneHasNoEllipse`] for a plane.
pub fn friction_elliptic(
    scene: &Scene,
    load: f64,
    phi: f64,
    force: f64,
) -> Result<Inverse<f64>, Error> {
    check(load, phi, force)?;
    // The ellipse (a, b, and K = mu d/b) does not depend on mu: the forward solution
    // with the scene's (unread) mu gives it, and its errors.
    let e = super::elliptic(scene, load, phi)?;
    if let Some(answer) = friction_trivial(load, phi, force) {
        return Ok(answer);
    }
    // eq (15): K = mu d/b, formed without mu.
    let k = tangential::slip_ratio(
        scene.shear_modulus(),
        1.0,
        e.shape.mn(),
        super::hertz_scale(scene),
        load,
        phi,
    );
    Ok(friction_from_ratio(
        libm::fabs(force) / load,
        k,
        elliptic_ratio_over_s,
        tangential::axial_force_ratio_slope,
        0.75 * PI,
    ))
}

/// The friction coefficient mu for line contact (section 8) from load per unit length
/// `load` (N/m), misalignment `phi` (rad, signed) and axial force per unit length
/// `force` (N/m): `mu = F/P` in gross slip (`F <= K P`), else the root of eq (27)
/// over s, which is the closed form `mu = K^2 P / (2 K P - F)` of eqs (23), (27).
/// The scene's friction is not read.
///
/// # Errors
/// [`Error::Load`], [`Error::Angle`] (|phi| above pi/2 included), [`Error::Force`].
pub fn friction_line(
    scene: &Scene,
    load: f64,
    phi: f64,
    force: f64,
) -> Result<Inverse<f64>, Error> {
    check(load, phi, force)?;
    if libm::fabs(phi) > FRAC_PI_2 {
        return Err(Error::Angle);
    }
    if let Some(answer) = friction_trivial(load, phi, force) {
        return Ok(answer);
    }
    let (nu, g_mod, radius) = (
        scene.poisson_ratio(),
        scene.shear_modulus(),
        scene.effective_radius(),
    );
    let k = strip::slip_ratio(load, nu, g_mod, radius, 1.0, phi); // eq (23) at mu = 1
    let r = libm::fabs(force) / load;
    Ok(friction_from_ratio(
        r,
        k,
        |s| if s >= 1.0 { 1.0 / s } else { 2.0 - s }, // eq (27) over s
        |s| if s >= 1.0 { 0.0 } else { 2.0 - 2.0 * s },
        2.0,
    ))
}

/// The friction coefficient through section 9's model choice ([`super::estimate`]):
/// `load` (N) and `force` (N) are totals; with line contact both are divided by the
/// scene's length. The scene's friction is not read.
///
/// # Errors
/// As [`friction_elliptic`] and [`friction_line`].
pub fn friction_estimate(
    scene: &Scene,
    load: f64,
    phi: f64,
    force: f64,
) -> Result<Inverse<f64>, Error> {
    check(load, phi, force)?;
    // The model depends on P and phi only: the forward choice at the scene's mu is it.
    match super::estimate(scene, load, phi)?.model() {
        ContactModel::Elliptic => friction_elliptic(scene, load, phi, force),
        ContactModel::Line => {
            let length = scene.length().unwrap_or(1.0);
            friction_line(scene, load / length, phi, force / length)
        }
    }
}

/// The cases every phi-inverse shares: `Some(answer)` when P = 0 or F = 0 decide it.
/// `zero_angle_sensitivity` is `S` as phi -> 0.
pub(crate) fn angle_trivial<T: Real>(
    load: T,
    force: T,
    zero_angle_sensitivity: T,
) -> Option<Inverse<T>> {
    if load == T::ZERO {
        // Zero load: F = 0 at every phi (phi0 = 0), any other F is impossible.
        return Some(if force == T::ZERO {
            Inverse::AtLeast { value: T::ZERO }
        } else {
            Inverse::Inconsistent(Inconsistency::ZeroLoad)
        });
    }
    if force == T::ZERO {
        return Some(Inverse::Exact {
            value: T::ZERO,
            sensitivity: zero_angle_sensitivity,
        });
    }
    None
}

/// The slip ratio s in (0, 1) with eq (21) `f(s) = r`, for r in (0, 1).
fn elliptic_slip_ratio_of(r: f64) -> Option<f64> {
    let guess = libm::fmin(r / (0.75 * PI), 1.0); // f(s) <= 3 pi s / 4
    solve::increasing_root(|s| tangential::axial_force_ratio(s) - r, guess, 0.0, 1.0)
}

/// `d ln g / d ln theta` at theta (central difference in ln theta, clamped to
/// [0, pi/2]); 2/3 at theta = 0 (g ~ theta^(2/3), reference README).
fn log_slope_of_g(theta: f64) -> f64 {
    if theta == 0.0 {
        return 2.0 / 3.0;
    }
    let h = 1e-4;
    let lo = theta * libm::exp(-h);
    let hi = libm::fmin(theta * libm::exp(h), FRAC_PI_2);
    let g = |t: f64| super::normal::ellipse_shape(t).map_or(f64::NAN, |s| s.g());
    (libm::log(g(hi)) - libm::log(g(lo))) / (libm::log(hi) - libm::log(lo))
}

/// `d ln theta / d ln phi` under the scene's relation (1 for eq 4).
fn log_slope_of_theta(scene: &Scene, phi: f64, theta: f64) -> f64 {
    match scene.theta_relation() {
        ThetaRelation::SmallAngle => 1.0,
        ThetaRelation::Exact => {
            // sin theta = c sin phi: d theta / d phi = c cos phi / cos theta.
            let c = scene.radius_factor();
            phi * c * libm::cos(phi) / (theta * libm::cos(theta))
        }
    }
}

/// The misalignment phi (rad, signed like F) for the elliptic contact from load `load`
/// (N) and measured axial force `force` (N), with the scene's friction mu.
///
/// # Errors
/// [`Error::Load`], [`Error::Force`], [`Error::PlaneHasNoEllipse`] for a plane.
pub fn angle_elliptic(scene: &Scene, load: f64, force: f64) -> Result<Inverse<f64>, Error> {
    check(load, 0.0, force)?;
    if scene.is_plane() || scene.radius_factor() == 0.0 {
        return Err(Error::PlaneHasNoEllipse);
    }
    if let Some(answer) = angle_trivial(load, force, 1.5) {
        return Ok(answer);
    }
    // The saturated force as the forward solution forms it: mu (P f) with f = 1.
    let saturated = scene.friction() * (load * 1.0);
    Ok(signed(
        angle_elliptic_below(scene, load, libm::fabs(force), saturated),
        force,
    ))
}

/// The elliptic phi-inverse for `force > 0`, its saturation at `saturated` = mu P.
fn angle_elliptic_below(scene: &Scene, load: f64, force: f64, saturated: f64) -> Inverse<f64> {
    if force > saturated * (1.0 + ROUNDING_ABOVE_SATURATION) {
        return Inverse::Inconsistent(Inconsistency::AboveModel);
    }
    if force >= saturated {
        return match super::critical_angle(scene, load) {
            Some((phi0, _)) => Inverse::AtLeast { value: phi0 },
            // No theta <= pi/2 reaches gross slip: F stays below mu P.
            None => Inverse::Inconsistent(Inconsistency::AboveModel),
        };
    }
    let r = force / saturated;
    let Some(s) = elliptic_slip_ratio_of(r) else {
        return Inverse::Inconsistent(Inconsistency::AboveModel);
    };
    let Some((phi, theta)) = super::angle_at_slip_ratio(scene, load, s) else {
        // The slip ratio at theta = pi/2 stays below s: F above the model's largest.
        return Inverse::Inconsistent(Inconsistency::AboveModel);
    };
    // eq (16): s is proportional to g(theta); S = f / (s f' E).
    let e = log_slope_of_g(theta) * log_slope_of_theta(scene, phi, theta);
    let sensitivity = r / (s * tangential::axial_force_ratio_slope(s) * e);
    Inverse::Exact {
        value: phi,
        sensitivity: if sensitivity.is_nan() {
            f64::INFINITY
        } else {
            sensitivity
        },
    }
}

/// The misalignment phi (rad, signed like F) for line contact from load per unit
/// length `load` (N/m) and axial force per unit length `force` (N/m), with the scene's
/// mu. Closed form: `s = r / (1 + sqrt(1 - r))`, `r = F / (mu P)` (eq 27 solved without
/// cancellation), `phi = s phi0` (eqs 23, 28).
///
/// # Errors
/// [`Error::Load`], [`Error::Force`].
pub fn angle_line(scene: &Scene, load: f64, force: f64) -> Result<Inverse<f64>, Error> {
    check(load, 0.0, force)?;
    if let Some(answer) = angle_trivial(load, force, 1.0) {
        return Ok(answer);
    }
    let saturated = scene.friction() * (load * 1.0);
    Ok(signed(
        angle_line_below(scene, load, libm::fabs(force), saturated, 1.0),
        force,
    ))
}

/// `answer` with its value signed like `force`.
fn signed(answer: Inverse<f64>, force: f64) -> Inverse<f64> {
    match answer {
        Inverse::Exact { value, sensitivity } => Inverse::Exact {
            value: libm::copysign(value, force),
            sensitivity,
        },
        Inverse::AtLeast { value } => Inverse::AtLeast {
            value: libm::copysign(value, force),
        },
        other => other,
    }
}

/// The line phi-inverse for `force > 0` per unit length times `length` (the forward
/// solution's total), its saturation at `saturated` (mu P per length, times length).
fn angle_line_below(
    scene: &Scene,
    load: f64,
    force: f64,
    saturated: f64,
    length: f64,
) -> Inverse<f64> {
    let phi0 = strip::critical_angle(
        load,
        scene.poisson_ratio(),
        scene.shear_modulus(),
        scene.effective_radius(),
        scene.friction(),
    );
    let saturated = saturated * length;
    // r = F / (mu P), and whether F exceeds or reaches mu P: as the forward solution
    // forms mu P, or factor by factor where that overflows (mu P beyond f64, or only
    // mu P / length, with F finite).
    let (r, above, at) = if saturated.is_finite() {
        (
            force / saturated,
            force > saturated * (1.0 + ROUNDING_ABOVE_SATURATION),
            force >= saturated,
        )
    } else {
        let r = chain(&[force], &[scene.friction(), load, length]);
        (r, r > 1.0 + ROUNDING_ABOVE_SATURATION, r >= 1.0)
    };
    if above {
        return Inverse::Inconsistent(Inconsistency::AboveModel);
    }
    if at {
        // Gross slip needs |phi| >= phi0; the forward solution takes |phi| < pi/2 only
        // (phi0 overflows to inf where mu or P / R is extreme).
        return if phi0 <= FRAC_PI_2 {
            Inverse::AtLeast { value: phi0 }
        } else {
            Inverse::Inconsistent(Inconsistency::AboveModel)
        };
    }
    let s = r / (1.0 + libm::sqrt(1.0 - r)); // eq (27): 2 s - s^2 = r
    // eqs (23), (28): |phi| = s phi0 = r phi0 / (1 + sqrt(1 - r)), and
    // r phi0 = 2 (F / length) / sqrt(pi (1 - nu) G R P) holds no mu: formed so, the
    // product s phi0 cannot be 0 x inf (mu P overflowing to inf, so r = 0, while phi0
    // overflows too). F / length as the line inverse per unit length has it, or
    // factor by factor where it overflows.
    let sq = libm::sqrt;
    let stiffness = [
        SQRT_PI,
        sq(1.0 - scene.poisson_ratio()),
        sq(scene.shear_modulus()),
        sq(scene.effective_radius()),
        sq(load),
    ];
    let force_per_length = force / length;
    let r_phi0 = if force_per_length.is_finite() {
        chain(&[2.0, force_per_length], &stiffness)
    } else {
        let [a, b, c, d, e] = stiffness;
        chain(&[2.0, force], &[a, b, c, d, e, length])
    };
    let phi = r_phi0 / (1.0 + sq(1.0 - r));
    if phi > FRAC_PI_2 {
        return Inverse::Inconsistent(Inconsistency::AboveModel);
    }
    Inverse::Exact {
        value: phi,
        sensitivity: (2.0 - s) / (2.0 * (1.0 - s)), // f / (s f')
    }
}

/// P / length (N/m), refused with [`Error::Load`] where it overflows, as
/// [`super::estimate`] refuses it.
fn per_length(load: f64, length: f64) -> Result<f64, Error> {
    let p = load / length;
    if p.is_finite() {
        Ok(p)
    } else {
        Err(Error::Load)
    }
}

/// The misalignment through section 9's model choice ([`super::estimate`]): `load` (N)
/// and `force` (N) are totals. Each model's answer counts only where the model choice
/// at that phi picks that model; see the module docs for two answers or none.
///
/// # Errors
/// As [`angle_elliptic`] and [`angle_line`].
pub fn angle_estimate(scene: &Scene, load: f64, force: f64) -> Result<Inverse<f64>, Error> {
    check(load, 0.0, force)?;
    // A plane, or radii so unequal that c underflows, has a strip at every phi: line
    // contact (section 8), P and F per unit length without a length, as
    // [`super::estimate`] reads them.
    if scene.is_plane() || scene.radius_factor() == 0.0 {
        let length = scene.length().unwrap_or(1.0);
        let per_length = per_length(load, length)?;
        let saturated = scene.friction() * (per_length * 1.0);
        if let Some(answer) = angle_trivial(load, force, 1.0) {
            return Ok(answer);
        }
        return Ok(signed(
            angle_line_below(scene, per_length, libm::fabs(force), saturated, length),
            force,
        ));
    }
    // Without a length section 9 always takes the ellipse.
    let Some(length) = scene.length() else {
        return angle_elliptic(scene, load, force);
    };
    let per_length = per_length(load, length)?;
    if let Some(answer) = angle_trivial(load, force, 1.5) {
        // F = 0: phi = 0, where the ellipse is infinitely long: line contact, S = 1.
        return Ok(match answer {
            Inverse::Exact { value, .. } => Inverse::Exact {
                value,
                sensitivity: 1.0,
            },
            other => other,
        });
    }
    let abs_force = libm::fabs(force);
    let line_answer = angle_line_below(
        scene,
        per_length,
        abs_force,
        scene.friction() * (per_length * 1.0),
        length,
    );
    let elliptic_answer = angle_elliptic_below(scene, load, abs_force, scene.friction() * load);
    let picks = |phi: f64, model: ContactModel| {
        super::estimate(scene, load, phi).is_ok_and(|e| e.model() == model)
    };
    // The largest phi the forward solution takes: FRAC_PI_2 (the f64 below pi/2) and,
    // for eq (4), at most theta = pi/2. The ellipse is shortest there, so the
    // elliptic model is chosen somewhere iff it is there.
    let below_right_angle = FRAC_PI_2;
    let phi_max = match scene.theta_relation() {
        ThetaRelation::SmallAngle => libm::fmin(
            FRAC_PI_2 / scene.radius_factor() * (1.0 - 4.0 * f64::EPSILON),
            below_right_angle,
        ),
        ThetaRelation::Exact => below_right_angle,
    };
    let line_ok = match line_answer {
        Inverse::Exact { value, .. } | Inverse::AtLeast { value } => {
            picks(value, ContactModel::Line)
        }
        Inverse::Inconsistent(_) => false,
    };
    let elliptic_ok = match elliptic_answer {
        Inverse::Exact { value, .. } => picks(value, ContactModel::Elliptic),
        // Saturated: every phi >= phi0 in the elliptic region gives F; phi0 bounds them.
        Inverse::AtLeast { value } => {
            picks(value, ContactModel::Elliptic) || picks(phi_max, ContactModel::Elliptic)
        }
        Inverse::Inconsistent(_) => false,
    };
    let answer = match (line_ok, elliptic_ok) {
        (true, false) => line_answer,
        (false, true) => elliptic_answer,
        (true, true) => Inverse::AtLeast {
            value: libm::fmin(
                line_answer.value().unwrap_or(0.0),
                elliptic_answer.value().unwrap_or(0.0),
            ),
        },
        (false, false) => match (line_answer, elliptic_answer) {
            (Inverse::Inconsistent(_), Inverse::Inconsistent(_)) => {
                Inverse::Inconsistent(Inconsistency::AboveModel)
            }
            _ => Inverse::Inconsistent(Inconsistency::BetweenModels),
        },
    };
    Ok(signed(answer, force))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_slip_limits() {
        // eq (21) over s tends to 3 pi / 4 as s -> 0; eq (27) over s to 2.
        assert!((elliptic_ratio_over_s(1e-12) / (0.75 * PI) - 1.0).abs() < 1e-11);
    }
}
