//! The fixed-point core's public entry points on structured scenes, LSBs and counts
//! (extreme values: fuzz_targets/extreme.rs): a typed error or an answer; never a
//! panic or a wrapped value (debug assertions, so overflow checks, on), and at a load
//! above 0 no result that stands for 0 or infinity, with F <= mu P.
#![no_main]


use arbitrary::Arbitrary;
use misalign_fuzz::{Angle, Count, X64};
use libfuzzer_sys::fuzz_target;
use misalign::Scene;
use misalign::fixed::logexp::{div3, exp2_fixed, log2_u32};
use misalign::fixed::{FixedEllipticScene, FixedEstimate, FixedLineScene, Log2};
use misalign::reference::Regime;

#[derive(Arbitrary, Debug)]
struct Input {
    r1: X64,
    r2: X64,
    g: X64,
    nu: X64,
    mu: X64,
    load_lsb: X64,
    angle_lsb: X64,
    load: Count,
    angle: Angle,
    bits: u32,
    risk: X64,
}

/// What every accepted estimate must hold; `mu_p` is mu P in N.
fn check(model: &str, e: &FixedEstimate, load: u32, angle: i32, mu_p: f64) {
    let what = format!("{model} load {load} angle {angle}: {e:?}");
    assert_eq!(
        e.regime == Regime::Gross,
        e.slip_ratio.0 >= 0 && e.slip_ratio != Log2::ZERO,
        "{what}"
    );
    if load == 0 {
        return;
    }
    let special = [Log2::ZERO, Log2::INFINITY];
    assert!(
        !special.contains(&e.critical_angle.unwrap_or(Log2(0))),
        "{what}"
    );
    if angle != 0 {
        assert!(!special.contains(&e.slip_ratio), "{what}");
        assert!(!special.contains(&e.axial_force), "{what}");
        assert!(
            e.axial_force.to_f64() <= mu_p,
            "{what}: F above mu P = {mu_p:e}"
        );
    }
}

fuzz_target!(|i: Input| {
    let (load, angle) = (i.load.0, i.angle.0);
    let _ = (
        log2_u32(load),
        exp2_fixed(angle, i.bits % 40),
        div3(angle & i32::MAX),
    );
    let _ = Log2(angle).to_fixed(i.bits);
    let Ok(scene) = Scene::new(i.r1.0, i.r2.0, i.g.0, i.nu.0, i.mu.0) else {
        return;
    };
    let (load_lsb, angle_lsb) = (i.load_lsb.0, i.angle_lsb.0);
    let mu_p = scene.friction() * load as f64 * load_lsb;
    if let Ok(core) = FixedEllipticScene::new(&scene, load_lsb, angle_lsb) {
        let core = core.with_risk_slip_ratio(i.risk.0 as f32).unwrap_or(core);
        if let Ok(e) = core.estimate(load, angle) {
            check("elliptic", &e, load, angle, mu_p);
        }
        let _ = core.details(load, angle);
    }
    if let Ok(core) = FixedLineScene::new(&scene, load_lsb, angle_lsb) {
        let core = core.with_risk_slip_ratio(i.risk.0 as f32).unwrap_or(core);
        if let Ok(e) = core.estimate(load, angle) {
            check("line", &e, load, angle, mu_p);
        }
    }
});
