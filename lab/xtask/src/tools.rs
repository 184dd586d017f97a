//! Finding the tools the chores run, and installing the ones cargo can install: QEMU,
//! defmt-print, the toolchain's LLVM tools, cargo-fuzz.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// defmt-print, pinned to the defmt wire format of the defmt in Cargo.lock (1.x).
pub const DEFMT_PRINT_VERSION: &str = "1.2.0";

/// Whether `program args...` runs and succeeds (`--version` and the like).
pub fn have(program: &str, args: &[&str]) -> bool {
    Command::new(program)
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// `cargo install --locked <krate> [--version <version>]`, its output on stderr (the
/// chores that print a CSV keep stdout for it).
pub fn install(krate: &str, version: Option<&str>) -> Result<(), String> {
    eprintln!("installing {krate}: cargo install --locked {krate}");
    let mut cmd = Command::new(std::env::var_os("CARGO").unwrap_or("cargo".into()));
    cmd.args(["install", "--locked", krate]);
    if let Some(v) = version {
        cmd.args(["--version", v]);
    }
    let status = cmd
        .stdout(std::io::stderr())
        .status()
        .map_err(|e| format!("cannot run cargo install: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("cargo install {krate} failed"))
    }
}

/// What the firmware chores need: QEMU and defmt-print (installed here if missing,
/// pinned).
pub fn preflight() -> Result<(), String> {
    if !have("qemu-system-arm", &["--version"]) {
        return Err("qemu-system-arm not found: apt-get install -y qemu-system-arm".into());
    }
    if !have("defmt-print", &["--version"]) {
        install("defmt-print", Some(DEFMT_PRINT_VERSION))?;
        if !have("defmt-print", &["--version"]) {
            return Err("defmt-print installed but not found (is ~/.cargo/bin on PATH?)".into());
        }
    }
    Ok(())
}

/// defmt-print (installed here if missing, pinned): what the Pico's harness decodes
/// the node's log with.
pub fn preflight_defmt() -> Result<(), String> {
    if !have("defmt-print", &["--version"]) {
        install("defmt-print", Some(DEFMT_PRINT_VERSION))?;
    }
    Ok(())
}

/// An LLVM tool of the toolchain (`rustup component add llvm-tools`).
pub fn llvm_tool(name: &str) -> Result<PathBuf, String> {
    let rustc = |arg: &str| -> Result<String, String> {
        let out = Command::new(std::env::var_os("RUSTC").unwrap_or_else(|| "rustc".into()))
            .arg(arg)
            .output()
            .map_err(|e| format!("cannot run rustc: {e}"))?;
        Ok(String::from_utf8_lossy(&out.stdout).into_owned())
    };
    let sysroot = rustc("--print=sysroot")?;
    let version = rustc("-vV")?;
    let host = version
        .lines()
        .find_map(|l| l.strip_prefix("host: "))
        .ok_or("rustc -vV names no host")?;
    let path = Path::new(sysroot.trim())
        .join("lib/rustlib")
        .join(host)
        .join("bin")
        .join(name);
    if path.exists() {
        Ok(path)
    } else {
        Err(format!(
            "{} not found: rustup component add llvm-tools",
            path.display()
        ))
    }
}
