//! The f64 reference: every equation of the paper, to a few ulps, `no_std` (libm).
//! It is the ground truth the f32 and fixed-point cores are tested against and the
//! source of their tables. Sub-modules follow the paper: [`normal`] (section 5),
//! [`tangential`] (sections 6-7), [`line`](mod@line) (section 8); this module holds the
//! per-sample results and the model choice of section 9.

mod carlson;
mod chain;
#[cfg(test)]
mod cost;
pub mod fast;
pub mod inverse;
pub mod line;
pub mod normal;
mod solve;
pub mod tangential;

#[cfg(feature = "_internals")]
#[doc(hidden)]
pub use carlson::carlson_rd;
pub use normal::EllipseShape;
pub use tangential::Regime;

use crate::{Error, Scene, ThetaRelation};
use core::f64::consts::{FRAC_PI_2, PI};

/// Above this |phi| (rad) the small-angle form of eq (4) and the slender-ellipse
/// expansion of section 4 are stretched (sin phi differs from phi by 0.17 %).
pub const ANGLE_LIMIT: f64 = 0.1;
/// Above this `p0 / G` the contact is far beyond the stresses the paper discusses
/// (its example has 0.005; the reference data stop at 0.05).
pub const PRESSURE_LIMIT: f64 = 0.05;

/// Section 9's switch is flagged ([`Validity::near_model_switch`]) while the ellipse's
/// length 2a is within this factor of the rollers' length: 2a / length in
/// [1/1.25, 1.25]. There the two models disagree by a jump, not by rounding: at
/// 2a = length the line model's d/b is `sqrt(3 / (2 E(k)))` times the elliptic one
/// (1.22 for a slender ellipse, E(k) -> 1), because P / length is the mean load per
/// length while the ellipse's centre carries 1.5 times that (eq 7 against eq 22); F
/// moves by a few per cent and phi0 jumps to the other model's value.
pub const MODEL_SWITCH_BAND: f64 = 1.25;
/// Below this axis ratio a/b the ellipse is too round for the slender theory
/// ([`Validity::round_ellipse`]): the paper's line integrals under-predict F against
/// Kalker's exact three-dimensional theory by about 2 % at a/b = 10 (1 % at 17.6),
/// the error growing like (b/a)^1.5 to 33 % at a/b = 1 (tests/data/physics-error.md).
pub const SLENDER_LIMIT: f64 = 10.0;

/// Which solution produced a result.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ContactModel {
    /// The contact ellipse, sections 5-7.
    Elliptic,
    /// The contact strip, section 8 (load per unit length).
    Line,
}

/// How the contact model of a sample is chosen, the same in the reference and in both
/// cores. P is the total load (N) whenever the scene has a length; without one, line
/// contact reads it as a load per unit length (N/m).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ModelChoice {
    /// Section 9, per sample: line contact with P / length when the ellipse is longer
    /// than the rollers (2a > length), and always for a plane; the ellipse otherwise.
    #[default]
    Section9,
    /// Always the ellipse (sections 5-7), e.g. a firmware that must not switch; the
    /// flags still say when the ellipse is longer than the rollers.
    Elliptic,
    /// Always line contact (section 8), with P / length when the scene has a length.
    Line,
}

impl ModelChoice {
    /// The model for a sample with an ellipse (not a plane) that is, or is not, longer
    /// than the rollers (2a > length).
    #[inline]
    pub fn model(self, longer_than_rollers: bool) -> ContactModel {
        match self {
            ModelChoice::Elliptic => ContactModel::Elliptic,
            ModelChoice::Line => ContactModel::Line,
            ModelChoice::Section9 if longer_than_rollers => ContactModel::Line,
            ModelChoice::Section9 => ContactModel::Elliptic,
        }
    }
}

impl ContactModel {
    /// `"elliptic"` or `"line"`.
    pub fn as_str(self) -> &'static str {
        match self {
            ContactModel::Elliptic => "elliptic",
            ContactModel::Line => "line",
        }
    }
}

/// Where the theory's assumptions are stretched. The numbers are still the paper's
/// equations evaluated exactly; these flags say how far to trust the physics.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Validity {
    /// |phi| above [`ANGLE_LIMIT`], or a critical angle above it.
    pub large_angle: bool,
    /// `p0 / G` above [`PRESSURE_LIMIT`].
    pub high_pressure: bool,
    /// The ellipse (2a) is longer than the rollers' contact length.
    pub longer_than_rollers: bool,
    /// 2a / length within [`MODEL_SWITCH_BAND`] of 1: the model choice of section 9
    /// could go either way, and the two models differ there by a jump.
    pub near_model_switch: bool,
    /// a/b below [`SLENDER_LIMIT`]: the slender-ellipse theory under-predicts F by
    /// more than about 2 %.
    pub round_ellipse: bool,
}

impl Validity {
    /// True when no flag is raised.
    pub fn is_valid(&self) -> bool {
        !(self.large_angle
            || self.high_pressure
            || self.longer_than_rollers
            || self.near_model_switch
            || self.round_ellipse)
    }
}

/// Results of the elliptic solution (sections 5-7) for one sample.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Elliptic {
    /// Misalignment phi (rad), signed, as given.
    pub phi: f64,
    /// Load P (N).
    pub load: f64,
    /// theta, k', m, n at this phi (eqs 4-6).
    pub shape: EllipseShape,
    /// Semi-axis along the rollers a = m L (m); +inf at phi = 0.
    pub a: f64,
    /// Semi-axis in the rolling direction b = n L (m).
    pub b: f64,
    /// Peak pressure p0 = 3P/(2 pi a b) (Pa), eq (7).
    pub p0: f64,
    /// Non-dimensional load P* (eq 17).
    pub pstar: f64,
    /// Critical non-dimensional load P0* (eq 18).
    pub p0star: f64,
    /// Slip ratio d/b (eqs 15, 16, 19).
    pub slip_ratio: f64,
    /// Distance d of the stick zone's centre from the x axis (m), eq (14), capped at b
    /// (in gross slip the whole width b slips).
    pub d: f64,
    /// Partial or gross slip.
    pub regime: Regime,
    /// Axial force F (N) with the sign of phi, eq (21).
    pub axial_force: f64,
    /// Critical angle phi0 (rad) at this load, where d/b = 1 (eqs 18, 30); `None`
    /// when no theta <= pi/2 reaches d/b = 1, or when phi0 = theta0 / c (eq 4) would
    /// lie beyond pi/2 (unequal radii): no angle between two axes reaches gross slip.
    pub critical_angle: Option<f64>,
    /// Auxiliary angle at the critical angle, theta0 (rad).
    pub critical_theta: Option<f64>,
    /// Critical load (N) at this phi: the load at which d/b = 1 (eqs 17-19).
    pub critical_load: f64,
    /// Where the theory is stretched.
    pub validity: Validity,
}

/// Results of the line-contact solution (section 8) for one sample.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Line {
    /// Misalignment phi (rad), signed, as given.
    pub phi: f64,
    /// Load per unit length P (N/m).
    pub load: f64,
    /// Radius of eqs (22)-(28): R1 on a plane, R = R1 R2/(R1 + R2) for rollers (eq 31).
    pub radius: f64,
    /// Half-width of the strip b (m), eq (22).
    pub b: f64,
    /// Peak pressure p0 = 2P/(pi b) (Pa).
    pub p0: f64,
    /// Non-dimensional load P* (eq 24).
    pub pstar: f64,
    /// Critical non-dimensional load P0* (eq 25).
    pub p0star: f64,
    /// Slip ratio d/b (eq 23).
    pub slip_ratio: f64,
    /// Half the width of the microslip strip (m): the strip runs from the leading edge
    /// y = -b to y = 2d - b (eq 26), so it is 2d wide; d = (d/b) b, capped at b in
    /// gross slip.
    pub d: f64,
    /// Partial or gross slip.
    pub regime: Regime,
    /// Axial force per unit length F (N/m) with the sign of phi, eqs (27), (29).
    pub axial_force: f64,
    /// Critical angle phi0 (rad), eq (28); `None` where eq (28) gives more than pi/2
    /// (an extreme load per length): no angle between two axes reaches gross slip.
    pub critical_angle: Option<f64>,
    /// Critical load per unit length (N/m) at this phi.
    pub critical_load: f64,
    /// Where the theory is stretched.
    pub validity: Validity,
}

/// A result of either model, as chosen by [`estimate`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Solution {
    /// The ellipse fits on the rollers (or no length was given).
    Elliptic(Elliptic),
    /// The ellipse would be longer than the rollers: line contact with P / length.
    Line(Line),
}

impl Solution {
    /// Which model produced it.
    pub fn model(&self) -> ContactModel {
        match self {
            Solution::Elliptic(_) => ContactModel::Elliptic,
            Solution::Line(_) => ContactModel::Line,
        }
    }
    /// Slip ratio d/b.
    pub fn slip_ratio(&self) -> f64 {
        match self {
            Solution::Elliptic(e) => e.slip_ratio,
            Solution::Line(l) => l.slip_ratio,
        }
    }
    /// Regime.
    pub fn regime(&self) -> Regime {
        Regime::of(self.slip_ratio())
    }
    /// Total axial force F (N): per unit length times the length for line contact
    /// (N/m for line contact without a length).
    pub fn axial_force(&self, scene: &Scene) -> f64 {
        match self {
            Solution::Elliptic(e) => e.axial_force,
            Solution::Line(l) => l.axial_force * scene.length().unwrap_or(1.0),
        }
    }
    /// Rolling resistance `F phi / 2` (N) on each cylinder (section 7): the line
    /// model's per unit length times the length (section 9), or N/m without a length.
    pub fn rolling_resistance(&self, scene: &Scene) -> f64 {
        match self {
            Solution::Elliptic(e) => e.rolling_resistance(),
            Solution::Line(l) => l.rolling_resistance() * scene.length().unwrap_or(1.0),
        }
    }
    /// Power `F phi V` (W) dissipated by microslip at rolling speed `speed` (m/s),
    /// section 7; for line contact per unit length times the length (W/m without one).
    pub fn dissipated_power(&self, scene: &Scene, speed: f64) -> f64 {
        match self {
            Solution::Elliptic(e) => e.dissipated_power(speed),
            Solution::Line(l) => l.dissipated_power(speed) * scene.length().unwrap_or(1.0),
        }
    }
    /// Critical angle phi0 (rad), if any.
    pub fn critical_angle(&self) -> Option<f64> {
        match self {
            Solution::Elliptic(e) => e.critical_angle,
            Solution::Line(l) => l.critical_angle,
        }
    }
    /// Validity flags.
    pub fn validity(&self) -> Validity {
        match self {
            Solution::Elliptic(e) => e.validity,
            Solution::Line(l) => l.validity,
        }
    }
}

/// `d = min(d/b, 1) b` (m): 0 without slip even where b overflowed (0 x inf).
fn slip_width(slip_ratio: f64, b: f64) -> f64 {
    if slip_ratio == 0.0 {
        0.0
    } else {
        libm::fmin(slip_ratio, 1.0) * b
    }
}

fn check_sample(load: f64, phi: f64) -> Result<(), Error> {
    if !(load.is_finite() && load >= 0.0) {
        return Err(Error::Load);
    }
    // The angle between two axes is at most a right angle (theta = pi/2 at c = 1: m = n
    // = 1, crossed cylinders). Every f64 up to FRAC_PI_2, which lies below the true
    // pi/2, is accepted (NaN fails the compare).
    if phi.is_nan() || libm::fabs(phi) > FRAC_PI_2 {
        return Err(Error::Angle);
    }
    Ok(())
}

/// The ellipse's length over the rollers', 2a / length (section 9); `None` without a
/// length.
fn length_ratio(scene: &Scene, a: f64) -> Option<f64> {
    scene.length().map(|l| 2.0 * (a / l))
}

/// Whether line contact can answer any sample of `scene` under `choice`: forced, or
/// section 9's rule with a plane or a length. (A prepared core scene needs its line
/// constants only then.)
pub fn line_may_answer(scene: &Scene, choice: ModelChoice) -> bool {
    match choice {
        ModelChoice::Elliptic => false,
        ModelChoice::Line => true,
        ModelChoice::Section9 => scene.is_plane() || scene.length().is_some(),
    }
}

/// Whether `ratio` = 2a / length lies within [`MODEL_SWITCH_BAND`] of 1.
pub fn near_model_switch(ratio: f64) -> bool {
    (1.0 / MODEL_SWITCH_BAND..=MODEL_SWITCH_BAND).contains(&ratio)
}

/// `L^3 / P = 3 (1 - nu) R1 R2 / (2 G (R1 + R2))` (eqs 2-3 with the erratum).
pub fn hertz_volume(scene: &Scene) -> f64 {
    3.0 * (1.0 - scene.poisson_ratio()) * scene.effective_radius() / (2.0 * scene.shear_modulus())
}

/// The Hertz scale `v = (L^3/P)^(1/3)`, so that `L = v P^(1/3)` (eqs 2-3 with the
/// erratum), formed factor by factor so that no extreme but valid scene underflows.
pub fn hertz_scale(scene: &Scene) -> f64 {
    chain::chain(
        &[
            libm::cbrt(1.5 * (1.0 - scene.poisson_ratio())),
            libm::cbrt(scene.effective_radius()),
        ],
        &[libm::cbrt(scene.shear_modulus())],
    )
}

/// The phi (rad, >= 0) that gives auxiliary angle `theta` under the scene's relation.
fn phi_of_theta(scene: &Scene, theta: f64) -> f64 {
    let c = scene.radius_factor();
    match scene.theta_relation() {
        ThetaRelation::SmallAngle => theta / c,
        ThetaRelation::Exact => libm::asin(libm::fmin(libm::sin(theta) / c, 1.0)),
    }
}

/// Critical angle at `load`: the phi >= 0 with d/b = 1 (eq 15 = 1, i.e. eq 30
/// `phi0 = 2 mu p0 / G` with p0 at phi0). Returns `(phi0, theta0)`, or `None` when
/// d/b stays below 1 up to theta = pi/2 or up to phi = pi/2 (theta0 / c beyond pi/2
/// for unequal radii under eq 4): no angle between two axes reaches gross slip.
pub fn critical_angle(scene: &Scene, load: f64) -> Option<(f64, f64)> {
    angle_at_slip_ratio(scene, load, 1.0)
}

/// The phi >= 0 (and its theta) at which eq (16) gives the slip ratio `slip_ratio`
/// (> 0) at `load`; [`critical_angle`] is the case d/b = 1, the inverses of
/// [`inverse`] use the others. `None` when no theta <= pi/2 and phi <= pi/2 reaches it.
fn angle_at_slip_ratio(scene: &Scene, load: f64, slip_ratio: f64) -> Option<(f64, f64)> {
    if load == 0.0 {
        return Some((0.0, 0.0));
    }
    // d/b = s  <=>  m n |phi| = 3 mu s P^(1/3) / (pi G v^2) (eq 15), with G v^2 from
    // hertz_scale:
    // 3 mu / pi (P / (G h^2 R^2))^(1/3), h = 1.5 (1 - nu), one cube root.
    let h = 1.5 * (1.0 - scene.poisson_ratio());
    let r = scene.effective_radius();
    let target = chain::chain(
        &[
            3.0,
            scene.friction(),
            slip_ratio,
            chain::chain_cbrt(&[load], &[scene.shear_modulus(), h, h, r, r]),
        ],
        &[PI],
    );
    let c = scene.radius_factor();
    if c == 0.0 {
        return None; // a strip: no contact ellipse, no elliptic critical angle
    }
    if c * target < normal::small_theta_g_limit() {
        // theta0 < 1e-100: the asymptotics, where sin phi = phi exactly (both relations).
        let theta0 = normal::small_theta_for_g(c * target);
        return within_right_angle(theta0 / c, theta0);
    }
    let theta_max = match scene.theta_relation() {
        ThetaRelation::SmallAngle => FRAC_PI_2,
        ThetaRelation::Exact => libm::asin(c),
    };
    // theta = pi/2 is k' = 1 (tan^2(theta/2) = 1, eqs 5-6).
    let kprime_max = match scene.theta_relation() {
        ThetaRelation::SmallAngle => 1.0,
        ThetaRelation::Exact => normal::ellipse_shape(theta_max)?.kprime,
    };
    // d ln phi / d ln theta, and the curvature it adds (large where phi nears pi/2).
    let phi = |theta: f64| match scene.theta_relation() {
        ThetaRelation::SmallAngle => (theta / c, 1.0, 1.0),
        ThetaRelation::Exact => {
            let phi = phi_of_theta(scene, theta);
            let cos_phi = libm::cos(phi);
            let slope = theta * libm::cos(theta) / (c * cos_phi * phi);
            (phi, slope, 1.0 + 1.0 / (cos_phi * cos_phi))
        }
    };
    let seed = normal::seed_for_g(libm::fmin(target * c, FRAC_PI_2));
    let (_, theta0) =
        normal::kprime_for_mn_phi(target, phi, libm::fmin(seed, kprime_max), kprime_max)?;
    let theta0 = libm::fmin(theta0, theta_max);
    within_right_angle(phi_of_theta(scene, theta0), theta0)
}

/// `(phi, theta)` if phi is an angle between two axes (at most pi/2; FRAC_PI_2 lies
/// below it), else `None`: under eq (4) with unequal radii theta / c can exceed it.
fn within_right_angle(phi: f64, theta: f64) -> Option<(f64, f64)> {
    (phi <= FRAC_PI_2).then_some((phi, theta))
}

/// The elliptic solution (sections 5-7) for load `load` (N) and misalignment `phi`
/// (rad, signed). Zero angle gives the strip limit (a = inf, p0 = 0, d/b = 0, F = 0);
/// zero load gives a = b = p0 = F = 0, d/b = inf (gross slip), phi0 = 0.
///
/// # Errors
/// [`Error::Load`], [`Error::Angle`] for undefined input or |phi| above pi/2,
/// [`Error::PlaneHasNoEllipse`] for a plane.
pub fn elliptic(scene: &Scene, load: f64, phi: f64) -> Result<Elliptic, Error> {
    check_sample(load, phi)?;
    // c = 0: a plane, or radii so unequal that c underflows; the contact is a strip.
    if scene.is_plane() || scene.radius_factor() == 0.0 {
        return Err(Error::PlaneHasNoEllipse);
    }
    let theta = scene.auxiliary_angle(phi);
    let shape = normal::ellipse_shape(theta).ok_or(Error::Angle)?;
    let (g_mod, nu, mu) = (
        scene.shear_modulus(),
        scene.poisson_ratio(),
        scene.friction(),
    );
    let v = hertz_scale(scene);
    let (a, b) = normal::semi_axes(&shape, v, load);
    let p0 = normal::peak_pressure(&shape, v, load);
    let s = if load == 0.0 && phi != 0.0 {
        f64::INFINITY
    } else {
        tangential::slip_ratio(g_mod, mu, shape.mn(), v, load, phi)
    };
    let (r1, r2) = (scene.r1(), scene.r2());
    let pstar = tangential::nondimensional_load(load, nu, g_mod, r1, r2);
    let p0star = tangential::critical_nondimensional_load(shape.g(), mu);
    // P at which d/b = 1 for this phi: P0* scaled back by eq (17).
    let critical_load = chain::chain(
        &[
            p0star,
            1.0 - nu,
            1.0 - nu,
            g_mod,
            tangential::half_sum(r1, r2),
            libm::sqrt(r1),
            libm::sqrt(r2),
        ],
        &[],
    );
    let axial_force = libm::copysign(mu * (load * tangential::axial_force_ratio(s)), phi);
    let critical = critical_angle(scene, load);
    let ratio = length_ratio(scene, a);
    let validity = Validity {
        large_angle: libm::fabs(phi) > ANGLE_LIMIT || critical.is_none_or(|(p, _)| p > ANGLE_LIMIT),
        high_pressure: p0 / g_mod > PRESSURE_LIMIT,
        longer_than_rollers: ratio.is_some_and(|r| r > 1.0),
        near_model_switch: ratio.is_some_and(near_model_switch),
        // a/b = 1/k' (eqs 5-6).
        round_ellipse: shape.kprime * SLENDER_LIMIT > 1.0,
    };
    Ok(Elliptic {
        phi,
        load,
        shape,
        a,
        b,
        p0,
        pstar,
        p0star,
        slip_ratio: s,
        d: slip_width(s, b),
        regime: Regime::of(s),
        axial_force,
        critical_angle: critical.map(|c| c.0),
        critical_theta: critical.map(|c| c.1),
        critical_load,
        validity,
    })
}

impl Elliptic {
    /// Hertz pressure p(x, y) (Pa), eq (7).
    pub fn pressure(&self, x: f64, y: f64) -> f64 {
        normal::pressure(self.p0, self.a, self.b, x, y)
    }
    /// Axial traction X(x, y) (Pa), eqs (11), (13), (14); the friction comes from `scene`.
    pub fn traction(&self, scene: &Scene, x: f64, y: f64) -> f64 {
        tangential::elliptic_traction(
            libm::copysign(scene.friction() * self.p0, self.phi),
            self.a,
            self.b,
            self.d,
            x,
            y,
        )
    }
    /// The stick zone `(y_min, y_max)` at axial position x (m), if any.
    pub fn stick_zone(&self, x: f64) -> Option<(f64, f64)> {
        tangential::elliptic_stick_zone(self.a, self.b, self.d, x)
    }
    /// Component `F phi / 2` (N) of the axial force opposing the rolling of each cylinder (section 7).
    pub fn rolling_resistance(&self) -> f64 {
        0.5 * self.axial_force * self.phi
    }
    /// Power `F phi V` (W) dissipated by microslip at rolling speed `speed` (m/s), section 7.
    pub fn dissipated_power(&self, speed: f64) -> f64 {
        self.axial_force * self.phi * speed
    }
}

/// The line-contact solution (section 8) for load per unit length `load` (N/m) and
/// misalignment `phi` (rad), with R1 for a plane and eq (31) for two rollers.
/// Zero angle: d/b = 0, F = 0. Zero load: b = p0 = F = phi0 = 0, d/b = inf.
///
/// # Errors
/// [`Error::Load`], [`Error::Angle`] for undefined input or |phi| above pi/2.
pub fn line(scene: &Scene, load: f64, phi: f64) -> Result<Line, Error> {
    check_sample(load, phi)?;
    let (g_mod, nu, mu) = (
        scene.shear_modulus(),
        scene.poisson_ratio(),
        scene.friction(),
    );
    let radius = scene.effective_radius();
    let b = line::half_width(load, nu, g_mod, radius);
    let p0 = line::peak_pressure(load, nu, g_mod, radius);
    let s = if load == 0.0 && phi != 0.0 {
        f64::INFINITY
    } else {
        line::slip_ratio(load, nu, g_mod, radius, mu, phi)
    };
    let p0star = line::critical_nondimensional_load(phi, mu);
    let critical_angle =
        Some(line::critical_angle(load, nu, g_mod, radius, mu)).filter(|&p| p <= FRAC_PI_2);
    Ok(Line {
        phi,
        load,
        radius,
        b,
        p0,
        pstar: line::nondimensional_load(load, nu, g_mod, radius),
        p0star,
        slip_ratio: s,
        d: slip_width(s, b),
        regime: Regime::of(s),
        axial_force: libm::copysign(mu * (load * line::axial_force_ratio(s)), phi),
        critical_angle,
        critical_load: chain::chain(&[p0star, 1.0 - nu, g_mod, radius], &[]),
        validity: Validity {
            large_angle: libm::fabs(phi) > ANGLE_LIMIT
                || critical_angle.is_none_or(|p| p > ANGLE_LIMIT),
            high_pressure: p0 / g_mod > PRESSURE_LIMIT,
            longer_than_rollers: false,
            near_model_switch: false,
            round_ellipse: false,
        },
    })
}

impl Line {
    /// Axial traction X(y) (Pa) across the strip, eq (26); friction from `scene`.
    pub fn traction(&self, scene: &Scene, y: f64) -> f64 {
        line::traction(
            libm::copysign(scene.friction() * self.p0, self.phi),
            self.b,
            self.d,
            y,
        )
    }
    /// Component `F phi / 2` (N/m) of the axial force per unit length opposing the
    /// rolling of each cylinder (section 7, applied to the strip of section 8).
    pub fn rolling_resistance(&self) -> f64 {
        0.5 * self.axial_force * self.phi
    }
    /// Power `F phi V` per unit length (W/m) dissipated by microslip at rolling speed
    /// `speed` (m/s), section 7 applied to the strip of section 8.
    pub fn dissipated_power(&self, speed: f64) -> f64 {
        self.axial_force * self.phi * speed
    }
    /// Stick zone `(y_min, y_max) = (2d - b, b)`, or `None` in gross slip.
    pub fn stick_zone(&self) -> Option<(f64, f64)> {
        if self.b > self.d {
            Some((2.0 * self.d - self.b, self.b))
        } else {
            None
        }
    }
}

/// The paper's model choice (section 9), per sample: the elliptic solution, unless
/// body 2 is a plane or the scene has a contact length and the ellipse is longer than
/// it (2a > length), in which case the line solution with the load per unit length
/// `P / length`. P is the total load (N) when the scene has a length; a plane without
/// a length reads P as N/m. The result's flags say when 2a / length is near 1
/// ([`MODEL_SWITCH_BAND`]), where the two models differ by a jump.
///
/// # Errors
/// As [`elliptic`] and [`line()`].
pub fn estimate(scene: &Scene, load: f64, phi: f64) -> Result<Solution, Error> {
    estimate_with(scene, load, phi, ModelChoice::Section9)
}

/// [`estimate`] with the model chosen by `choice`: section 9's rule, or one model
/// forced, with the same meaning of P (total load with a length; per unit length in
/// line contact without one).
///
/// # Errors
/// As [`elliptic`] and [`line()`]; [`Error::PlaneHasNoEllipse`] for a plane forced to
/// the ellipse.
pub fn estimate_with(
    scene: &Scene,
    load: f64,
    phi: f64,
    choice: ModelChoice,
) -> Result<Solution, Error> {
    check_sample(load, phi)?;
    if choice == ModelChoice::Elliptic {
        return elliptic(scene, load, phi).map(Solution::Elliptic);
    }
    // A plane, or radii so unequal that c underflows, has a strip for every phi (no
    // ellipse); forced line contact without a length needs no ellipse either.
    let ellipse = if choice == ModelChoice::Line && scene.length().is_none() {
        None
    } else {
        elliptic(scene, load, phi).ok()
    };
    if let Some(e) = ellipse
        && choice == ModelChoice::Section9
        && !e.validity.longer_than_rollers
    {
        return Ok(Solution::Elliptic(e));
    }
    let per_length = load / scene.length().unwrap_or(1.0);
    let mut l = line(scene, per_length, phi)?;
    l.validity.near_model_switch = ellipse.is_some_and(|e| e.validity.near_model_switch);
    Ok(Solution::Line(l))
}
