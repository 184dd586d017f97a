//! One installation: the two rollers' radii, their contact length, the material and
//! the friction. Built once and validated; samples (load, angle) come per reading.

use crate::Error;

/// The peak contact pressure, as a fraction of the shear modulus G, at which a roller
/// length must still hold section 8's contact strip ([`Scene::shortest_length`]):
/// 0.8 MPa in steel, a five-hundredth of the paper's example (p0 / G = 0.005).
pub const SHORT_ROLLER_PRESSURE: f64 = 1e-5;

/// How the auxiliary angle theta follows from the misalignment phi.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ThetaRelation {
    /// The paper's eq (4): `theta = 2 |phi| sqrt(R1 R2) / (R1 + R2)`. Default; the
    /// reference data use it.
    #[default]
    SmallAngle,
    /// The exact crossed-cylinder relation
    /// `sin(theta) = 2 sqrt(R1 R2) sin|phi| / (R1 + R2)`; it equals eq (4) for
    /// R1 = R2 and differs by `(1 - c^2) phi^2 / 6` otherwise.
    Exact,
}

/// A validated installation, in SI units. Same elastic material for both bodies,
/// as the paper assumes.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Scene {
    r1: f64,
    r2: f64,
    length: Option<f64>,
    shear_modulus: f64,
    poisson_ratio: f64,
    friction: f64,
    theta_relation: ThetaRelation,
}

impl Scene {
    /// The demo installation of this crate's examples, firmware, benchmarks, figures
    /// and tests: two steel printing-press rollers, R1 = R2 = 50 mm, G = 79.3 GPa,
    /// nu = 0.3, mu = 0.3, no length (elliptic contact). A valid scene: it is what
    /// [`Scene::new`] makes of these values.
    pub const DEMO: Scene = Scene {
        r1: 0.05,
        r2: 0.05,
        length: None,
        shear_modulus: 79.3e9,
        poisson_ratio: 0.3,
        friction: 0.3,
        theta_relation: ThetaRelation::SmallAngle,
    };

    /// A scene of two rollers of radii `r1`, `r2` (m; `r2 = f64::INFINITY` is a plane),
    /// shear modulus `shear_modulus` G (Pa), Poisson's ratio `poisson_ratio` nu and
    /// friction coefficient `friction` mu.
    ///
    /// # Errors
    /// A typed [`Error`] for non-finite or non-positive radii or modulus, nu outside
    /// [0, 0.5] (only 1 - nu enters the paper's equations, so incompressible rollers,
    /// nu = 0.5, are fine), or mu not finite and positive; [`Error::Radius`] also for radii
    /// whose effective radius R1 R2 / (R1 + R2) (eq 31) is below the smallest f64 (both
    /// radii under 1e-323 m), where every model would divide by 0.
    pub fn new(
        r1: f64,
        r2: f64,
        shear_modulus: f64,
        poisson_ratio: f64,
        friction: f64,
    ) -> Result<Self, Error> {
        if !(r1.is_finite() && r1 > 0.0) || r2.is_nan() || r2 <= 0.0 {
            return Err(Error::Radius);
        }
        let scene = Self {
            r1,
            r2,
            length: None,
            shear_modulus,
            poisson_ratio,
            friction,
            theta_relation: ThetaRelation::SmallAngle,
        };
        if scene.effective_radius() == 0.0 {
            return Err(Error::Radius);
        }
        if !(shear_modulus.is_finite() && shear_modulus > 0.0) {
            return Err(Error::ShearModulus);
        }
        if !(0.0..=0.5).contains(&poisson_ratio) {
            return Err(Error::PoissonRatio);
        }
        if !(friction.is_finite() && friction > 0.0) {
            return Err(Error::Friction);
        }
        Ok(scene)
    }

    /// Whether [`Scene::new`] accepts two rollers of radii `r1`, `r2` (both finite: no
    /// plane), G, nu and mu, and [`Scene::with_length`] then `length` (if any): the same
    /// rules without a branch, for a scene per row in SIMD lanes (the batch's); the
    /// row's error, where not, comes from [`Scene::new`].
    #[inline(always)]
    pub(crate) fn accepts_rollers(
        r1: f64,
        r2: f64,
        shear_modulus: f64,
        poisson_ratio: f64,
        friction: f64,
        length: Option<f64>,
    ) -> bool {
        let positive_finite = |x: f64| (x > 0.0) & (x < f64::INFINITY);
        let (small, large) = (r1.min(r2), r1.max(r2));
        let radius = small / (1.0 + small / large);
        let rollers = positive_finite(r1)
            & positive_finite(r2)
            & (radius != 0.0)
            & positive_finite(shear_modulus)
            & (0.0..=0.5).contains(&poisson_ratio)
            & positive_finite(friction);
        match length {
            None => rollers,
            Some(l) => {
                let shortest = 2.0 * (1.0 - poisson_ratio) * radius * SHORT_ROLLER_PRESSURE;
                rollers & positive_finite(l) & (l >= shortest)
            }
        }
    }

    /// The same scene with the rollers' contact length (m), which lets the model
    /// choice of section 9 switch to line contact when the ellipse is longer.
    ///
    /// # Errors
    /// [`Error::Length`] unless `length` is finite and positive;
    /// [`Error::LengthTooShort`] for a length below [`Scene::shortest_length`], at which
    /// the contact is wider than the rollers are long at every working load (a length
    /// in the wrong unit, say).
    pub fn with_length(mut self, length: f64) -> Result<Self, Error> {
        if !(length.is_finite() && length > 0.0) {
            return Err(Error::Length);
        }
        if length < self.shortest_length() {
            return Err(Error::LengthTooShort);
        }
        self.length = Some(length);
        Ok(self)
    }

    /// The shortest contact length (m) [`Scene::with_length`] accepts,
    /// `2 (1 - nu) R x` [`SHORT_ROLLER_PRESSURE`] with R of eq (31): the half-width b
    /// of section 8's strip, `b / R = 2 (1 - nu) p0 / G` (eq 22 with p0 = 2 P / (pi b)),
    /// reaches it at a peak pressure of `SHORT_ROLLER_PRESSURE x G`. Shorter rollers
    /// are narrower than their contact at every working load; docs/physics.md derives
    /// it.
    pub fn shortest_length(&self) -> f64 {
        2.0 * (1.0 - self.poisson_ratio) * self.effective_radius() * SHORT_ROLLER_PRESSURE
    }

    /// The same scene with another theta(phi) relation.
    pub fn with_theta_relation(mut self, relation: ThetaRelation) -> Self {
        self.theta_relation = relation;
        self
    }

    /// Radius R1 (m).
    pub const fn r1(&self) -> f64 {
        self.r1
    }
    /// Radius R2 (m); infinite for a plane.
    pub const fn r2(&self) -> f64 {
        self.r2
    }
    /// Contact length of the rollers (m), if given.
    pub const fn length(&self) -> Option<f64> {
        self.length
    }
    /// Shear modulus G (Pa).
    pub const fn shear_modulus(&self) -> f64 {
        self.shear_modulus
    }
    /// Poisson's ratio nu.
    pub const fn poisson_ratio(&self) -> f64 {
        self.poisson_ratio
    }
    /// Friction coefficient mu.
    pub const fn friction(&self) -> f64 {
        self.friction
    }
    /// The theta(phi) relation in use.
    pub const fn theta_relation(&self) -> ThetaRelation {
        self.theta_relation
    }
    /// True when body 2 is a plane (R2 = infinity).
    pub const fn is_plane(&self) -> bool {
        self.r2.is_infinite()
    }

    /// Effective radius `R = R1 R2 / (R1 + R2)` (eq 31); R1 for a plane. Formed as
    /// `small / (1 + small/large)`, which does not overflow; it is never 0, since
    /// [`Scene::new`] refuses radii whose R is below the smallest subnormal f64.
    pub fn effective_radius(&self) -> f64 {
        let (small, large) = if self.r1 <= self.r2 {
            (self.r1, self.r2)
        } else {
            (self.r2, self.r1)
        };
        small / (1.0 + small / large)
    }

    /// `c = 2 sqrt(R1 R2) / (R1 + R2)` of eq (4), so that `theta = c phi`; 0 for a plane.
    /// Formed as `2 q / (1 + q^2)`, `q = sqrt(R_small / R_large) <= 1`, which stays
    /// finite and exact to a few ulps for any pair of radii.
    pub fn radius_factor(&self) -> f64 {
        let (small, large) = if self.r1 <= self.r2 {
            (self.r1, self.r2)
        } else {
            (self.r2, self.r1)
        };
        let q = libm::sqrt(small / large);
        2.0 * q / (1.0 + q * q)
    }

    /// The auxiliary angle theta (rad) for a misalignment `phi` (rad), by the scene's
    /// [`ThetaRelation`]; depends on |phi| only.
    pub fn auxiliary_angle(&self, phi: f64) -> f64 {
        let c = self.radius_factor();
        match self.theta_relation {
            ThetaRelation::SmallAngle => c * libm::fabs(phi),
            ThetaRelation::Exact => libm::asin(c * libm::sin(libm::fabs(phi))),
        }
    }
}
