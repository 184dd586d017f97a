//! `cargo xtask bench [--csv] [--short]`: speed against error, in one run.
//!
//! Speed: the benchmark image (examples/bench) on the Cortex-M0, M3, M4F and M7 in
//! QEMU with `-icount` (instructions per call, mean and maximum over the practical
//! samples of benches/common/samples.rs). Error: the same code on the host against the
//! independent reference data (tests/data/vectors_scene.csv and
//! vectors_line.csv, or `$MISALIGN_REFERENCE_DIR`). Writes docs/bench.csv, docs/speed-vs-error.svg and the README's
//! "Accuracy and cost" table; `--csv` prints the CSV, else a readable table.

#[path = "../../benches/common/hamrock_brewe.rs"]
mod hamrock_brewe;

use crate::cross;
use misalign::Scene;
use misalign::fixed::logexp::{exp2_fixed, log2_u32};
use misalign::fixed::uniform::ONE;
use misalign::fixed::{FixedEllipticScene, FixedLineScene, exact_lsb};
use misalign::float::{EllipticScene, LineScene};
use misalign::kernels::{axial_force::axial_force_ratio, cbrt::cbrt, sqrt::inv_sqrt};
use misalign::reference;
use misalign::tables::{G_OF_THETA, LOG_G_HIGH, LOG_G_LOW, THETA_OF_G};
use std::collections::HashMap;
use std::fmt::Write;
use std::process::ExitCode;

struct Cpu {
    name: &'static str,
    target: &'static str,
    machine: &'static str,
}

const CPUS: [Cpu; 4] = [
    Cpu {
        name: "cortex-m0",
        target: "thumbv6m-none-eabi",
        machine: "microbit",
    },
    Cpu {
        name: "cortex-m3",
        target: "thumbv7m-none-eabi",
        machine: "mps2-an385",
    },
    Cpu {
        name: "cortex-m4f",
        target: "thumbv7em-none-eabihf",
        machine: "mps2-an386",
    },
    Cpu {
        name: "cortex-m7",
        target: "thumbv7em-none-eabihf",
        machine: "mps2-an500",
    },
];

/// One measured row.
#[derive(Clone)]
pub struct Row {
    pub cpu: &'static str,
    pub model: String,
    pub operation: String,
    pub mean: u64,
    pub max: u64,
    pub error: f64,
}

fn rel(got: f64, want: f64) -> f64 {
    if got == want {
        0.0
    } else {
        ((got - want) / want).abs()
    }
}

type Rows = Vec<HashMap<String, String>>;

fn read(name: &str) -> Result<Rows, String> {
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

fn num(row: &HashMap<String, String>, key: &str) -> f64 {
    row[key].parse().unwrap_or(f64::NAN)
}

fn scene(row: &HashMap<String, String>) -> Scene {
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
fn worst3(got: (f64, f64, f64), row: &HashMap<String, String>) -> f64 {
    rel(got.0, num(row, "s"))
        .max(rel(got.1, num(row, "F")))
        .max(rel(got.2, num(row, "phi0")))
}

/// Angle counts with the sign of phi.
fn signed(counts: u32, phi: f64) -> i32 {
    if phi < 0.0 {
        -(counts as i32)
    } else {
        counts as i32
    }
}

/// d/b, F and phi0 of a fixed-point estimate, as f64.
fn fixed3(x: &misalign::fixed::FixedEstimate) -> (f64, f64, f64) {
    let force = x.axial_force.to_f64() * if x.axial_force_negative { -1.0 } else { 1.0 };
    (
        x.slip_ratio.to_f64(),
        force,
        x.critical_angle.map_or(f64::NAN, |c| c.to_f64()),
    )
}

/// Error of an inverse's answer against the true value: relative, divided by
/// max(1, sensitivity) (issue 11's measure), counted where the sensitivity is below
/// 1e3; 0 for a lower bound (tested elsewhere), +inf for a wrong `inconsistent`.
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

/// Errors of every (model, operation) on the host, over the reference files.
pub fn errors() -> Result<HashMap<(String, String), f64>, String> {
    let scenes = read("vectors_scene.csv")?;
    let lines = read("vectors_line.csv")?;
    let mut e: HashMap<(String, String), f64> = HashMap::new();
    let mut put = |model: &str, op: &str, x: f64| {
        let slot = e.entry((model.to_string(), op.to_string())).or_insert(0.0);
        *slot = slot.max(if x.is_nan() { f64::INFINITY } else { x });
    };
    for row in &scenes {
        let s = scene(row);
        let (p, phi) = (num(row, "P"), num(row, "phi"));
        let r = reference::elliptic(&s, p, phi).map_err(|e| e.to_string())?;
        put(
            "reference",
            "estimate",
            worst3(
                (
                    r.slip_ratio,
                    r.axial_force,
                    r.critical_angle.unwrap_or(f64::NAN),
                ),
                row,
            ),
        );
        let f = EllipticScene::new(&s)
            .map_err(|e| e.to_string())?
            .estimate(p as f32, phi as f32)
            .map_err(|e| e.to_string())?;
        let f3 = (
            f.slip_ratio as f64,
            f.axial_force as f64,
            f.critical_angle.map_or(f64::NAN, f64::from),
        );
        put("f32", "estimate", worst3(f3, row));
        let mu = s.friction();
        let inv = reference::inverse::friction_elliptic(&s, p, phi, r.axial_force);
        put(
            "reference",
            "inverse:mu",
            inv.map_or(f64::NAN, |a| inverse_error(a, mu)),
        );
        let inv = reference::inverse::angle_elliptic(&s, p, r.axial_force);
        put(
            "reference",
            "inverse:phi",
            inv.map_or(f64::NAN, |a| inverse_error(a, phi)),
        );
        let core = EllipticScene::new(&s).map_err(|e| e.to_string())?;
        let (p32, phi32, f32_force) = (p as f32, phi as f32, f.axial_force);
        let inv = core.friction_from_axial_force(p32, phi32, f32_force);
        put(
            "f32",
            "inverse:mu",
            inv.map_or(f64::NAN, |a| inverse_error(a.map(f64::from), mu)),
        );
        let inv = core.angle_from_axial_force(p32, f32_force);
        put(
            "f32",
            "inverse:phi",
            inv.map_or(f64::NAN, |a| inverse_error(a.map(f64::from), phi)),
        );
        let (load_lsb, pc) = exact_lsb(p, 1 << 30, 0.0);
        let (angle_lsb, ac) = exact_lsb(phi, 1 << 30, FixedEllipticScene::min_angle_lsb(&s));
        let x = FixedEllipticScene::new(&s, load_lsb, angle_lsb).map_err(|e| e.to_string())?;
        let x = x.estimate(pc, signed(ac, phi)).map_err(|e| e.to_string())?;
        put("fixed", "estimate", worst3(fixed3(&x), row));
        let hb = hamrock_brewe::HamrockBrewe::new(
            s.r1(),
            s.r2(),
            s.shear_modulus(),
            s.poisson_ratio(),
            s.friction(),
        );
        let h = hb.estimate(p as f32, phi as f32);
        put(
            "hamrock-brewe",
            "estimate",
            worst3(
                (
                    h.slip_ratio as f64,
                    h.axial_force as f64,
                    h.critical_angle as f64,
                ),
                row,
            ),
        );
        // Kernels, at the inputs these rows give them (their whole-domain sweep is
        // `cargo xtask sweep`).
        let theta = num(row, "theta");
        let g = num(row, "m") * num(row, "n") * theta;
        put(
            "f32",
            "table:g",
            rel(G_OF_THETA.eval(theta as f32).map_or(f64::NAN, f64::from), g),
        );
        let theta0 = num(row, "theta0");
        let g0 = reference::normal::ellipse_shape(theta0).map_or(f64::NAN, |sh| sh.g());
        put(
            "f32",
            "table:theta_of_g",
            rel(
                THETA_OF_G.eval(g0 as f32).map_or(f64::NAN, f64::from),
                theta0,
            ),
        );
        put(
            "f32",
            "kernel:cbrt",
            rel(cbrt(p as f32) as f64, (p as f32 as f64).cbrt()),
        );
        put(
            "f32",
            "kernel:libm_cbrtf",
            rel(libm::cbrtf(p as f32) as f64, (p as f32 as f64).cbrt()),
        );
        put(
            "f32",
            "kernel:inv_sqrt",
            rel(inv_sqrt(p as f32) as f64, 1.0 / (p as f32 as f64).sqrt()),
        );
        put(
            "f32",
            "kernel:libm_sqrtf",
            rel(libm::sqrtf(p as f32) as f64, (p as f32 as f64).sqrt()),
        );
        let sr = num(row, "s");
        if sr < 1.0 {
            let want = num(row, "F").abs() / (s.friction() * p);
            put(
                "f32",
                "kernel:axial_force",
                rel(axial_force_ratio(sr as f32) as f64, want),
            );
        }
        let pu = p.round().max(1.0) as u32;
        let log_err = (log2_u32(pu) as f64 / ONE as f64 - (pu as f64).log2()).abs();
        put("fixed", "kernel:log2", log_err * std::f64::consts::LN_2);
        // 2^(5 + f) in Q8.24 keeps 29 significant bits: the error is the kernel's,
        // not the output format's.
        let l = ((5.0 + p.log2().abs().fract()) * ONE as f64) as i32;
        put(
            "fixed",
            "kernel:exp2",
            rel(
                exp2_fixed(l, 24) as f64 / ONE as f64,
                (l as f64 / ONE as f64).exp2(),
            ),
        );
        let y = (theta.log2() * ONE as f64).round() as i32;
        let table = if y < LOG_G_HIGH.start {
            LOG_G_LOW
        } else {
            LOG_G_HIGH
        };
        let lg = table.eval(y).map_or(f64::NAN, |v| v as f64 / ONE as f64);
        put(
            "fixed",
            "table:log_g",
            (lg - g.log2()).abs() * std::f64::consts::LN_2,
        );
    }
    for row in &lines {
        let s = scene(row);
        let (p, phi) = (num(row, "P"), num(row, "phi"));
        let r = reference::line(&s, p, phi).map_err(|e| e.to_string())?;
        put(
            "reference",
            "estimate:line",
            worst3((r.slip_ratio, r.axial_force, r.critical_angle), row),
        );
        let f = LineScene::new(&s)
            .map_err(|e| e.to_string())?
            .estimate(p as f32, phi as f32)
            .map_err(|e| e.to_string())?;
        let f3 = (
            f.slip_ratio as f64,
            f.axial_force as f64,
            f.critical_angle.map_or(f64::NAN, f64::from),
        );
        put("f32", "estimate:line", worst3(f3, row));
        let (mu, core) = (s.friction(), LineScene::new(&s).map_err(|e| e.to_string())?);
        let inv = reference::inverse::friction_line(&s, p, phi, r.axial_force);
        put(
            "reference",
            "inverse:mu:line",
            inv.map_or(f64::NAN, |a| inverse_error(a, mu)),
        );
        let inv = reference::inverse::angle_line(&s, p, r.axial_force);
        put(
            "reference",
            "inverse:phi:line",
            inv.map_or(f64::NAN, |a| inverse_error(a, phi)),
        );
        let inv = core.friction_from_axial_force(p as f32, phi as f32, f.axial_force);
        let e = inv.map_or(f64::NAN, |a| inverse_error(a.map(f64::from), mu));
        put("f32", "inverse:mu:line", e);
        let inv = core.angle_from_axial_force(p as f32, f.axial_force);
        let e = inv.map_or(f64::NAN, |a| inverse_error(a.map(f64::from), phi));
        put("f32", "inverse:phi:line", e);
        let ((load_lsb, pc), (angle_lsb, ac)) =
            (exact_lsb(p, 1 << 30, 0.0), exact_lsb(phi, 1 << 30, 0.0));
        let x = FixedLineScene::new(&s, load_lsb, angle_lsb).map_err(|e| e.to_string())?;
        let x = x.estimate(pc, signed(ac, phi)).map_err(|e| e.to_string())?;
        put("fixed", "estimate:line", worst3(fixed3(&x), row));
    }
    Ok(e)
}

/// Builds and runs the benchmark image on every CPU.
/// `(cpu, model, operation, mean, max)` per measurement.
type Measured = Vec<(&'static str, String, String, u64, u64)>;

fn measure(samples: usize) -> Result<Measured, String> {
    crate::firmware::preflight()?;
    let mut out = Vec::new();
    let mut built: HashMap<&str, std::path::PathBuf> = HashMap::new();
    for cpu in &CPUS {
        if !built.contains_key(cpu.target) {
            let mut cmd = cross::cargo();
            cmd.env("MISALIGN_BENCH_SAMPLES", samples.to_string())
                .args([
                    "build",
                    "--profile",
                    "firmware",
                    "--target",
                    cpu.target,
                    "--features",
                    "firmware",
                    "--example",
                    "bench",
                    "--message-format=json-render-diagnostics",
                ]);
            let artifacts = cross::build(&mut cmd)?;
            built.insert(cpu.target, cross::artifact(&artifacts, "bench")?);
        }
        let (status, log) = cross::qemu(cpu.machine, &built[cpu.target])?;
        if status != Some(0) {
            return Err(format!("bench on {} exited {status:?}:\n{log}", cpu.name));
        }
        for line in log.lines() {
            let Some(rest) = line.find("bench model=").map(|i| &line[i + 6..]) else {
                continue;
            };
            let field = |k: &str| {
                rest.split_whitespace()
                    .find_map(|kv| kv.strip_prefix(k)?.strip_prefix('='))
            };
            let (Some(model), Some(op), Some(mean), Some(max)) =
                (field("model"), field("op"), field("mean"), field("max"))
            else {
                continue;
            };
            out.push((
                cpu.name,
                model.to_string(),
                op.to_string(),
                mean.parse().unwrap_or(0),
                max.parse().unwrap_or(0),
            ));
        }
        eprintln!("bench: {} done", cpu.name);
    }
    Ok(out)
}

fn csv_text(rows: &[Row]) -> String {
    let mut s =
        String::from("cpu,model,operation,instructions_mean,instructions_max,max_rel_error\n");
    for r in rows {
        writeln!(
            s,
            "{},{},{},{},{},{:.3e}",
            r.cpu, r.model, r.operation, r.mean, r.max, r.error
        )
        .unwrap();
    }
    s
}

fn find<'a>(rows: &'a [Row], cpu: &str, model: &str, op: &str) -> Option<&'a Row> {
    rows.iter()
        .find(|r| r.cpu == cpu && r.model == model && r.operation == op)
}

/// The readable table: per CPU the full estimate of every model, with ratios to the
/// baseline and the reference.
fn readable(rows: &[Row]) -> String {
    let mut s = String::new();
    writeln!(s, "| cpu | model | operation | instructions mean / max | max relative error | fewer instructions than the reference | more accurate than Hamrock & Brewe |").unwrap();
    writeln!(s, "|---|---|---|--:|--:|--:|--:|").unwrap();
    for r in rows.iter().filter(|r| r.operation.starts_with("estimate")) {
        let reference = find(rows, r.cpu, "reference", &r.operation);
        let baseline = find(rows, r.cpu, "hamrock-brewe", &r.operation);
        let faster = reference
            .filter(|_| r.model != "reference")
            .map_or(String::from("-"), |x| {
                format!("{:.0}x", x.mean as f64 / r.mean.max(1) as f64)
            });
        let core = r.model == "f32" || r.model == "fixed";
        let better = baseline.filter(|_| core).map_or(String::from("-"), |b| {
            if r.error > 0.0 {
                format!("{:.0}x", b.error / r.error)
            } else {
                "-".into()
            }
        });
        writeln!(
            s,
            "| {} | {} | {} | {} / {} | {:.1e} | {} | {} |",
            r.cpu, r.model, r.operation, r.mean, r.max, r.error, faster, better
        )
        .unwrap();
    }
    s
}

/// The README's "Accuracy and cost" table: per kernel and per core, error and
/// instructions on the M0 and the M4F.
/// Bytes of table data (flash) that an operation reads, from the generated tables
/// themselves; `None` where it is code only or not ours (libm). Code sizes are in the
/// firmware's table (`cargo xtask firmware`).
fn table_bytes(model: &str, operation: &str) -> Option<usize> {
    use misalign::tables as t;
    use std::mem::size_of_val as size;
    let force = size(&t::AXIAL_FORCE_LOW) + size(&t::AXIAL_FORCE_HIGH);
    let log_exp = size(t::LOG2_MANTISSA.values) + size(t::EXP2_FRACTION.values);
    let log_g = size(t::LOG_G_LOW.values) + size(t::LOG_G_HIGH.values);
    let log_theta = size(t::LOG_THETA_LOW.values) + size(t::LOG_THETA_HIGH.values);
    Some(match (model, operation) {
        ("f32", "estimate") => size(&t::G_OF_THETA_ROWS) + size(&t::THETA_OF_G_ROWS) + force,
        ("f32", "table:g") => size(&t::G_OF_THETA_ROWS),
        ("f32", "table:theta_of_g") => size(&t::THETA_OF_G_ROWS),
        ("f32", "kernel:axial_force") => force,
        ("f32", "estimate:line" | "kernel:cbrt" | "kernel:inv_sqrt") => 0,
        ("f32", "inverse:mu") => size(&t::G_OF_THETA_ROWS) + force,
        ("f32", "inverse:phi") => size(&t::G_OF_THETA_ROWS) + size(&t::THETA_OF_G_ROWS) + force,
        ("f32", "inverse:mu:line" | "inverse:phi:line") => 0,
        ("fixed", "estimate") => log_exp + log_g + log_theta + size(t::LOG_FORCE_OVER_S.values),
        ("fixed", "estimate:line") => log_exp,
        ("fixed", "kernel:log2") => size(t::LOG2_MANTISSA.values),
        ("fixed", "kernel:exp2") => size(t::EXP2_FRACTION.values),
        ("fixed", "table:log_g") => log_g,
        _ => return None,
    })
}

fn accuracy_and_cost(rows: &[Row]) -> String {
    let mut s = String::new();
    writeln!(s, "| model | operation | max relative error | instructions on Cortex-M0 (mean / max) | instructions on Cortex-M4F (mean / max) | table bytes |").unwrap();
    writeln!(s, "|---|---|--:|--:|--:|--:|").unwrap();
    let mut seen = Vec::new();
    for r in rows {
        let key = (r.model.clone(), r.operation.clone());
        if seen.contains(&key) {
            continue;
        }
        seen.push(key);
        let on = |cpu: &str| {
            find(rows, cpu, &r.model, &r.operation)
                .map_or("-".to_string(), |x| format!("{} / {}", x.mean, x.max))
        };
        let bytes = table_bytes(&r.model, &r.operation).map_or("-".to_string(), |b| b.to_string());
        writeln!(
            s,
            "| {} | `{}` | {:.1e} | {} | {} | {} |",
            r.model,
            r.operation,
            r.error,
            on("cortex-m0"),
            on("cortex-m4f"),
            bytes
        )
        .unwrap();
    }
    s
}

fn write_readme(table: &str) -> Result<(), String> {
    let path = crate::root().join("README.md");
    let text = std::fs::read_to_string(&path).map_err(|e| e.to_string())?;
    let (begin, end) = ("<!-- bench:begin -->", "<!-- bench:end -->");
    let (Some(a), Some(b)) = (text.find(begin), text.find(end)) else {
        return Err("README.md has no bench markers".into());
    };
    std::fs::write(
        &path,
        format!("{}{begin}\n{table}{}", &text[..a], &text[b..]),
    )
    .map_err(|e| e.to_string())
}

pub fn run(csv: bool, short: bool) -> ExitCode {
    let samples = if short { 32 } else { 256 };
    let result = (|| -> Result<Vec<Row>, String> {
        let errors = errors()?;
        let measured = measure(samples)?;
        Ok(measured
            .into_iter()
            .map(|(cpu, model, operation, mean, max)| {
                let error = errors
                    .get(&(model.clone(), operation.clone()))
                    .copied()
                    .unwrap_or(f64::NAN);
                Row {
                    cpu,
                    model,
                    operation,
                    mean,
                    max,
                    error,
                }
            })
            .collect())
    })();
    let rows = match result {
        Ok(rows) => rows,
        Err(e) => {
            eprintln!("xtask bench: {e}");
            return ExitCode::FAILURE;
        }
    };
    let text = csv_text(&rows);
    if csv {
        print!("{text}");
    } else {
        print!("{}", readable(&rows));
    }
    if !short {
        let docs = crate::root().join("docs");
        let csv_path = docs.join("bench.csv");
        // The figure: every estimate, and the kernels where they run (f32 on the
        // Cortex-M4F, fixed point on the Cortex-M0), so that the labels stay legible.
        let shown: Vec<Row> = rows
            .iter()
            .filter(|r| {
                r.operation == "estimate"
                    || (r.model == "f32"
                        && r.cpu == "cortex-m4f"
                        && !r.operation.ends_with(":line"))
                    || (r.model == "fixed"
                        && r.cpu == "cortex-m0"
                        && r.operation != "estimate:line")
            })
            .cloned()
            .collect();
        let figure_csv = std::env::temp_dir().join("misalign-bench-figure.csv");
        let written = std::fs::write(&csv_path, &text)
            .and_then(|_| std::fs::write(&figure_csv, csv_text(&shown)))
            .map_err(|e| e.to_string())
            .and_then(|_| {
                crate::figures::speed_vs_error(&figure_csv, &docs.join("speed-vs-error.svg"))
                    .map_err(|e| e.to_string())
            })
            .and_then(|_| {
                write_readme(&format!(
                    "{}\n{}",
                    readable(&rows),
                    accuracy_and_cost(&rows)
                ))
            });
        if let Err(e) = written {
            eprintln!("xtask bench: {e}");
            return ExitCode::FAILURE;
        }
        eprintln!(
            "wrote docs/bench.csv, docs/speed-vs-error.svg and the README's Accuracy and cost table"
        );
    }
    ExitCode::SUCCESS
}
