//! The f32 core: what runs on a microcontroller with an FPU for every sample.
//!
//! A scene is prepared once ([`EllipticScene::new`], [`LineScene::new`]): everything
//! constant is computed then, in f64. Per sample the estimator gets only the load P and
//! the misalignment phi and returns the slip ratio d/b, the regime, the axial force F,
//! the critical angle phi0 at this load, the margin to it and a microslip-risk flag.
//!
//! The elliptic path (sections 5-7) is `theta = c |phi|` (eq 4), `g(theta) = m n theta`
//! from a table, `g0 = (B^3 P)^(1/3)` (eq 18 at d/b = 1, one cube root), `d/b = g / g0`
//! (eq 16), F from eq (21) by a kernel, and `phi0 = theta(g0) / c` from the inverse
//! table; the line path (section 8) needs no table at all. Each type links only what it uses:
//! [`EllipticScene`] and [`LineScene`] are one model each and never switch;
//! [`Auto`] applies section 9's model choice per sample, as `reference::estimate` does.

mod auto;
pub(crate) mod block;
mod elliptic;
pub mod inverse;
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

pub use auto::{Auto, AutoEstimate, ContactDetails};
pub use elliptic::{Details, EllipticScene, Tables};
pub use line::{LineDetails, LineScene};
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

f32_estimator!(EllipticScene<'_>, LineScene);
