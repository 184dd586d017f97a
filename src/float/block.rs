//! The elliptic core's hot path over a block of samples, for the PC's batch
//! ([`crate::batch`]): the same operations as [`EllipticScene::estimate`] per sample,
//! bit for bit, but in passes over the block, each a short loop of independent
//! iterations (the cube roots and the finish in SIMD lanes where the compiler finds
//! them; the table reads many rows deep in flight), instead of one long dependent chain
//! per sample. A sample off the hot path is marked and left to the caller.

use super::elliptic::{
    FRICTION_LIMIT, HOT_GAIN_MAX, HOT_GAIN_MIN, HOT_MIN_RADIUS_FACTOR, MIN_RADIUS_FACTOR, Parts,
    off_hot_range,
};
use super::kernels::cbrt::cbrt_hot;
use super::{Auto, EllipticScene};
use crate::reference::{ContactModel, ModelChoice, Regime};

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

/// The constants the hot path reads of a scene (the [`EllipticScene`] fields of the
/// same names).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Hot {
    pub radius_factor: f32,
    pub inv_radius_factor: f32,
    pub friction: f32,
    pub cubed_critical_gain: f32,
}

/// The hot path's scene of each sample of a block: one for all ([`Hot`]) or one a
/// sample ([`HotPerSample`]).
pub(crate) trait HotScenes {
    /// Sample `i`'s constants.
    fn sample(&self, i: usize) -> Hot;
}

impl HotScenes for Hot {
    #[inline(always)]
    fn sample(&self, _: usize) -> Hot {
        *self
    }
}

/// A scene per sample, each constant a column.
pub(crate) struct HotPerSample {
    pub radius_factor: [f32; BLOCK],
    pub inv_radius_factor: [f32; BLOCK],
    pub friction: [f32; BLOCK],
    pub cubed_critical_gain: [f32; BLOCK],
}

impl HotScenes for HotPerSample {
    #[inline(always)]
    fn sample(&self, i: usize) -> Hot {
        Hot {
            radius_factor: self.radius_factor[i],
            inv_radius_factor: self.inv_radius_factor[i],
            friction: self.friction[i],
            cubed_critical_gain: self.cubed_critical_gain[i],
        }
    }
}

/// A margin, relative, on the f64 side of a range test of preparation: far above the
/// difference between [`hot_of`]'s numbers and `EllipticScene::new`'s (1e-14), so that
/// a value this close to a range's end gives the sample to `Auto` itself.
const RANGE_MARGIN: f64 = 1e-9;

/// f64 ulps an f64 of [`hot_of`] may lie from `EllipticScene::new`'s (2^10; theirs
/// differ by fewer than 100: about 60 roundings at most, none cancelling).
const ROUNDING_WINDOW: u64 = 1 << 10;

/// Whether `x` (f64, positive, in f32's normal range) rounds to the same f32 as every
/// f64 within [`ROUNDING_WINDOW`] ulps of it: it is not that close to a midpoint between
/// two f32 (the 29 bits f32 drops, at 2^28).
#[inline(always)]
fn rounds_surely(x: f64) -> bool {
    let low = x.to_bits() & ((1 << 29) - 1);
    low.abs_diff(1 << 28) > ROUNDING_WINDOW
}

/// `x` within `[lo, hi]` by [`RANGE_MARGIN`] on both sides.
#[inline(always)]
fn well_within(x: f64, lo: f64, hi: f64) -> bool {
    (x > lo * (1.0 + RANGE_MARGIN)) & (x < hi * (1.0 - RANGE_MARGIN))
}

/// `(f32::MAX / 2 x cbrt(2^-149) / (pi/2))^3`: the cube of the largest slip gain A
/// that `EllipticScene::new` accepts (d/b at the lightest load fits f32).
const SLIP_GAIN_LIMIT_CUBED: f64 = {
    let half_max = f32::MAX as f64 / 2.0;
    let pi_2 = core::f64::consts::FRAC_PI_2;
    half_max * half_max * half_max * (f32::from_bits(1) as f64) / (pi_2 * pi_2 * pi_2)
};

/// The hot path's constants of the scene R1, R2 (both finite), G, nu, mu without a
/// length, as [`EllipticScene::new`] forms them, bit for bit, and whether that scene
/// is accepted, takes the hot path and has these constants surely: without a branch or
/// a cube root, for a scene per sample in SIMD lanes. c and 1/c as the scene forms them
/// (a square root within an ulp of libm's); `B^3 = 1/A^3` from `v^3 = h R / G` as
/// `27 mu^3 c^3 / (pi^3 G (h R)^2)` (eq 16, `A = pi G v^2 / (3 mu c)`), where the
/// preparation takes three cube roots; each rounded to f32 only where every f64 near it
/// rounds alike ([`rounds_surely`]), each range test by a margin. `false` (about one
/// sample in 10^5, and every scene off the hot path or refused) leaves the sample to
/// [`Auto::with_choice`]. Cost: one square root, four divisions.
#[inline(always)]
pub(crate) fn hot_of(r1: f64, r2: f64, g: f64, nu: f64, mu: f64) -> (Hot, bool) {
    let scene = crate::Scene::accepts_rollers(r1, r2, g, nu, mu, None);
    let (small, large) = (r1.min(r2), r1.max(r2));
    let ratio = small / large;
    // Scene::radius_factor's expression, the square root within an ulp of libm's.
    let q = crate::reference::fast::sqrt(ratio);
    let c = 2.0 * q / (1.0 + q * q);
    let inverse_c = 1.0 / c;
    let radius = small / (1.0 + ratio);
    let hr = 1.5 * (1.0 - nu) * radius;
    let v3 = hr / g;
    let mu_c = mu * c;
    let pi3 = core::f64::consts::PI * core::f64::consts::PI * core::f64::consts::PI;
    // A^3 and B^3 = 1/A^3.
    let a3 = pi3 * g * (hr * hr) / (27.0 * (mu_c * mu_c * mu_c));
    let b3 = 1.0 / a3;
    let (min, max) = (f32::MIN_POSITIVE as f64, f32::MAX as f64);
    let (min3, max3) = (min * min * min, max * max * max);
    let hot = Hot {
        radius_factor: c as f32,
        inv_radius_factor: inverse_c as f32,
        friction: mu as f32,
        cubed_critical_gain: b3 as f32,
    };
    // EllipticScene::with_tables' tests, each with a margin: c at least 2^-40, mu below
    // 128, A below the limit, the six constants (c, 1/c, A, 1/A, mu, v) normal f32.
    let accepted = well_within(c, MIN_RADIUS_FACTOR as f64, 1.0 / RANGE_MARGIN)
        & (mu < FRICTION_LIMIT)
        & well_within(a3, f64::MIN_POSITIVE, SLIP_GAIN_LIMIT_CUBED)
        & well_within(c, min, max)
        & well_within(inverse_c, min, max)
        & well_within(a3, min3, max3)
        & well_within(b3, min3, max3)
        & hot.friction.is_normal()
        & well_within(v3, min3, max3);
    // The hot path: c (f32) from HOT_MIN_RADIUS_FACTOR up, B^3 (f32) in its range.
    let hot_path = (hot.radius_factor >= HOT_MIN_RADIUS_FACTOR)
        & (hot.cubed_critical_gain >= HOT_GAIN_MIN)
        & (hot.cubed_critical_gain <= HOT_GAIN_MAX);
    let sure = rounds_surely(c) & rounds_surely(inverse_c) & rounds_surely(b3);
    (hot, scene & accepted & hot_path & sure)
}

impl EllipticScene<'_> {
    /// This scene's hot constants.
    #[inline(always)]
    pub(crate) fn hot(&self) -> Hot {
        Hot {
            radius_factor: self.radius_factor,
            inv_radius_factor: self.inv_radius_factor,
            friction: self.friction,
            cubed_critical_gain: self.cubed_critical_gain,
        }
    }

    /// The hot path over the block, each sample with its scene's constants from
    /// `scenes` and this scene's tables and risk threshold: `hot` says which samples it
    /// answered.
    #[inline(always)]
    fn estimate_block<S: HotScenes>(&self, scenes: &S, b: &mut Block) {
        // The range and the cube root: B^3 P's root is taken for every sample (a bad
        // one gives a number that is not used), so that the loop has no branch.
        for (i, (((hot, theta), g0), (&load, &phi))) in b
            .hot
            .iter_mut()
            .zip(&mut b.scratch)
            .zip(&mut b.g0)
            .zip(b.load.iter().zip(&b.phi))
            .enumerate()
        {
            let k = scenes.sample(i);
            let abs_phi = phi.abs();
            let w = k.cubed_critical_gain * load; // g0^3 (eq 18 at d/b = 1)
            *hot = !off_hot_range(abs_phi, w);
            *theta = k.radius_factor * abs_phi; // eq (4)
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
        for (i, ((((s, f), c), r), (((&g, &g0), &theta0), (&load, &phi)))) in b
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
            .enumerate()
        {
            let k = scenes.sample(i);
            let abs_phi = phi.abs();
            *s = g / g0;
            let e = self.finish(
                Parts {
                    slip_ratio: *s,
                    // phi / |phi| is phi's sign on the hot path (phi is not 0 there).
                    signed_limit: k.friction * load * (phi / abs_phi),
                    critical_angle: Some(theta0 * k.inv_radius_factor),
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

    /// [`Auto::estimate_block`] for a scene per sample without a length (`scenes`, each
    /// as [`Auto::with_choice`] prepares it with `choice`, not forced line contact), this
    /// scene lending its tables and its risk threshold (the default's): where the hot
    /// path answers, the bits of each sample's own scene.
    #[inline(always)]
    pub(crate) fn estimate_block_per_sample(
        &self,
        scenes: &HotPerSample,
        choice: ModelChoice,
        b: &mut Block,
    ) {
        self.estimate_block(scenes, b);
        // Without a length `choose` compares nothing: the choice alone decides.
        let elliptic = choice.model(false) == ContactModel::Elliptic;
        for hot in &mut b.hot {
            *hot &= elliptic;
        }
        b.near_model_switch = [false; BLOCK];
    }
}

impl Auto {
    /// [`Auto::estimate`] over a block where the ellipse answers on its hot path (the
    /// same bits); `hot` false marks every other sample. The hot path's own range
    /// (|phi| <= 1, a positive finite load) implies [`Auto::estimate`]'s checks.
    #[inline(always)]
    pub(crate) fn estimate_block(&self, b: &mut Block) {
        let Some(e) = &self.elliptic else {
            b.hot = [false; BLOCK];
            return;
        };
        e.estimate_block(&e.hot(), b);
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
