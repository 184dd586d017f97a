//! The reference's fast path (`reference::fast`, the batch's) against the 50-digit
//! values of tests/data and against the reference itself over many random rows: where
//! it answers, every number within a few ulps of the reference's and every decision
//! (regime, model, flags) the reference's; and it answers on the practical domain.

mod common;
use common::{num, read_rows, rel_err};
use misalign::reference::fast::{Answer, Prepared, shape, theta_of_g_cubed};
use misalign::reference::{self, ModelChoice, Solution};
use misalign::{Scene, ThetaRelation};

/// d/b, F, phi0 of the fast path against the 50-digit data (the reference's bound).
const DATA_BOUND: f64 = 4e-15;
/// k', m n, theta0 of the kernels against the 50-digit data.
const KERNEL_BOUND: f64 = 1.5e-15;
/// d/b, F, phi0 against the reference row by row (both are within a few ulps).
const ROW_BOUND: f64 = 3e-15;

#[test]
fn kernels_meet_the_50_digit_shapes() {
    let (mut worst, mut answered) = ([0.0f64; 3], 0);
    for row in read_rows("vectors_mn.csv") {
        let theta = num(&row, "theta");
        let Some(s) = shape(theta) else { continue };
        answered += 1;
        let mn = num(&row, "m") * num(&row, "n");
        worst[0] = worst[0].max(rel_err(s.kprime, num(&row, "kprime")));
        worst[1] = worst[1].max(rel_err(libm::cbrt(s.mn_cubed), mn));
        let g = num(&row, "g");
        let theta0 = theta_of_g_cubed(g * g * g);
        if let Some(t) = theta0 {
            worst[2] = worst[2].max(rel_err(t, theta));
        }
    }
    assert!(answered > 100, "{answered} rows in the domain");
    assert!(worst.iter().all(|&w| w < KERNEL_BOUND), "{worst:?}");
}

fn fast_answer(scene: &Scene, choice: ModelChoice, load: f64, phi: f64) -> Option<Answer> {
    Prepared::new(scene, choice)?.estimate(load, phi)
}

#[test]
fn fast_path_meets_the_50_digit_scenes() {
    let (mut worst, mut answered) = ([0.0f64; 3], 0);
    for row in read_rows("vectors_scene.csv") {
        let n = |k| num(&row, k);
        let scene = Scene::new(n("R1"), n("R2"), n("G"), n("nu"), n("mu")).unwrap();
        let Some(Answer::Elliptic(e)) =
            fast_answer(&scene, ModelChoice::Section9, n("P"), n("phi"))
        else {
            continue;
        };
        answered += 1;
        worst[0] = worst[0].max(rel_err(e.slip_ratio, n("s")));
        worst[1] = worst[1].max(rel_err(e.axial_force, n("F")));
        worst[2] = worst[2].max(rel_err(e.critical_angle, common::phi0(&row)));
        assert_eq!(e.regime.as_str(), row["regime"]);
    }
    assert!(answered > 1000, "{answered} rows in the domain");
    assert!(worst.iter().all(|&w| w < DATA_BOUND), "{worst:?}");
}

/// A small deterministic generator (xorshift64*), uniform in [0, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo * (hi / lo).powf(self.next())
    }
}

/// The fast answer against the reference's on one row; whether the fast path answered.
fn check_row(
    scene: &Scene,
    choice: ModelChoice,
    load: f64,
    phi: f64,
    worst: &mut [f64; 3],
) -> bool {
    let Some(fast) = fast_answer(scene, choice, load, phi) else {
        return false;
    };
    let slow = reference::estimate_with(scene, load, phi, choice).unwrap();
    let ctx = format!("{scene:?} {choice:?} P={load:e} phi={phi:e}");
    match (fast, slow) {
        (Answer::Elliptic(f), Solution::Elliptic(s)) => {
            worst[0] = worst[0].max(rel_err(f.slip_ratio, s.slip_ratio));
            worst[1] = worst[1].max(rel_err(f.axial_force, s.axial_force));
            worst[2] = worst[2].max(rel_err(f.critical_angle, s.critical_angle.unwrap()));
            assert!(
                rel_err(f.critical_theta, s.critical_theta.unwrap()) < ROW_BOUND,
                "{ctx}"
            );
            assert!(rel_err(f.kprime, s.shape.kprime) < ROW_BOUND, "{ctx}");
            assert_eq!(f.regime, s.regime, "{ctx}");
            assert_eq!(f.validity, s.validity, "{ctx}");
        }
        (Answer::Line(f), Solution::Line(s)) => assert_eq!(f, s, "{ctx}"),
        (f, s) => panic!("{ctx}: models differ: {f:?} {s:?}"),
    }
    true
}

#[test]
fn fast_path_is_the_reference_on_random_rows() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut worst = [0.0f64; 3];
    let (mut rows, mut answered) = (0, 0);
    // The benchmark's scene and rows: every one answered.
    let demo = Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3).unwrap();
    for _ in 0..200_000 {
        let load = rng.log_uniform(200.0, 2e4);
        let phi = rng.log_uniform(2e-5, 2e-3) * if rng.next() < 0.5 { -1.0 } else { 1.0 };
        assert!(
            check_row(&demo, ModelChoice::Section9, load, phi, &mut worst),
            "P={load} phi={phi}"
        );
    }
    // Random scenes, with and without a length, both choices, wide loads and angles.
    for _ in 0..200_000 {
        let r1 = rng.log_uniform(1e-3, 1.0);
        let r2 = rng.log_uniform(1e-3, 1.0);
        let scene = Scene::new(
            r1,
            r2,
            rng.log_uniform(1e9, 3e11),
            0.5 * rng.next(),
            rng.log_uniform(0.01, 1.0),
        )
        .unwrap();
        let scene = if rng.next() < 0.5 {
            scene
                .with_length(rng.log_uniform(1e-3, 1.0).max(scene.shortest_length()))
                .unwrap()
        } else {
            scene
        };
        let choice = if rng.next() < 0.8 {
            ModelChoice::Section9
        } else {
            ModelChoice::Elliptic
        };
        let load = rng.log_uniform(1e-2, 1e6);
        let phi = rng.log_uniform(1e-9, 0.2) * if rng.next() < 0.5 { -1.0 } else { 1.0 };
        rows += 1;
        answered += usize::from(check_row(&scene, choice, load, phi, &mut worst));
    }
    eprintln!("worst {worst:?}, {answered} of {rows}");
    assert!(worst.iter().all(|&w| w < ROW_BOUND), "{worst:?}");
    // Most random rows lie in the domain (theta and theta0 below 2^-3, no decision at
    // its threshold).
    assert!(answered * 10 > rows * 7, "{answered} of {rows}");
    // The exact theta relation and forced line contact are the reference's alone.
    let exact = demo.with_theta_relation(ThetaRelation::Exact);
    assert!(Prepared::new(&exact, ModelChoice::Section9).is_none());
    assert!(Prepared::new(&demo, ModelChoice::Line).is_none());
}

/// Eight rows at a time (the batch's way) give the numbers of one at a time, bit for
/// bit, including rows the fast path leaves to the reference.
#[test]
fn rows_at_a_time_are_rows_one_at_a_time() {
    let mut rng = Rng(11);
    let scene = Scene::new(0.05, 0.08, 79.3e9, 0.3, 0.3)
        .unwrap()
        .with_length(0.1)
        .unwrap();
    let fast = Prepared::new(&scene, ModelChoice::Section9).unwrap();
    for _ in 0..20_000 {
        let load: [f64; 8] = core::array::from_fn(|_| rng.log_uniform(1e-3, 1e6));
        let phi: [f64; 8] = core::array::from_fn(|i| match i {
            0 => f64::NAN,
            1 => -rng.log_uniform(1e-14, 1.0),
            _ => rng.log_uniform(1e-9, 0.3),
        });
        let many = fast.estimate_rows(&load, &phi);
        for i in 0..8 {
            assert_eq!(
                many[i],
                fast.estimate(load[i], phi[i]),
                "P={} phi={}",
                load[i],
                phi[i]
            );
        }
    }
}
