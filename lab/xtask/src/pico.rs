//! `cargo xtask pico`: the Raspberry Pi Pico node (`nodes/pico`) in an emulator of its
//! chip (rp2040js under Node, `lab/pico`), its sensors simulated at the pins.
//!
//! - no option: the checks of `tests/modbus/test_pico.py` (pytest, pymodbus in the
//!   venv of `cargo xtask modbus`): commissioning over the bus surviving a reset,
//!   power cuts in a checkpoint, a commit and an acknowledgement, each sensor
//!   unplugged and stuck, the driver-enable pin; then the harness restarted on the
//!   same flash image, the node still commissioned.
//! - `--serve PORT`: the node on 127.0.0.1:PORT (its UART0 bridged) until killed, in
//!   real time, its sensors on a steady process.
//! - `--trace T.csv --scene S.csv --events OUT.csv [--samples SAMPLES.csv]`: commissions
//!   the scene over the bus (tools/commission.py: the scene prepared for the node's
//!   fixed-point core and the default configuration), drives the sensors from the
//!   trace (through the inverse of the calibration the node runs, read over the bus;
//!   `--settings C.csv` commits one, and the sample period, before the scene),
//!   reads the events over Modbus into OUT (the monitor example's `--events` format)
//!   and writes to SAMPLES what the node's sensors delivered (the monitor example's
//!   trace format): `cargo run --example monitor -- --model fixed --scene S.csv
//!   --trace SAMPLES.csv --events E.csv` gives OUT again, bit for bit.
//! - `--uf2 OUT.uf2`: the image as a UF2 file, for a Pico in its USB boot mode.
//! - `--measure`: the image's flash and RAM (statics, the deepest stack) into
//!   docs/pico.csv and its table in docs/measurements.md.

use crate::cross;
use misalign::monitor::Sample;
use std::fmt::Write as _;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

#[allow(dead_code)]
#[path = "../../../nodes/pico/src/board.rs"]
mod board;

/// The node's target.
const TARGET: &str = "thumbv6m-none-eabi";
/// Probe 2's displacement in the drive (m): mid-range; probe 1 reads it plus
/// `span * tan(phi)`.
const D2_M: f32 = 1.0e-3;

/// `cargo xtask pico`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// Serve on 127.0.0.1:PORT until killed.
    #[arg(long, value_name = "PORT", conflicts_with_all = ["trace", "uf2", "measure"])]
    serve: Option<u16>,
    /// Drive the sensors from this trace (the monitor example's --trace format).
    #[arg(long, value_name = "T.csv", requires_all = ["scene", "events"])]
    trace: Option<String>,
    /// The trace's scene (the monitor example's --scene format).
    #[arg(long, value_name = "S.csv")]
    scene: Option<String>,
    /// Where to write the events read over Modbus (the monitor example's --events).
    #[arg(long, value_name = "OUT.csv")]
    events: Option<String>,
    /// Where to write the samples the node's sensors delivered (a trace).
    #[arg(long, value_name = "SAMPLES.csv")]
    samples: Option<String>,
    /// Settings committed before the scene (`name,value` lines as tools/commission.py
    /// --config takes them: the sample period and the sensors' calibration, ...).
    #[arg(long, value_name = "C.csv", requires = "trace")]
    settings: Option<String>,
    /// Write the image as a UF2 file.
    #[arg(long, value_name = "OUT.uf2")]
    uf2: Option<String>,
    /// Measure the image's flash and RAM; write docs/pico.csv and its table.
    #[arg(long)]
    measure: bool,
}

/// `cargo xtask pico`.
pub fn run(args: &Args) -> std::process::ExitCode {
    let result = if let Some(port) = args.serve {
        serve(port)
    } else if let Some(trace) = &args.trace {
        let (Some(scene), Some(events)) = (&args.scene, &args.events) else {
            unreachable!("clap requires them")
        };
        run_trace(
            Path::new(trace),
            Path::new(scene),
            Path::new(events),
            args.samples.as_deref().map(Path::new),
            args.settings.as_deref().map(Path::new),
        )
    } else if let Some(out) = &args.uf2 {
        uf2(Path::new(out))
    } else if args.measure {
        measure()
    } else {
        tests()
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask pico: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}

/// The work folder, target/pico.
fn dir() -> Result<PathBuf, String> {
    let dir = crate::root().join("target/pico");
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    Ok(dir)
}

/// Builds the node (release: the image a user flashes); its ELF.
pub fn build() -> Result<PathBuf, String> {
    let mut cmd = cross::cargo();
    cmd.args(["build", "--release", "--target", TARGET])
        .arg("--manifest-path")
        .arg(crate::root().join("nodes/pico/Cargo.toml"))
        .arg("--message-format=json-render-diagnostics")
        .env("CARGO_TARGET_DIR", crate::root().join("target"))
        .env_remove("MISALIGN_MODBUS_EXTERNAL");
    let built = cross::build(&mut cmd)?;
    cross::artifact(&built, "misalign-pico-node")
}

/// The harness's packages (`npm ci` from its lock file, once).
pub(crate) fn npm() -> Result<(), String> {
    let lab = crate::root().join("lab/pico");
    let lock = std::fs::read_to_string(lab.join("package-lock.json")).map_err(|e| e.to_string())?;
    let stamp = lab.join("node_modules/.misalign-lock");
    if std::fs::read_to_string(&stamp).ok().as_deref() == Some(lock.as_str()) {
        return Ok(());
    }
    let status = Command::new("npm")
        .args(["ci", "--no-audit", "--no-fund"])
        .current_dir(&lab)
        .stdout(std::io::stderr())
        .status()
        .map_err(|e| format!("cannot run npm (Node 20 or later is needed): {e}"))?;
    if !status.success() {
        return Err(format!("npm ci in lab/pico: {status}"));
    }
    std::fs::write(&stamp, lock).map_err(|e| e.to_string())
}

/// One row of the harness's drive: what the sensors see from `t_ms` on.
struct Row {
    t_ms: i64,
    load_code: i32,
    probe_v: [f32; 2],
    pulse_hz: f64,
    flags: u8,
}

/// The trace's samples as the harness drives the sensors: each row through the
/// inverse of the node's calibration (`board.rs`), the load as the HX711's code, each
/// probe's displacement as the volts at the ADS1115's input, the speed as the
/// tachometer's pulse rate. A value the trace could not read (NaN) puts that sensor at
/// its rail (the load cell's code, probe 1's input at full scale); a value the trace
/// holds bit for bit as long as the monitor's stuck time (the default configuration's
/// `stuck`) freezes that sensor's code from then on, as a stuck sensor's would (a
/// shorter repeat is a steady value, read through the sensor's noise) (flags 1 load,
/// 2 the probes, 4 and 8 the rails); an empty speed holds the last (the
/// configuration's nominal speed before one).
pub(crate) fn drive(samples: &[Sample]) -> Result<String, String> {
    drive_through(samples, &board::SensorSettings::DEFAULT)
}

/// [`drive`] through the inverse of `settings`' calibration (the node's in force).
fn drive_through(samples: &[Sample], settings: &board::SensorSettings) -> Result<String, String> {
    let cal = board::calibration(settings).map_err(|e| format!("the node's calibration: {e}"))?;
    let speed_cal = cal
        .speed
        .ok_or("the node's calibration has no tachometer")?;
    let volts_per_code = board::ADS1115_FULL_SCALE_V / 32768.0;
    let pulse_hz = |v: f32| {
        f64::from(v.max(0.0)) * f64::from(speed_cal.pulses_per_rev)
            / (2.0 * std::f64::consts::PI * f64::from(speed_cal.radius_m))
    };
    let config = misalign::monitor::Config::default();
    let mut speed = pulse_hz(config.nominal_speed);
    let stuck_ms = i64::from(config.stuck_ms);
    // Since when (ms) the load and the angle hold their value bit for bit.
    let (mut load_since, mut phi_since) = (0i64, 0i64);
    let mut rows = Vec::with_capacity(samples.len());
    let mut t = 0i64;
    let mut last: Option<&Sample> = None;
    for s in samples {
        if let Some(p) = last {
            t += i64::from(s.time_ms.wrapping_sub(p.time_ms) as i32);
        }
        let mut flags = 0u8;
        if last.is_none_or(|p| p.load.to_bits() != s.load.to_bits()) {
            load_since = t;
        }
        if last.is_none_or(|p| p.phi.to_bits() != s.phi.to_bits()) {
            phi_since = t;
        }
        if stuck_ms > 0 && t - load_since >= stuck_ms {
            flags |= 1;
        }
        if stuck_ms > 0 && t - phi_since >= stuck_ms {
            flags |= 2;
        }
        let load_code = if s.load.is_finite() {
            cal.load.counts_for(s.load)
        } else {
            flags |= 4;
            0
        };
        let pr = &cal.misalignment;
        let d1 = D2_M + pr.zero_offset_m + pr.span_m * libm::tanf(s.phi);
        let probe_v = if s.phi.is_finite() {
            [
                pr.probe1.counts_for(d1) as f32 * volts_per_code,
                pr.probe2.counts_for(D2_M) as f32 * volts_per_code,
            ]
        } else {
            flags |= 8;
            [0.0, pr.probe2.counts_for(D2_M) as f32 * volts_per_code]
        };
        if let Some(v) = s.speed.filter(|v| v.is_finite()) {
            speed = pulse_hz(v);
        }
        rows.push(Row {
            t_ms: t,
            load_code,
            probe_v,
            pulse_hz: speed,
            flags,
        });
        last = Some(s);
    }
    if rows.is_empty() {
        return Err("the trace has no sample".into());
    }
    let mut out = String::from("t_ms,load_code,probe1_v,probe2_v,pulse_hz,flags\n");
    for r in rows {
        writeln!(
            out,
            "{},{},{},{},{},{}",
            r.t_ms, r.load_code, r.probe_v[0], r.probe_v[1], r.pulse_hz, r.flags
        )
        .unwrap();
    }
    Ok(out)
}

/// The steady process of `--serve` and the checks: 2500 N, 2e-4 rad, 2 m/s.
pub(crate) fn steady() -> Sample {
    Sample::new(0, 2500.0, 2e-4).with_speed(2.0)
}

/// A free loopback port.
fn free_port() -> Result<u16, String> {
    let l = std::net::TcpListener::bind("127.0.0.1:0").map_err(|e| e.to_string())?;
    Ok(l.local_addr().map_err(|e| e.to_string())?.port())
}

/// The harness running the node; killed (its process group) when dropped.
pub struct Harness {
    child: Child,
    pub port: u16,
    pub control: u16,
    log: mpsc::Receiver<String>,
}

/// How the harness runs.
pub struct Options<'a> {
    pub flash: &'a Path,
    pub drive: &'a Path,
    pub samples: Option<&'a Path>,
    pub realtime: bool,
    pub port: Option<u16>,
}

impl Harness {
    /// Starts the harness on `elf` and waits until the node serves.
    pub fn start(elf: &Path, o: &Options) -> Result<Harness, String> {
        use std::os::unix::process::CommandExt;
        npm()?;
        crate::tools::preflight_defmt()?;
        let port = match o.port {
            Some(p) => p,
            None => free_port()?,
        };
        let control = free_port()?;
        let mut cmd = Command::new("node");
        cmd.arg(crate::root().join("lab/pico/harness.mjs"))
            .arg("--elf")
            .arg(elf)
            .arg("--flash")
            .arg(o.flash)
            .arg("--drive")
            .arg(o.drive)
            .args([
                "--port",
                &port.to_string(),
                "--control",
                &control.to_string(),
            ]);
        if let Some(s) = o.samples {
            cmd.arg("--samples").arg(s);
        }
        if o.realtime {
            cmd.arg("--realtime");
        }
        let mut child = cmd
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .process_group(0)
            .spawn()
            .map_err(|e| format!("cannot run node (Node 20 or later): {e}"))?;
        let stdout = child.stdout.take().unwrap();
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                eprintln!("  pico| {line}");
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        let h = Harness {
            child,
            port,
            control,
            log: rx,
        };
        h.wait_for("modbus: serving", Duration::from_secs(120))?;
        Ok(h)
    }

    /// Waits until the node logs a line holding `what`.
    pub fn wait_for(&self, what: &str, timeout: Duration) -> Result<String, String> {
        let start = Instant::now();
        loop {
            match self.log.recv_timeout(Duration::from_millis(200)) {
                Ok(line) if line.contains(what) => return Ok(line),
                Ok(_) => {}
                Err(mpsc::RecvTimeoutError::Disconnected) => {
                    return Err(format!(
                        "the harness stopped before the node logged {what:?}"
                    ));
                }
                Err(mpsc::RecvTimeoutError::Timeout) if start.elapsed() > timeout => {
                    return Err(format!("the node did not log {what:?} within {timeout:?}"));
                }
                Err(_) => {}
            }
        }
    }

    /// One command on the control port; its answer (one JSON line).
    pub fn command(&self, line: &str) -> Result<String, String> {
        let mut s = TcpStream::connect(("127.0.0.1", self.control)).map_err(|e| e.to_string())?;
        s.set_read_timeout(Some(Duration::from_secs(30)))
            .map_err(|e| e.to_string())?;
        writeln!(s, "{line}").map_err(|e| e.to_string())?;
        let mut answer = String::new();
        let mut byte = [0u8];
        while s.read(&mut byte).map_err(|e| e.to_string())? == 1 && byte[0] != b'\n' {
            answer.push(byte[0] as char);
        }
        Ok(answer)
    }
}

impl Drop for Harness {
    fn drop(&mut self) {
        let _ = Command::new("kill")
            .args(["-TERM", "--", &format!("-{}", self.child.id())])
            .status();
        let _ = self.child.wait();
    }
}

/// A number field of a JSON answer (`"key":123`); `None` if absent or null.
pub fn json_num(json: &str, key: &str) -> Option<f64> {
    let at = json.find(&format!("\"{key}\":"))? + key.len() + 3;
    let rest = &json[at..];
    let end = rest.find([',', '}']).unwrap_or(rest.len());
    rest[..end].trim().parse().ok()
}

/// `--serve PORT`.
fn serve(port: u16) -> Result<(), String> {
    let elf = build()?;
    let dir = dir()?;
    let drive_path = dir.join("steady-drive.csv");
    std::fs::write(&drive_path, drive(&[steady()])?).map_err(|e| e.to_string())?;
    let flash = dir.join("serve-flash.bin");
    let mut h = Harness::start(
        &elf,
        &Options {
            flash: &flash,
            drive: &drive_path,
            samples: None,
            realtime: true,
            port: Some(port),
        },
    )?;
    println!("serving on 127.0.0.1:{port}");
    let status = h.child.wait().map_err(|e| e.to_string())?;
    Err(format!("the harness stopped: {status}"))
}

/// `--trace`.
fn run_trace(
    trace: &Path,
    scene: &Path,
    events_out: &Path,
    samples_out: Option<&Path>,
    settings: Option<&Path>,
) -> Result<(), String> {
    let open = |p: &Path| std::fs::File::open(p).map_err(|e| format!("{}: {e}", p.display()));
    let scene_v = misalign_cli::monitor_input::read_scene(open(scene)?)
        .map_err(|e| format!("{}: {e}", scene.display()))?;
    let samples = misalign_cli::monitor_input::read_trace(open(trace)?)
        .map_err(|e| format!("{}: {e}", trace.display()))?;
    let elf = build()?;
    let dir = dir()?;
    let drive_path = dir.join("trace-drive.csv");
    // Until the node's settings are read back: the build's.
    std::fs::write(&drive_path, drive(&samples)?).map_err(|e| e.to_string())?;
    // The scene's estimator for the trace's operating range, as the monitor example
    // builds it: its prepared bytes go to the node.
    let load_max = samples
        .iter()
        .map(|s| f64::from(s.load))
        .filter(|l| l.is_finite())
        .fold(misalign::monitor::scenario::LOAD_MAX, f64::max);
    let core = crate::modbus::host::core_for(false, &scene_v, load_max)?;
    let scene_bin = dir.join("trace-scene.bin");
    crate::modbus::host::write_prepared(&core, &scene_bin)?;
    let python = crate::modbus::venv()?;
    let registers = dir.join("registers.csv");
    std::fs::write(&registers, crate::modbus::registers_text()?).map_err(|e| e.to_string())?;
    let config_csv = dir.join("trace-config.csv");
    crate::modbus::host::write_default_config(&core, &registers, &config_csv)?;
    let flash = dir.join("trace-flash.bin");
    let _ = std::fs::remove_file(&flash);
    let delivered = dir.join("trace-delivered.csv");
    let h = Harness::start(
        &elf,
        &Options {
            flash: &flash,
            drive: &drive_path,
            samples: Some(&delivered),
            realtime: false,
            port: None,
        },
    )?;
    let code = misalign::modbus::DEFAULT_UNLOCK_CODE.to_string();
    // The node answers (its first answer may take seconds of the emulator's warm-up).
    read_holding(h.port, 0)?;
    if let Some(settings) = settings {
        // Committed before the scene: the node samples nothing until the scene is.
        let args = [
            "--code".as_ref(),
            code.as_ref(),
            "--config".as_ref(),
            settings.as_os_str(),
        ];
        crate::modbus::commission_py(&python, h.port, &registers, &args)
            .map_err(|e| format!("committing {}: {e}", settings.display()))?;
    }
    // The sensors driven through the inverse of the calibration the node runs.
    let in_force = read_sensor_settings(h.port)?;
    std::fs::write(&drive_path, drive_through(&samples, &in_force)?).map_err(|e| e.to_string())?;
    let answer = h.command(&format!("drive {}", drive_path.display()))?;
    if !answer.contains("\"ok\":true") {
        return Err(format!("the harness refused the drive: {answer}"));
    }
    let args = [
        "--code".as_ref(),
        code.as_ref(),
        "--prepared".as_ref(),
        scene_bin.as_os_str(),
        "--config".as_ref(),
        config_csv.as_os_str(),
    ];
    crate::modbus::commission_py(&python, h.port, &registers, &args)
        .map_err(|e| format!("commissioning the node failed: {e}"))?;
    let raw = dir.join("trace-events-raw.csv");
    let status = Command::new(&python)
        .arg(crate::root().join("lab/pico/master.py"))
        .args(["--port", &h.port.to_string()])
        .args(["--control", &h.control.to_string()])
        .arg("--registers")
        .arg(&registers)
        .arg("--events")
        .arg(&raw)
        .status()
        .map_err(|e| format!("master.py: {e}"))?;
    if !status.success() {
        return Err(format!("the master failed: {status}"));
    }
    let st = h.command("status")?;
    let end_ms = json_num(&st, "end_ms").ok_or("the trace never started")? as u32;
    if json_num(&st, "de_errors") != Some(0.0) {
        return Err(format!("the driver-enable pin was wrong: {st}"));
    }
    drop(h);
    // What the sensors delivered up to the trace's end, and the events of those
    // samples (each event carries its sample's time).
    let text = std::fs::read_to_string(&delivered).map_err(|e| e.to_string())?;
    let mut trace_csv = String::from("t,P,phi,V,fault\n");
    let mut n = 0;
    let mut delivered_max = misalign::monitor::scenario::LOAD_MAX;
    // Whether the node's log went past the trace's end (every sample of it decoded).
    let mut complete = false;
    for line in text.lines() {
        let f: Vec<u32> = line
            .split(',')
            .map(|w| match w {
                "true" => 1,
                "false" => 0,
                w => w.parse().unwrap_or(u32::MAX),
            })
            .collect();
        let [t, p, phi, measured, v, fault] = f[..] else {
            return Err(format!("a sample line {line:?}"));
        };
        if t > end_ms {
            complete = true;
            break;
        }
        // The sensor's own fault, as the monitor example's `fault` column names it.
        let fault = if fault == 255 {
            String::new()
        } else {
            use misalign::monitor::{FaultKind, SensorId};
            let sensor = SensorId::ALL.get((fault >> 4) as usize);
            let kind = FaultKind::ALL.get((fault & 15) as usize);
            let (Some(sensor), Some(&kind)) = (sensor, kind) else {
                return Err(format!("a sample line's fault {fault:#x}"));
            };
            format!(
                "{}:{}",
                sensor.name(),
                misalign_cli::monitor_input::fault_kind_name(kind)
            )
        };
        let f64s = |bits: u32| f64::from(f32::from_bits(bits));
        if f64s(p).is_finite() {
            delivered_max = delivered_max.max(f64s(p));
        }
        let speed = if measured == 1 {
            format!("{}", f64s(v))
        } else {
            String::new()
        };
        writeln!(
            trace_csv,
            "{}.{:03},{},{},{speed},{fault}",
            t / 1000,
            t % 1000,
            f64s(p),
            f64s(phi)
        )
        .unwrap();
        n += 1;
    }
    if !complete {
        return Err(format!(
            "the node's log holds no sample after the trace's end ({end_ms} ms)"
        ));
    }
    // The monitor example prepares its scene for the loads of the trace it reads: the
    // delivered samples' must give the scene the node was commissioned with.
    let replayed = crate::modbus::host::core_for(false, &scene_v, delivered_max)?;
    let replayed_bin = dir.join("trace-scene-delivered.bin");
    crate::modbus::host::write_prepared(&replayed, &replayed_bin)?;
    if std::fs::read(&replayed_bin).ok() != std::fs::read(&scene_bin).ok() {
        return Err(format!(
            "the delivered samples' highest load ({delivered_max} N) prepares another model \
             than the trace's ({load_max} N): the monitor example would not replay the node's \
             scene"
        ));
    }
    if let Some(out) = samples_out {
        std::fs::write(out, &trace_csv).map_err(|e| format!("{}: {e}", out.display()))?;
    }
    let csv = crate::modbus::host::events_csv(&raw, Some(end_ms))?;
    std::fs::write(events_out, &csv.csv).map_err(|e| format!("{}: {e}", events_out.display()))?;
    println!(
        "{} trace rows drove the Pico node's sensors; it delivered {n} samples and {} events \
         over Modbus; wrote {}",
        samples.len(),
        csv.events,
        events_out.display()
    );
    Ok(())
}

/// `--uf2 OUT`: the image's flash segments in UF2 blocks of 256 bytes (family RP2040).
fn uf2(out: &Path) -> Result<(), String> {
    let elf = build()?;
    let bytes = std::fs::read(&elf).map_err(|e| e.to_string())?;
    let image = flash_image(&bytes)?;
    const FAMILY_RP2040: u32 = 0xe48b_ff56;
    let blocks: Vec<(u32, &[u8])> = image
        .iter()
        .flat_map(|(addr, data)| {
            data.chunks(256)
                .enumerate()
                .map(move |(i, c)| (addr + 256 * i as u32, c))
        })
        .collect();
    let mut file = Vec::with_capacity(blocks.len() * 512);
    for (i, (addr, chunk)) in blocks.iter().enumerate() {
        let mut block = [0u8; 512];
        let words = [
            0x0A32_4655,
            0x9E5D_5157,
            0x0000_2000, // flags: the family id is present
            *addr,
            256,
            i as u32,
            blocks.len() as u32,
            FAMILY_RP2040,
        ];
        for (k, w) in words.iter().enumerate() {
            block[4 * k..4 * k + 4].copy_from_slice(&w.to_le_bytes());
        }
        block[32..32 + chunk.len()].copy_from_slice(chunk);
        block[508..].copy_from_slice(&0x0AB1_6F30u32.to_le_bytes());
        file.extend_from_slice(&block);
    }
    std::fs::write(out, file).map_err(|e| format!("{}: {e}", out.display()))?;
    println!(
        "wrote {} ({} blocks of 256 bytes): hold BOOTSEL while plugging the Pico in, then \
         copy the file onto the RPI-RP2 drive",
        out.display(),
        blocks.len()
    );
    Ok(())
}

/// The ELF's loadable segments in the flash's range (address, bytes), 256-byte aligned.
fn flash_image(elf: &[u8]) -> Result<Vec<(u32, Vec<u8>)>, String> {
    let u16_at = |o: usize| u16::from_le_bytes([elf[o], elf[o + 1]]);
    let u32_at = |o: usize| u32::from_le_bytes(elf[o..o + 4].try_into().unwrap());
    if elf.get(..4) != Some(b"\x7fELF") {
        return Err("not an ELF".into());
    }
    let (phoff, phentsize, phnum) = (u32_at(28) as usize, u16_at(42) as usize, u16_at(44));
    let mut pages: std::collections::BTreeMap<u32, [u8; 256]> = Default::default();
    for i in 0..usize::from(phnum) {
        let at = phoff + i * phentsize;
        let (kind, offset, paddr, filesz) =
            (u32_at(at), u32_at(at + 4), u32_at(at + 12), u32_at(at + 16));
        if kind != 1 || filesz == 0 || !(0x1000_0000..0x1020_0000).contains(&paddr) {
            continue;
        }
        for k in 0..filesz {
            let a = paddr + k;
            pages.entry(a & !255).or_insert([0xff; 256])[(a & 255) as usize] =
                elf[(offset + k) as usize];
        }
    }
    Ok(pages.into_iter().map(|(a, p)| (a, p.to_vec())).collect())
}

/// A fresh node (its flash erased) on the steady process, not paced: what the checks
/// and the measurement run against. Its work folder's files: the drive, the flash.
fn fresh(elf: &Path, name: &str) -> Result<Harness, String> {
    let dir = dir()?;
    let drive_path = dir.join("steady-drive.csv");
    std::fs::write(&drive_path, drive(&[steady()])?).map_err(|e| e.to_string())?;
    let flash = dir.join(format!("{name}-flash.bin"));
    let _ = std::fs::remove_file(&flash);
    Harness::start(
        elf,
        &Options {
            flash: &flash,
            drive: &drive_path,
            samples: None,
            realtime: false,
            port: None,
        },
    )
}

/// What the checks need beside the node: the venv, the register map, a scene prepared
/// for the node's core (not the one it was built with) and the default configuration.
fn check_files() -> Result<(PathBuf, PathBuf, PathBuf, PathBuf), String> {
    let dir = dir()?;
    let python = crate::modbus::venv()?;
    let registers = dir.join("registers.csv");
    std::fs::write(&registers, crate::modbus::registers_text()?).map_err(|e| e.to_string())?;
    let scene = dir.join("scene-fixed.bin");
    crate::modbus::host::write_other_scene(false, &scene)?;
    let config = dir.join("default-config.csv");
    let core = crate::node::core(false)?;
    crate::modbus::host::write_default_config(&core, &registers, &config)?;
    Ok((python, registers, scene, config))
}

/// The checks: tests/modbus/test_pico.py (pytest) against a fresh node, then a new
/// harness on its flash image.
fn tests() -> Result<(), String> {
    let start = Instant::now();
    let elf = build()?;
    let (python, registers, scene, config) = check_files()?;
    let h = fresh(&elf, "checks")?;
    let status = Command::new(&python)
        .current_dir(crate::root())
        .args([
            "-m",
            "pytest",
            "-q",
            "-p",
            "no:cacheprovider",
            "tests/modbus/test_pico.py",
        ])
        .env("PYTHONPATH", crate::root().join("tests/modbus"))
        .env("MODBUS_PORT", h.port.to_string())
        .env("PICO_CONTROL", h.control.to_string())
        .env("MODBUS_REGISTERS", &registers)
        .env("MODBUS_SCENE", &scene)
        .env("PICO_CONFIG", &config)
        .env(
            "MODBUS_UNLOCK_CODE",
            misalign::modbus::DEFAULT_UNLOCK_CODE.to_string(),
        )
        .status()
        .map_err(|e| format!("pytest: {e}"))?;
    let st = h.command("status")?;
    drop(h);
    if !status.success() {
        return Err(format!("pytest tests/modbus/test_pico.py: {status}"));
    }
    // The flash image outlives the harness: a new one on the same file boots into the
    // commissioned node.
    let h = Harness::start(
        &elf,
        &Options {
            flash: &dir()?.join("checks-flash.bin"),
            drive: &dir()?.join("steady-drive.csv"),
            samples: None,
            realtime: false,
            port: None,
        },
    )?;
    let source = read_holding(h.port, holding_address("config_source")?)?;
    drop(h);
    if source != 1 {
        return Err(format!(
            "after a restart of the harness the node's config_source is {source}, not 1 \
             (committed): its flash image was not kept"
        ));
    }
    println!(
        "pico: every check passed in {} s ({} s of the node's time, {} boots); a new \
         harness on the flash image booted the commissioned node",
        start.elapsed().as_secs(),
        json_num(&st, "ns").unwrap_or(0.0) as u64 / 1_000_000_000,
        json_num(&st, "boots").unwrap_or(0.0)
    );
    Ok(())
}

/// The address of the holding register `name` (the library's register map).
fn holding_address(name: &str) -> Result<u16, String> {
    let map = crate::modbus::registers_text()?;
    map.lines()
        .find_map(|l| {
            let c: Vec<&str> = l.splitn(4, ',').collect();
            (c.len() > 2 && c[0] == "holding" && c[2] == name).then(|| c[1].parse().ok())?
        })
        .ok_or_else(|| format!("no holding register {name}"))
}

/// One holding register of unit 1 on 127.0.0.1:`port`.
fn read_holding(port: u16, address: u16) -> Result<u16, String> {
    Ok(read_holdings(port, address, 1)?[0])
}

/// `n` (at most 125) holding registers of unit 1 on 127.0.0.1:`port` from `address`
/// (function 3, an RTU frame on the bridge), asked up to five times.
fn read_holdings(port: u16, address: u16, n: u16) -> Result<Vec<u16>, String> {
    let mut frame = vec![1, 3];
    frame.extend_from_slice(&address.to_be_bytes());
    frame.extend_from_slice(&n.to_be_bytes());
    frame.extend_from_slice(&misalign::modbus::crc16(&frame).to_le_bytes());
    let len = 5 + 2 * usize::from(n);
    let mut last = String::new();
    for _ in 0..5 {
        let mut s = TcpStream::connect(("127.0.0.1", port)).map_err(|e| e.to_string())?;
        s.set_read_timeout(Some(Duration::from_secs(5)))
            .map_err(|e| e.to_string())?;
        s.write_all(&frame).map_err(|e| e.to_string())?;
        let mut answer = vec![0u8; len];
        match s.read_exact(&mut answer) {
            Ok(())
                if answer[..3] == [1, 3, (2 * n) as u8]
                    && misalign::modbus::crc16(&answer[..len - 2]).to_le_bytes()
                        == answer[len - 2..] =>
            {
                return Ok(answer[3..len - 2]
                    .chunks_exact(2)
                    .map(|c| u16::from_be_bytes([c[0], c[1]]))
                    .collect());
            }
            Ok(()) => last = format!("the answer {answer:02x?}"),
            Err(e) => last = e.to_string(),
        }
    }
    Err(format!("reading holding registers from {address}: {last}"))
}

/// The sensor settings in force on the node (`active_sample_period` on, 13 values of
/// two registers, high word first, in the image's order).
fn read_sensor_settings(port: u16) -> Result<board::SensorSettings, String> {
    let at = holding_address("active_sample_period")?;
    let w = read_holdings(port, at, 26)?;
    let v: Vec<u32> = w
        .chunks_exact(2)
        .map(|c| u32::from(c[0]) << 16 | u32::from(c[1]))
        .collect();
    let f = |i: usize| f32::from_bits(v[i]);
    Ok(board::SensorSettings {
        sample_period_ms: v[0],
        load_zero_counts: f(1),
        load_newtons_per_count: f(2),
        load_capacity_n: f(3),
        probe1_zero_counts: f(4),
        probe1_metres_per_count: f(5),
        probe2_zero_counts: f(6),
        probe2_metres_per_count: f(7),
        probe_span_m: f(8),
        probe_zero_offset_m: f(9),
        tacho_pulses_per_rev: v[10],
        tacho_radius_m: f(11),
        tacho_max_speed_m_s: f(12),
    })
}

/// The stack's reservation (nodes/pico/memory.x) keeps at least this much (bytes) above
/// the deepest stack `--measure` finds: for the paths its run does not take (a power
/// cut's recovery, a sensor's fault, every exception answer).
pub const STACK_HEADROOM: u64 = 4096;

/// `--measure`: the image's flash and statics (llvm-size), the deepest stack of a
/// commissioned node over 60 s of its sensors and a burst of requests, the board's
/// RAM; into docs/pico.csv and its table.
fn measure() -> Result<(), String> {
    let elf = build()?;
    let llvm_size = crate::tools::llvm_tool("llvm-size")?;
    let sections = cross::Sections::of(&llvm_size, &elf)?;
    let (python, registers, scene, config) = check_files()?;
    let h = fresh(&elf, "measure")?;
    let code = misalign::modbus::DEFAULT_UNLOCK_CODE.to_string();
    let args = [
        "--code".as_ref(),
        code.as_ref(),
        "--prepared".as_ref(),
        scene.as_os_str(),
        "--config".as_ref(),
        config.as_os_str(),
    ];
    crate::modbus::commission_py(&python, h.port, &registers, &args)?;
    let at = json_num(&h.command("status")?, "ns").unwrap_or(0.0);
    while json_num(&h.command("status")?, "ns").unwrap_or(0.0) < at + 60e9 {
        std::thread::sleep(Duration::from_millis(200));
    }
    // Every register read once (the requests' deepest frames).
    let dump = dir()?.join("measure-registers.csv");
    let args = [
        "--events-from".as_ref(),
        "0".as_ref(),
        "--events".as_ref(),
        dump.as_os_str(),
    ];
    crate::modbus::commission_py(&python, h.port, &registers, &args)?;
    let st = h.command("status")?;
    drop(h);
    let stack = json_num(&st, "stack").ok_or("the harness measured no stack")? as u64;
    let stack_reserved =
        json_num(&st, "stack_reserved").ok_or("the image reserves no stack")? as u64;
    if stack + STACK_HEADROOM > stack_reserved {
        return Err(format!(
            "the deepest stack, {stack} B, leaves less than {STACK_HEADROOM} B of its \
             {stack_reserved} B reservation (nodes/pico/memory.x): make it larger"
        ));
    }
    let row = crate::records::PicoRow {
        board: "Raspberry Pi Pico (RP2040, Cortex-M0+)".into(),
        flash: sections.flash(),
        ram: sections.ram(),
        stack,
        stack_reserved,
        board_ram: 256 * 1024,
        samples: json_num(&st, "samples").unwrap_or(0.0) as u64,
    };
    crate::records::write(&[row])?;
    crate::measurements::update()?;
    println!(
        "wrote docs/pico.csv and its table in {}",
        crate::measurements::PAGE
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows(text: &str) -> Vec<Vec<String>> {
        text.lines()
            .skip(1)
            .map(|l| l.split(',').map(str::to_string).collect())
            .collect()
    }

    #[test]
    fn the_drive_inverts_the_calibration_and_marks_what_a_sensor_cannot_read() {
        let site = board::SensorSettings {
            load_zero_counts: -3000.0,
            load_newtons_per_count: -0.01,
            probe1_zero_counts: 5000.0,
            probe2_metres_per_count: 1.2e-7,
            probe_span_m: 0.3,
            probe_zero_offset_m: 2e-6,
            tacho_pulses_per_rev: 360,
            tacho_radius_m: 0.08,
            ..board::SensorSettings::DEFAULT
        };
        for settings in [board::SensorSettings::DEFAULT, site] {
            inverts(&settings);
        }
    }

    fn inverts(settings: &board::SensorSettings) {
        let cal = board::calibration(settings).unwrap();
        let speed = cal.speed.unwrap();
        let mut samples = vec![
            Sample::new(1000, 2500.0, 2e-4).with_speed(2.0),
            Sample::new(1100, f32::NAN, 2e-4),
            Sample::new(1200, 2500.0, f32::NAN).with_speed(1.0),
        ];
        let d = rows(&drive_through(&samples, settings).unwrap());
        assert_eq!(d.len(), 3);
        assert_eq!(d[0][0], "0");
        assert_eq!(d[2][0], "200");
        // The load's code reads back as the load, to a code.
        let code: i32 = d[0][1].parse().unwrap();
        assert!((cal.load.newtons(code) - 2500.0).abs() <= cal.load.newtons_per_count.abs());
        // Probe 1 sits span * tan(phi) beyond probe 2: the angle back from the volts.
        let v1: f32 = d[0][2].parse().unwrap();
        let v2: f32 = d[0][3].parse().unwrap();
        let counts = |v: f32| (v / (board::ADS1115_FULL_SCALE_V / 32768.0)).round() as i32;
        let pr = cal.misalignment;
        let phi = pr.phi(pr.probe1.metres(counts(v1)), pr.probe2.metres(counts(v2)));
        assert!((phi - 2e-4).abs() < 3e-7, "{phi}");
        // The pulse rate of 2 m/s, held where the trace has no speed, then 1 m/s.
        let hz = |r: &Vec<String>| r[4].parse::<f64>().unwrap();
        let per_m = f64::from(speed.pulses_per_rev)
            / (2.0 * std::f64::consts::PI * f64::from(speed.radius_m));
        assert!((hz(&d[0]) - 2.0 * per_m).abs() < 1e-6);
        assert_eq!(hz(&d[1]), hz(&d[0]));
        assert!((hz(&d[2]) - per_m).abs() < 1e-6);
        // Unreadable values put their sensor at its rail.
        assert_eq!(d[1][5], "4");
        assert_eq!(d[2][5], "8");
        // A value held as long as the stuck time freezes its sensor from then on.
        let stuck = misalign::monitor::Config::default().stuck_ms;
        samples = (0..=stuck / 1000 + 1)
            .map(|s| Sample::new(s * 1000, 2500.0, 2e-4 + s as f32 * 1e-6))
            .collect();
        let d = rows(&drive_through(&samples, settings).unwrap());
        let frozen: Vec<bool> = d.iter().map(|r| r[5] == "1").collect();
        let first = frozen.iter().position(|&f| f).unwrap();
        assert_eq!(d[first][0].parse::<u32>().unwrap(), stuck);
        assert!(frozen[first..].iter().all(|&f| f) && !frozen[..first].iter().any(|&f| f));
    }

    #[test]
    fn the_uf2_pages_hold_the_flash_segments_and_nothing_else() {
        // A minimal ELF: one PT_LOAD of 300 bytes at 0x10000100, one in RAM.
        let mut elf = vec![0u8; 52 + 2 * 32];
        elf[..4].copy_from_slice(b"\x7fELF");
        elf[28..32].copy_from_slice(&52u32.to_le_bytes());
        elf[42..44].copy_from_slice(&32u16.to_le_bytes());
        elf[44..46].copy_from_slice(&2u16.to_le_bytes());
        let data_at = elf.len() as u32;
        elf.extend((0..300).map(|i| i as u8));
        for (k, paddr) in [(0usize, 0x1000_0100u32), (1, 0x2000_0000)] {
            let at = 52 + 32 * k;
            elf[at..at + 4].copy_from_slice(&1u32.to_le_bytes());
            elf[at + 4..at + 8].copy_from_slice(&data_at.to_le_bytes());
            elf[at + 12..at + 16].copy_from_slice(&paddr.to_le_bytes());
            elf[at + 16..at + 20].copy_from_slice(&300u32.to_le_bytes());
        }
        let pages = flash_image(&elf).unwrap();
        assert_eq!(
            pages.iter().map(|p| p.0).collect::<Vec<_>>(),
            [0x1000_0100, 0x1000_0200]
        );
        assert_eq!(pages[0].1[..4], [0, 1, 2, 3]);
        // The segment's byte 299 (299 mod 256 = 43) at 0x1000022b.
        assert_eq!(pages[1].1[43], 43);
        assert_eq!(pages[1].1[44], 0xff);
    }
}
