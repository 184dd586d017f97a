//! `cargo xtask accuracy`: the worst relative error of every quantity each model
//! gives, against every row of the independent reference data
//! (tests/data/vectors_scene.csv and vectors_line.csv), on the host. Writes
//! docs/accuracy.csv and its table in docs/measurements.md (and the README's headline).
//!
//! As the tests measure it (tests/float_core.rs, fixed_core.rs, reference_vectors.rs,
//! which hold each core to its bound): the f32 core with its inputs rounded to f32; the
//! fixed-point core with each row's load and angle as counts of an LSB that represents
//! them exactly (up to 1 234 567 891 counts, so that log2 of the counts is not exact),
//! so that what is measured is the core's arithmetic, not a sensor's quantisation.

use crate::bench::{Record, data, f32s, fixed3, num, read, rel, scene, signed};
use crate::measurements::accuracy::table;
use crate::records::{self, AccuracyRow};
use misalign::fixed::{FixedEllipticScene, FixedLineScene, exact_lsb};
use misalign::float::{EllipticScene, LineScene};
use misalign::reference;
use std::process::ExitCode;

/// The worst error per quantity of one model on one contact, over the rows compared.
struct Worst {
    model: &'static str,
    contact: &'static str,
    errors: Vec<(&'static str, f64)>,
    rows: u64,
}

impl Worst {
    fn new(model: &'static str, contact: &'static str) -> Self {
        Worst {
            model,
            contact,
            errors: Vec::new(),
            rows: 0,
        }
    }

    /// Keeps the worst error of `quantity` (NaN counts as infinite).
    fn add(&mut self, quantity: &'static str, got: f64, row: &Record) {
        let e = rel(got, data(row, quantity));
        let e = if e.is_nan() { f64::INFINITY } else { e };
        match self.errors.iter_mut().find(|(q, _)| *q == quantity) {
            Some(slot) => slot.1 = slot.1.max(e),
            None => self.errors.push((quantity, e)),
        }
    }

    /// d/b, F and phi0.
    fn add3(&mut self, (s, f, phi0): (f64, f64, f64), row: &Record) {
        self.add("s", s, row);
        self.add("F", f, row);
        self.add("phi0", phi0, row);
        self.rows += 1;
    }

    fn rows(self) -> impl Iterator<Item = AccuracyRow> {
        let (model, contact, rows) = (self.model, self.contact, self.rows);
        self.errors
            .into_iter()
            .map(move |(quantity, e)| AccuracyRow {
                model: model.into(),
                contact: contact.into(),
                quantity: quantity.into(),
                max_rel: records::rounded(e),
                rows,
            })
    }
}

/// The exact counts of `x` with an LSB of at least `floor` (as tests/fixed_core.rs).
fn counts(x: f64, floor: f64) -> (f64, u32) {
    exact_lsb(x, 1_234_567_891, floor)
}

/// Every model's worst errors.
pub fn measure() -> Result<Vec<AccuracyRow>, String> {
    let err = |e: misalign::Error| e.to_string();
    let mut reference = Worst::new("reference", "elliptic");
    let mut float = Worst::new("f32", "elliptic");
    let mut fixed = Worst::new("fixed", "elliptic");
    for row in &read("vectors_scene.csv")? {
        let s = scene(row);
        let (p, phi) = (num(row, "P"), num(row, "phi"));
        let r = reference::elliptic(&s, p, phi).map_err(err)?;
        let c = r.critical_angle.unwrap_or(f64::NAN);
        reference.add3((r.slip_ratio, r.axial_force, c), row);
        for (q, v) in [
            ("m", r.shape.m),
            ("n", r.shape.n),
            ("a", r.a),
            ("b", r.b),
            ("p0", r.p0),
        ] {
            reference.add(q, v, row);
        }
        let core = EllipticScene::new(&s).map_err(err)?;
        let (p32, phi32) = (p as f32, phi as f32);
        float.add3(f32s(&core.estimate(p32, phi32).map_err(err)?), row);
        let d = core.details(p32, phi32).map_err(err)?;
        for (q, v) in [("m", d.m), ("n", d.n), ("a", d.a), ("b", d.b), ("p0", d.p0)] {
            float.add(q, f64::from(v), row);
        }
        let (load_lsb, pc) = counts(p, 0.0);
        let (angle_lsb, ac) = counts(phi, FixedEllipticScene::min_angle_lsb(&s));
        let core = FixedEllipticScene::new(&s, load_lsb, angle_lsb).map_err(err)?;
        let ac = signed(ac, phi);
        fixed.add3(fixed3(&core.estimate(pc, ac).map_err(err)?), row);
        let d = core.details(pc, ac).map_err(err)?;
        for (q, v) in [("m", d.m), ("n", d.n), ("a", d.a), ("b", d.b), ("p0", d.p0)] {
            fixed.add(q, v.to_f64(), row);
        }
    }
    let mut reference_line = Worst::new("reference", "line");
    let mut float_line = Worst::new("f32", "line");
    let mut fixed_line = Worst::new("fixed", "line");
    for row in &read("vectors_line.csv")? {
        let s = scene(row);
        let (p, phi) = (num(row, "P"), num(row, "phi"));
        let r = reference::line(&s, p, phi).map_err(err)?;
        reference_line.add3(
            (
                r.slip_ratio,
                r.axial_force,
                r.critical_angle.unwrap_or(f64::NAN),
            ),
            row,
        );
        reference_line.add("b", r.b, row);
        reference_line.add("p0", r.p0, row);
        let core = LineScene::new(&s).map_err(err)?;
        let (p32, phi32) = (p as f32, phi as f32);
        float_line.add3(f32s(&core.estimate(p32, phi32).map_err(err)?), row);
        let d = core.details(p32, phi32).map_err(err)?;
        float_line.add("b", f64::from(d.b), row);
        float_line.add("p0", f64::from(d.p0), row);
        let ((load_lsb, pc), (angle_lsb, ac)) = (counts(p, 0.0), counts(phi, 0.0));
        let core = FixedLineScene::new(&s, load_lsb, angle_lsb).map_err(err)?;
        let ac = signed(ac, phi);
        fixed_line.add3(fixed3(&core.estimate(pc, ac).map_err(err)?), row);
        let d = core.details(pc, ac).map_err(err)?;
        fixed_line.add("b", d.b.to_f64(), row);
        fixed_line.add("p0", d.p0.to_f64(), row);
    }
    Ok([
        float,
        float_line,
        fixed,
        fixed_line,
        reference,
        reference_line,
    ]
    .into_iter()
    .flat_map(Worst::rows)
    .collect())
}

/// `cargo xtask accuracy`: measures, prints the table, writes docs/accuracy.csv and
/// the tables drawn from it.
pub fn run() -> ExitCode {
    let result = measure().and_then(|rows| {
        print!("{}", table(&rows));
        records::write(&rows)?;
        crate::measurements::update()
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask accuracy: {e}");
            ExitCode::FAILURE
        }
    }
}
