//! The estimator on a microcontroller: a `no_std`, `no_main` Cortex-M application
//! (cortex-m-rt) that prepares the demo scene (two printing-press rollers), runs the
//! estimator over a built-in trace of samples (`trace.rs`: elliptic and line contact,
//! partial and gross slip, the edge cases), logs every answer through defmt and checks
//! it against the f64 reference, evaluated on the host at build time (build.rs), to a
//! relative 2e-6. It also measures, per contact model, the deepest stack use of the
//! per-sample call (stack painting) and its instruction count (SysTick under QEMU's
//! `-icount`), and prints them on a `result` line that `cargo xtask firmware` reads.
//!
//! Exit status (semihosting): 0 when every answer matches, 1 on a mismatch, 2 when the
//! scene cannot be prepared, 101 on a panic.
//!
//! ```sh
//! cargo fw                                        # Cortex-M4F in QEMU (mps2-an386)
//! MISALIGN_QEMU_MACHINE=mps2-an500 cargo fw       # the same image on a Cortex-M7
//! cargo run --release --target thumbv6m-none-eabi --features firmware --example firmware
//! ```
//!
//! On the host it builds as a stub, so that `cargo build --all-features` keeps working.
#![cfg_attr(target_os = "none", no_std)]
#![cfg_attr(target_os = "none", no_main)]

#[cfg(target_os = "none")]
mod app;
#[cfg(target_os = "none")]
#[path = "../support/mod.rs"]
mod support;
#[cfg(target_os = "none")]
mod trace;

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("the firmware example runs on a Cortex-M: `cargo fw` runs it in QEMU (README)");
    std::process::exit(2);
}
