//! Line contact (paper section 8) in f32: no table, one inverse square root per sample.

use super::{DEFAULT_RISK_SLIP_RATIO, Estimate, check};
use crate::estimator::check_risk;
use crate::kernels::sqrt::inv_sqrt;
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
        Ok(LineScene {
            slip_gain: f[0],
            critical_gain: f[1],
            friction: f[2],
            width_gain: f[3],
            pressure_gain: f[4],
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
    /// non-finite angle or |phi| >= pi/2.
    #[inline]
    pub fn estimate(&self, load: f32, phi: f32) -> Result<Estimate, Error> {
        check(load, phi)?;
        let abs_phi = phi.abs();
        // f32's FRAC_PI_2 lies above pi/2: refused with everything above it.
        if abs_phi >= FRAC_PI_2 {
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

    /// The contact strip on request: half-width b (m, eq 22) and peak pressure p0
    /// (Pa), from the load per unit length P / l (l = 1 m without a length).
    ///
    /// # Errors
    /// As [`LineScene::estimate`].
    pub fn details(&self, load: f32, phi: f32) -> Result<LineDetails, Error> {
        check(load, phi)?;
        if phi.abs() >= FRAC_PI_2 {
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
