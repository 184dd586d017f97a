//! Section 9's model choice per sample, the same in the reference, the f32 core and the
//! fixed-point core: which model answers, one meaning of P with a length,
//! the flag and the jump at the switch, |phi| <= pi/2, nu = 0.5, line-contact details,
//! rolling resistance and power.

use misalign::fixed::{FixedAuto, FixedContactDetails, FixedLineScene, exact_lsb};
use misalign::float::{Auto, ContactDetails, EllipticScene, LineScene};
use misalign::reference::{self, ContactModel, MODEL_SWITCH_BAND, ModelChoice, Solution};
use misalign::{Error, Scene};

fn rel(got: f64, want: f64) -> f64 {
    if got == want {
        0.0
    } else {
        ((got - want) / want).abs()
    }
}

/// A small deterministic generator (xorshift), so that the samples are repeatable.
struct Draw(u64);

impl Draw {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Log-uniform in [lo, hi].
    fn log(&mut self, lo: f64, hi: f64) -> f64 {
        lo * (hi / lo).powf(self.unit())
    }
}

/// 2a / length of the reference ellipse, or None for a plane.
fn length_ratio(scene: &Scene, load: f64, phi: f64) -> Option<f64> {
    let e = reference::elliptic(scene, load, phi).ok()?;
    Some(2.0 * e.a / scene.length().unwrap())
}

/// The fixed-point scene and counts for one sample: LSBs that hold P and phi exactly.
fn fixed_sample(scene: &Scene, load: f64, phi: f64, choice: ModelChoice) -> (FixedAuto, u32, i32) {
    let (load_lsb, p) = exact_lsb(load, 1 << 30, 0.0);
    let min_angle = misalign::fixed::FixedEllipticScene::min_angle_lsb(scene);
    let (angle_lsb, a) = exact_lsb(phi, 1 << 30, if scene.is_plane() { 0.0 } else { min_angle });
    let angle = if phi < 0.0 { -(a as i32) } else { a as i32 };
    let auto = FixedAuto::with_choice(scene, load_lsb, angle_lsb, choice).unwrap();
    (auto, p, angle)
}

#[test]
fn every_model_chooses_the_same_model_on_every_sample() {
    let mut draw = Draw(0x9e37_79b9_7f4a_7c15);
    let (mut line, mut elliptic, mut near) = (0, 0, 0);
    for i in 0..3000 {
        let r1 = draw.log(0.01, 2.0);
        let r2 = if i % 10 == 0 {
            f64::INFINITY
        } else {
            draw.log(0.01, 2.0)
        };
        let length = draw.log(0.05, 3.0);
        let scene = Scene::new(r1, r2, 79.3e9, 0.3, draw.log(0.05, 0.5))
            .unwrap()
            .with_length(length)
            .unwrap();
        // Every 50th sample at zero angle (a = inf: line contact), every 50th unloaded
        // (a = 0: the ellipse).
        let load = if i % 50 == 2 { 0.0 } else { draw.log(1.0, 1e6) };
        let phi = if i % 50 == 1 {
            0.0
        } else {
            draw.log(1e-6, 0.05) * if i % 3 == 0 { -1.0 } else { 1.0 }
        };
        // Within 1e-5 of 2a = length the cores' rounding may take the other side.
        if length_ratio(&scene, load, phi).is_some_and(|r| (r - 1.0).abs() < 1e-5) {
            continue;
        }
        let want = reference::estimate(&scene, load, phi).unwrap();
        let f32_auto = Auto::new(&scene)
            .unwrap()
            .estimate(load as f32, phi as f32)
            .unwrap();
        let (fixed, p, a) = fixed_sample(&scene, load, phi, ModelChoice::Section9);
        let fixed_auto = fixed.estimate(p, a).unwrap();
        assert_eq!(f32_auto.model, want.model(), "f32, sample {i}");
        assert_eq!(fixed_auto.model, want.model(), "fixed, sample {i}");
        let flag = want.validity().near_model_switch;
        // The band's edges are as sharp as the model edge: skip them for the flag.
        let r = length_ratio(&scene, load, phi);
        let at_edge = r.is_some_and(|r| {
            (r * MODEL_SWITCH_BAND - 1.0).abs() < 1e-5 || (r / MODEL_SWITCH_BAND - 1.0).abs() < 1e-5
        });
        if !at_edge {
            assert_eq!(f32_auto.near_model_switch, flag, "f32 flag, sample {i}");
            assert_eq!(fixed_auto.near_model_switch, flag, "fixed flag, sample {i}");
        }
        // And the numbers of the chosen model agree (the cores' bounds).
        let s = want.slip_ratio();
        if s.is_finite() && s > 0.0 {
            assert!(
                rel(f32_auto.estimate.slip_ratio as f64, s) < 2e-6,
                "sample {i}"
            );
            assert!(
                rel(fixed_auto.estimate.slip_ratio.to_f64(), s) < 1e-4,
                "sample {i}"
            );
            let f = want.axial_force(&scene);
            assert!(
                rel(f32_auto.estimate.axial_force as f64, f) < 2e-6,
                "sample {i}"
            );
        }
        match want.model() {
            ContactModel::Line => line += 1,
            ContactModel::Elliptic => elliptic += 1,
        }
        near += flag as usize;
    }
    println!("line {line}, elliptic {elliptic}, near the switch {near}");
    assert!(
        line > 500 && elliptic > 500 && near > 50,
        "{line} {elliptic} {near}"
    );
}

/// With a length, P is the total load in every model and every choice: line contact
/// works with P / length, and F comes back as a total.
#[test]
fn forced_line_contact_reads_the_total_load_in_every_model() {
    let scene = Scene::new(0.05, 0.08, 79.3e9, 0.3, 0.3)
        .unwrap()
        .with_length(0.4)
        .unwrap();
    let (load, phi) = (2000.0, 3e-4);
    let per_length = reference::line(&scene, load / 0.4, phi).unwrap();
    let Solution::Line(r) = reference::estimate_with(&scene, load, phi, ModelChoice::Line).unwrap()
    else {
        panic!("forced line contact answered with the ellipse");
    };
    assert_eq!(r, per_length);
    let f = per_length.axial_force * 0.4;
    let c = Auto::with_choice(&scene, ModelChoice::Line)
        .unwrap()
        .estimate(load as f32, phi as f32)
        .unwrap();
    assert_eq!(c.model, ContactModel::Line);
    assert!(rel(c.estimate.slip_ratio as f64, r.slip_ratio) < 2e-6);
    assert!(rel(c.estimate.axial_force as f64, f) < 2e-6);
    let (fixed, p, a) = fixed_sample(&scene, load, phi, ModelChoice::Line);
    let x = fixed.estimate(p, a).unwrap();
    assert_eq!(x.model, ContactModel::Line);
    assert!(rel(x.estimate.slip_ratio.to_f64(), r.slip_ratio) < 1e-4);
    assert!(rel(x.estimate.axial_force.to_f64(), f) < 1e-4);
    // Forced ellipse: the ellipse, flagged as longer than the rollers when it is.
    let e = reference::estimate_with(&scene, load, 1e-6, ModelChoice::Elliptic).unwrap();
    assert_eq!(e.model(), ContactModel::Elliptic);
    assert!(e.validity().longer_than_rollers);
    // A plane cannot be forced to the ellipse, anywhere.
    let plane = Scene::new(0.05, f64::INFINITY, 79.3e9, 0.3, 0.3).unwrap();
    assert_eq!(
        reference::estimate_with(&plane, load, phi, ModelChoice::Elliptic).err(),
        Some(Error::PlaneHasNoEllipse)
    );
    assert_eq!(
        Auto::with_choice(&plane, ModelChoice::Elliptic).err(),
        Some(Error::PlaneHasNoEllipse)
    );
    assert_eq!(
        FixedAuto::with_choice(&plane, 1.0, 1e-6, ModelChoice::Elliptic).err(),
        Some(Error::PlaneHasNoEllipse)
    );
    // A plane without a length: line contact with P in N/m, in every model.
    let r = reference::estimate(&plane, 1e4, phi).unwrap();
    assert_eq!(r.model(), ContactModel::Line);
    let c = Auto::new(&plane)
        .unwrap()
        .estimate(1e4, phi as f32)
        .unwrap();
    assert_eq!(c.model, ContactModel::Line);
    assert!(rel(c.estimate.slip_ratio as f64, r.slip_ratio()) < 2e-6);
}

/// E(k), the complete elliptic integral of the second kind, by Simpson's rule.
fn complete_e(k: f64) -> f64 {
    let n = 20_000;
    let h = core::f64::consts::FRAC_PI_2 / n as f64;
    let f = |t: f64| (1.0 - k * k * t.sin().powi(2)).sqrt();
    let mut sum = f(0.0) + f(core::f64::consts::FRAC_PI_2);
    for i in 1..n {
        sum += f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    sum * h / 3.0
}

/// At 2a = length the line model's d/b is sqrt(3 / (2 E(k))) times the ellipse's
/// (1.22 for a slender ellipse), phi0 jumps to the other model's value, and every model
/// flags the sample as near the switch.
#[test]
fn the_jump_at_the_switch_is_the_documented_one() {
    for (phi, length) in [(2e-4, 0.3), (2e-3, 0.3), (0.02, 0.05)] {
        let base = Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3).unwrap();
        let scene = base.with_length(length).unwrap();
        // a grows like P^(1/3): the load at which 2a = length.
        let a1 = reference::elliptic(&base, 1.0, phi).unwrap().a;
        let p_switch = (length / (2.0 * a1)).powi(3);
        let below = reference::estimate(&scene, p_switch * (1.0 - 1e-9), phi).unwrap();
        let above = reference::estimate(&scene, p_switch * (1.0 + 1e-9), phi).unwrap();
        let (Solution::Elliptic(e), Solution::Line(l)) = (below, above) else {
            panic!("no switch at 2a = length");
        };
        let k = (1.0 - e.shape.kprime * e.shape.kprime).sqrt();
        let jump = (3.0 / (2.0 * complete_e(k))).sqrt();
        println!(
            "phi {phi}: a/b {:.0}, d/b line/elliptic {:.6}, predicted {jump:.6}, F {:.4}, phi0 {:.4}",
            e.a / e.b,
            l.slip_ratio / e.slip_ratio,
            above.axial_force(&scene) / e.axial_force,
            l.critical_angle.unwrap() / e.critical_angle.unwrap()
        );
        assert!(rel(l.slip_ratio / e.slip_ratio, jump) < 1e-6);
        assert!((jump - 1.5f64.sqrt()).abs() < 0.1);
        assert!(e.validity.near_model_switch && l.validity.near_model_switch);
        // phi0 of the line model: eq (28) at P / length, not the ellipse's.
        assert!(
            rel(
                l.critical_angle.unwrap(),
                reference::line(&scene, p_switch / length, 0.0)
                    .unwrap()
                    .critical_angle
                    .unwrap()
            ) < 1e-9
        );
        for p in [p_switch * 0.999, p_switch * 1.001] {
            let f = Auto::new(&scene)
                .unwrap()
                .estimate(p as f32, phi as f32)
                .unwrap();
            assert!(f.near_model_switch);
            let (x, counts, a) = fixed_sample(&scene, p, phi, ModelChoice::Section9);
            assert!(x.estimate(counts, a).unwrap().near_model_switch);
        }
    }
}

/// The angle between two axes is at most a right angle: |phi| above pi/2 (as the
/// input's precision rounds it) is refused in every model, also when unequal radii keep
/// theta = c |phi| below pi/2; f64's FRAC_PI_2 and f32's are accepted.
#[test]
fn beyond_a_right_angle_is_refused_in_every_model() {
    let unequal = Scene::new(0.05, 0.5, 79.3e9, 0.3, 0.3).unwrap();
    let equal = Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3).unwrap();
    let half_pi = core::f64::consts::FRAC_PI_2;
    let above = half_pi.next_up();
    let above32 = core::f32::consts::FRAC_PI_2.next_up();
    for scene in [unequal, equal] {
        for (phi, phi32) in [(above, above32), (-above, -above32), (2.0, 2.0), (3.0, 3.0)] {
            let answers = [
                reference::elliptic(&scene, 1e3, phi).err(),
                reference::line(&scene, 1e3, phi).err(),
                reference::estimate(&scene, 1e3, phi).err(),
                EllipticScene::new(&scene)
                    .unwrap()
                    .estimate(1e3, phi32)
                    .err(),
                EllipticScene::new(&scene)
                    .unwrap()
                    .details(1e3, phi32)
                    .err(),
                LineScene::new(&scene).unwrap().estimate(1e3, phi32).err(),
                LineScene::new(&scene).unwrap().details(1e3, phi32).err(),
                Auto::new(&scene).unwrap().estimate(1e3, phi32).err(),
            ];
            assert_eq!(answers, [Some(Error::Angle); 8], "phi = {phi}");
        }
        for phi in [half_pi, half_pi.next_down()] {
            assert!(reference::elliptic(&scene, 1e3, phi).is_ok());
            assert!(reference::line(&scene, 1e3, phi).is_ok());
            assert!(reference::estimate(&scene, 1e3, phi).is_ok());
        }
        let phi32 = core::f32::consts::FRAC_PI_2;
        assert!(
            EllipticScene::new(&scene)
                .unwrap()
                .estimate(1e3, phi32)
                .is_ok()
        );
        assert!(LineScene::new(&scene).unwrap().estimate(1e3, phi32).is_ok());
        assert!(Auto::new(&scene).unwrap().estimate(1e3, phi32).is_ok());
        // Fixed point: the last count is the largest whose angle is at most pi/2 in f64.
        let lsb = half_pi / 1000.0;
        let fixed = misalign::fixed::FixedEllipticScene::new(&scene, 1.0, lsb).unwrap();
        let last = fixed.input_range().angle_max;
        assert!(last as f64 * lsb <= half_pi && (last + 1) as f64 * lsb > half_pi);
        assert!(last >= 999, "{last}");
        assert_eq!(
            fixed.estimate(1000, last as i32 + 1).err(),
            Some(Error::Angle)
        );
        assert!(fixed.estimate(1000, last as i32).is_ok());
        let line = FixedLineScene::new(&scene, 1.0, lsb).unwrap();
        assert_eq!(line.input_range().angle_max, last);
        assert_eq!(
            line.estimate(1000, -(last as i32) - 1).err(),
            Some(Error::Angle)
        );
        assert!(line.estimate(1000, -(last as i32)).is_ok());
    }
}

/// Only 1 - nu enters: incompressible rollers (nu = 0.5, rubber) are accepted and every
/// model answers alike.
#[test]
fn incompressible_rollers_are_accepted() {
    let scene = Scene::new(0.05, 0.05, 1e6, 0.5, 0.8).unwrap();
    let r = reference::elliptic(&scene, 10.0, 1e-3).unwrap();
    assert!(r.slip_ratio.is_finite() && r.a.is_finite() && r.p0 > 0.0);
    let f = EllipticScene::new(&scene)
        .unwrap()
        .estimate(10.0, 1e-3)
        .unwrap();
    assert!(rel(f.slip_ratio as f64, r.slip_ratio) < 2e-6);
    let l = reference::line(&scene, 100.0, 1e-3).unwrap();
    let g = LineScene::new(&scene)
        .unwrap()
        .estimate(100.0, 1e-3)
        .unwrap();
    assert!(rel(g.slip_ratio as f64, l.slip_ratio) < 2e-6);
    assert_eq!(
        Scene::new(0.05, 0.05, 1e6, 0.5 + 1e-12, 0.8).err(),
        Some(Error::PoissonRatio)
    );
}

/// Section 7's rolling resistance F phi / 2 and power F phi V for the strip too, per
/// unit length, and as totals over the length from the model choice.
#[test]
fn rolling_resistance_and_power_in_line_contact() {
    let scene = Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3)
        .unwrap()
        .with_length(0.3)
        .unwrap();
    let (load, phi, speed) = (5000.0, -4e-4, 2.0);
    let l = reference::line(&scene, load / 0.3, phi).unwrap();
    assert_eq!(l.rolling_resistance(), 0.5 * l.axial_force * phi);
    assert_eq!(l.dissipated_power(speed), l.axial_force * phi * speed);
    assert!(l.rolling_resistance() > 0.0); // F has the sign of phi
    let est = reference::estimate(&scene, load, 1e-6).unwrap();
    assert_eq!(est.model(), ContactModel::Line);
    let Solution::Line(per_length) = est else {
        unreachable!()
    };
    assert!(
        rel(
            est.rolling_resistance(&scene),
            per_length.rolling_resistance() * 0.3
        ) < 1e-15
    );
    assert!(
        rel(
            est.dissipated_power(&scene, speed),
            per_length.dissipated_power(speed) * 0.3
        ) < 1e-15
    );
}

/// b and p0 of the strip in both cores, against the reference, with and without a length.
#[test]
fn line_details_in_both_cores() {
    let base = Scene::new(0.04, f64::INFINITY, 79.3e9, 0.3, 0.3).unwrap();
    for (scene, per_length) in [(base, 1.0), (base.with_length(0.25).unwrap(), 0.25)] {
        for load in [0.0, 1.0, 1234.5, 3e6] {
            let r = reference::line(&scene, load / per_length, 1e-3).unwrap();
            let d = LineScene::new(&scene)
                .unwrap()
                .details(load as f32, 1e-3)
                .unwrap();
            assert!(
                rel(d.b as f64, r.b) < 2e-6 && rel(d.p0 as f64, r.p0) < 2e-6,
                "{load}"
            );
            let ContactDetails::Line(a) = Auto::new(&scene)
                .unwrap()
                .details(load as f32, 1e-3)
                .unwrap()
            else {
                panic!("a plane answered with an ellipse");
            };
            assert_eq!(a, d);
            let (x, p, angle) = fixed_sample(&scene, load.max(1.0), 1e-3, ModelChoice::Section9);
            let FixedContactDetails::Line(f) = x.details(p, angle).unwrap() else {
                panic!("a plane answered with an ellipse");
            };
            let r = reference::line(&scene, load.max(1.0) / per_length, 1e-3).unwrap();
            assert!(
                rel(f.b.to_f64(), r.b) < 1e-4 && rel(f.p0.to_f64(), r.p0) < 1e-4,
                "{load}"
            );
        }
    }
}

/// The slender-ellipse theory is flagged where the ellipse is rounder than a/b = 10.
#[test]
fn round_ellipses_are_flagged() {
    let scene = Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3).unwrap();
    let slender = reference::elliptic(&scene, 1e3, 1e-3).unwrap();
    assert!(slender.a / slender.b > 100.0 && !slender.validity.round_ellipse);
    let round = reference::elliptic(&scene, 1e3, 0.5).unwrap();
    assert!(round.a / round.b < reference::SLENDER_LIMIT && round.validity.round_ellipse);
    assert!(!round.validity.is_valid());
}

/// A length absurd against the radii (1e-12 m or 1e-30 m for 50 mm rollers, or one in
/// the wrong unit) is refused when the scene is built, so that every model, prepared
/// scene and batch refuses it alike. The f32 chooser had answered a margin of 406 rad
/// at 2 kN and 2 mrad (phi0 far beyond pi/2), the fixed-point one a margin saturated
/// at 214.748 rad, both with d/b 0.
#[test]
fn a_length_absurd_against_the_radii_is_refused_in_every_model() {
    let (load, phi) = (2e3, 2e-3);
    for length in [1e-12, 1e-30, 1e-7] {
        match Scene::DEMO.with_length(length) {
            Err(e) => assert_eq!(e, Error::LengthTooShort, "{length}"),
            Ok(scene) => {
                let f32_margin = Auto::new(&scene)
                    .ok()
                    .and_then(|a| a.estimate(load as f32, phi as f32).ok())
                    .and_then(|e| e.estimate.margin);
                let fixed_margin = FixedAuto::new(&scene, 1.0, 1e-7)
                    .ok()
                    .and_then(|a| {
                        misalign::Estimator::estimate_si(&a, load as f32, phi as f32).ok()
                    })
                    .and_then(|e| e.margin);
                panic!(
                    "length {length} m accepted: margin {f32_margin:?} rad (f32), \
                     {fixed_margin:?} rad (fixed)"
                );
            }
        }
    }
    // The bound: 2 (1 - nu) R x 1e-5, the strip's half-width at p0 = 1e-5 G.
    let shortest = Scene::DEMO.shortest_length();
    let r = Scene::DEMO.effective_radius();
    assert!(rel(shortest, 2.0 * 0.7 * r * misalign::SHORT_ROLLER_PRESSURE) < 1e-15);
    assert!(Scene::DEMO.with_length(shortest).is_ok());
    assert_eq!(
        Scene::DEMO.with_length(shortest.next_down()),
        Err(Error::LengthTooShort)
    );
    // The relation it rests on, b / R = 2 (1 - nu) p0 / G (eqs 22, 31), over loads.
    for per_length in [1e-3, 1.0, 1e4, 1e8] {
        let l = reference::line(&Scene::DEMO, per_length, 1e-3).unwrap();
        let g = Scene::DEMO.shear_modulus();
        assert!(rel(l.b / r, 2.0 * 0.7 * l.p0 / g) < 1e-12, "{per_length}");
    }
    // A length in mm for a scene in m is fine: the bound is far below any roller.
    assert!(Scene::DEMO.with_length(1e-3).is_ok());
    // The message says what is wrong and suggests the unit.
    let message = Error::LengthTooShort.to_string();
    assert!(
        message.contains("1e-5") && message.contains(" m?"),
        "{message}"
    );
    assert_eq!(format!("{:e}", misalign::SHORT_ROLLER_PRESSURE), "1e-5");
    // The batch API builds each row's scene the same way: the row is refused.
    let (r1, l) = ([0.05; 2], [0.3, 1e-12]);
    let inputs = misalign::batch::Inputs {
        r1: misalign::batch::Column::Each(&r1),
        length: Some(misalign::batch::Column::Each(&l)),
        ..misalign::batch::Inputs::one_scene(
            &Scene::DEMO,
            misalign::batch::Column::One(load),
            misalign::batch::Column::One(phi),
        )
    };
    for model in [
        misalign::batch::Model::Reference,
        misalign::batch::Model::F32,
        misalign::batch::Model::Fixed(misalign::batch::Counts::Adc {
            load_lsb: 1.0,
            angle_lsb: Some(1e-7),
        }),
        misalign::batch::Model::Fixed(misalign::batch::Counts::Exact),
    ] {
        let mut status = [0u8; 2];
        let (mut s, mut f, mut phi0) = ([0.0; 2], [0.0; 2], [0.0; 2]);
        let (mut regime, mut choice, mut flags) = ([0u8; 2], [0u8; 2], [0u8; 2]);
        let mut out = misalign::batch::Outputs {
            slip_ratio: &mut s,
            axial_force: &mut f,
            critical_angle: &mut phi0,
            regime: &mut regime,
            model: &mut choice,
            flags: &mut flags,
            status: &mut status,
            details: None,
        };
        assert_eq!(misalign::batch::estimate(&inputs, &mut out, model), Ok(1));
        assert_eq!(
            misalign::batch::error_of(status[1]),
            Some(Error::LengthTooShort),
            "{model:?}"
        );
        assert_eq!(status[0], misalign::batch::OK, "{model:?}");
    }
}
