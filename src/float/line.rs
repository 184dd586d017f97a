//! Line contact (paper section 8) in f32: no table, one inverse square root per sample.

use super::kernels::sqrt::inv_sqrt;
use super::{DEFAULT_RISK_SLIP_RATIO, Estimate, check};
use crate::estimator::check_risk;
use crate::{Error, Scene};
use core::f32::consts::FRAC_PI_2;

/// A prepared line-contact scene: a cylinder on a plane, or two rollers whose contact
/// runs from end to end (section 9), with R from eq (31).
///
/// The load is per unit length (N/m) when the scene has no length, and the total load
/// (N) when it has one; F follows (N/m or N).
#[derive(Debug, Clone, Copy)]
pub struct LineScene {
    /// `sqrt(pi (1 - nu) G R l) / (2 mu)`: d/b = this |phi| / sqrt(P) (eq 23), l the
    /// length (1 without one).
    slip_gain: f32,
    /// `2 mu / sqrt(pi G (1 - nu) R l)`: phi0 = this sqrt(P) (eq 28).
    critical_gain: f32,
    /// Friction coefficient mu.
    friction: f32,
    /// d/b at and above which the risk flag is raised.
    risk_slip_ratio: f32,
}

impl LineScene {
    /// Prepares `scene` for line contact.
    ///
    /// # Errors
    /// [`Error::OutOfRange`] if a constant does not fit in f32.
    pub fn new(scene: &Scene) -> Result<Self, Error> {
        let mu = scene.friction();
        let stiffness = core::f64::consts::PI
            * (1.0 - scene.poisson_ratio())
            * scene.shear_modulus()
            * scene.effective_radius()
            * scene.length().unwrap_or(1.0);
        let root = libm::sqrt(stiffness);
        let constants = [root / (2.0 * mu), 2.0 * mu / root, mu];
        let mut f = [0.0f32; 3];
        for (out, x) in f.iter_mut().zip(constants) {
            *out = x as f32;
            if !(out.is_normal() && *out > 0.0) {
                return Err(Error::OutOfRange);
            }
        }
        Ok(LineScene {
            slip_gain: f[0],
            critical_gain: f[1],
            friction: f[2],
            risk_slip_ratio: DEFAULT_RISK_SLIP_RATIO,
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
    /// non-finite angle or |phi| above pi/2.
    #[inline]
    pub fn estimate(&self, load: f32, phi: f32) -> Result<Estimate, Error> {
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
}
