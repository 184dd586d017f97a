//! The minimal images (`cargo xtask firmware`'s size table) and the no-panic images:
//! inputs from flash through volatile reads (so that nothing is folded at compile
//! time, as for a scene read from a configuration block and samples from a sensor),
//! outputs through `black_box`, exit through semihosting. No logger: the images hold
//! the estimator and as little else as possible.

use misalign::Scene;

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

/// The fixed-point core's LSBs in the minimal images (N and rad per count), from the
/// build script, which prepares the build-time scenes with the same.
pub use crate::prepared::{ANGLE_LSB, LOAD_LSB};

/// `*x` through a volatile read: the optimiser cannot know the value.
pub fn read<T: Copy>(x: &T) -> T {
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
