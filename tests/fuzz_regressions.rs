//! Inputs that `cargo xtask fuzz` found, kept as regression tests.

use misalign::float::EllipticScene;
use misalign::{Scene, reference};

/// Fuzz (reference): an absurd but valid scene (G = 1e-308 Pa, mu = 1e-312, R ~ 1e-311 m)
/// made line contact's d/b inf * 0 = NaN; products now carry their exponents apart.
#[test]
fn line_contact_with_extreme_scene_values() {
    let s = Scene::new(
        1.086461831314e-311,
        7.290259803442857e-304,
        1.1125369292536007e-308,
        0.0,
        1.35807730622e-312,
    )
    .unwrap();
    // The fuzzer's angle was -1.56e202 rad: above pi/2 it is now refused, as the cores do.
    let huge = reference::line(&s, 1.390671161566996e-309, -1.5576917880761318e202);
    assert_eq!(huge.err(), Some(misalign::Error::Angle));
    for phi in [-1.5, -1e-3] {
        let l = reference::line(&s, 1.390671161566996e-309, phi).unwrap();
        assert!(!l.slip_ratio.is_nan() && !l.axial_force.is_nan(), "{l:?}");
        assert!(
            l.critical_angle.is_finite() && l.critical_angle > 0.0,
            "{l:?}"
        );
    }
}

/// Fuzz (float_core): zero load at a subnormal angle made the details' p0 0/0 and n
/// underflow to 0 through g * (1/m).
#[test]
fn f32_details_at_zero_load_and_subnormal_angle() {
    let x = 0.0004767922794117647;
    let s = Scene::new(x, x, x, x, 0.00047679227941355493).unwrap();
    let d = EllipticScene::new(&s)
        .unwrap()
        .details(0.0, -3.903073e-39)
        .unwrap();
    assert!(
        [d.theta, d.m, d.n, d.a, d.b, d.p0]
            .iter()
            .all(|v| !v.is_nan()),
        "{d:?}"
    );
    assert!(d.n > 0.0 && d.p0 == 0.0);
}

/// Fuzz (reference): radii 1e92 and 1e-303 m make c underflow to 0; the exact relation
/// then divided 0/0 for phi0. Such a contact is a strip: the elliptic model says so.
#[test]
fn radius_factor_underflow_is_a_strip() {
    let s = Scene::new(
        6.518521340770791e91,
        7.290259803442857e-304,
        3.785766995733679e-270,
        2.952003749742552e-304,
        8.622161334340142e-308,
    )
    .unwrap()
    .with_theta_relation(misalign::ThetaRelation::Exact);
    assert_eq!(s.radius_factor(), 0.0);
    assert_eq!(
        reference::elliptic(&s, 2.590327e-318, -1.0).err(),
        Some(misalign::Error::PlaneHasNoEllipse)
    );
    assert_eq!(reference::critical_angle(&s, 1.0), None);
}

/// Fuzz (float_core): radii 5e-4 and 9e62 m (c = 4.6e-33) and a load of 1.9e-36 N gave
/// phi0 = NaN through log(0) in the asymptotic inverse. Such a scene is refused when
/// prepared (radii differing by more than 1e24), and the inverse returns 0 below 2^-100.
#[test]
fn f32_scene_with_radii_apart_by_more_than_1e24() {
    let s = Scene::new(
        0.0004767922794117647,
        9.127408091420644e62,
        0.0004767922794134512,
        0.00047679321141646033,
        0.0004767922794117647,
    )
    .unwrap();
    assert_eq!(
        EllipticScene::new(&s).err(),
        Some(misalign::Error::OutOfRange)
    );
    assert_eq!(
        misalign::float::kernels::small_theta::theta_small(1e-44),
        0.0
    );
    assert!(misalign::float::kernels::small_theta::theta_small(1e-20) > 0.0);
}

/// Fuzz (reference and float_core): mu P overflows while d/b underflows to 0, and
/// (mu P) * 0 was NaN; F is now mu (P F/(mu P)), which is 0 there.
#[test]
fn overflowing_mu_p_times_zero_ratio() {
    let s = Scene::new(
        1.086461831314e-311,
        7.290259803442857e-304,
        1.1125369292536007e-308,
        0.0,
        1.8926744494855492e154,
    )
    .unwrap();
    let e = reference::elliptic(&s, 2.6817251671999785e154, 7.29112201955619e-304).unwrap();
    assert_eq!(e.axial_force, 0.0);
    let s = Scene::new(
        0.0004767922794117647,
        0.0004768057835890966,
        1.4349289806516917e-42,
        0.00047679321141646033,
        5.764064971737949e20,
    )
    .unwrap();
    if let Ok(core) = EllipticScene::new(&s) {
        let e = core.estimate(1.2573343e38, 0.74315256).unwrap();
        assert!(!e.axial_force.is_nan());
    }
}

/// Fuzz (reference, in CI): at d/b = 0.9999997 eq (21) is 1 - 5e-17, and its sum
/// rounded one ulp above 1; F/(mu P) never exceeds 1.
#[test]
fn axial_force_ratio_never_exceeds_one() {
    use misalign::reference::tangential::axial_force_ratio;
    for s in [
        0.9999997112900018,
        1.0 - 1e-9,
        1.0 - f64::EPSILON,
        0.999_999,
    ] {
        let f = axial_force_ratio(s);
        assert!(f <= 1.0 && f > 0.999_999_999, "{s}: {f}");
    }
}
