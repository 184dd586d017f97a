//! `cargo xtask firmware`: builds every firmware image and on-target test, runs them in
//! QEMU, prints the size and stack table and holds the estimator to its budget.
//!
//! Measured, per core (profile `firmware`: release with fat LTO, one codegen unit):
//!
//! - image flash and RAM of the minimal images (`lab/harness/src/bin/minimal_*.rs`): flash is
//!   .vector_table + .text + .rodata + .data, RAM the statics (.data + .bss + .uninit)
//!   as llvm-size counts them; the stack comes on top;
//! - **estimator flash** (budgeted): `minimal_<model>` minus `minimal_<model>_prepare`,
//!   two images that differ only in the per-sample `estimate` call: its code, the
//!   kernels it inlines and calls (soft-float routines included where the core has no
//!   FPU) and its tables;
//! - preparation flash (reported): `minimal_<model>_prepare` minus `minimal_base`, the
//!   one-off `Scene::new` + `*Scene::new` (f64, soft on every Cortex-M here);
//! - **estimator stack** (budgeted): the deepest stack use of one per-sample call over
//!   the firmware's trace, by stack painting on the target (`nodes/firmware`);
//! - instructions per sample (reported): SysTick under QEMU's `-icount`;
//! - **build-time scenes** (reported, rows `<model>, build-time scene`): the minimal
//!   images `minimal_<model>_const`, which load the demo scene's bytes prepared on the
//!   host (lab/harness/build.rs) instead of preparing it: their *preparation* is loading the
//!   bytes (`minimal_<model>_const` minus the estimator flash and `minimal_base`);
//! - **the monitoring node** (row `node`, reported against [`NODE_FLASH_TARGET`] and
//!   [`NODE_RAM_TARGET`]): `minimal_node` (monitor, estimator on a build-time scene,
//!   event log, defmt), profile `node` (opt-level "s"); its RAM is statics plus the
//!   stack it measured.

use crate::cross::{self, Artifacts, CPUS, Cpu, Sections};
use crate::log::Fields;
use crate::measurements::firmware::{FLASH_BUDGET, NODE_MODEL, STACK_BUDGET, node_table, table};
use crate::records::{self, NodeRow, SizeRow};
use crate::{node, tools};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

const MODELS: [&str; 2] = ["elliptic", "line"];
const MINIMAL: [&str; 7] = [
    "minimal_base",
    "minimal_elliptic_prepare",
    "minimal_elliptic",
    "minimal_line_prepare",
    "minimal_line",
    "minimal_elliptic_const",
    "minimal_line_const",
];
/// The monitoring node image (profile `node`).
const NODE: &str = "minimal_node";

/// The monitoring node through the simulated sensors runs on these cores (their
/// targets are built with them): the FPU core, and the Cortex-M0 with its 16 KiB of RAM.
const SENSORS_CPUS: [&str; 2] = ["cortex-m4f", "cortex-m0"];

/// The RAM of the board a core's image is linked for (lab/harness/boards/): the node's
/// statics and stack must fit it.
fn board_ram(core: &Cpu) -> u64 {
    if core.machine == "microbit" {
        16 * 1024
    } else {
        4 * 1024 * 1024
    }
}

/// Checks the node's log on `core` against the host replay (`node.rs`) and measures
/// its image; a row for the node table, or failures.
fn node_check(
    core: &Cpu,
    elf: &Path,
    log: &str,
    sensors: bool,
    llvm_size: &Path,
    failures: &mut Vec<String>,
    nodes: &mut Vec<NodeRow>,
) {
    let what = if sensors {
        "node with simulated sensors"
    } else {
        "node"
    };
    let fpu = core.has_fpu();
    let checked = (|| -> Result<NodeRow, String> {
        let got = node::parse_log(log)?;
        let measured = node::parse_measured(log)?;
        let host = node::host_replay(fpu, sensors)?;
        let tol = node::tolerance(fpu);
        let c = node::compare(&got, &host, tol);
        if !c.mismatches.is_empty() {
            return Err(format!(
                "events differ from the host replay:\n  {}",
                c.mismatches.join("\n  ")
            ));
        }
        println!(
            "  {what}: {} samples, {} events, the host replay's (same states, order and times; \
             values within {tol:e}, at most {:.2} of it); stack {} B, instructions per sample \
             {} mean / {} max",
            measured.samples,
            got.events.len(),
            c.worst,
            measured.stack,
            measured.instructions_mean,
            measured.instructions_max
        );
        let sections = Sections::of(llvm_size, elf)?;
        Ok(NodeRow {
            core: core.name.into(),
            number: if fpu { "f32" } else { "fixed" }.into(),
            input: if sensors {
                "simulated sensors"
            } else {
                "scenario"
            }
            .into(),
            flash: sections.flash(),
            ram: sections.ram(),
            stack: measured.stack,
            board_ram: board_ram(core),
            samples: measured.samples,
            events: measured.events,
            worst: records::rounded(c.worst),
            instructions_mean: measured.instructions_mean,
            instructions_max: measured.instructions_max,
        })
    })();
    match checked {
        Ok(row) => nodes.push(row),
        Err(e) => failures.push(format!("{} {what}: {e}", core.name)),
    }
}

/// One row of the firmware's `result model=... stack_bytes=...` line.
#[derive(Default, Clone)]
struct Run {
    worst_relative_error: f64,
    stack: u64,
    instructions_mean: u64,
    instructions_max: u64,
}

/// `write`: also write docs/firmware.csv and docs/node.csv, and the tables drawn from
/// them (docs/measurements.md), when everything passed.
pub fn run(write: bool) -> ExitCode {
    let start = Instant::now();
    let llvm_size = match tools::preflight().and_then(|()| tools::llvm_tool("llvm-size")) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("firmware: {e}");
            return ExitCode::FAILURE;
        }
    };
    let mut failures: Vec<String> = Vec::new();
    let mut rows = Vec::new();
    let mut built: Vec<Built> = Vec::new();
    let mut nodes = Vec::new();
    // The Cortex-M4F first: the table starts with the FPU core.
    for core in CPUS.iter().rev() {
        step(
            start,
            &format!("{} ({}, QEMU {})", core.name, core.target, core.machine),
        );
        // Build once per target.
        if !built.iter().any(|b| b.target == core.target) {
            match build_target(core.target) {
                Ok(b) => built.push(b),
                Err(e) => {
                    failures.push(format!("{}: build failed:\n{e}", core.target));
                    continue;
                }
            }
        }
        let b = built.iter().find(|b| b.target == core.target).unwrap();
        rows.extend(check_core(core, b, &llvm_size, &mut failures, &mut nodes));
    }
    check_commands(start, &llvm_size, &mut failures);
    let (table, over) = table(&rows);
    let (node_table, node_over) = node_table(&nodes);
    println!(
        "\nEstimator on Cortex-M (profile `firmware`, bytes; budget per sample: \
         {FLASH_BUDGET} B flash, {STACK_BUDGET} B stack)\n\n{table}\n\
         The monitoring node (`nodes/firmware`):\n\n{node_table}"
    );
    failures.extend(over);
    failures.extend(node_over);
    if write && failures.is_empty() {
        let written = records::write(&rows)
            .and_then(|()| records::write(&nodes))
            .and_then(|()| crate::measurements::update());
        if let Err(e) = written {
            failures.push(e);
        }
    }
    step(start, "done");
    report(&failures)
}

/// On one core: the firmware (every answer checked, stack and instructions measured),
/// the on-target tests, and the minimal images (they run; their sizes) where the core
/// measures them. Returns the core's rows of the size table.
fn check_core(
    core: &Cpu,
    built: &Built,
    llvm_size: &Path,
    failures: &mut Vec<String>,
    nodes: &mut Vec<NodeRow>,
) -> Vec<SizeRow> {
    let runs = match run_firmware(core, &built.firmware) {
        Ok((runs, log)) => {
            node_check(
                core,
                &built.firmware,
                &log,
                false,
                llvm_size,
                failures,
                nodes,
            );
            runs
        }
        Err(e) => {
            failures.push(format!("{} firmware: {e}", core.name));
            Vec::new()
        }
    };
    if let Some(elf) = built
        .firmware_sensors
        .as_ref()
        .filter(|_| SENSORS_CPUS.contains(&core.id))
    {
        match cross::qemu(core.machine, elf) {
            Ok((Some(0), log)) => node_check(core, elf, &log, true, llvm_size, failures, nodes),
            Ok((status, log)) => failures.push(format!(
                "{} node with simulated sensors: exit {status:?}:\n{log}",
                core.name
            )),
            Err(e) => failures.push(format!("{} node with simulated sensors: {e}", core.name)),
        }
    }
    match cross::qemu(core.machine, &built.test) {
        Ok((Some(0), log)) if log.contains("all tests passed!") => {
            let n = log.lines().filter(|l| l.contains(") running `")).count();
            println!("  on-target tests: {n} passed");
        }
        Ok((status, log)) => failures.push(format!(
            "{} on-target tests failed (exit {status:?}):\n{log}",
            core.name
        )),
        Err(e) => failures.push(format!("{} on-target tests: {e}", core.name)),
    }
    if !core.sizes {
        return Vec::new();
    }
    let mut rows = sizes(core, &built.harness, llvm_size, &runs).unwrap_or_else(|e| {
        failures.push(format!("{} sizes: {e}", core.name));
        Vec::new()
    });
    match node_row(core, &built.node, llvm_size) {
        Ok(row) => rows.push(row),
        Err(e) => failures.push(format!("{} node: {e}", core.name)),
    }
    rows
}

/// The README's command (`cargo fw`) and the real board's build.
fn check_commands(start: Instant, llvm_size: &Path, failures: &mut Vec<String>) {
    step(start, "the README's command: cargo fw");
    match fw_alias() {
        Ok(()) => println!("  cargo fw: exit 0"),
        Err(e) => failures.push(format!("cargo fw: {e}")),
    }
    step(
        start,
        "a real board's layout: MISALIGN_MEMORY_X=lab/harness/boards/stm32f4.x, --features rtt",
    );
    match board(llvm_size) {
        Ok(line) => println!("  {line}"),
        Err(e) => failures.push(format!("board build: {e}")),
    }
}

/// Success if nothing failed, else every failure on stderr.
fn report(failures: &[String]) -> ExitCode {
    if failures.is_empty() {
        println!("firmware: every image and on-target test passed, within budget");
        return ExitCode::SUCCESS;
    }
    for f in failures {
        eprintln!("\nFAILED: {f}");
    }
    eprintln!("\nfirmware: {} failure(s)", failures.len());
    ExitCode::FAILURE
}

fn step(start: Instant, what: &str) {
    println!("\n=== {what} ({}s)", start.elapsed().as_secs());
}

/// What one target's builds made.
struct Built {
    target: &'static str,
    /// The firmware example (profile `firmware`).
    firmware: PathBuf,
    /// The same with the simulated sensors (`--features sim-sensors`), on the targets
    /// of [`SENSORS_CPUS`].
    firmware_sensors: Option<PathBuf>,
    /// The harness's minimal images (profile `firmware`).
    harness: Artifacts,
    /// The monitoring node image (profile `node`).
    node: PathBuf,
    /// The on-target test (profile `test`).
    test: PathBuf,
}

/// Builds the firmware example, the minimal images and the on-target test for `target`.
fn build_target(target: &'static str) -> Result<Built, String> {
    // First the node through the simulated sensors, kept under its own name: the
    // plain build that follows writes the same file.
    let sensors = CPUS
        .iter()
        .any(|c| c.target == target && SENSORS_CPUS.contains(&c.id));
    let firmware_sensors = if sensors {
        let elf = build_firmware(target, "sim-sensors")?;
        let kept = elf.with_file_name("firmware-sensors");
        std::fs::copy(&elf, &kept).map_err(|e| format!("{}: {e}", kept.display()))?;
        Some(kept)
    } else {
        None
    };
    let firmware = build_firmware(target, "firmware")?;
    let mut minimal = cross::harness_build(target);
    for m in MINIMAL {
        minimal.args(["--bin", m]);
    }
    let harness = cross::build(&mut minimal)?;
    let node = cross::build(cross::harness_build_with(target, "node").args(["--bin", NODE]))?;
    let tests = cross::build(cross::cargo().args([
        "test",
        "--no-run",
        "--target",
        target,
        "--features",
        "firmware",
        "--test",
        "on_target",
        "--message-format=json-render-diagnostics",
    ]))?;
    Ok(Built {
        target,
        firmware,
        firmware_sensors,
        harness,
        node: cross::artifact(&node, NODE)?,
        test: cross::artifact(&tests, "on_target")?,
    })
}

/// The firmware example for `target` with `features` (profile `firmware`): its ELF.
fn build_firmware(target: &str, features: &str) -> Result<PathBuf, String> {
    let built = cross::build(cross::cargo().args([
        "build",
        "--profile",
        "firmware",
        "--target",
        target,
        "--features",
        features,
        "--example",
        "firmware",
        "--message-format=json-render-diagnostics",
    ]))?;
    cross::artifact(&built, "firmware")
}

/// Runs the firmware on `core`: exit 0 and one `result` line per contact model; the
/// results and the whole log.
fn run_firmware(core: &Cpu, elf: &Path) -> Result<(Vec<(String, Run)>, String), String> {
    let (status, log) = cross::qemu(core.machine, elf)?;
    let results: Vec<(String, Run)> = Fields::all(&log, "result model=")
        .filter_map(parse_result)
        .collect();
    if status != Some(0) || results.len() != MODELS.len() {
        return Err(format!(
            "exit {status:?}, {} result lines:\n{log}",
            results.len()
        ));
    }
    cores_named(&log)?;
    for (model, r) in &results {
        println!(
            "  firmware self-test {model}: answers match the reference (worst relative error {:.1e}); \
             stack {} B, instructions {} mean / {} max",
            r.worst_relative_error, r.stack, r.instructions_mean, r.instructions_max
        );
    }
    Ok((results, log))
}

/// The log says which core ran: the core the self-test's first line names
/// (`self-test: demo scene, ..., fixed core; ...`) and the node's (`node: monitoring ...,
/// fixed core, ...`) are the one every `result` line reports (`core=fixed`).
fn cores_named(log: &str) -> Result<(), String> {
    let named = |start: &str| -> Result<&str, String> {
        let line = log
            .lines()
            .find(|l| l.starts_with(start))
            .ok_or_else(|| format!("no `{start}` line in the log"))?;
        line.split([',', ';'])
            .find_map(|part| part.trim().strip_suffix(" core"))
            .ok_or_else(|| format!("`{line}` names no core"))
    };
    let ran: Vec<&str> = Fields::all(log, "result model=")
        .filter_map(|f| f.get("core").ok())
        .collect();
    for start in ["self-test: demo scene", "node: monitoring"] {
        let name = named(start)?;
        if let Some(other) = ran.iter().find(|&&c| c != name) {
            return Err(format!(
                "the log's `{start}` line names the {name} core, the self-test ran the {other} core"
            ));
        }
    }
    Ok(())
}

/// `result model=elliptic core=f32 samples=36 failures=0 worst_relative_error=... stack_bytes=...`.
fn parse_result(f: Fields) -> Option<(String, Run)> {
    Some((
        f.get("model").ok()?.to_string(),
        Run {
            worst_relative_error: f.num("worst_relative_error").ok()?,
            stack: f.num("stack_bytes").ok()?,
            instructions_mean: f.num("instructions_mean").ok()?,
            instructions_max: f.num("instructions_max").ok()?,
        },
    ))
}

/// Runs the minimal images (each must exit 0) and measures them.
fn sizes(
    core: &Cpu,
    images: &Artifacts,
    llvm_size: &Path,
    runs: &[(String, Run)],
) -> Result<Vec<SizeRow>, String> {
    let mut measured = Vec::new();
    for name in MINIMAL {
        let elf = cross::artifact(images, name)?;
        match cross::qemu(core.machine, &elf)? {
            (Some(0), _) => {}
            (status, log) => return Err(format!("{name} exited {status:?}:\n{log}")),
        }
        measured.push((name, Sections::of(llvm_size, &elf)?));
    }
    let get = |name: &str| &measured.iter().find(|(n, _)| *n == name).unwrap().1;
    let base = get("minimal_base").flash();
    let run = |model: &str| {
        runs.iter()
            .find(|(m, _)| m == model)
            .map(|(_, r)| r.clone())
            .unwrap_or_default()
    };
    let number = if core.has_fpu() { "f32" } else { "fixed" };
    let row = |model: &str, image: &Sections, estimator: u64, preparation: u64, run: Run| SizeRow {
        core: core.name.into(),
        number: number.into(),
        model: model.into(),
        image_flash: image.flash(),
        image_ram: image.ram(),
        estimator_flash: estimator,
        preparation_flash: preparation,
        stack: run.stack,
        instructions_mean: run.instructions_mean,
        instructions_max: run.instructions_max,
    };
    let mut rows = Vec::new();
    for model in MODELS {
        let full = get(&format!("minimal_{model}"));
        let prepare = get(&format!("minimal_{model}_prepare"));
        let estimator = full.flash().saturating_sub(prepare.flash());
        let preparation = prepare.flash().saturating_sub(base);
        rows.push(row(model, full, estimator, preparation, run(model)));
    }
    // The same estimators on the build-time scene: loading bytes instead of preparing.
    for (i, model) in MODELS.into_iter().enumerate() {
        let constant = get(&format!("minimal_{model}_const"));
        let estimator = rows[i].estimator_flash;
        let loading = constant.flash().saturating_sub(estimator + base);
        let name = format!("{model}, build-time scene");
        rows.push(row(&name, constant, estimator, loading, run(model)));
    }
    Ok(rows)
}

/// The monitoring node (`minimal_node`): runs it (exit 0, its `node ...` line) and
/// measures it; RAM is statics plus the stack it measured.
fn node_row(core: &Cpu, elf: &Path, llvm_size: &Path) -> Result<SizeRow, String> {
    let (status, log) = cross::qemu(core.machine, elf)?;
    let stack = Fields::all(&log, "stack_bytes=").find_map(|f| f.num::<u64>("stack_bytes").ok());
    let (Some(0), Some(stack)) = (status, stack) else {
        return Err(format!("{NODE} exit {status:?}:\n{log}"));
    };
    let events = log.lines().filter(|l| l.contains("Event {")).count();
    let s = Sections::of(llvm_size, elf)?;
    println!(
        "  node: {} B flash, {} B statics + {stack} B stack, {events} events logged",
        s.flash(),
        s.ram()
    );
    Ok(SizeRow {
        core: core.name.into(),
        number: if core.has_fpu() { "f32" } else { "fixed" }.into(),
        model: NODE_MODEL.into(),
        image_flash: s.flash(),
        image_ram: s.ram() + stack,
        estimator_flash: 0,
        preparation_flash: 0,
        stack,
        instructions_mean: 0,
        instructions_max: 0,
    })
}

/// The README's command, through the alias and the runner: `cargo fw`.
fn fw_alias() -> Result<(), String> {
    let out = cross::cargo()
        .arg("fw")
        .env_remove("MISALIGN_QEMU_MACHINE")
        .output()
        .map_err(|e| format!("cannot run cargo fw: {e}"))?;
    if out.status.success() {
        Ok(())
    } else {
        Err(format!(
            "exit {:?}:\n{}{}",
            out.status.code(),
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        ))
    }
}

/// A real board's build without editing the crate: the STM32F4 layout (flash at
/// 0x08000000, 128 KiB RAM) and RTT logging. Checks where the image landed and runs it
/// on QEMU's netduinoplus2 (an STM32F405), where its log is in RTT (unread) and its
/// exit status says whether every answer matched.
fn board(llvm_size: &Path) -> Result<String, String> {
    let built = cross::build(
        cross::cargo()
            .env("MISALIGN_MEMORY_X", "lab/harness/boards/stm32f4.x")
            .args(["build", "--release", "--target", "thumbv7em-none-eabihf"])
            .args(["--features", "rtt", "--example", "firmware"])
            .arg("--message-format=json-render-diagnostics"),
    )?;
    let elf = cross::artifact(&built, "firmware")?;
    let sections = Sections::of(llvm_size, &elf)?;
    let vectors = sections.addr(".vector_table");
    let ram = sections.addr(".data");
    if vectors != Some(0x0800_0000) || ram != Some(0x2000_0000) {
        return Err(format!(
            "vector table at {vectors:x?}, .data at {ram:x?}: want 0x08000000, 0x20000000"
        ));
    }
    match cross::qemu("netduinoplus2", &elf)? {
        (Some(0), _) => Ok(format!(
            "vector table at 0x08000000, RAM at 0x20000000; {} B of flash; runs on netduinoplus2: exit 0",
            sections.flash()
        )),
        (status, log) => Err(format!("netduinoplus2 exit {status:?}:\n{log}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const RESULT: &str = "result model=elliptic core=fixed samples=36 failures=0";

    #[test]
    fn the_log_must_name_the_core_that_ran() {
        let log = |selftest: &str, node: &str| {
            format!(
                "self-test: demo scene, 36 elliptic and 20 line samples, {selftest} core; SysTick ticks per 1000 instructions 1599\n\
                 {RESULT}\n\
                 node: monitoring the built-in scenario (8 h, one sample a second), {node} core, from the scenario's values\n"
            )
        };
        assert_eq!(cores_named(&log("fixed", "fixed")), Ok(()));
        // The Cortex-M0's log once named the f32 core it does not run.
        assert!(cores_named(&log("f32-soft", "fixed")).is_err());
        assert!(cores_named(&log("fixed", "f32")).is_err());
        assert!(cores_named(RESULT).is_err());
    }
}
