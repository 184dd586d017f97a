//! `cargo xtask fuzz [--seconds N | --runs N]`: every fuzz target under lab/fuzz/ (libFuzzer through
//! cargo-fuzz, which needs a nightly toolchain) for a bounded time each. A crash stops
//! with a non-zero status and leaves the input under lab/fuzz/artifacts/: turn it into a
//! test in tests/fuzz_regressions.rs. Each target starts from its seed inputs in
//! lab/fuzz/seeds/<target>/ (committed: realistic scenes and the crafted corner cases of
//! past defects, written by lab/fuzz/seeds/make.py) and its growing corpus in
//! lab/fuzz/corpus/<target>/ (not committed).

use crate::tools::{have, install};
use std::path::Path;
use std::process::Command;

/// The targets, as named in lab/fuzz/Cargo.toml.
pub const TARGETS: [&str; 5] = [
    "estimator_csv",
    "reference",
    "float_core",
    "fixed_core",
    "modbus",
];

/// How long each target runs.
pub enum Budget {
    /// Wall-clock seconds (exploration; differs from run to run).
    Seconds(u32),
    /// A fixed number of inputs from a fixed seed: the same inputs on every machine, so
    /// that CI's pass is repeatable.
    Runs(u64),
}

/// Runs the targets; Err with a message on a crash or a missing tool.
pub fn run(root: &Path, budget: Budget) -> Result<(), String> {
    if !have("cargo", &["+nightly", "--version"]) {
        return Err(
            "cargo-fuzz needs a nightly toolchain (`rustup toolchain install nightly`)".into(),
        );
    }
    if !have("cargo", &["+nightly", "fuzz", "--version"]) {
        // About 2.5 minutes.
        install("cargo-fuzz", None)?;
    }
    let limits: Vec<String> = match budget {
        Budget::Seconds(s) => vec![format!("-max_total_time={s}")],
        Budget::Runs(n) => vec![format!("-runs={n}"), "-seed=1".into()],
    };
    for target in TARGETS {
        eprintln!("fuzzing {target}: {}", limits.join(" "));
        // libFuzzer writes new inputs to the first directory and reads them all.
        let corpus = root.join("lab/fuzz/corpus").join(target);
        std::fs::create_dir_all(&corpus).map_err(|e| format!("{}: {e}", corpus.display()))?;
        let seeds = root.join("lab/fuzz/seeds").join(target);
        let status = Command::new("cargo")
            .current_dir(root)
            .args(["+nightly", "fuzz", "run", "--fuzz-dir", "lab/fuzz", target])
            .arg(&corpus)
            .args(seeds.is_dir().then_some(&seeds))
            .arg("--")
            .args(&limits)
            .status()
            .map_err(|e| e.to_string())?;
        if !status.success() {
            return Err(format!(
                "fuzz target {target} failed: see lab/fuzz/artifacts/{target}/"
            ));
        }
    }
    Ok(())
}
