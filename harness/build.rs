//! The memory layout of every Cortex-M image that depends on this crate: the
//! measurement images here, and the root package's firmware example and on-target
//! tests (through their dev-dependency on this crate). Writes into OUT_DIR, which it
//! puts on the linker's search path of every dependent:
//!
//! - `misalign-memory.x`: the file named by the environment variable
//!   `MISALIGN_MEMORY_X` (a linker script with a MEMORY command, absolute or relative
//!   to the repository root), or else the QEMU board of the target:
//!   `boards/microbit.x` for thumbv6m (Cortex-M0), `boards/mps2-an386.x` for every
//!   other target (paths in this crate);
//! - `memory.x`, which includes it, for cortex-m-rt's `link.x`. (The root package's
//!   own `memory.x` includes the same file; a layout cannot simply be a `memory.x`
//!   on the search path, since the linker looks in its current directory first.)
//!
//! On the host it does nothing. The library `misalign` has no build script.

use std::path::{Path, PathBuf};

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=MISALIGN_MEMORY_X");
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("none") {
        return;
    }
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR"));
    let here = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("manifest dir"));
    let layout = chosen_layout(&here);
    println!("cargo:rerun-if-changed={}", layout.display());
    let text = std::fs::read_to_string(&layout).unwrap_or_else(|e| {
        panic!(
            "MISALIGN_MEMORY_X: cannot read the memory layout {}: {e}",
            layout.display()
        )
    });
    write(
        &out,
        "misalign-memory.x",
        &format!(
            "/* Written by harness/build.rs from {} */\n{text}",
            layout.display()
        ),
    );
    write(&out, "memory.x", "INCLUDE misalign-memory.x\n");
    println!("cargo:rustc-link-search={}", out.display());
}

/// `MISALIGN_MEMORY_X` (relative to the repository root), or the target's QEMU board.
fn chosen_layout(here: &Path) -> PathBuf {
    let target = std::env::var("TARGET").unwrap_or_default();
    match std::env::var_os("MISALIGN_MEMORY_X") {
        Some(path) if !path.is_empty() => here.join("..").join(path),
        _ if target.starts_with("thumbv6m") => here.join("boards/microbit.x"),
        _ => here.join("boards/mps2-an386.x"),
    }
}

fn write(dir: &Path, name: &str, text: &str) {
    std::fs::write(dir.join(name), text).unwrap_or_else(|e| panic!("write {name}: {e}"));
}
