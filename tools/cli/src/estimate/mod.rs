//! The CSV estimator (`cargo run --example estimate`), shared by
//! `examples/estimate/main.rs`, the tests, the host benchmark and the fuzz target.
//!
//! Arguments through clap; every output row is one typed [`OutRow`] (with `--solve`,
//! a `solve::SolveRow`) written through csv's serde support, so that the header and
//! the values cannot drift apart; every
//! number goes through one formatter (csv's, ryu: the shortest text that reads back to
//! the same f64 or f32). Input is read as bytes: a bad row (wrong number of fields,
//! non-UTF-8 or NUL bytes, an unterminated quote, a number that is not one) becomes that
//! row's `error` and the batch goes on.

use crate::table::{self, number};
use clap::{Parser, ValueEnum};
use misalign::fixed::{FixedAuto, FixedContactDetails, FixedEllipticScene, Log2, exact_lsb};
use misalign::float::{Auto, ContactDetails};
use misalign::reference::{
    self, ANGLE_LIMIT, ContactModel, ModelChoice, PRESSURE_LIMIT, SLENDER_LIMIT, Solution, Validity,
};
use misalign::{Error, Scene};
use serde::Serialize;
use std::io::{Read, Write};

mod solve;

const ABOUT: &str = "Misalignment, microslip and axial force for each row of a CSV file, \
after \"The rolling contact of misaligned elastic cylinders\".";

const AFTER_HELP: &str = "\
INPUT (stdin): CSV with a header naming at least R1,R2,G,nu,mu,P,phi (with --solve,
    the columns under SOLVE), in any order; other columns are ignored, and each needed
    one may appear once. SI units: R1, R2 in m (R2 = inf is a plane), G in Pa, phi in
    rad (signed). An optional column `length` (m) is the rollers' contact length. P is
    the total load in N; only line contact without a length reads it as a load per
    unit length (N/m). A ';'-separated file is detected and read so (said on stderr).

MODEL CHOICE (--contact auto, the default; section 9 of the paper): the ellipse, or
    line contact with P / length when the ellipse is longer than the rollers
    (2a > length), and line contact for a plane. The same rule in every --model; the
    `model` column says which answered. Near the switch (2a / length within 1.25 of 1)
    the flag near_model_switch is raised: there line d/b is up to 1.22 times the
    ellipse's (sqrt(3 / (2 E(k)))), and phi0 jumps to the other model's value.

OUTPUT (stdout): one row per input row, in order, under one header:
    theta,m,n,a,b,p0,s,F,phi0,regime,error,kprime,Pstar,P0star,theta0,d,R,model,flags
    s is the slip ratio d/b; regime is partial (s < 1) or gross; F has the sign of phi
    and is the total axial force (N; N/m in line contact without a length). Line rows
    fill R,b,p0,s,F,phi0,d (and Pstar,P0star from the reference); elliptic rows the
    ellipse's columns. The cores leave empty what they do not compute (Pstar, P0star,
    theta0). Numbers are in shortest round-trip form. A row that cannot be computed has
    empty values and a message in `error`; the batch goes on. phi0 is empty when no
    theta < pi/2 reaches s = 1. flags lists, separated by ';', where the theory is
    stretched: large_angle, high_pressure, longer_than_rollers, near_model_switch,
    round_ellipse (a/b < 10: F under-predicted by 2 % or more), no_critical_angle.

SOLVE (--solve mu|phi): the inverse, from a measured axial force F (signed like phi;
    in N, the same unit as the forward F: per unit length in line contact without a
    length).
    --solve mu reads R1,R2,G,nu,P,phi,F (no mu) and writes mu,bound,sensitivity,error.
        The scene needs a friction coefficient to be built: it gets the placeholder
        mu = 1, which the inverses do not read.
    --solve phi reads R1,R2,G,nu,mu,P,F and writes phi,bound,sensitivity,error; phi is
        signed like F.
    bound is exact (sensitivity = d ln answer / d ln F: a relative error of F times it
    is the answer's), at_least (F only bounds the answer from below, where the forward
    map saturates: gross slip for phi, no slip for mu) or inconsistent (no state of the
    model gives F; error says why: above_model, opposite_sign, zero_load,
    no_misalignment, between_models). --contact as for the forward estimate: auto follows
    section 9 (the mu-inverse takes the model chosen at P and phi; the phi-inverse keeps
    each model's answer only where the choice takes that model). --model reference or
    f32; --model fixed answers every row with an error: the fixed-point core has no
    inverse. Bad rows get a message in error, and the batch goes on.

FIXED-POINT COUNTS (--model fixed): --counts exact (the default) asks the core: each
    row's P and phi become counts of an LSB that holds them exactly (up to 2^30
    counts), so the answer carries the core's own error only. --counts adc asks the
    node with its ADC: P in counts of --load-lsb (default 0.01 N), phi in counts of
    --angle-lsb (default the finest angle the scene's tables allow, at least 1e-10
    rad), each rounded to the nearest count, so the answer carries that rounding too.
    The Python package's estimate(model=\"fixed\", counts=...) is the same choice.

EXIT STATUS: 0; 1 when the input has no header, lacks a column or repeats one, or the
    output cannot be written; 2 for bad options.";

/// Command-line options.
#[derive(Parser, Debug)]
#[command(name = "estimate", about = ABOUT, after_help = AFTER_HELP)]
struct Options {
    /// Which implementation computes each row.
    #[arg(long, value_enum, default_value_t = Model::Reference)]
    model: Model,
    /// Which contact model answers: section 9's choice per row, or one forced.
    #[arg(long, value_enum, default_value_t = Contact::Auto)]
    contact: Contact,
    /// The inverse: this unknown from a measured axial force F instead of the forward
    /// estimate (SOLVE below).
    #[arg(long, value_enum)]
    solve: Option<solve::Unknown>,
    /// With --model fixed: how P and phi become the core's integer counts.
    #[arg(long, value_enum, default_value_t = Counts::Exact)]
    counts: Counts,
    /// With --counts adc: N per load count [default: 0.01].
    #[arg(long, value_parser = lsb, allow_hyphen_values = true)]
    load_lsb: Option<f64>,
    /// With --counts adc: rad per angle count [default: the finest angle the scene's
    /// tables allow, at least 1e-10].
    #[arg(long, value_parser = lsb, allow_hyphen_values = true)]
    angle_lsb: Option<f64>,
}

/// An LSB: a finite number above 0.
fn lsb(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        _ => Err(format!("{text:?} is not a finite number above 0")),
    }
}

/// `--counts`: how the fixed-point core's inputs become integer counts.
#[derive(Clone, Copy, PartialEq, Debug, ValueEnum)]
pub enum Counts {
    /// The core: each row's P and phi in counts of an LSB that holds them exactly (up
    /// to 2^30 counts): the answer carries the core's own error only.
    Exact,
    /// The node with its ADC: P in counts of --load-lsb, phi in counts of --angle-lsb,
    /// each rounded to the nearest count: the answer carries the rounding too.
    Adc,
}

/// The ADC's LSBs of `--counts adc`, as given (`None`: the defaults).
#[derive(Clone, Copy, Debug)]
struct Adc {
    load_lsb: Option<f64>,
    angle_lsb: Option<f64>,
}

/// `--model`.
#[derive(Clone, Copy, PartialEq, Debug, ValueEnum)]
pub enum Model {
    /// The f64 reference of the whole paper.
    Reference,
    /// The f32 core that runs on a Cortex-M4F (tables, kernels).
    F32,
    /// The fixed-point core for a Cortex-M0/M3; each row's P and phi become integer
    /// counts as --counts says. It has no inverse: with --solve, each row's error says
    /// so.
    Fixed,
}

/// `--contact`.
#[derive(Clone, Copy, PartialEq, Debug, ValueEnum)]
pub enum Contact {
    /// Section 9 per row: line contact when the ellipse is longer than the rollers.
    Auto,
    /// Always the contact ellipse (sections 5-7).
    Elliptic,
    /// Always line contact (section 8), with P / length when a length is given.
    Line,
}

impl Contact {
    fn choice(self) -> ModelChoice {
        match self {
            Contact::Auto => ModelChoice::Section9,
            Contact::Elliptic => ModelChoice::Elliptic,
            Contact::Line => ModelChoice::Line,
        }
    }
}

/// A number of an output row: the reference's f64 or the f32 core's own value, each
/// written in its shortest round-trip form.
#[derive(Clone, Copy, Debug, Serialize)]
#[serde(untagged)]
pub enum Num {
    /// From the reference or the fixed-point core.
    F64(f64),
    /// From the f32 core.
    F32(f32),
}

/// One output row; its field names are the header.
#[derive(Debug, Default, Serialize)]
pub struct OutRow<'a> {
    theta: Option<Num>,
    m: Option<Num>,
    n: Option<Num>,
    a: Option<Num>,
    b: Option<Num>,
    p0: Option<Num>,
    s: Option<Num>,
    #[serde(rename = "F")]
    force: Option<Num>,
    phi0: Option<Num>,
    regime: &'a str,
    error: &'a str,
    kprime: Option<Num>,
    #[serde(rename = "Pstar")]
    pstar: Option<Num>,
    #[serde(rename = "P0star")]
    p0star: Option<Num>,
    theta0: Option<Num>,
    d: Option<Num>,
    #[serde(rename = "R")]
    radius: Option<Num>,
    model: &'a str,
    flags: &'a str,
}

const INPUTS: [&str; 7] = ["R1", "R2", "G", "nu", "mu", "P", "phi"];

impl Options {
    /// The input columns this run needs, in the order its rows are read.
    fn inputs(&self) -> &'static [&'static str; 7] {
        self.solve.map_or(&INPUTS, solve::Unknown::inputs)
    }
}

/// The flags column, built in a buffer reused from row to row.
fn write_flags(out: &mut String, v: &Validity, no_critical_angle: bool) {
    out.clear();
    for (raised, name) in [
        (v.large_angle, "large_angle"),
        (v.high_pressure, "high_pressure"),
        (v.longer_than_rollers, "longer_than_rollers"),
        (v.near_model_switch, "near_model_switch"),
        (v.round_ellipse, "round_ellipse"),
        (no_critical_angle, "no_critical_angle"),
    ] {
        if raised {
            if !out.is_empty() {
                out.push(';');
            }
            out.push_str(name);
        }
    }
}

/// The reference's validity flags for a core's answer, from its own numbers.
fn core_validity(
    scene: &Scene,
    phi: f64,
    critical_angle: Option<f64>,
    p0: f64,
    ellipse: Option<(f64, f64)>, // (a, k')
    near_model_switch: bool,
) -> Validity {
    Validity {
        large_angle: phi.abs() > ANGLE_LIMIT || critical_angle.is_none_or(|c| c > ANGLE_LIMIT),
        high_pressure: p0 / scene.shear_modulus() > PRESSURE_LIMIT,
        longer_than_rollers: ellipse
            .zip(scene.length())
            .is_some_and(|((a, _), l)| 2.0 * a > l),
        near_model_switch,
        round_ellipse: ellipse.is_some_and(|(_, k)| k * SLENDER_LIMIT > 1.0),
    }
}

/// A core's answer: its row, and the flags from its own numbers.
fn core_answer(
    x: &Sample,
    row: OutRow<'static>,
    critical: Option<f64>,
    p0: f64,
    ellipse: Option<(f64, f64)>,
    near_model_switch: bool,
) -> Answer {
    Answer {
        row,
        validity: core_validity(&x.scene, x.phi, critical, p0, ellipse, near_model_switch),
        no_critical_angle: critical.is_none(),
    }
}

/// The numbers of a row's needed columns (named `names`), or the message for its
/// `error` column.
fn numbers(
    record: &csv::ByteRecord,
    columns: &[usize; 7],
    names: &[&str; 7],
) -> Result<[f64; 7], String> {
    let mut x = [0.0; 7];
    for (k, &c) in columns.iter().enumerate() {
        x[k] = number(names[k], record.get(c).unwrap_or(b""))?;
    }
    Ok(x)
}

/// The scene of a row from its constants (R1, R2, G, nu, mu) and its optional length.
fn scene_of(
    [r1, r2, g, nu, mu]: [f64; 5],
    record: &csv::ByteRecord,
    length: Option<usize>,
) -> Result<Scene, String> {
    let mut scene = Scene::new(r1, r2, g, nu, mu).map_err(|e| e.to_string())?;
    if let Some(field) = length.and_then(|c| record.get(c))
        && !field.iter().all(u8::is_ascii_whitespace)
    {
        let l = number("length", field)?;
        scene = scene.with_length(l).map_err(|e| e.to_string())?;
    }
    Ok(scene)
}

/// The scene and sample of a row, or the message for its `error` column.
fn scene_and_sample(
    record: &csv::ByteRecord,
    columns: &[usize; 7],
    length: Option<usize>,
) -> Result<(Scene, f64, f64), String> {
    let x = numbers(record, columns, &INPUTS)?;
    let scene = scene_of([x[0], x[1], x[2], x[3], x[4]], record, length)?;
    Ok((scene, x[5], x[6]))
}

/// The `--solve` answer of a row, or the message for its `error` column.
fn solve_row(
    options: &Options,
    unknown: solve::Unknown,
    record: &csv::ByteRecord,
    columns: &[usize; 7],
    length: Option<usize>,
) -> Result<misalign::reference::inverse::Inverse<Num>, String> {
    let x = numbers(record, columns, unknown.inputs())?;
    let scene = scene_of(unknown.scene_constants(&x), record, length)?;
    solve::answer(unknown, options.model, options.contact, &scene, &x)
}

/// One row's input.
struct Sample {
    scene: Scene,
    load: f64,
    phi: f64,
    choice: ModelChoice,
}

/// One row's answer: its values, and what its flags column says.
struct Answer {
    row: OutRow<'static>,
    validity: Validity,
    no_critical_angle: bool,
}

/// The reference's answer for one row.
fn reference_row(x: &Sample) -> Result<Answer, String> {
    let (scene, load, phi, choice) = (&x.scene, x.load, x.phi, x.choice);
    let est = reference::estimate_with(scene, load, phi, choice).map_err(|e| e.to_string())?;
    let f = Some(Num::F64(est.axial_force(scene)));
    match est {
        Solution::Elliptic(e) => {
            let opt = |x: Option<f64>| x.map(Num::F64);
            let row = OutRow {
                theta: opt(Some(e.shape.theta)),
                m: opt(Some(e.shape.m)),
                n: opt(Some(e.shape.n)),
                a: opt(Some(e.a)),
                b: opt(Some(e.b)),
                p0: opt(Some(e.p0)),
                s: opt(Some(e.slip_ratio)),
                force: f,
                phi0: opt(e.critical_angle),
                regime: e.regime.as_str(),
                kprime: opt(Some(e.shape.kprime)),
                pstar: opt(Some(e.pstar)),
                p0star: opt(Some(e.p0star)),
                theta0: opt(e.critical_theta),
                d: opt(Some(e.d)),
                model: ContactModel::Elliptic.as_str(),
                ..OutRow::default()
            };
            Ok(Answer {
                row,
                validity: e.validity,
                no_critical_angle: e.critical_angle.is_none(),
            })
        }
        Solution::Line(l) => {
            let row = OutRow {
                b: Some(Num::F64(l.b)),
                p0: Some(Num::F64(l.p0)),
                s: Some(Num::F64(l.slip_ratio)),
                force: f,
                phi0: l.critical_angle.map(Num::F64),
                regime: l.regime.as_str(),
                pstar: Some(Num::F64(l.pstar)),
                p0star: Some(Num::F64(l.p0star)),
                d: Some(Num::F64(l.d)),
                radius: Some(Num::F64(l.radius)),
                model: ContactModel::Line.as_str(),
                ..OutRow::default()
            };
            Ok(Answer {
                row,
                validity: l.validity,
                no_critical_angle: l.critical_angle.is_none(),
            })
        }
    }
}

/// f32's range for an input: finite, and not so small that it rounds to 0.
fn to_f32(name: &str, unit: &str, x: f64) -> Result<f32, String> {
    let y = x as f32;
    if y.is_infinite() {
        return Err(format!(
            "f32 core: {name} = {x:e} {unit} is outside f32's range (|{name}| <= 3.4028235e38)"
        ));
    }
    if y == 0.0 && x != 0.0 {
        return Err(format!(
            "f32 core: {name} = {x:e} {unit} is below f32's smallest number (1.4e-45)"
        ));
    }
    Ok(y)
}

fn f32_error(e: Error) -> String {
    match e {
        Error::OutOfRange => "f32 core: a scene constant is outside f32's normal range \
            (1.2e-38 to 3.4e38): R1, R2, G, mu or length too extreme for f32, or radii \
            more than 1e24 apart"
            .into(),
        e => e.to_string(),
    }
}

/// The f32 core's answer for one row.
fn f32_row(x: &Sample) -> Result<Answer, String> {
    let (scene, load, phi, choice) = (&x.scene, x.load, x.phi, x.choice);
    // As the reference: |phi| up to f64's FRAC_PI_2; above it, refused before f32's
    // rounding would carry it down onto f32's FRAC_PI_2, which the core accepts.
    if phi.abs() > core::f64::consts::FRAC_PI_2 {
        return Err(f32_error(Error::Angle));
    }
    let (p, a) = (to_f32("P", "N", load)?, to_f32("phi", "rad", phi)?);
    let auto = Auto::with_choice(scene, choice).map_err(f32_error)?;
    let e = auto.estimate(p, a).map_err(f32_error)?;
    let est = e.estimate;
    let critical = est.critical_angle.map(f64::from);
    let s = est.slip_ratio;
    let common = OutRow {
        s: Some(Num::F32(s)),
        force: Some(Num::F32(est.axial_force)),
        phi0: est.critical_angle.map(Num::F32),
        regime: est.regime.as_str(),
        model: e.model.as_str(),
        ..OutRow::default()
    };
    let near = e.near_model_switch;
    Ok(match auto.details(p, a).map_err(f32_error)? {
        ContactDetails::Elliptic(d) => {
            let kprime = d.n / d.m;
            let row = OutRow {
                theta: Some(Num::F32(d.theta)),
                m: Some(Num::F32(d.m)),
                n: Some(Num::F32(d.n)),
                a: Some(Num::F32(d.a)),
                b: Some(Num::F32(d.b)),
                p0: Some(Num::F32(d.p0)),
                kprime: Some(Num::F32(kprime)),
                d: Some(Num::F32(s.min(1.0) * d.b)),
                ..common
            };
            let ellipse = Some((d.a as f64, kprime as f64));
            core_answer(x, row, critical, d.p0 as f64, ellipse, near)
        }
        ContactDetails::Line(d) => {
            let row = OutRow {
                b: Some(Num::F32(d.b)),
                p0: Some(Num::F32(d.p0)),
                d: Some(Num::F32(s.min(1.0) * d.b)),
                radius: Some(Num::F64(scene.effective_radius())),
                ..common
            };
            core_answer(x, row, critical, d.p0 as f64, None, near)
        }
    })
}

/// The ADC's load LSB of `--counts adc` without `--load-lsb` (N): 10 mN, as the nodes.
const ADC_LOAD_LSB: f64 = 1e-2;

/// The fixed-point core's messages, with the value and the range it missed.
fn fixed_error(e: Error, what: &str) -> String {
    match e {
        Error::OutOfRange => format!("fixed-point core: {what}"),
        e => e.to_string(),
    }
}

fn signed(x: Log2, negative: bool) -> f64 {
    if negative { -x.to_f64() } else { x.to_f64() }
}

/// The fixed-point core's answer for one row: its counts exact (`adc` None) or an
/// ADC's.
fn fixed_row(x: &Sample, adc: Option<Adc>) -> Result<Answer, String> {
    let (scene, load, phi, choice) = (&x.scene, x.load, x.phi, x.choice);
    if !(load.is_finite() && load >= 0.0) {
        return Err(Error::Load.to_string());
    }
    if !phi.is_finite() {
        return Err(Error::Angle.to_string());
    }
    // Counts: up to 2^30 of an LSB that holds the value exactly; angles no finer than
    // the tables allow (theta >= 2^-40 rad per count) where an ellipse may answer.
    let min_angle = if scene.is_plane() || choice == ModelChoice::Line {
        0.0
    } else {
        FixedEllipticScene::min_angle_lsb(scene)
    };
    let (load_lsb, p, angle_lsb, angle) = match adc {
        None => {
            let (load_lsb, p) = exact_lsb(load, 1 << 30, 0.0);
            let (angle_lsb, a) = exact_lsb(phi, 1 << 30, min_angle);
            let angle = i32::try_from(a).map_err(|_| Error::Angle.to_string())?;
            (
                load_lsb,
                p,
                angle_lsb,
                if phi < 0.0 { -angle } else { angle },
            )
        }
        Some(adc) => {
            if phi.abs() > core::f64::consts::FRAC_PI_2 {
                return Err(Error::Angle.to_string());
            }
            let load_lsb = adc.load_lsb.unwrap_or(ADC_LOAD_LSB);
            let angle_lsb = adc.angle_lsb.unwrap_or(min_angle.max(1e-10));
            let (p, a) = ((load / load_lsb).round(), (phi / angle_lsb).round());
            if p > u32::MAX as f64 || a.abs() > i32::MAX as f64 {
                return Err(fixed_error(
                    Error::OutOfRange,
                    &format!(
                        "P or phi beyond 2^32 counts of --load-lsb {load_lsb:e} N, --angle-lsb {angle_lsb:e} rad"
                    ),
                ));
            }
            (load_lsb, p as u32, angle_lsb, a as i32)
        }
    };
    let auto = FixedAuto::with_choice(scene, load_lsb, angle_lsb, choice).map_err(|e| {
        if adc.is_some() && angle_lsb < min_angle {
            fixed_error(
                e,
                &format!(
                    "--angle-lsb {angle_lsb:e} rad is finer than this scene's tables allow, \
                     {min_angle:e} rad (theta = c |phi| >= 2^-40 rad, eq 4)"
                ),
            )
        } else if adc.is_some() {
            fixed_error(
                e,
                &format!(
                    "a scene constant or --load-lsb {load_lsb:e} N, --angle-lsb {angle_lsb:e} \
                     rad is outside its Q8.24 logarithms (2^-100 to 2^100)"
                ),
            )
        } else if angle_lsb < min_angle {
            fixed_error(
                e,
                &format!(
                    "|phi| = {:e} rad is below its smallest angle {min_angle:e} rad for this \
                     scene (theta = c |phi| >= 2^-40 rad, eq 4)",
                    phi.abs()
                ),
            )
        } else {
            fixed_error(
                e,
                &format!(
                    "a scene constant is outside its Q8.24 logarithms (2^-100 to 2^100): \
                     R1, R2, G, mu, length or P = {load:e} N too extreme"
                ),
            )
        }
    })?;
    let range = auto.input_range();
    let sample_error = |e: Error| {
        fixed_error(
            e,
            &format!(
                "P = {load:e} N is below its smallest load for this scene, {:e} N (the \
                 critical angle's table starts at theta = 2^-40 rad)",
                range.load_min as f64 * load_lsb
            ),
        )
    };
    let e = auto.estimate(p, angle).map_err(sample_error)?;
    let est = e.estimate;
    let critical = est.critical_angle.map(Log2::to_f64);
    let s = est.slip_ratio.to_f64();
    let common = OutRow {
        s: Some(Num::F64(s)),
        force: Some(Num::F64(signed(est.axial_force, est.axial_force_negative))),
        phi0: critical.map(Num::F64),
        regime: est.regime.as_str(),
        model: e.model.as_str(),
        ..OutRow::default()
    };
    let near = e.near_model_switch;
    Ok(match auto.details(p, angle).map_err(sample_error)? {
        FixedContactDetails::Elliptic(d) => {
            let (m, n, b, p0) = (d.m.to_f64(), d.n.to_f64(), d.b.to_f64(), d.p0.to_f64());
            let kprime = n / m;
            let row = OutRow {
                theta: Some(Num::F64(d.theta.to_f64())),
                m: Some(Num::F64(m)),
                n: Some(Num::F64(n)),
                a: Some(Num::F64(d.a.to_f64())),
                b: Some(Num::F64(b)),
                p0: Some(Num::F64(p0)),
                kprime: Some(Num::F64(kprime)),
                d: Some(Num::F64(s.min(1.0) * b)),
                ..common
            };
            core_answer(x, row, critical, p0, Some((d.a.to_f64(), kprime)), near)
        }
        FixedContactDetails::Line(d) => {
            let (b, p0) = (d.b.to_f64(), d.p0.to_f64());
            let row = OutRow {
                b: Some(Num::F64(b)),
                p0: Some(Num::F64(p0)),
                d: Some(Num::F64(s.min(1.0) * b)),
                radius: Some(Num::F64(scene.effective_radius())),
                ..common
            };
            core_answer(x, row, critical, p0, None, near)
        }
    })
}

/// Where the needed columns are: `Err` with the message when one is missing or repeated.
fn find_columns(
    header: &csv::ByteRecord,
    inputs: &[&str; 7],
) -> Result<([usize; 7], Option<usize>), String> {
    let (at, optional) = table::find_columns(header, inputs, &["length"])?;
    let mut columns = [0usize; 7];
    columns.copy_from_slice(&at);
    Ok((columns, optional[0]))
}

/// The header `row` is written under, alone (an input with no data row): the row
/// serialised into a scratch writer, whose first record is the header.
fn write_header<W: Write, R: Serialize>(
    writer: &mut csv::Writer<W>,
    row: &R,
) -> Result<(), csv::Error> {
    let mut scratch = csv::Writer::from_writer(Vec::new());
    scratch.serialize(row)?;
    let bytes = scratch.into_inner().map_err(|e| e.into_error())?;
    let mut header = csv::ByteRecord::new();
    csv::ReaderBuilder::new()
        .has_headers(false)
        .from_reader(&bytes[..])
        .read_byte_record(&mut header)?;
    writer.write_byte_record(&header)
}

fn reader(delimiter: u8, headers: bool, input: &[u8]) -> csv::Reader<&[u8]> {
    csv::ReaderBuilder::new()
        .delimiter(delimiter)
        .has_headers(headers)
        .flexible(true)
        .trim(csv::Trim::All)
        .from_reader(input)
}

/// Runs the estimator over `input`, writing CSV to `output` and diagnostics to `err`;
/// returns the process exit code.
pub fn run(args: &[String], mut input: impl Read, output: impl Write, err: &mut dyn Write) -> i32 {
    let options = match Options::try_parse_from(
        std::iter::once("estimate".into()).chain(args.iter().cloned()),
    ) {
        Ok(o) => o,
        Err(e) => {
            let text = e.render().to_string();
            return match e.kind() {
                clap::error::ErrorKind::DisplayHelp | clap::error::ErrorKind::DisplayVersion => {
                    let mut output = output;
                    match output.write_all(text.as_bytes()) {
                        Ok(()) => 0,
                        Err(e) => {
                            let _ = writeln!(err, "estimate: cannot write the output: {e}");
                            1
                        }
                    }
                }
                _ => {
                    let _ = write!(err, "{text}");
                    2
                }
            };
        }
    };
    let adc_only = [
        ("--load-lsb", options.load_lsb),
        ("--angle-lsb", options.angle_lsb),
    ];
    if let Some((name, _)) = adc_only.iter().find(|(_, v)| v.is_some())
        && (options.model != Model::Fixed || options.counts != Counts::Adc)
    {
        let _ = writeln!(
            err,
            "estimate: {name} is the ADC's: it needs --model fixed --counts adc"
        );
        return 2;
    }
    if options.counts == Counts::Adc && options.model != Model::Fixed {
        let _ = writeln!(
            err,
            "estimate: --counts is the fixed-point core's: it needs --model fixed"
        );
        return 2;
    }
    let mut data = Vec::new();
    if let Err(e) = input.read_to_end(&mut data) {
        let _ = writeln!(err, "estimate: cannot read the input: {e}");
        return 1;
    }
    // The header: the first record, ','-separated, or ';'-separated if only that
    // gives the needed columns.
    let inputs = options.inputs();
    let (delimiter, header) = match table::header(&data, inputs) {
        Ok(h) => h,
        Err(message) => {
            let _ = writeln!(err, "estimate: {message}");
            return 1;
        }
    };
    if delimiter == b';' {
        let _ = writeln!(err, "estimate: {}", table::SEMICOLON_NOTE);
    }
    let mut rdr = reader(delimiter, true, &data);
    let _ = rdr.byte_headers();
    let (columns, length) = match find_columns(&header, inputs) {
        Ok(c) => c,
        Err(message) => {
            let _ = writeln!(err, "estimate: {message}");
            return 1;
        }
    };
    let choice = options.contact.choice();
    let adc = (options.counts == Counts::Adc).then_some(Adc {
        load_lsb: options.load_lsb,
        angle_lsb: options.angle_lsb,
    });
    let mut writer = csv::Writer::from_writer(output);
    let mut record = csv::ByteRecord::new();
    let (mut flags, mut message) = (String::new(), String::new());
    let mut origin = 0; // byte offset of `rdr`'s input in `data`
    let mut rows = 0usize;
    loop {
        let mut restart = None;
        while let Ok(true) = rdr.read_byte_record(&mut record) {
            let start = origin + record.position().map_or(0, |p| p.byte() as usize);
            message.clear();
            // An unterminated quote runs to the end of the input: that row's error,
            // and the batch goes on from the line after the row's start.
            let rest = &data[start.min(data.len())..];
            let to_the_end = origin + rdr.position().byte() as usize >= data.len();
            if to_the_end && rest.iter().filter(|&&b| b == b'"').count() % 2 == 1 {
                message.push_str("unterminated quote: the row runs to the end of the input");
                restart = rest.iter().position(|&b| b == b'\n').map(|i| start + i + 1);
            } else if let Some(m) = table::bad_record(&record, header.len()) {
                message.push_str(&m);
            }
            let readable = message.is_empty();
            let written = if let Some(unknown) = options.solve {
                let mut answer = None;
                if readable {
                    match solve_row(&options, unknown, &record, &columns, length) {
                        Ok(a) => answer = Some(a),
                        Err(m) => message = m,
                    }
                }
                writer.serialize(solve::SolveRow::new(unknown, answer, &message))
            } else {
                let mut row = OutRow::default();
                if readable {
                    let result = scene_and_sample(&record, &columns, length).and_then(
                        |(scene, load, phi)| {
                            let x = Sample {
                                scene,
                                load,
                                phi,
                                choice,
                            };
                            match options.model {
                                Model::Reference => reference_row(&x),
                                Model::F32 => f32_row(&x),
                                Model::Fixed => fixed_row(&x, adc),
                            }
                        },
                    );
                    match result {
                        Ok(answer) => {
                            write_flags(&mut flags, &answer.validity, answer.no_critical_angle);
                            row = answer.row;
                            row.flags = &flags;
                        }
                        Err(m) => message = m,
                    }
                }
                row.error = &message;
                writer.serialize(&row)
            };
            if let Err(e) = written {
                let _ = writeln!(err, "estimate: cannot write the output: {e}");
                return 1;
            }
            rows += 1;
            if restart.is_some() {
                break;
            }
        }
        match restart {
            Some(at) if at < data.len() => {
                origin = at;
                rdr = reader(delimiter, false, &data[at..]);
            }
            _ => break,
        }
    }
    // No data row: the header alone, so that the output is still a table.
    let header = if rows > 0 {
        Ok(())
    } else if let Some(unknown) = options.solve {
        write_header(&mut writer, &solve::SolveRow::new(unknown, None, ""))
    } else {
        write_header(&mut writer, &OutRow::default())
    };
    if let Err(e) = header.and_then(|()| writer.flush().map_err(csv::Error::from)) {
        let _ = writeln!(err, "estimate: cannot write the output: {e}");
        return 1;
    }
    0
}
