//! The elliptic core's hot path over a block of samples, for the PC's batch
//! ([`crate::batch`]): the same operations as [`EllipticScene::estimate`] per sample,
//! bit for bit, but in passes over the block, each a short loop of independent
//! iterations (the cube roots and the finish in SIMD lanes where the compiler finds
//! them; the table reads many rows deep in flight), instead of one long dependent chain
//! per sample. A sample off the hot path is marked and left to the caller.

use super::elliptic::{Parts, off_hot_range};
use super::kernels::cbrt::cbrt_hot;
use super::{Auto, EllipticScene};
use crate::reference::{ContactModel, Regime};

/// Samples per block.
pub(crate) const BLOCK: usize = 64;

/// A block's samples in, their answers out.
pub(crate) struct Block {
    /// Load P (N), as the core takes it.
    pub load: [f32; BLOCK],
    /// Misalignment phi (rad, signed).
    pub phi: [f32; BLOCK],
    /// d/b (eq 16).
    pub slip_ratio: [f32; BLOCK],
    /// F (N), signed like phi (eq 21).
    pub axial_force: [f32; BLOCK],
    /// phi0 (rad) at the sample's load (eq 18).
    pub critical_angle: [f32; BLOCK],
    /// 0 partial slip, 1 gross slip.
    pub regime: [u8; BLOCK],
    /// 2a / length near 1 (see [`super::AutoEstimate::near_model_switch`]).
    pub near_model_switch: [bool; BLOCK],
    /// Whether the hot path answered the sample; where not, the other fields are
    /// meaningless and [`Auto::estimate`] answers it.
    pub hot: [bool; BLOCK],
    /// theta (rad), then g(theta) (eqs 4, 5-6).
    scratch: [f32; BLOCK],
    /// g0 = (B^3 P)^(1/3) (eq 18 at d/b = 1).
    g0: [f32; BLOCK],
    /// theta0 = theta(g0) (rad).
    theta0: [f32; BLOCK],
}

impl Block {
    /// An empty block.
    pub fn new() -> Self {
        Block {
            load: [0.0; BLOCK],
            phi: [0.0; BLOCK],
            slip_ratio: [0.0; BLOCK],
            axial_force: [0.0; BLOCK],
            critical_angle: [0.0; BLOCK],
            regime: [0; BLOCK],
            near_model_switch: [false; BLOCK],
            hot: [false; BLOCK],
            scratch: [0.0; BLOCK],
            g0: [0.0; BLOCK],
            theta0: [0.0; BLOCK],
        }
    }
}

impl EllipticScene<'_> {
    /// The hot path over the block: `hot` says which samples it answered.
    #[inline(always)]
    fn estimate_block(&self, b: &mut Block) {
        // The range and the cube root: B^3 P's root is taken for every sample (a bad
        // one gives a number that is not used), so that the loop has no branch.
        for (((hot, theta), g0), (&load, &phi)) in b
            .hot
            .iter_mut()
            .zip(&mut b.scratch)
            .zip(&mut b.g0)
            .zip(b.load.iter().zip(&b.phi))
        {
            let abs_phi = phi.abs();
            let w = self.cubed_critical_gain * load; // g0^3 (eq 18 at d/b = 1)
            *hot = !off_hot_range(abs_phi, w);
            *theta = self.radius_factor * abs_phi; // eq (4)
            *g0 = cbrt_hot(w);
        }
        // g(theta) from its table; theta below it (a sample off the hot path) misses.
        for (hot, x) in b.hot.iter_mut().zip(&mut b.scratch) {
            match self.tables.g.eval(*x) {
                Some(g) => *x = g,
                None => *hot = false,
            }
        }
        // theta0 = theta(g0) from the inverse table.
        for (hot, (t, &g0)) in b.hot.iter_mut().zip(b.theta0.iter_mut().zip(&b.g0)) {
            match self.tables.theta_of_g.eval(g0) {
                Some(x) => *t = x,
                None => *hot = false,
            }
        }
        // d/b = g / g0 (eq 16), F (eq 21), the regime and phi0 = theta0 / c, as the
        // per-sample path ends.
        for ((((s, f), c), r), (((&g, &g0), &theta0), (&load, &phi))) in b
            .slip_ratio
            .iter_mut()
            .zip(&mut b.axial_force)
            .zip(&mut b.critical_angle)
            .zip(&mut b.regime)
            .zip(
                b.scratch
                    .iter()
                    .zip(&b.g0)
                    .zip(&b.theta0)
                    .zip(b.load.iter().zip(&b.phi)),
            )
        {
            let abs_phi = phi.abs();
            *s = g / g0;
            let e = self.finish(
                Parts {
                    slip_ratio: *s,
                    // phi / |phi| is phi's sign on the hot path (phi is not 0 there).
                    signed_limit: self.friction * load * (phi / abs_phi),
                    critical_angle: Some(theta0 * self.inv_radius_factor),
                },
                abs_phi,
            );
            *f = e.axial_force;
            *c = e.critical_angle.unwrap_or(f32::NAN);
            *r = match e.regime {
                Regime::Partial => 0,
                Regime::Gross => 1,
            };
        }
    }
}

impl Auto {
    /// [`Auto::estimate`] over a block where the ellipse answers on its hot path (the
    /// same bits); `hot` false marks every other sample. The hot path's own range
    /// (|phi| <= 1, a positive finite load) implies [`Auto::estimate`]'s checks.
    pub(crate) fn estimate_block(&self, b: &mut Block) {
        let Some(e) = &self.elliptic else {
            b.hot = [false; BLOCK];
            return;
        };
        e.estimate_block(b);
        if self.two_over_length == 0.0 {
            // Without a length `choose` compares nothing: the choice alone decides.
            let elliptic = self.choice.model(false) == ContactModel::Elliptic;
            for hot in &mut b.hot {
                *hot &= elliptic;
            }
            b.near_model_switch = [false; BLOCK];
            return;
        }
        for ((hot, near), (&load, &phi)) in b
            .hot
            .iter_mut()
            .zip(&mut b.near_model_switch)
            .zip(b.load.iter().zip(&b.phi))
        {
            if *hot {
                let (model, n) = self.choose(load, phi);
                *hot = model == ContactModel::Elliptic;
                *near = n;
            }
        }
    }
}
