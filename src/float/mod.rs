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
//! path (section 8) needs no table at all. Each type links only what it uses:
//! [`EllipticScene`] and [`LineScene`] are one model each and never switch;
//! [`Auto`] applies section 9's model choice per sample, as `reference::estimate` does.

mod auto;
mod elliptic;
mod line;

pub use auto::{Auto, AutoEstimate, ContactDetails};
pub use elliptic::{Details, EllipticScene, Tables};
pub use line::{LineDetails, LineScene};

use crate::reference::Regime;

/// The slip ratio at and above which [`Estimate::microslip_risk`] is raised, unless the
/// scene sets another: 0.8, so that the flag comes before gross slip (d/b = 1).
pub const DEFAULT_RISK_SLIP_RATIO: f32 = 0.8;

/// The per-sample answer of both cores' f32 paths. Units SI: N (N/m for line contact
/// without a length), rad.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// Slip ratio d/b (eqs 16, 23); 0 at phi = 0, +inf at P = 0 with phi != 0.
    pub slip_ratio: f32,
    /// Partial slip (d/b < 1) or gross slip.
    pub regime: Regime,
    /// Axial force F with the sign of phi (eqs 21, 27, 29).
    pub axial_force: f32,
    /// Critical angle phi0 at this load (rad), where d/b = 1; `None` when no
    /// theta <= pi/2 reaches d/b = 1 (elliptic contact at very high load).
    pub critical_angle: Option<f32>,
    /// `phi0 - |phi|` (rad): positive while part of the contact sticks.
    pub margin: Option<f32>,
    /// d/b at or above the scene's risk threshold.
    pub microslip_risk: bool,
}

impl Estimate {
    /// Builds the common fields from d/b, F/(mu P) and phi0.
    #[inline(always)]
    fn new(
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
