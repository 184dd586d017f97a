//! The f32 core: what runs on a microcontroller with an FPU for every sample.
//!
//! A scene is prepared once ([`EllipticScene::new`], [`LineScene::new`]): everything
//! constant is computed then, in f64. Per sample the estimator gets only the load P and
//! the misalignment phi and returns the slip ratio d/b, the regime, the axial force F,
//! the critical angle phi0 at this load, the margin to it and a microslip-risk flag.
//!
//! The elliptic path (sections 5-7) is `theta = c |phi|` (eq 4), `g(theta) = m n theta`
//! from a table, `d/b = A g P^(-1/3)` (eq 16), F from eq (21) by a kernel, and
//! `phi0 = theta(B P^(1/3)) / c` (eq 18 at d/b = 1) from the inverse table; the line
//! path (section 8) needs no table at all. Each type links only what it uses.

mod elliptic;
internal! {
    /// The f32 kernels of the per-sample path.
    mod kernels;
}
mod line;
pub mod octave;
internal! {
    /// The generated tables of the f32 core.
    #[rustfmt::skip]
    mod tables;
}

pub use elliptic::{Details, EllipticScene, Tables};
pub use line::LineScene;
/// The generated tables over their whole range, the rows that [`octave::narrow_rows`]
/// narrows for a [`Tables`] of a smaller range of misalignment.
pub use tables::{G_OF_THETA, G_OF_THETA_ROWS, THETA_OF_G, THETA_OF_G_ROWS};

use crate::estimator::Estimator;
#[doc(no_inline)]
pub use crate::estimator::{DEFAULT_RISK_SLIP_RATIO, Estimate};
use crate::reference::Regime;

impl Estimate {
    /// Builds the common fields from d/b, F/(mu P) and phi0.
    #[inline(always)]
    pub(crate) fn new(
        slip_ratio: f32,
        force: f32,
        critical_angle: Option<f32>,
        abs_phi: f32,
        risk: f32,
    ) -> Self {
        Estimate {
            slip_ratio,
            regime: if slip_ratio < 1.0 {
                Regime::Partial
            } else {
                Regime::Gross
            },
            axial_force: force,
            critical_angle,
            margin: critical_angle.map(|c| c - abs_phi),
            microslip_risk: slip_ratio >= risk,
        }
    }
}

/// Per-sample input check shared by the f32 paths: load finite and >= 0 (-0 counts as
/// 0), angle finite.
#[inline(always)]
fn check(load: f32, phi: f32) -> Result<(), crate::Error> {
    // On the bits: +0 and positive finite values are below the +inf pattern; -0 is
    // the one negative pattern accepted. (Two integer compares instead of float ones.)
    let bits = load.to_bits();
    if bits >= 0x7f80_0000 && bits != 0x8000_0000 {
        return Err(crate::Error::Load);
    }
    if (phi.to_bits() & 0x7fff_ffff) >= 0x7f80_0000 {
        return Err(crate::Error::Angle);
    }
    Ok(())
}

/// The scene's model choice (section 9) for the f32 core: line contact for a plane, or
/// when the rollers have a length and the ellipse is longer than them anywhere in the
/// declared operating range (at its heaviest load and smallest misalignment, where the
/// ellipse is longest); the elliptic contact otherwise. Made once, when the scene is
/// prepared; a firmware that knows its model uses [`EllipticScene`] or [`LineScene`]
/// directly and links only that one.
#[derive(Debug, Clone, Copy)]
pub enum Prepared {
    /// The contact ellipse fits on the rollers.
    Elliptic(EllipticScene<'static>),
    /// Line contact: load per unit length without a scene length, total load with one.
    Line(LineScene),
}

impl Prepared {
    /// Chooses and prepares the model for loads up to `load_max` (N) and misalignments
    /// down to `angle_min` (rad, > 0).
    ///
    /// # Errors
    /// As the scenes' `new`; [`crate::Error::Load`] or [`crate::Error::Angle`] for an
    /// operating range that is not positive and finite.
    pub fn new(scene: &crate::Scene, load_max: f64, angle_min: f64) -> Result<Self, crate::Error> {
        if !(load_max.is_finite() && load_max > 0.0) {
            return Err(crate::Error::Load);
        }
        if !(angle_min.is_finite() && angle_min > 0.0) {
            return Err(crate::Error::Angle);
        }
        let line = match scene.length() {
            _ if scene.is_plane() => true,
            None => false,
            Some(_) => {
                crate::reference::elliptic(scene, load_max, angle_min)?
                    .validity
                    .longer_than_rollers
            }
        };
        if line {
            Ok(Prepared::Line(LineScene::new(scene)?))
        } else {
            Ok(Prepared::Elliptic(EllipticScene::new(scene)?))
        }
    }

    /// Which model was chosen.
    pub fn model(&self) -> crate::reference::ContactModel {
        match self {
            Prepared::Elliptic(_) => crate::reference::ContactModel::Elliptic,
            Prepared::Line(_) => crate::reference::ContactModel::Line,
        }
    }

    /// The d/b threshold of [`Estimate::microslip_risk`].
    pub fn risk_slip_ratio(&self) -> f32 {
        match self {
            Prepared::Elliptic(e) => e.risk_slip_ratio(),
            Prepared::Line(l) => l.risk_slip_ratio(),
        }
    }

    /// The same scene with another d/b threshold for [`Estimate::microslip_risk`].
    ///
    /// # Errors
    /// [`crate::Error::OutOfRange`] for a threshold that is not positive and finite.
    pub fn with_risk_slip_ratio(self, slip_ratio: f32) -> Result<Self, crate::Error> {
        Ok(match self {
            Prepared::Elliptic(e) => Prepared::Elliptic(e.with_risk_slip_ratio(slip_ratio)?),
            Prepared::Line(l) => Prepared::Line(l.with_risk_slip_ratio(slip_ratio)?),
        })
    }

    /// The estimate of the chosen model (load in N; see [`LineScene`] for its units).
    ///
    /// # Errors
    /// As the chosen scene's `estimate`.
    pub fn estimate(&self, load: f32, phi: f32) -> Result<Estimate, crate::Error> {
        match self {
            Prepared::Elliptic(e) => e.estimate(load, phi),
            Prepared::Line(l) => l.estimate(load, phi),
        }
    }
}

/// The estimator contract for the f32 scenes: SI values in and out, so that
/// [`Estimator::input`] and [`Estimator::to_estimate`] are the identity.
macro_rules! f32_estimator {
    ($($scene:ty),*) => {$(
        impl Estimator for $scene {
            type Load = f32;
            type Angle = f32;
            type Output = Estimate;
            #[inline(always)]
            fn estimate(&self, load: f32, phi: f32) -> Result<Estimate, crate::Error> {
                <$scene>::estimate(self, load, phi)
            }
            #[inline(always)]
            fn input(&self, load: f32, phi: f32) -> Result<(f32, f32), crate::Error> {
                Ok((load, phi))
            }
            #[inline(always)]
            fn to_estimate(&self, output: &Estimate) -> Estimate {
                *output
            }
            fn risk_slip_ratio(&self) -> f32 {
                <$scene>::risk_slip_ratio(self)
            }
            fn with_risk_slip_ratio(self, slip_ratio: f32) -> Result<Self, crate::Error> {
                <$scene>::with_risk_slip_ratio(self, slip_ratio)
            }
        }
    )*};
}

f32_estimator!(EllipticScene<'_>, LineScene, Prepared);
