//! Property tests: what the physics demands, on random scenes and samples,
//! for the reference and both cores.

use misalign::Scene;
use misalign::fixed::{FixedEllipticScene, exact_lsb};
use misalign::float::EllipticScene;
use misalign::reference::{self, tangential};
use proptest::prelude::*;

/// log-uniform in [lo, hi].
fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo.ln()..hi.ln()).prop_map(f64::exp)
}

prop_compose! {
    fn scenes()(r1 in log_uniform(1e-3, 1.0), r2 in log_uniform(1e-3, 1.0), g in log_uniform(1e9, 1e11),
                nu in 0.0..0.49f64, mu in log_uniform(0.01, 1.0)) -> Scene {
        Scene::new(r1, r2, g, nu, mu).unwrap()
    }
}

fn rel(a: f64, b: f64) -> f64 {
    if a == b { 0.0 } else { ((a - b) / b).abs() }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn slip_ratio_grows_with_angle_and_falls_with_load(
        s in scenes(), load in log_uniform(0.1, 1e6), phi in log_uniform(1e-8, 0.02), k in 1.001..3.0f64,
    ) {
        let base = reference::elliptic(&s, load, phi).unwrap();
        let wider = reference::elliptic(&s, load, phi * k).unwrap();
        let heavier = reference::elliptic(&s, load * k, phi).unwrap();
        prop_assert!(wider.slip_ratio > base.slip_ratio);
        prop_assert!(heavier.slip_ratio < base.slip_ratio);
        // The critical angle grows with the load (eq 30: phi0 = 2 mu p0 / G), until the
        // load is so high that no theta <= pi/2 reaches d/b = 1 (None).
        match (base.critical_angle, heavier.critical_angle) {
            (Some(light), Some(heavy)) => prop_assert!(heavy > light),
            (None, Some(_)) => prop_assert!(false, "a heavier load regained a critical angle"),
            _ => {}
        }
    }

    #[test]
    fn axial_force_is_odd_bounded_and_grows_with_angle(
        s in scenes(), load in log_uniform(0.1, 1e6), phi in log_uniform(1e-8, 0.02), k in 1.001..3.0f64,
    ) {
        let p = reference::elliptic(&s, load, phi).unwrap();
        let n = reference::elliptic(&s, load, -phi).unwrap();
        let wider = reference::elliptic(&s, load, phi * k).unwrap();
        prop_assert_eq!(p.axial_force, -n.axial_force);
        prop_assert!(p.axial_force > 0.0 && p.axial_force <= s.friction() * load);
        prop_assert!(wider.axial_force >= p.axial_force);
        if p.slip_ratio < 1.0 {
            prop_assert!(wider.axial_force > p.axial_force);
        }
        let core = EllipticScene::new(&s).unwrap();
        let e = core.estimate(load as f32, -phi as f32).unwrap();
        prop_assert!(e.axial_force < 0.0 && -e.axial_force <= (s.friction() * load) as f32 * (1.0 + 2e-7));
    }

    /// F/(mu P) and its first two derivatives are continuous at d/b = 1 (eq 21 meets
    /// eq 29): one-sided differences agree as the step shrinks.
    #[test]
    fn axial_force_is_smooth_at_gross_slip(h in 1e-5..1e-3f64) {
        let f = tangential::axial_force_ratio;
        prop_assert_eq!(f(1.0), 1.0);
        let slope_below = (f(1.0) - f(1.0 - h)) / h;
        let curvature_below = (f(1.0) - 2.0 * f(1.0 - h) + f(1.0 - 2.0 * h)) / (h * h);
        // (4 sqrt 2 / 5)(1 - s)^(5/2): slope ~ h^1.5, curvature ~ h^0.5, both -> 0.
        prop_assert!(slope_below.abs() < 4.0 * h.powf(1.5));
        prop_assert!(curvature_below.abs() < 20.0 * h.sqrt());
        prop_assert_eq!(tangential::axial_force_ratio_slope(1.0 + h), 0.0);
    }

    #[test]
    fn the_cores_agree_with_the_reference(
        s in scenes(), load in log_uniform(0.1, 1e6), phi in log_uniform(1e-7, 0.05), negative in any::<bool>(),
    ) {
        let phi = if negative { -phi } else { phi };
        let r = reference::elliptic(&s, load, phi).unwrap();
        let e = EllipticScene::new(&s).unwrap().estimate(load as f32, phi as f32).unwrap();
        prop_assert!(rel(e.slip_ratio as f64, r.slip_ratio) <= 2e-6, "{} {}", e.slip_ratio, r.slip_ratio);
        prop_assert!(rel(e.axial_force as f64, r.axial_force) <= 2e-6);
        match (e.critical_angle, r.critical_angle) {
            (Some(a), Some(b)) => prop_assert!(rel(a as f64, b) <= 2e-6),
            (None, None) => {}
            other => prop_assert!(false, "{other:?}"),
        }
        let (load_lsb, p) = exact_lsb(load, 1 << 30, 0.0);
        let (angle_lsb, a) = exact_lsb(phi, 1 << 30, FixedEllipticScene::min_angle_lsb(&s));
        let fixed = FixedEllipticScene::new(&s, load_lsb, angle_lsb).unwrap();
        let f = fixed.estimate(p, if negative { -(a as i32) } else { a as i32 }).unwrap();
        prop_assert!(rel(f.slip_ratio.to_f64(), r.slip_ratio) <= 1e-4);
        let force = f.axial_force.to_f64();
        let signed = if f.axial_force_negative { -force } else { force };
        prop_assert!(rel(signed, r.axial_force) <= 1e-4);
        if let (Some(a), Some(b)) = (f.critical_angle, r.critical_angle) {
            prop_assert!(rel(a.to_f64(), b) <= 1e-4);
        }
    }
}
