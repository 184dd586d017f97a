//! The fixed-point core's public entry points on arbitrary scenes, LSBs and counts:
//! a typed error or an answer; never a panic or a wrapped value (debug assertions on).
#![no_main]

use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;
use misalign::Scene;
use misalign::fixed::logexp::{div3, exp2_fixed, log2_u32};
use misalign::fixed::{FixedEllipticScene, FixedLineScene, Log2};
use misalign::reference::Regime;

#[derive(Arbitrary, Debug)]
struct Input {
    r1: f64,
    r2: f64,
    g: f64,
    nu: f64,
    mu: f64,
    load_lsb: f64,
    angle_lsb: f64,
    load: u32,
    angle: i32,
    bits: u32,
    risk: f32,
}

fuzz_target!(|i: Input| {
    let _ = (log2_u32(i.load), exp2_fixed(i.angle, i.bits % 40), div3(i.angle & i32::MAX));
    let _ = Log2(i.angle).to_fixed(i.bits % 40);
    let Ok(scene) = Scene::new(i.r1, i.r2, i.g, i.nu, i.mu) else { return };
    if let Ok(core) = FixedEllipticScene::new(&scene, i.load_lsb, i.angle_lsb) {
        let core = core.with_risk_slip_ratio(i.risk).unwrap_or(core);
        if let Ok(e) = core.estimate(i.load, i.angle) {
            assert_eq!(e.regime == Regime::Gross, e.slip_ratio.0 >= 0 && e.slip_ratio != Log2::ZERO);
        }
        let _ = core.details(i.load, i.angle);
    }
    if let Ok(core) = FixedLineScene::new(&scene, i.load_lsb, i.angle_lsb) {
        let _ = core.estimate(i.load, i.angle);
    }
});
