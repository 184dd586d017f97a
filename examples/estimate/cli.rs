//! The estimator's logic, shared by `examples/estimate/main.rs` and the tests.

use misalign::fixed::{FixedEllipticScene, FixedLineScene, Log2, exact_lsb};
use misalign::float::{EllipticScene, LineScene};
use misalign::reference::{self, Regime, Validity};
use misalign::{Error, Scene};
use std::io::{Read, Write};

pub const HELP: &str = "\
estimate: misalignment, microslip and axial force for each row of a CSV file

USAGE:
    cargo run --release --example estimate -- [--model reference|f32|fixed] [--contact elliptic|line] < in.csv > out.csv

OPTIONS:
    --model reference     the f64 reference of the whole paper (default)
    --model f32           the f32 core that runs on a Cortex-M4F (tables, kernels)
    --model fixed         the fixed-point core for a Cortex-M0/M3; each row's P and phi
                          become integer counts of an LSB that holds them exactly
                          (up to 2^30 counts; angles no finer than the tables allow)
    --contact elliptic    the contact ellipse, sections 5-7 (default); P in N
    --contact line        line contact, section 8; P in N/m, R2 = inf for a plane
    -h, --help            this text

INPUT (stdin): CSV with a header naming at least R1,R2,G,nu,mu,P,phi, in any order;
    other columns are ignored. SI units: R1, R2 in m (R2 may be inf), G in Pa, P in N
    (N/m for line contact), phi in rad (signed). An optional column `length` (m) is the
    rollers' contact length: the flags then say when the ellipse is longer.

OUTPUT (stdout): one row per input row, in order.
    elliptic: theta,m,n,a,b,p0,s,F,phi0,regime,error,kprime,Pstar,P0star,theta0,d,model,flags
    line:     R,b,p0,s,F,phi0,regime,error,Pstar,P0star,d,model,flags
    s is the slip ratio d/b; regime is partial (s < 1) or gross; F has the sign of phi.
    The cores leave empty what they do not compute (Pstar, P0star, theta0, flags other
    than no_critical_angle).
    Numbers are in shortest round-trip form. A row that cannot be computed has empty
    values and a message in `error`; the batch goes on. phi0 is empty when no
    theta <= pi/2 reaches s = 1 (flag no_critical_angle). flags lists, separated by
    ';', where the theory is stretched: large_angle, high_pressure,
    longer_than_rollers.

EXIT STATUS: 0, unless the input is not CSV or lacks a column (2 for bad options).
";

const INPUTS: [&str; 7] = ["R1", "R2", "G", "nu", "mu", "P", "phi"];
const ELLIPTIC: [&str; 18] = [
    "theta", "m", "n", "a", "b", "p0", "s", "F", "phi0", "regime", "error", "kprime", "Pstar",
    "P0star", "theta0", "d", "model", "flags",
];
const LINE: [&str; 13] = [
    "R", "b", "p0", "s", "F", "phi0", "regime", "error", "Pstar", "P0star", "d", "model", "flags",
];

#[derive(Clone, Copy, PartialEq, Debug)]
pub enum Contact {
    Elliptic,
    Line,
}

#[derive(Clone, Copy, PartialEq, Debug)]
pub enum Model {
    Reference,
    F32,
    Fixed,
}

/// Shortest text that reads back to the same f64.
pub fn number(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 || !x.is_finite() || (1e-3..1e7).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// Shortest text that reads back to the same f32.
pub fn number32(x: f32) -> String {
    let a = x.abs();
    if x == 0.0 || !x.is_finite() || (1e-3..1e7).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

fn flags(v: &Validity, no_critical_angle: bool) -> String {
    let mut out = Vec::new();
    if v.large_angle {
        out.push("large_angle");
    }
    if v.high_pressure {
        out.push("high_pressure");
    }
    if v.longer_than_rollers {
        out.push("longer_than_rollers");
    }
    if no_critical_angle {
        out.push("no_critical_angle");
    }
    out.join(";")
}

/// A row's inputs, or the message for its `error` column.
fn scene_and_sample(
    values: &[Option<&str>; 7],
    length: Option<&str>,
) -> Result<(Scene, f64, f64), String> {
    let mut x = [0.0; 7];
    for (i, v) in values.iter().enumerate() {
        let text = v.unwrap_or("").trim();
        x[i] = text
            .parse::<f64>()
            .map_err(|_| format!("{}: not a number: {text:?}", INPUTS[i]))?;
    }
    let mut scene = Scene::new(x[0], x[1], x[2], x[3], x[4]).map_err(|e: Error| e.to_string())?;
    if let Some(l) = length.map(str::trim).filter(|l| !l.is_empty()) {
        let l: f64 = l
            .parse()
            .map_err(|_| format!("length: not a number: {l:?}"))?;
        scene = scene.with_length(l).map_err(|e| e.to_string())?;
    }
    Ok((scene, x[5], x[6]))
}

fn elliptic_row(scene: &Scene, load: f64, phi: f64) -> Result<Vec<String>, String> {
    let e = reference::elliptic(scene, load, phi).map_err(|e| e.to_string())?;
    let opt = |x: Option<f64>| x.map(number).unwrap_or_default();
    Ok(vec![
        number(e.shape.theta),
        number(e.shape.m),
        number(e.shape.n),
        number(e.a),
        number(e.b),
        number(e.p0),
        number(e.slip_ratio),
        number(e.axial_force),
        opt(e.critical_angle),
        e.regime.as_str().into(),
        String::new(),
        number(e.shape.kprime),
        number(e.pstar),
        number(e.p0star),
        opt(e.critical_theta),
        number(e.d),
        "elliptic".into(),
        flags(&e.validity, e.critical_angle.is_none()),
    ])
}

fn no_critical(phi0: &str) -> String {
    if phi0.is_empty() {
        "no_critical_angle".into()
    } else {
        String::new()
    }
}

fn f32_elliptic_row(scene: &Scene, load: f64, phi: f64) -> Result<Vec<String>, String> {
    let prepared = EllipticScene::new(scene).map_err(|e| e.to_string())?;
    let (p, a) = (load as f32, phi as f32);
    let e = prepared.estimate(p, a).map_err(|e| e.to_string())?;
    let d = prepared.details(p, a).map_err(|e| e.to_string())?;
    let phi0 = e.critical_angle.map(number32).unwrap_or_default();
    let width = if e.slip_ratio < 1.0 {
        e.slip_ratio * d.b
    } else {
        d.b
    };
    Ok(vec![
        number32(d.theta),
        number32(d.m),
        number32(d.n),
        number32(d.a),
        number32(d.b),
        number32(d.p0),
        number32(e.slip_ratio),
        number32(e.axial_force),
        phi0.clone(),
        e.regime.as_str().into(),
        String::new(),
        number32(d.n / d.m),
        String::new(),
        String::new(),
        String::new(),
        number32(width),
        "elliptic".into(),
        no_critical(&phi0),
    ])
}

fn f32_line_row(scene: &Scene, load: f64, phi: f64) -> Result<Vec<String>, String> {
    let prepared = LineScene::new(scene).map_err(|e| e.to_string())?;
    let e = prepared
        .estimate(load as f32, phi as f32)
        .map_err(|e| e.to_string())?;
    Ok(vec![
        number(scene.effective_radius()),
        String::new(),
        String::new(),
        number32(e.slip_ratio),
        number32(e.axial_force),
        e.critical_angle.map(number32).unwrap_or_default(),
        e.regime.as_str().into(),
        String::new(),
        String::new(),
        String::new(),
        String::new(),
        "line".into(),
        String::new(),
    ])
}

/// Counts for the fixed-point core: 2^30 of an LSB that holds the value exactly.
fn counts(x: f64, min_lsb: f64) -> (f64, u32) {
    exact_lsb(x, 1 << 30, min_lsb)
}

fn signed(x: Log2, negative: bool) -> String {
    number(if negative { -x.to_f64() } else { x.to_f64() })
}

fn fixed_elliptic_row(scene: &Scene, load: f64, phi: f64) -> Result<Vec<String>, String> {
    if !(load.is_finite() && load >= 0.0) {
        return Err(Error::Load.to_string());
    }
    if !phi.is_finite() || scene.is_plane() {
        return Err(if scene.is_plane() {
            Error::PlaneHasNoEllipse
        } else {
            Error::Angle
        }
        .to_string());
    }
    let (load_lsb, p) = counts(load, 0.0);
    let (angle_lsb, a) = counts(phi, FixedEllipticScene::min_angle_lsb(scene));
    let angle = if phi < 0.0 { -(a as i64) } else { a as i64 };
    let angle = i32::try_from(angle).map_err(|_| Error::Angle.to_string())?;
    let prepared =
        FixedEllipticScene::new(scene, load_lsb, angle_lsb).map_err(|e| e.to_string())?;
    let e = prepared.estimate(p, angle).map_err(|e| e.to_string())?;
    let d = prepared.details(p, angle).map_err(|e| e.to_string())?;
    let phi0 = e
        .critical_angle
        .map(|x| number(x.to_f64()))
        .unwrap_or_default();
    let width = if e.regime == Regime::Partial {
        e.slip_ratio.to_f64() * d.b.to_f64()
    } else {
        d.b.to_f64()
    };
    Ok(vec![
        number(d.theta.to_f64()),
        number(d.m.to_f64()),
        number(d.n.to_f64()),
        number(d.a.to_f64()),
        number(d.b.to_f64()),
        number(d.p0.to_f64()),
        number(e.slip_ratio.to_f64()),
        signed(e.axial_force, e.axial_force_negative),
        phi0.clone(),
        e.regime.as_str().into(),
        String::new(),
        number(d.n.to_f64() / d.m.to_f64()),
        String::new(),
        String::new(),
        String::new(),
        number(width),
        "elliptic".into(),
        no_critical(&phi0),
    ])
}

fn fixed_line_row(scene: &Scene, load: f64, phi: f64) -> Result<Vec<String>, String> {
    if !(load.is_finite() && load >= 0.0) {
        return Err(Error::Load.to_string());
    }
    if !phi.is_finite() {
        return Err(Error::Angle.to_string());
    }
    let (load_lsb, p) = counts(load, 0.0);
    let (angle_lsb, a) = counts(phi, 0.0);
    let angle = if phi < 0.0 { -(a as i32) } else { a as i32 };
    let prepared = FixedLineScene::new(scene, load_lsb, angle_lsb).map_err(|e| e.to_string())?;
    let e = prepared.estimate(p, angle).map_err(|e| e.to_string())?;
    Ok(vec![
        number(scene.effective_radius()),
        String::new(),
        String::new(),
        number(e.slip_ratio.to_f64()),
        signed(e.axial_force, e.axial_force_negative),
        e.critical_angle
            .map(|x| number(x.to_f64()))
            .unwrap_or_default(),
        e.regime.as_str().into(),
        String::new(),
        String::new(),
        String::new(),
        String::new(),
        "line".into(),
        String::new(),
    ])
}

fn line_row(scene: &Scene, load: f64, phi: f64) -> Result<Vec<String>, String> {
    let l = reference::line(scene, load, phi).map_err(|e| e.to_string())?;
    Ok(vec![
        number(l.radius),
        number(l.b),
        number(l.p0),
        number(l.slip_ratio),
        number(l.axial_force),
        number(l.critical_angle),
        l.regime.as_str().into(),
        String::new(),
        number(l.pstar),
        number(l.p0star),
        number(l.d),
        "line".into(),
        flags(&l.validity, false),
    ])
}

/// Runs the estimator over `input`, writing CSV to `output` and diagnostics to `err`;
/// returns the process exit code.
pub fn run(args: &[String], input: impl Read, output: impl Write, err: &mut dyn Write) -> i32 {
    let mut contact = Contact::Elliptic;
    let mut model = Model::Reference;
    let mut i = 0;
    while i < args.len() {
        let value = args.get(i + 1).map(String::as_str);
        match (args[i].as_str(), value) {
            ("-h" | "--help", _) => {
                let mut output = output;
                let _ = output.write_all(HELP.as_bytes());
                return 0;
            }
            ("--model", Some("reference")) => (model, i) = (Model::Reference, i + 1),
            ("--model", Some("f32")) => (model, i) = (Model::F32, i + 1),
            ("--model", Some("fixed")) => (model, i) = (Model::Fixed, i + 1),
            ("--contact", Some("elliptic")) => (contact, i) = (Contact::Elliptic, i + 1),
            ("--contact", Some("line")) => (contact, i) = (Contact::Line, i + 1),
            (other, v) => {
                let _ = writeln!(
                    err,
                    "estimate: bad option {other} {}\n\n{HELP}",
                    v.unwrap_or("")
                );
                return 2;
            }
        }
        i += 1;
    }
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(input);
    let headers = match reader.headers() {
        Ok(h) => h.clone(),
        Err(e) => {
            let _ = writeln!(err, "estimate: input is not CSV: {e}");
            return 1;
        }
    };
    let mut columns = [0usize; 7];
    for (k, name) in INPUTS.iter().enumerate() {
        match headers.iter().position(|h| h == *name) {
            Some(p) => columns[k] = p,
            None => {
                let _ = writeln!(
                    err,
                    "estimate: input lacks column {name} (needs {})",
                    INPUTS.join(",")
                );
                return 1;
            }
        }
    }
    let length_column = headers.iter().position(|h| h == "length");
    let out_columns: &[&str] = if contact == Contact::Elliptic {
        &ELLIPTIC
    } else {
        &LINE
    };
    let mut writer = csv::Writer::from_writer(output);
    let error_index = out_columns.iter().position(|c| *c == "error").unwrap_or(0);
    if writer.write_record(out_columns).is_err() {
        return 1;
    }
    for (row, record) in reader.records().enumerate() {
        let record = match record {
            Ok(r) => r,
            Err(e) => {
                let _ = writer.flush();
                let _ = writeln!(
                    err,
                    "estimate: input is not CSV at data row {}: {e}",
                    row + 1
                );
                return 1;
            }
        };
        let values = columns.map(|c| record.get(c));
        let result = scene_and_sample(&values, length_column.and_then(|c| record.get(c))).and_then(
            |(scene, load, phi)| match (model, contact) {
                (Model::Reference, Contact::Elliptic) => elliptic_row(&scene, load, phi),
                (Model::Reference, Contact::Line) => line_row(&scene, load, phi),
                (Model::F32, Contact::Elliptic) => f32_elliptic_row(&scene, load, phi),
                (Model::F32, Contact::Line) => f32_line_row(&scene, load, phi),
                (Model::Fixed, Contact::Elliptic) => fixed_elliptic_row(&scene, load, phi),
                (Model::Fixed, Contact::Line) => fixed_line_row(&scene, load, phi),
            },
        );
        let fields = result.unwrap_or_else(|message| {
            let mut empty = vec![String::new(); out_columns.len()];
            empty[error_index] = message;
            empty
        });
        if writer.write_record(&fields).is_err() {
            return 1;
        }
    }
    if writer.flush().is_err() { 1 } else { 0 }
}
