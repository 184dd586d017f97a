//! On-target tests of both cores: every public path of the f32 core (`misalign::float`)
//! and of the fixed-point core (`misalign::fixed`) run on the microcontroller (`cargo
//! xtask firmware` runs them on the Cortex-M4F, M7, M3 and M0 in QEMU; defmt-test
//! harness, log over semihosting, exit status 0 when all pass, 101 on the first
//! failure). The answers are held to the f64 reference evaluated on the same target,
//! to the relative 2e-6 of `tests/float_core.rs` (f32) and 1e-4 (fixed point).
//! The logger, handlers and memory layout come from the harness crate.
//!
//! ```sh
//! cargo test --target thumbv7em-none-eabihf --features firmware --test on_target
//! cargo test --target thumbv6m-none-eabi --features firmware --test on_target
//! ```
//!
//! On the host it builds as a stub that says so.
#![cfg_attr(target_os = "none", no_std)]
#![cfg_attr(target_os = "none", no_main)]

#[cfg(target_os = "none")]
misalign_harness::log_panics_and_faults!();
#[cfg(target_os = "none")]
use misalign_logger as _;

#[cfg(not(target_os = "none"))]
fn main() {
    println!("on_target: these tests run on a Cortex-M (cargo xtask firmware)");
}

/// What the tests share (defmt-test wants only tests in its module).
#[cfg(target_os = "none")]
mod check {
    use misalign::Scene;
    use misalign::reference::Regime;

    pub const BOUND: f64 = 2e-6;

    /// Loads (N, or N/m for line contact) and angles (rad) of the sweeps: both
    /// regimes, both signs.
    pub const LOADS: [f32; 5] = [50.0, 300.0, 1000.0, 4000.0, 2e4];
    pub const LINE_LOADS: [f32; 4] = [3e3, 2e4, 2e5, 2e6];
    pub const ANGLES: [f32; 7] = [-1.5e-3, -2e-5, 3e-6, 9e-5, 4e-4, 1e-3, 5e-3];

    pub fn demo() -> Scene {
        Scene::DEMO
    }

    /// A scene of unequal rollers, so that theta != phi.
    pub fn unequal() -> Scene {
        Scene::new(0.02, 0.35, 26e9, 0.34, 0.15).unwrap()
    }

    pub fn rel(got: f32, want: f64) -> f64 {
        if got as f64 == want {
            0.0
        } else {
            ((got as f64 - want) / want).abs()
        }
    }

    pub fn close(what: &str, got: f32, want: f64) {
        defmt::assert!(
            rel(got, want) <= BOUND,
            "{=str}: got {=f32} want {=f64} (relative error {=f64})",
            what,
            got,
            want,
            rel(got, want)
        );
    }

    pub fn regime_agrees(got: Regime, s_ref: f64) {
        if (s_ref - 1.0).abs() > 1e-6 {
            defmt::assert!(got == Regime::of(s_ref), "regime at d/b = {=f64}", s_ref);
        }
    }
}

#[cfg(target_os = "none")]
#[defmt_test::tests]
mod tests {
    use misalign::float::octave::{OctaveTable, Row, WIDE, narrow_rows};
    use misalign::float::{EllipticScene, LineScene, Tables};
    use misalign::float::{G_OF_THETA, G_OF_THETA_ROWS, THETA_OF_G, THETA_OF_G_ROWS};
    use misalign::reference::{self, Regime};
    use misalign::{Error, Scene, ThetaRelation};

    use super::check::*;

    #[test]
    fn elliptic_estimate_matches_the_reference() {
        for scene in [demo(), unequal()] {
            let prepared = EllipticScene::new(&scene).unwrap();
            for p in LOADS {
                for phi in ANGLES {
                    let e = prepared.estimate(p, phi).unwrap();
                    let r = reference::elliptic(&scene, p as f64, phi as f64).unwrap();
                    close("d/b", e.slip_ratio, r.slip_ratio);
                    close("F", e.axial_force, r.axial_force);
                    let phi0 = r.critical_angle.unwrap();
                    close("phi0", e.critical_angle.unwrap(), phi0);
                    // phi0 - |phi| cancels: hold it to the error of the larger term.
                    let abs_phi = (phi as f64).abs();
                    let margin = e.margin.unwrap() as f64 - (phi0 - abs_phi);
                    defmt::assert!(
                        margin.abs() <= BOUND * phi0.max(abs_phi),
                        "margin off by {=f64}",
                        margin
                    );
                    regime_agrees(e.regime, r.slip_ratio);
                    if (r.slip_ratio - 0.8).abs() > 1e-6 {
                        defmt::assert_eq!(e.microslip_risk, r.slip_ratio >= 0.8);
                    }
                }
            }
        }
    }

    #[test]
    fn elliptic_details_match_the_reference() {
        for scene in [demo(), unequal()] {
            let prepared = EllipticScene::new(&scene).unwrap();
            for p in LOADS {
                for phi in ANGLES {
                    let d = prepared.details(p, phi).unwrap();
                    let r = reference::elliptic(&scene, p as f64, phi as f64).unwrap();
                    close("theta", d.theta, r.shape.theta);
                    close("m", d.m, r.shape.m);
                    close("n", d.n, r.shape.n);
                    close("a", d.a, r.a);
                    close("b", d.b, r.b);
                    close("p0", d.p0, r.p0);
                }
            }
        }
    }

    #[test]
    fn line_estimate_matches_the_reference() {
        for scene in [
            demo(),
            unequal(),
            Scene::new(0.1, f64::INFINITY, 79.3e9, 0.3, 0.2).unwrap(),
        ] {
            let prepared = LineScene::new(&scene).unwrap();
            for p in LINE_LOADS {
                for phi in ANGLES {
                    let e = prepared.estimate(p, phi).unwrap();
                    let r = reference::line(&scene, p as f64, phi as f64).unwrap();
                    close("d/b", e.slip_ratio, r.slip_ratio);
                    close("F", e.axial_force, r.axial_force);
                    close("phi0", e.critical_angle.unwrap(), r.critical_angle.unwrap());
                    regime_agrees(e.regime, r.slip_ratio);
                }
            }
        }
    }

    #[test]
    fn line_with_a_length_takes_the_total_load() {
        let scene = demo().with_length(0.4).unwrap();
        let e = LineScene::new(&scene).unwrap().estimate(8e4, 1e-3).unwrap();
        let r = reference::line(&scene, 8e4 / 0.4, 1e-3).unwrap();
        close("d/b", e.slip_ratio, r.slip_ratio);
        close("F", e.axial_force, r.axial_force * 0.4);
        close("phi0", e.critical_angle.unwrap(), r.critical_angle.unwrap());
    }

    #[test]
    fn zero_angle_and_zero_load() {
        let elliptic = EllipticScene::new(&demo()).unwrap();
        let line = LineScene::new(&demo()).unwrap();
        for e in [
            elliptic.estimate(1000.0, 0.0).unwrap(),
            line.estimate(1e5, -0.0).unwrap(),
        ] {
            defmt::assert_eq!(e.slip_ratio, 0.0);
            defmt::assert_eq!(e.axial_force, 0.0);
            defmt::assert!(e.regime == Regime::Partial && !e.microslip_risk);
            defmt::assert!(e.critical_angle.unwrap() > 0.0);
            defmt::assert_eq!(e.margin, e.critical_angle);
        }
        for e in [
            elliptic.estimate(0.0, 2e-4).unwrap(),
            line.estimate(-0.0, -2e-4).unwrap(),
        ] {
            defmt::assert_eq!(e.slip_ratio, f32::INFINITY);
            defmt::assert_eq!(e.axial_force, 0.0);
            defmt::assert!(e.regime == Regime::Gross && e.microslip_risk);
            defmt::assert_eq!(e.critical_angle, Some(0.0));
            defmt::assert_eq!(e.margin, Some(-2e-4));
        }
        for e in [
            elliptic.estimate(0.0, 0.0).unwrap(),
            line.estimate(0.0, 0.0).unwrap(),
        ] {
            defmt::assert_eq!(e.slip_ratio, 0.0);
            defmt::assert!(e.regime == Regime::Partial);
        }
        let d = elliptic.details(1000.0, 0.0).unwrap();
        defmt::assert!(d.m == f32::INFINITY && d.a == f32::INFINITY);
        defmt::assert!(d.n == 0.0 && d.b == 0.0 && d.p0 == 0.0 && d.theta == 0.0);
        let d = elliptic.details(0.0, 1e-3).unwrap();
        defmt::assert!(d.a == 0.0 && d.b == 0.0 && d.p0 == 0.0 && d.m > 1.0);
    }

    #[test]
    fn bad_samples_are_refused() {
        let elliptic = EllipticScene::new(&demo()).unwrap();
        let line = LineScene::new(&demo()).unwrap();
        for p in [f32::NAN, f32::INFINITY, -1.0, -1e-40, f32::NEG_INFINITY] {
            defmt::assert!(elliptic.estimate(p, 1e-4) == Err(Error::Load));
            defmt::assert!(elliptic.details(p, 1e-4).err() == Some(Error::Load));
            defmt::assert!(line.estimate(p, 1e-4) == Err(Error::Load));
        }
        for phi in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 1.6, -2.0] {
            defmt::assert!(elliptic.estimate(1e3, phi) == Err(Error::Angle));
            defmt::assert!(elliptic.details(1e3, phi).err() == Some(Error::Angle));
            defmt::assert!(line.estimate(1e3, phi) == Err(Error::Angle));
        }
        // f32's pi/2 (the rounding of pi/2, above it by 4.4e-8) stands for pi/2 and is
        // accepted, as is the f32 below it; the f32 above it is refused.
        let half_pi = core::f32::consts::FRAC_PI_2;
        defmt::assert!(elliptic.estimate(1e3, half_pi).is_ok());
        defmt::assert!(line.estimate(1e3, half_pi).is_ok());
        let below = f32::from_bits(half_pi.to_bits() - 1);
        defmt::assert!(elliptic.estimate(1e3, below).is_ok());
        let above = f32::from_bits(half_pi.to_bits() + 1);
        defmt::assert!(elliptic.estimate(1e3, above) == Err(Error::Angle));
        defmt::assert!(line.estimate(1e3, above) == Err(Error::Angle));
    }

    #[test]
    fn bad_scenes_are_refused() {
        defmt::assert!(Scene::new(-1.0, 0.05, 79.3e9, 0.3, 0.3) == Err(Error::Radius));
        defmt::assert!(Scene::new(0.05, 0.05, f64::NAN, 0.3, 0.3) == Err(Error::ShearModulus));
        defmt::assert!(Scene::new(0.05, 0.05, 79.3e9, 0.6, 0.3) == Err(Error::PoissonRatio));
        defmt::assert!(Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.0) == Err(Error::Friction));
        defmt::assert!(demo().with_length(-1.0) == Err(Error::Length));
        let plane = Scene::new(0.05, f64::INFINITY, 79.3e9, 0.3, 0.3).unwrap();
        defmt::assert!(EllipticScene::new(&plane).err() == Some(Error::PlaneHasNoEllipse));
        defmt::assert!(LineScene::new(&plane).is_ok());
        let exact = demo().with_theta_relation(ThetaRelation::Exact);
        defmt::assert!(EllipticScene::new(&exact).err() == Some(Error::Unsupported));
        // A modulus so large that the slip gain overflows f32.
        let stiff = Scene::new(0.05, 0.05, 1e300, 0.3, 0.3).unwrap();
        defmt::assert!(EllipticScene::new(&stiff).err() == Some(Error::OutOfRange));
        defmt::assert!(LineScene::new(&stiff).err() == Some(Error::OutOfRange));
    }

    #[test]
    fn small_theta_subnormal_load_and_no_critical_angle() {
        let scene = demo();
        let prepared = EllipticScene::new(&scene).unwrap();
        // Below the tables (theta < 2^-40): the small-theta asymptotics.
        for phi in [1e-13f32, -3e-20, 1e-38] {
            let e = prepared.estimate(1000.0, phi).unwrap();
            let r = reference::elliptic(&scene, 1000.0, phi as f64).unwrap();
            close("d/b (small theta)", e.slip_ratio, r.slip_ratio);
            close("F (small theta)", e.axial_force, r.axial_force);
            let d = prepared.details(1000.0, phi).unwrap();
            close("m (small theta)", d.m, r.shape.m);
            close("n (small theta)", d.n, r.shape.n);
        }
        // A load this high has no critical angle (theta0 would pass pi/2).
        let e = prepared.estimate(1e14, 1e-3).unwrap();
        defmt::assert!(e.critical_angle.is_none() && e.margin.is_none());
        defmt::assert!(
            reference::elliptic(&scene, 1e14, 1e-3)
                .unwrap()
                .critical_angle
                .is_none()
        );
        // A subnormal load.
        let line = LineScene::new(&scene).unwrap();
        for p in [1e-40f32, 1e-44] {
            let e = line.estimate(p, 1e-30).unwrap();
            let r = reference::line(&scene, p as f64, 1e-30).unwrap();
            close("d/b (subnormal load)", e.slip_ratio, r.slip_ratio);
            let e = prepared.estimate(p, 1e-30).unwrap();
            let r = reference::elliptic(&scene, p as f64, 1e-30).unwrap();
            close("d/b (subnormal load, elliptic)", e.slip_ratio, r.slip_ratio);
        }
    }

    #[test]
    fn narrowed_tables_and_risk_threshold() {
        // Rows from theta = 2^-20 up: below that the scene refuses the sample.
        const SKIP: usize = 12; // the table starts at 2^-32
        const G_ROWS: usize = G_OF_THETA_ROWS.len();
        const T_ROWS: usize = THETA_OF_G_ROWS.len();
        static G: [Row<WIDE>; G_ROWS - SKIP] = narrow_rows(&G_OF_THETA_ROWS, SKIP);
        static T: [Row<WIDE>; T_ROWS] = narrow_rows(&THETA_OF_G_ROWS, 0);
        let narrow = Tables {
            g: OctaveTable::new(G_OF_THETA.first_exponent() + SKIP as i32, &G),
            theta_of_g: OctaveTable::new(THETA_OF_G.first_exponent(), &T),
        };
        let scene = demo();
        let full = EllipticScene::new(&scene).unwrap();
        let narrowed = EllipticScene::with_tables(&scene, narrow).unwrap();
        defmt::assert!(narrowed.estimate(1000.0, 4e-4) == full.estimate(1000.0, 4e-4));
        defmt::assert!(narrowed.estimate(1000.0, 1e-7) == Err(Error::OutOfRange));
        defmt::assert!(narrowed.estimate(1000.0, 0.0) == full.estimate(1000.0, 0.0));
        // The risk flag follows the scene's threshold.
        let e = full.estimate(1000.0, 2e-4).unwrap(); // d/b = 0.63
        defmt::assert!(!e.microslip_risk);
        defmt::assert!(
            full.with_risk_slip_ratio(0.5)
                .unwrap()
                .estimate(1000.0, 2e-4)
                .unwrap()
                .microslip_risk
        );
        let line = LineScene::new(&scene)
            .unwrap()
            .with_risk_slip_ratio(0.1)
            .unwrap();
        defmt::assert!(line.estimate(2e5, 5e-4).unwrap().microslip_risk); // d/b = 0.12
    }

    /// The fixed-point core's public paths (the Cortex-M0 and M3 run it in the
    /// firmware): estimate, details and line contact against the reference within its
    /// 1e-4, and its input range.
    #[test]
    fn fixed_core_matches_the_reference() {
        use misalign::fixed::{FixedEllipticScene, FixedLineScene, Log2};
        let rel = |got: f64, want: f64| {
            if got == want {
                0.0
            } else {
                ((got - want) / want).abs()
            }
        };
        let (load_lsb, angle_lsb) = (1e-3, 1e-11);
        for scene in [demo(), unequal()] {
            let fixed = FixedEllipticScene::new(&scene, load_lsb, angle_lsb).unwrap();
            let line = FixedLineScene::new(&scene, load_lsb, angle_lsb).unwrap();
            for p in [1000u32 * 1000, 4000 * 1000] {
                for a in [-150_000_000i32, 2_000_000, 40_000_000, 500_000_000] {
                    let (load, phi) = (p as f64 * load_lsb, a as f64 * angle_lsb);
                    let r = reference::elliptic(&scene, load, phi).unwrap();
                    let e = fixed.estimate(p, a).unwrap();
                    defmt::assert!(rel(e.slip_ratio.to_f64(), r.slip_ratio) <= 1e-4);
                    let force =
                        e.axial_force.to_f64() * if e.axial_force_negative { -1.0 } else { 1.0 };
                    defmt::assert!(rel(force, r.axial_force) <= 1e-4);
                    defmt::assert!(
                        rel(
                            e.critical_angle.unwrap().to_f64(),
                            r.critical_angle.unwrap()
                        ) <= 1e-4
                    );
                    let d = fixed.details(p, a).unwrap();
                    defmt::assert!(
                        rel(d.m.to_f64(), r.shape.m) <= 1e-4 && rel(d.b.to_f64(), r.b) <= 1e-4
                    );
                    let l = reference::line(&scene, load, phi).unwrap();
                    let e = line.estimate(p, a).unwrap();
                    defmt::assert!(rel(e.slip_ratio.to_f64(), l.slip_ratio) <= 1e-4);
                    defmt::assert!(
                        rel(
                            e.critical_angle.unwrap().to_f64(),
                            l.critical_angle.unwrap()
                        ) <= 1e-4
                    );
                }
            }
            // Zero load, zero angle, and the declared input range.
            defmt::assert!(fixed.estimate(0, 1000).unwrap().slip_ratio == Log2::INFINITY);
            defmt::assert!(fixed.estimate(1000, 0).unwrap().slip_ratio == Log2::ZERO);
            let max = fixed.input_range().angle_max;
            if max < i32::MAX as u32 {
                defmt::assert!(fixed.estimate(1000, max as i32 + 1) == Err(Error::Angle));
            }
        }
    }
}
