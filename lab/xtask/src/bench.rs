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
use crate::measurements::bench::{estimates, missed_targets, stages};
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
