//! Bad and edge input for the f32 and fixed-point cores: typed errors, defined answers
//! at zero load and zero angle, no NaN: bad input never panics or answers NaN.

use misalign::fixed::{FixedEllipticScene, FixedLineScene, Log2};
use misalign::float::{EllipticScene, LineScene};
use misalign::reference::Regime;
use misalign::{Error, Scene, ThetaRelation};

fn scene() -> Scene {
    Scene::DEMO
}

#[test]
fn f32_bad_input_is_a_typed_error() {
    let e = EllipticScene::new(&scene()).unwrap();
    let l = LineScene::new(&scene()).unwrap();
    for load in [
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        -1.0,
        -f32::MIN_POSITIVE,
    ] {
        assert_eq!(e.estimate(load, 1e-4), Err(Error::Load), "{load}");
        assert_eq!(l.estimate(load, 1e-4), Err(Error::Load), "{load}");
        assert_eq!(e.details(load, 1e-4), Err(Error::Load));
    }
    for phi in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 2.0, -2.0] {
        assert_eq!(e.estimate(1e3, phi), Err(Error::Angle), "{phi}");
        assert_eq!(l.estimate(1e3, phi), Err(Error::Angle), "{phi}");
    }
    let plane = Scene::new(0.02, f64::INFINITY, 8e10, 0.3, 0.3).unwrap();
    assert!(matches!(
        EllipticScene::new(&plane),
        Err(Error::PlaneHasNoEllipse)
    ));
    assert!(LineScene::new(&plane).is_ok());
    let exact = scene().with_theta_relation(ThetaRelation::Exact);
    assert!(matches!(
        EllipticScene::new(&exact),
        Err(Error::Unsupported)
    ));
}

#[test]
fn f32_zero_load_and_zero_angle() {
    for est in [
        EllipticScene::new(&scene())
            .unwrap()
            .estimate(0.0, 1e-4)
            .unwrap(),
        LineScene::new(&scene())
            .unwrap()
            .estimate(0.0, -1e-4)
            .unwrap(),
    ] {
        assert_eq!((est.slip_ratio, est.regime), (f32::INFINITY, Regime::Gross));
        assert_eq!((est.axial_force, est.critical_angle), (0.0, Some(0.0)));
    }
    // -0 is a zero load, not a negative one.
    assert!(
        EllipticScene::new(&scene())
            .unwrap()
            .estimate(-0.0, 1e-4)
            .is_ok()
    );
    for est in [
        EllipticScene::new(&scene())
            .unwrap()
            .estimate(1e3, 0.0)
            .unwrap(),
        LineScene::new(&scene())
            .unwrap()
            .estimate(1e3, 0.0)
            .unwrap(),
        EllipticScene::new(&scene())
            .unwrap()
            .estimate(0.0, 0.0)
            .unwrap(),
    ] {
        assert_eq!(
            (est.slip_ratio, est.axial_force, est.regime),
            (0.0, 0.0, Regime::Partial)
        );
        assert!(est.critical_angle.is_some() && !est.microslip_risk);
    }
    let d = EllipticScene::new(&scene())
        .unwrap()
        .details(1e3, 0.0)
        .unwrap();
    assert_eq!(
        (d.m, d.n, d.a, d.b, d.p0),
        (f32::INFINITY, 0.0, f32::INFINITY, 0.0, 0.0)
    );
}

#[test]
fn f32_extreme_but_valid_input_gives_no_nan() {
    let e = EllipticScene::new(&scene()).unwrap();
    let l = LineScene::new(&scene()).unwrap();
    let loads = [1e-45, f32::MIN_POSITIVE, 1e-3, 1.0, 1e8, f32::MAX];
    let angles = [
        1e-45,
        1e-30,
        1e-12,
        1e-6,
        0.01,
        1.0,
        // The largest f32 below pi/2 (f32's FRAC_PI_2 lies above it: refused).
        f32::from_bits(core::f32::consts::FRAC_PI_2.to_bits() - 1),
        -1e-6,
    ];
    for &p in &loads {
        for &phi in &angles {
            for est in [e.estimate(p, phi).unwrap(), l.estimate(p, phi).unwrap()] {
                assert!(
                    !est.slip_ratio.is_nan() && !est.axial_force.is_nan(),
                    "{p} {phi}"
                );
                assert!(est.axial_force.abs() <= 0.3 * p * (1.0 + 1e-6), "{p} {phi}");
                assert_eq!(est.axial_force < 0.0, phi < 0.0 && est.axial_force != 0.0);
                if let Some(c) = est.critical_angle {
                    assert!(c.is_finite() && c >= 0.0, "{p} {phi}: {c}");
                }
            }
            let d = e.details(p, phi).unwrap();
            for x in [d.theta, d.m, d.n, d.a, d.b, d.p0] {
                assert!(!x.is_nan(), "{p} {phi}: {d:?}");
            }
        }
    }
    // Above g(pi/2) there is no critical angle at all.
    assert_eq!(e.estimate(f32::MAX, 1e-3).unwrap().critical_angle, None);
}

#[test]
fn fixed_inputs_outside_the_declared_range_are_errors() {
    let e = FixedEllipticScene::new(&scene(), 0.01, 1e-7).unwrap();
    let range = e.input_range();
    assert!(range.angle_max > 1_000_000);
    let over = range.angle_max as i64 + 1;
    if over <= i32::MAX as i64 {
        assert_eq!(e.estimate(1000, over as i32), Err(Error::Angle));
        assert_eq!(e.estimate(1000, -(over as i32)), Err(Error::Angle));
    }
    assert!(e.estimate(1000, range.angle_max as i32).is_ok());
    // Every u32 load and every angle in range gives an answer, never a wrapped one.
    for load in [0, 1, 2, 1000, u32::MAX / 3, u32::MAX] {
        for angle in [i32::MIN + 1, -1, 0, 1, 12345, range.angle_max as i32] {
            if angle.unsigned_abs() > range.angle_max {
                continue;
            }
            let est = e.estimate(load, angle).unwrap();
            assert_eq!(
                est.regime == Regime::Gross,
                est.slip_ratio.0 >= 0,
                "{load} {angle}"
            );
        }
    }
    let l = FixedLineScene::new(&scene(), 0.01, 1e-7).unwrap();
    assert_eq!(l.estimate(1000, i32::MIN), Err(Error::Angle));
    for lsb in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(FixedEllipticScene::new(&scene(), lsb, 1e-7).is_err());
        assert!(FixedLineScene::new(&scene(), 1.0, lsb).is_err());
    }
    // An angle LSB below the tables' theta = 2^-40 is refused when preparing.
    assert_eq!(
        FixedEllipticScene::new(&scene(), 0.01, 1e-13).err(),
        Some(Error::OutOfRange)
    );
}

#[test]
fn fixed_zero_load_and_zero_angle() {
    let e = FixedEllipticScene::new(&scene(), 0.01, 1e-7).unwrap();
    let z = e.estimate(0, 100).unwrap();
    assert_eq!(
        (z.slip_ratio, z.axial_force, z.regime),
        (Log2::INFINITY, Log2::ZERO, Regime::Gross)
    );
    assert_eq!((z.critical_angle, z.margin), (Some(Log2::ZERO), Some(-100)));
    let z = e.estimate(100_000, 0).unwrap();
    assert_eq!(
        (z.slip_ratio, z.axial_force, z.regime),
        (Log2::ZERO, Log2::ZERO, Regime::Partial)
    );
    assert!(z.margin.unwrap() > 0);
    assert_eq!(Log2::ZERO.to_f64(), 0.0);
    assert_eq!(Log2::INFINITY.to_f64(), f64::INFINITY);
    assert_eq!(Log2::from_f64(0.0), Err(Error::OutOfRange));
}

/// The demo scene is a valid scene: exactly what `Scene::new` makes of its values.
#[test]
fn the_demo_scene_is_what_new_makes_of_its_values() {
    let d = Scene::DEMO;
    let made = Scene::new(
        d.r1(),
        d.r2(),
        d.shear_modulus(),
        d.poisson_ratio(),
        d.friction(),
    );
    assert_eq!(made, Ok(d));
    assert_eq!(d.length(), None);
    assert_eq!(d.theta_relation(), ThetaRelation::SmallAngle);
}
