//! The minimal images (`cargo xtask firmware`'s size table) and the no-panic images:
//! inputs from flash through volatile reads (so that nothing is folded at compile
//! time, as for a scene read from a configuration block and samples from a sensor),
//! outputs through `black_box`, exit through semihosting. No logger: the images hold
//! the estimator and as little else as possible.

use misalign::{Error, Estimator, Scene};

/// The demo scene ([`Scene::DEMO`]) `(R1, R2, G, nu, mu)`, as a configuration block
/// would hold it.
static SCENE: [f64; 5] = [
    Scene::DEMO.r1(),
    Scene::DEMO.r2(),
    Scene::DEMO.shear_modulus(),
    Scene::DEMO.poisson_ratio(),
    Scene::DEMO.friction(),
];
/// One sample `(load, phi)`.
static SAMPLE: [f32; 2] = [1000.0, 2e-4];
/// The same sample for the fixed-point core: counts of [`LOAD_LSB`] and [`ANGLE_LSB`].
static COUNTS: (u32, i32) = (1_000_000, 20_000_000);

/// The fixed-point core's load LSB in the minimal images (N per count).
pub const LOAD_LSB: f64 = 1e-3;
/// The fixed-point core's angle LSB in the minimal images (rad per count).
pub const ANGLE_LSB: f64 = 1e-11;

fn read<T: Copy>(x: &T) -> T {
    // SAFETY: a reference is valid for a read.
    unsafe { core::ptr::read_volatile(x) }
}

/// The scene parameters.
pub fn scene() -> (f64, f64, f64, f64, f64) {
    (
        read(&SCENE[0]),
        read(&SCENE[1]),
        read(&SCENE[2]),
        read(&SCENE[3]),
        read(&SCENE[4]),
    )
}

/// The scene read from [`SCENE`], validated.
pub fn demo() -> Result<Scene, Error> {
    let (r1, r2, g, nu, mu) = scene();
    Scene::new(r1, r2, g, nu, mu)
}

/// What a minimal image does with the prepared core.
#[derive(Clone, Copy)]
pub enum Body {
    /// One estimate ([`estimate_once`]).
    Estimate,
    /// Nothing: the core is only kept ([`prepare_only`]).
    Prepare,
}

/// A minimal image: the demo scene prepared by the core of this target (`f32_core`
/// with an FPU, on the sample in N and rad; `fixed_core` without one, with the LSBs
/// [`LOAD_LSB`] and [`ANGLE_LSB`], on the sample in counts), then `body`.
pub fn image<F, X>(
    f32_core: impl FnOnce(&Scene) -> Result<F, Error>,
    fixed_core: impl FnOnce(&Scene, f64, f64) -> Result<X, Error>,
    body: Body,
) -> !
where
    F: Estimator<Load = f32, Angle = f32>,
    X: Estimator<Load = u32, Angle = i32>,
{
    let scene = demo();
    if cfg!(target_abi = "eabihf") {
        let core = scene.and_then(|s| f32_core(&s));
        match body {
            Body::Estimate => estimate_once(core, sample()),
            Body::Prepare => prepare_only(core, sample()),
        }
    } else {
        let core = scene.and_then(|s| fixed_core(&s, LOAD_LSB, ANGLE_LSB));
        match body {
            Body::Estimate => estimate_once(core, counts()),
            Body::Prepare => prepare_only(core, counts()),
        }
    }
}

/// The body of a minimal image with an estimator: exit 2 if the core was not
/// prepared, else one estimate of `sample` (in the core's numbers), emitted; exit 0,
/// or 1 if the core refused the sample.
pub fn estimate_once<E: Estimator>(prepared: Result<E, Error>, sample: (E::Load, E::Angle)) -> ! {
    let Ok(core) = prepared else { exit(2) };
    match core.estimate(sample.0, sample.1) {
        Ok(e) => {
            emit(e);
            exit(0)
        }
        Err(_) => exit(1),
    }
}

/// The body of a minimal image that only prepares: exit 2 if the core was not
/// prepared, else the core and the sample emitted (as if kept for later); exit 0.
pub fn prepare_only<E, S>(prepared: Result<E, Error>, sample: S) -> ! {
    let Ok(core) = prepared else { exit(2) };
    emit((core, sample));
    exit(0)
}

/// The sample `(load, phi)`.
pub fn sample() -> (f32, f32) {
    (read(&SAMPLE[0]), read(&SAMPLE[1]))
}

/// The sample as fixed-point counts `(load, angle)`.
pub fn counts() -> (u32, i32) {
    read(&COUNTS)
}

/// Keeps `x` alive, as if the answer went out in a report: the optimiser must compute
/// it, in memory, without knowing what happens to it.
pub fn emit<T>(x: T) {
    core::hint::black_box(x);
}

/// Semihosting exit.
pub fn exit(code: i32) -> ! {
    semihosting::process::exit(code)
}
