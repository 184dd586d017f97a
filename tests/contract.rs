//! The estimator contract: every prepared scene of both cores answers through
//! `Estimator`, and the fixed-point core's SI answers match the f32 core's.

use misalign::fixed::FixedAuto;
use misalign::fixed::{FixedEllipticScene, FixedLineScene, Log2};
use misalign::float::{Auto, EllipticScene, LineScene};
use misalign::{Error, Estimate, Estimator, Scene};

fn scene() -> Scene {
    Scene::DEMO
}

/// Relative difference, with both zero or both infinite counting as equal.
fn rel(a: f32, b: f32) -> f32 {
    if a == b { 0.0 } else { ((a - b) / b).abs() }
}

/// Both SI answers agree within `tol` (margin absolute, to `tol` of phi0).
fn agree(a: &Estimate, b: &Estimate, tol: f32) {
    assert_eq!(a.regime, b.regime, "{a:?} {b:?}");
    assert_eq!(a.microslip_risk, b.microslip_risk, "{a:?} {b:?}");
    assert!(rel(a.slip_ratio, b.slip_ratio) <= tol, "{a:?} {b:?}");
    assert!(rel(a.axial_force, b.axial_force) <= tol, "{a:?} {b:?}");
    let (c, d) = (a.critical_angle.unwrap(), b.critical_angle.unwrap());
    assert!(rel(c, d) <= tol, "{a:?} {b:?}");
    let (m, n) = (a.margin.unwrap(), b.margin.unwrap());
    assert!((m - n).abs() <= tol * c.max(n.abs()) + 1e-11, "{a:?} {b:?}");
}

/// Every estimate of a generic caller, over loads and signed angles.
fn sweep<E: Estimator>(core: &E) -> Vec<Estimate> {
    let mut out = Vec::new();
    for load in [10.0, 1e3, 3e4, 1e6] {
        for phi in [-3e-3, -1e-4, 2e-6, 2e-4, 1e-3, 1e-2] {
            out.push(core.estimate_si(load, phi).unwrap());
        }
    }
    out
}

#[test]
fn fixed_and_f32_cores_agree_through_the_contract() {
    let s = scene();
    let float = sweep(&EllipticScene::new(&s).unwrap());
    // 0.1 nrad per count: margins up to 0.21 rad fit an i32 (finer LSBs saturate it).
    let fixed = sweep(&FixedEllipticScene::new(&s, 1e-3, 1e-10).unwrap());
    for (a, b) in float.iter().zip(&fixed) {
        agree(a, b, 2e-5);
    }
    let line = s.with_length(0.1).unwrap();
    let float = sweep(&LineScene::new(&line).unwrap());
    let fixed = sweep(&FixedLineScene::new(&line, 1e-3, 1e-10).unwrap());
    for (a, b) in float.iter().zip(&fixed) {
        agree(a, b, 2e-5);
    }
}

#[test]
fn f32_contract_is_the_scene_itself() {
    let s = scene();
    let core = EllipticScene::new(&s).unwrap();
    // Without a length section 9 takes the ellipse for every sample.
    let auto = Auto::new(&s).unwrap();
    for (load, phi) in [(1e3, 2e-4), (0.0, 1e-3), (5e3, -1e-2), (1.0, 0.0)] {
        let want = core.estimate(load, phi).unwrap();
        assert_eq!(Estimator::estimate(&core, load, phi).unwrap(), want);
        assert_eq!(core.estimate_si(load, phi).unwrap(), want);
        assert_eq!(auto.estimate_si(load, phi).unwrap(), want);
    }
    assert_eq!(core.estimate_si(f32::NAN, 0.0), Err(Error::Load));
    assert_eq!(core.estimate_si(1.0, f32::INFINITY), Err(Error::Angle));
}

#[test]
fn fixed_input_conversion_refuses_what_does_not_fit() {
    let core = FixedEllipticScene::new(&scene(), 1e-3, 1e-11).unwrap();
    assert_eq!(core.input(1.0, -2e-9), Ok((1000, -200)));
    assert_eq!(core.input(-0.0, 0.0), Ok((0, 0)));
    assert_eq!(core.input(-1.0, 0.0), Err(Error::Load));
    assert_eq!(core.input(f32::NAN, 0.0), Err(Error::Load));
    assert_eq!(core.input(f32::INFINITY, 0.0), Err(Error::Load));
    assert_eq!(core.input(1.0, f32::NAN), Err(Error::Angle));
    assert_eq!(core.input(1.0, f32::NEG_INFINITY), Err(Error::Angle));
    // 5e6 N is 5e9 counts of 1 mN: more than a u32 holds.
    assert_eq!(core.input(5e6, 0.0), Err(Error::OutOfRange));
    // 0.03 rad is 3e9 counts of 10 prad: more than an i32 holds.
    assert_eq!(core.input(1.0, -0.03), Err(Error::OutOfRange));
    assert_eq!(core.estimate_si(5e6, 0.0), Err(Error::OutOfRange));
}

#[test]
fn risk_threshold_is_set_the_same_way_in_every_core() {
    let s = scene();
    fn check<E: Estimator + Copy>(core: E) {
        assert!((core.risk_slip_ratio() - 0.8).abs() < 1e-6);
        let low = core.with_risk_slip_ratio(0.5).unwrap();
        assert!((low.risk_slip_ratio() - 0.5).abs() < 1e-6);
        // d/b = 0.63 at 1 kN and 0.2 mrad: flagged at 0.5, not at 0.8.
        assert!(!core.estimate_si(1e3, 2e-4).unwrap().microslip_risk);
        assert!(low.estimate_si(1e3, 2e-4).unwrap().microslip_risk);
        for bad in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            assert_eq!(
                core.with_risk_slip_ratio(bad).err(),
                Some(Error::OutOfRange)
            );
        }
    }
    check(EllipticScene::new(&s).unwrap());
    check(FixedEllipticScene::new(&s, 1e-3, 1e-11).unwrap());
    // Rollers 1 m long: the ellipse fits, section 9 takes it.
    let long = s.with_length(1.0).unwrap();
    check(Auto::new(&long).unwrap());
    check(FixedAuto::new(&long, 1e-3, 1e-10).unwrap());
}

#[test]
fn log2_to_f32_is_within_its_bound_over_every_fraction() {
    // Every Q8.24 fraction, at one exponent; then the limits of f32's range.
    let bound = misalign::fixed::EXP2_MAX_REL_ERROR + f32::EPSILON as f64 / 2.0;
    let mut worst: f64 = 0.0;
    for f in (0..1 << 24).step_by(7) {
        let l = (-3 << 24) + f;
        let want = (l as f64 / (1 << 24) as f64).exp2();
        worst = worst.max((Log2(l).to_f32() as f64 / want - 1.0).abs());
    }
    assert!(worst <= bound, "{worst:e}");
    assert_eq!(Log2::ZERO.to_f32(), 0.0);
    assert_eq!(Log2::INFINITY.to_f32(), f32::INFINITY);
    assert!(Log2(i32::MAX - 1).to_f32().is_finite());
    assert_eq!(Log2(-127 << 24).to_f32(), 0.0);
    assert_eq!(Log2(-126 << 24).to_f32(), f32::MIN_POSITIVE);
    assert_eq!(Log2(5 << 24).to_f32(), 32.0);
}
