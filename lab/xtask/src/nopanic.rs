//! `cargo xtask nopanic`: the compiler's proof that the estimator cannot panic.
//!
//! `lab/harness/src/bin/nopanic.rs` holds every per-sample path of the estimator and the scene
//! preparation, and the condition monitor on both cores, with panic-never as its panic handler: a handler that calls a symbol
//! which does not exist. The image links only if optimisation (profile `nopanic`: the
//! firmware profile, release with fat LTO, plus overflow checks) removed every call to
//! it, i.e. every panic path, an integer overflow included. Built for each
//! Cortex-M class; run in QEMU where it is installed. `lab/harness/src/bin/nopanic_canary.rs`
//! has a panic path on purpose and must fail to link with panic-never's message,
//! or the proof proves nothing in this setup; `nopanic_overflow_canary.rs` likewise, with an
//! integer overflow as its one panic path, or the proof is blind to overflow.

use crate::cross::{self, CPUS};
use std::process::ExitCode;

/// What panic-never's undefined symbol says in the linker's error.
const PANIC_NEVER: &str = "error(panic-never)";

pub fn run() -> ExitCode {
    let qemu = crate::tools::have("qemu-system-arm", &["--version"]);
    let mut failed = false;
    for cpu in CPUS.iter().filter(|c| c.sizes) {
        let (target, machine) = (cpu.target, cpu.machine);
        let built = cross::build(&mut image(target, "nopanic"));
        match built.and_then(|b| cross::artifact(&b, "nopanic")) {
            Ok(elf) if qemu => match cross::qemu(machine, &elf) {
                Ok((Some(0), _)) => {
                    println!(
                        "{target}: nopanic links (no panic path) and runs on {machine}: exit 0"
                    )
                }
                Ok((status, log)) => {
                    failed = true;
                    eprintln!("{target}: nopanic links but exits {status:?} on {machine}:\n{log}");
                }
                Err(e) => {
                    failed = true;
                    eprintln!("{target}: {e}");
                }
            },
            Ok(_) => println!("{target}: nopanic links (no panic path); not run (no QEMU)"),
            Err(e) => {
                failed = true;
                eprintln!("{target}: nopanic does NOT link: a panic path remains.");
                // The linker names the object and function that reference the handler.
                for line in e.lines().filter(|l| {
                    l.contains("panic-never") || l.contains("referenced by") || l.contains(">>>")
                }) {
                    eprintln!("    {}", line.trim());
                }
                if !e.contains(PANIC_NEVER) {
                    eprintln!("{e}");
                }
            }
        }
        for (canary, what) in [
            ("nopanic_canary", "a panic on purpose"),
            ("nopanic_overflow_canary", "an integer overflow on purpose"),
        ] {
            match cross::build(&mut image(target, canary)) {
                Err(e) if e.contains(PANIC_NEVER) => {
                    println!("{target}: {canary} ({what}) fails to link, as it must")
                }
                Err(e) => {
                    failed = true;
                    eprintln!("{target}: {canary} failed for another reason:\n{e}");
                }
                Ok(_) => {
                    failed = true;
                    eprintln!("{target}: {canary} LINKS: the proof cannot see {what}");
                }
            }
        }
    }
    if failed {
        eprintln!("nopanic: FAILED");
        ExitCode::FAILURE
    } else {
        println!("nopanic: the estimator has no panic path on any Cortex-M target");
        ExitCode::SUCCESS
    }
}

fn image(target: &str, bin: &str) -> std::process::Command {
    let mut cmd = cross::harness_build_with(target, "nopanic");
    cmd.args(["--bin", bin]);
    cmd
}
