//! Line contact (paper section 8) in f32: no table, one inverse square root per sample.

use super::kernels::sqrt::inv_sqrt;
use super::{DEFAULT_RISK_SLIP_RATIO, Estimate, check};
use crate::estimator::check_risk;
use crate::prepared::{
    Kind, PreparedError, Reader, Writer, positive_finite, positive_normal, seal, value,
};
use crate::{Error, Scene};
use core::f32::consts::FRAC_PI_2;

/// A prepared line-contact scene: a cylinder on a plane, or two rollers whose contact
/// runs from end to end (section 9), with R from eq (31).
///
/// The load is per unit length (N/m) when the scene has no length, and the total load
/// (N) when it has one; F follows (N/m or N).
#[derive(Debug, Clone, Copy)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LineScene {
    /// `sqrt(pi (1 - nu) G R l) / (2 mu)`: d/b = this |phi| / sqrt(P) (eq 23), l the
    /// length (1 without one).
    pub(super) slip_gain: f32,
    /// `2 mu / sqrt(pi G (1 - nu) R l)`: phi0 = this sqrt(P) (eq 28).
    pub(super) critical_gain: f32,
    /// Friction coefficient mu.
    pub(super) friction: f32,
    /// `sqrt(4 (1 - nu) R / (pi G l))`: b = this sqrt(P) (eq 22).
    width_gain: f32,
    /// `sqrt(G / (pi (1 - nu) R l))`: p0 = 2 P / (pi b l) = this sqrt(P) (eq 22).
    pressure_gain: f32,
    /// d/b at and above which the risk flag is raised.
    risk_slip_ratio: f32,
    /// The lightest load (as f32 bits) above 0 whose results fit f32: d/b finite,
    /// phi0 a normal number.
    load_min_bits: u32,
    /// `heaviest - lightest` (f32 bits) of the hot path: F = mu P finite and phi0
    /// below pi/2 up to its heaviest load. Heavier loads take the cold path, which
    /// answers no critical angle where phi0 passes pi/2: the hot path needs no check.
    load_span_bits: u32,
}

impl LineScene {
    /// Prepares `scene` for line contact.
    ///
    /// # Errors
    /// [`Error::OutOfRange`] if a constant does not fit in f32, or no load has all its
    /// results in f32 (see [`LineScene::load_range`]) with phi0 below pi/2 (an absurd
    /// scene: phi0 beyond a right angle at the lightest load).
    pub fn new(scene: &Scene) -> Result<Self, Error> {
        let mu = scene.friction();
        let stiffness = core::f64::consts::PI
            * (1.0 - scene.poisson_ratio())
            * scene.shear_modulus()
            * scene.effective_radius()
            * scene.length().unwrap_or(1.0);
        let root = libm::sqrt(stiffness);
        // sqrt((1 - nu) R / (pi G l)), as a product of roots (no overflow).
        let sq = libm::sqrt;
        let compliance = sq((1.0 - scene.poisson_ratio()) / core::f64::consts::PI)
            * (sq(scene.effective_radius()) / sq(scene.shear_modulus()))
            / sq(scene.length().unwrap_or(1.0));
        let constants = [
            root / (2.0 * mu),
            2.0 * mu / root,
            mu,
            2.0 * compliance, // eq (22)
            // p0 = 2 P / (pi b l) = sqrt(P) / (pi compliance l)
            1.0 / (core::f64::consts::PI * compliance * scene.length().unwrap_or(1.0)),
        ];
        let mut f = [0.0f32; 5];
        for (out, x) in f.iter_mut().zip(constants) {
            *out = x as f32;
            if !(out.is_normal() && *out > 0.0) {
                return Err(Error::OutOfRange);
            }
        }
        let (slip, critical, mu) = (f[0] as f64, f[1] as f64, f[2] as f64);
        // With a factor 2 for inv_sqrt's and the products' rounding: d/b =
        // slip |phi| / sqrt(P) <= slip (pi/2) / sqrt(P) finite (eq 23); phi0 =
        // critical sqrt(P) normal (eq 28); F <= mu P finite (eqs 27, 29). The hot path
        // stops 2^-20 short of phi0 = pi/2 (inv_sqrt's and the products' rounding are
        // far smaller), so that its phi0 never passes pi/2.
        let (max, min_normal) = (f32::MAX as f64, f32::MIN_POSITIVE as f64);
        let lightest = f64::max(
            f64::max(
                f32::from_bits(1) as f64,
                square(2.0 * slip * core::f64::consts::FRAC_PI_2 / max),
            ),
            square(2.0 * min_normal / critical),
        );
        let right_angle = square(core::f64::consts::FRAC_PI_2 / critical) * (1.0 - 1.0 / 1048576.0);
        let heaviest = f64::min(f64::min(max, max / mu), right_angle);
        let (lightest, heaviest) = (f32_above(lightest), f32_below(heaviest));
        if lightest > heaviest {
            return Err(Error::OutOfRange);
        }
        Ok(LineScene {
            slip_gain: f[0],
            critical_gain: f[1],
            friction: f[2],
            width_gain: f[3],
            pressure_gain: f[4],
            risk_slip_ratio: DEFAULT_RISK_SLIP_RATIO,
            load_min_bits: lightest.to_bits(),
            // Positive f32 order as their bits: no wrap.
            load_span_bits: heaviest.to_bits().wrapping_sub(lightest.to_bits()),
        })
    }

    /// The same scene with another d/b threshold for [`Estimate::microslip_risk`].
    ///
    /// # Errors
    /// [`Error::OutOfRange`] for a threshold that is not positive and finite.
    pub fn with_risk_slip_ratio(mut self, slip_ratio: f32) -> Result<Self, Error> {
        self.risk_slip_ratio = check_risk(slip_ratio)?;
        Ok(self)
    }

    /// The d/b threshold of [`Estimate::microslip_risk`].
    pub fn risk_slip_ratio(&self) -> f32 {
        self.risk_slip_ratio
    }

    /// The estimate for load `load` (N/m, or N with a length) and misalignment `phi`
    /// (rad, signed). Zero angle: d/b = 0, F = 0. Zero load: d/b = +inf, F = 0, phi0 = 0.
    ///
    /// # Errors
    /// [`Error::Load`] for a NaN, infinite or negative load; [`Error::Angle`] for a
    /// non-finite angle or |phi| above pi/2; [`Error::OutOfRange`] for a load outside
    /// [`LineScene::load_range`] (other than 0), where a result would not fit f32.
    #[inline]
    pub fn estimate(&self, load: f32, phi: f32) -> Result<Estimate, Error> {
        // One unsigned compare on the bits: load outside the scene's range (0, negative,
        // NaN and inf included) goes to the cold path, which sorts them out.
        if !self.load_in_range(load) {
            return self.outside_load(load, phi);
        }
        let abs_phi = phi.abs();
        // On the bits: above f32's pi/2 (which stands for pi/2), and also inf and NaN,
        // whose patterns lie above.
        if abs_phi.to_bits() > FRAC_PI_2.to_bits() {
            return Err(Error::Angle);
        }
        let y = inv_sqrt(load); // P^(-1/2), subnormal loads included
        let s = self.slip_gain * abs_phi * y; // eq (23)
        let ratio = if s < 1.0 { s * (2.0 - s) } else { 1.0 }; // eqs (27), (29)
        let force = (self.friction * (load * ratio)).copysign(phi);
        let critical = self.critical_gain * (load * y); // eq (28)
        Ok(Estimate::new(
            s,
            force,
            Some(critical),
            abs_phi,
            self.risk_slip_ratio,
        ))
    }

    /// Whether `load` lies in [`LineScene::load_range`]: one unsigned compare on the
    /// bits (0, negative, NaN and inf are outside).
    #[inline(always)]
    pub(super) fn load_in_range(&self, load: f32) -> bool {
        load.to_bits().wrapping_sub(self.load_min_bits) <= self.load_span_bits
    }

    /// Loads outside the hot path's range: bad input, zero load (d/b = inf at
    /// phi != 0, F = 0, phi0 = 0), a load whose results would not fit f32, or a load
    /// heavy enough for phi0 to near pi/2 (answered as the hot path does, with no
    /// critical angle where phi0 passes pi/2).
    #[cold]
    #[inline(never)]
    fn outside_load(&self, load: f32, phi: f32) -> Result<Estimate, Error> {
        check(load, phi)?;
        let abs_phi = phi.abs();
        if abs_phi > FRAC_PI_2 {
            return Err(Error::Angle);
        }
        if load == 0.0 {
            let s = if abs_phi == 0.0 { 0.0 } else { f32::INFINITY };
            return Ok(Estimate::new(
                s,
                0.0,
                Some(0.0),
                abs_phi,
                self.risk_slip_ratio,
            ));
        }
        if !self.accepts(load) {
            return Err(Error::OutOfRange);
        }
        let y = inv_sqrt(load);
        let s = self.slip_gain * abs_phi * y; // eq (23)
        let ratio = if s < 1.0 { s * (2.0 - s) } else { 1.0 }; // eqs (27), (29)
        let force = (self.friction * (load * ratio)).copysign(phi);
        let critical = self.critical_gain * (load * y); // eq (28)
        Ok(Estimate::new(
            s,
            force,
            within_right_angle(critical),
            abs_phi,
            self.risk_slip_ratio,
        ))
    }

    /// Whether `load` (finite, above 0) is one [`LineScene::estimate`] accepts: from
    /// the lightest on, mu P finite.
    pub(super) fn accepts(&self, load: f32) -> bool {
        load.to_bits() >= self.load_min_bits && (self.friction * load).is_finite()
    }

    /// The loads (N/m, or N with a length) [`LineScene::estimate`] accepts besides 0:
    /// those at which d/b and F are finite and phi0 is a normal f32 (or none, beyond
    /// pi/2). For a realistic scene, every positive f32 load, subnormal ones included.
    pub fn load_range(&self) -> (f32, f32) {
        // The heaviest load with mu P finite: near f32::MAX / mu, then to the ulp.
        let mut heaviest = (f32::MAX / self.friction).min(f32::MAX);
        for _ in 0..4 {
            if !(self.friction * heaviest).is_finite() {
                heaviest = heaviest.next_down();
            } else if heaviest < f32::MAX && (self.friction * heaviest.next_up()).is_finite() {
                heaviest = heaviest.next_up();
            }
        }
        (f32::from_bits(self.load_min_bits), heaviest)
    }

    /// The contact strip on request: half-width b (m, eq 22) and peak pressure p0
    /// (Pa), from the load per unit length P / l (l = 1 m without a length).
    ///
    /// # Errors
    /// As [`LineScene::estimate`].
    pub fn details(&self, load: f32, phi: f32) -> Result<LineDetails, Error> {
        check(load, phi)?;
        if phi.abs() > FRAC_PI_2 {
            return Err(Error::Angle);
        }
        let root = if load == 0.0 {
            0.0
        } else {
            load * inv_sqrt(load)
        }; // sqrt(P)
        Ok(LineDetails {
            b: self.width_gain * root,
            p0: self.pressure_gain * root,
        })
    }
}

/// The contact strip of one sample, on request ([`LineScene::details`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LineDetails {
    /// Half-width of the strip b (m), eq (22).
    pub b: f32,
    /// Peak pressure p0 = 2 P / (pi b) (Pa), P per unit length.
    pub p0: f32,
}

/// phi0 if it is an angle between two axes (at most f32's pi/2, which stands for pi/2),
/// else `None`: eq (28) passes pi/2 only at extreme loads per length, where no angle
/// reaches gross slip. One compare on the bits.
#[inline(always)]
pub(super) fn within_right_angle(phi0: f32) -> Option<f32> {
    (phi0.to_bits() <= FRAC_PI_2.to_bits()).then_some(phi0)
}

fn square(x: f64) -> f64 {
    x * x
}

/// The smallest f32 at or above `x` (x >= 0; the largest finite f32 for x beyond it).
fn f32_above(x: f64) -> f32 {
    let y = x as f32;
    if (y as f64) < x {
        y.next_up()
    } else if y.is_infinite() {
        f32::MAX
    } else {
        y
    }
}

/// The largest f32 at or below `x` (x >= 0; the largest finite f32 for x beyond it).
fn f32_below(x: f64) -> f32 {
    let y = x as f32;
    if y.is_infinite() {
        f32::MAX
    } else if (y as f64) > x {
        y.next_down()
    } else {
        y
    }
}

impl LineScene {
    /// The length of [`LineScene::to_bytes`].
    pub const BYTES: usize = crate::prepared::OVERHEAD + Self::PAYLOAD;
    pub(super) const PAYLOAD: usize = 32;

    /// The prepared scene as bytes (format in [`crate::prepared`]).
    pub fn to_bytes(&self) -> [u8; Self::BYTES] {
        seal(Kind::Line, |w| self.write(w))
    }

    /// The scene [`LineScene::to_bytes`] wrote, checked on the bits of its constants
    /// (no floating-point operation); it answers bit for bit as the scene that wrote it.
    ///
    /// # Errors
    /// A [`PreparedError`] for a wrong length, magic, kind, version or checksum, or a
    /// constant that [`LineScene::new`] does not produce.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, PreparedError> {
        Self::read(&mut Reader::open(bytes, Kind::Line, Self::BYTES)?)
    }

    pub(super) fn write(&self, w: &mut Writer<'_>) -> Result<(), PreparedError> {
        let constants = [
            self.slip_gain,
            self.critical_gain,
            self.friction,
            self.width_gain,
            self.pressure_gain,
            self.risk_slip_ratio,
        ];
        w.each(&constants, |w, x| w.f32(*x))?;
        w.u32(self.load_min_bits)?;
        w.u32(self.load_span_bits)
    }

    pub(super) fn read(r: &mut Reader<'_>) -> Result<Self, PreparedError> {
        let mut c = [0.0f32; 5];
        for x in &mut c {
            *x = positive_normal(r.f32()?)?;
        }
        let risk_slip_ratio = positive_finite(r.f32()?)?;
        let (load_min_bits, load_span_bits) = (r.u32()?, r.u32()?);
        // The load range: positive f32 from the lightest up to at most f32::MAX.
        value(
            load_min_bits != 0
                && load_min_bits
                    .checked_add(load_span_bits)
                    .is_some_and(|heaviest| heaviest <= f32::MAX.to_bits()),
        )?;
        Ok(LineScene {
            slip_gain: c[0],
            critical_gain: c[1],
            friction: c[2],
            width_gain: c[3],
            pressure_gain: c[4],
            risk_slip_ratio,
            load_min_bits,
            load_span_bits,
        })
    }
}
