//! The repository tracks sources, never what a build, a test run or a documented
//! command writes: `.gitignore` names every such output, and no tracked file matches it.

use std::process::Command;

/// `git args...` from the repository's root: its stdout, or why it failed.
fn git(args: &[&str]) -> Result<String, String> {
    let out = Command::new("git")
        .args(args)
        .current_dir(crate::root())
        .output()
        .map_err(|e| format!("cannot run git: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "git {}: {}",
            args.join(" "),
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// Tracked files that `.gitignore` says are outputs (a cache, a build, data a command
/// wrote).
fn tracked_outputs() -> Result<Vec<String>, String> {
    Ok(
        git(&["ls-files", "--cached", "--ignored", "--exclude-standard"])?
            .lines()
            .map(str::to_string)
            .collect(),
    )
}

/// What the repository's own commands write inside a clone, one example path of each
/// kind: Python's byte code (pytest over tests/modbus and tools/python), pytest's cache,
/// the synthetic fleet (`tools/python/examples/make_fleet.py`'s default `--out`, from
/// the root as docs/python.md runs it), cargo's and npm's outputs, a virtual environment.
const OUTPUTS: [&str; 8] = [
    "tests/modbus/__pycache__/test_config.cpython-311.pyc",
    "tools/python/misalign/__pycache__/fleet.cpython-311.pyc",
    "tests/modbus/.pytest_cache/v/cache/nodeids",
    "fleet-data/roller-00.parquet",
    "target/release/examples/monitor",
    "lab/fuzz/target/debug/build",
    "tools/web/node_modules/vite/package.json",
    ".venv/bin/python",
];

#[cfg(test)]
mod tests {
    use super::*;

    /// Nothing a command writes is committed (a `__pycache__` was, once).
    #[test]
    fn no_tracked_file_is_an_output() {
        assert_eq!(
            tracked_outputs().unwrap(),
            Vec::<String>::new(),
            "tracked files that .gitignore names as outputs: `git rm --cached` them"
        );
    }

    /// Every kind of output the repository's commands write is ignored, so that it
    /// cannot be committed by accident (`git add -A` after a run).
    #[test]
    fn every_output_kind_is_ignored() {
        let unignored: Vec<&str> = OUTPUTS
            .iter()
            .copied()
            .filter(|path| git(&["check-ignore", "--quiet", "--no-index", path]).is_err())
            .collect();
        assert_eq!(
            unignored,
            Vec::<&str>::new(),
            "outputs .gitignore does not name"
        );
    }
}
