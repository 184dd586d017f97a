//! `cargo xtask modbus`: the Modbus node (`nodes/firmware` with the library's
//! feature `modbus`) in QEMU, driven by pymodbus, a client nobody here wrote.
//!
//! - no option: on the Cortex-M4F (f32 core, mps2-an386) and the Cortex-M0
//!   (fixed-point core, microbit), boots the node with serial0 on a loopback TCP port
//!   (`lab/qemu-run`, `MISALIGN_QEMU_SERIAL_PORT`) and runs the pytest tests of
//!   `tests/modbus/` against it: the node on its own samples (the built-in scenario;
//!   every register equal, word for word, to this host's replay of the same samples
//!   through `misalign::modbus::Server`), then the node on a master's samples (every
//!   event read back across the event window's wrap); and on both cores the node with
//!   flash (feature `modbus-flash`: RAM a reset keeps on the Cortex-M4F, the
//!   micro:bit's flash through its NVMC on the Cortex-M0) across a reset through QEMU's
//!   monitor (`tests/modbus/test_reset.py`: the committed configuration and the
//!   unacknowledged events back), and a test build of it through power cuts at points
//!   of a commit, an event push and an acknowledgement (feature `_power-cut`,
//!   `tests/modbus/test_power_cut.py`; `MODBUS_POWER_CUT_ALL=1`: at every point), each
//!   printing the RAM it took (statics, and the deepest stack read through QEMU's
//!   monitor). On
//!   the Cortex-M4F, tools/commission.py also commissions the node over a serial line
//!   (serial0 on a pseudo-terminal, `tests/modbus/test_serial.py`). pymodbus, pyserial
//!   and pytest, pinned, in a virtual environment under `target/modbus-venv`.
//!   With `--boards`, the node on its own samples also on the Cortex-M7 and M3 (MPS2,
//!   CMSDK UART0) and the STM32F405 (`netduinoplus2`, USART1).
//!   Last, every command and snippet of docs/modbus.md as the page shows them
//!   (`tests/modbus/test_docs.py`; `--docs`: that alone).
//! - `--serve PORT [--target TRIPLE]`: boots the node and serves until killed.
//! - `--trace T.csv --scene S.csv --events OUT.csv [--model f32|fixed] [--target
//!   TRIPLE]`: feeds a trace to the node over Modbus, reads its events back, writes
//!   them as `examples/monitor --events` does and compares them with the host replay.
//!   Before the trace, the node is commissioned over the bus (tools/commission.py:
//!   unlock, the scene prepared for its core and the default configuration, commit,
//!   read back), so any scene goes; the host replays through the same prepared scene.
//! - `--default-config C.csv`: writes the default configuration as
//!   tools/commission.py's `--config` file.
//! - `--registers`: writes `docs/modbus/registers.csv` from the library.
//! - `--measure`: what the server costs on the Cortex-M0 and the Cortex-M4F (flash,
//!   RAM, instructions per request; harness images `modbus_node` against
//!   `minimal_node`), into `docs/modbus-cost.csv` and `docs/measurements-modbus.md`.

use crate::cross;
use std::io::{BufRead, BufReader};
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitCode, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// The Python packages of the tests, pinned.
const PYTHON_PACKAGES: [&str; 3] = ["pymodbus==3.16.1", "pyserial==3.5", "pytest==8.4.2"];

/// The register map's export, relative to the repository root.
const REGISTERS_CSV: &str = "docs/modbus/registers.csv";

/// A node image: a core, its target and QEMU machine, its sample source.
struct Node {
    cpu: &'static cross::Cpu,
    /// The QEMU machine, and the memory layout its image needs (`MISALIGN_MEMORY_X`)
    /// if not the target's default.
    machine: &'static str,
    memory_x: Option<&'static str>,
    external: bool,
    /// Built with flash (`modbus-flash`: nodes/firmware/persist.rs) and
    /// tested across a reset (`tests/modbus/test_reset.py`).
    stored: bool,
    /// A test build with flash that cuts its own power where the test plans
    /// (`_power-cut`: nodes/firmware/cut.rs, `tests/modbus/test_power_cut.py`).
    cut: bool,
}

impl Node {
    /// The node on `cpu`'s own board.
    fn on(cpu: &'static cross::Cpu, external: bool) -> Self {
        Node {
            cpu,
            machine: cpu.machine,
            memory_x: None,
            external,
            stored: false,
            cut: false,
        }
    }
}

/// With `--boards`, the node on its own samples on the other boards too: the
/// Cortex-M7 and M3 (CMSDK UART0) and the STM32F405 (USART1, its own memory layout).
const OTHER_BOARDS: [(&str, &str, Option<&str>); 3] = [
    ("cortex-m7", "mps2-an500", None),
    ("cortex-m3", "mps2-an385", None),
    (
        "cortex-m4f",
        "netduinoplus2",
        Some("lab/harness/boards/stm32f4.x"),
    ),
];

fn cpu(id: &str) -> &'static cross::Cpu {
    cross::CPUS
        .iter()
        .find(|c| c.id == id)
        .expect("a known core")
}

fn cpu_for_target(target: &str) -> Result<&'static cross::Cpu, String> {
    // The first core of the target: the Cortex-M4F for thumbv7em (not the M7).
    cross::CPUS
        .iter()
        .rev()
        .find(|c| c.target == target && c.sizes)
        .ok_or_else(|| {
            format!(
                "no QEMU board for {target}: one of thumbv6m-none-eabi, thumbv7m-none-eabi, \
                 thumbv7em-none-eabihf"
            )
        })
}

/// `cargo xtask modbus`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// Also run the node on its own samples on the Cortex-M7, M3 and the STM32F405.
    #[arg(long)]
    boards: bool,
    /// Boot the node and serve on 127.0.0.1:PORT until killed.
    #[arg(long, value_name = "PORT", conflicts_with_all = ["boards", "trace", "registers", "measure"])]
    serve: Option<String>,
    /// Feed this trace (the monitor example's --trace format) over Modbus and compare
    /// the events read back with the host replay.
    #[arg(long, value_name = "T.csv", requires_all = ["scene", "events"], conflicts_with_all = ["boards", "registers", "measure"])]
    trace: Option<String>,
    /// The trace's scene (the monitor example's --scene format).
    #[arg(long, value_name = "S.csv")]
    scene: Option<String>,
    /// Where to write the events read back (the monitor example's --events format).
    #[arg(long, value_name = "OUT.csv")]
    events: Option<String>,
    /// The core of --trace (f32 or fixed); must match the target's.
    #[arg(long, value_name = "f32|fixed")]
    model: Option<String>,
    /// The node's target for --serve and --trace.
    #[arg(long, value_name = "TRIPLE")]
    target: Option<String>,
    /// Write docs/modbus/registers.csv from the library's register map.
    #[arg(long, conflicts_with_all = ["boards", "measure"])]
    registers: bool,
    /// Write the default configuration (`Config::default()`) as tools/commission.py's
    /// --config file (`name,value`).
    #[arg(long, value_name = "C.csv", conflicts_with_all = ["boards", "measure", "trace", "serve"])]
    default_config: Option<String>,
    /// Measure flash, RAM and instructions per request; write docs/modbus-cost.csv and
    /// its table.
    #[arg(long, conflicts_with = "boards")]
    measure: bool,
    /// Run only docs/modbus.md's commands and snippets (tests/modbus/test_docs.py),
    /// which the whole test runs last.
    #[arg(long, conflicts_with_all = ["boards", "measure", "trace", "serve", "registers"])]
    docs: bool,
    /// Run only the nodes with flash across resets (tests/modbus/test_reset.py and
    /// test_line.py, on the Cortex-M4F and the Cortex-M0), without the page.
    #[arg(long, conflicts_with_all = ["boards", "measure", "trace", "serve", "registers", "docs"])]
    stored: bool,
    /// Eight nodes on one RS-485 line (lab/bus): four Cortex-M4F and three Cortex-M0
    /// nodes with flash and a Pico, addressed one by one, polled together, through a
    /// wrong baud rate, a babbler, a stopped node and an unconfirmed change
    /// (tests/modbus/test_bus.py); each QEMU node's events against the host replay.
    #[arg(long, conflicts_with_all = ["boards", "measure", "trace", "serve", "registers", "docs", "stored"])]
    bus: bool,
}

/// `cargo xtask modbus`.
pub fn run(args: &Args) -> ExitCode {
    let result = if args.registers {
        registers()
    } else if let Some(out) = &args.default_config {
        default_config(out)
    } else if args.measure {
        measure()
    } else if let Some(port) = &args.serve {
        serve(port, args.target.as_deref())
    } else if args.bus {
        bus()
    } else if args.docs {
        prepare().and_then(|(python, _, _)| docs(&python))
    } else if args.trace.is_some() {
        trace(
            args.trace.as_deref(),
            args.scene.as_deref(),
            args.events.as_deref(),
            args.model.as_deref(),
            args.target.as_deref(),
        )
    } else {
        tests(args.boards, args.stored)
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask modbus: {e}");
            ExitCode::FAILURE
        }
    }
}

/// `--default-config C.csv`: the default configuration, for tools/commission.py.
pub(crate) fn default_config(out: &str) -> Result<(), String> {
    let registers = crate::root().join("target/modbus/registers.csv");
    std::fs::create_dir_all(registers.parent().unwrap()).map_err(|e| e.to_string())?;
    std::fs::write(&registers, registers_text()?).map_err(|e| e.to_string())?;
    host::write_default_config(&crate::node::core(true)?, &registers, Path::new(out))?;
    println!("wrote {out}");
    Ok(())
}

/// `--registers`: the register map as the library exports it.
fn registers() -> Result<(), String> {
    let text = registers_text()?;
    let path = crate::root().join(REGISTERS_CSV);
    std::fs::create_dir_all(path.parent().unwrap()).map_err(|e| e.to_string())?;
    std::fs::write(&path, text).map_err(|e| format!("{REGISTERS_CSV}: {e}"))?;
    println!("wrote {REGISTERS_CSV}");
    Ok(())
}

pub(crate) fn registers_text() -> Result<String, String> {
    let mut text = String::new();
    misalign::modbus::registers_csv(&mut text).map_err(|e| e.to_string())?;
    Ok(text)
}

/// Builds the node for `node`'s core (profile `firmware`) and returns its ELF, kept
/// under a name of its own (the two sample sources build the same file).
fn build(node: &Node) -> Result<PathBuf, String> {
    let mut cmd = cross::cargo();
    cmd.args([
        "build",
        "--profile",
        "firmware",
        "--target",
        node.cpu.target,
    ])
    .args(["--features", "modbus-node", "--example", "firmware"])
    .args(
        node.stored
            .then_some(["--features", "modbus-flash"])
            .into_iter()
            .flatten(),
    )
    .args(
        node.cut
            .then_some(["--features", "_power-cut"])
            .into_iter()
            .flatten(),
    )
    .arg("--message-format=json-render-diagnostics");
    if node.external {
        cmd.env("MISALIGN_MODBUS_EXTERNAL", "1");
    } else {
        cmd.env_remove("MISALIGN_MODBUS_EXTERNAL");
    }
    match node.memory_x {
        Some(layout) => cmd.env("MISALIGN_MEMORY_X", layout),
        None => cmd.env_remove("MISALIGN_MEMORY_X"),
    };
    let built = cross::build(&mut cmd)?;
    let elf = cross::artifact(&built, "firmware")?;
    let kept = elf.with_file_name(format!(
        "firmware-modbus-{}-{}{}{}",
        node.machine,
        if node.external { "external" } else { "own" },
        if node.stored { "-stored" } else { "" },
        if node.cut { "-cut" } else { "" }
    ));
    std::fs::copy(&elf, &kept).map_err(|e| format!("{}: {e}", kept.display()))?;
    Ok(kept)
}

/// A free loopback port (bound, then released for QEMU).
fn free_port() -> Result<u16, String> {
    let listener = TcpListener::bind("127.0.0.1:0").map_err(|e| e.to_string())?;
    Ok(listener.local_addr().map_err(|e| e.to_string())?.port())
}

/// A node running in QEMU; killed (its whole process group) when dropped.
struct Booted {
    child: Child,
    port: u16,
    log: mpsc::Receiver<String>,
}

impl Drop for Booted {
    fn drop(&mut self) {
        // qemu-run's process group: the script, timeout, QEMU and defmt-print.
        let _ = Command::new("kill")
            .args(["-TERM", "--", &format!("-{}", self.child.id())])
            .status();
        let _ = self.child.wait();
    }
}

/// Boots `elf` on `machine` with serial0 on 127.0.0.1:`port` (and QEMU's monitor on
/// 127.0.0.1:`monitor`, if given); returns once the node logs that it serves. Its log goes to stderr, prefixed: every line with `all`, else
/// its Modbus lines, warnings and errors (the self-test's lines are `cargo xtask
/// firmware`'s business).
fn boot(
    machine: &str,
    elf: &Path,
    port: u16,
    monitor: Option<u16>,
    timeout: Duration,
    all: bool,
) -> Result<Booted, String> {
    use std::os::unix::process::CommandExt;
    let mut cmd = Command::new(crate::root().join("lab/qemu-run"));
    if let Some(monitor) = monitor {
        cmd.env("MISALIGN_QEMU_MONITOR_PORT", monitor.to_string());
    }
    let mut child = cmd
        .arg(machine)
        .arg(elf)
        .env("MISALIGN_QEMU_MACHINE", machine)
        .env("MISALIGN_QEMU_SERIAL_PORT", port.to_string())
        .env("MISALIGN_QEMU_TIMEOUT", "0")
        .env("MISALIGN_QEMU_PARENT", std::process::id().to_string())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .process_group(0)
        .spawn()
        .map_err(|e| format!("cannot run lab/qemu-run: {e}"))?;
    let stdout = child.stdout.take().unwrap();
    let (tx, rx) = mpsc::channel();
    // The whole log also in a file beside the image, for the tests that read what the
    // node measured (`MODBUS_NODE_LOG`).
    let mut file = std::fs::File::create(node_log(elf)).map_err(|e| e.to_string())?;
    std::thread::spawn(move || {
        use std::io::Write as _;
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            let _ = writeln!(file, "{line}");
            let notable = ["modbus", "storage", "ERROR", "WARN", "panick", "qemu"];
            if all || notable.iter().any(|n| line.contains(n)) {
                eprintln!("  node| {line}");
            }
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    let booted = Booted {
        child,
        port,
        log: rx,
    };
    let start = Instant::now();
    loop {
        match booted.log.recv_timeout(Duration::from_millis(200)) {
            Ok(line) if line.contains("modbus: serving") => return Ok(booted),
            Ok(_) => {}
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                return Err(format!("{machine}: the node stopped before it served"));
            }
            Err(mpsc::RecvTimeoutError::Timeout) if start.elapsed() > timeout => {
                return Err(format!(
                    "{machine}: the node did not serve within {} s",
                    timeout.as_secs()
                ));
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {}
        }
    }
}

/// The file a booted node's whole log goes to: beside its image.
fn node_log(elf: &Path) -> PathBuf {
    elf.with_extension("log")
}

/// The virtual environment with the pinned packages; its python.
pub(crate) fn venv() -> Result<PathBuf, String> {
    let dir = crate::root().join("target/modbus-venv");
    let python = dir.join("bin/python");
    let stamp = dir.join("installed.txt");
    let want = PYTHON_PACKAGES.join("\n");
    if std::fs::read_to_string(&stamp).ok().as_deref() == Some(want.as_str()) {
        return Ok(python);
    }
    let run = |cmd: &mut Command| -> Result<(), String> {
        let status = cmd
            .stdout(std::io::stderr())
            .status()
            .map_err(|e| format!("{cmd:?}: {e}"))?;
        status
            .success()
            .then_some(())
            .ok_or_else(|| format!("{cmd:?}: {status}"))
    };
    run(Command::new("python3").args(["-m", "venv"]).arg(&dir))?;
    run(Command::new(&python)
        .args([
            "-m",
            "pip",
            "install",
            "--quiet",
            "--disable-pip-version-check",
        ])
        .args(PYTHON_PACKAGES))?;
    std::fs::write(&stamp, want).map_err(|e| e.to_string())?;
    Ok(python)
}

/// What every QEMU run needs: the tools, the venv's python, the work folder
/// (target/modbus) and the register map written into it for the tests to read.
fn prepare() -> Result<(PathBuf, PathBuf, PathBuf), String> {
    crate::tools::preflight()?;
    let python = venv()?;
    let dir = crate::root().join("target/modbus");
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let registers = dir.join("registers.csv");
    std::fs::write(&registers, registers_text()?).map_err(|e| e.to_string())?;
    Ok((python, dir, registers))
}

/// The whole test: both cores, both sample sources.
fn tests(boards: bool, stored_only: bool) -> Result<(), String> {
    let start = Instant::now();
    let (python, dir, registers) = prepare()?;
    let mut failures = Vec::new();
    let mut nodes: Vec<Node> = ["cortex-m4f", "cortex-m0"]
        .iter()
        .flat_map(|id| [false, true].map(|external| Node::on(cpu(id), external)))
        .collect();
    // With flash, across a reset, and a test build of it through power cuts at points
    // of a commit, an event push and an acknowledgement: on the Cortex-M4F (flash
    // emulated in RAM a reset keeps) and the Cortex-M0 (the micro:bit's flash, through
    // its NVMC; nodes/firmware/flash.rs).
    for id in ["cortex-m4f", "cortex-m0"] {
        for cut in [false, true] {
            nodes.push(Node {
                stored: true,
                cut,
                ..Node::on(cpu(id), true)
            });
        }
    }
    if stored_only {
        nodes.retain(|n| n.stored && !n.cut);
    }
    if boards {
        nodes.extend(OTHER_BOARDS.map(|(id, machine, memory_x)| Node {
            machine,
            memory_x,
            ..Node::on(cpu(id), false)
        }));
    }
    for node in &nodes {
        let source = match (node.external, node.stored) {
            (true, true) if node.cut => "the master, with flash, through power cuts",
            (true, true) => "the master, with flash, across a reset",
            (true, false) => "the master",
            _ => "the node",
        };
        let what = format!(
            "{} ({}), samples from {source}",
            node.cpu.name, node.machine
        );
        println!("\n=== {what} ({}s)", start.elapsed().as_secs());
        if let Err(e) = test_node(node, &python, &dir, &registers) {
            failures.push(format!("{what}: {e}"));
        }
    }
    println!(
        "\n=== docs/modbus.md: every command and snippet ({}s)",
        start.elapsed().as_secs()
    );
    if stored_only {
        println!("  (not with --stored)");
    } else if let Err(e) = docs(&python) {
        failures.push(format!("docs/modbus.md: {e}"));
    }
    if failures.is_empty() {
        println!(
            "modbus: every test passed on every node{}",
            if stored_only {
                " with flash"
            } else {
                " and the page"
            }
        );
        return Ok(());
    }
    Err(failures.join("\n"))
}

/// The samples each QEMU node on the bus is fed: the scenario's first five minutes (its
/// first event among them), so that seven nodes take them in about a minute at 19200
/// baud.
const BUS_SAMPLES: usize = 300;

/// `--bus`: tests/modbus/test_bus.py on eight nodes joined by lab/bus/bus.py, then
/// each QEMU node's events against the host's replay of the samples it was fed.
fn bus() -> Result<(), String> {
    let start = Instant::now();
    let (python, dir, registers) = prepare()?;
    crate::tools::preflight_defmt()?;
    let stored = |id| Node {
        stored: true,
        ..Node::on(cpu(id), true)
    };
    let m4f = build(&stored("cortex-m4f"))?;
    let m0 = build(&stored("cortex-m0"))?;
    let pico = crate::pico::build()?;
    crate::pico::npm()?;
    let drive = dir.join("bus-pico-drive.csv");
    std::fs::write(&drive, crate::pico::drive(&[crate::pico::steady()])?)
        .map_err(|e| e.to_string())?;
    let samples: Vec<_> = host::scenario().into_iter().take(BUS_SAMPLES).collect();
    host::write_samples(&dir.join("bus-samples.csv"), &samples)?;
    let out = dir.join("bus");
    let _ = std::fs::remove_dir_all(&out);
    std::fs::create_dir_all(&out).map_err(|e| e.to_string())?;
    println!("built in {} s", start.elapsed().as_secs());
    let status = Command::new(&python)
        .current_dir(crate::root())
        .args(["-m", "pytest", "-q", "-s", "-p", "no:cacheprovider"])
        .arg("tests/modbus/test_bus.py")
        .env("BUS_M4F_ELF", &m4f)
        .env("BUS_M0_ELF", &m0)
        .env("PICO_ELF", &pico)
        .env("PICO_DRIVE", &drive)
        .env("MODBUS_REGISTERS", &registers)
        .env("MODBUS_SAMPLES", dir.join("bus-samples.csv"))
        .env(
            "MODBUS_UNLOCK_CODE",
            misalign::modbus::DEFAULT_UNLOCK_CODE.to_string(),
        )
        .env("BUS_OUT", &out)
        .status()
        .map_err(|e| format!("pytest: {e}"))?;
    if !status.success() {
        return Err(format!("pytest tests/modbus/test_bus.py: {status}"));
    }
    for (name, fpu) in [
        ("m4f-1", true),
        ("m4f-2", true),
        ("m4f-3", true),
        ("m4f-4", true),
        ("m0-1", false),
        ("m0-2", false),
        ("m0-3", false),
    ] {
        let raw = out.join(format!("events-{name}.csv"));
        let compared = host::compare_events(crate::node::core(fpu)?, &samples, &raw)
            .map_err(|e| format!("{name}: {e}"))?;
        if compared.events == 0 {
            return Err(format!("{name}: no event to compare"));
        }
        println!(
            "  {name}: its {} events are the host replay's, bit for bit",
            compared.events
        );
    }
    println!("the bus test took {} s", start.elapsed().as_secs());
    Ok(())
}

/// Every command and snippet of docs/modbus.md, as the page shows them
/// (`tests/modbus/test_docs.py`): the page's own `cargo xtask modbus --serve` boots
/// its nodes.
fn docs(python: &Path) -> Result<(), String> {
    let start = Instant::now();
    let status = Command::new(python)
        .current_dir(crate::root())
        .args(["-m", "pytest", "-q", "-p", "no:cacheprovider"])
        .arg("tests/modbus/test_docs.py")
        .status()
        .map_err(|e| format!("pytest: {e}"))?;
    println!("  docs/modbus.md: {} s", start.elapsed().as_secs());
    if status.success() {
        Ok(())
    } else {
        Err(format!("pytest tests/modbus/test_docs.py: {status}"))
    }
}

fn test_node(node: &Node, python: &Path, dir: &Path, registers: &Path) -> Result<(), String> {
    let elf = build(node)?;
    let fpu = node.cpu.has_fpu();
    let id = node.cpu.id;
    // The node on its own samples: every register as the host's replay reads it. On a
    // master's samples: every event the master reads back, compared below.
    let (tests, file) = if node.stored {
        host::write_samples(&dir.join("samples.csv"), &host::scenario())?;
        host::write_other_scene(fpu, &dir.join(format!("scene-{id}.bin")))?;
        (
            if node.cut {
                &["tests/modbus/test_power_cut.py"][..]
            } else {
                &["tests/modbus/test_reset.py", "tests/modbus/test_line.py"][..]
            },
            dir.join(format!("reset-{id}.csv")),
        )
    } else if node.external {
        host::write_samples(&dir.join("samples.csv"), &host::scenario())?;
        (
            &["tests/modbus/test_external.py"][..],
            dir.join(format!("events-{id}.csv")),
        )
    } else {
        let expected = dir.join(format!("expected-{id}.csv"));
        host::write_registers(fpu, &expected)?;
        host::write_other_scene(fpu, &dir.join(format!("scene-{id}.bin")))?;
        // Commissioning after the node's registers were compared: it changes them. On
        // the Cortex-M4F's own board, commissioning over a serial line too (a second
        // QEMU of the image, serial0 on a pseudo-terminal).
        const OWN: [&str; 3] = [
            "tests/modbus/test_node.py",
            "tests/modbus/test_config.py",
            "tests/modbus/test_serial.py",
        ];
        let serial = id == "cortex-m4f" && node.machine == node.cpu.machine;
        (if serial { &OWN[..] } else { &OWN[..2] }, expected)
    };
    let port = free_port()?;
    let monitor = node.stored.then(free_port).transpose()?;
    let booted = boot(
        node.machine,
        &elf,
        port,
        monitor,
        Duration::from_secs(300),
        false,
    )?;
    let status = Command::new(python)
        .current_dir(crate::root())
        .args(["-m", "pytest", "-q", "-p", "no:cacheprovider"])
        .args(tests)
        .env("MODBUS_PORT", booted.port.to_string())
        .env(
            "MODBUS_QEMU_MONITOR",
            monitor.map(|m| m.to_string()).unwrap_or_default(),
        )
        .env("MODBUS_REGISTERS", registers)
        .env("MODBUS_CORE", if fpu { "f32" } else { "fixed" })
        .env("MODBUS_EXPECTED", &file)
        .env("MODBUS_SCENE", dir.join(format!("scene-{id}.bin")))
        .env(
            "MODBUS_UNLOCK_CODE",
            misalign::modbus::DEFAULT_UNLOCK_CODE.to_string(),
        )
        .env(
            "MODBUS_WRONG_CODES_MAX",
            misalign::modbus::WRONG_CODES_MAX.to_string(),
        )
        .env("MODBUS_SAMPLES", dir.join("samples.csv"))
        .env("MODBUS_ELF", &elf)
        .env("MODBUS_MACHINE", node.machine)
        .env("MODBUS_NODE_LOG", node_log(&elf))
        // The plan file of a test build's power cuts: the image's path and `.cut`.
        .env("MODBUS_POWER_CUT_PLAN", elf.with_extension("cut"))
        .env("MODBUS_EVENTS_OUT", &file)
        .env(
            "MODBUS_EVENT_WINDOW",
            misalign::modbus::EVENT_WINDOW.to_string(),
        )
        .status()
        .map_err(|e| format!("pytest: {e}"))?;
    // The node's RAM once the tests ran, read through the monitor before it stops.
    let ram = monitor.map(|m| ram_used(&elf, m));
    drop(booted);
    if !status.success() {
        return Err(format!("pytest {}: {status}", tests.join(" ")));
    }
    match ram {
        Some(Ok((statics, stack, board))) => {
            let free = board as i64 - (statics + stack) as i64;
            println!(
                "  RAM: {statics} B of statics + {stack} B of stack (the deepest since the \
                 node's last boot) = {} B of the board's {board} B, {free} B left free",
                statics + stack
            );
            if id == "cortex-m0" && free < M0_RAM_FREE_TARGET as i64 {
                return Err(format!(
                    "{free} B of RAM left free, under the target of {M0_RAM_FREE_TARGET} B"
                ));
            }
        }
        Some(Err(e)) => return Err(format!("the node's RAM not read: {e}")),
        None => {}
    }
    if node.external && !node.stored {
        let compared = host::compare_events(crate::node::core(fpu)?, &host::scenario(), &file)?;
        println!(
            "  the {} events read over Modbus are the host replay's, bit for bit",
            compared.events
        );
    }
    Ok(())
}

/// The RAM the node in QEMU takes (bytes): its statics (llvm-size), the deepest stack
/// it used since its last boot, and the board's RAM. The stack is read through QEMU's
/// human monitor on 127.0.0.1:`monitor` (`xp`): the self-test paints the stack below
/// its frame at each boot (`misalign_harness::support::stack`), and the node's frames
/// reach deeper than the self-test's, so every word written since is counted.
fn ram_used(elf: &Path, monitor: u16) -> Result<(u64, u64, u64), String> {
    use std::io::{Read, Write};
    const PAINT: &str = "0xcccccccc";
    let sections = cross::Sections::of(&crate::tools::llvm_tool("llvm-size")?, elf)?;
    let (top, bottom, origin) = stack_bounds(elf, &sections)?;
    let mut conn = std::net::TcpStream::connect(("127.0.0.1", monitor))
        .map_err(|e| format!("QEMU's monitor: {e}"))?;
    conn.set_read_timeout(Some(Duration::from_secs(20)))
        .map_err(|e| e.to_string())?;
    let words = (top - bottom) / 4;
    write!(conn, "xp /{words}xw {bottom:#x}\nquit\n").map_err(|e| e.to_string())?;
    let mut text = String::new();
    // QEMU closes the connection at `quit`, after the dump.
    conn.read_to_string(&mut text)
        .map_err(|e| format!("QEMU's monitor: {e}"))?;
    let values: Vec<String> = text
        .lines()
        .filter_map(|l| l.split_once(": ").map(|(_, rest)| rest.to_string()))
        .flat_map(|rest| {
            rest.split_whitespace()
                .map(str::to_string)
                .collect::<Vec<_>>()
        })
        .collect();
    if values.len() as u64 != words {
        return Err(format!(
            "QEMU's monitor dumped {} words of {words}",
            values.len()
        ));
    }
    let painted = values.iter().take_while(|w| w.as_str() == PAINT).count() as u64;
    Ok((sections.ram(), top - bottom - 4 * painted, top - origin))
}

/// An image's stack: its top (the RAM's end) and lowest address (cortex-m-rt's
/// symbols), and the RAM's origin (where cortex-m-rt links .data).
fn stack_bounds(elf: &Path, sections: &cross::Sections) -> Result<(u64, u64, u64), String> {
    let nm = Command::new(crate::tools::llvm_tool("llvm-nm")?)
        .arg(elf)
        .output()
        .map_err(|e| format!("llvm-nm: {e}"))?;
    let symbol = |name: &str| {
        String::from_utf8_lossy(&nm.stdout)
            .lines()
            .find_map(|l| {
                let f: Vec<&str> = l.split_whitespace().collect();
                (f.len() == 3 && f[2] == name).then(|| u64::from_str_radix(f[0], 16).ok())?
            })
            .ok_or_else(|| format!("{}: no symbol {name}", elf.display()))
    };
    let (top, bottom) = (symbol("_stack_start")?, symbol("_stack_end")?);
    Ok((top, bottom, sections.addr(".data").unwrap_or(bottom)))
}

/// `--serve PORT [--target TRIPLE]`: the node on its own samples until killed.
fn serve(port: &str, target: Option<&str>) -> Result<(), String> {
    let port: u16 = port
        .parse()
        .map_err(|_| format!("--serve {port}: not a TCP port"))?;
    crate::tools::preflight()?;
    let cpu = cpu_for_target(target.unwrap_or("thumbv7em-none-eabihf"))?;
    let elf = build(&Node::on(cpu, false))?;
    let mut booted = boot(
        cpu.machine,
        &elf,
        port,
        None,
        Duration::from_secs(600),
        true,
    )?;
    println!("serving on 127.0.0.1:{port}");
    // The node's log goes on to stderr; QEMU runs until it is killed (with us).
    let status = booted.child.wait().map_err(|e| e.to_string())?;
    Err(format!("the node stopped: {status}"))
}

/// `--trace T.csv --scene S.csv --events OUT.csv [--model f32|fixed] [--target T]`.
fn trace(
    trace: Option<&str>,
    scene: Option<&str>,
    events: Option<&str>,
    model: Option<&str>,
    target: Option<&str>,
) -> Result<(), String> {
    let (Some(trace), Some(scene), Some(events)) = (trace, scene, events) else {
        return Err("--trace T.csv needs --scene S.csv and --events OUT.csv".into());
    };
    let open = |p: &str| std::fs::File::open(p).map_err(|e| format!("{p}: {e}"));
    let scene = misalign_cli::monitor_input::read_scene(open(scene)?)
        .map_err(|e| format!("{scene}: {e}"))?;
    let samples = misalign_cli::monitor_input::read_trace(open(trace)?)
        .map_err(|e| format!("{trace}: {e}"))?;
    let cpu = match (model, target) {
        (_, Some(t)) => cpu_for_target(t)?,
        (Some("fixed"), None) => cpu("cortex-m0"),
        (Some("f32") | None, None) => cpu("cortex-m4f"),
        (Some(m), None) => return Err(format!("--model {m}: f32 or fixed")),
    };
    let fpu = cpu.has_fpu();
    match model {
        Some("f32") if !fpu => {
            return Err(format!("--model f32 needs an FPU; {} has none", cpu.target));
        }
        Some("fixed") if fpu => {
            return Err(format!(
                "the node on {} runs the f32 core; --model fixed runs on thumbv6m-none-eabi or \
                 thumbv7m-none-eabi",
                cpu.target
            ));
        }
        _ => {}
    }
    let (python, dir, registers) = prepare()?;
    let samples_csv = dir.join("trace-samples.csv");
    host::write_samples(&samples_csv, &samples)?;
    // The scene's estimator for the trace's operating range, as the monitor example
    // builds it (`scenario::estimator_for` up to the largest finite load, at least the
    // scenario's): its prepared bytes go to the node, and the host replays through it.
    let load_max = samples
        .iter()
        .map(|s| f64::from(s.load))
        .filter(|l| l.is_finite())
        .fold(misalign::monitor::scenario::LOAD_MAX, f64::max);
    let core = host::core_for(fpu, &scene, load_max)?;
    let scene_bin = dir.join("trace-scene.bin");
    host::write_prepared(&core, &scene_bin)?;
    let config_csv = dir.join("trace-config.csv");
    host::write_default_config(&core, &registers, &config_csv)?;
    let elf = build(&Node::on(cpu, true))?;
    let port = free_port()?;
    let booted = boot(
        cpu.machine,
        &elf,
        port,
        None,
        Duration::from_secs(300),
        false,
    )?;
    // Commissioned over the bus as on site: unlock, the prepared scene and the
    // default configuration, commit, read back (tools/commission.py).
    let code = misalign::modbus::DEFAULT_UNLOCK_CODE.to_string();
    let (scene_bin, config_csv) = (scene_bin.as_os_str(), config_csv.as_os_str());
    let args = [
        "--code".as_ref(),
        code.as_ref(),
        "--prepared".as_ref(),
        scene_bin,
        "--config".as_ref(),
        config_csv,
    ];
    commission_py(&python, booted.port, &registers, &args)
        .map_err(|e| format!("commissioning the node failed: {e}"))?;
    let raw = dir.join("trace-events-raw.csv");
    let status = Command::new(&python)
        .arg(crate::root().join("tests/modbus/master.py"))
        .args(["--port", &booted.port.to_string()])
        .arg("--registers")
        .arg(&registers)
        .arg("--samples")
        .arg(&samples_csv)
        .arg("--events")
        .arg(&raw)
        .status()
        .map_err(|e| format!("master.py: {e}"))?;
    if !status.success() {
        return Err(format!("the master failed: {status}"));
    }
    // The events as the commissioning tool reads and decodes them (no code: status
    // only), from the first: those the node still holds, the host's last ones.
    let decoded = dir.join("trace-events-tool.csv");
    let args = [
        "--events-from".as_ref(),
        "0".as_ref(),
        "--events".as_ref(),
        decoded.as_os_str(),
    ];
    let read = commission_py(&python, booted.port, &registers, &args);
    drop(booted);
    read.map_err(|e| format!("reading the events with commission.py failed: {e}"))?;
    let compared = host::compare_events(core, &samples, &raw)?;
    let tool =
        std::fs::read_to_string(&decoded).map_err(|e| format!("{}: {e}", decoded.display()))?;
    let tool: Vec<&str> = tool.lines().collect();
    let host: Vec<&str> = compared.csv.lines().collect();
    // Each row the host's of its sequence number (numbered from 0), and at least as
    // many rows as the window holds.
    let same = |row: &&str| {
        let seq = row.split(',').nth(1).and_then(|q| q.parse::<usize>().ok());
        seq.and_then(|q| host.get(q + 1)) == Some(row)
    };
    let held = compared.events.min(misalign::modbus::EVENT_WINDOW);
    if tool.first() != host.first() || tool.len() < held + 1 || !tool[1..].iter().all(same) {
        return Err(format!(
            "tools/commission.py --events wrote {}: not {held} or more of the host's events",
            decoded.display()
        ));
    }
    std::fs::write(events, &compared.csv).map_err(|e| format!("{events}: {e}"))?;
    println!(
        "{} samples fed over Modbus to the {} node, {} events read back: the host replay's, \
         bit for bit; wrote {events}",
        samples.len(),
        cpu.name,
        compared.events
    );
    Ok(())
}

/// Runs tools/commission.py against the node on 127.0.0.1:`port` with `args` (its
/// status lines on stdout).
pub(crate) fn commission_py(
    python: &Path,
    port: u16,
    registers: &Path,
    args: &[&std::ffi::OsStr],
) -> Result<(), String> {
    let status = Command::new(python)
        .current_dir(crate::root())
        .arg("tools/commission.py")
        .arg("--tcp")
        .arg(format!("127.0.0.1:{port}"))
        .arg("--registers")
        .arg(registers)
        .args(args)
        .status()
        .map_err(|e| format!("commission.py: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(status.to_string())
    }
}

/// The host's side: what the node must answer, from the same samples through the same
/// library (`misalign::modbus::Server`, `misalign::monitor::Monitor`) and the same
/// estimator as the node's (`node::core`).
pub(crate) mod host {
    use crate::node::{self, Core};
    use misalign::Estimator;
    use misalign::modbus::map::{Table, TableMap};
    use misalign::modbus::{PreparedScene, Server, ServerConfig, crc16, event_from_registers};
    use misalign::monitor::scenario::{self, Scenario};
    use misalign::monitor::{Config, Event, Monitor, Sample};
    use misalign_cli::monitor_output::event_row;
    use std::fmt::Write as _;
    use std::path::Path;

    /// The node's estimator (`fpu`: the f32 core's `Auto`, else `FixedAuto`) for
    /// `scene` up to `load_max` (N), as the monitor example builds it.
    pub fn core_for(fpu: bool, scene: &misalign::Scene, load_max: f64) -> Result<Core, String> {
        let err = |e: misalign::Error| e.to_string();
        Ok(if fpu {
            Core::F32(scenario::estimator_for(scene, load_max).map_err(err)?)
        } else {
            Core::Fixed(scenario::estimator_for(scene, load_max).map_err(err)?)
        })
    }

    /// `core`'s prepared scene, as `examples/prepare.rs --out` writes it.
    pub fn write_prepared(core: &Core, out: &Path) -> Result<(), String> {
        fn bytes<C: PreparedScene>(core: &C) -> Vec<u8> {
            let mut out = [0; misalign::modbus::SCENE_BYTES_MAX];
            core.to_prepared(&mut out);
            out[..C::BYTES].to_vec()
        }
        let bytes = match core {
            Core::F32(c) => bytes(c),
            Core::Fixed(c) => bytes(c),
        };
        std::fs::write(out, bytes).map_err(|e| format!("{}: {e}", out.display()))
    }

    /// The default configuration (`Config::default()`) as tools/commission.py's
    /// `--config` file (`name,value`, one `config_*` register a line, the line
    /// settings' not among them), read through
    /// the library's server from its staged view, which reads as the active one
    /// before a first write. `registers`: the map's CSV, for the names and types.
    pub fn write_default_config(core: &Core, registers: &Path, out: &Path) -> Result<(), String> {
        let map = std::fs::read_to_string(registers)
            .map_err(|e| format!("{}: {e}", registers.display()))?;
        let mut rows = Vec::new();
        for line in map.lines().skip(1) {
            let cells: Vec<&str> = line.splitn(8, ',').collect();
            // The staged registers (config_source is the running one's origin).
            if let [table, address, name, ty, _, _, access, _] = cells[..]
                && table == "holding"
                && name.starts_with("config_")
                && access == "rw"
            {
                let at = address.parse::<u16>().map_err(|e| format!("{name}: {e}"))?;
                // The monitor's configuration only: a file of line settings given to
                // every node would put them all at one unit id.
                if at < misalign::modbus::map::LINE_ADDRESS {
                    rows.push((at, name, ty));
                }
            }
        }
        let start = rows
            .iter()
            .map(|r| r.0)
            .min()
            .ok_or("the map has no config_*")?;
        let words = match core {
            Core::F32(c) => config_view(*c, start)?,
            Core::Fixed(c) => config_view(*c, start)?,
        };
        let mut text = String::from("name,value\n");
        for (at, name, ty) in rows {
            let i = usize::from(at - start);
            let word = |k: usize| words.get(i + k).copied().ok_or("config_* past the view");
            let u32_at =
                || -> Result<u32, &str> { Ok(u32::from(word(0)?) << 16 | u32::from(word(1)?)) };
            let value = match ty {
                "u16" => word(0)?.to_string(),
                "u32" => u32_at()?.to_string(),
                "i32" => (u32_at()? as i32).to_string(),
                // Rust's shortest form that reads back to the same f32.
                "f32" => f32::from_bits(u32_at()?).to_string(),
                _ => return Err(format!("{name}: type {ty}")),
            };
            writeln!(text, "{name},{value}").unwrap();
        }
        std::fs::write(out, text).map_err(|e| format!("{}: {e}", out.display()))
    }

    /// The staged configuration view of a fresh server (the defaults), from `start`.
    fn config_view<E: Estimator + PreparedScene>(core: E, start: u16) -> Result<Vec<u16>, String> {
        let monitor = Monitor::new(core, Config::default()).map_err(|e| e.to_string())?;
        let mut server =
            Server::new(monitor, ServerConfig::default()).map_err(|e| e.to_string())?;
        let [a, b] = start.to_be_bytes();
        let [c, d] = (misalign::modbus::CONFIG_WORDS as u16).to_be_bytes();
        let answer = request(&mut server, &[3, a, b, c, d]);
        if answer.get(1) != Some(&3) {
            return Err(format!("the host's server answered {answer:02x?}"));
        }
        let data = &answer[3..answer.len() - 2];
        Ok(data
            .chunks(2)
            .map(|w| u16::from_be_bytes([w[0], w[1]]))
            .collect())
    }

    /// The tables in the order the test reads them, with the function that reads each.
    const TABLES: [(Table, u8, &str); 4] = [
        (Table::Coil, 1, "coil"),
        (Table::Discrete, 2, "discrete"),
        (Table::Input, 4, "input"),
        (Table::Holding, 3, "holding"),
    ];
    /// The most registers (or bits) one read of the test asks for.
    const READ_MAX: u16 = 120;

    /// One request through `server`: its answer.
    fn request<E: Estimator>(server: &mut Server<E>, pdu: &[u8]) -> Vec<u8> {
        let mut frame = vec![1];
        frame.extend_from_slice(pdu);
        let crc = crc16(&frame);
        frame.extend_from_slice(&crc.to_le_bytes());
        for b in frame {
            server.receive(b);
        }
        let answer = server.response().map(<[u8]>::to_vec).unwrap_or_default();
        server.sent();
        answer
    }

    /// Every value of the map, read as the test reads the node: table by table, in
    /// reads of at most [`READ_MAX`] from address 0 up, around the reserved run; `read,table,address,value`.
    /// The server counts the reads (`bus_*`), and so does the node's: the same reads
    /// in the same order leave the same counts.
    fn dump<E: Estimator + PreparedScene>(core: E) -> Result<String, String> {
        let monitor = Monitor::new(core, Config::default()).map_err(|e| e.to_string())?;
        let mut server =
            Server::new(monitor, ServerConfig::default()).map_err(|e| e.to_string())?;
        // As the node: it takes scenes over the bus (`scene_bytes`, `scene_active_crc`).
        server.accept_scenes();
        for sample in Scenario::new() {
            server.process(sample);
        }
        let mut out = String::from("read,table,address,value\n");
        let mut read = 0;
        for (table, function, name) in TABLES {
            for run in TableMap::of(table).runs() {
                let (mut start, end) = (run.start, run.end);
                while start < end {
                    let n = READ_MAX.min(end - start);
                    let [a, b] = start.to_be_bytes();
                    let [c, d] = n.to_be_bytes();
                    let answer = request(&mut server, &[function, a, b, c, d]);
                    if answer.get(1) != Some(&function) {
                        return Err(format!(
                            "{name} {start}+{n}: the host's server answered {answer:02x?}"
                        ));
                    }
                    let data = &answer[3..answer.len() - 2];
                    for k in 0..n {
                        let value = if function <= 2 {
                            u16::from(data[usize::from(k / 8)] >> (k % 8) & 1)
                        } else {
                            let i = usize::from(k) * 2;
                            u16::from_be_bytes([data[i], data[i + 1]])
                        };
                        writeln!(out, "{read},{name},{},{value}", start + k).unwrap();
                    }
                    read += 1;
                    start += n;
                }
            }
        }
        Ok(out)
    }

    /// A scene the node was not built with, prepared for its core (`fpu`: the f32
    /// core's `Auto`, else `FixedAuto`), as `examples/prepare.rs --out` writes it: what
    /// tests/modbus/test_config.py commissions with tools/commission.py.
    pub fn write_other_scene(fpu: bool, out: &Path) -> Result<(), String> {
        fn bytes<C: scenario::Core + PreparedScene>() -> Result<Vec<u8>, String> {
            let scene =
                misalign::Scene::new(0.04, 0.08, 79.3e9, 0.3, 0.25).map_err(|e| e.to_string())?;
            let core: C = scenario::estimator_for(&scene, 5e3).map_err(|e| e.to_string())?;
            let mut out = [0; misalign::modbus::SCENE_BYTES_MAX];
            core.to_prepared(&mut out);
            Ok(out[..C::BYTES].to_vec())
        }
        let bytes = if fpu {
            bytes::<misalign::float::Auto>()?
        } else {
            bytes::<misalign::fixed::FixedAuto>()?
        };
        std::fs::write(out, bytes).map_err(|e| format!("{}: {e}", out.display()))
    }

    /// The expected registers of the node on its own samples (`fpu`: the f32 core).
    pub fn write_registers(fpu: bool, out: &Path) -> Result<(), String> {
        let text = match node::core(fpu)? {
            Core::F32(core) => dump(core)?,
            Core::Fixed(core) => dump(core)?,
        };
        std::fs::write(out, text).map_err(|e| format!("{}: {e}", out.display()))
    }

    /// Samples as `tests/modbus/master.py` reads them: the timestamp, every f32 as its
    /// bit pattern, an empty cell for a channel not measured.
    pub fn write_samples(out: &Path, samples: &[Sample]) -> Result<(), String> {
        let mut text = String::from("time_ms,load,phi,speed,axial_force\n");
        let bits = |x: Option<f32>| x.map_or(String::new(), |x| x.to_bits().to_string());
        for s in samples {
            writeln!(
                text,
                "{},{},{},{},{}",
                s.time_ms,
                s.load.to_bits(),
                s.phi.to_bits(),
                bits(s.speed),
                bits(s.axial_force)
            )
            .unwrap();
        }
        std::fs::write(out, text).map_err(|e| format!("{}: {e}", out.display()))
    }

    /// The scenario's samples (what the tests feed the node on a master's samples).
    pub fn scenario() -> Vec<Sample> {
        Scenario::new().collect()
    }

    /// What a comparison found: the node's events in `examples/monitor --events`'s
    /// format, and how many.
    pub struct Compared {
        pub csv: String,
        pub events: usize,
    }

    /// Compares the events the master read from the node (`raw`: master.py's output)
    /// with the host's replay of `samples` through the node's estimator; every field
    /// bit for bit, or an error naming the first differences.
    pub fn compare_events(core: Core, samples: &[Sample], raw: &Path) -> Result<Compared, String> {
        let host = match core {
            Core::F32(core) => replay(core, samples)?,
            Core::Fixed(core) => replay(core, samples)?,
        };
        let text = std::fs::read_to_string(raw).map_err(|e| format!("{}: {e}", raw.display()))?;
        let mut got = Vec::new();
        for (i, line) in text.lines().enumerate().skip(1) {
            let words: Vec<u16> = line
                .split(',')
                .skip(1)
                .map(|w| {
                    w.parse()
                        .map_err(|_| format!("{}:{}: {w}", raw.display(), i + 1))
                })
                .collect::<Result<_, _>>()?;
            match event_from_registers(&words) {
                Ok(Some(event)) => got.push(event),
                Ok(None) => return Err(format!("{}:{}: an empty slot", raw.display(), i + 1)),
                Err(e) => return Err(format!("{}:{}: {e:?}", raw.display(), i + 1)),
            }
        }
        let (got, host): (Vec<String>, Vec<String>) = (
            got.iter().map(event_row).collect(),
            host.iter().map(event_row).collect(),
        );
        let mut differences: Vec<String> = got
            .iter()
            .zip(&host)
            .enumerate()
            .filter(|(_, (g, h))| g != h)
            .take(5)
            .map(|(i, (g, h))| format!("event {i}:\n    node {g}\n    host {h}"))
            .collect();
        if got.len() != host.len() {
            differences.push(format!(
                "the node gave {} events, the host replay {}",
                got.len(),
                host.len()
            ));
        }
        if !differences.is_empty() {
            return Err(format!(
                "the node's events differ from the host replay:\n  {}",
                differences.join("\n  ")
            ));
        }
        let mut csv = format!("{}\n", misalign_cli::monitor_output::EVENTS_HEADER);
        for row in &got {
            csv += row;
            csv.push('\n');
        }
        Ok(Compared {
            csv,
            events: got.len(),
        })
    }

    /// The events of `raw` (master.py's `--events`: each event's registers) in
    /// `examples/monitor --events`'s format, those of samples after `end_ms` left out.
    pub fn events_csv(raw: &Path, end_ms: Option<u32>) -> Result<Compared, String> {
        let text = std::fs::read_to_string(raw).map_err(|e| format!("{}: {e}", raw.display()))?;
        let mut csv = format!("{}\n", misalign_cli::monitor_output::EVENTS_HEADER);
        let mut events = 0;
        for (i, line) in text.lines().enumerate().skip(1) {
            let words: Vec<u16> = line
                .split(',')
                .skip(1)
                .map(|w| {
                    w.parse()
                        .map_err(|_| format!("{}:{}: {w}", raw.display(), i + 1))
                })
                .collect::<Result<_, _>>()?;
            let event = match event_from_registers(&words) {
                Ok(Some(event)) => event,
                Ok(None) => return Err(format!("{}:{}: an empty slot", raw.display(), i + 1)),
                Err(e) => return Err(format!("{}:{}: {e:?}", raw.display(), i + 1)),
            };
            if end_ms.is_some_and(|end| event.time_ms > end) {
                continue;
            }
            csv += &event_row(&event);
            csv.push('\n');
            events += 1;
        }
        Ok(Compared { csv, events })
    }

    /// The monitor as the node's server runs it (`Monitor::process`), over `samples`.
    fn replay<E: Estimator>(core: E, samples: &[Sample]) -> Result<Vec<Event>, String> {
        let mut monitor = Monitor::new(core, Config::default()).map_err(|e| e.to_string())?;
        let mut events = Vec::new();
        for &s in samples {
            monitor.process(s);
            while let Some(e) = monitor.pop_event() {
                events.push(e);
            }
        }
        Ok(events)
    }
}

/// The Cortex-M0 node without storage (`modbus_node`): RAM (statics and stack), bytes;
/// a function-3 read of 16 registers, instructions.
pub const M0_RAM_TARGET: u64 = 8 * 1024;
pub const M0_FC3_TARGET: u64 = 1500;
/// The Cortex-M0 node with its flash storage (`modbus_flash_node`, and the firmware
/// example's node with flash on the micro:bit): its program at most 48 KiB, so that a
/// 64 KiB part (the STM32F030C8 class) keeps 16 KiB for its storage; at least 1 KiB
/// of the micro:bit's 16 KiB of RAM left free (statics and the deepest stack taken).
pub const M0_PROGRAM_TARGET: u64 = 48 * 1024;
pub const M0_RAM_FREE_TARGET: u64 = 1024;

/// What one core measured.
struct Cost {
    cpu: &'static cross::Cpu,
    /// `minimal_node`: flash, statics, stack.
    base: (u64, u64, u64),
    /// `modbus_node`: flash, statics, stack.
    node: (u64, u64, u64),
    /// Instructions: function 3 of 16, function 4 of 16, function 16 of 20 samples;
    /// the framing of functions 3 and 16 (every byte but the last).
    requests: [u64; 5],
    /// Bytes of the register map's descriptions found in `modbus_node`'s image.
    descriptions: u64,
    /// `size_of` the server (the monitor in it included) and of the monitor.
    server_bytes: u64,
    monitor_bytes: u64,
    /// The deepest stack use once the server was built, once the samples were processed.
    stack_built: u64,
    stack_samples: u64,
}

/// Bytes of the map's descriptions (the CSV's last column) that `elf` holds: text the
/// server never sends, linked because its map entries carry it.
fn description_bytes(elf: &Path) -> Result<u64, String> {
    let image = std::fs::read(elf).map_err(|e| format!("{}: {e}", elf.display()))?;
    let map = registers_text()?;
    let mut descriptions: Vec<&str> = map
        .lines()
        .skip(1)
        .filter_map(|l| l.split_once(",\"")?.1.strip_suffix('"'))
        .collect();
    descriptions.sort_unstable();
    descriptions.dedup();
    Ok(descriptions
        .iter()
        .filter(|d| image.windows(d.len()).any(|w| w == d.as_bytes()))
        .map(|d| d.len() as u64)
        .sum())
}

/// `--measure`: builds `minimal_node` and `modbus_node` (profile `node`) for the
/// Cortex-M0 and M4F, runs them in QEMU, writes the CSV and the markdown table.
fn measure() -> Result<(), String> {
    crate::tools::preflight()?;
    let llvm_size = crate::tools::llvm_tool("llvm-size")?;
    let (mut costs, mut nodes) = (Vec::new(), Vec::new());
    for id in ["cortex-m0", "cortex-m4f"] {
        let cpu = cpu(id);
        let built = cross::build(cross::harness_build_with(cpu.target, "node").args([
            "--bin",
            "minimal_node",
            "--bin",
            "modbus_node",
            "--bin",
            "modbus_flash_node",
        ]))?;
        nodes.push(flash_node(
            cpu,
            &cross::artifact(&built, "modbus_flash_node")?,
        )?);
        let mut measured = Vec::new();
        for name in ["minimal_node", "modbus_node"] {
            let elf = cross::artifact(&built, name)?;
            let (status, log) = cross::qemu(cpu.machine, &elf)?;
            if status != Some(0) {
                return Err(format!("{name} on {}: exit {status:?}\n{log}", cpu.machine));
            }
            // Every `key=value` of the whole log (the fields stand on several lines).
            let fields =
                crate::log::Fields::of(&log, "").ok_or_else(|| format!("{name}: no log"))?;
            let field = |key: &str| -> Result<u64, String> {
                fields
                    .num(key)
                    .map_err(|e| format!("{name}: {e} in its log:\n{log}"))
            };
            let s = cross::Sections::of(&llvm_size, &elf)?;
            let requests = if name == "modbus_node" {
                [
                    field("fc3_16")?,
                    field("fc4_16")?,
                    field("fc16_20")?,
                    field("fc3_16_framing")?,
                    field("fc16_20_framing")?,
                ]
            } else {
                [0; 5]
            };
            let sizes = if name == "modbus_node" {
                [
                    field("server_bytes")?,
                    field("monitor_bytes")?,
                    field("stack_built")?,
                    field("stack_samples")?,
                ]
            } else {
                [0; 4]
            };
            measured.push(((s.flash(), s.ram(), field("stack_bytes")?), requests, sizes));
        }
        costs.push(Cost {
            cpu,
            base: measured[0].0,
            node: measured[1].0,
            requests: measured[1].1,
            descriptions: description_bytes(&cross::artifact(&built, "modbus_node")?)?,
            server_bytes: measured[1].2[0],
            monitor_bytes: measured[1].2[1],
            stack_built: measured[1].2[2],
            stack_samples: measured[1].2[3],
        });
    }
    let (csv, table, misses) = cost_tables(&costs);
    let docs = crate::root().join("docs");
    std::fs::write(docs.join("modbus-cost.csv"), &csv).map_err(|e| e.to_string())?;
    let page = docs.join("measurements-modbus.md");
    let text = std::fs::read_to_string(&page).map_err(|e| format!("{}: {e}", page.display()))?;
    let (begin, end) = ("<!-- modbus:begin -->", "<!-- modbus:end -->");
    let (Some(a), Some(b)) = (text.find(begin), text.find(end)) else {
        return Err(format!("{} has no modbus markers", page.display()));
    };
    let new = format!("{}{begin}\n{table}{}", &text[..a], &text[b..]);
    std::fs::write(&page, new).map_err(|e| e.to_string())?;
    print!("{table}");
    println!("wrote docs/modbus-cost.csv and docs/measurements-modbus.md");
    for m in &misses {
        println!("over target: {m}");
    }
    crate::records::write(&nodes)?;
    crate::measurements::update()?;
    let mut missed = Vec::new();
    for n in nodes.iter().filter(|n| n.core == "Cortex-M0") {
        let free = n.board_ram as i64 - (n.ram + n.stack) as i64;
        println!(
            "{} node with flash: a program of {} B (target: at most {M0_PROGRAM_TARGET} B), \
             {free} B of its {} B of RAM left free (target: at least {M0_RAM_FREE_TARGET} B)",
            n.core, n.program, n.board_ram
        );
        if n.program > M0_PROGRAM_TARGET {
            missed.push(format!(
                "the program, {} B > {M0_PROGRAM_TARGET} B",
                n.program
            ));
        }
        if free < M0_RAM_FREE_TARGET as i64 {
            missed.push(format!(
                "the RAM left free, {free} B < {M0_RAM_FREE_TARGET} B"
            ));
        }
    }
    println!(
        "wrote docs/modbus-node.csv and its table in {}",
        crate::measurements::PAGE
    );
    if missed.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "the Cortex-M0 node with flash misses its targets: {}",
            missed.join("; ")
        ))
    }
}

/// `modbus_flash_node` on `cpu`'s board: its program and statics (llvm-size), the
/// deepest stack of its run (its log), the board's RAM (its memory layout).
fn flash_node(cpu: &cross::Cpu, elf: &Path) -> Result<crate::records::ModbusNodeRow, String> {
    let (status, log) = cross::qemu(cpu.machine, elf)?;
    if status != Some(0) {
        return Err(format!(
            "modbus_flash_node on {}: exit {status:?}\n{log}",
            cpu.machine
        ));
    }
    let fields = crate::log::Fields::first(&log, "modbus_flash_node samples=")?;
    let s = cross::Sections::of(&crate::tools::llvm_tool("llvm-size")?, elf)?;
    let (top, _, origin) = stack_bounds(elf, &s)?;
    Ok(crate::records::ModbusNodeRow {
        core: cpu.name.to_string(),
        program: s.flash(),
        ram: s.ram(),
        stack: fields
            .num("stack_bytes")
            .map_err(|e| format!("modbus_flash_node: {e}"))?,
        board_ram: top - origin,
    })
}

/// The CSV, the markdown table, and the Cortex-M0 targets missed.
fn cost_tables(costs: &[Cost]) -> (String, String, Vec<String>) {
    use std::fmt::Write as _;
    let mut csv = String::from(
        "core,node_flash,node_statics,node_stack,node_ram,server_flash,server_statics,\
         server_stack,fc3_16_instructions,fc3_16_framing,fc4_16_instructions,\
         fc16_20_instructions,fc16_20_framing,server_flash_descriptions,server_struct,\
         monitor_struct\n",
    );
    let mut md = String::from(
        "| core | node flash | node RAM: statics + stack | the server adds: flash (descriptions) | \
         statics | stack | function 3, 16 registers (framing) | function 4, 16 registers | \
         function 16, 20 samples (framing) |\n|---|--:|--:|--:|--:|--:|--:|--:|--:|\n",
    );
    let mut misses = Vec::new();
    for c in costs {
        let (flash, statics, stack) = c.node;
        let ram = statics + stack;
        let d = |a: u64, b: u64| a as i64 - b as i64;
        let m0 = c.cpu.id == "cortex-m0";
        let checks = [
            (ram, M0_RAM_TARGET, "node RAM (B)"),
            (
                c.requests[0],
                M0_FC3_TARGET,
                "function 3 of 16 registers (instructions)",
            ),
        ];
        let marks = checks.map(|(value, target, what)| {
            if m0 && value > target {
                misses.push(format!("{} {what}: {value} > {target}", c.cpu.name));
                " **over target**"
            } else {
                ""
            }
        });
        writeln!(
            csv,
            "{},{flash},{statics},{stack},{ram},{},{},{},{},{},{},{},{},{},{},{}",
            c.cpu.name,
            d(flash, c.base.0),
            d(statics, c.base.1),
            d(stack, c.base.2),
            c.requests[0],
            c.requests[3],
            c.requests[1],
            c.requests[2],
            c.requests[4],
            c.descriptions,
            c.server_bytes,
            c.monitor_bytes
        )
        .unwrap();
        writeln!(
            md,
            "| {} | {flash} | {statics} + {stack} = {ram}{} | {} ({}) | {} | {} | {}{} ({}) | {} | {} ({}) |",
            c.cpu.name,
            marks[0],
            d(flash, c.base.0),
            c.descriptions,
            d(statics, c.base.1),
            d(stack, c.base.2),
            c.requests[0],
            marks[1],
            c.requests[3],
            c.requests[1],
            c.requests[2],
            c.requests[4]
        )
        .unwrap();
    }
    md.push('\n');
    for c in costs.iter().filter(|c| c.cpu.id == "cortex-m0") {
        let (_, statics, stack) = c.node;
        let left = |value: u64, target: u64| target as i64 - value as i64;
        writeln!(
            md,
            "{}: left under the targets, {} B of RAM, {} instructions of a function-3 \
             read of 16 registers.\n",
            c.cpu.name,
            left(statics + stack, M0_RAM_TARGET),
            left(c.requests[0], M0_FC3_TARGET)
        )
        .unwrap();
    }
    for c in costs {
        writeln!(
            md,
            "{}: `Server<E>` takes {} B, of which the monitor {} B; the node keeps one, \
             built on the stack. The deepest stack use is {} B once it is built, {} B once \
             the samples are processed, {} B after the requests.",
            c.cpu.name, c.server_bytes, c.monitor_bytes, c.stack_built, c.stack_samples, c.node.2
        )
        .unwrap();
    }
    (csv, md, misses)
}
