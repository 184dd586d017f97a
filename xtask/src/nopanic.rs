//! `cargo xtask nopanic`: the compiler's proof that the estimator cannot panic.
//!
//! `examples/nopanic` holds every per-sample path of the estimator and the scene
//! preparation, with panic-never as its panic handler: a handler that calls a symbol
//! which does not exist. The image links only if optimisation (profile `firmware`:
//! release, fat LTO) removed every call to it, i.e. every panic path. Built for each
//! Cortex-M class; run in QEMU where it is installed. `examples/nopanic/canary.rs`
//! has a panic path on purpose and must fail to link with panic-never's message,
//! or the proof proves nothing in this setup.

use crate::cross;
use std::process::ExitCode;

const TARGETS: [(&str, &str); 3] = [
    ("thumbv7em-none-eabihf", "mps2-an386"),
    ("thumbv7m-none-eabi", "mps2-an385"),
    ("thumbv6m-none-eabi", "microbit"),
];

/// What panic-never's undefined symbol says in the linker's error.
const PANIC_NEVER: &str = "error(panic-never)";

pub fn run() -> ExitCode {
    let qemu = cross::have("qemu-system-arm");
    let mut failed = false;
    for (target, machine) in TARGETS {
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
        match cross::build(&mut image(target, "nopanic_canary")) {
            Err(e) if e.contains(PANIC_NEVER) => {
                println!("{target}: the canary (a panic on purpose) fails to link, as it must")
            }
            Err(e) => {
                failed = true;
                eprintln!("{target}: the canary failed for another reason:\n{e}");
            }
            Ok(_) => {
                failed = true;
                eprintln!("{target}: the canary LINKS: panic-never proves nothing in this build");
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

fn image(target: &str, example: &str) -> std::process::Command {
    let mut cmd = cross::cargo();
    cmd.args([
        "build",
        "--profile",
        "firmware",
        "--target",
        target,
        "--features",
        "firmware",
    ])
    .args([
        "--example",
        example,
        "--message-format=json-render-diagnostics",
    ]);
    cmd
}
