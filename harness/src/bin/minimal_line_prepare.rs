//! Minimal image that only prepares the line-contact scene ([`LineScene::new`], f64)
//! and emits it: `minimal_line` minus this is the per-sample estimator, this minus
//! `minimal_base` the preparation.
#![cfg_attr(target_os = "none", no_std)]
#![cfg_attr(target_os = "none", no_main)]

#[cfg(target_os = "none")]
mod common;
#[cfg(target_os = "none")]
mod panic;

#[cfg(all(target_os = "none", target_abi = "eabihf"))]
#[cortex_m_rt::entry]
fn main() -> ! {
    use misalign::{Scene, float::LineScene};
    let (r1, r2, g, nu, mu) = common::scene();
    let Ok(scene) = Scene::new(r1, r2, g, nu, mu).and_then(|s| LineScene::new(&s)) else {
        common::exit(2)
    };
    let (load, phi) = common::sample();
    common::emit((scene, load, phi));
    common::exit(0)
}

/// Without an FPU (Cortex-M0, M3) the image holds the fixed-point core.
#[cfg(all(target_os = "none", not(target_abi = "eabihf")))]
#[cortex_m_rt::entry]
fn main() -> ! {
    use misalign::{Scene, fixed::FixedLineScene};
    let (r1, r2, g, nu, mu) = common::scene();
    let prepared = Scene::new(r1, r2, g, nu, mu)
        .and_then(|s| FixedLineScene::new(&s, common::LOAD_LSB, common::ANGLE_LSB));
    let Ok(scene) = prepared else { common::exit(2) };
    common::emit((scene, common::counts()));
    common::exit(0)
}

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("a firmware image: `cargo xtask firmware` builds it for Cortex-M");
    std::process::exit(2);
}
