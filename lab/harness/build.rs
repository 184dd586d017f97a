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
//! - `prepared.rs` (every target, `lab/harness/src/prepared.rs` includes it): the demo
//!   scene [`Scene::DEMO`] prepared here, on the host, as the bytes of
//!   `misalign::prepared` for every scene type, and the fixed-point LSBs of the images:
//!   the build-time scenes of the `_const` and node images, which link no f64
//!   preparation.
//! - `shapes.rs` (every target, the `shapes` image includes it): the file named by
//!   `MISALIGN_SHAPES_TABLES` (the table shapes that `cargo xtask shapes` generated and
//!   weighs), or else a stub without shapes, with which the image measures the
//!   library's kernels only.
//!
//! - the linker's identical code folding (`--icf=all`) for the node images
//!   (`minimal_node`, `modbus_node`, `modbus_flash_node`).
//!
//! Besides that, on the host it does nothing. The library `misalign` has no build
//! script.

use misalign::Scene;
use misalign::fixed::{FixedEllipticScene, FixedLineScene};
use misalign::float::{EllipticScene, LineScene};
use misalign::monitor::{model_for_range, scenario};
use misalign::reference::ModelChoice;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The fixed-point core's LSBs in every image (N and rad per count).
const LOAD_LSB: f64 = 1e-3;
const ANGLE_LSB: f64 = 1e-11;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=MISALIGN_MEMORY_X");
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR"));
    write(&out, "prepared.rs", &prepared());
    write(&out, "shapes.rs", &shapes());
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("none") {
        return;
    }
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
            "/* Written by lab/harness/build.rs from {} */\n{text}",
            layout.display()
        ),
    );
    write(&out, "memory.x", "INCLUDE misalign-memory.x\n");
    println!("cargo:rustc-link-search={}", out.display());
    // The node images: identical functions folded into one by the linker
    // (compiler_builtins' __aeabi_memclr4 and memclr8, memcpy4 and memcpy8 are the same
    // code twice). Nothing in them compares two functions' addresses, the one thing
    // folding changes. The other images keep the link their tables were measured with.
    for node in ["minimal_node", "modbus_node", "modbus_flash_node"] {
        println!("cargo:rustc-link-arg-bin={node}=--icf=all");
    }
}

/// `MISALIGN_MEMORY_X` (relative to the repository root), or the target's QEMU board.
fn chosen_layout(here: &Path) -> PathBuf {
    let target = std::env::var("TARGET").unwrap_or_default();
    match std::env::var_os("MISALIGN_MEMORY_X") {
        Some(path) if !path.is_empty() => here.join("../..").join(path),
        _ if target.starts_with("thumbv6m") => here.join("boards/microbit.x"),
        _ => here.join("boards/mps2-an386.x"),
    }
}

fn write(dir: &Path, name: &str, text: &str) {
    std::fs::write(dir.join(name), text).unwrap_or_else(|e| panic!("write {name}: {e}"));
}

/// The demo scene prepared on the host, as Rust source: the LSBs and one byte array per
/// scene type (`misalign::prepared`'s format).
fn prepared() -> String {
    let scene = Scene::DEMO;
    // The node image runs the model the monitor's rule picks for the scenario's
    // operating range: the ellipse, for which it loads the elliptic scene.
    let choice = model_for_range(&scene, scenario::LOAD_MAX, scenario::ANGLE_MIN)
        .expect("the demo scene has a model for its range");
    assert_eq!(
        choice,
        ModelChoice::Elliptic,
        "the node image expects the ellipse"
    );
    let arrays: [(&str, &str, Vec<u8>); 4] = [
        (
            "FIXED_ELLIPTIC",
            "`fixed::FixedEllipticScene` at the LSBs",
            FixedEllipticScene::new(&scene, LOAD_LSB, ANGLE_LSB)
                .unwrap_or_else(refused)
                .to_bytes()
                .to_vec(),
        ),
        (
            "FIXED_LINE",
            "`fixed::FixedLineScene` at the LSBs",
            FixedLineScene::new(&scene, LOAD_LSB, ANGLE_LSB)
                .unwrap_or_else(refused)
                .to_bytes()
                .to_vec(),
        ),
        (
            "ELLIPTIC",
            "`float::EllipticScene` (its constants; the image names the tables)",
            EllipticScene::new(&scene)
                .unwrap_or_else(refused)
                .to_bytes()
                .to_vec(),
        ),
        (
            "LINE",
            "`float::LineScene`",
            LineScene::new(&scene)
                .unwrap_or_else(refused)
                .to_bytes()
                .to_vec(),
        ),
    ];
    let mut rs = format!(
        "// Written by lab/harness/build.rs: Scene::DEMO prepared on the host.\n\
         /// The fixed-point core's load LSB in the images (N per count).\n\
         pub const LOAD_LSB: f64 = {LOAD_LSB:?};\n\
         /// The fixed-point core's angle LSB in the images (rad per count).\n\
         pub const ANGLE_LSB: f64 = {ANGLE_LSB:?};\n"
    );
    for (name, what, bytes) in arrays {
        writeln!(
            rs,
            "/// Scene::DEMO as {what}, prepared at build time.\n\
             pub static {name}: [u8; {}] = {bytes:?};",
            bytes.len()
        )
        .unwrap();
    }
    rs
}

/// The generated table shapes (`MISALIGN_SHAPES_TABLES`), or the stub.
fn shapes() -> String {
    println!("cargo:rerun-if-env-changed=MISALIGN_SHAPES_TABLES");
    match std::env::var_os("MISALIGN_SHAPES_TABLES") {
        Some(path) if !path.is_empty() => {
            let path = PathBuf::from(path);
            println!("cargo:rerun-if-changed={}", path.display());
            std::fs::read_to_string(&path).unwrap_or_else(|e| {
                panic!(
                    "MISALIGN_SHAPES_TABLES: cannot read {}: {e}",
                    path.display()
                )
            })
        }
        _ => "// Written by lab/harness/build.rs: no MISALIGN_SHAPES_TABLES, no shapes.\n\
              #[cfg(target_abi = \"eabihf\")]\n\
              pub fn f32_shapes(_: &Counter, _: &[f32], _: &[f32]) {}\n\
              #[cfg(not(target_abi = \"eabihf\"))]\n\
              pub fn fixed_shapes(_: &Counter, _: &[i32], _: &[i32]) {}\n"
            .to_string(),
    }
}

fn refused<T>(e: misalign::Error) -> T {
    panic!("Scene::DEMO does not prepare: {e}")
}
