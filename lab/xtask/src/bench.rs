//! `cargo xtask bench [--csv] [--short] [--cpu ID]`: speed against error, in one run.
//!
//! Speed: the benchmark image (lab/harness/src/bin/bench.rs) on the Cortex-M0, M3, M4F and
//! M7 in QEMU with `-icount` (instructions per call, mean and maximum over the
//! practical samples of `misalign_workload::samples`; the monitor's pipeline per sample over
//! the built-in scenario, and its profile). Error: the same code on the host against the
//! independent reference data (tests/data/vectors_scene.csv and
//! vectors_line.csv, or `$MISALIGN_REFERENCE_DIR`). Writes docs/bench.csv,
//! docs/speed-vs-error.svg and the tables drawn from them (docs/measurements.md, the
//! README's headline); `--csv` prints the CSV, else a readable table. `--cpu ID`
//! (`cortex-m4f`, ...) runs the image on that core only, for iterating on one core's
//! code; such a partial run writes nothing.

use crate::cross::{self, CPUS};
use crate::log::Fields;
use crate::records::{self, BenchRow};
use misalign::Scene;
use misalign::fixed::logexp::{exp2_fixed, log2_u32};
use misalign::fixed::tables::{LOG_G_HIGH, LOG_G_LOW};
use misalign::fixed::uniform::ONE;
use misalign::fixed::{FixedEllipticScene, FixedLineScene, exact_lsb};
use misalign::float::kernels::theta_top::theta_of_g_top;
use misalign::float::kernels::{axial_force::axial_force_ratio, cbrt::cbrt, sqrt::inv_sqrt};
use misalign::float::{EllipticScene, G_OF_THETA, LineScene, THETA_OF_G};
use misalign::reference;
use misalign_workload::hamrock_brewe::HamrockBrewe;
use misalign_workload::{Model, Operation};
use std::collections::HashMap;
use std::fmt::Write;
use std::process::ExitCode;

/// Relative error of `got` against `want`; equal values (zeros, infinities) give 0.
pub fn rel(got: f64, want: f64) -> f64 {
    if got == want || (got.is_nan() && want.is_nan()) {
        0.0
    } else {
        ((got - want) / want).abs()
    }
}

/// The rows of a reference file of tests/data/ (or `$MISALIGN_REFERENCE_DIR`).
pub fn read(name: &str) -> Result<Vec<Record>, String> {
    let dir = std::env::var_os("MISALIGN_REFERENCE_DIR").map_or_else(
        || crate::root().join("tests/data"),
        std::path::PathBuf::from,
    );
    let path = dir.join(name);
    let mut r = csv::Reader::from_path(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let headers = r.headers().map_err(|e| e.to_string())?.clone();
    r.records()
        .map(|rec| {
            let rec = rec.map_err(|e| e.to_string())?;
            Ok(headers
                .iter()
                .zip(rec.iter())
                .map(|(h, v)| (h.to_string(), v.to_string()))
                .collect())
        })
        .collect()
}

pub fn num(row: &Record, key: &str) -> f64 {
    row[key].parse().unwrap_or(f64::NAN)
}

pub fn scene(row: &Record) -> Scene {
    Scene::new(
        num(row, "R1"),
        num(row, "R2"),
        num(row, "G"),
        num(row, "nu"),
        num(row, "mu"),
    )
    .expect("scene")
}

/// Worst of d/b, F and phi0 against a reference row.
fn worst3(got: (f64, f64, f64), row: &Record) -> f64 {
    rel(got.0, num(row, "s"))
        .max(rel(got.1, num(row, "F")))
        .max(rel(got.2, data(row, "phi0")))
}

/// A reference row's value of `quantity`; phi0 beyond pi/2 (theta0 / c of eq 4 with
/// unequal radii) is NaN, as every model answers no critical angle there.
pub fn data(row: &Record, quantity: &str) -> f64 {
    let x = num(row, quantity);
    if quantity == "phi0" && x > std::f64::consts::FRAC_PI_2 {
        f64::NAN
    } else {
        x
    }
}

/// Angle counts with the sign of phi.
pub fn signed(counts: u32, phi: f64) -> i32 {
    if phi < 0.0 {
        -(counts as i32)
    } else {
        counts as i32
    }
}

/// d/b, F and phi0 of a fixed-point estimate, as f64.
pub fn fixed3(x: &misalign::fixed::FixedEstimate) -> (f64, f64, f64) {
    let force = x.axial_force.to_f64() * if x.axial_force_negative { -1.0 } else { 1.0 };
    (
        x.slip_ratio.to_f64(),
        force,
        x.critical_angle.map_or(f64::NAN, |c| c.to_f64()),
    )
}

/// The worst relative error of every (model, operation) on the host.
type Errors = HashMap<(Model, Operation), f64>;

/// Keeps the worst of `x` (NaN counts as infinite) for `(model, op)`.
fn put(e: &mut Errors, model: Model, op: Operation, x: f64) {
    let slot = e.entry((model, op)).or_insert(0.0);
    *slot = slot.max(if x.is_nan() { f64::INFINITY } else { x });
}

/// Errors of every (model, operation) on the host, over the reference files.
pub fn errors() -> Result<Errors, String> {
    let mut e = Errors::new();
    for row in &read("vectors_scene.csv")? {
        elliptic_errors(&mut e, row)?;
        inverse_errors(&mut e, row, false)?;
        kernel_errors(&mut e, row);
    }
    for row in &read("vectors_line.csv")? {
        line_errors(&mut e, row)?;
        inverse_errors(&mut e, row, true)?;
    }
    monitor_errors(&mut e)?;
    Ok(e)
}

/// Error of an inverse's answer against the true value: relative, divided by
/// max(1, sensitivity) (the round trips' measure: an input rounded to f32 already moves the
/// answer by that much), counted where the sensitivity is below 1e3; 0 for a lower
/// bound (tests/inverse.rs checks where it is said), +inf for a wrong `inconsistent`.
fn inverse_error(answer: reference::inverse::Inverse<f64>, want: f64) -> f64 {
    use reference::inverse::Inverse;
    match answer {
        Inverse::Exact { value, sensitivity } if sensitivity < 1e3 => {
            rel(value, want) / sensitivity.max(1.0)
        }
        Inverse::Exact { .. } | Inverse::AtLeast { .. } => 0.0,
        Inverse::Inconsistent(_) => f64::INFINITY,
    }
}

/// The round trips of one reference row through the inverses: the forward estimate's
/// F (the reference's in f64, the f32 core's in f32), then mu from (P, phi, F) and phi
/// from (P, F), against the row's mu and phi.
fn inverse_errors(e: &mut Errors, row: &Record, line: bool) -> Result<(), String> {
    use reference::inverse as inv;
    let s = scene(row);
    let (p, phi, mu) = (num(row, "P"), num(row, "phi"), s.friction());
    let (p32, phi32) = (p as f32, phi as f32);
    let err = |r: Result<inv::Inverse<f64>, misalign::Error>, want: f64| {
        r.map_or(f64::NAN, |a| inverse_error(a, want))
    };
    let err32 = |r: Result<inv::Inverse<f32>, misalign::Error>, want: f64| {
        r.map_or(f64::NAN, |a| inverse_error(a.map(f64::from), want))
    };
    let (ops, ref_mu, ref_phi, f32_mu, f32_phi) = if line {
        let force = reference::line(&s, p, phi)
            .map_err(|e| e.to_string())?
            .axial_force;
        let core = LineScene::new(&s).map_err(|e| e.to_string())?;
        let f = core.estimate(p32, phi32).map_err(|e| e.to_string())?;
        (
            (Operation::InverseMuLine, Operation::InversePhiLine),
            err(inv::friction_line(&s, p, phi, force), mu),
            err(inv::angle_line(&s, p, force), phi),
            err32(
                core.friction_from_axial_force(p32, phi32, f.axial_force),
                mu,
            ),
            err32(core.angle_from_axial_force(p32, f.axial_force), phi),
        )
    } else {
        let force = reference::elliptic(&s, p, phi)
            .map_err(|e| e.to_string())?
            .axial_force;
        let core = EllipticScene::new(&s).map_err(|e| e.to_string())?;
        let f = core.estimate(p32, phi32).map_err(|e| e.to_string())?;
        (
            (Operation::InverseMu, Operation::InversePhi),
            err(inv::friction_elliptic(&s, p, phi, force), mu),
            err(inv::angle_elliptic(&s, p, force), phi),
            err32(
                core.friction_from_axial_force(p32, phi32, f.axial_force),
                mu,
            ),
            err32(core.angle_from_axial_force(p32, f.axial_force), phi),
        )
    };
    put(e, Model::Reference, ops.0, ref_mu);
    put(e, Model::Reference, ops.1, ref_phi);
    put(e, Model::F32, ops.0, f32_mu);
    put(e, Model::F32, ops.1, f32_phi);
    Ok(())
}

/// The monitor's error: over the whole built-in scenario, the worst relative error of
/// d/b, F and phi0 in its readings against the reference at the same conditioned
/// sample (the reading's load and phi), with the model it holds; the pipeline's own
/// steps (spikes, smoothing) are its purpose, not an error.
fn monitor_errors(e: &mut Errors) -> Result<(), String> {
    use misalign::monitor::{Config, Monitor, Reading, model_for_range, scenario};
    use misalign::reference::ModelChoice;
    let [r1, r2, g, nu, mu] = scenario::SCENE;
    let s = Scene::new(r1, r2, g, nu, mu).map_err(|e| e.to_string())?;
    let choice =
        model_for_range(&s, scenario::LOAD_MAX, scenario::ANGLE_MIN).map_err(|e| e.to_string())?;
    let worst = |reading: &Reading| -> f64 {
        let (p, phi) = (f64::from(reading.load), f64::from(reading.phi));
        let want = match choice {
            ModelChoice::Line => reference::line(&s, p, phi).map(|r| {
                (
                    r.slip_ratio,
                    r.axial_force,
                    r.critical_angle.unwrap_or(f64::NAN),
                )
            }),
            _ => reference::elliptic(&s, p, phi).map(|r| {
                let c = r.critical_angle.unwrap_or(f64::NAN);
                (r.slip_ratio, r.axial_force, c)
            }),
        };
        let Ok((sr, f, c)) = want else {
            return f64::INFINITY;
        };
        let got_c = reading.critical_angle.map_or(f64::NAN, f64::from);
        rel(f64::from(reading.slip_ratio), sr)
            .max(rel(f64::from(reading.axial_force), f))
            .max(rel(got_c, c))
    };
    fn run<E: misalign::Estimator>(
        core: E,
        worst: &dyn Fn(&misalign::monitor::Reading) -> f64,
    ) -> Result<f64, String> {
        let mut m = Monitor::new(core, Config::default()).map_err(|e| e.to_string())?;
        let mut err = 0.0f64;
        for sample in scenario::Scenario::new() {
            m.process(sample);
            // The last valid running sample's reading (the same again after a fault).
            if let Some(r) = m.reading() {
                let x = worst(&r);
                err = err.max(if x.is_nan() { f64::INFINITY } else { x });
            }
        }
        Ok(err)
    }
    let f32_core = scenario::estimator::<misalign::float::Auto>().map_err(|e| e.to_string())?;
    put(e, Model::F32, Operation::Monitor, run(f32_core, &worst)?);
    let fixed_core =
        scenario::estimator::<misalign::fixed::FixedAuto>().map_err(|e| e.to_string())?;
    put(
        e,
        Model::Fixed,
        Operation::Monitor,
        run(fixed_core, &worst)?,
    );
    Ok(())
}

/// One row of a reference file: column name to text.
pub type Record = HashMap<String, String>;

/// The whole elliptic estimate of every model against one reference row.
fn elliptic_errors(e: &mut Errors, row: &Record) -> Result<(), String> {
    let s = scene(row);
    let (p, phi) = (num(row, "P"), num(row, "phi"));
    let r = reference::elliptic(&s, p, phi).map_err(|e| e.to_string())?;
    let r3 = (
        r.slip_ratio,
        r.axial_force,
        r.critical_angle.unwrap_or(f64::NAN),
    );
    put(e, Model::Reference, Operation::Estimate, worst3(r3, row));
    let f = EllipticScene::new(&s)
        .map_err(|e| e.to_string())?
        .estimate(p as f32, phi as f32)
        .map_err(|e| e.to_string())?;
    put(e, Model::F32, Operation::Estimate, worst3(f32s(&f), row));
    let (load_lsb, pc) = exact_lsb(p, 1 << 30, 0.0);
    let (angle_lsb, ac) = exact_lsb(phi, 1 << 30, FixedEllipticScene::min_angle_lsb(&s));
    let x = FixedEllipticScene::new(&s, load_lsb, angle_lsb).map_err(|e| e.to_string())?;
    let x = x.estimate(pc, signed(ac, phi)).map_err(|e| e.to_string())?;
    put(
        e,
        Model::Fixed,
        Operation::Estimate,
        worst3(fixed3(&x), row),
    );
    let h = HamrockBrewe::of(&s).estimate(p as f32, phi as f32);
    let h3 = (
        h.slip_ratio as f64,
        h.axial_force as f64,
        h.critical_angle as f64,
    );
    put(e, Model::HamrockBrewe, Operation::Estimate, worst3(h3, row));
    Ok(())
}

/// The line-contact estimate of every model against one reference row.
fn line_errors(e: &mut Errors, row: &Record) -> Result<(), String> {
    let s = scene(row);
    let (p, phi) = (num(row, "P"), num(row, "phi"));
    let r = reference::line(&s, p, phi).map_err(|e| e.to_string())?;
    let r3 = (
        r.slip_ratio,
        r.axial_force,
        r.critical_angle.unwrap_or(f64::NAN),
    );
    put(
        e,
        Model::Reference,
        Operation::EstimateLine,
        worst3(r3, row),
    );
    let f = LineScene::new(&s)
        .map_err(|e| e.to_string())?
        .estimate(p as f32, phi as f32)
        .map_err(|e| e.to_string())?;
    put(
        e,
        Model::F32,
        Operation::EstimateLine,
        worst3(f32s(&f), row),
    );
    let ((load_lsb, pc), (angle_lsb, ac)) =
        (exact_lsb(p, 1 << 30, 0.0), exact_lsb(phi, 1 << 30, 0.0));
    let x = FixedLineScene::new(&s, load_lsb, angle_lsb).map_err(|e| e.to_string())?;
    let x = x.estimate(pc, signed(ac, phi)).map_err(|e| e.to_string())?;
    put(
        e,
        Model::Fixed,
        Operation::EstimateLine,
        worst3(fixed3(&x), row),
    );
    Ok(())
}

/// d/b, F and phi0 of an f32 estimate, as f64.
pub fn f32s(f: &misalign::Estimate) -> (f64, f64, f64) {
    (
        f.slip_ratio as f64,
        f.axial_force as f64,
        f.critical_angle.map_or(f64::NAN, f64::from),
    )
}

/// The kernels and tables at the inputs one reference row gives them (their
/// whole-domain sweep is `cargo xtask sweep`).
fn kernel_errors(e: &mut Errors, row: &Record) {
    f32_kernel_errors(e, row);
    fixed_kernel_errors(e, row);
}

fn f32_kernel_errors(e: &mut Errors, row: &Record) {
    let p = num(row, "P");
    let theta = num(row, "theta");
    let g = num(row, "m") * num(row, "n") * theta;
    let g_table = G_OF_THETA.eval(theta as f32).map_or(f64::NAN, f64::from);
    put(e, Model::F32, Operation::TableG, rel(g_table, g));
    let theta0 = num(row, "theta0");
    let g0 = reference::normal::ellipse_shape(theta0).map_or(f64::NAN, |sh| sh.g());
    // From g = 1 the core reads theta(g) from the finer table of that octave.
    let theta_table = if g0 >= 1.0 {
        f64::from(theta_of_g_top(g0 as f32))
    } else {
        THETA_OF_G.eval(g0 as f32).map_or(f64::NAN, f64::from)
    };
    put(
        e,
        Model::F32,
        Operation::TableThetaOfG,
        rel(theta_table, theta0),
    );
    let p32 = p as f32;
    let exact_cbrt = (p32 as f64).cbrt();
    put(
        e,
        Model::F32,
        Operation::KernelCbrt,
        rel(cbrt(p32) as f64, exact_cbrt),
    );
    let libm_cbrt = libm::cbrtf(p32) as f64;
    put(
        e,
        Model::F32,
        Operation::KernelLibmCbrtf,
        rel(libm_cbrt, exact_cbrt),
    );
    let exact_inv_sqrt = 1.0 / (p32 as f64).sqrt();
    put(
        e,
        Model::F32,
        Operation::KernelInvSqrt,
        rel(inv_sqrt(p32) as f64, exact_inv_sqrt),
    );
    let libm_sqrt = libm::sqrtf(p32) as f64;
    put(
        e,
        Model::F32,
        Operation::KernelLibmSqrtf,
        rel(libm_sqrt, (p32 as f64).sqrt()),
    );
    let sr = num(row, "s");
    if sr < 1.0 {
        let want = num(row, "F").abs() / (scene(row).friction() * p);
        let got = axial_force_ratio(sr as f32) as f64;
        put(e, Model::F32, Operation::KernelAxialForce, rel(got, want));
    }
}

fn fixed_kernel_errors(e: &mut Errors, row: &Record) {
    let one = ONE as f64;
    let p = num(row, "P");
    let pu = p.round().max(1.0) as u32;
    let log_err = (log2_u32(pu) as f64 / one - (pu as f64).log2()).abs();
    put(
        e,
        Model::Fixed,
        Operation::KernelLog2,
        log_err * std::f64::consts::LN_2,
    );
    // 2^(5 + f) in Q8.24 keeps 29 significant bits: the error is the kernel's,
    // not the output format's.
    let l = ((5.0 + p.log2().abs().fract()) * one) as i32;
    let exp_err = rel(exp2_fixed(l, 24) as f64 / one, (l as f64 / one).exp2());
    put(e, Model::Fixed, Operation::KernelExp2, exp_err);
    let theta = num(row, "theta");
    let g = num(row, "m") * num(row, "n") * theta;
    let y = (theta.log2() * one).round() as i32;
    let table = if y < LOG_G_HIGH.start {
        LOG_G_LOW
    } else {
        LOG_G_HIGH
    };
    let lg = table.eval(y).map_or(f64::NAN, |v| v as f64 / one);
    let log_g_err = (lg - g.log2()).abs() * std::f64::consts::LN_2;
    put(e, Model::Fixed, Operation::TableLogG, log_g_err);
}

/// One measurement of the benchmark image: `(cpu, model, operation, mean, max)`.
type Measured = (&'static str, Model, Operation, u64, u64);

/// Builds and runs the benchmark image on every CPU (or only on `only`).
fn measure(samples: usize, only: Option<&str>) -> Result<Vec<Measured>, String> {
    crate::tools::preflight()?;
    let mut out = Vec::new();
    let mut built: HashMap<&str, std::path::PathBuf> = HashMap::new();
    for cpu in CPUS.iter().filter(|c| only.is_none_or(|id| c.id == id)) {
        if !built.contains_key(cpu.target) {
            let mut cmd = cross::harness_build(cpu.target);
            cmd.env("MISALIGN_BENCH_SAMPLES", samples.to_string())
                .args(["--bin", "bench"]);
            let artifacts = cross::build(&mut cmd)?;
            built.insert(cpu.target, cross::artifact(&artifacts, "bench")?);
        }
        let (status, log) = cross::qemu(cpu.machine, &built[cpu.target])?;
        if status != Some(0) {
            return Err(format!("bench on {} exited {status:?}:\n{log}", cpu.id));
        }
        out.extend(
            log.lines()
                .filter_map(parse_bench_line)
                .map(|(model, op, mean, max)| (cpu.id, model, op, mean, max)),
        );
        eprintln!("bench: {} done", cpu.id);
    }
    Ok(out)
}

/// `bench model=<m> op=<op> n=<calls> mean=<x> max=<y>`.
fn parse_bench_line(line: &str) -> Option<(Model, Operation, u64, u64)> {
    let f = Fields::of(line, "bench model=")?;
    Some((
        Model::from_name(f.get("model").ok()?)?,
        Operation::from_name(f.get("op").ok()?)?,
        f.num("mean").ok()?,
        f.num("max").ok()?,
    ))
}

/// The row of `(cpu, model, operation)`.
pub fn find<'a>(
    rows: &'a [BenchRow],
    cpu: &str,
    model: Model,
    op: Operation,
) -> Option<&'a BenchRow> {
    rows.iter()
        .find(|r| r.cpu == cpu && r.model == model.name() && r.operation == op.name())
}

/// `mean / max` of a row.
fn counts(r: &BenchRow) -> String {
    format!("{} / {}", r.mean, r.max)
}

/// An error as the tables print it (two digits), `-` where none was measured.
fn error(r: &BenchRow) -> String {
    r.error.map_or("-".to_string(), |e| format!("{e:.1e}"))
}

/// The estimates table: per CPU the full estimate of every model, with ratios to the
/// reference and to Hamrock & Brewe.
pub fn estimates(rows: &[BenchRow]) -> String {
    let mut s = String::new();
    writeln!(s, "| cpu | model | operation | instructions mean / max | max relative error | fewer instructions than the reference | more accurate than Hamrock & Brewe |").unwrap();
    writeln!(s, "|---|---|---|--:|--:|--:|--:|").unwrap();
    let estimate =
        |r: &&BenchRow| Operation::from_name(&r.operation).is_some_and(|o| o.is_estimate());
    for r in rows.iter().filter(estimate) {
        writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} |",
            r.cpu,
            r.model,
            r.operation,
            counts(r),
            error(r),
            fewer_instructions(rows, r),
            more_accurate(rows, r)
        )
        .unwrap();
    }
    s
}

/// A target of the elliptic estimate on one core: its mean instructions per call in
/// QEMU, its worst relative error and the bytes of table data it reads, at most these.
pub struct Target {
    pub cpu: &'static str,
    /// The core's name in prose.
    pub cpu_name: &'static str,
    pub model: Model,
    /// The model's name in prose.
    pub model_name: &'static str,
    pub instructions: u64,
    pub error: f64,
    pub table_bytes: Option<usize>,
}

/// The elliptic estimate's targets (the per-sample path at its limit): a full `cargo
/// xtask bench` fails over one, and a test holds the committed docs/bench.csv to them.
pub const TARGETS: [Target; 2] = [
    Target {
        cpu: "cortex-m4f",
        cpu_name: "Cortex-M4F",
        model: Model::F32,
        model_name: "f32",
        instructions: 100,
        error: 5e-7,
        table_bytes: Some(4096),
    },
    Target {
        cpu: "cortex-m0",
        cpu_name: "Cortex-M0",
        model: Model::Fixed,
        model_name: "fixed point",
        instructions: 350,
        error: 1e-5,
        table_bytes: None,
    },
];

/// The targets `rows` miss, one sentence each (a target without its row is missed).
pub fn missed_targets(rows: &[BenchRow]) -> Vec<String> {
    let mut missed = Vec::new();
    for t in &TARGETS {
        let what = format!("{} estimate on the {}", t.model_name, t.cpu_name);
        let Some(r) = find(rows, t.cpu, t.model, Operation::Estimate) else {
            missed.push(format!("{what}: not measured"));
            continue;
        };
        if r.mean > t.instructions {
            missed.push(format!(
                "{what}: {} instructions, target {}",
                r.mean, t.instructions
            ));
        }
        if !r.error.is_some_and(|e| e <= t.error) {
            missed.push(format!(
                "{what}: error {}, target {:.0e}",
                error(r),
                t.error
            ));
        }
        if let (Some(limit), Some(b)) = (t.table_bytes, table_bytes(t.model, Operation::Estimate))
            && b > limit
        {
            missed.push(format!("{what}: {b} bytes of tables, target {limit}"));
        }
    }
    missed
}

/// The targets and the figures `rows` give, as the measurements page states them below
/// the estimates' table.
pub fn targets_note(rows: &[BenchRow]) -> String {
    let parts: Vec<String> = TARGETS
        .iter()
        .map(|t| {
            let bytes = table_bytes(t.model, Operation::Estimate).unwrap_or(0);
            let (target_bytes, measured_bytes) = match t.table_bytes {
                Some(limit) => (
                    format!(", {limit} bytes of tables"),
                    format!(", {bytes} bytes"),
                ),
                None => (String::new(), String::new()),
            };
            let measured = find(rows, t.cpu, t.model, Operation::Estimate)
                .map_or("not measured".to_string(), |r| {
                    format!("{} at {}{measured_bytes}", r.mean, error(r))
                });
            format!(
                "{} on the {}, at most {} instructions at {:.0e}{target_bytes} ({measured})",
                t.model_name, t.cpu_name, t.instructions, t.error
            )
        })
        .collect();
    let missed = missed_targets(rows);
    format!(
        "Targets of the elliptic estimate (a full run fails over one; a test holds this \
         table to them): {}.{}\n",
        parts.join("; "),
        if missed.is_empty() {
            String::new()
        } else {
            format!(" **Missed**: {}.", missed.join("; "))
        }
    )
}

/// How many times fewer instructions `r` takes than the reference on its CPU.
fn fewer_instructions(rows: &[BenchRow], r: &BenchRow) -> String {
    rows.iter()
        .find(|x| {
            x.cpu == r.cpu && x.model == Model::Reference.name() && x.operation == r.operation
        })
        .filter(|_| r.model != Model::Reference.name())
        .map_or(String::from("-"), |x| {
            format!("{:.0}x", x.mean as f64 / r.mean.max(1) as f64)
        })
}

/// How many times more accurate a core's `r` is than Hamrock & Brewe.
fn more_accurate(rows: &[BenchRow], r: &BenchRow) -> String {
    let core = r.model == Model::F32.name() || r.model == Model::Fixed.name();
    let hb = rows.iter().find(|x| {
        x.cpu == r.cpu && x.model == Model::HamrockBrewe.name() && x.operation == r.operation
    });
    match (hb.and_then(|b| b.error), r.error) {
        (Some(b), Some(e)) if core && e > 0.0 => format!("{:.0}x", b / e),
        _ => String::from("-"),
    }
}

/// Bytes of table data (flash) that an operation reads, from the generated tables
/// themselves; `None` where it is code only or not ours (libm). Code sizes are in the
/// firmware's table (`cargo xtask firmware`).
fn table_bytes(model: Model, operation: Operation) -> Option<usize> {
    use misalign::fixed::tables as x;
    use misalign::float::tables as t;
    use std::mem::size_of_val as size;
    let force = size(&t::AXIAL_FORCE_LOW) + size(&t::AXIAL_FORCE_HIGH);
    // theta(g): its table and the finer one of its top octave.
    let theta_of_g = size(&t::THETA_OF_G_ROWS) + size(&t::THETA_OF_G_TOP);
    let log_exp = size(x::LOG2_MANTISSA.values) + size(x::EXP2_FRACTION.values);
    let log_g = size(x::LOG_G_LOW.values) + size(x::LOG_G_HIGH.values);
    let log_theta = size(x::LOG_THETA_LOW.values) + size(x::LOG_THETA_HIGH.values);
    use Operation as O;
    Some(match (model, operation) {
        (Model::F32, O::Estimate) => size(&t::G_OF_THETA_ROWS) + theta_of_g + force,
        (Model::F32, O::TableG) => size(&t::G_OF_THETA_ROWS),
        (Model::F32, O::TableThetaOfG) => theta_of_g,
        (Model::F32, O::KernelAxialForce) => force,
        (Model::F32, O::EstimateLine | O::KernelCbrt | O::KernelInvSqrt) => 0,
        (Model::F32, O::InverseMu) => size(&t::G_OF_THETA_ROWS) + force,
        (Model::F32, O::InversePhi) => size(&t::G_OF_THETA_ROWS) + theta_of_g + force,
        (Model::F32, O::InverseMuLine | O::InversePhiLine) => 0,
        (Model::Fixed, O::Estimate) => {
            log_exp + log_g + log_theta + size(x::LOG_FORCE_OVER_S.values)
        }
        (Model::Fixed, O::EstimateLine) => log_exp,
        (Model::Fixed, O::KernelLog2) => size(x::LOG2_MANTISSA.values),
        (Model::Fixed, O::KernelExp2) => size(x::EXP2_FRACTION.values),
        (Model::Fixed, O::TableLogG) => log_g,
        _ => return None,
    })
}

/// The cost table: per kernel and per core, error and instructions on the M0 and the
/// M4F, and the table bytes it reads.
pub fn cost(rows: &[BenchRow]) -> String {
    let mut s = String::new();
    writeln!(s, "| model | operation | max relative error | instructions on Cortex-M0 (mean / max) | instructions on Cortex-M4F (mean / max) | table bytes |").unwrap();
    writeln!(s, "|---|---|--:|--:|--:|--:|").unwrap();
    let mut seen = Vec::new();
    for r in rows {
        let (Some(model), Some(op)) = (
            Model::from_name(&r.model),
            Operation::from_name(&r.operation),
        ) else {
            continue;
        };
        // The monitor's profile has its own table (`stages`) and no error of its own.
        if (op.is_monitor() && op != Operation::Monitor) || seen.contains(&(model, op)) {
            continue;
        }
        seen.push((model, op));
        let on = |cpu: &str| find(rows, cpu, model, op).map_or("-".to_string(), counts);
        let bytes = table_bytes(model, op).map_or("-".to_string(), |b| b.to_string());
        writeln!(
            s,
            "| {} | `{}` | {} | {} | {} | {} |",
            r.model,
            r.operation,
            error(r),
            on("cortex-m0"),
            on("cortex-m4f"),
            bytes
        )
        .unwrap();
    }
    s
}

/// The monitor's stages table: per CPU and core, the monitor's whole per-sample
/// pipeline beside the bare estimate, and where the rest goes: a stage's cost is the
/// mean with it on minus the mean with it off, in the same run.
pub fn stages(rows: &[BenchRow]) -> String {
    let mut s = String::new();
    writeln!(s, "| cpu | core | monitor per sample (mean / max) | bare estimate (mean / max) | spike test | smoothing | trend | checks, states, wear, statistics, conversions |").unwrap();
    writeln!(s, "|---|---|--:|--:|--:|--:|--:|--:|").unwrap();
    for r in rows
        .iter()
        .filter(|r| r.operation == Operation::Monitor.name())
    {
        let Some(model) = Model::from_name(&r.model) else {
            continue;
        };
        let mean = |op| find(rows, &r.cpu, model, op).map(|x| x.mean as i64);
        let minus = |a: Option<i64>, b: Option<i64>| match (a, b) {
            (Some(a), Some(b)) => (a - b).to_string(),
            _ => "-".to_string(),
        };
        let all = Some(r.mean as i64);
        let bare = find(rows, &r.cpu, model, Operation::Estimate);
        writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} |",
            r.cpu,
            r.model,
            counts(r),
            bare.map_or("-".to_string(), counts),
            minus(all, mean(Operation::MonitorNoSpikes)),
            minus(all, mean(Operation::MonitorNoSmoothing)),
            minus(all, mean(Operation::MonitorNoTrend)),
            minus(mean(Operation::MonitorBare), bare.map(|b| b.mean as i64)),
        )
        .unwrap();
    }
    s
}

/// Errors on the host and instructions in QEMU, paired per (model, operation); the
/// error as docs/bench.csv holds it, so that tables and figure redrawn from the CSV
/// are these.
fn rows(samples: usize, only: Option<&str>) -> Result<Vec<BenchRow>, String> {
    let errors = errors()?;
    let measured = measure(samples, only)?;
    Ok(measured
        .into_iter()
        .map(|(cpu, model, operation, mean, max)| BenchRow {
            cpu: cpu.to_string(),
            model: model.name().to_string(),
            operation: operation.name().to_string(),
            mean,
            max,
            error: errors
                .get(&(model, operation))
                .filter(|e| !e.is_nan())
                .map(|&e| records::rounded(e)),
        })
        .collect())
}

/// docs/bench.csv, docs/speed-vs-error.svg and the tables drawn from them.
fn write_outputs(rows: &[BenchRow]) -> Result<(), String> {
    records::write(rows)?;
    let svg = crate::root().join("docs").join(crate::figures::SPEED_SVG);
    crate::figures::speed_vs_error(rows, &svg).map_err(|e| e.to_string())?;
    eprintln!("wrote {}", svg.display());
    crate::measurements::update()
}

pub fn run(csv: bool, short: bool, only: Option<&str>) -> ExitCode {
    if let Some(id) = only.filter(|id| !CPUS.iter().any(|c| c.id == *id)) {
        let ids: Vec<&str> = CPUS.iter().map(|c| c.id).collect();
        eprintln!("xtask bench: no cpu {id} (one of {})", ids.join(", "));
        return ExitCode::from(2);
    }
    let samples = if short { 32 } else { 256 };
    let rows = match rows(samples, only) {
        Ok(rows) => rows,
        Err(e) => {
            eprintln!("xtask bench: {e}");
            return ExitCode::FAILURE;
        }
    };
    if csv {
        print!("{}", records::to_csv(&rows));
    } else {
        print!("{}\n{}", estimates(&rows), stages(&rows));
    }
    if only.is_some() && !short {
        eprintln!("xtask bench: a run on one cpu writes nothing");
    } else if !short {
        if let Err(e) = write_outputs(&rows) {
            eprintln!("xtask bench: {e}");
            return ExitCode::FAILURE;
        }
        // Written as measured, then held to the targets.
        let missed = missed_targets(&rows);
        if !missed.is_empty() {
            for m in &missed {
                eprintln!("xtask bench: target missed: {m}");
            }
            return ExitCode::FAILURE;
        }
    }
    ExitCode::SUCCESS
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(cpu: &str, model: Model, mean: u64, error: f64) -> BenchRow {
        BenchRow {
            cpu: cpu.into(),
            model: model.name().into(),
            operation: Operation::Estimate.name().into(),
            mean,
            max: mean + 20,
            error: Some(error),
        }
    }

    /// The committed figures (docs/bench.csv, from a full run) meet the estimate's
    /// targets.
    #[test]
    fn committed_estimates_meet_their_targets() {
        let rows = records::read::<BenchRow>().unwrap();
        assert_eq!(missed_targets(&rows), Vec::<String>::new());
    }

    /// One instruction or one error above a target, or a target's row missing, is a
    /// miss; the figures at the targets are not.
    #[test]
    fn a_target_is_missed_by_one_instruction_or_a_larger_error() {
        let at = [
            row("cortex-m4f", Model::F32, 100, 5e-7),
            row("cortex-m0", Model::Fixed, 350, 1e-5),
        ];
        assert_eq!(missed_targets(&at), Vec::<String>::new());
        let over = [
            row("cortex-m4f", Model::F32, 101, 5e-7),
            row("cortex-m0", Model::Fixed, 350, 2e-5),
        ];
        let missed = missed_targets(&over);
        assert_eq!(missed.len(), 2, "{missed:?}");
        assert!(
            missed[0].contains("101 instructions, target 100"),
            "{missed:?}"
        );
        assert!(missed[1].contains("error 2.0e-5"), "{missed:?}");
        assert_eq!(missed_targets(&at[..1]).len(), 1);
        assert!(targets_note(&over).contains("**Missed**"));
    }
}
