//! The f32 core against the independent reference data, to its accuracy target: maximum
//! relative error <= 2e-6 for m, n, d/b, F and phi0 over every row, inputs rounded to
//! f32; the regime agrees except within 1e-6 of d/b = 1.

mod common;
use common::{Row, Worst, num, read_rows};
use misalign::Scene;
use misalign::float::{EllipticScene, LineScene};

const BOUND: f64 = 2e-6;

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

fn check_regime(i: usize, regime: &str, s_ref: f64, got: misalign::reference::Regime) {
    if (s_ref - 1.0).abs() > 1e-6 {
        assert_eq!(got.as_str(), regime, "row {i}: s = {s_ref}");
    }
}

#[test]
fn elliptic_against_vectors_scene() {
    let mut worst = Worst::default();
    for (i, row) in read_rows("vectors_scene.csv").iter().enumerate() {
        let prepared = EllipticScene::new(&scene(row)).unwrap();
        let (p, phi) = (num(row, "P") as f32, num(row, "phi") as f32);
        let e = prepared.estimate(p, phi).unwrap();
        let d = prepared.details(p, phi).unwrap();
        worst.add("m", i, d.m as f64, num(row, "m"));
        worst.add("n", i, d.n as f64, num(row, "n"));
        worst.add("a", i, d.a as f64, num(row, "a"));
        worst.add("b", i, d.b as f64, num(row, "b"));
        worst.add("p0", i, d.p0 as f64, num(row, "p0"));
        worst.add("s", i, e.slip_ratio as f64, num(row, "s"));
        worst.add("F", i, e.axial_force as f64, num(row, "F"));
        worst.add(
            "phi0",
            i,
            e.critical_angle.map_or(f64::NAN, f64::from),
            common::phi0(row),
        );
        check_regime(i, &row["regime"], num(row, "s"), e.regime);
    }
    worst.assert_below(BOUND);
}

#[test]
fn line_against_vectors_line() {
    let mut worst = Worst::default();
    for (i, row) in read_rows("vectors_line.csv").iter().enumerate() {
        let prepared = LineScene::new(&scene(row)).unwrap();
        let (p, phi) = (num(row, "P") as f32, num(row, "phi") as f32);
        let e = prepared.estimate(p, phi).unwrap();
        let d = prepared.details(p, phi).unwrap();
        worst.add("b", i, d.b as f64, num(row, "b"));
        worst.add("p0", i, d.p0 as f64, num(row, "p0"));
        worst.add("s", i, e.slip_ratio as f64, num(row, "s"));
        worst.add("F", i, e.axial_force as f64, num(row, "F"));
        worst.add(
            "phi0",
            i,
            e.critical_angle.map_or(f64::NAN, f64::from),
            common::phi0(row),
        );
        check_regime(i, &row["regime"], num(row, "s"), e.regime);
    }
    worst.assert_below(BOUND);
}
