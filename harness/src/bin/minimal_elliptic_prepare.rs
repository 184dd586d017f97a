//! Minimal image that only prepares the elliptic scene and emits it:
//! `minimal_elliptic` minus this is the per-sample estimator (code and tables), this
//! minus `minimal_base` the preparation. It prepares with empty tables
//! ([`EllipticScene::with_tables`], which [`EllipticScene::new`] calls with the full
//! ones), so that the emitted scene keeps no table in the image.
#![cfg_attr(target_os = "none", no_std)]
#![cfg_attr(target_os = "none", no_main)]

#[cfg(target_os = "none")]
mod common;
#[cfg(target_os = "none")]
mod panic;

#[cfg(all(target_os = "none", target_abi = "eabihf"))]
#[cortex_m_rt::entry]
fn main() -> ! {
    use misalign::Scene;
    use misalign::float::{EllipticScene, Tables};
    use misalign::kernels::octave::OctaveTable;
    const NONE: OctaveTable<'static> = OctaveTable::new(0, &[]);
    let empty = Tables {
        g: NONE,
        theta_of_g: NONE,
    };
    let (r1, r2, g, nu, mu) = common::scene();
    let Ok(scene) =
        Scene::new(r1, r2, g, nu, mu).and_then(|s| EllipticScene::with_tables(&s, empty))
    else {
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
    use misalign::{Scene, fixed::FixedEllipticScene};
    let (r1, r2, g, nu, mu) = common::scene();
    let prepared = Scene::new(r1, r2, g, nu, mu)
        .and_then(|s| FixedEllipticScene::new(&s, common::LOAD_LSB, common::ANGLE_LSB));
    let Ok(scene) = prepared else { common::exit(2) };
    common::emit((scene, common::counts()));
    common::exit(0)
}

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("a firmware image: `cargo xtask firmware` builds it for Cortex-M");
    std::process::exit(2);
}
