//! What the firmware chores share: the Cortex-M cores, cargo for a Cortex-M target
//! (the harness's images and the root's firmware example), section sizes, QEMU through
//! `lab/qemu-run`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

/// A Cortex-M core the firmware chores run on.
pub struct Cpu {
    /// `cortex-m4f`: the benchmark's name.
    pub id: &'static str,
    /// `Cortex-M4F`: the firmware table's name.
    pub name: &'static str,
    /// The cargo target of its images.
    pub target: &'static str,
    /// The QEMU machine that runs them.
    pub machine: &'static str,
    /// Its images are measured (sizes, budget, no-panic proof): false for the
    /// Cortex-M7, which runs the Cortex-M4F's images.
    pub sizes: bool,
}

impl Cpu {
    /// Whether the target has an FPU (the f32 core runs there, the fixed-point core
    /// elsewhere).
    pub fn has_fpu(&self) -> bool {
        self.target.ends_with("eabihf")
    }
}

/// The cores of every table: Cortex-M0, M3, M4F, M7.
pub const CPUS: [Cpu; 4] = [
    Cpu {
        id: "cortex-m0",
        name: "Cortex-M0",
        target: "thumbv6m-none-eabi",
        machine: "microbit",
        sizes: true,
    },
    Cpu {
        id: "cortex-m3",
        name: "Cortex-M3",
        target: "thumbv7m-none-eabi",
        machine: "mps2-an385",
        sizes: true,
    },
    Cpu {
        id: "cortex-m4f",
        name: "Cortex-M4F",
        target: "thumbv7em-none-eabihf",
        machine: "mps2-an386",
        sizes: true,
    },
    Cpu {
        id: "cortex-m7",
        name: "Cortex-M7",
        target: "thumbv7em-none-eabihf",
        machine: "mps2-an500",
        sizes: false,
    },
];

/// `cargo build` of the harness's images (lab/harness/, its own workspace) for `target`,
/// profile `firmware`, into the root's target directory (`CARGO_TARGET_DIR` if set),
/// with JSON messages for [`build`]; add `--bin` arguments.
pub fn harness_build(target: &str) -> Command {
    harness_build_with(target, "firmware")
}

/// [`harness_build`] with another profile of the harness (`nopanic`: overflow checks).
pub fn harness_build_with(target: &str, profile: &str) -> Command {
    let target_dir = std::env::var_os("CARGO_TARGET_DIR")
        .map_or_else(|| crate::root().join("target"), PathBuf::from);
    let mut cmd = cargo();
    cmd.env("CARGO_TARGET_DIR", target_dir)
        .args(["build", "--manifest-path", "lab/harness/Cargo.toml"])
        .args(["--profile", profile, "--target", target])
        .arg("--message-format=json-render-diagnostics");
    cmd
}

/// `cargo` as the one that runs this xtask, in the repository root. Without
/// `RUSTFLAGS`: cargo would use it instead of the thumb targets' rustflags in
/// .cargo/config.toml, and the images would lose cortex-m-rt's and defmt's linker
/// scripts (no vector table).
pub fn cargo() -> Command {
    let mut cmd = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()));
    cmd.current_dir(crate::root());
    static NOTE: std::sync::Once = std::sync::Once::new();
    for var in ["RUSTFLAGS", "CARGO_ENCODED_RUSTFLAGS"] {
        if std::env::var_os(var).is_some() {
            NOTE.call_once(|| eprintln!("note: {var} is set; not passed to the firmware builds"));
            cmd.env_remove(var);
        }
    }
    cmd
}

/// `(target name, executable)` of every artifact a cargo build made.
pub type Artifacts = Vec<(String, PathBuf)>;

/// Runs `cmd` (a cargo build with `--message-format=json-render-diagnostics`) and
/// returns the artifacts it built; `Err` with the compiler's messages when it fails.
pub fn build(cmd: &mut Command) -> Result<Artifacts, String> {
    let out = cmd
        .stderr(Stdio::piped())
        .stdout(Stdio::piped())
        .output()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    if !out.status.success() {
        return Err(format!(
            "{}\n{}",
            String::from_utf8_lossy(&out.stderr),
            stdout
                .lines()
                .filter(|l| !l.starts_with('{'))
                .collect::<Vec<_>>()
                .join("\n")
        ));
    }
    Ok(stdout
        .lines()
        .filter(|l| l.contains(r#""reason":"compiler-artifact""#))
        .filter_map(|l| {
            let exe = json_str(l, "executable")?;
            let name = json_str(&l[l.find(r#""target":"#)?..], "name")?;
            Some((name, PathBuf::from(exe)))
        })
        .collect())
}

/// The string value of the first `"key":"..."` in `json` (no escapes in our paths).
fn json_str(json: &str, key: &str) -> Option<String> {
    let start = json.find(&format!(r#""{key}":""#))? + key.len() + 4;
    let len = json[start..].find('"')?;
    Some(json[start..start + len].to_string())
}

/// The artifact named `name` among `built`.
pub fn artifact(built: &Artifacts, name: &str) -> Result<PathBuf, String> {
    built
        .iter()
        .find(|(n, _)| n == name)
        .map(|(_, p)| p.clone())
        .ok_or_else(|| format!("cargo built no `{name}`"))
}

/// Section sizes and addresses of an ELF (`llvm-size -A`).
pub struct Sections(Vec<(String, u64, u64)>);

impl Sections {
    pub fn of(llvm_size: &Path, elf: &Path) -> Result<Self, String> {
        let out = Command::new(llvm_size)
            .args(["-A", "-d"])
            .arg(elf)
            .output()
            .map_err(|e| format!("cannot run llvm-size: {e}"))?;
        if !out.status.success() {
            return Err(String::from_utf8_lossy(&out.stderr).into_owned());
        }
        let text = String::from_utf8_lossy(&out.stdout);
        Ok(Sections(
            text.lines()
                .filter_map(|l| {
                    let mut f = l.split_whitespace();
                    let name = f.next()?;
                    let size = f.next()?.parse().ok()?;
                    let addr = f.next()?.parse().ok()?;
                    name.starts_with('.')
                        .then(|| (name.to_string(), size, addr))
                })
                .collect(),
        ))
    }

    fn size(&self, name: &str) -> u64 {
        self.0.iter().filter(|s| s.0 == name).map(|s| s.1).sum()
    }

    pub fn addr(&self, name: &str) -> Option<u64> {
        self.0.iter().find(|s| s.0 == name).map(|s| s.2)
    }

    /// Bytes in flash: vector table, code, read-only data and the initial values of
    /// .data (what llvm-size's Berkeley format counts as text + data).
    pub fn flash(&self) -> u64 {
        [".vector_table", ".text", ".rodata", ".data", ".gnu.sgstubs"]
            .iter()
            .map(|s| self.size(s))
            .sum()
    }

    /// Bytes of RAM taken by statics (.data, .bss, .uninit); the stack comes on top.
    pub fn ram(&self) -> u64 {
        [".data", ".bss", ".uninit"]
            .iter()
            .map(|s| self.size(s))
            .sum()
    }
}

/// Runs `elf` in QEMU's `machine` through `lab/qemu-run` (as cargo's runner does),
/// with its defmt log decoded; returns the exit status and the log.
pub fn qemu(machine: &str, elf: &Path) -> Result<(Option<i32>, String), String> {
    let out: Output = Command::new(crate::root().join("lab/qemu-run"))
        .arg(machine)
        .arg(elf)
        .env("MISALIGN_QEMU_MACHINE", machine)
        .stdin(Stdio::null())
        .output()
        .map_err(|e| format!("cannot run lab/qemu-run: {e}"))?;
    let mut log = String::from_utf8_lossy(&out.stdout).into_owned();
    log.push_str(&String::from_utf8_lossy(&out.stderr));
    Ok((out.status.code(), log))
}
