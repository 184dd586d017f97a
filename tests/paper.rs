//! The paper's own claims and the classical results the reference must reproduce.

use misalign::reference::{self, Regime, normal, tangential};
use misalign::{Error, Scene};

/// Timoshenko & Goodier, Theory of Elasticity, section 140: theta (deg), m, n to 3
/// decimals. The reference README names the misprints: 5 of 13 rows are off in the
/// third decimal, worst 0.0016 in m (55 deg) and 0.0021 in n (70 deg).
const TIMOSHENKO_GOODIER: [(f64, f64, f64); 13] = [
    (30.0, 2.731, 0.493),
    (35.0, 2.397, 0.530),
    (40.0, 2.136, 0.567),
    (45.0, 1.926, 0.604),
    (50.0, 1.754, 0.641),
    (55.0, 1.611, 0.678),
    (60.0, 1.486, 0.717),
    (65.0, 1.378, 0.759),
    (70.0, 1.284, 0.802),
    (75.0, 1.202, 0.846),
    (80.0, 1.128, 0.893),
    (85.0, 1.061, 0.944),
    (90.0, 1.000, 1.000),
];
const MISPRINTED_ROWS: [f64; 5] = [35.0, 55.0, 65.0, 70.0, 75.0];

#[test]
fn timoshenko_goodier_table() {
    for (deg, m, n) in TIMOSHENKO_GOODIER {
        let s = normal::ellipse_shape(deg.to_radians()).unwrap();
        let (dm, dn) = ((s.m - m).abs(), (s.n - n).abs());
        if MISPRINTED_ROWS.contains(&deg) {
            assert!(
                dm <= 0.0016 + 5e-5 && dn <= 0.0021 + 5e-5,
                "{deg} deg: m {} n {}",
                s.m,
                s.n
            );
            assert!(
                dm > 0.0005 || dn > 0.0005,
                "{deg} deg is no misprint after all"
            );
        } else {
            // Correct to 3 decimals: within half a unit of the last place.
            assert!(
                dm <= 0.0005 && dn <= 0.0005,
                "{deg} deg: m {} n {}",
                s.m,
                s.n
            );
        }
    }
}

#[test]
fn round_contact_at_ninety_degrees() {
    let s = normal::ellipse_shape(core::f64::consts::FRAC_PI_2).unwrap();
    assert!(
        (s.m - 1.0).abs() < 1e-15 && (s.n - 1.0).abs() < 1e-15 && (s.kprime - 1.0).abs() < 1e-15
    );
}

/// Section 9: p(0)/G = 0.005 and mu = 0.3 give phi0 = 0.003 rad (eq 30), and for equal
/// radii a/b = 1876.6 there (not 1100: that belongs to theta = 0.00494, README).
#[test]
fn paper_example_critical_angle() {
    let (g, mu) = (79.3e9, 0.3);
    let scene = Scene::new(0.05, 0.05, g, 0.3, mu).unwrap();
    // The load at which phi0 = 0.003: d/b = 1 at phi = 0.003 is the critical load there.
    let at = reference::elliptic(&scene, 1.0, 0.003).unwrap();
    let load = at.critical_load;
    let e = reference::elliptic(&scene, load, 0.003).unwrap();
    assert!((e.slip_ratio - 1.0).abs() < 1e-13, "{}", e.slip_ratio);
    assert!((e.p0 / g - 0.005).abs() < 1e-15, "p0/G = {}", e.p0 / g);
    assert!((e.critical_angle.unwrap() / 0.003 - 1.0).abs() < 1e-13);
    let a_over_b = e.a / e.b;
    assert!((a_over_b - 1876.6).abs() < 0.05, "a/b = {a_over_b}");
    let s = normal::ellipse_shape(0.00494).unwrap();
    assert!((s.m / s.n - 1100.0).abs() < 2.0, "a/b = {}", s.m / s.n);
}

/// Eq (30), phi0 = 2 mu p0 / G with p0 taken at phi0, holds for any scene.
#[test]
fn eq30_holds_at_the_critical_angle() {
    for (r1, r2, load, mu) in [
        (0.02, 0.03, 500.0, 0.1),
        (0.5, 0.001, 1e4, 0.6),
        (0.1, 0.1, 2.0, 0.2),
    ] {
        let scene = Scene::new(r1, r2, 8e10, 0.28, mu).unwrap();
        let phi0 = reference::critical_angle(&scene, load).unwrap().0;
        let e = reference::elliptic(&scene, load, phi0).unwrap();
        assert!((phi0 / (2.0 * mu * e.p0 / 8e10) - 1.0).abs() < 1e-13);
        assert!((e.slip_ratio - 1.0).abs() < 1e-13);
    }
}

/// Reference README: m's small-theta asymptotic is off by about 3.6e-6 at theta = 1e-2
/// and 3.4e-8 at 1e-3, and the error falls like theta^2.
#[test]
fn small_theta_asymptotics() {
    for (theta, err) in [(1e-2, 3.6e-6), (1e-3, 3.4e-8)] {
        let exact = normal::ellipse_shape(theta).unwrap();
        let asym = normal::small_theta_shape(theta);
        let e = (asym.m / exact.m - 1.0).abs();
        assert!((e / err - 1.0).abs() < 0.05, "theta {theta}: {e:e}");
    }
    for theta in [1e-7, 1e-9, 1e-12, 1e-50, 1e-99] {
        let exact = normal::ellipse_shape(theta).unwrap();
        let asym = normal::small_theta_shape(theta);
        for (x, y) in [
            (exact.m, asym.m),
            (exact.n, asym.n),
            (exact.kprime, asym.kprime),
        ] {
            assert!((x / y - 1.0).abs() < 2e-15, "theta {theta}: {x} {y}");
        }
    }
}

fn scene() -> Scene {
    Scene::new(0.04, 0.06, 8e10, 0.3, 0.25).unwrap()
}

#[test]
fn axial_force_is_odd_in_phi() {
    let s = scene();
    for phi in [1e-9, 1e-6, 2e-4, 3e-3, 0.05] {
        let (p, n) = (
            reference::elliptic(&s, 2e3, phi).unwrap(),
            reference::elliptic(&s, 2e3, -phi).unwrap(),
        );
        assert_eq!(p.axial_force, -n.axial_force);
        assert_eq!(p.slip_ratio, n.slip_ratio);
        let (p, n) = (
            reference::line(&s, 1e5, phi).unwrap(),
            reference::line(&s, 1e5, -phi).unwrap(),
        );
        assert_eq!(p.axial_force, -n.axial_force);
    }
}

/// F(phi) and its first two derivatives are continuous at d/b = 1 (eq 21: dF/ds and
/// d2F/ds2 vanish there), so one-sided differences on both sides agree.
#[test]
fn axial_force_is_smooth_at_gross_slip() {
    let s = scene();
    let load = 2e3;
    let phi0 = reference::critical_angle(&s, load).unwrap().0;
    let f = |phi: f64| reference::elliptic(&s, load, phi).unwrap().axial_force;
    let h = phi0 * 1e-3;
    let (below, at, above) = (f(phi0 - h), f(phi0), f(phi0 + h));
    assert!((at - 0.25 * load).abs() < 1e-12 * load);
    // F = mu P - O(h^2.5) below, mu P above: the jump and both slopes vanish with h.
    let scale = 0.25 * load;
    assert!((at - below) / scale < 1e-6, "jump {}", at - below);
    // At phi0 itself d/b is 1 to the last ulp (either side), so F is mu P to rounding.
    assert_eq!(above, scale);
    assert!((above - at).abs() <= 1e-15 * scale);
    let slope_below = (at - below) / h * phi0 / scale;
    let slope_above = (above - at) / h * phi0 / scale;
    assert!(slope_below.abs() < 1e-4 && slope_above.abs() < 1e-12);
    // Second difference below ~ h^0.5: small, and falling as h falls.
    let second =
        |h: f64| (f(phi0) - 2.0 * f(phi0 - h) + f(phi0 - 2.0 * h)) / (h * h) * phi0 * phi0 / scale;
    assert!(second(phi0 * 1e-2).abs() > second(phi0 * 1e-4).abs());
    assert!(second(phi0 * 1e-4).abs() < 0.1);
    // The analytic slopes of eq (21) vanish at s = 1.
    assert_eq!(tangential::axial_force_ratio_slope(1.0), 0.0);
    assert!(tangential::axial_force_ratio_slope(1.0 - 1e-8) < 1e-11);
}

#[test]
fn zero_load_and_zero_angle_have_defined_answers() {
    let s = scene();
    let e = reference::elliptic(&s, 0.0, 1e-3).unwrap();
    assert_eq!((e.a, e.b, e.p0, e.axial_force), (0.0, 0.0, 0.0, 0.0));
    assert_eq!(
        (e.slip_ratio, e.regime, e.critical_angle),
        (f64::INFINITY, Regime::Gross, Some(0.0))
    );
    let e = reference::elliptic(&s, 1e3, 0.0).unwrap();
    assert_eq!(
        (e.slip_ratio, e.axial_force, e.p0, e.regime),
        (0.0, 0.0, 0.0, Regime::Partial)
    );
    assert!(e.a.is_infinite() && e.critical_angle.is_some());
    let e = reference::elliptic(&s, 0.0, 0.0).unwrap();
    assert_eq!((e.slip_ratio, e.axial_force), (0.0, 0.0));
    let l = reference::line(&s, 0.0, 1e-3).unwrap();
    assert_eq!(
        (l.b, l.p0, l.axial_force, l.critical_angle),
        (0.0, 0.0, 0.0, Some(0.0))
    );
}

#[test]
fn bad_input_gets_a_typed_error() {
    assert_eq!(Scene::new(f64::NAN, 1.0, 1.0, 0.3, 0.3), Err(Error::Radius));
    assert_eq!(Scene::new(1.0, 0.0, 1.0, 0.3, 0.3), Err(Error::Radius));
    assert_eq!(
        Scene::new(f64::INFINITY, 1.0, 1.0, 0.3, 0.3),
        Err(Error::Radius)
    );
    assert_eq!(
        Scene::new(1.0, 1.0, -1.0, 0.3, 0.3),
        Err(Error::ShearModulus)
    );
    assert_eq!(
        Scene::new(1.0, 1.0, 1.0, 0.5 + 1e-12, 0.3),
        Err(Error::PoissonRatio)
    );
    assert_eq!(
        Scene::new(1.0, 1.0, 1.0, -0.1, 0.3),
        Err(Error::PoissonRatio)
    );
    assert_eq!(Scene::new(1.0, 1.0, 1.0, 0.3, 0.0), Err(Error::Friction));
    assert_eq!(scene().with_length(f64::NAN), Err(Error::Length));
    let s = scene();
    for load in [f64::NAN, f64::INFINITY, -1.0] {
        assert_eq!(reference::elliptic(&s, load, 1e-3), Err(Error::Load));
        assert_eq!(reference::line(&s, load, 1e-3), Err(Error::Load));
    }
    for phi in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 2.0] {
        assert_eq!(reference::elliptic(&s, 1.0, phi), Err(Error::Angle));
    }
    let plane = Scene::new(0.02, f64::INFINITY, 8e10, 0.3, 0.3).unwrap();
    assert_eq!(
        reference::elliptic(&plane, 1.0, 1e-3),
        Err(Error::PlaneHasNoEllipse)
    );
}

/// Section 9: an ellipse longer than the rollers switches to line contact with the
/// load per unit length.
#[test]
fn model_choice_switches_to_line_contact() {
    let s = scene().with_length(0.1).unwrap();
    let short = reference::estimate(&s, 2e3, 0.01).unwrap();
    let long = reference::estimate(&s, 2e3, 1e-5).unwrap();
    assert_eq!(short.model(), reference::ContactModel::Elliptic);
    assert_eq!(long.model(), reference::ContactModel::Line);
    match long {
        reference::Solution::Line(l) => assert_eq!(l.load, 2e3 / 0.1),
        _ => unreachable!(),
    }
    assert!(
        reference::elliptic(&s, 2e3, 1e-5)
            .unwrap()
            .validity
            .longer_than_rollers
    );
}
