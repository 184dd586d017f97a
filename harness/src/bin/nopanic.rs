//! The no-panic proof (`cargo xtask nopanic`): an image with every per-sample path of
//! the estimator (the f32 core: `EllipticScene::estimate`, `details`,
//! `LineScene::estimate`; the fixed-point core: `FixedEllipticScene::estimate`,
//! `details`, `FixedLineScene::estimate`) and the scene preparation, fed from volatile reads so that
//! nothing is known at compile time. Its panic handler is panic-never's, which refers
//! to a symbol that does not exist: the image links only if the optimiser (release,
//! fat LTO: the `firmware` profile) removed every path to a panic. It also runs: in
//! QEMU it exits with 0.
#![no_std]
#![no_main]

use panic_never as _;

use misalign_harness::io;

/// Which per-sample paths run: both cores.
mod paths {
    use misalign::fixed::{FixedEllipticScene, FixedLineScene};
    use misalign::float::{EllipticScene, LineScene};
    use misalign::{Error, Scene};
    use misalign_harness::io;

    pub fn fixed_core(scene: &Scene, load: u32, angle: i32) -> Result<(), Error> {
        let (lsb_p, lsb_a) = (io::LOAD_LSB, io::ANGLE_LSB);
        let elliptic = FixedEllipticScene::new(scene, lsb_p, lsb_a)?;
        let line = FixedLineScene::new(scene, lsb_p, lsb_a)?;
        io::emit(elliptic.estimate(load, angle));
        io::emit(elliptic.details(load, angle));
        io::emit(line.estimate(load, angle));
        Ok(())
    }

    pub fn f32_core(scene: &Scene, load: f32, phi: f32) -> Result<(), Error> {
        let elliptic = EllipticScene::new(scene)?;
        let line = LineScene::new(scene)?;
        io::emit(elliptic.estimate(load, phi));
        io::emit(elliptic.details(load, phi));
        io::emit(line.estimate(load, phi));
        Ok(())
    }
}

#[cortex_m_rt::entry]
fn main() -> ! {
    let (r1, r2, g, nu, mu) = io::scene();
    let (load, phi) = io::sample();
    let (load_counts, angle_counts) = io::counts();
    let result = misalign::Scene::new(r1, r2, g, nu, mu).and_then(|scene| {
        paths::f32_core(&scene, load, phi)?;
        paths::fixed_core(&scene, load_counts, angle_counts)
    });
    semihosting::process::exit(if result.is_ok() { 0 } else { 1 })
}
