//! Chores for people and CI alike: `cargo xtask <task>`.

mod bench;
mod cross;
mod figures;
mod firmware;
mod fit;
mod fixed_tables;
mod fuzz;
mod modbus;
mod node;
mod nopanic;
mod shapes;
mod sweep;
mod tables;
mod trace;

use std::path::PathBuf;
use std::process::ExitCode;

const USAGE: &str = "\
usage: cargo xtask <task>

tasks:
    tables [--check]               generate src/float/tables.rs, src/fixed/tables.rs and the
                                   firmware's trace (examples/firmware/trace.rs) from the
                                   f64 reference (--check: fail if a committed file differs)
    fuzz [--seconds N | --runs N]  every fuzz target for N seconds (default 60), or for N
                                   inputs from a fixed seed (repeatable; CI); nightly
    sweep [--quick] [--readme]     every f32 kernel over every input of its domain against
                                   the reference (--quick strides; --readme writes the table)
    tables --explore | --explore-force | --explore-fixed | --derivatives
                                   error and size of the table shapes considered
    figures [--check]              write the paper's Figs 1-4 (and the speed against
                                   error from docs/bench.csv, the table shapes from
                                   docs/shapes.csv, if any) as SVG to docs/
                                   (--check: fail if a committed SVG differs)
    bench [--csv] [--short] [--cpu ID]
                                   speed against error: the benchmark image on Cortex-M0, M3,
                                   M4F, M7 in QEMU (instructions) and the same code on the
                                   host against the reference data (error); writes
                                   docs/bench.csv, docs/speed-vs-error.svg and the README
                                   table (--short: fewer samples, writes nothing; --cpu
                                   cortex-m4f etc.: that core only, writes nothing)
    shapes [--short] [--csv]       the table shapes weighed (f32: variable, segments, degree;
                                   fixed point: spacing, interpolation, one table or two):
                                   instructions in QEMU (f32 on the Cortex-M4F, fixed point
                                   on the M0 and M3) beside the library's kernels, bytes,
                                   and error against the reference on the host; writes
                                   docs/shapes.csv and docs/table-shapes.svg (--short:
                                   fewer inputs, writes nothing)
    firmware [--readme]            build every firmware image and on-target test, run them
                                   in QEMU (Cortex-M4F, M7, M3, M0), print the size and
                                   stack table (--readme: write it into README.md); fail
                                   on any failure or over budget
    nopanic                        prove the estimator has no panic path (panic-never)
    modbus [--boards | --serve PORT | --trace T.csv --scene S.csv --events OUT.csv
           [--model f32|fixed] | --registers | --measure] [--target TRIPLE]
                                   the Modbus node in QEMU against pymodbus (xtask/src/modbus.rs)
";

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let flag = |f: &str| args.iter().any(|a| a == f);
    match args.first().map(String::as_str) {
        Some("tables") if flag("--explore-octaves") => {
            tables::explore_octaves(0, 6);
            ExitCode::SUCCESS
        }
        Some("tables") if flag("--explore-force") => {
            tables::explore_force();
            ExitCode::SUCCESS
        }
        Some("fuzz") => {
            let value = |name: &str| {
                args.iter()
                    .position(|a| a == name)
                    .and_then(|i| args.get(i + 1))
                    .and_then(|s| s.parse::<u64>().ok())
            };
            let budget = match (value("--runs"), value("--seconds")) {
                (Some(n), _) => fuzz::Budget::Runs(n),
                (None, s) => fuzz::Budget::Seconds(s.unwrap_or(60) as u32),
            };
            match fuzz::run(&root(), budget) {
                Ok(()) => ExitCode::SUCCESS,
                Err(e) => {
                    eprintln!("xtask fuzz: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        Some("sweep") => {
            let quick = flag("--quick");
            let start = std::time::Instant::now();
            let rows = sweep::run(quick);
            let table = sweep::markdown(&rows, quick);
            print!("{table}");
            eprintln!("swept in {:.0} s", start.elapsed().as_secs_f64());
            if flag("--readme") {
                write_readme_section("sweep", &table).expect("write README.md");
            }
            ExitCode::SUCCESS
        }
        Some("tables") if flag("--derivatives") => {
            fixed_tables::derivatives();
            ExitCode::SUCCESS
        }
        Some("tables") if flag("--explore-fixed") => {
            fixed_tables::explore();
            ExitCode::SUCCESS
        }
        Some("tables") if flag("--explore") => {
            tables::explore();
            ExitCode::SUCCESS
        }
        Some("tables") => tables_task(flag("--check")),
        Some("figures") => figures::run(&root().join("docs"), flag("--check")),
        Some("shapes") => shapes::run(flag("--short"), flag("--csv")),
        Some("bench") => {
            let cpu = args
                .iter()
                .position(|a| a == "--cpu")
                .map(|i| args.get(i + 1).map(String::as_str).unwrap_or(""));
            bench::run(flag("--csv"), flag("--short"), cpu)
        }
        Some("firmware") => firmware::run(flag("--readme")),
        Some("nopanic") => nopanic::run(),
        Some("modbus") => modbus::run(&args[1..]),
        _ => {
            eprint!("{USAGE}");
            ExitCode::from(2)
        }
    }
}

/// `cargo xtask tables [--check]`: writes (or checks) every generated file.
fn tables_task(check: bool) -> ExitCode {
    let mut stale = false;
    for (path, text) in tables::generated() {
        let full = root().join(path);
        if check {
            if std::fs::read_to_string(&full).ok().as_deref() == Some(text.as_str()) {
                println!("{path} matches the reference");
            } else {
                eprintln!("{path} differs from the reference: run `cargo xtask tables`");
                stale = true;
            }
        } else {
            std::fs::write(&full, text).unwrap_or_else(|e| panic!("write {path}: {e}"));
            println!("wrote {path}");
        }
    }
    if stale {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}

/// Writes `section` between the markers `<!-- {name}:begin -->` and
/// `<!-- {name}:end -->` of README.md.
pub fn write_readme_section(name: &str, section: &str) -> Result<(), String> {
    let path = root().join("README.md");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("README.md: {e}"))?;
    let (begin, end) = (
        format!("<!-- {name}:begin -->"),
        format!("<!-- {name}:end -->"),
    );
    let (Some(a), Some(b)) = (text.find(&begin), text.find(&end)) else {
        return Err(format!("README.md has no {name} markers"));
    };
    let new = format!("{}{begin}\n{section}{}", &text[..a], &text[b..]);
    std::fs::write(&path, new).map_err(|e| format!("README.md: {e}"))
}

#[cfg(test)]
mod tests {
    /// The committed tables and firmware trace are exactly what the reference generates
    /// today: any change to the reference or the fit that moves a coefficient or an
    /// expected answer fails here.
    #[test]
    fn committed_generated_files_match_the_reference() {
        for (path, text) in super::tables::generated() {
            let committed = std::fs::read_to_string(super::root().join(path)).unwrap();
            assert!(
                committed == text,
                "{path} drifted from the reference: run `cargo xtask tables`"
            );
        }
    }
}
