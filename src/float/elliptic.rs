//! The elliptic contact (paper sections 5-7) in f32.

use super::kernels::axial_force::axial_force_partial;
use super::kernels::cbrt::{cbrt, cbrt_cold, cbrt_hot, cbrt_normal};
use super::kernels::small_theta;
use super::kernels::theta_top::theta_of_g_top;
use super::octave::{OctaveTable, WIDE};
use super::tables;
use super::{DEFAULT_RISK_SLIP_RATIO, Estimate, check};
use crate::estimator::check_risk;
use crate::prepared::{
    Kind, PreparedError, Reader, Writer, positive_finite, positive_normal, seal, value,
};
use crate::reference::{Regime, hertz_scale};
use crate::{Error, Scene, ThetaRelation};
use core::f32::consts::{FRAC_PI_2, PI};

/// Below these (theta for g, 1/m; g for theta(g)) the small-theta asymptotics take over
/// from the tables: exact to the float's last few bits there (their own error falls
/// like theta^2).
const SMALL_THETA: f32 = 2.328_306_4e-10; // 2^-32, the g table's first octave
const SMALL_THETA_INV_M: f32 = 9.094_947e-13; // 2^-40, the 1/m table's
const SMALL_G: f32 = 7.450_581e-9; // 2^-27
/// c below this: the radii differ by more than 1e24, theta never leaves the asymptotic
/// range and theta0 would underflow f32 while phi0 does not.
pub(super) const MIN_RADIUS_FACTOR: f32 = 9.094_947e-13; // 2^-40
/// Loads outside [2^-120, 2^120) N take the cold path: zero, or a cube root that must
/// scale. As bits: the lower end and the width of the range (both immediates of one
/// Thumb-2 instruction).
const LIGHT_LOAD_BITS: u32 = 0x0380_0000; // 2^-120
const NORMAL_LOAD_SPAN: u32 = 0x7b80_0000 - 0x0380_0000; // up to 2^120
/// The hot path takes g0^3 = B^3 P in [2^-81, 1/2): g0 in [2^-27, 0.8), on the
/// inverse table below its top octave. As bits: the lower end and the width (both, and
/// the upper end, immediates of one Thumb-2 instruction).
const HOT_CUBE_LOW_BITS: u32 = 0x1700_0000; // 2^-81
const HOT_CUBE_SPAN: u32 = 0x3f00_0000 - 0x1700_0000; // up to 1/2
/// B^3 of the hot path: from 2^-120 (B^3 P < 1/2 means P < 2^119) to 2^39 (B^3 P >= 2^-81
/// means P >= 2^-120).
pub(super) const HOT_GAIN_MIN: f32 = 7.523_164e-37; // 2^-120
pub(super) const HOT_GAIN_MAX: f32 = 549_755_813_888.0; // 2^39

/// The smallest c (eq 4) whose scene takes the hot path, rounded up to f32 (a test
/// holds it to `theta(cbrt(1/2)) / (pi/2)` of the reference, plus 1e-4 for the
/// tables' error): the hot path's largest theta0 (g0 below cbrt(1/2)) is 0.632 rad,
/// so its phi0 = theta0 / c stays at most pi/2 from this c up. Scenes of smaller c
/// (radii more than 22 times apart) take the general path, which says `None` where
/// phi0 would pass pi/2; so the hot path needs no check of its own.
pub(super) const HOT_MIN_RADIUS_FACTOR: f32 = 0.402_505_9;

/// `2^31 - bits(threshold)` for a positive finite threshold.
fn risk_offset(threshold: f32) -> u32 {
    0x8000_0000u32.wrapping_sub(threshold.to_bits())
}

/// `B^3` if the hot path takes it, else 0.
fn hot_gain(cubed: f32) -> f32 {
    if (HOT_GAIN_MIN..=HOT_GAIN_MAX).contains(&cubed) {
        cubed
    } else {
        0.0
    }
}
/// mu at and above which F = mu P could overflow f32 at a load of 2^120 N (the hot
/// path's heaviest): mu P < 2^127 below it.
pub(super) const FRICTION_LIMIT: f64 = 128.0;
/// The largest slip gain A that preparing accepts, rounded up to f32 (a test holds it
/// to `f32::MAX / 2 x cbrt(2^-149) / (pi/2)`): d/b at the lightest load fits f32.
const SLIP_GAIN_LIMIT: f32 = 1.212_09e23;

/// The tables one elliptic scene reads per sample: g(theta) (eqs 5, 6, 16) and its
/// inverse (eq 18). [`Tables::FULL`] covers theta from 0 to pi/2; a firmware whose
/// scene declares a narrower range of misalignment can pass narrower ones (built at
/// compile time with [`super::octave::narrow_rows`]) and link only those rows.
#[derive(Debug, Clone, Copy)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Tables<'a> {
    /// g(theta) = m n theta.
    pub g: OctaveTable<'a, WIDE>,
    /// theta(g), the inverse of g, in wide segments.
    pub theta_of_g: OctaveTable<'a, WIDE>,
}

impl Tables<'static> {
    /// The generated tables over the whole range, theta from 0 to pi/2.
    pub const FULL: Tables<'static> = Tables {
        g: tables::G_OF_THETA,
        theta_of_g: tables::THETA_OF_G,
    };
}

/// What an estimate is finished from: d/b, `+-mu P` with the sign of phi (the axial
/// force in gross slip), phi0.
#[derive(Clone, Copy)]
pub(super) struct Parts {
    pub(super) slip_ratio: f32,
    pub(super) signed_limit: f32,
    pub(super) critical_angle: Option<f32>,
}

/// Whether a sample is outside the hot path's range, |phi| <= 1 and B^3 P = `w` in
/// [2^-81, 1/2): on the bits, each one unsigned compare with an immediate. |phi| > 1
/// includes inf and NaN, whose patterns lie above; B^3 P outside the range includes a
/// load that is 0, negative, NaN or inf. Stated as the test that fails: `x > 1.0`'s
/// bound is an immediate of Thumb-2, while the compiler forms `x <= 1.0` as `x <` the
/// next pattern, which is not (three instructions more on the Cortex-M4F).
#[inline(always)]
pub(super) fn off_hot_range(abs_phi: f32, w: f32) -> bool {
    abs_phi.to_bits() > 1.0f32.to_bits()
        || w.to_bits().wrapping_sub(HOT_CUBE_LOW_BITS) >= HOT_CUBE_SPAN
}

/// A prepared elliptic-contact scene: the per-sample constants of eqs (4), (16), (18).
#[derive(Debug, Clone, Copy)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct EllipticScene<'t> {
    /// `c = 2 sqrt(R1 R2) / (R1 + R2)` (eq 4): theta = c |phi|.
    pub(super) radius_factor: f32,
    /// `1 / c`.
    pub(super) inv_radius_factor: f32,
    /// `A = pi G V^(2/3) / (3 mu c)`: d/b = A g(theta) P^(-1/3) (eq 16), V = L^3/P.
    pub(super) slip_gain: f32,
    /// `1 / A`: at d/b = 1, g(theta0) = P^(1/3) / A (eq 18).
    pub(super) critical_gain: f32,
    /// Friction coefficient mu.
    pub(super) friction: f32,
    /// `V^(1/3)`: L = V^(1/3) P^(1/3) (eqs 2, 3).
    hertz_gain: f32,
    /// d/b at and above which the risk flag is raised.
    risk_slip_ratio: f32,
    /// `2^31 - bits(risk_slip_ratio)`: d/b at or above the threshold sets bit 31 of
    /// `bits(d/b) + risk_offset` (both below 2^31 as bits).
    risk_offset: u32,
    /// `B^3 = 1/A^3` for the hot path, where g0 = (B^3 P)^(1/3) (eq 18); 0 (no hot
    /// path) when B^3 lies outside [2^-120, 2^39], so that B^3 P in the hot path's range
    /// [2^-81, 1/2) means a load in [2^-120, 2^119), or when c is below
    /// `HOT_MIN_RADIUS_FACTOR`.
    pub(super) cubed_critical_gain: f32,
    pub(super) tables: Tables<'t>,
}

impl EllipticScene<'static> {
    /// Prepares `scene` with the full tables.
    ///
    /// # Errors
    /// [`Error::PlaneHasNoEllipse`] for a plane, [`Error::Unsupported`] for the exact
    /// theta relation (the cores implement eq 4), [`Error::OutOfRange`] if a constant
    /// does not fit in f32, the radii differ by more than 1e24 (c < 2^-40), mu is 128
    /// or more (F = mu P would overflow f32 at ordinary loads), or d/b would overflow
    /// f32 at the lightest load (A g / P^(1/3) above f32::MAX, eq 16).
    pub fn new(scene: &Scene) -> Result<Self, Error> {
        Self::with_tables(scene, Tables::FULL)
    }
}

impl<'t> EllipticScene<'t> {
    /// Prepares `scene` with the given tables (see [`Tables`]).
    ///
    /// # Errors
    /// As [`EllipticScene::new`].
    pub fn with_tables(scene: &Scene, tables: Tables<'t>) -> Result<Self, Error> {
        if scene.is_plane() {
            return Err(Error::PlaneHasNoEllipse);
        }
        if scene.theta_relation() != ThetaRelation::SmallAngle {
            return Err(Error::Unsupported);
        }
        let c = scene.radius_factor();
        if c < MIN_RADIUS_FACTOR as f64 {
            return Err(Error::OutOfRange);
        }
        let v = hertz_scale(scene);
        let slip_gain =
            core::f64::consts::PI * scene.shear_modulus() * v * v / (3.0 * scene.friction() * c);
        // mu P < 2^127 for every load of the hot path (up to 2^120 N); heavier loads are
        // checked per sample. d/b = A g P^(-1/3) <= A (pi/2) / cbrt(2^-149) must fit,
        // with a factor 2 for the tables' and the cube root's rounding.
        let lightest_cbrt = libm::cbrt(f32::from_bits(1) as f64);
        if scene.friction() >= FRICTION_LIMIT
            || slip_gain * core::f64::consts::FRAC_PI_2 / lightest_cbrt > f32::MAX as f64 / 2.0
        {
            return Err(Error::OutOfRange);
        }
        let constants = [c, 1.0 / c, slip_gain, 1.0 / slip_gain, scene.friction(), v];
        let mut f = [0.0f32; 6];
        for (out, x) in f.iter_mut().zip(constants) {
            *out = x as f32;
            if !(out.is_normal() && *out > 0.0) {
                return Err(Error::OutOfRange);
            }
        }
        Ok(EllipticScene {
            radius_factor: f[0],
            inv_radius_factor: f[1],
            slip_gain: f[2],
            critical_gain: f[3],
            friction: f[4],
            hertz_gain: f[5],
            risk_slip_ratio: DEFAULT_RISK_SLIP_RATIO,
            risk_offset: risk_offset(DEFAULT_RISK_SLIP_RATIO),
            cubed_critical_gain: if f[0] >= HOT_MIN_RADIUS_FACTOR {
                hot_gain((1.0 / (slip_gain * slip_gain * slip_gain)) as f32)
            } else {
                0.0
            },
            tables,
        })
    }

    /// The same scene with another d/b threshold for [`Estimate::microslip_risk`].
    ///
    /// # Errors
    /// [`Error::OutOfRange`] for a threshold that is not positive and finite.
    pub fn with_risk_slip_ratio(mut self, slip_ratio: f32) -> Result<Self, Error> {
        self.risk_slip_ratio = check_risk(slip_ratio)?;
        self.risk_offset = risk_offset(self.risk_slip_ratio);
        Ok(self)
    }

    /// The d/b threshold of [`Estimate::microslip_risk`].
    pub fn risk_slip_ratio(&self) -> f32 {
        self.risk_slip_ratio
    }

    /// The estimate for load `load` (N) and misalignment `phi` (rad, signed).
    /// Zero angle: d/b = 0, F = 0. Zero load: d/b = +inf (gross slip), F = 0, phi0 = 0.
    ///
    /// # Errors
    /// [`Error::Load`] for a NaN, infinite or negative load; [`Error::Angle`] for a
    /// non-finite angle or |phi| above pi/2; [`Error::OutOfRange`] for a theta below
    /// narrowed tables, a load above 2^120 N whose mu P overflows f32, or a load so
    /// light that phi0 would underflow f32 (below its smallest normal value).
    #[inline(always)]
    pub fn estimate(&self, load: f32, phi: f32) -> Result<Estimate, Error> {
        let abs_phi = phi.abs();
        let parts = match self.hot_parts(load, phi, abs_phi) {
            Some(parts) => parts,
            None => self.general_parts(load, phi)?,
        };
        Ok(self.finish(parts, abs_phi))
    }

    /// The hot path: |phi| <= 1, B^3 P in [2^-81, 1/2) (so g0 in [2^-27, 0.8) and the
    /// load in [2^-120, 2^119) N), theta on the tables; `None` for everything else (bad
    /// input, zero, the asymptotics, no critical angle, the edges), which
    /// `general_parts` answers the same.
    #[inline(always)]
    fn hot_parts(&self, load: f32, phi: f32, abs_phi: f32) -> Option<Parts> {
        let w = self.cubed_critical_gain * load; // g0^3 (eq 18 at d/b = 1)
        if off_hot_range(abs_phi, w) {
            return None;
        }
        let theta = self.radius_factor * abs_phi;
        let g = self.tables.g.eval(theta)?;
        let g0 = cbrt_hot(w);
        let theta0 = self.tables.theta_of_g.eval(g0)?;
        Some(Parts {
            // eq (16) as d/b = g / g0 (A = 1/B).
            slip_ratio: g / g0,
            // theta >= 2^-32 here, so phi is not 0: phi / |phi| is its sign, exactly.
            signed_limit: self.friction * load * (phi / abs_phi),
            critical_angle: Some(theta0 * self.inv_radius_factor),
        })
    }

    /// The estimate from its parts: the axial force of eq (21) (F <= mu P), the regime
    /// and the risk flag, on the bits (d/b is positive or zero and not NaN, the
    /// threshold positive and finite: their order is that of their bits).
    #[inline(always)]
    pub(super) fn finish(&self, parts: Parts, abs_phi: f32) -> Estimate {
        let Parts {
            slip_ratio: s,
            signed_limit,
            critical_angle,
        } = parts;
        let bits = s.to_bits();
        // d/b >= 1: bit 31 of bits + 2^31 - bits(1) (d/b <= +inf: no wrap-around).
        let gross = bits.wrapping_add(0x8000_0000 - 1.0f32.to_bits()) >> 31;
        let (force, regime) = if gross == 0 {
            (axial_force_partial(signed_limit, s), Regime::Partial)
        } else {
            (signed_limit, Regime::Gross)
        };
        Estimate {
            slip_ratio: s,
            regime,
            axial_force: force,
            critical_angle,
            margin: critical_angle.map(|c| c - abs_phi),
            microslip_risk: bits.wrapping_add(self.risk_offset) >> 31 != 0,
        }
    }

    /// The parts of [`EllipticScene::estimate`] for every sample: the checks, zero load
    /// and angle, the asymptotics below the tables, phi0 where there is none.
    #[cold]
    #[inline(never)]
    fn general_parts(&self, load: f32, phi: f32) -> Result<Parts, Error> {
        let abs_phi = phi.abs();
        // f32's nearest pi/2 (above the true pi/2 by 4e-8) stands for pi/2: the
        // rounding of f64's, accepted by the reference.
        if abs_phi.to_bits() > FRAC_PI_2.to_bits() {
            return Err(Error::Angle);
        }
        let theta = self.radius_factor * abs_phi;
        let cbrt_load = if load.to_bits().wrapping_sub(LIGHT_LOAD_BITS) >= NORMAL_LOAD_SPAN {
            match self.extreme_load(load, phi, theta)? {
                Ok(cbrt_load) => cbrt_load,
                Err(zero_load) => return Ok(zero_load),
            }
        } else {
            cbrt_normal(load)
        };
        let g = self.g_of_theta(theta)?;
        let g0 = self.critical_g(load);
        // eq (16): d/b = g / g0 as the hot path has it, or A g / P^(1/3) where g0 is
        // not normal (a light load on a scene of large A: d/b still fits f32).
        let slip_ratio = if g0.is_normal() {
            g / g0
        } else {
            self.slip_gain * g / cbrt_load
        };
        Ok(Parts {
            slip_ratio,
            // mu P is finite: `extreme_load` refused the loads where it is not.
            signed_limit: (self.friction * load).copysign(phi),
            critical_angle: self.critical_angle_of(g0)?,
        })
    }

    /// phi0 = theta0 / c (eqs 4, 18) for g0 = g(theta0); `None` where no theta <= pi/2
    /// reaches g0, or where phi0 would pass pi/2 (f32's pi/2, which stands for it):
    /// no angle between two axes reaches gross slip.
    #[inline]
    pub(super) fn critical_angle_of(&self, g0: f32) -> Result<Option<f32>, Error> {
        Ok(self
            .theta_of_g(g0)?
            .map(|t| t * self.inv_radius_factor)
            .filter(|phi0| phi0.to_bits() <= FRAC_PI_2.to_bits()))
    }

    /// g0 = g(theta0) at load `load` (eq 18 at d/b = 1) for a load 0 or above:
    /// (B^3 P)^(1/3) as the hot path has it where B^3 P is in its range, else
    /// B P^(1/3).
    #[inline]
    pub(super) fn critical_g(&self, load: f32) -> f32 {
        let w = self.cubed_critical_gain * load;
        if w.to_bits().wrapping_sub(HOT_CUBE_LOW_BITS) < HOT_CUBE_SPAN {
            cbrt_hot(w)
        } else {
            self.critical_gain * cbrt_cold(load)
        }
    }

    /// Loads outside [2^-120, 2^120) N: bad input (a typed error), zero load (an
    /// unloaded contact slips wherever it is misaligned: d/b = inf, F = 0, phi0 = 0, the
    /// parts in `Ok(Err(..))`), a load whose mu P overflows f32 (a typed error: F would
    /// be infinite), or a cube root that must scale (`Ok(Ok(..))`).
    #[cold]
    #[inline(never)]
    fn extreme_load(&self, load: f32, phi: f32, theta: f32) -> Result<Result<f32, Parts>, Error> {
        check(load, phi)?;
        if load == 0.0 {
            return Ok(Err(Parts {
                slip_ratio: if theta == 0.0 { 0.0 } else { f32::INFINITY },
                signed_limit: 0.0,
                critical_angle: Some(0.0),
            }));
        }
        // F <= mu P (eq 21) fits f32 when mu P does.
        if (self.friction * load).to_bits() >= f32::INFINITY.to_bits() {
            return Err(Error::OutOfRange);
        }
        Ok(Ok(cbrt_cold(load)))
    }

    #[inline(always)]
    pub(super) fn g_of_theta(&self, theta: f32) -> Result<f32, Error> {
        match self.tables.g.eval(theta) {
            Some(g) => Ok(g),
            None => self.g_outside(theta),
        }
    }

    #[cold]
    #[inline(never)]
    fn g_outside(&self, theta: f32) -> Result<f32, Error> {
        if theta == 0.0 {
            Ok(0.0)
        } else if theta < self.tables.g.lower() && self.tables.g.lower() <= SMALL_THETA {
            Ok(small_theta::g_small(theta))
        } else {
            Err(Error::OutOfRange)
        }
    }

    /// theta0 with g(theta0) = g; `Ok(None)` above g(pi/2) = pi/2 (no critical angle).
    #[inline(always)]
    pub(super) fn theta_of_g(&self, g: f32) -> Result<Option<f32>, Error> {
        if g.to_bits() > FRAC_PI_2.to_bits() {
            return Ok(None);
        }
        match self.tables.theta_of_g.eval(g) {
            // The top octave from its own, finer table.
            Some(_) if g.to_bits() >= 1.0f32.to_bits() => Ok(Some(theta_of_g_top(g))),
            Some(t) => Ok(Some(t)),
            None => self.theta_outside(g).map(Some),
        }
    }

    /// Below the inverse table: the asymptotics, or [`Error::OutOfRange`] where theta0
    /// (and so phi0 = theta0 / c) would underflow f32's normal range at a load above 0.
    #[cold]
    #[inline(never)]
    fn theta_outside(&self, g: f32) -> Result<f32, Error> {
        if g == 0.0 {
            return Ok(0.0);
        }
        if g < self.tables.theta_of_g.lower() && self.tables.theta_of_g.lower() <= SMALL_G {
            let theta = small_theta::theta_small(g);
            if theta >= f32::MIN_POSITIVE {
                return Ok(theta);
            }
        }
        Err(Error::OutOfRange)
    }

    /// 2a / length for a checked sample (load finite and >= 0, |phi| <= pi/2), with
    /// `two_over_length` = 2 / length (1/m): section 9's measure, from a = m L (eqs 2,
    /// 5-6) with 1/m from its table. 0 at zero load, +inf at zero angle.
    #[inline]
    pub(super) fn length_ratio(&self, load: f32, phi: f32, two_over_length: f32) -> f32 {
        if load == 0.0 {
            return 0.0;
        }
        let theta = self.radius_factor * phi.abs();
        let inv_m = match tables::INV_M_OF_THETA.eval(theta) {
            Some(x) => x,
            None if theta == 0.0 => return f32::INFINITY, // the strip limit: a = inf
            None if theta < SMALL_THETA_INV_M => small_theta::inv_m_small(theta),
            None => 1.0, // not reached: the table covers theta up to pi/2
        };
        // 2 m V^(1/3) P^(1/3) / length; inf / 0 cannot occur (P > 0).
        two_over_length * self.hertz_gain * cbrt(load) / inv_m
    }

    /// The contact ellipse on request: m, n (eqs 5-6), a, b (eqs 2-3), p0 (eq 7).
    ///
    /// # Errors
    /// As [`EllipticScene::estimate`].
    pub fn details(&self, load: f32, phi: f32) -> Result<Details, Error> {
        check(load, phi)?;
        if phi.abs() > FRAC_PI_2 {
            return Err(Error::Angle);
        }
        let theta = self.radius_factor * phi.abs();
        if theta == 0.0 {
            // The strip limit: an infinitely long ellipse of zero width.
            return Ok(Details {
                theta,
                m: f32::INFINITY,
                n: 0.0,
                a: f32::INFINITY,
                b: 0.0,
                p0: 0.0,
            });
        }
        let g = self.g_of_theta(theta)?;
        let inv_m = match tables::INV_M_OF_THETA.eval(theta) {
            Some(x) => x,
            None if theta < SMALL_THETA_INV_M => small_theta::inv_m_small(theta),
            None => return Err(Error::OutOfRange),
        };
        let m = 1.0 / inv_m;
        let n = g / theta * inv_m; // in this order: g inv_m underflows at tiny theta
        let l = self.hertz_gain * cbrt(load); // L, eqs (2)-(3)
        // p0 = 3 P / (2 pi a b) = 3 P^(1/3) / (2 pi m n V^(2/3)); 0 at P = 0.
        let p0 = if load == 0.0 {
            0.0
        } else {
            3.0 * cbrt(load) / (2.0 * PI * m * n * self.hertz_gain * self.hertz_gain)
        };
        Ok(Details {
            theta,
            m,
            n,
            a: m * l,
            b: n * l,
            p0,
        })
    }
}

/// The contact ellipse of one sample, on request ([`EllipticScene::details`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Details {
    /// Auxiliary angle theta (rad), eq (4).
    pub theta: f32,
    /// m (eqs 5-6); +inf at phi = 0.
    pub m: f32,
    /// n (eqs 5-6).
    pub n: f32,
    /// Semi-axis along the rollers a = m L (m); +inf at phi = 0.
    pub a: f32,
    /// Semi-axis in the rolling direction b = n L (m).
    pub b: f32,
    /// Peak pressure p0 (Pa), eq (7).
    pub p0: f32,
}

impl EllipticScene<'static> {
    /// The length of [`EllipticScene::to_bytes`].
    pub const BYTES: usize = crate::prepared::OVERHEAD + Self::PAYLOAD;
    pub(super) const PAYLOAD: usize = 32;

    /// The scene [`EllipticScene::to_bytes`] wrote, with the full tables, checked on
    /// the bits of its constants (no floating-point operation); it answers bit for bit
    /// as the scene that wrote it (with the same tables).
    ///
    /// # Errors
    /// A [`PreparedError`] for a wrong length, magic, kind, version or checksum, or a
    /// constant that [`EllipticScene::new`] does not produce.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, PreparedError> {
        Self::from_bytes_with_tables(bytes, Tables::FULL)
    }
}

impl<'t> EllipticScene<'t> {
    /// The prepared constants as bytes (format in [`crate::prepared`]); the tables are
    /// not in them: the loading firmware names its own.
    pub fn to_bytes(&self) -> [u8; EllipticScene::BYTES] {
        seal(Kind::Elliptic, |w| self.write(w))
    }

    /// As [`EllipticScene::from_bytes`], with the given tables (see [`Tables`]).
    ///
    /// # Errors
    /// As [`EllipticScene::from_bytes`].
    pub fn from_bytes_with_tables(bytes: &[u8], tables: Tables<'t>) -> Result<Self, PreparedError> {
        Self::read(
            &mut Reader::open(bytes, Kind::Elliptic, EllipticScene::BYTES)?,
            tables,
        )
    }

    pub(super) fn write(&self, w: &mut Writer<'_>) -> Result<(), PreparedError> {
        let constants = [
            self.radius_factor,
            self.inv_radius_factor,
            self.slip_gain,
            self.critical_gain,
            self.friction,
            self.hertz_gain,
            self.risk_slip_ratio,
            self.cubed_critical_gain,
        ];
        w.each(&constants, |w, x| w.f32(*x))
    }

    pub(super) fn read(r: &mut Reader<'_>, tables: Tables<'t>) -> Result<Self, PreparedError> {
        let mut c = [0.0f32; 6];
        for x in &mut c {
            *x = positive_normal(r.f32()?)?;
        }
        let risk_slip_ratio = positive_finite(r.f32()?)?;
        let cubed_critical_gain = r.f32()?;
        // On the bits (positive f32 order as their bits): 2^-40 <= c <= 1, A within
        // `SLIP_GAIN_LIMIT`, mu at most 128 (the f32 of a mu below 128), B^3 0 or in
        // the hot path's [2^-120, 2^39] with c from `HOT_MIN_RADIUS_FACTOR` up
        // (whether it is B's cube takes floating point:
        // like A against B, it is the writer's).
        let bits = |x: f32| x.to_bits();
        value(
            bits(MIN_RADIUS_FACTOR) <= bits(c[0])
                && bits(c[0]) <= bits(1.0)
                && bits(c[2]) <= bits(SLIP_GAIN_LIMIT)
                && bits(c[4]) <= bits(FRICTION_LIMIT as f32)
                && (bits(cubed_critical_gain) == 0
                    || (bits(HOT_GAIN_MIN) <= bits(cubed_critical_gain)
                        && bits(cubed_critical_gain) <= bits(HOT_GAIN_MAX)
                        && bits(HOT_MIN_RADIUS_FACTOR) <= bits(c[0]))),
        )?;
        Ok(EllipticScene {
            radius_factor: c[0],
            inv_radius_factor: c[1],
            slip_gain: c[2],
            critical_gain: c[3],
            friction: c[4],
            hertz_gain: c[5],
            risk_slip_ratio,
            risk_offset: risk_offset(risk_slip_ratio),
            cubed_critical_gain,
            tables,
        })
    }
}

#[cfg(test)]
mod prepared_tests {
    use super::{HOT_MIN_RADIUS_FACTOR, SLIP_GAIN_LIMIT};

    /// The hot path's smallest c is the reference's theta0 at its largest g0
    /// (cbrt(1/2)) over pi/2, with 1e-4 for the tables, rounded up to f32.
    #[test]
    fn hot_min_radius_factor_is_the_largest_hot_theta0_over_a_right_angle() {
        let theta = crate::reference::normal::theta_for_g(libm::cbrt(0.5))
            .unwrap()
            .theta;
        let bound = theta / core::f64::consts::FRAC_PI_2 * (1.0 + 1e-4);
        let limit = HOT_MIN_RADIUS_FACTOR as f64;
        assert!(
            bound <= limit && limit <= bound * (1.0 + 1e-6),
            "{bound} {limit}"
        );
    }

    /// The bound that `from_bytes` checks on the bits is the one `with_tables` applies
    /// in f64, rounded up to f32 (within 1e-5): no prepared scene is refused.
    #[test]
    fn slip_gain_limit_is_the_preparation_bound_rounded_up() {
        let lightest_cbrt = libm::cbrt(f32::from_bits(1) as f64);
        let bound = f32::MAX as f64 / 2.0 * lightest_cbrt / core::f64::consts::FRAC_PI_2;
        let limit = SLIP_GAIN_LIMIT as f64;
        assert!(
            bound <= limit && limit <= bound * (1.0 + 1e-5),
            "{bound} {limit}"
        );
    }
}

#[cfg(test)]
mod hot_path_tests {
    use super::{EllipticScene, Parts};
    use crate::Scene;

    /// The general path's parts, as `estimate` finishes them.
    fn general(core: &EllipticScene<'_>, load: f32, phi: f32) -> Option<(f32, f32, Option<f32>)> {
        let p: Parts = core.general_parts(load, phi).ok()?;
        Some((p.slip_ratio, p.signed_limit, p.critical_angle))
    }

    /// Wherever the hot path answers, the general path answers the same to the bit:
    /// over scenes of equal and unequal radii and the edges of the hot path's range
    /// (|phi| up to 1, B^3 P up to 1/2, theta near the g table's first octave).
    #[test]
    fn the_hot_path_is_the_general_one_to_the_bit() {
        let scenes = [
            Scene::DEMO,
            Scene::new(0.02, 0.5, 79.3e9, 0.3, 0.15).unwrap(),
            Scene::new(1e-3, 1e-3, 1e9, 0.45, 0.6).unwrap(),
            Scene::new(2.0, 3.0, 80e9, 0.28, 0.05).unwrap(),
        ];
        let (mut hot, mut total) = (0, 0);
        for scene in scenes {
            let core = EllipticScene::new(&scene).unwrap();
            for i in 0..4000u32 {
                // Loads from 1e-6 to 1e12 N, angles from 1e-12 to 1.2 rad, both signs.
                let u = i as f32 / 4000.0;
                let load = libm::powf(10.0, -6.0 + 18.0 * u);
                let v = (i as f32 * 0.618_034).fract();
                let phi = libm::powf(10.0, -12.0 + 12.1 * v) * if i % 2 == 0 { 1.0 } else { -1.0 };
                total += 1;
                if let Some(p) = core.hot_parts(load, phi, phi.abs()) {
                    hot += 1;
                    assert_eq!(
                        Some((p.slip_ratio, p.signed_limit, p.critical_angle)),
                        general(&core, load, phi),
                        "{load:e} {phi:e}"
                    );
                }
            }
        }
        assert!(hot > total / 4, "{hot} of {total} on the hot path");
    }

    /// B^3 outside [2^-120, 2^39] (here a scene of A near 1e16: stiff, huge rollers,
    /// almost no friction): no hot path, every sample through the general one, which
    /// still answers as the reference does.
    #[test]
    fn scenes_without_a_hot_path_still_answer() {
        let scene = Scene::new(1e6, 1e6, 1e12, 0.3, 1e-8).unwrap();
        let core = EllipticScene::new(&scene).unwrap();
        assert_eq!(core.cubed_critical_gain, 0.0);
        for (load, phi) in [(1e3f32, 1e-3f32), (1e20, 0.3), (1e-20, -1e-6)] {
            let e = core.estimate(load, phi).unwrap();
            let r = crate::reference::elliptic(&scene, load as f64, phi as f64).unwrap();
            let close = |a: f32, b: f64| (a as f64 / b - 1.0).abs() < 2e-6;
            assert!(close(e.slip_ratio, r.slip_ratio), "{load} {phi}");
            assert!(close(e.axial_force, r.axial_force), "{load} {phi}");
        }
    }
}
