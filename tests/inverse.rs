//! Inverse estimates: forward, then inverse, over the public reference
//! scenes recovers mu and phi within 1e-12 relative (reference) times the sensitivity
//! where it exceeds 1, wherever the sensitivity is below 1e3; says `at_least` exactly
//! where the forward map saturates; bad input gets typed errors or `inconsistent`.

mod common;
use common::{Row, num, read_rows, rel_err};
use misalign::reference::inverse::{self, Inconsistency, Inverse};
use misalign::reference::{self, ContactModel};
use misalign::{Error, Scene};

/// Round-trip bound of the reference, relative, times max(1, sensitivity).
const REFERENCE_BOUND: f64 = 1e-12;
/// Above this sensitivity the answer is not held to a bound (F alone hardly fixes it).
const SENSITIVITY_CAP: f64 = 1e3;

fn scene(row: &Row) -> Scene {
    Scene::new(
        num(row, "R1"),
        num(row, "R2"),
        num(row, "G"),
        num(row, "nu"),
        num(row, "mu"),
    )
    .unwrap()
}

/// The same installation with another (placeholder) friction: the mu-inverse must not
/// read it.
fn placeholder(scene: &Scene) -> Scene {
    let s = Scene::new(
        scene.r1(),
        scene.r2(),
        scene.shear_modulus(),
        scene.poisson_ratio(),
        0.777,
    )
    .unwrap()
    .with_theta_relation(scene.theta_relation());
    match scene.length() {
        Some(l) => s.with_length(l).unwrap(),
        None => s,
    }
}

/// Tally of the round trips, so that a test that checked nothing fails.
#[derive(Default, Debug)]
struct Tally {
    exact: usize,
    at_least: usize,
    skipped_sensitive: usize,
    worst: f64,
}

impl Tally {
    /// A mu-inverse's answer for true `mu` at slip ratio `slip`: exact within the
    /// bound, or `at_least` (never above mu) only far in partial slip, within rounding
    /// of the no-slip limit (`slip` below `tiny`).
    #[allow(clippy::too_many_arguments)]
    fn friction(
        &mut self,
        what: &str,
        i: usize,
        answer: Inverse<f64>,
        mu: f64,
        slip: f64,
        tiny: f64,
        bound: f64,
    ) {
        match answer {
            Inverse::AtLeast { value } => {
                assert!(slip < tiny && value <= mu, "{what} row {i}: {answer:?}");
                self.at_least += 1;
            }
            _ => self.exact(what, i, answer, mu, bound),
        }
    }

    /// An exact answer `got` for true value `want`: within the bound where S < 1e3.
    fn exact(&mut self, what: &str, i: usize, answer: Inverse<f64>, want: f64, bound: f64) {
        let Inverse::Exact { value, sensitivity } = answer else {
            panic!("{what} row {i}: expected exact {want}, got {answer:?}");
        };
        assert!(
            sensitivity >= 0.0,
            "{what} row {i}: sensitivity {sensitivity}"
        );
        if sensitivity >= SENSITIVITY_CAP {
            self.skipped_sensitive += 1;
            return;
        }
        let e = rel_err(value, want) / sensitivity.max(1.0);
        assert!(
            e <= bound,
            "{what} row {i}: {value} vs {want}, error {e:e} / max(1, S = {sensitivity})"
        );
        self.worst = self.worst.max(e);
        self.exact += 1;
    }
}

#[test]
fn elliptic_round_trips_over_the_reference_scenes() {
    let (mut mu_tally, mut phi_tally) = (Tally::default(), Tally::default());
    for (i, row) in read_rows("vectors_scene.csv").iter().enumerate() {
        let scene = scene(row);
        let (load, phi, mu) = (num(row, "P"), num(row, "phi"), num(row, "mu"));
        let e = reference::elliptic(&scene, load, phi).unwrap();
        let force = e.axial_force;
        let answer = inverse::friction_elliptic(&placeholder(&scene), load, phi, force).unwrap();
        mu_tally.friction("mu", i, answer, mu, e.slip_ratio, 1e-10, REFERENCE_BOUND);
        let answer = inverse::angle_elliptic(&scene, load, force).unwrap();
        if force.abs() == mu * load {
            // Saturated: F = mu P to the last bit says only |phi| >= phi0.
            let phi0 = e.critical_angle.unwrap();
            assert_eq!(
                answer,
                Inverse::AtLeast {
                    value: phi0.copysign(phi)
                },
                "row {i}"
            );
            phi_tally.at_least += 1;
        } else {
            phi_tally.exact("phi", i, answer, phi, REFERENCE_BOUND);
        }
    }
    println!("mu: {mu_tally:?}\nphi: {phi_tally:?}");
    assert!(mu_tally.exact > 1000 && phi_tally.exact > 500 && phi_tally.at_least > 500);
}

#[test]
fn line_round_trips_over_the_reference_scenes() {
    let (mut mu_tally, mut phi_tally) = (Tally::default(), Tally::default());
    for (i, row) in read_rows("vectors_line.csv").iter().enumerate() {
        let scene = scene(row);
        let (load, phi, mu) = (num(row, "P"), num(row, "phi"), num(row, "mu"));
        let l = reference::line(&scene, load, phi).unwrap();
        let force = l.axial_force;
        let answer = inverse::friction_line(&placeholder(&scene), load, phi, force).unwrap();
        mu_tally.friction("mu", i, answer, mu, l.slip_ratio, 1e-10, REFERENCE_BOUND);
        let answer = inverse::angle_line(&scene, load, force).unwrap();
        if force.abs() == mu * load {
            assert_eq!(
                answer,
                Inverse::AtLeast {
                    value: l.critical_angle.unwrap().copysign(phi)
                },
                "row {i}"
            );
            phi_tally.at_least += 1;
        } else {
            phi_tally.exact("phi", i, answer, phi, REFERENCE_BOUND);
        }
    }
    println!("mu: {mu_tally:?}\nphi: {phi_tally:?}");
    assert!(mu_tally.exact > 300 && phi_tally.exact > 100 && phi_tally.at_least > 100);
}

/// Section 9: the reference scenes with a roller length that makes the ellipse longer
/// than the rollers in part of them.
#[test]
fn model_choice_round_trips() {
    let (mut mu_tally, mut phi_tally) = (Tally::default(), Tally::default());
    let mut models = [0usize; 2];
    let mut ambiguous = 0;
    for (i, row) in read_rows("vectors_scene.csv").iter().enumerate() {
        let base = scene(row);
        let (load, phi, mu) = (num(row, "P"), num(row, "phi"), num(row, "mu"));
        let a = num(row, "a");
        // The ellipse's own length, longer or shorter by a factor 3.
        let length = if i % 2 == 0 { a / 1.5 } else { 6.0 * a };
        let scene = base.with_length(length).unwrap();
        let est = reference::estimate(&scene, load, phi).unwrap();
        models[(est.model() == ContactModel::Line) as usize] += 1;
        let force = est.axial_force(&scene);
        let answer = inverse::friction_estimate(&placeholder(&scene), load, phi, force).unwrap();
        mu_tally.friction(
            "mu",
            i,
            answer,
            mu,
            est.slip_ratio(),
            1e-10,
            REFERENCE_BOUND,
        );
        let answer = inverse::angle_estimate(&scene, load, force).unwrap();
        let saturated = est.slip_ratio() >= 1.0
            || match est {
                reference::Solution::Elliptic(_) => force.abs() == mu * load,
                reference::Solution::Line(_) => force.abs() == mu * (load / length) * length,
            };
        match answer {
            Inverse::AtLeast { value } => {
                // A lower bound: never above the true |phi| (saturated: at most phi0,
                // which may exceed |phi| by the rounding of F near d/b = 1).
                let limit = if saturated {
                    est.critical_angle().unwrap().max(phi.abs())
                } else {
                    phi.abs()
                };
                assert!(
                    value.abs() <= limit * (1.0 + 1e-12),
                    "row {i}: {answer:?} {phi}"
                );
                assert_eq!(value.signum(), phi.signum(), "row {i}");
                if saturated {
                    phi_tally.at_least += 1;
                } else {
                    ambiguous += 1;
                }
            }
            _ => {
                assert!(!saturated, "row {i}: saturated but {answer:?}");
                phi_tally.exact("phi", i, answer, phi, REFERENCE_BOUND);
            }
        }
    }
    println!("models {models:?} ambiguous {ambiguous}\nmu: {mu_tally:?}\nphi: {phi_tally:?}");
    assert!(models[0] > 500 && models[1] > 500);
    assert!(mu_tally.exact > 1000 && phi_tally.exact > 500 && phi_tally.at_least > 300);
}

/// Round-trip bound of the f32 core, relative, times max(1, sensitivity).
const FLOAT_BOUND: f64 = 2e-6;

/// An f32 answer as f64, to share the tallies.
fn wide(answer: Inverse<f32>) -> Inverse<f64> {
    answer.map(f64::from)
}

#[test]
fn float_round_trips_over_the_reference_scenes() {
    use misalign::float::inverse::ROUNDING_BELOW_SATURATION;
    use misalign::float::{EllipticScene, LineScene};
    let (mut mu_tally, mut phi_tally) = (Tally::default(), Tally::default());
    let mut refused = 0;
    let mut sensitivity_worst = 0.0f64;
    for (i, row) in read_rows("vectors_scene.csv").iter().enumerate() {
        let scene = scene(row);
        let (load, phi, mu) = (num(row, "P"), num(row, "phi"), num(row, "mu"));
        let (Ok(core), Ok(placeholder)) = (
            EllipticScene::new(&scene),
            EllipticScene::new(&placeholder(&scene)),
        ) else {
            refused += 1;
            continue;
        };
        let (load32, phi32) = (load as f32, phi as f32);
        let Ok(est) = core.estimate(load32, phi32) else {
            refused += 1;
            continue;
        };
        let force = est.axial_force;
        let answer = placeholder
            .friction_from_axial_force(load32, phi32, force)
            .unwrap();
        mu_tally.friction(
            "f32 mu",
            i,
            wide(answer),
            mu,
            est.slip_ratio as f64,
            1e-5,
            FLOAT_BOUND,
        );
        let answer = core.angle_from_axial_force(load32, force).unwrap();
        // The sensitivity agrees with the reference's to 1e-4 times max(1, S): it is
        // ~1/f'(s), and f' is steep in s near gross slip (plus the g table's difference).
        let want = inverse::angle_elliptic(&scene, load, force as f64).unwrap();
        if let (Some(a), Some(b)) = (answer.sensitivity(), want.sensitivity())
            && b < SENSITIVITY_CAP
        {
            sensitivity_worst = sensitivity_worst.max(rel_err(a as f64, b) / b.max(1.0));
        }
        // Within f32's rounding of mu P (F / (mu P) within the band): at_least phi0,
        // which the true phi may undercut by the sensitivity times the band, as an
        // exact answer's error is its sensitivity times F's rounding.
        let saturated = mu as f32 * load32;
        if force.abs() >= saturated * (1.0 - ROUNDING_BELOW_SATURATION) {
            let phi0 = est.critical_angle.unwrap();
            assert_eq!(
                answer,
                Inverse::AtLeast {
                    value: phi0.copysign(phi32)
                },
                "row {i}"
            );
            let s = want.sensitivity().unwrap_or(0.0);
            assert!(
                phi.abs() >= phi0 as f64 * (1.0 - FLOAT_BOUND * s.max(1.0)),
                "row {i}: phi {phi} below phi0 {phi0} (S {s})"
            );
            phi_tally.at_least += 1;
        } else {
            phi_tally.exact("f32 phi", i, wide(answer), phi, FLOAT_BOUND);
        }
    }
    println!("refused {refused}\nmu: {mu_tally:?}\nphi: {phi_tally:?}");
    println!("f32 phi sensitivity against the reference / max(1, S): {sensitivity_worst:.2e}");
    assert!(sensitivity_worst < 1e-4);
    assert!(mu_tally.exact > 1000 && phi_tally.exact > 500 && phi_tally.at_least > 500);

    let (mut mu_tally, mut phi_tally) = (Tally::default(), Tally::default());
    for (i, row) in read_rows("vectors_line.csv").iter().enumerate() {
        let scene = scene(row);
        let (load, phi, mu) = (num(row, "P") as f32, num(row, "phi") as f32, num(row, "mu"));
        let core = LineScene::new(&scene).unwrap();
        let est = core.estimate(load, phi).unwrap();
        let force = est.axial_force;
        let answer = LineScene::new(&placeholder(&scene))
            .unwrap()
            .friction_from_axial_force(load, phi, force)
            .unwrap();
        mu_tally.friction(
            "f32 line mu",
            i,
            wide(answer),
            mu,
            est.slip_ratio as f64,
            1e-5,
            FLOAT_BOUND,
        );
        let answer = core.angle_from_axial_force(load, force).unwrap();
        if force.abs() >= mu as f32 * load * (1.0 - ROUNDING_BELOW_SATURATION) {
            let phi0 = est.critical_angle.unwrap();
            assert_eq!(
                answer,
                Inverse::AtLeast {
                    value: phi0.copysign(phi)
                },
                "row {i}"
            );
            phi_tally.at_least += 1;
        } else {
            phi_tally.exact(
                "f32 line phi",
                i,
                wide(answer),
                num(row, "phi"),
                FLOAT_BOUND,
            );
        }
    }
    println!("line mu: {mu_tally:?}\nline phi: {phi_tally:?}");
    assert!(mu_tally.exact > 300 && phi_tally.exact > 100 && phi_tally.at_least > 100);
}

#[test]
fn forward_map_shape() {
    // F(mu) grows towards the no-slip limit pi^2 G a b |phi| / 4 (module docs).
    let s = Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3).unwrap();
    let (load, phi) = (1e3, 2e-4);
    let mut last = 0.0;
    for k in 0..40 {
        let mu = 1e-3 * 1.5f64.powi(k);
        let s = Scene::new(0.05, 0.05, 79.3e9, 0.3, mu).unwrap();
        let f = reference::elliptic(&s, load, phi).unwrap().axial_force;
        assert!(f > last, "F must grow with mu");
        last = f;
    }
    let e = reference::elliptic(&s, load, phi).unwrap();
    let limit = std::f64::consts::PI.powi(2) * 79.3e9 * e.a * e.b * phi / 4.0;
    assert!(
        last < limit && last > limit * (1.0 - 1e-3),
        "{last} {limit}"
    );
    // Just above the limit: inconsistent; at it: at_least.
    let above = inverse::friction_elliptic(&s, load, phi, limit * 1.000_001).unwrap();
    assert_eq!(above, Inverse::Inconsistent(Inconsistency::AboveModel));
    let at = inverse::friction_elliptic(&s, load, phi, limit).unwrap();
    assert!(
        matches!(at, Inverse::AtLeast { value } if value > 1e10),
        "{at:?}"
    );
    // Line contact: limit 2 K P = |phi| sqrt(pi (1 - nu) G R P).
    let r = s.effective_radius();
    let limit = phi * (std::f64::consts::PI * 0.7 * 79.3e9 * r * load).sqrt();
    let near = inverse::friction_line(&s, load, phi, limit * (1.0 - 1e-9)).unwrap();
    assert!(matches!(near, Inverse::Exact { sensitivity, .. } if sensitivity > 1e8));
    let above = inverse::friction_line(&s, load, phi, limit * 1.000_001).unwrap();
    assert_eq!(above, Inverse::Inconsistent(Inconsistency::AboveModel));
    // Gross slip: mu = F / P exactly, sensitivity 1.
    let gross = inverse::friction_elliptic(&s, load, phi, 0.01 * load).unwrap();
    assert_eq!(
        gross,
        Inverse::Exact {
            value: 0.01,
            sensitivity: 1.0
        }
    );
}

/// The f32 core through [`misalign::float::Auto`] (section 9 per sample), with a
/// roller length that makes it pick line contact (total load and force) for about half
/// of the reference scenes.
#[test]
fn auto_round_trips() {
    use misalign::float::Auto;
    use misalign::float::inverse::ROUNDING_BELOW_SATURATION;
    let mut tally = [Tally::default(), Tally::default()];
    let mut models = [0usize; 2];
    let mut ambiguous = 0;
    for (i, row) in read_rows("vectors_scene.csv").iter().enumerate() {
        let (load, phi, mu) = (num(row, "P"), num(row, "phi"), num(row, "mu"));
        let length = num(row, "a") * if i % 2 == 0 { 0.5 } else { 4.0 };
        let scene = scene(row).with_length(length).unwrap();
        let (Ok(core), Ok(unread)) = (Auto::new(&scene), Auto::new(&placeholder(&scene))) else {
            continue;
        };
        let (p, a) = (load as f32, phi as f32);
        let Ok(est) = core.estimate(p, a) else {
            continue;
        };
        models[(est.model == ContactModel::Line) as usize] += 1;
        let (est, force) = (est.estimate, est.estimate.axial_force);
        let answer = unread.friction_from_axial_force(p, a, force).unwrap();
        tally[0].friction(
            "auto mu",
            i,
            wide(answer),
            mu,
            est.slip_ratio as f64,
            1e-5,
            FLOAT_BOUND,
        );
        let answer = core.angle_from_axial_force(p, force).unwrap();
        let within_rounding = force.abs() >= mu as f32 * p * (1.0 - ROUNDING_BELOW_SATURATION);
        if est.slip_ratio >= 1.0 || within_rounding {
            // A lower bound: never above the true |phi| (saturated: at most phi0 of the
            // model taken, which may exceed |phi| by the rounding of F near d/b = 1).
            let Inverse::AtLeast { value } = answer else {
                panic!("row {i}: saturated but {answer:?}");
            };
            let limit = est.critical_angle.unwrap_or(a.abs()).max(a.abs());
            assert!(
                value.abs() <= limit * (1.0 + FLOAT_BOUND as f32),
                "row {i}: {answer:?} {phi}"
            );
            assert_eq!(value.signum(), a.signum(), "row {i}");
            tally[1].at_least += 1;
        } else if let Inverse::AtLeast { value } = answer {
            // Both models give this F at some phi: the smaller bounds the true one.
            assert!(value.abs() <= a.abs() * (1.0 + 2e-6), "row {i}: {answer:?}");
            ambiguous += 1;
        } else {
            tally[1].exact("auto phi", i, wide(answer), phi, FLOAT_BOUND);
        }
    }
    println!(
        "models {models:?}, ambiguous {ambiguous}\nmu: {:?}\nphi: {:?}",
        tally[0], tally[1]
    );
    assert!(models[0] > 500 && models[1] > 500);
    assert!(tally[0].exact > 1000 && tally[1].exact > 500 && tally[1].at_least > 300);
}

/// Section 9, f32: where the forward answer is a saturated ellipse, phi's inverse
/// counts the elliptic answer (at least the ellipse's phi0) even where phi0 itself lies
/// in the line region (the ellipse longer than the rollers at phi0): the choice takes
/// the ellipse at larger phi, as `reference::inverse::angle_estimate` finds.
#[test]
fn auto_counts_a_saturated_ellipse_above_the_switch() {
    use misalign::float::Auto;
    let mut phi0_in_line_region = 0;
    for (i, row) in read_rows("vectors_scene.csv").iter().enumerate() {
        let scene = scene(row).with_length(6.0 * num(row, "a")).unwrap();
        let Ok(core) = Auto::new(&scene) else {
            continue;
        };
        let (p, a) = (num(row, "P") as f32, num(row, "phi") as f32);
        let Ok(est) = core.estimate(p, a) else {
            continue;
        };
        let (Some(phi0), true) = (
            est.estimate.critical_angle,
            est.model == ContactModel::Elliptic && est.estimate.slip_ratio >= 1.0,
        ) else {
            continue;
        };
        if core.estimate(p, phi0).unwrap().model == ContactModel::Line {
            phi0_in_line_region += 1;
        }
        let answer = core.angle_from_axial_force(p, est.estimate.axial_force);
        assert!(
            matches!(answer, Ok(Inverse::AtLeast { value })
                if value.abs() <= phi0 * (1.0 + FLOAT_BOUND as f32)
                    && value.signum() == a.signum()),
            "row {i}: {answer:?}, phi0 {phi0}"
        );
    }
    assert!(phi0_in_line_region > 10, "{phi0_in_line_region}");
}

#[test]
fn float_bad_input() {
    use misalign::float::{Auto, EllipticScene, LineScene};
    let s = Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3).unwrap();
    let e = EllipticScene::new(&s).unwrap();
    let l = LineScene::new(&s).unwrap();
    let p = Auto::new(&s.with_length(0.01).unwrap()).unwrap();
    for f in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        assert_eq!(e.friction_from_axial_force(1e3, 1e-4, f), Err(Error::Force));
        assert_eq!(l.friction_from_axial_force(1e3, 1e-4, f), Err(Error::Force));
        assert_eq!(p.angle_from_axial_force(1e3, f), Err(Error::Force));
        assert_eq!(l.angle_from_axial_force(1e3, f), Err(Error::Force));
    }
    assert_eq!(e.angle_from_axial_force(f32::NAN, 1.0), Err(Error::Load));
    assert_eq!(
        e.friction_from_axial_force(1e3, f32::NAN, 1.0),
        Err(Error::Angle)
    );
    assert_eq!(
        e.friction_from_axial_force(1e3, 2.0, 1.0),
        Err(Error::Angle)
    );
    let zero_load = Inverse::Inconsistent(Inconsistency::ZeroLoad);
    assert_eq!(e.friction_from_axial_force(0.0, 1e-4, 1.0), Ok(zero_load));
    assert_eq!(l.angle_from_axial_force(0.0, 1.0), Ok(zero_load));
    let aligned = Inverse::Inconsistent(Inconsistency::NoMisalignment);
    assert_eq!(e.friction_from_axial_force(1e3, 0.0, 1.0), Ok(aligned));
    let opposite = Inverse::Inconsistent(Inconsistency::OppositeSign);
    assert_eq!(l.friction_from_axial_force(1e3, -1e-4, 1.0), Ok(opposite));
    let above = Inverse::Inconsistent(Inconsistency::AboveModel);
    assert_eq!(e.angle_from_axial_force(1e3, -301.0), Ok(above));
    assert_eq!(e.friction_from_axial_force(1e3, 1e-4, 1e9), Ok(above));
    // Gross slip: mu = F / P, exactly.
    let gross = e.friction_from_axial_force(1e3, 1e-2, 20.0).unwrap();
    assert_eq!(
        gross,
        Inverse::Exact {
            value: 0.02,
            sensitivity: 1.0
        }
    );
}

/// Section 9 on a plane (section 9's rule): line contact at every phi, P and F per unit
/// length without a length, totals with one; both inverses through the model choice
/// are the line inverses at the per-length values, and round-trip the forward answer.
#[test]
fn plane_estimates_are_line_contact() {
    let plane = Scene::new(0.05, f64::INFINITY, 79.3e9, 0.3, 0.3).unwrap();
    let placeholder_plane = placeholder(&plane);
    for length in [None, Some(0.02)] {
        let s = length.map_or(plane, |l| plane.with_length(l).unwrap());
        let p = length.map_or(placeholder_plane, |l| {
            placeholder_plane.with_length(l).unwrap()
        });
        let per = length.unwrap_or(1.0);
        for (load, phi) in [(1e3, 1e-5), (1e3, 1e-4), (1e3, 1e-2), (1e5, 3e-4)] {
            let est = reference::estimate(&s, load, phi).unwrap();
            assert_eq!(est.model(), ContactModel::Line, "{length:?} {load} {phi}");
            let force = est.axial_force(&s);
            let mu = inverse::friction_estimate(&p, load, phi, force).unwrap();
            assert_eq!(
                mu,
                inverse::friction_line(&p, load / per, phi, force / per).unwrap()
            );
            let Inverse::Exact { value, sensitivity } = mu else {
                panic!("{length:?} {load} {phi}: {mu:?}");
            };
            assert!(rel_err(value, 0.3) <= REFERENCE_BOUND * sensitivity.max(1.0));
            let angle = inverse::angle_estimate(&s, load, force).unwrap();
            assert_eq!(
                angle,
                inverse::angle_line(&s, load / per, force / per).unwrap()
            );
            if est.slip_ratio() >= 1.0 {
                let phi0 = est.critical_angle().unwrap();
                assert_eq!(angle, Inverse::AtLeast { value: phi0 });
                assert!(phi0 <= phi, "{angle:?}");
            } else {
                let Inverse::Exact { value, sensitivity } = angle else {
                    panic!("{length:?} {load} {phi}: {angle:?}");
                };
                assert!(rel_err(value, phi) <= REFERENCE_BOUND * sensitivity.max(1.0));
            }
        }
    }
}

#[test]
fn bad_input() {
    let s = Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3).unwrap();
    let plane = Scene::new(0.05, f64::INFINITY, 79.3e9, 0.3, 0.3).unwrap();
    for f in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert_eq!(
            inverse::friction_elliptic(&s, 1e3, 1e-4, f),
            Err(Error::Force)
        );
        assert_eq!(inverse::friction_line(&s, 1e3, 1e-4, f), Err(Error::Force));
        assert_eq!(inverse::angle_elliptic(&s, 1e3, f), Err(Error::Force));
        assert_eq!(inverse::angle_line(&s, 1e3, f), Err(Error::Force));
        assert_eq!(inverse::angle_estimate(&s, 1e3, f), Err(Error::Force));
        assert_eq!(
            inverse::friction_estimate(&s, 1e3, 1e-4, f),
            Err(Error::Force)
        );
    }
    assert_eq!(inverse::angle_elliptic(&s, f64::NAN, 1.0), Err(Error::Load));
    assert_eq!(
        inverse::friction_elliptic(&s, -1.0, 1e-4, 1.0),
        Err(Error::Load)
    );
    assert_eq!(
        inverse::friction_elliptic(&s, 1.0, f64::NAN, 1.0),
        Err(Error::Angle)
    );
    assert_eq!(inverse::friction_line(&s, 1.0, 2.0, 1.0), Err(Error::Angle));
    assert_eq!(
        inverse::angle_elliptic(&plane, 1e3, 1.0),
        Err(Error::PlaneHasNoEllipse)
    );
    let zero_load = Inverse::Inconsistent(Inconsistency::ZeroLoad);
    assert_eq!(
        inverse::friction_elliptic(&s, 0.0, 1e-4, 1.0),
        Ok(zero_load)
    );
    assert_eq!(inverse::angle_elliptic(&s, 0.0, 1.0), Ok(zero_load));
    assert_eq!(inverse::angle_line(&s, 0.0, -1.0), Ok(zero_load));
    let aligned = Inverse::Inconsistent(Inconsistency::NoMisalignment);
    assert_eq!(inverse::friction_elliptic(&s, 1e3, 0.0, 1.0), Ok(aligned));
    assert_eq!(inverse::friction_line(&s, 1e3, -0.0, 1.0), Ok(aligned));
    let opposite = Inverse::Inconsistent(Inconsistency::OppositeSign);
    assert_eq!(
        inverse::friction_elliptic(&s, 1e3, -1e-4, 1.0),
        Ok(opposite)
    );
    assert_eq!(inverse::friction_line(&s, 1e3, 1e-4, -1.0), Ok(opposite));
    // Above mu P: inconsistent; zero F and zero load: any phi, any mu.
    let above = Inverse::Inconsistent(Inconsistency::AboveModel);
    assert_eq!(inverse::angle_elliptic(&s, 1e3, 301.0), Ok(above));
    assert_eq!(inverse::angle_line(&s, 1e3, -301.0), Ok(above));
    // F within the rounding of mu P above it: saturated; further above: inconsistent.
    let phi0 = reference::critical_angle(&s, 1e3).unwrap().0;
    let near = inverse::angle_elliptic(&s, 1e3, 300.0 * (1.0 + 2.0 * f64::EPSILON));
    assert_eq!(near, Ok(Inverse::AtLeast { value: phi0 }));
    let beyond = inverse::angle_elliptic(&s, 1e3, 300.0 * (1.0 + 1e-12));
    assert_eq!(beyond, Ok(above));
    let anything = Inverse::AtLeast { value: 0.0 };
    assert_eq!(inverse::angle_elliptic(&s, 0.0, 0.0), Ok(anything));
    assert_eq!(inverse::friction_elliptic(&s, 1e3, 0.0, 0.0), Ok(anything));
    // F = 0 with load: phi = 0 exactly.
    let zero = inverse::angle_elliptic(&s, 1e3, 0.0).unwrap();
    assert_eq!(zero.value(), Some(0.0));
}

mod properties {
    use super::*;
    use proptest::prelude::*;

    fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
        (lo.ln()..hi.ln()).prop_map(f64::exp)
    }

    /// Any f64 at all, with the awkward ones often.
    fn any_force() -> impl Strategy<Value = f64> {
        prop_oneof![
            Just(0.0),
            Just(-0.0),
            Just(f64::MIN_POSITIVE),
            Just(f64::MAX),
            log_uniform(1e-300, 1e300),
            log_uniform(1e-300, 1e300).prop_map(|x| -x),
            any::<f64>(),
        ]
    }

    prop_compose! {
        fn scenes()(r1 in log_uniform(1e-4, 10.0), r2 in log_uniform(1e-4, 10.0),
                    plane in 0..8u8, g in log_uniform(1e6, 1e12), nu in 0.0..0.4999f64,
                    mu in log_uniform(1e-4, 10.0), length in log_uniform(1e-4, 10.0),
                    with_length in any::<bool>(), exact in any::<bool>()) -> Scene {
            let r2 = if plane == 0 { f64::INFINITY } else { r2 };
            let s = Scene::new(r1, r2, g, nu, mu).unwrap();
            let s = if exact { s.with_theta_relation(misalign::ThetaRelation::Exact) } else { s };
            // A length below the scene's shortest is refused (tests/model_choice.rs): such
            // a draw takes the shortest, the boundary itself.
            if with_length { s.with_length(length.max(s.shortest_length())).unwrap() } else { s }
        }
    }

    /// Any positive f64 of the scene's constants, the extremes often.
    fn any_magnitude() -> impl Strategy<Value = f64> {
        prop_oneof![
            Just(f64::MAX),
            Just(1.7e308),
            Just(f64::MIN_POSITIVE),
            Just(5e-324),
            log_uniform(1e-300, 1e300),
            log_uniform(1e-4, 10.0),
        ]
    }

    prop_compose! {
        /// Scenes with every constant anywhere in f64 (that `Scene::new` accepts): the
        /// products of eqs (23), (28) overflow or underflow on their way.
        fn extreme_scenes()(r1 in any_magnitude(), r2 in any_magnitude(), plane in 0..8u8,
                            g in any_magnitude(), nu in 0.0..0.5f64, mu in any_magnitude(),
                            length in any_magnitude(), with_length in any::<bool>())
                            -> Option<Scene> {
            let r2 = if plane == 0 { f64::INFINITY } else { r2 };
            let s = Scene::new(r1, r2, g, nu, mu).ok()?;
            if with_length { s.with_length(length).ok() } else { Some(s) }
        }
    }

    /// An answer inside the physical range: finite value and sensitivity, mu >= 0,
    /// |phi| <= pi/2 (theta <= pi/2 for eq 4) signed like F.
    fn physical(answer: &Inverse<f64>, max: f64, force: f64) -> Result<(), TestCaseError> {
        if let Some(v) = answer.value() {
            prop_assert!(v.is_finite() && v.abs() <= max, "{answer:?}");
            prop_assert!(v == 0.0 || v.is_sign_negative() == force.is_sign_negative());
        }
        if let Some(s) = answer.sensitivity() {
            prop_assert!(s >= 0.0, "{answer:?}"); // +inf allowed where F is flat
        }
        Ok(())
    }

    /// Every reference inverse at (P, phi, F) answers inside the physical range or
    /// refuses the input.
    fn reference_answers_are_physical(
        s: &Scene,
        load: f64,
        phi: f64,
        force: f64,
    ) -> Result<(), TestCaseError> {
        let phi_max = std::f64::consts::FRAC_PI_2 / s.radius_factor().min(1.0);
        for answer in [
            inverse::friction_elliptic(s, load, phi, force),
            inverse::friction_line(s, load, phi, force),
            inverse::friction_estimate(s, load, phi, force),
        ]
        .into_iter()
        .flatten()
        {
            if let Some(v) = answer.value() {
                prop_assert!(v.is_finite() && v >= 0.0, "{answer:?}");
            }
            physical(&answer, f64::MAX, 1.0)?;
        }
        for answer in [
            inverse::angle_elliptic(s, load, force),
            inverse::angle_line(s, load, force),
            inverse::angle_estimate(s, load, force),
        ]
        .into_iter()
        .flatten()
        {
            physical(&answer, phi_max, force)?;
        }
        Ok(())
    }

    /// The same for the f32 core through [`misalign::float::Auto`] (where it prepares).
    fn float_answers_are_physical(
        s: &Scene,
        load: f32,
        phi: f32,
        force: f32,
    ) -> Result<(), TestCaseError> {
        let Ok(p) = misalign::float::Auto::new(s) else {
            return Ok(());
        };
        if let Ok(answer) = p.friction_from_axial_force(load, phi, force) {
            let answer = answer.map(f64::from);
            physical(&answer, f64::MAX, 1.0)?;
            prop_assert!(answer.value().is_none_or(|v| v >= 0.0));
        }
        if let Ok(answer) = p.angle_from_axial_force(load, force) {
            let phi_max = std::f64::consts::FRAC_PI_2 / s.radius_factor().min(1.0);
            physical(
                &answer.map(f64::from),
                phi_max * (1.0 + 1e-6),
                f64::from(force),
            )?;
        }
        Ok(())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(400))]

        #[test]
        fn never_panics_never_leaves_the_physical_range(
            s in scenes(), load in prop_oneof![Just(0.0), log_uniform(1e-6, 1e9), any::<f64>()],
            phi in prop_oneof![Just(0.0), log_uniform(1e-12, 1.5), any::<f64>()],
            sign in any::<bool>(), force in any_force(),
        ) {
            let phi = if sign { -phi } else { phi };
            reference_answers_are_physical(&s, load, phi, force)?;
        }

        #[test]
        fn float_never_panics_never_leaves_the_physical_range(
            s in scenes(), load in prop_oneof![Just(0.0f32), any::<f32>(), (1e-6f32..1e9)],
            phi in prop_oneof![Just(0.0f32), any::<f32>(), (-1.5f32..1.5)],
            force in prop_oneof![Just(0.0f32), any::<f32>(), (-1e6f32..1e6)],
        ) {
            float_answers_are_physical(&s, load, phi, force)?;
        }

        /// The same over scenes with extreme constants, where mu P, phi0 and the
        /// Hertz products leave f64 (the phi-inverse once answered `Exact` with a NaN
        /// there, from 0 x inf in eq 28's `s phi0`).
        #[test]
        fn extreme_scenes_never_leave_the_physical_range(
            s in extreme_scenes(), load in prop_oneof![any_magnitude(), any::<f64>()],
            phi in prop_oneof![log_uniform(1e-12, 1.5), any::<f64>()],
            force in any_force(),
        ) {
            let Some(s) = s else { return Ok(()) };
            reference_answers_are_physical(&s, load, phi, force)?;
            float_answers_are_physical(&s, load as f32, phi as f32, force as f32)?;
        }

        #[test]
        fn round_trip_on_random_scenes(
            s in scenes(), load in log_uniform(1e-3, 1e7), phi in log_uniform(1e-9, 0.1),
        ) {
            let Ok(est) = reference::estimate(&s, load, phi) else { return Ok(()) };
            let force = est.axial_force(&s);
            let mu = s.friction();
            let answer = inverse::friction_estimate(&placeholder(&s), load, phi, force).unwrap();
            if let Inverse::Exact { value, sensitivity } = answer && sensitivity < SENSITIVITY_CAP {
                prop_assert!(rel_err(value, mu) <= REFERENCE_BOUND * sensitivity.max(1.0),
                    "{answer:?} vs {mu}");
            } else {
                prop_assert!(matches!(answer, Inverse::AtLeast { value } if value <= mu)
                    || answer.sensitivity().is_some_and(|s| s >= SENSITIVITY_CAP), "{answer:?}");
            }
            let answer = inverse::angle_estimate(&s, load, force).unwrap();
            match answer {
                Inverse::Exact { value, sensitivity } if sensitivity < SENSITIVITY_CAP => {
                    prop_assert!(rel_err(value, phi) <= REFERENCE_BOUND * sensitivity.max(1.0),
                        "{answer:?} vs {phi}");
                }
                Inverse::Exact { .. } => {}
                Inverse::AtLeast { value } => {
                    let phi0 = est.critical_angle().unwrap_or(phi).max(phi);
                    prop_assert!(value <= phi0 * (1.0 + 1e-12), "{answer:?} vs {phi}");
                }
                Inverse::Inconsistent(_) => prop_assert!(false, "{answer:?}"),
            }
        }
    }
}

/// A load per length that overflows f64 (P / length) is refused as the forward model
/// refuses it, never answered with a NaN (found by the property test above at 200 000
/// cases: a plane 0.1 mm long at 1.7e306 N, F the smallest normal f64).
#[test]
fn overflowing_load_per_length_is_refused() {
    let s = Scene::new(1.0, f64::INFINITY, 1e6, 0.0, 1.0)
        .unwrap()
        .with_length(1.04e-4)
        .unwrap();
    let (load, force) = (1.68e306, f64::MIN_POSITIVE);
    assert_eq!(inverse::angle_estimate(&s, load, force), Err(Error::Load));
    assert_eq!(
        inverse::friction_estimate(&s, load, 0.0, force),
        Err(Error::Load)
    );
    let ellipse = Scene::new(1.0, 2.0, 1e6, 0.0, 1.0)
        .unwrap()
        .with_length(1.04e-4)
        .unwrap();
    assert_eq!(
        inverse::angle_estimate(&ellipse, load, force),
        Err(Error::Load)
    );
}

/// Line contact's phi-inverse where mu P and phi0 (eq 28) overflow f64: the answer is
/// formed without mu (`s phi0 = 2 F / (sqrt(pi (1 - nu) G R P) (1 + sqrt(1 - r)))`),
/// never `Exact` with the NaN of 0 x inf that it once gave (found by the Python
/// package's sweep of extreme values: R1 = 1e300, R2 = 1e-300, mu = 1.7e308).
#[test]
fn overflowing_critical_angle_gives_an_answer_not_a_nan() {
    // c underflows to 0: a strip at every phi, R = 1e-300 m. F = 1 N needs
    // phi = F / sqrt(pi (1 - nu) G R P) ~ 7.6e142 rad: no phi below pi/2 gives it.
    let s = Scene::new(1e300, 1e-300, 79.3e9, 0.3, 1.7e308).unwrap();
    let above = Ok(Inverse::Inconsistent(Inconsistency::AboveModel));
    assert_eq!(s.radius_factor(), 0.0);
    assert_eq!(inverse::angle_estimate(&s, 1e3, 1.0), above);
    assert_eq!(inverse::angle_line(&s, 1e3, -1.0), above);
    // A plane of the paper's steel: mu P = inf and phi0 = inf, F / (mu P) = 0 in f64;
    // the answer is the no-slip limit F = |phi| sqrt(pi (1 - nu) G R P) solved for phi.
    let plane = Scene::new(0.05, f64::INFINITY, 79.3e9, 0.3, 1.7e308).unwrap();
    let (load, force) = (1e3, 1.0);
    let want = force / (std::f64::consts::PI * 0.7 * 79.3e9 * 0.05 * load).sqrt();
    for answer in [
        inverse::angle_line(&plane, load, force),
        inverse::angle_estimate(&plane, load, force),
    ] {
        let Ok(Inverse::Exact { value, sensitivity }) = answer else {
            panic!("{answer:?}");
        };
        assert!(rel_err(value, want) < 1e-15, "{value} vs {want}");
        assert_eq!(sensitivity, 1.0);
    }
    // The same through a length, where only mu P / length overflows (F / (mu P) > 1:
    // above the model, not a NaN from sqrt(1 - r)).
    let short = Scene::new(0.3, f64::INFINITY, 5e-2, 0.3, 1e308)
        .unwrap()
        .with_length(1e-3)
        .unwrap();
    assert!((1e308f64 * 1.0 / 1e-3).is_infinite());
    assert_eq!(inverse::angle_estimate(&short, 1.0, 1.7e308), above);
}

/// The f32 line inverse refuses a load outside the scene's load range (where phi0 or
/// mu P leaves f32) with the forward estimate's error, instead of `s phi0 = 0 x inf`.
#[test]
fn float_line_inverse_refuses_loads_the_estimate_refuses() {
    use misalign::float::LineScene;
    let s = Scene::new(0.05, 1e-45, 1e3, 0.0, 7.93e10).unwrap();
    // (mu = 8e10 on R = 1e-45 m puts phi0 beyond pi/2 at every load: the f32 scene is
    // refused when prepared, as no load has all its results in range.)
    assert_eq!(LineScene::new(&s).err(), Some(Error::OutOfRange));
    let s = Scene::new(0.05, 1e-45, 1e3, 0.0, 2.0).unwrap();
    let core = LineScene::new(&s).unwrap();
    let (load, force) = (3.4e38f32, 1.57f32);
    assert!(load > core.load_range().1, "{:?}", core.load_range());
    assert_eq!(core.estimate(load, 1e-3), Err(Error::OutOfRange));
    assert_eq!(
        core.angle_from_axial_force(load, force),
        Err(Error::OutOfRange)
    );
}

/// The f32 phi-inverses at F = mu P: where the inputs read as f32 put F / (mu P) within
/// the core's rounding of 1 (`ROUNDING_BELOW_SATURATION`), the answer is `at_least`
/// phi0, as the reference answers at F = mu P (it had been `exact`, phi 0.25 % below
/// phi0 with a sensitivity of 8e3, for mu 0.1, P 777 N, F 77.7 N); outside the band,
/// `exact` with its sensitivity, as the reference on the same f32 inputs.
#[test]
fn float_angle_inverse_within_rounding_of_saturation_is_at_least() {
    use misalign::float::inverse::ROUNDING_BELOW_SATURATION;
    use misalign::float::{EllipticScene, LineScene};
    for (mu, load) in [(0.1, 777.0), (0.3, 1234.5), (0.3, 2000.0), (0.6, 3.3)] {
        let scene = Scene::new(0.05, 0.05, 79.3e9, 0.3, mu).unwrap();
        let force = mu * load;
        assert!(matches!(
            inverse::angle_elliptic(&scene, load, force).unwrap(),
            Inverse::AtLeast { .. }
        ));
        let core = EllipticScene::new(&scene).unwrap();
        let line = LineScene::new(&scene).unwrap();
        let (p, f) = (load as f32, force as f32);
        let phi0 = core.estimate(p, 1e-9).unwrap().critical_angle.unwrap();
        let line_phi0 = line.estimate(p, 1e-9).unwrap().critical_angle.unwrap();
        let what = format!("mu {mu}, P {load}");
        assert_eq!(
            core.angle_from_axial_force(p, f),
            Ok(Inverse::AtLeast { value: phi0 }),
            "{what}"
        );
        assert_eq!(
            line.angle_from_axial_force(p, f),
            Ok(Inverse::AtLeast { value: line_phi0 }),
            "{what}"
        );
        // F stepped down from mu P in f32 ulps, across the band: the reference reads
        // the same f32 inputs.
        let same = Scene::new(0.05, 0.05, 79.3e9, 0.3, mu as f32 as f64).unwrap();
        let saturated = mu as f32 * p;
        let (mut inside, mut outside) = (0, 0);
        for k in 0..64u32 {
            let f = f32::from_bits(saturated.to_bits() - k);
            let within = f >= saturated * (1.0 - ROUNDING_BELOW_SATURATION);
            let pairs = [
                (
                    core.angle_from_axial_force(p, f).unwrap(),
                    inverse::angle_elliptic(&same, p as f64, f as f64).unwrap(),
                    phi0,
                ),
                (
                    line.angle_from_axial_force(p, f).unwrap(),
                    inverse::angle_line(&same, p as f64, f as f64).unwrap(),
                    line_phi0,
                ),
            ];
            for (got, want, phi0) in pairs {
                if within {
                    assert_eq!(got, Inverse::AtLeast { value: phi0 }, "{what}, {k} ulps");
                    inside += 1;
                    continue;
                }
                outside += 1;
                let (Inverse::Exact { value, sensitivity }, Inverse::Exact { value: w, .. }) =
                    (got, want)
                else {
                    panic!("{what}, {k} ulps: {got:?} vs {want:?}");
                };
                assert!(value < phi0 && sensitivity > 1.0, "{what}, {k} ulps");
                // The module's bound: 2e-6 times the sensitivity.
                let bound = 2e-6 * f64::from(sensitivity);
                assert!(
                    rel_err(f64::from(value), w) <= bound,
                    "{what}, {k} ulps: {value} vs {w} (S {sensitivity})"
                );
            }
        }
        assert!(inside >= 4 && outside >= 4, "{what}: {inside} {outside}");
    }
}

/// The f32 mu-inverses at the no-slip limit F = K P f'(0) (mu -> inf, K = mu d/b):
/// within `SATURATION_ULPS` of it the inputs do not tell F from the limit and the
/// answer is `at_least`; further below, `exact`, mu growing with F and below that bound.
#[test]
fn float_friction_inverse_at_the_no_slip_limit() {
    use misalign::float::inverse::SATURATION_ULPS;
    use misalign::float::{EllipticScene, LineScene};
    let scene = Scene::DEMO;
    let (p, phi) = (1e3f32, 2e-4f32);
    let mu = scene.friction() as f32;
    let core = EllipticScene::new(&scene).unwrap();
    let line = LineScene::new(&scene).unwrap();
    type Case<'a> = (&'a dyn Fn(f32) -> Inverse<f32>, f64, f32);
    let cases: [Case<'_>; 2] = [
        (
            &|f| core.friction_from_axial_force(p, phi, f).unwrap(),
            3.0 * core::f64::consts::PI / 4.0,
            core.estimate(p, phi).unwrap().slip_ratio,
        ),
        (
            &|f| line.friction_from_axial_force(p, phi, f).unwrap(),
            2.0,
            line.estimate(p, phi).unwrap().slip_ratio,
        ),
    ];
    let eps = f64::from(f32::EPSILON);
    let band = f64::from(SATURATION_ULPS) / eps;
    for (inverse, limit, s) in cases {
        // K P f'(0), from the forward estimate's d/b.
        let f_limit = f64::from(mu) * f64::from(s) * f64::from(p) * limit;
        let mut bound = f32::NAN;
        for j in [0.0, 1.0, 2.0] {
            let answer = inverse((f_limit * (1.0 - j * eps)) as f32);
            let Inverse::AtLeast { value } = answer else {
                panic!("{j} eps below the limit: {answer:?}");
            };
            assert!(value > 1e3 * mu, "{value}");
            bound = value;
        }
        let mut last = 0.0f32;
        for j in [4.0 * band, 3.0 * band, 2.0 * band] {
            let answer = inverse((f_limit * (1.0 - j * eps)) as f32);
            let Inverse::Exact { value, sensitivity } = answer else {
                panic!("{j} eps below the limit: {answer:?}");
            };
            assert!(
                value > last && value < bound && sensitivity > 1.0,
                "{answer:?}"
            );
            last = value;
        }
    }
}
