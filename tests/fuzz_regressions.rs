//! Inputs that `cargo xtask fuzz` found, kept as regression tests.

use misalign::fixed::{FixedEllipticScene, FixedEstimate, FixedLineScene, Log2, exact_lsb};
use misalign::float::{EllipticScene, LineScene};
use misalign::reference::Regime;
use misalign::{Error, Scene, reference};

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
            l.critical_angle.is_none_or(|c| c.is_finite() && c > 0.0),
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

// An adversarial probe's crafted inputs (extreme but accepted scenes, LSBs
// that leave no angle but 0, loads whose mu P leaves the number format).

/// Every f64 field of an elliptic result is a number (infinities where documented).
fn assert_no_nan_elliptic(e: &reference::Elliptic) {
    let s = e.shape;
    let fields = [
        s.theta,
        s.kprime,
        s.m,
        s.n,
        e.a,
        e.b,
        e.p0,
        e.pstar,
        e.p0star,
        e.slip_ratio,
        e.d,
        e.axial_force,
        e.critical_load,
        e.critical_angle.unwrap_or(0.0),
        e.critical_theta.unwrap_or(0.0),
    ];
    assert!(fields.iter().all(|x| !x.is_nan()), "{e:?}");
}

/// Every f64 field of a line result is a number.
fn assert_no_nan_line(l: &reference::Line) {
    let fields = [
        l.radius,
        l.b,
        l.p0,
        l.pstar,
        l.p0star,
        l.slip_ratio,
        l.d,
        l.axial_force,
        l.critical_angle.unwrap_or(0.0),
        l.critical_load,
    ];
    assert!(fields.iter().all(|x| !x.is_nan()), "{l:?}");
}

/// R1 = R2 = 5e-324 m gave an effective radius of 0 (R1 R2/(R1 + R2)
/// is 2.5e-324, not an f64), and from it NaN in p0, phi0, P*, a. Such radii are refused;
/// twice the smallest subnormal still works, without NaN.
#[test]
fn effective_radius_that_underflows_is_refused() {
    let tiny = f64::from_bits(1);
    assert_eq!(
        Scene::new(tiny, tiny, 79.3e9, 0.3, 0.3).err(),
        Some(Error::Radius)
    );
    let s = Scene::new(2.0 * tiny, 2.0 * tiny, 79.3e9, 0.3, 0.3).unwrap();
    assert_eq!(s.effective_radius(), tiny);
    for phi in [0.0, 1e-3, 1.0] {
        for load in [0.0, 1e-300, 1.0, 1e300] {
            assert_no_nan_line(&reference::line(&s, load, phi).unwrap());
            assert_no_nan_elliptic(&reference::elliptic(&s, load, phi).unwrap());
        }
    }
}

/// R = 1e308 m on a plane with G = 5e-324 Pa: the half-width b
/// overflows, and d = (d/b) b was 0 x inf = NaN at phi = 0.
#[test]
fn line_slip_width_of_an_overflowing_strip() {
    let s = Scene::new(1e308, f64::INFINITY, f64::from_bits(1), 0.3, 0.3).unwrap();
    for phi in [0.0, 1e-300, 1e-3, 1.0] {
        for load in [0.0, 1e-300, 1.0, 1e300] {
            assert_no_nan_line(&reference::line(&s, load, phi).unwrap());
        }
    }
}

/// R1 = R2 = f64::MAX, G = 5e-324 Pa, mu = f64::MAX, P = 0: R1 + R2
/// overflowed and the critical load was 0 x inf = NaN; P* lost its value the same way.
#[test]
fn critical_load_with_radii_whose_sum_overflows() {
    let s = Scene::new(f64::MAX, f64::MAX, f64::from_bits(1), 0.3, f64::MAX).unwrap();
    for phi in [0.0, 1e-3, 1.0] {
        for load in [0.0, 1.0, 1e300] {
            let e = reference::elliptic(&s, load, phi).unwrap();
            assert_no_nan_elliptic(&e);
            assert_no_nan_line(&reference::line(&s, load, phi).unwrap());
        }
    }
    // P* = 2 P / ((1 - nu)^2 G (R1 + R2) sqrt(R1 R2)) is a normal number here.
    let e = reference::elliptic(&s, 1.0, 1e-3).unwrap();
    let want = 1.0 / (0.49 * (f64::from_bits(1) * f64::MAX) * f64::MAX);
    assert!(
        want > 1e-294 && (e.pstar / want - 1.0).abs() < 1e-12,
        "{} {want}",
        e.pstar
    );
}

/// An angle LSB with c x LSB above pi/2 left no angle count but 0
/// (angle_max = 0), and `log2 theta0 - log2(c LSB)` overflowed i32: with overflow
/// checks a panic, without them a margin of i32::MAX counts where the true one is 0.
/// Such an LSB is now refused when the scene is prepared.
#[test]
fn fixed_angle_lsb_above_a_right_angle_is_refused() {
    let s = Scene::new(1e10, 1e10, 1.0, 1e-300, 0.3).unwrap();
    match FixedEllipticScene::new(&s, 1e-6, 1e30) {
        Err(e) => assert_eq!(e, Error::OutOfRange),
        Ok(core) => panic!(
            "accepted with {:?}: {:?}",
            core.input_range(),
            core.estimate(1000, 0)
        ),
    }
    assert_eq!(
        FixedLineScene::new(&s, 1e-6, 1e30).err(),
        Some(Error::OutOfRange)
    );
    // The largest LSB that still has an angle count of 1 in range is accepted.
    let core = FixedEllipticScene::new(&s, 1e-6, 1.5).unwrap();
    assert_eq!(core.input_range().angle_max, 1);
    let e = core.estimate(1000, 1).unwrap();
    assert!(e.margin.is_none_or(|m| m.abs() <= 2), "{e:?}");
}

/// In the fixed-point core mu P above 2^127 N saturated F to
/// `Log2::INFINITY` (here in gross slip of line contact: R = 1e-30 m, G = 1e90 Pa,
/// mu = 1e-10, mu x load LSB x 2^32 = 2^130 N). A scene whose largest load count would
/// do so is refused.
#[test]
fn fixed_axial_force_beyond_the_log2_range_is_refused() {
    let s = Scene::new(1e-30, 1e-30, 1e90, 0.3, 1e-10).unwrap();
    let lsb = 2f64.powi(98) / 1e-10;
    let angle_lsb = 2f64.powi(-40);
    for core in [
        FixedEllipticScene::new(&s, lsb, angle_lsb).map(|c| c.estimate(u32::MAX, 1)),
        FixedLineScene::new(&s, lsb, angle_lsb).map(|c| c.estimate(u32::MAX, 1)),
    ] {
        match core {
            Err(e) => assert_eq!(e, Error::OutOfRange),
            Ok(Err(e)) => assert_eq!(e, Error::OutOfRange),
            Ok(Ok(e)) => assert!(e.axial_force != Log2::INFINITY, "{e:?}"),
        }
    }
}

/// In gross slip the fixed-point F exceeded mu P by up to 3.8e-8
/// relative (a quarter of realistic rows; this one gave 300.0000050 N for mu P = 300 N).
#[test]
fn fixed_axial_force_never_exceeds_mu_p() {
    let s = Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3).unwrap();
    let mu = s.friction();
    let (load_lsb, p) = exact_lsb(1000.0, 1 << 30, 0.0);
    let (angle_lsb, a) = exact_lsb(1.0, 1 << 30, FixedEllipticScene::min_angle_lsb(&s));
    let core = FixedEllipticScene::new(&s, load_lsb, angle_lsb).unwrap();
    let e = core.estimate(p, a as i32).unwrap();
    assert_eq!(e.regime, Regime::Gross);
    let f = e.axial_force.to_f64();
    assert!(f <= mu * 1000.0 && f > mu * 1000.0 * (1.0 - 1e-6), "{f}");
    // Every load count's octave and fraction, both models, partial and gross slip.
    let line = FixedLineScene::new(&s, 1.0, 1e-7).unwrap();
    let elliptic = FixedEllipticScene::new(&s, 1.0, 1e-7).unwrap();
    let mut worst: f64 = 0.0;
    for k in 0..32 {
        for frac in [0u32, 1, 0x1234_5678, 0x7fff_ffff, 0xffff_ffff] {
            let load = (1u32 << k) | (frac >> (32 - k.max(1)));
            for angle in [1, 1000, 100_000, 10_000_000, -15_000_000] {
                for est in [line.estimate(load, angle), elliptic.estimate(load, angle)] {
                    let Ok(est) = est else { continue };
                    let ratio = est.axial_force.to_f64() / (mu * load as f64);
                    worst = worst.max(ratio);
                }
            }
        }
    }
    assert!(worst <= 1.0, "F / (mu P) up to {worst}");
}

/// One fixed-point scene's estimator.
type Estimator = Box<dyn Fn(u32, i32) -> Result<FixedEstimate, Error>>;

/// Over extreme but accepted scenes and LSBs, every fixed-point answer
/// at a load above 0 holds its values: no d/b, F or phi0 saturated to the values that
/// stand for 0 or infinity (F was 2^-128 = `Log2::ZERO` at a misalignment for mu = 1e-10,
/// G = 1e-38 Pa), and no sum wraps (the tests build with overflow checks).
#[test]
fn fixed_results_fit_over_extreme_scenes() {
    let extremes = [1e-30, 0.05, 1e30, 1e300];
    let mut accepted = 0;
    for r in extremes {
        for g in [1e-38, 79.3e9, 1e38, 1e300] {
            for mu in [1e-10, 0.3, 1e10, 1e30] {
                let s = Scene::new(r, r, g, 0.3, mu).unwrap();
                for (lp, la) in (-100..=99)
                    .step_by(20)
                    .flat_map(|lp| [-60, -40, -20, 0, 1].map(|la| (lp, la)))
                {
                    let (load_lsb, angle_lsb) = (2f64.powi(lp), 2f64.powi(la));
                    let elliptic = FixedEllipticScene::new(&s, load_lsb, angle_lsb);
                    let line = FixedLineScene::new(&s, load_lsb, angle_lsb);
                    for (model, range, estimate) in [
                        elliptic.map(|c| (c.input_range(), c)).ok().map(|(r, c)| {
                            (
                                "elliptic",
                                r,
                                Box::new(move |p, a| c.estimate(p, a)) as Estimator,
                            )
                        }),
                        line.map(|c| (c.input_range(), c)).ok().map(|(r, c)| {
                            (
                                "line",
                                r,
                                Box::new(move |p, a| c.estimate(p, a)) as Estimator,
                            )
                        }),
                    ]
                    .into_iter()
                    .flatten()
                    {
                        accepted += 1;
                        let angle_max = range.angle_max.min(i32::MAX as u32) as i32;
                        for load in [range.load_min.max(1), 1000, u32::MAX] {
                            for angle in [0, 1, -1, angle_max / 2, angle_max] {
                                let Ok(e) = estimate(load, angle) else {
                                    continue;
                                };
                                let what = format!(
                                    "{model} R {r} G {g} mu {mu} LSBs 2^{lp} 2^{la} P {load} a {angle}: {e:?}"
                                );
                                let special = [Log2::ZERO, Log2::INFINITY];
                                assert!(
                                    !special.contains(&e.critical_angle.unwrap_or(Log2(0))),
                                    "{what}"
                                );
                                if angle != 0 {
                                    assert!(!special.contains(&e.slip_ratio), "{what}");
                                    assert!(!special.contains(&e.axial_force), "{what}");
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    assert!(accepted > 100, "{accepted}");
}

/// Mu = 1e10 and P = 1e38 N gave F = inf in the f32 core (rollers of
/// 1e15 m, where d/b is not small); it is refused with a typed error where mu P does
/// not fit f32 (scene or sample), never an infinity.
#[test]
fn f32_axial_force_that_overflows_is_refused() {
    let s = Scene::new(1e15, 1e15, 79.3e9, 0.3, 1e10).unwrap();
    if let Ok(core) = EllipticScene::new(&s) {
        let got = core.estimate(1e38, 1.0);
        assert!(
            got.is_err_and(|e| e == Error::OutOfRange)
                || got.is_ok_and(|e| e.axial_force.is_finite()),
            "{got:?}"
        );
    }
    if let Ok(core) = LineScene::new(&s) {
        let got = core.estimate(1e38, 1e-3);
        assert!(
            got.is_err_and(|e| e == Error::OutOfRange)
                || got.is_ok_and(|e| e.axial_force.is_finite()),
            "{got:?}"
        );
    }
}

/// G = 1e-38 Pa and P = 1e38 N/m gave a line-contact phi0 = inf in f32
/// (a roller of 0.1 mm on a plane): refused, or no critical angle (phi0 beyond pi/2),
/// never a number above it.
#[test]
fn f32_line_critical_angle_that_overflows_is_refused() {
    let s = Scene::new(1e-4, f64::INFINITY, 1e-38, 0.3, 0.3).unwrap();
    if let Ok(core) = LineScene::new(&s) {
        let got = core.estimate(1e38, 1e-3);
        assert!(
            got.is_err_and(|e| e == Error::OutOfRange)
                || got.is_ok_and(|e| e
                    .critical_angle
                    .is_none_or(|c| c <= core::f32::consts::FRAC_PI_2)
                    && e.margin.is_none_or(f32::is_finite)
                    && e.axial_force.is_finite()),
            "{got:?}"
        );
    }
}

/// Phi0 underflowed to 0 at a load above 0 in the f32 cores (a light load
/// with a small critical gain); 0 is the answer for zero load only.
#[test]
fn f32_critical_angle_never_underflows_to_zero_at_a_load() {
    for mu in [1e-30, 1e-12, 1e-6, 0.3] {
        let s = Scene::new(0.05, 0.05, 79.3e9, 0.3, mu).unwrap();
        for load in [f32::from_bits(1), 1e-40, 1e-30, 1e-20, 1.0] {
            for phi in [0.0, 1e-3] {
                if let Ok(core) = EllipticScene::new(&s)
                    && let Ok(e) = core.estimate(load, phi)
                {
                    assert!(
                        e.critical_angle.is_none_or(|c| c > 0.0 && c.is_finite()),
                        "elliptic mu {mu} P {load}: {e:?}"
                    );
                }
                if let Ok(core) = LineScene::new(&s)
                    && let Ok(e) = core.estimate(load, phi)
                {
                    assert!(
                        e.critical_angle.is_some_and(|c| c > 0.0 && c.is_finite()),
                        "line mu {mu} P {load}: {e:?}"
                    );
                }
            }
        }
    }
}

/// Over extreme but accepted scenes, every f32 answer at a load above 0
/// is finite, with |F| <= mu P and a normal phi0 (line phi0 was inf for R = 1e-30 m,
/// G = 1e-38 Pa, mu = 1e-10, P = 1e38 N/m).
#[test]
fn f32_results_fit_over_extreme_scenes() {
    let mut accepted = 0;
    for r in [1e-30, 0.05, 1e30, 1e300] {
        for g in [1e-38, 79.3e9, 1e38, 1e300] {
            for mu in [1e-30, 1e-10, 0.3, 100.0, 1e10, 1e30] {
                let s = Scene::new(r, r, g, 0.3, mu).unwrap();
                let (e, l) = (EllipticScene::new(&s), LineScene::new(&s));
                accepted += e.is_ok() as usize + l.is_ok() as usize;
                for p in [f32::from_bits(1), 1e-38, 1e-3, 1e20, 1e38, f32::MAX] {
                    for phi in [1e-30f32, 1e-3, -1.0, 1.5] {
                        let answers = [
                            e.as_ref().ok().map(|c| ("elliptic", c.estimate(p, phi))),
                            l.as_ref().ok().map(|c| ("line", c.estimate(p, phi))),
                        ];
                        for (model, answer) in answers.into_iter().flatten() {
                            let Ok(x) = answer else { continue };
                            let what =
                                format!("{model} R {r} G {g} mu {mu} P {p} phi {phi}: {x:?}");
                            assert!(x.slip_ratio.is_finite() && x.slip_ratio >= 0.0, "{what}");
                            let mu_p = s.friction() * p as f64;
                            assert!(
                                (x.axial_force.abs() as f64) <= mu_p * (1.0 + 1e-6),
                                "{what}"
                            );
                            assert!(x.critical_angle.is_none_or(|c| c.is_normal()), "{what}");
                            assert!(x.margin.is_none_or(f32::is_finite), "{what}");
                        }
                    }
                }
            }
        }
    }
    assert!(accepted > 50, "{accepted}");
    // A realistic scene accepts every positive f32 load.
    let steel = Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3).unwrap();
    let range = LineScene::new(&steel).unwrap().load_range();
    assert_eq!(range, (f32::from_bits(1), f32::MAX));
}

/// The structured fuzzer from an empty corpus: `Log2::to_fixed` with a
/// fraction-bit count above 2^31 overflowed i32 (a panic with overflow checks). It
/// saturates like any other result beyond u32.
#[test]
fn log2_to_fixed_with_a_huge_fraction_bit_count() {
    for bits in [40, 1 << 31, u32::MAX] {
        assert_eq!(Log2(0).to_fixed(bits), u32::MAX, "{bits}");
    }
    // 2^-120 with 2^31 fraction bits is still far beyond u32; with 40 it is 0.
    assert_eq!(Log2(-(120 << 24)).to_fixed(1 << 31), u32::MAX);
    assert_eq!(Log2(-(120 << 24)).to_fixed(40), 0);
    assert_eq!(Log2::ZERO.to_fixed(u32::MAX), 0);
    assert_eq!(Log2(0).to_fixed(0), 1);
}
