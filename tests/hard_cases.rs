//! Hard cases: awkward but valid input to the reference and both cores.
//! Each case matches the reference within the core's stated error (f32 2e-6, fixed
//! 1e-4) or gets a typed error from all of them: never a panic, a NaN or a silent
//! infinity.

use misalign::fixed::{FixedEllipticScene, FixedEstimate, FixedLineScene, exact_lsb};
use misalign::float::{EllipticScene, Estimate, LineScene};
use misalign::reference::{self, Regime};
use misalign::{Error, Scene};

const F32_BOUND: f64 = 2e-6;
const FIXED_BOUND: f64 = 1e-4;

fn rel(got: f64, want: f64) -> f64 {
    if got == want {
        0.0
    } else {
        ((got - want) / want).abs()
    }
}

/// What every path must agree on.
#[derive(Debug, Clone, Copy)]
struct Answer {
    s: f64,
    f: f64,
    phi0: Option<f64>,
    regime: Regime,
}

fn close(what: &str, got: Answer, want: Answer, bound: f64) {
    let near_one =
        (want.s - 1.0).abs() <= 1e-6 || (bound > F32_BOUND && (want.s - 1.0).abs() <= 1e-4);
    assert!(
        rel(got.s, want.s) <= bound,
        "{what}: d/b {} vs {}",
        got.s,
        want.s
    );
    assert!(
        rel(got.f, want.f) <= bound,
        "{what}: F {} vs {}",
        got.f,
        want.f
    );
    match (got.phi0, want.phi0) {
        (Some(g), Some(w)) => assert!(rel(g, w) <= bound, "{what}: phi0 {g} vs {w}"),
        (None, None) => {}
        other => panic!("{what}: phi0 {other:?}"),
    }
    if !near_one {
        assert_eq!(got.regime, want.regime, "{what}: s = {}", want.s);
    }
    assert!(!got.s.is_nan() && !got.f.is_nan());
}

fn from_f32(e: Estimate) -> Answer {
    Answer {
        s: e.slip_ratio as f64,
        f: e.axial_force as f64,
        phi0: e.critical_angle.map(f64::from),
        regime: e.regime,
    }
}

fn from_fixed(e: FixedEstimate) -> Answer {
    let f = e.axial_force.to_f64();
    Answer {
        s: e.slip_ratio.to_f64(),
        f: if e.axial_force_negative { -f } else { f },
        phi0: e.critical_angle.map(|x| x.to_f64()),
        regime: e.regime,
    }
}

/// The elliptic case through all three paths. Returns the reference's answer, or the
/// error all of them gave.
fn elliptic_case(what: &str, scene: &Scene, load: f64, phi: f64) -> Result<Answer, Error> {
    let r = match reference::elliptic(scene, load, phi) {
        Ok(r) => r,
        Err(e) => {
            // Every path refuses what the reference refuses (f32: its nearest value
            // may round onto the boundary; only check the f64-representable refusals).
            if let Ok(core) = EllipticScene::new(scene)
                && (load as f32 as f64) == load
                && (phi as f32 as f64) == phi
            {
                assert!(
                    core.estimate(load as f32, phi as f32).is_err(),
                    "{what}: f32 accepted"
                );
            }
            return Err(e);
        }
    };
    let want = Answer {
        s: r.slip_ratio,
        f: r.axial_force,
        phi0: r.critical_angle,
        regime: r.regime,
    };
    let core = EllipticScene::new(scene).expect("f32 scene");
    let got = core
        .estimate(load as f32, phi as f32)
        .expect("f32 estimate");
    close(&format!("{what} (f32)"), from_f32(got), want, F32_BOUND);
    let (load_lsb, p) = exact_lsb(load, 1 << 30, 0.0);
    let (angle_lsb, a) = exact_lsb(phi, 1 << 30, FixedEllipticScene::min_angle_lsb(scene));
    let angle = if phi < 0.0 { -(a as i32) } else { a as i32 };
    match FixedEllipticScene::new(scene, load_lsb, angle_lsb) {
        Ok(fixed) if phi.abs() >= angle_lsb * 0.999_999 || phi == 0.0 => {
            let got = fixed.estimate(p, angle).expect("fixed estimate");
            close(
                &format!("{what} (fixed)"),
                from_fixed(got),
                want,
                FIXED_BOUND,
            );
        }
        // Below the fixed core's range (theta < 2^-40 rad per count): refused, typed.
        Ok(_) => {}
        Err(e) => assert_eq!(e, Error::OutOfRange, "{what}"),
    }
    Ok(want)
}

fn line_case(what: &str, scene: &Scene, load: f64, phi: f64) -> Answer {
    let r = reference::line(scene, load, phi).expect("line reference");
    let want = Answer {
        s: r.slip_ratio,
        f: r.axial_force,
        phi0: r.critical_angle,
        regime: r.regime,
    };
    let got = LineScene::new(scene)
        .unwrap()
        .estimate(load as f32, phi as f32)
        .unwrap();
    close(
        &format!("{what} (f32 line)"),
        from_f32(got),
        want,
        F32_BOUND,
    );
    let ((load_lsb, p), (angle_lsb, a)) =
        (exact_lsb(load, 1 << 30, 0.0), exact_lsb(phi, 1 << 30, 0.0));
    let angle = if phi < 0.0 { -(a as i32) } else { a as i32 };
    let got = FixedLineScene::new(scene, load_lsb, angle_lsb)
        .unwrap()
        .estimate(p, angle)
        .unwrap();
    close(
        &format!("{what} (fixed line)"),
        from_fixed(got),
        want,
        FIXED_BOUND,
    );
    want
}

fn steel(r1: f64, r2: f64, nu: f64, mu: f64) -> Scene {
    Scene::new(r1, r2, 79.3e9, nu, mu).unwrap()
}

#[test]
fn theta_towards_zero() {
    let s = steel(0.05, 0.05, 0.3, 0.3);
    let mut last = f64::INFINITY;
    for phi in [1e-6, 1e-9, 1e-11, 1e-12, 5e-13] {
        let a = elliptic_case(&format!("phi {phi:e}"), &s, 1e3, phi).unwrap();
        assert!(a.s > 0.0 && a.s < last, "d/b falls with phi");
        last = a.s;
    }
    let a = elliptic_case("phi 0", &s, 1e3, 0.0).unwrap();
    assert_eq!((a.s, a.f, a.regime), (0.0, 0.0, Regime::Partial));
    // Below the f32 tables (theta < 2^-40) the asymptotics take over.
    let r = reference::elliptic(&s, 1e3, 1e-13).unwrap();
    let got = EllipticScene::new(&s)
        .unwrap()
        .estimate(1e3, 1e-13)
        .unwrap();
    assert!(rel(got.slip_ratio as f64, r.slip_ratio) <= F32_BOUND);
    line_case("line phi 1e-12", &s, 1e5, 1e-12);
}

#[test]
fn theta_at_a_right_angle_and_its_neighbours() {
    let s = steel(0.05, 0.05, 0.3, 0.3); // c = 1: theta = phi
    let half_pi = core::f64::consts::FRAC_PI_2;
    let below = f64::from_bits(half_pi.to_bits() - 1);
    let above = f64::from_bits(half_pi.to_bits() + 1);
    // The angle between two axes is at most a right angle. f64's FRAC_PI_2 lies below
    // the true pi/2 and is accepted (theta = pi/2: m = n = 1, crossed cylinders) in
    // every model; the f64 above it lies above pi/2 and is refused.
    for phi in [half_pi, -half_pi, below] {
        let a = elliptic_case(&format!("phi = {phi}"), &s, 1e3, phi).unwrap();
        assert!(a.s.is_finite() && a.s > 0.0 && a.f.is_finite());
        line_case(&format!("line phi = {phi}"), &s, 1e5, phi);
    }
    assert_eq!(
        elliptic_case("theta = pi/2 + ulp", &s, 1e3, above).err(),
        Some(Error::Angle)
    );
    assert_eq!(reference::line(&s, 1e5, above).err(), Some(Error::Angle));
    let shape = reference::normal::ellipse_shape(half_pi).unwrap();
    assert!((shape.m - 1.0).abs() < 1e-15 && (shape.n - 1.0).abs() < 1e-15);
    // The f32 core reads f32: f32's FRAC_PI_2 (the rounding of f64's, above pi/2 by
    // 4.4e-8) stands for pi/2 and answers as the reference at pi/2; its lower
    // neighbour as the reference at that value; the f32 above is refused.
    let f32_half_pi = core::f32::consts::FRAC_PI_2;
    let f32_below = f32_half_pi.next_down();
    let core = EllipticScene::new(&s).unwrap();
    let line = LineScene::new(&s).unwrap();
    for (phi, at) in [(f32_half_pi, half_pi), (f32_below, f32_below as f64)] {
        let want = reference::elliptic(&s, 1e3, at).unwrap();
        let got = core.estimate(1e3, phi).unwrap();
        let what = format!("f32 phi = {phi}");
        close(
            &what,
            from_f32(got),
            Answer {
                s: want.slip_ratio,
                f: want.axial_force,
                phi0: want.critical_angle,
                regime: want.regime,
            },
            F32_BOUND,
        );
        let d = core.details(1e3, phi).unwrap();
        assert!(
            rel(d.m as f64, want.shape.m) < F32_BOUND,
            "{what}: m {}",
            d.m
        );
        let want = reference::line(&s, 1e5, at).unwrap();
        let got = line.estimate(1e5, phi).unwrap();
        assert!(
            rel(got.slip_ratio as f64, want.slip_ratio) <= F32_BOUND,
            "{what}"
        );
        assert!(
            rel(got.axial_force as f64, want.axial_force) <= F32_BOUND,
            "{what}"
        );
    }
    let f32_above = f32_half_pi.next_up();
    assert_eq!(core.estimate(1e3, f32_above), Err(Error::Angle));
    assert_eq!(line.estimate(1e5, f32_above), Err(Error::Angle));
    // Section 9's choosers and the inverses take it too.
    let long = s.with_length(0.3).unwrap();
    reference::estimate(&long, 1e3, half_pi).unwrap();
    misalign::float::Auto::new(&long)
        .unwrap()
        .estimate(1e3, f32_half_pi)
        .unwrap();
    let (load_lsb, p) = exact_lsb(1e3, 1 << 30, 0.0);
    let (angle_lsb, a) = exact_lsb(half_pi, 1 << 30, 0.0);
    misalign::fixed::FixedAuto::new(&long, load_lsb, angle_lsb)
        .unwrap()
        .estimate(p, a as i32)
        .unwrap();
    misalign::reference::inverse::friction_estimate(&long, 1e3, half_pi, 100.0).unwrap();
}

#[test]
fn slip_ratio_at_one_from_both_sides() {
    for s in [steel(0.05, 0.05, 0.3, 0.3), steel(0.5, 0.0005, 0.25, 0.1)] {
        let phi0 = reference::critical_angle(&s, 2e3).unwrap().0;
        for k in [1.0 - 1e-9, 1.0, 1.0 + 1e-9] {
            let a = elliptic_case(&format!("phi0 x {k}"), &s, 2e3, phi0 * k).unwrap();
            assert!((a.s - 1.0).abs() < 1e-8, "{}", a.s);
            assert!((a.f / (s.friction() * 2e3) - 1.0).abs() < 1e-15);
        }
        let l = reference::line(&s, 1e5, 1e-3).unwrap();
        for k in [1.0 - 1e-9, 1.0, 1.0 + 1e-9] {
            line_case(
                &format!("line phi0 x {k}"),
                &s,
                1e5,
                l.critical_angle.unwrap() * k,
            );
        }
    }
}

#[test]
fn slip_ratio_towards_zero() {
    let s = steel(0.05, 0.05, 0.3, 0.3);
    // d/b ~ 1e-8: F ~ (3 pi / 4) 1e-8 mu P, exact through eq (21)'s rearrangement.
    let phi0 = reference::critical_angle(&s, 1e3).unwrap().0;
    let a = elliptic_case("d/b ~ 1e-8", &s, 1e3, phi0 * 1e-12).unwrap();
    assert!(a.s < 1e-7 && a.s > 1e-10, "{}", a.s);
    let l = line_case("line d/b 1e-8", &s, 1e5, 3.2127409e-3 * 1e-8);
    assert!(l.s < 2e-8);
}

#[test]
fn friction_towards_zero() {
    let s = steel(0.05, 0.05, 0.3, 1e-6);
    for phi in [1e-9, 1e-6, 1e-3] {
        elliptic_case(&format!("mu 1e-6 phi {phi:e}"), &s, 1e3, phi).unwrap();
        line_case(&format!("line mu 1e-6 phi {phi:e}"), &s, 1e5, phi);
    }
}

#[test]
fn loads_over_eleven_decades() {
    let s = steel(0.05, 0.05, 0.3, 0.3);
    for load in [1e-3, 1.0, 1e3, 1e6, 1e8] {
        for phi in [1e-6, 1e-3, -2e-2] {
            elliptic_case(&format!("P {load:e} phi {phi:e}"), &s, load, phi).unwrap();
            line_case(&format!("line P {load:e} phi {phi:e}"), &s, load, phi);
        }
    }
}

#[test]
fn radius_ratios_planes_and_poisson_extremes() {
    for (r1, r2) in [(1e-3, 1.0), (1.0, 1e-3), (0.02, 0.02)] {
        for nu in [0.0, 0.4999] {
            let s = steel(r1, r2, nu, 0.3);
            for phi in [1e-5, -1e-3] {
                elliptic_case(
                    &format!("R1 {r1} R2 {r2} nu {nu} phi {phi}"),
                    &s,
                    500.0,
                    phi,
                )
                .unwrap();
                line_case(&format!("line R1 {r1} R2 {r2} nu {nu}"), &s, 1e4, phi);
            }
        }
    }
    let plane = steel(0.02, f64::INFINITY, 0.3, 0.3);
    assert_eq!(
        elliptic_case("plane", &plane, 1e3, 1e-3).err(),
        Some(Error::PlaneHasNoEllipse)
    );
    assert!(
        EllipticScene::new(&plane).is_err() && FixedEllipticScene::new(&plane, 1.0, 1e-6).is_err()
    );
    line_case("plane, line contact", &plane, 1e5, 1e-3);
}

#[test]
fn negative_angles_mirror_positive_ones() {
    let s = steel(0.03, 0.07, 0.3, 0.2);
    for phi in [1e-7, 1e-4, 1e-2] {
        let p = elliptic_case("phi +", &s, 800.0, phi).unwrap();
        let n = elliptic_case("phi -", &s, 800.0, -phi).unwrap();
        assert_eq!((p.s, p.f, p.phi0), (n.s, -n.f, n.phi0));
    }
}

#[test]
fn undefined_input_gets_a_typed_error_everywhere() {
    let bad = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -1.0];
    for x in bad {
        assert_eq!(
            Scene::new(x, 0.05, 79.3e9, 0.3, 0.3).err(),
            Some(Error::Radius)
        );
        assert!(Scene::new(0.05, x, 79.3e9, 0.3, 0.3).is_err() || x == f64::INFINITY);
        assert_eq!(
            Scene::new(0.05, 0.05, x, 0.3, 0.3).err(),
            Some(Error::ShearModulus)
        );
        assert_eq!(
            Scene::new(0.05, 0.05, 79.3e9, x, 0.3).err(),
            Some(Error::PoissonRatio)
        );
        assert_eq!(
            Scene::new(0.05, 0.05, 79.3e9, 0.3, x).err(),
            Some(Error::Friction)
        );
    }
    // Subnormal but positive scene values are valid input; the cores refuse constants
    // they cannot hold, with a typed error.
    let tiny = f64::from_bits(1);
    let s = Scene::new(tiny, 0.05, 79.3e9, 0.3, 0.3).unwrap();
    assert!(reference::elliptic(&s, 1e3, 1e-3).is_ok());
    assert_eq!(EllipticScene::new(&s).err(), Some(Error::OutOfRange));
    let s = steel(0.05, 0.05, 0.3, 0.3);
    for x in bad {
        assert_eq!(reference::elliptic(&s, x, 1e-3).err(), Some(Error::Load));
        assert_eq!(
            EllipticScene::new(&s)
                .unwrap()
                .estimate(x as f32, 1e-3)
                .err(),
            Some(Error::Load)
        );
        if x != -1.0 {
            assert_eq!(reference::elliptic(&s, 1e3, x).err(), Some(Error::Angle));
            assert_eq!(
                EllipticScene::new(&s)
                    .unwrap()
                    .estimate(1e3, x as f32)
                    .err(),
                Some(Error::Angle)
            );
            assert_eq!(
                LineScene::new(&s).unwrap().estimate(1e3, x as f32).err(),
                Some(Error::Angle)
            );
        }
    }
    // Subnormal load and angle are valid: defined answers, no NaN.
    let e = EllipticScene::new(&s)
        .unwrap()
        .estimate(1e-40, 1e-40)
        .unwrap();
    assert!(e.slip_ratio.is_finite() && e.axial_force.is_finite());
    let r = reference::elliptic(&s, tiny, tiny).unwrap();
    assert!(r.slip_ratio.is_finite() && r.axial_force.is_finite() && r.critical_angle.is_some());
}

/// phi0 beyond pi/2 is no critical angle (`None`, no margin) in every model, never a
/// number: eq (4) with unequal radii gives phi0 = theta0 / c, which passes pi/2 while
/// theta0 is still below it, and eq (28) passes it at extreme loads per length.
#[test]
fn a_critical_angle_beyond_a_right_angle_is_none_in_every_model() {
    let half_pi = core::f64::consts::FRAC_PI_2;
    // c = 0.198: phi0 reaches pi/2 at theta0 = 0.311. The load where it does, by
    // bisection in log P on the reference (phi0 grows with P).
    let s = steel(0.01, 1.0, 0.3, 0.3);
    let (mut lo, mut hi) = (1e-3f64, 1e12f64);
    for _ in 0..100 {
        let mid = (lo * hi).sqrt();
        match reference::critical_angle(&s, mid) {
            Some(_) => lo = mid,
            None => hi = mid,
        }
    }
    let (phi0, theta0) = reference::critical_angle(&s, lo).unwrap();
    assert!(
        rel(phi0, half_pi) < 1e-9 && theta0 < 0.32,
        "{phi0} {theta0}"
    );
    let core = EllipticScene::new(&s).unwrap();
    for (load, none) in [(lo / 1.1, false), (hi * 1.1, true), (hi * 1e3, true)] {
        let a = elliptic_case(&format!("P = {load:e}"), &s, load, 0.01).unwrap();
        assert_eq!(a.phi0.is_none(), none, "P = {load:e}: {:?}", a.phi0);
        assert!(a.phi0.is_none_or(|p| p <= half_pi));
        let e = core.estimate(load as f32, 0.01).unwrap();
        assert_eq!(e.margin.is_none(), none, "P = {load:e}");
    }
    // A cylinder on a plane, per unit length: eq (28) reaches pi/2 near 6e10 N/m.
    let plane = steel(0.05, f64::INFINITY, 0.3, 0.3);
    for (load, none) in [(1e10, false), (1e11, true), (1e14, true)] {
        let a = line_case(&format!("line P = {load:e}"), &plane, load, 1e-3);
        assert_eq!(a.phi0.is_none(), none, "P = {load:e}: {:?}", a.phi0);
        let e = LineScene::new(&plane)
            .unwrap()
            .estimate(load as f32, 1e-3)
            .unwrap();
        assert_eq!(e.margin.is_none(), none, "P = {load:e}");
    }
}
