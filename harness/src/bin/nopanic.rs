//! The no-panic proof (`cargo xtask nopanic`): an image with every per-sample path of
//! the estimator (the f32 core: `EllipticScene::estimate`, `details`,
//! `LineScene::estimate`; the fixed-point core: `FixedEllipticScene::estimate`,
//! `details`, `FixedLineScene::estimate`) and the scene preparation, fed from volatile reads so that
//! nothing is known at compile time. Its panic handler is panic-never's, which refers
//! to a symbol that does not exist: the image links only if the optimiser (release,
//! fat LTO: the `firmware` profile) removed every path to a panic. It also runs: in
//! QEMU it exits with 0.
#![cfg_attr(target_os = "none", no_std)]
#![cfg_attr(target_os = "none", no_main)]

#[cfg(target_os = "none")]
use panic_never as _;

#[cfg(target_os = "none")]
#[path = "../minimal/common.rs"]
mod io;

/// Which per-sample paths run: both cores.
#[cfg(target_os = "none")]
mod paths {
    use misalign::fixed::{FixedEllipticScene, FixedLineScene};
    use misalign::float::{EllipticScene, LineScene};
    use misalign::{Error, Scene};

    pub fn fixed_core(scene: &Scene, load: u32, angle: i32) -> Result<(), Error> {
        let (lsb_p, lsb_a) = (super::io::LOAD_LSB, super::io::ANGLE_LSB);
        let elliptic = FixedEllipticScene::new(scene, lsb_p, lsb_a)?;
        let line = FixedLineScene::new(scene, lsb_p, lsb_a)?;
        super::io::emit(elliptic.estimate(load, angle));
        super::io::emit(elliptic.details(load, angle));
        super::io::emit(line.estimate(load, angle));
        Ok(())
    }

    pub fn f32_core(scene: &Scene, load: f32, phi: f32) -> Result<(), Error> {
        let elliptic = EllipticScene::new(scene)?;
        let line = LineScene::new(scene)?;
        super::io::emit(elliptic.estimate(load, phi));
        super::io::emit(elliptic.details(load, phi));
        super::io::emit(line.estimate(load, phi));
        Ok(())
    }
}

#[cfg(target_os = "none")]
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

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("a firmware image: `cargo xtask nopanic` builds it for Cortex-M");
    std::process::exit(2);
}
