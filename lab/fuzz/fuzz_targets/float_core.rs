//! The f32 core's public entry points on structured scenes and samples (extreme
//! values: fuzz_targets/extreme.rs): a typed error, or at a load above 0 a finite d/b,
//! |F| <= mu P, a normal phi0 and a finite margin; never NaN.
#![no_main]


use arbitrary::Arbitrary;
use misalign_fuzz::{X32, X64};
use libfuzzer_sys::fuzz_target;
use misalign::Scene;
use misalign::float::kernels::{axial_force, cbrt, sqrt};
use misalign::float::{Auto, EllipticScene, Estimate, LineScene};

#[derive(Arbitrary, Debug)]
struct Input {
    r1: X64,
    r2: X64,
    g: X64,
    nu: X64,
    mu: X64,
    load: X32,
    phi: X32,
    risk: X32,
    length: X64,
}

/// What every accepted estimate must hold. |F| <= mu P in the core's own f32
/// arithmetic: F = mu (P ratio) with ratio <= 1 cannot round above mu P, subnormal
/// loads included.
fn check(model: &str, e: &Estimate, mu: f32, load: f32) {
    let what = format!("{model} P {load:e}: {e:?}");
    assert!(!e.slip_ratio.is_nan() && !e.axial_force.is_nan(), "{what}");
    assert!(e.axial_force.abs() <= mu * load.abs(), "{what}");
    if load > 0.0 {
        assert!(
            e.slip_ratio.is_finite() && e.axial_force.is_finite(),
            "{what}"
        );
        assert!(
            e.critical_angle.is_none_or(|c| c.is_normal() && c > 0.0),
            "{what}"
        );
    }
    assert!(e.margin.is_none_or(f32::is_finite), "{what}");
}

fuzz_target!(|i: Input| {
    let (load, phi) = (i.load.0, i.phi.0);
    let _ = (
        cbrt::cbrt(load),
        sqrt::inv_sqrt(load),
        axial_force::axial_force_ratio(phi),
    );
    let Ok(scene) = Scene::new(i.r1.0, i.r2.0, i.g.0, i.nu.0, i.mu.0) else {
        return;
    };
    let mu = scene.friction() as f32;
    if let Ok(core) = EllipticScene::new(&scene) {
        let core = core.with_risk_slip_ratio(i.risk.0).unwrap_or(core);
        if let Ok(e) = core.estimate(load, phi) {
            check("elliptic", &e, mu, load);
        }
        if let Ok(d) = core.details(load, phi) {
            assert!(
                ![d.theta, d.m, d.n, d.a, d.b, d.p0]
                    .iter()
                    .any(|x| x.is_nan()),
                "{d:?}"
            );
        }
    }
    if let Ok(core) = LineScene::new(&scene) {
        let core = core.with_risk_slip_ratio(i.risk.0).unwrap_or(core);
        let (lightest, heaviest) = core.load_range();
        assert!(0.0 < lightest && lightest <= heaviest && heaviest.is_finite());
        if let Ok(e) = core.estimate(load, phi) {
            check("line", &e, mu, load);
        }
    }
    if let Ok(with_length) = scene.with_length(i.length.0)
        && let Ok(auto) = Auto::new(&with_length)
        && let Ok(e) = auto.estimate(load, phi)
    {
        check("auto", &e.estimate, mu, load);
    }
});
