//! The built-in scenario: a press roller pair over one shift, generated one sample at
//! a time, deterministic and `no_std`, so that the PC example and a firmware replay
//! the same samples and must report the same events.
//!
//! The scene is the demo scene (two steel rollers of 50 mm radius, G = 79.3 GPa,
//! nu = 0.3, mu = 0.3). One sample a second for 8 hours ([`SHIFT_S`]):
//!
//! | time | what happens |
//! | --- | --- |
//! | 0 - 8 h | the load varies around 2.5 kN (press cycle of 40 min, +-0.8 kN, and a faster +-0.3 kN); the misalignment drifts from 0.10 to 0.80 mrad, through the critical angle phi0(P) of about 0.5 to 0.6 mrad; the speed is 2 m/s |
//! | all along | noise: load 1 % (rms), angle 3 urad, speed 1 %; a single-sample spike every 1777 s (load x3 or angle +2 mrad) |
//! | 1 h | the node's u32 ms counter wraps (it starts 1 h before the wrap) |
//! | 2 h 00 - 2 h 03 | dropout: no samples for 3 min |
//! | 3 h 00 - 3 h 05 | the angle sensor is stuck at one value |
//! | 5 h 00 - 5 h 20 | the machine stops: load near 0 (the load cell reads +-20 N), speed 0 |
//!
//! Noise comes from a seeded xorshift generator and every value is computed in f32
//! with `libm`, so that the samples are bit-identical on every target.
//!
//! [`estimator`] builds the scenario's estimator on either core, the one the PC
//! example, the firmware node, the host replay that checks the node and the
//! benchmarks all run: the same model and units everywhere, so that their events agree.

use super::Sample;
use super::model::model_for_range;
use crate::fixed::{FixedAuto, FixedEllipticScene};
use crate::float::Auto;
use crate::reference::ModelChoice;
use crate::{Error, Estimator, Scene};

/// Shift length (s).
pub const SHIFT_S: u32 = 8 * 3600;
/// Sample period (ms).
pub const SAMPLE_PERIOD_MS: u32 = 1000;
/// The node's counter at the first sample: it wraps one hour in.
pub const START_TIME_MS: u32 = u32::MAX - 3_600_000 + 1;
/// The demo scene: R1, R2 (m), G (Pa), nu, mu.
pub const SCENE: [f64; 5] = [0.05, 0.05, 79.3e9, 0.3, 0.3];
/// The load (N) up to which the scenario's model is chosen ([`model_for_range`]): the
/// press cycle's; the spikes go above it, with the same model (a test checks it).
pub const LOAD_MAX: f64 = 5e3;
/// The smallest misalignment worth a model choice (rad).
pub const ANGLE_MIN: f64 = 1e-5;
/// The generator's seed.
pub const SEED: u32 = 0x2545_f491;

/// The dropout: no samples from the first to before the second second.
pub const DROPOUT_S: (u32, u32) = (2 * 3600, 2 * 3600 + 180);
/// The angle sensor repeats one value from the first to before the second second.
pub const STUCK_S: (u32, u32) = (3 * 3600, 3 * 3600 + 300);
/// The machine stands from the first to before the second second.
pub const STOP_S: (u32, u32) = (5 * 3600, 5 * 3600 + 1200);
/// A single-sample spike at every second `s` with `s % SPIKE_EVERY_S ==
/// SPIKE_EVERY_S - 1`, except while the machine stands.
pub const SPIKE_EVERY_S: u32 = 1777;

/// The fixed-point core's load LSB (N a count): 10 mN.
pub const FIXED_LOAD_LSB: f64 = 1e-2;
/// The smallest angle LSB (rad a count) the fixed-point core is given: 0.1 nrad.
pub const FIXED_ANGLE_LSB_MIN: f64 = 1e-10;

/// The scenario's scene ([`SCENE`]).
///
/// # Errors
/// None for [`SCENE`]; [`Scene::new`]'s errors were it changed to an invalid one.
pub fn scene() -> Result<Scene, Error> {
    let [r1, r2, g, nu, mu] = SCENE;
    Scene::new(r1, r2, g, nu, mu)
}

/// A core the scenario's estimator is built on: [`Auto`] (f32) or [`FixedAuto`]
/// (fixed point).
pub trait Core: Estimator + Sized {
    /// The core over `scene` with the contact model `choice`.
    ///
    /// # Errors
    /// The core's errors for the scene.
    fn with_model(scene: &Scene, choice: ModelChoice) -> Result<Self, Error>;
}

impl Core for Auto {
    fn with_model(scene: &Scene, choice: ModelChoice) -> Result<Self, Error> {
        Auto::with_choice(scene, choice)
    }
}

impl Core for FixedAuto {
    /// [`FIXED_LOAD_LSB`] a count; the finest angle LSB the elliptic tables allow for
    /// the scene, at least [`FIXED_ANGLE_LSB_MIN`] ([`FIXED_ANGLE_LSB_MIN`] for line
    /// contact).
    fn with_model(scene: &Scene, choice: ModelChoice) -> Result<Self, Error> {
        let angle_lsb = match choice {
            ModelChoice::Elliptic => {
                FixedEllipticScene::min_angle_lsb(scene).max(FIXED_ANGLE_LSB_MIN)
            }
            _ => FIXED_ANGLE_LSB_MIN,
        };
        FixedAuto::with_choice(scene, FIXED_LOAD_LSB, angle_lsb, choice)
    }
}

/// The estimator on core `C` for `scene` sampled at loads up to `load_max` (N): one
/// contact model for that range ([`model_for_range`] down to [`ANGLE_MIN`]), and the
/// core's units ([`Core::with_model`]). The PC example calls it with a scene and a
/// trace of its own.
///
/// # Errors
/// [`model_for_range`]'s errors, the core's errors for the scene.
pub fn estimator_for<C: Core>(scene: &Scene, load_max: f64) -> Result<C, Error> {
    C::with_model(scene, model_for_range(scene, load_max, ANGLE_MIN)?)
}

/// The scenario's estimator on core `C`: [`estimator_for`] the scenario's scene up to
/// [`LOAD_MAX`] (the same model as up to the highest load of the samples: a test
/// checks it).
///
/// # Errors
/// None for the scenario's scene; [`estimator_for`]'s were it changed.
pub fn estimator<C: Core>() -> Result<C, Error> {
    estimator_for(&scene()?, LOAD_MAX)
}

/// The scenario's samples, in order (an iterator of [`SHIFT_S`] minus the dropout's
/// samples).
#[derive(Debug, Clone)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Scenario {
    second: u32,
    rng: u32,
    stuck_phi: f32,
}

impl Default for Scenario {
    fn default() -> Self {
        Self::new()
    }
}

impl Scenario {
    /// The scenario from its first sample.
    pub const fn new() -> Self {
        Scenario {
            second: 0,
            rng: SEED,
            stuck_phi: 0.0,
        }
    }

    /// Uniform in [0, 1) (xorshift32).
    fn uniform(&mut self) -> f32 {
        let mut x = self.rng;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.rng = x;
        (x >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    /// Approximately standard normal: the sum of four uniforms, rescaled.
    fn normal(&mut self) -> f32 {
        let s = self.uniform() + self.uniform() + self.uniform() + self.uniform();
        (s - 2.0) * 1.732_050_8
    }
}

/// Drift of the misalignment (rad) at time `t` (s): 0.10 to 0.80 mrad over the shift.
pub fn drift_angle(t: f32) -> f32 {
    1.0e-4 + 7.0e-4 * (t / SHIFT_S as f32)
}

/// The load (N) at time `t` (s) without noise.
pub fn nominal_load(t: f32) -> f32 {
    let tau = core::f32::consts::TAU;
    2500.0 + 800.0 * libm::sinf(tau * t / 2400.0) + 300.0 * libm::sinf(tau * t / 517.0)
}

impl Iterator for Scenario {
    type Item = Sample;

    fn next(&mut self) -> Option<Sample> {
        if (DROPOUT_S.0..DROPOUT_S.1).contains(&self.second) {
            self.second = DROPOUT_S.1;
        }
        let s = self.second;
        if s >= SHIFT_S {
            return None;
        }
        self.second += 1;
        let t = s as f32;
        let time_ms = START_TIME_MS.wrapping_add(s.wrapping_mul(SAMPLE_PERIOD_MS));
        let (nl, na, nv) = (self.normal(), self.normal(), self.normal());
        let stopped = (STOP_S.0..STOP_S.1).contains(&s);
        let (mut load, speed) = if stopped {
            (20.0 * nl, 0.0)
        } else {
            (nominal_load(t) * (1.0 + 0.01 * nl), 2.0 * (1.0 + 0.01 * nv))
        };
        let mut phi = drift_angle(t) + 3e-6 * na;
        if (STUCK_S.0..STUCK_S.1).contains(&s) {
            if s == STUCK_S.0 {
                self.stuck_phi = phi;
            }
            phi = self.stuck_phi;
        }
        if s % SPIKE_EVERY_S == SPIKE_EVERY_S - 1 && !stopped {
            if (s / SPIKE_EVERY_S).is_multiple_of(2) {
                load *= 3.0;
            } else {
                phi += 2e-3;
            }
        }
        Some(Sample::new(time_ms, load, phi).with_speed(speed))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The model up to [`LOAD_MAX`] is the one up to the highest load of the samples
    /// (spikes included), which the PC example chooses for a trace.
    #[test]
    fn the_model_covers_every_sample() {
        let scene = scene().unwrap();
        let highest = Scenario::new()
            .map(|s| f64::from(s.load))
            .fold(LOAD_MAX, f64::max);
        assert!(highest > LOAD_MAX);
        assert_eq!(
            model_for_range(&scene, highest, ANGLE_MIN).unwrap(),
            model_for_range(&scene, LOAD_MAX, ANGLE_MIN).unwrap()
        );
        assert!(estimator::<Auto>().is_ok() && estimator::<FixedAuto>().is_ok());
    }
}
