//! The f64 reference against the independent 50-digit values of tests/data:
//! every row, every quantity, within 1e-12 relative (the reference's accuracy).

mod common;
use common::{Worst, num, read_rows};
use misalign::{Scene, reference};

const BOUND: f64 = 1e-12;

#[test]
fn m_n_kprime_g_against_vectors_mn() {
    let mut worst = Worst::default();
    for (i, row) in read_rows("vectors_mn.csv").iter().enumerate() {
        let theta = num(row, "theta");
        let s = reference::normal::ellipse_shape(theta).expect("theta in [0, pi/2]");
        worst.add("kprime", i, s.kprime, num(row, "kprime"));
        worst.add("m", i, s.m, num(row, "m"));
        worst.add("n", i, s.n, num(row, "n"));
        worst.add("a_over_b", i, s.m / s.n, num(row, "a_over_b"));
        worst.add("g", i, s.g(), num(row, "g"));
    }
    worst.assert_below(BOUND);
}

#[test]
fn elliptic_scenes_against_vectors_scene() {
    let mut worst = Worst::default();
    for (i, row) in read_rows("vectors_scene.csv").iter().enumerate() {
        let scene = Scene::new(
            num(row, "R1"),
            num(row, "R2"),
            num(row, "G"),
            num(row, "nu"),
            num(row, "mu"),
        )
        .expect("valid scene");
        let e = reference::elliptic(&scene, num(row, "P"), num(row, "phi")).expect("defined");
        worst.add("theta", i, e.shape.theta, num(row, "theta"));
        worst.add("kprime", i, e.shape.kprime, num(row, "kprime"));
        worst.add("m", i, e.shape.m, num(row, "m"));
        worst.add("n", i, e.shape.n, num(row, "n"));
        worst.add("a", i, e.a, num(row, "a"));
        worst.add("b", i, e.b, num(row, "b"));
        worst.add("p0", i, e.p0, num(row, "p0"));
        worst.add("s", i, e.slip_ratio, num(row, "s"));
        worst.add("d", i, e.d, num(row, "d"));
        worst.add("F", i, e.axial_force, num(row, "F"));
        worst.add("Pstar", i, e.pstar, num(row, "Pstar"));
        worst.add("P0star", i, e.p0star, num(row, "P0star"));
        worst.add(
            "phi0",
            i,
            e.critical_angle.unwrap_or(f64::NAN),
            common::phi0(row),
        );
        worst.add(
            "theta0",
            i,
            e.critical_theta.unwrap_or(f64::NAN),
            common::theta0(row),
        );
        assert_eq!(e.regime.as_str(), row["regime"], "row {i}");
    }
    worst.assert_below(BOUND);
}

#[test]
fn line_contact_against_vectors_line() {
    let mut worst = Worst::default();
    for (i, row) in read_rows("vectors_line.csv").iter().enumerate() {
        let scene = Scene::new(
            num(row, "R1"),
            num(row, "R2"),
            num(row, "G"),
            num(row, "nu"),
            num(row, "mu"),
        )
        .expect("valid scene");
        let l = reference::line(&scene, num(row, "P"), num(row, "phi")).expect("defined");
        worst.add("R", i, l.radius, num(row, "R"));
        worst.add("b", i, l.b, num(row, "b"));
        worst.add("p0", i, l.p0, num(row, "p0"));
        worst.add("Pstar", i, l.pstar, num(row, "Pstar"));
        worst.add("P0star", i, l.p0star, num(row, "P0star"));
        worst.add("s", i, l.slip_ratio, num(row, "s"));
        worst.add("d", i, l.d, num(row, "d"));
        worst.add("F", i, l.axial_force, num(row, "F"));
        worst.add(
            "phi0",
            i,
            l.critical_angle.unwrap_or(f64::NAN),
            common::phi0(row),
        );
        assert_eq!(
            l.regime.as_str(),
            row["regime"],
            "row {i} ({})",
            row["case"]
        );
    }
    worst.assert_below(BOUND);
}

/// What rounding the inputs by a few ulps alone can change in `sqrt(v)`: the
/// traction's square roots are ill-conditioned at the contact edge and at the
/// stick-zone edge, where the reference (exact geometry) and any f64 evaluation
/// (rounded a, b, c, d) must differ by about sqrt(eps).
fn sqrt_allowance(v: f64) -> f64 {
    let v = v.max(0.0);
    (v + 16.0 * f64::EPSILON).sqrt() - v.sqrt()
}

#[test]
fn traction_against_vectors_traction() {
    let mut worst = Worst::default();
    let mut edge_rows = 0;
    for (i, row) in read_rows("vectors_traction.csv").iter().enumerate() {
        let scene = Scene::new(
            num(row, "R1"),
            num(row, "R2"),
            num(row, "G"),
            num(row, "nu"),
            num(row, "mu"),
        )
        .expect("valid scene");
        let (p, phi, x, y) = (num(row, "P"), num(row, "phi"), num(row, "x"), num(row, "y"));
        let want = num(row, "X");
        // (got, scale mu p0, the two square roots' arguments)
        let (got, scale, v_edge, v_stick) = match row["kind"].as_str() {
            "ellipse" => {
                let e = reference::elliptic(&scene, p, phi).unwrap();
                let ex = 1.0 - (x / e.a).powi(2);
                let c = e.b * ex.max(0.0).sqrt();
                let u = (y - e.d) / (c - e.d);
                (
                    e.traction(&scene, x, y),
                    scene.friction() * e.p0,
                    ex - (y / e.b).powi(2),
                    1.0 - u * u,
                )
            }
            "line" => {
                let l = reference::line(&scene, p, phi).unwrap();
                let u = (y - l.d) / (l.b - l.d);
                (
                    l.traction(&scene, y),
                    scene.friction() * l.p0,
                    1.0 - (y / l.b).powi(2),
                    1.0 - u * u,
                )
            }
            other => panic!("unknown kind {other}"),
        };
        let allowance = scale * (sqrt_allowance(v_edge) + sqrt_allowance(v_stick));
        let err = (got - want).abs();
        if err > BOUND * want.abs() {
            // Only an edge point may miss the relative bound, and only by what the
            // inputs' rounding explains.
            assert!(
                err <= allowance,
                "row {i}: X = {got:e}, want {want:e}, allowance {allowance:e}"
            );
            edge_rows += 1;
        } else {
            worst.add(&row["kind"], i, got, want);
        }
    }
    println!("{edge_rows} edge rows held to the input-rounding allowance");
    worst.assert_below(BOUND);
}
