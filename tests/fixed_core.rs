//! The fixed-point core against the independent reference data, to its accuracy target:
//! maximum relative error <= 1e-4 for d/b, F and phi0 over every row. Each row's load
//! and angle become counts of an LSB that represents them exactly (x = counts x LSB,
//! with up to 1.2e9 counts, as many as the scene's angle range allows), so that what is
//! measured is the core's arithmetic, not a sensor's quantisation.

mod common;
use common::{Row, Worst, num, read_rows};
use misalign::Scene;
use misalign::fixed::{FixedEllipticScene, FixedEstimate, FixedLineScene, exact_lsb};

const BOUND: f64 = 1e-4;

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

/// Counts and LSB that represent x exactly with up to 1234567891 counts (no power of
/// two, so that log2 of the counts is not exact), the LSB at least `floor`.
fn lsb(x: f64, floor: f64) -> (f64, f64) {
    let (lsb, counts) = exact_lsb(x, 1_234_567_891, floor);
    (lsb, (counts as f64).copysign(x))
}

fn signed_force(e: &FixedEstimate) -> f64 {
    let f = e.axial_force.to_f64();
    if e.axial_force_negative { -f } else { f }
}

#[test]
fn elliptic_against_vectors_scene() {
    let mut worst = Worst::default();
    for (i, row) in read_rows("vectors_scene.csv").iter().enumerate() {
        let s = scene(row);
        let (p, phi) = (num(row, "P"), num(row, "phi"));
        let (angle_lsb, angle) = lsb(phi, FixedEllipticScene::min_angle_lsb(&s));
        let (load_lsb, load) = lsb(p, 0.0);
        let prepared = FixedEllipticScene::new(&s, load_lsb, angle_lsb).unwrap();
        let e = prepared.estimate(load as u32, angle as i32).unwrap();
        worst.add("s", i, e.slip_ratio.to_f64(), num(row, "s"));
        worst.add("F", i, signed_force(&e), num(row, "F"));
        worst.add(
            "phi0",
            i,
            e.critical_angle.map_or(f64::NAN, |c| c.to_f64()),
            common::phi0(row),
        );
        if (num(row, "s") - 1.0).abs() > 1e-4 {
            assert_eq!(e.regime.as_str(), row["regime"], "row {i}");
        }
        let d = prepared.details(load as u32, angle as i32).unwrap();
        for (name, got) in [
            ("theta", d.theta),
            ("m", d.m),
            ("n", d.n),
            ("a", d.a),
            ("b", d.b),
            ("p0", d.p0),
        ] {
            worst.add(name, i, got.to_f64(), num(row, name));
        }
    }
    worst.assert_below(BOUND);
}

#[test]
fn line_against_vectors_line() {
    let mut worst = Worst::default();
    for (i, row) in read_rows("vectors_line.csv").iter().enumerate() {
        let (p, phi) = (num(row, "P"), num(row, "phi"));
        let ((load_lsb, load), (angle_lsb, angle)) = (lsb(p, 0.0), lsb(phi, 0.0));
        let prepared = FixedLineScene::new(&scene(row), load_lsb, angle_lsb).unwrap();
        let e = prepared.estimate(load as u32, angle as i32).unwrap();
        let d = prepared.details(load as u32, angle as i32).unwrap();
        worst.add("b", i, d.b.to_f64(), num(row, "b"));
        worst.add("p0", i, d.p0.to_f64(), num(row, "p0"));
        worst.add("s", i, e.slip_ratio.to_f64(), num(row, "s"));
        worst.add("F", i, signed_force(&e), num(row, "F"));
        worst.add(
            "phi0",
            i,
            e.critical_angle.map_or(f64::NAN, |c| c.to_f64()),
            common::phi0(row),
        );
        if (num(row, "s") - 1.0).abs() > 1e-4 {
            assert_eq!(
                e.regime.as_str(),
                row["regime"],
                "row {i} ({})",
                row["case"]
            );
        }
    }
    worst.assert_below(BOUND);
}
