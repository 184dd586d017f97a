//! The estimator contract: what every prepared scene of both cores answers per sample.
//!
//! A scene is prepared once (the f32 core's [`EllipticScene`](crate::float::EllipticScene),
//! [`LineScene`](crate::float::LineScene), [`Auto`](crate::float::Auto); the
//! fixed-point core's [`FixedEllipticScene`](crate::fixed::FixedEllipticScene),
//! [`FixedLineScene`](crate::fixed::FixedLineScene), [`FixedAuto`](crate::fixed::FixedAuto));
//! then [`Estimator::estimate`] answers
//! one sample in the core's own numbers (f32 SI values, or counts and base-2
//! logarithms), and [`Estimator::estimate_si`] the same in SI f32 for code that is
//! generic over the core, such as a condition monitor.
//!
//! One vocabulary for every core: an [`Estimate`] is the slip ratio d/b, the [`Regime`],
//! the axial force F, the critical angle phi0 at this load, the margin `phi0 - |phi|`
//! and the risk flag (d/b at or above the scene's risk threshold, 0.8 unless set).
//!
//! ```
//! use misalign::{Estimator, Scene, fixed::FixedEllipticScene, float::EllipticScene};
//!
//! fn slip_ratio<E: Estimator>(core: &E) -> f32 {
//!     core.estimate_si(1e3, 2e-4).map(|e| e.slip_ratio).unwrap_or(f32::NAN)
//! }
//! let scene = Scene::DEMO; // two steel rollers of 50 mm, mu = 0.3
//! let f32_core = EllipticScene::new(&scene)?;
//! // The fixed-point core counts 1 mN and 10 prad.
//! let fixed_core = FixedEllipticScene::new(&scene, 1e-3, 1e-11)?;
//! let (a, b) = (slip_ratio(&f32_core), slip_ratio(&fixed_core));
//! assert!((a / b - 1.0).abs() < 1e-5);
//! # Ok::<(), misalign::Error>(())
//! ```

use crate::Error;
use crate::reference::Regime;

/// The slip ratio at and above which [`Estimate::microslip_risk`] is raised, unless the
/// scene sets another: 0.8, so that the flag comes before gross slip (d/b = 1).
pub const DEFAULT_RISK_SLIP_RATIO: f32 = 0.8;

/// The per-sample answer in SI f32, whatever the core. Units: N (N/m for line contact
/// without a length), rad.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Estimate {
    /// Slip ratio d/b (eqs 16, 23); 0 at phi = 0, +inf at P = 0 with phi != 0.
    pub slip_ratio: f32,
    /// Partial slip (d/b < 1) or gross slip.
    pub regime: Regime,
    /// Axial force F with the sign of phi (eqs 21, 27, 29).
    pub axial_force: f32,
    /// Critical angle phi0 at this load (rad), where d/b = 1; `None` when no
    /// theta <= pi/2 reaches d/b = 1 (elliptic contact at very high load) or phi0
    /// would pass pi/2 (unequal radii, an extreme load per length): no angle between
    /// two axes reaches gross slip. Never a number above pi/2 (f32's, which stands
    /// for it).
    pub critical_angle: Option<f32>,
    /// `phi0 - |phi|` (rad): positive while part of the contact sticks.
    pub margin: Option<f32>,
    /// d/b at or above the scene's risk threshold.
    pub microslip_risk: bool,
}

/// A prepared scene of either core: one sample in, one estimate out.
///
/// Implemented by every prepared scene; a monitor or a firmware is generic over it and
/// links only the core it is given.
pub trait Estimator {
    /// The load as the core takes it: N as f32 (N/m for line contact without a
    /// length), or counts of the scene's load LSB as u32.
    type Load: Copy;
    /// The misalignment as the core takes it: rad as f32, or signed counts of the
    /// scene's angle LSB as i32.
    type Angle: Copy;
    /// The core's own answer ([`Estimate`], or [`FixedEstimate`](crate::fixed::FixedEstimate)).
    type Output: Copy;

    /// The estimate for one sample, in the core's own numbers.
    ///
    /// # Errors
    /// As the scene's own `estimate`: [`Error::Load`], [`Error::Angle`],
    /// [`Error::OutOfRange`] for input the scene does not accept.
    fn estimate(&self, load: Self::Load, phi: Self::Angle) -> Result<Self::Output, Error>;

    /// A sample in SI units (load N, phi rad) as the core takes it.
    ///
    /// # Errors
    /// [`Error::Load`] or [`Error::Angle`] for a non-finite or negative load or a
    /// non-finite angle; [`Error::OutOfRange`] when the value does not fit the core's
    /// counts.
    fn input(&self, load: f32, phi: f32) -> Result<(Self::Load, Self::Angle), Error>;

    /// The core's answer in SI f32.
    fn to_estimate(&self, output: &Self::Output) -> Estimate;

    /// The estimate for load `load` (N) and misalignment `phi` (rad), in SI f32.
    ///
    /// # Errors
    /// As [`Estimator::input`] and [`Estimator::estimate`].
    #[inline]
    fn estimate_si(&self, load: f32, phi: f32) -> Result<Estimate, Error> {
        let (load, phi) = self.input(load, phi)?;
        self.estimate(load, phi).map(|o| self.to_estimate(&o))
    }

    /// The d/b threshold of [`Estimate::microslip_risk`].
    fn risk_slip_ratio(&self) -> f32;

    /// The same scene with another d/b threshold for [`Estimate::microslip_risk`].
    ///
    /// # Errors
    /// [`Error::OutOfRange`] for a threshold that is not positive and finite, or does
    /// not fit the core's number format.
    fn with_risk_slip_ratio(self, slip_ratio: f32) -> Result<Self, Error>
    where
        Self: Sized;
}

/// A risk threshold as the cores accept it: positive and finite.
pub(crate) fn check_risk(slip_ratio: f32) -> Result<f32, Error> {
    if slip_ratio.is_finite() && slip_ratio > 0.0 {
        Ok(slip_ratio)
    } else {
        Err(Error::OutOfRange)
    }
}

/// The friction coefficient mu from a measured axial force, per sample: the inverse of
/// eqs (16, 21) for the ellipse and (23, 27) for line contact. Implemented by
/// the f32 core's scenes ([`EllipticScene`](crate::float::EllipticScene),
/// [`LineScene`](crate::float::LineScene), [`Auto`](crate::float::Auto)), which answer
/// it from the forward path's tables; the fixed-point core has no inverse, so a
/// condition monitor over it never tracks mu
/// ([`Monitor::process_with_friction`](crate::monitor::Monitor::process_with_friction)
/// needs this trait).
pub trait FrictionInverse {
    /// mu from load `load` (N; N/m for line contact without a length), misalignment
    /// `phi` (rad, signed) and measured axial force `force` (N, like the load): exact
    /// with its sensitivity `d ln mu / d ln F`, a lower bound where F has saturated
    /// (gross slip, or the no-slip limit), or inconsistent with the reason.
    ///
    /// # Errors
    /// The scene's input errors ([`Error::Load`], [`Error::Angle`],
    /// [`Error::OutOfRange`]) and [`Error::Force`] for a NaN or infinite F.
    fn friction_from_axial_force(
        &self,
        load: f32,
        phi: f32,
        force: f32,
    ) -> Result<crate::reference::inverse::Inverse<f32>, Error>;
}
