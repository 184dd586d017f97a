//! Minimal image with the elliptic estimator: prepares the scene once
//! ([`EllipticScene::new`], f64) and estimates one sample. Its flash minus that of
//! `minimal_elliptic_prepare` is the per-sample estimator (code and tables).
#![no_std]
#![no_main]

use misalign_harness::io;

misalign_harness::exit_on_panic!();

#[cfg(target_abi = "eabihf")]
#[cortex_m_rt::entry]
fn main() -> ! {
    use misalign::{Scene, float::EllipticScene};
    let (r1, r2, g, nu, mu) = io::scene();
    let Ok(scene) = Scene::new(r1, r2, g, nu, mu).and_then(|s| EllipticScene::new(&s)) else {
        io::exit(2)
    };
    let (load, phi) = io::sample();
    match scene.estimate(load, phi) {
        Ok(e) => {
            io::emit(e);
            io::exit(0)
        }
        Err(_) => io::exit(1),
    }
}

/// Without an FPU (Cortex-M0, M3) the image holds the fixed-point core.
#[cfg(not(target_abi = "eabihf"))]
#[cortex_m_rt::entry]
fn main() -> ! {
    use misalign::{Scene, fixed::FixedEllipticScene};
    let (r1, r2, g, nu, mu) = io::scene();
    let prepared = Scene::new(r1, r2, g, nu, mu)
        .and_then(|s| FixedEllipticScene::new(&s, io::LOAD_LSB, io::ANGLE_LSB));
    let Ok(scene) = prepared else { io::exit(2) };
    let (load, angle) = io::counts();
    match scene.estimate(load, angle) {
        Ok(e) => {
            io::emit(e);
            io::exit(0)
        }
        Err(_) => io::exit(1),
    }
}
