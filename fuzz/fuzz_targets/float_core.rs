//! The f32 core's public entry points on arbitrary scenes and samples: a typed error
//! or non-NaN results with |F| <= mu P.
#![no_main]

use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;
use misalign::Scene;
use misalign::float::{EllipticScene, LineScene};
use misalign::float::kernels::{axial_force, cbrt, sqrt};

#[derive(Arbitrary, Debug)]
struct Input {
    r1: f64,
    r2: f64,
    g: f64,
    nu: f64,
    mu: f64,
    load: f32,
    phi: f32,
    risk: f32,
}

fuzz_target!(|i: Input| {
    let _ = (cbrt::cbrt(i.load), sqrt::inv_sqrt(i.load), axial_force::axial_force_ratio(i.phi));
    let Ok(scene) = Scene::new(i.r1, i.r2, i.g, i.nu, i.mu) else { return };
    if let Ok(core) = EllipticScene::new(&scene) {
        let core = core.with_risk_slip_ratio(i.risk).unwrap_or(core);
        if let Ok(e) = core.estimate(i.load, i.phi) {
            assert!(!e.slip_ratio.is_nan() && !e.axial_force.is_nan(), "{e:?}");
            assert!(e.axial_force.abs() <= scene.friction() as f32 * i.load * 1.000_001);
            assert!(e.critical_angle.is_none_or(|c| c >= 0.0 && c.is_finite()));
        }
        if let Ok(d) = core.details(i.load, i.phi) {
            assert!(![d.theta, d.m, d.n, d.a, d.b, d.p0].iter().any(|x| x.is_nan()), "{d:?}");
        }
    }
    if let Ok(core) = LineScene::new(&scene) {
        if let Ok(e) = core.estimate(i.load, i.phi) {
            assert!(!e.slip_ratio.is_nan() && !e.axial_force.is_nan(), "{e:?}");
        }
    }
});
