//! Minimal image that only prepares the elliptic scene and emits it:
//! `minimal_elliptic` minus this is the per-sample estimator (code and tables), this
//! minus `minimal_base` the preparation. It prepares with empty tables
//! ([`EllipticScene::with_tables`], which [`EllipticScene::new`] calls with the full
//! ones), so that the emitted scene keeps no table in the image.
#![no_std]
#![no_main]

use misalign_harness::io;

misalign_harness::exit_on_panic!();

#[cfg(target_abi = "eabihf")]
#[cortex_m_rt::entry]
fn main() -> ! {
    use misalign::Scene;
    use misalign::float::octave::{OctaveTable, WIDE};
    use misalign::float::{EllipticScene, Tables};
    const NONE: OctaveTable<'static, WIDE> = OctaveTable::new(0, &[]);
    let empty = Tables {
        g: NONE,
        theta_of_g: NONE,
    };
    let (r1, r2, g, nu, mu) = io::scene();
    let Ok(scene) =
        Scene::new(r1, r2, g, nu, mu).and_then(|s| EllipticScene::with_tables(&s, empty))
    else {
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
    use misalign::{Scene, fixed::FixedEllipticScene};
    let (r1, r2, g, nu, mu) = io::scene();
    let prepared = Scene::new(r1, r2, g, nu, mu)
        .and_then(|s| FixedEllipticScene::new(&s, io::LOAD_LSB, io::ANGLE_LSB));
    let Ok(scene) = prepared else { io::exit(2) };
    io::emit((scene, io::counts()));
    io::exit(0)
}
