//! Minimal image that only prepares the line-contact scene ([`LineScene::new`], f64)
//! and emits it: `minimal_line` minus this is the per-sample estimator, this minus
//! `minimal_base` the preparation.
#![no_std]
#![no_main]

use misalign_harness::io;

misalign_harness::exit_on_panic!();

#[cfg(target_abi = "eabihf")]
#[cortex_m_rt::entry]
fn main() -> ! {
    use misalign::{Scene, float::LineScene};
    let (r1, r2, g, nu, mu) = io::scene();
    let Ok(scene) = Scene::new(r1, r2, g, nu, mu).and_then(|s| LineScene::new(&s)) else {
        io::exit(2)
    };
    let (load, phi) = io::sample();
    io::emit((scene, load, phi));
    io::exit(0)
}

/// Without an FPU (Cortex-M0, M3) the image holds the fixed-point core.
#[cfg(not(target_abi = "eabihf"))]
#[cortex_m_rt::entry]
fn main() -> ! {
    use misalign::{Scene, fixed::FixedLineScene};
    let (r1, r2, g, nu, mu) = io::scene();
    let prepared = Scene::new(r1, r2, g, nu, mu)
        .and_then(|s| FixedLineScene::new(&s, io::LOAD_LSB, io::ANGLE_LSB));
    let Ok(scene) = prepared else { io::exit(2) };
    io::emit((scene, io::counts()));
    io::exit(0)
}
