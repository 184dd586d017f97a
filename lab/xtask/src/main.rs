//! Chores for people and CI alike: `cargo xtask <task>` (`cargo xtask help` lists
//! them). A task is a variant of [`Task`] and its arm in [`main`].

mod accuracy;
mod bench;
mod cross;
mod docs;
mod figures;
mod firmware;
mod fit;
mod fixed_tables;
mod fuzz;
mod log;
mod measurements;
mod modbus;
mod node;
mod nopanic;
mod pico;
mod records;
mod seeds;
mod shapes;
mod sweep;
mod tables;
mod tools;
mod trace;
#[cfg(test)]
mod tracked;
mod web;

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "cargo xtask",
    bin_name = "cargo xtask",
    about = "Chores for people and CI alike"
)]
struct Cli {
    #[command(subcommand)]
    task: Task,
}

#[derive(Subcommand)]
enum Task {
    /// Generate src/float/tables.rs, src/fixed/tables.rs and the firmware's trace
    /// (nodes/firmware/trace.rs) from the f64 reference.
    Tables {
        /// Fail if a committed file differs instead of writing it.
        #[arg(long)]
        check: bool,
    },
    /// Every fuzz target for N seconds each (default 60), or N inputs from a fixed seed
    /// (repeatable; CI); needs a nightly toolchain.
    Fuzz {
        /// Wall-clock seconds per target (exploration; differs from run to run).
        #[arg(long, value_name = "N", conflicts_with = "runs")]
        seconds: Option<u32>,
        /// Inputs per target from a fixed seed (the same inputs on every machine).
        #[arg(long, value_name = "N")]
        runs: Option<u64>,
    },
    /// Every one-argument f32 kernel and fixed-point function over every input of its
    /// domain against the reference.
    Sweep {
        /// Stride through the domains (a short pass).
        #[arg(long)]
        quick: bool,
        /// Write docs/sweep.csv and its table in docs/measurements.md.
        #[arg(long, alias = "readme", conflicts_with = "quick")]
        write: bool,
    },
    /// Draw the paper's Figs 1-4 from the reference, and docs/speed-vs-error.svg and
    /// docs/table-shapes.svg from docs/bench.csv and docs/shapes.csv, as SVG in docs/.
    Figures {
        /// Fail if a committed SVG differs instead of writing it.
        #[arg(long)]
        check: bool,
        /// Instead: render every SVG under docs/ and the monitor example's figures in
        /// Chromium, librsvg and ImageMagick and fail where two renderings differ.
        #[arg(long, conflicts_with = "check")]
        renderers: bool,
    },
    /// Speed against error: the benchmark image on the Cortex-M0, M3, M4F, M7 in QEMU
    /// (instructions) and the same code on the host against the reference data
    /// (error); writes docs/bench.csv, docs/speed-vs-error.svg and their tables.
    Bench {
        /// Print the CSV (else a readable table).
        #[arg(long)]
        csv: bool,
        /// Fewer samples; writes nothing.
        #[arg(long)]
        short: bool,
        /// That core only (cortex-m0, cortex-m3, cortex-m4f, cortex-m7); writes nothing.
        #[arg(long, value_name = "ID")]
        cpu: Option<String>,
    },
    /// The table shapes weighed: instructions in QEMU beside the library's kernels,
    /// bytes, and error on the host; writes docs/shapes.csv, docs/table-shapes.svg and
    /// their table.
    Shapes {
        /// Fewer inputs; writes nothing.
        #[arg(long)]
        short: bool,
        /// Print the CSV (else the fronts as a table).
        #[arg(long)]
        csv: bool,
    },
    /// Build every firmware image and on-target test, run them in QEMU (Cortex-M4F, M7,
    /// M3, M0), print the size and stack tables; fail on any failure or over budget.
    Firmware {
        /// Also write docs/firmware.csv, docs/node.csv and their tables.
        #[arg(long, alias = "readme")]
        write: bool,
    },
    /// The worst relative error of every quantity of every model against the
    /// reference data, on the host; writes docs/accuracy.csv and its table.
    Accuracy,
    /// Prove the estimator and the monitor have no panic path (panic-never).
    Nopanic,
    /// Draw every table of docs/measurements.md and the README's headline from the
    /// committed CSVs under docs/.
    Measurements {
        /// Fail if a committed table differs instead of writing it.
        #[arg(long)]
        check: bool,
    },
    /// The Modbus node in QEMU (Cortex-M4F and M0) against pymodbus, every register
    /// compared with the host's replay; or serve, feed a trace, write the register map,
    /// measure the server's cost.
    Modbus(modbus::Args),
    /// Run every block of README.md and the pages under docs/ as a reader would, and
    /// write the text blocks that show a command's output from what it prints.
    Docs(docs::Args),
    /// The Raspberry Pi Pico node in an emulator of its chip (rp2040js, lab/pico), its
    /// sensors simulated at the pins: the checks, --serve, --trace, --uf2, --measure.
    Pico(pico::Args),
    /// The web console (tools/web): build it; or serve it, run its browser tests,
    /// measure its download, start and replay rate.
    Web(web::Args),
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn main() -> ExitCode {
    match Cli::parse().task {
        Task::Tables { check } => tables_task(check),
        Task::Fuzz { seconds, runs } => {
            let budget = match runs {
                Some(n) => fuzz::Budget::Runs(n),
                None => fuzz::Budget::Seconds(seconds.unwrap_or(60)),
            };
            fuzz::run(&root(), budget).map_or_else(
                |e| {
                    eprintln!("xtask fuzz: {e}");
                    ExitCode::FAILURE
                },
                |()| ExitCode::SUCCESS,
            )
        }
        Task::Sweep { quick, write } => sweep_task(quick, write),
        Task::Figures {
            renderers: true, ..
        } => match figures::render::check(&root()) {
            Ok(true) => ExitCode::SUCCESS,
            Ok(false) => ExitCode::FAILURE,
            Err(e) => {
                eprintln!("xtask figures --renderers: {e}");
                ExitCode::FAILURE
            }
        },
        Task::Figures { check, .. } => figures::run(&root().join("docs"), check),
        Task::Bench { csv, short, cpu } => bench::run(csv, short, cpu.as_deref()),
        Task::Shapes { short, csv } => shapes::run(short, csv),
        Task::Firmware { write } => firmware::run(write),
        Task::Accuracy => accuracy::run(),
        Task::Nopanic => nopanic::run(),
        Task::Measurements { check } => measurements::run(check),
        Task::Modbus(args) => modbus::run(&args),
        Task::Docs(args) => docs::run(&args),
        Task::Pico(args) => pico::run(&args),
        Task::Web(args) => web::run(&args),
    }
}

/// `cargo xtask sweep [--quick] [--write]`.
fn sweep_task(quick: bool, write: bool) -> ExitCode {
    let start = std::time::Instant::now();
    let rows = sweep::run(quick);
    print!("{}", measurements::sweep::markdown(&rows, quick));
    eprintln!("swept in {:.0} s", start.elapsed().as_secs_f64());
    if write && let Err(e) = records::write(&rows).and_then(|()| measurements::update()) {
        eprintln!("xtask sweep: {e}");
        return ExitCode::FAILURE;
    }
    ExitCode::SUCCESS
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
