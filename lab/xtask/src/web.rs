//! `cargo xtask web`: the web console (`tools/web`, its binding `tools/web/wasm`).
//!
//! - no option: builds it into `target/web-console/dist`, a folder any static server
//!   serves (offline: nothing is fetched from elsewhere). The steps: the
//!   `wasm32-unknown-unknown` target (rustup), the binding crate in the profile `web`,
//!   wasm-bindgen's CLI at the binding's exact version (`cargo install`, into
//!   `target/tools`), the packages of `tools/web/package-lock.json` (`npm ci`), vite.
//! - `--serve PORT`: builds it and serves it on 127.0.0.1:PORT until killed.
//! - `--test`: the browser tests (`tools/web/test/browser.mjs`: Debian's Chromium,
//!   headless, driven by playwright-core) against the page `--serve` serves: the
//!   page's events and thresholds against the monitor example's files written here,
//!   the Node view against the node in QEMU (`cargo xtask modbus --serve`) through
//!   `tools/web/bridge.mjs` (all three started by docs/web.md's `sh serve` commands,
//!   as the page shows them, on free ports), a short pass of the replay with the page answering
//!   meanwhile; screenshots of the three views in `target/web-console/screenshots/`.
//! - `--measure [--rows N]`: what a browser downloads (gzip), the time to a usable page
//!   from the loopback, and an N-row trace (default 1 000 000) replayed in the page
//!   against the monitor example in the same run; writes `docs/web.csv` and its table.

use crate::measurements::web::{DOWNLOAD_TARGET, RATE_TARGET, READY_TARGET_MS};
use crate::records::{self, WebRow};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitCode, Stdio};
use std::time::{Duration, Instant};

/// What the build writes, under the workspace's target directory.
const OUT: &str = "target/web-console";

/// Chromium, Debian's (`apt-get install -y chromium`); `MISALIGN_CHROMIUM` another.
const CHROMIUM: &str = "/usr/bin/chromium";

/// `cargo xtask web`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// Build the page and serve it on 127.0.0.1:PORT until killed.
    #[arg(long, value_name = "PORT", conflicts_with_all = ["test", "measure"])]
    serve: Option<u16>,
    /// Run the browser tests (Chromium, headless) against the built page and a QEMU node.
    #[arg(long)]
    test: bool,
    /// Measure the download, the time to a usable page and the replay's rate against
    /// the monitor example; write docs/web.csv and its table.
    #[arg(long, conflicts_with = "test")]
    measure: bool,
    /// Rows of the trace --measure replays.
    #[arg(
        long,
        value_name = "N",
        default_value_t = 1_000_000,
        requires = "measure"
    )]
    rows: u64,
}

/// `cargo xtask web`.
pub fn run(args: &Args) -> ExitCode {
    let result = if let Some(port) = args.serve {
        serve(port)
    } else if args.test {
        browser_tests()
    } else if args.measure {
        measure(args.rows)
    } else {
        build().map(|dist| println!("built {}", dist.display()))
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask web: {e}");
            ExitCode::FAILURE
        }
    }
}

fn out() -> PathBuf {
    crate::root().join(OUT)
}

/// Runs `cmd`, its output on stderr; `Err` naming `what` unless it succeeds.
fn run_cmd(cmd: &mut Command, what: &str) -> Result<(), String> {
    let status = cmd
        .stdout(std::io::stderr())
        .status()
        .map_err(|e| format!("{what}: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("{what} failed: {status}"))
    }
}

/// The version of `krate` in Cargo.lock (the binding's wasm-bindgen: its CLI must match).
fn locked_version(krate: &str) -> Result<String, String> {
    let lock = std::fs::read_to_string(crate::root().join("Cargo.lock"))
        .map_err(|e| format!("Cargo.lock: {e}"))?;
    let mut lines = lock.lines();
    while let Some(line) = lines.next() {
        if line == format!("name = \"{krate}\"")
            && let Some(v) = lines.next().and_then(|l| l.strip_prefix("version = \""))
        {
            return Ok(v.trim_end_matches('"').to_string());
        }
    }
    Err(format!("Cargo.lock has no {krate}"))
}

/// wasm-bindgen's CLI at the binding's version, installed into `target/tools` if it is
/// not there (`cargo install`: built here, nothing prebuilt downloaded).
fn wasm_bindgen() -> Result<PathBuf, String> {
    let version = locked_version("wasm-bindgen")?;
    let root = crate::root().join("target/tools");
    let bin = root.join("bin/wasm-bindgen");
    let have = Command::new(&bin)
        .arg("--version")
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string());
    if have.as_deref() != Some(&format!("wasm-bindgen {version}")) {
        eprintln!("installing wasm-bindgen-cli {version} into target/tools (cargo install)");
        // Without the default features: no TLS, the CLI downloads nothing.
        run_cmd(
            crate::cross::cargo()
                .args(["install", "wasm-bindgen-cli", "--version", &version])
                .args(["--no-default-features", "--root"])
                .arg(&root),
            "cargo install wasm-bindgen-cli",
        )?;
    }
    Ok(bin)
}

/// The rustup target the binding builds for.
fn wasm_target() -> Result<(), String> {
    let installed = Command::new("rustup")
        .args(["target", "list", "--installed"])
        .output()
        .map_err(|e| format!("rustup: {e}"))?;
    if !String::from_utf8_lossy(&installed.stdout)
        .lines()
        .any(|l| l == "wasm32-unknown-unknown")
    {
        run_cmd(
            Command::new("rustup").args(["target", "add", "wasm32-unknown-unknown"]),
            "rustup target add wasm32-unknown-unknown",
        )?;
    }
    Ok(())
}

/// tools/web's packages as package-lock.json pins them (`npm ci`, unless the lock is
/// older than what npm installed from it).
fn npm_packages(web: &Path) -> Result<(), String> {
    let modified = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    let lock =
        modified(&web.join("package-lock.json")).ok_or("tools/web/package-lock.json missing")?;
    // npm keeps a copy of the lock as it installed it.
    let installed = modified(&web.join("node_modules/.package-lock.json"));
    if installed.is_none_or(|i| i < lock) {
        run_cmd(
            Command::new("npm")
                .args(["ci", "--no-audit", "--no-fund"])
                .current_dir(web),
            "npm ci (tools/web)",
        )?;
    }
    Ok(())
}

/// Builds the page: returns its folder.
pub fn build() -> Result<PathBuf, String> {
    let start = Instant::now();
    wasm_target()?;
    let bindgen = wasm_bindgen()?;
    run_cmd(
        crate::cross::cargo().args([
            "build",
            "-p",
            "misalign-web",
            "--target",
            "wasm32-unknown-unknown",
            "--profile",
            "web",
        ]),
        "cargo build -p misalign-web",
    )?;
    let (pkg, dist) = (out().join("pkg"), out().join("dist"));
    run_cmd(
        Command::new(&bindgen)
            .args(["--target", "web", "--out-dir"])
            .arg(&pkg)
            .arg(crate::root().join("target/wasm32-unknown-unknown/web/misalign_web.wasm")),
        "wasm-bindgen",
    )?;
    let web = crate::root().join("tools/web");
    npm_packages(&web)?;
    run_cmd(
        Command::new(web.join("node_modules/.bin/vite"))
            .args(["build", "--logLevel", "warn"])
            .current_dir(&web)
            .env("MISALIGN_WEB_PKG", &pkg)
            .env("MISALIGN_WEB_OUT", &dist),
        "vite build",
    )?;
    eprintln!(
        "built the web console in {:.0} s: {}",
        start.elapsed().as_secs_f64(),
        dist.display()
    );
    Ok(dist)
}

/// A file's type for the browser.
fn content_type(path: &Path) -> &'static str {
    match path.extension().and_then(|e| e.to_str()) {
        Some("html") => "text/html; charset=utf-8",
        Some("js" | "mjs") => "text/javascript; charset=utf-8",
        Some("css") => "text/css; charset=utf-8",
        Some("wasm") => "application/wasm",
        Some("svg") => "image/svg+xml",
        Some("png") => "image/png",
        Some("json") => "application/json",
        Some("csv") => "text/csv; charset=utf-8",
        _ => "application/octet-stream",
    }
}

/// One request of a static server over `dir`: GET and HEAD of its files.
fn answer(mut stream: TcpStream, dir: &Path) -> std::io::Result<()> {
    let mut reader = BufReader::new(stream.try_clone()?);
    let mut request = String::new();
    reader.read_line(&mut request)?;
    loop {
        let mut header = String::new();
        if reader.read_line(&mut header)? == 0 || header == "\r\n" || header == "\n" {
            break;
        }
    }
    let mut parts = request.split_whitespace();
    let (method, target) = (parts.next().unwrap_or(""), parts.next().unwrap_or("/"));
    let path = target.split(['?', '#']).next().unwrap_or("/");
    let relative = path.trim_start_matches('/');
    let relative = if relative.is_empty() {
        "index.html"
    } else {
        relative
    };
    let file = dir.join(relative);
    let inside = !relative.split('/').any(|c| c == ".." || c.is_empty());
    let body = if inside && (method == "GET" || method == "HEAD") {
        std::fs::read(&file).ok()
    } else {
        None
    };
    // The head and the body in one write: written piecewise, Nagle's algorithm and
    // the browser's delayed acknowledgements would hold each piece back.
    let response = match body {
        Some(body) => {
            let mut r = format!(
                "HTTP/1.1 200 OK\r\nContent-Type: {}\r\nContent-Length: {}\r\n\
                 Cache-Control: no-cache\r\nConnection: close\r\n\r\n",
                content_type(&file),
                body.len()
            )
            .into_bytes();
            if method == "GET" {
                r.extend_from_slice(&body);
            }
            r
        }
        None => {
            let text = format!("{path}: not found\n");
            format!(
                "HTTP/1.1 404 Not Found\r\nContent-Type: text/plain\r\nContent-Length: {}\r\n\
                 Connection: close\r\n\r\n{text}",
                text.len()
            )
            .into_bytes()
        }
    };
    stream.set_nodelay(true)?;
    stream.write_all(&response)?;
    stream.flush()
}

/// Serves `dir` on 127.0.0.1:`port` (0: any free port) from a thread; the port.
fn serve_dir(dir: PathBuf, port: u16) -> Result<u16, String> {
    let listener =
        TcpListener::bind(("127.0.0.1", port)).map_err(|e| format!("127.0.0.1:{port}: {e}"))?;
    let port = listener.local_addr().map_err(|e| e.to_string())?.port();
    std::thread::spawn(move || {
        for stream in listener.incoming().flatten() {
            let dir = dir.clone();
            std::thread::spawn(move || {
                let _ = answer(stream, &dir);
            });
        }
    });
    Ok(port)
}

/// `--serve PORT`.
fn serve(port: u16) -> Result<(), String> {
    let dist = build()?;
    serve_dir(dist, port)?;
    println!("serving on 127.0.0.1:{port}");
    loop {
        std::thread::park();
    }
}

/// A child process in its own process group, the group ended when dropped (a shell,
/// cargo and the xtask it runs; the node's QEMU ends with that xtask).
struct Running(Child);

impl Drop for Running {
    fn drop(&mut self) {
        let group = format!("-{}", self.0.id());
        let _ = Command::new("kill").args(["-KILL", "--", &group]).status();
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Spawns `cmd` in a process group of its own and waits until a line of its stdout
/// contains one of `ready` (its lines go on to stderr, prefixed with `tag`).
fn spawn_until(
    cmd: &mut Command,
    ready: &[&str],
    tag: &'static str,
    timeout: Duration,
) -> Result<Running, String> {
    use std::os::unix::process::CommandExt;
    let mut child = cmd
        .stdout(Stdio::piped())
        .process_group(0)
        .spawn()
        .map_err(|e| format!("{tag}: {e}"))?;
    let stdout = child.stdout.take().ok_or("no stdout")?;
    let running = Running(child);
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            eprintln!("  {tag}| {line}");
            let _ = tx.send(line);
        }
    });
    let start = Instant::now();
    loop {
        match rx.recv_timeout(Duration::from_millis(200)) {
            Ok(line) if ready.iter().any(|r| line.contains(r)) => return Ok(running),
            Ok(_) | Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                return Err(format!("{tag} stopped before it was ready"));
            }
        }
        if start.elapsed() > timeout {
            return Err(format!("{tag} not ready within {} s", timeout.as_secs()));
        }
    }
}

/// A free loopback port (bound, then released).
fn free_port() -> Result<u16, String> {
    let l = TcpListener::bind("127.0.0.1:0").map_err(|e| e.to_string())?;
    Ok(l.local_addr().map_err(|e| e.to_string())?.port())
}

/// The ports docs/web.md's commands use: the page's, the bridge's, the node's.
const PAGE_PORTS: [u16; 3] = [8080, 8502, 5020];

/// The commands of docs/web.md's `sh serve` blocks (each serves until stopped), one a
/// line, comments dropped, in the page's order.
fn page_commands() -> Result<Vec<String>, String> {
    let path = crate::root().join("docs/web.md");
    let page = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut commands = Vec::new();
    let mut inside = None;
    for line in page.lines() {
        match (&mut inside, line.trim_start().strip_prefix("```")) {
            (None, Some(info)) => inside = Some(info.split_whitespace().eq(["sh", "serve"])),
            (Some(_), Some(_)) => inside = None,
            (Some(true), None) => {
                let command = line.split(" #").next().unwrap_or("").trim();
                if !command.is_empty() && !command.starts_with('#') {
                    commands.push(command.to_string());
                }
            }
            _ => {}
        }
    }
    for port in PAGE_PORTS {
        if !commands.iter().any(|c| with_ports(c, &[(port, 0)]) != *c) {
            return Err(format!("docs/web.md: no `sh serve` command on port {port}"));
        }
    }
    Ok(commands)
}

/// `line` with each number that is one of `ports`' first members replaced by its
/// second.
fn with_ports(line: &str, ports: &[(u16, u16)]) -> String {
    let mut out = String::new();
    let mut digits = String::new();
    let flush = |digits: &mut String, out: &mut String| {
        let swapped = ports
            .iter()
            .find(|(from, _)| digits.parse() == Ok(*from))
            .map(|(_, to)| to.to_string());
        out.push_str(swapped.as_deref().unwrap_or(digits));
        digits.clear();
    };
    for c in line.chars() {
        if c.is_ascii_digit() {
            digits.push(c);
        } else {
            flush(&mut digits, &mut out);
            out.push(c);
        }
    }
    flush(&mut digits, &mut out);
    out
}

/// The monitor example's binary (built here, release).
fn monitor_example() -> Result<PathBuf, String> {
    run_cmd(
        crate::cross::cargo().args([
            "build",
            "--release",
            "--example",
            "monitor",
            "--example",
            "prepare",
        ]),
        "cargo build --example monitor",
    )?;
    Ok(crate::root().join("target/release/examples/monitor"))
}

/// Runs the monitor example with `args`.
fn monitor(example: &Path, args: &[&str]) -> Result<(), String> {
    let out = Command::new(example)
        .args(args)
        .stderr(Stdio::piped())
        .stdout(Stdio::null())
        .output()
        .map_err(|e| format!("monitor example: {e}"))?;
    if out.status.success() {
        Ok(())
    } else {
        Err(format!(
            "monitor {}: {}",
            args.join(" "),
            String::from_utf8_lossy(&out.stderr)
        ))
    }
}

/// A trace with every kind of bad row the monitor example's reader knows (a cell not
/// a number, no time, a time not finite, too few or too many fields, an unterminated
/// quote, bytes not UTF-8, a blank line, a line over 64 KiB, CRLF ends, a repeated
/// and a backward time) among rows that raise warnings and alarms.
pub fn bad_rows_trace() -> Vec<u8> {
    let mut t = b"t,P,phi,V,F\r\n".to_vec();
    for i in 0..6000u32 {
        let x = f64::from(i);
        let p = 2500.0 + 40.0 * (x / 7.0).sin();
        let phi = 1e-4 + 9e-4 * (std::f64::consts::PI * x / 4000.0).sin().abs();
        let row = match i % 499 {
            5 => format!("{x},abc,{phi},2.0,\r\n"),
            17 => format!(",{p},{phi},2.0,\r\n"),
            29 => format!("nan,{p},{phi},2.0,\r\n"),
            41 => format!("{x},{p}\r\n"),
            53 => format!("{x},{p},{phi},2.0,,7\r\n"),
            67 => format!("{x},\"{p},{phi},2.0,\r\n"),
            79 => "\r\n".to_string(),
            97 => format!("{},{p},{phi},2.0,\r\n", x - 1.0),
            131 => format!("{},{p},{phi},2.0,\r\n", x - 30.0),
            151 => format!("{x},{p},inf,2.0,\r\n"),
            173 => format!("{x},{p},{phi},2.0,{}\r\n", "9".repeat(70_000)),
            _ if i % 3 == 0 => format!("{x},{p},{phi},2.0,{}\r\n", 120.0 + x % 50.0),
            _ => format!("{x},{p},{phi},2.0,\r\n"),
        };
        t.extend_from_slice(row.as_bytes());
        if i % 499 == 191 {
            t.extend_from_slice(b"200.5,2500,\xff\xfe,2.0,\r\n");
        }
    }
    t
}

/// A long trace for the replay's rate: `rows` samples a second apart, the load
/// varying with noise, the misalignment drifting through the critical angle and back.
pub fn long_trace(rows: u64) -> String {
    let mut t = String::with_capacity(rows as usize * 36);
    t.push_str("t,P,phi,V\n");
    let mut rng = 0x2545_f491u32;
    for i in 0..rows {
        rng ^= rng << 13;
        rng ^= rng >> 17;
        rng ^= rng << 5;
        let noise = f64::from(rng) / f64::from(u32::MAX) - 0.5;
        let x = i as f64;
        let p = 2500.0 + 400.0 * (x / 3600.0).sin() + 20.0 * noise;
        let phi =
            1e-4 + 6e-4 * (1.0 - (std::f64::consts::TAU * x / 200_000.0).cos()) + 2e-6 * noise;
        t.push_str(&format!("{i},{p:.2},{phi:.4e},2\n"));
    }
    t
}

/// Writes `text` to `path` (its folder made).
fn write(path: &Path, text: impl AsRef<[u8]>) -> Result<(), String> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))
}

/// The files the browser tests compare the page with, written by the monitor
/// example (and examples/prepare.rs) into `dir`.
fn reference_files(dir: &Path) -> Result<(), String> {
    let example = monitor_example()?;
    let p = |name: &str| dir.join(name).to_string_lossy().into_owned();
    let plot = p("plot.svg");
    write(&dir.join("bad-rows.csv"), bad_rows_trace())?;
    write(
        &dir.join("scene.csv"),
        "R1,R2,G,nu,mu,length\n0.06,0.04,79.3e9,0.3,0.25,0.5\n",
    )?;
    let (trace, scene) = (p("bad-rows.csv"), p("scene.csv"));
    let inputs: [(&str, &[&str]); 2] = [
        ("builtin", &[]),
        ("bad-rows", &["--trace", &trace, "--scene", &scene]),
    ];
    for model in ["f32", "fixed", "reference"] {
        for (name, input) in inputs {
            let events = p(&format!("{name}-{model}.csv"));
            let table = p(&format!("thresholds-{name}-{model}.csv"));
            let files = ["--events", &events, "--plot", &plot, "--thresholds", &table];
            monitor(&example, &[&["--model", model], input, &files[..]].concat())?;
        }
    }
    // The scene the Node view commissions, prepared as tools/commission.py prepares
    // it for the f32 node: the node must run these bytes (their CRC).
    write(
        &dir.join("commission-scene.csv"),
        "R1,R2,G,nu,mu\n0.06,0.04,79.3e9,0.3,0.25\n",
    )?;
    run_cmd(
        Command::new(crate::root().join("target/release/examples/prepare"))
            .args(["--type", "auto", "--out"])
            .arg(dir.join("commission-scene.bin"))
            .args(["0.06", "0.04", "79.3e9", "0.3", "0.25"]),
        "examples/prepare",
    )?;
    write(&dir.join("trace-short.csv"), long_trace(600_000))?;
    // The Plan view's config.csv for the defaults is this file, byte for byte.
    crate::modbus::default_config(&p("default-config.csv"))?;
    Ok(())
}

/// Runs a script of tools/web/test with node, `env` added.
fn node_script(script: &str, env: &[(&str, String)]) -> Result<String, String> {
    let web = crate::root().join("tools/web");
    let mut cmd = Command::new("node");
    cmd.arg(web.join("test").join(script)).current_dir(&web);
    cmd.env(
        "MISALIGN_CHROMIUM",
        std::env::var("MISALIGN_CHROMIUM").unwrap_or_else(|_| CHROMIUM.into()),
    );
    for (k, v) in env {
        cmd.env(k, v);
    }
    let out = cmd
        .stderr(std::io::stderr())
        .output()
        .map_err(|e| format!("node {script}: {e}"))?;
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    if out.status.success() {
        Ok(stdout)
    } else {
        Err(format!("{script} failed ({}):\n{stdout}", out.status))
    }
}

/// `--test`.
fn browser_tests() -> Result<(), String> {
    let start = Instant::now();
    let files = out().join("test");
    reference_files(&files)?;
    // The page, the node in QEMU and the bridge, started by docs/web.md's own
    // commands (its `sh serve` blocks), its ports standing for free ones.
    let ports: Vec<(u16, u16)> = PAGE_PORTS
        .iter()
        .map(|&p| Ok((p, free_port()?)))
        .collect::<Result<_, String>>()?;
    let [(_, port), (_, ws_port), _] = ports[..] else {
        unreachable!("three ports")
    };
    let mut served = Vec::new();
    for command in page_commands()? {
        let line = with_ports(&command, &ports);
        served.push(spawn_until(
            Command::new("bash")
                .args(["-c", &line])
                .current_dir(crate::root()),
            &["serving on", "bridging"],
            "docs/web.md",
            Duration::from_secs(3600),
        )?);
    }
    let shots = out().join("screenshots");
    std::fs::create_dir_all(&shots).map_err(|e| e.to_string())?;
    let report = node_script(
        "browser.mjs",
        &[
            ("MISALIGN_WEB_URL", format!("http://127.0.0.1:{port}/")),
            ("MISALIGN_WEB_WS", format!("ws://127.0.0.1:{ws_port}")),
            ("MISALIGN_WEB_FILES", files.to_string_lossy().into_owned()),
            ("MISALIGN_WEB_SHOTS", shots.to_string_lossy().into_owned()),
        ],
    )?;
    print!("{report}");
    println!(
        "browser tests passed in {:.0} s; screenshots of the three views in {}",
        start.elapsed().as_secs_f64(),
        shots.display()
    );
    Ok(())
}

/// The gzip -9 size of `path` (B).
fn gzipped(path: &Path) -> Result<u64, String> {
    let mut child = Command::new("gzip")
        .args(["-9", "-c"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| format!("gzip: {e}"))?;
    let data = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut stdin = child.stdin.take().ok_or("gzip: no stdin")?;
    let writer = std::thread::spawn(move || stdin.write_all(&data));
    let mut compressed = Vec::new();
    child
        .stdout
        .take()
        .ok_or("gzip: no stdout")?
        .read_to_end(&mut compressed)
        .map_err(|e| e.to_string())?;
    let _ = writer.join();
    child.wait().map_err(|e| e.to_string())?;
    Ok(compressed.len() as u64)
}

/// Every file under `dir`.
fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).into_iter().flatten().flatten() {
        let p = entry.path();
        if p.is_dir() {
            out.extend(files_under(&p));
        } else {
            out.push(p);
        }
    }
    out
}

/// `--measure`.
fn measure(rows: u64) -> Result<(), String> {
    let dist = build()?;
    let (mut wasm, mut script) = (0, 0);
    for f in files_under(&dist) {
        let size = gzipped(&f)?;
        if f.extension().is_some_and(|e| e == "wasm") {
            wasm += size;
        } else {
            script += size;
        }
    }
    let dir = out().join("measure");
    let trace = dir.join(format!("trace-{rows}.csv"));
    if !trace.exists() {
        write(&trace, long_trace(rows))?;
    }
    let example = monitor_example()?;
    let events = dir.join("events.csv");
    let args = [
        "--trace",
        &trace.to_string_lossy(),
        "--events",
        &events.to_string_lossy(),
    ]
    .map(str::to_string);
    let time_example = || -> Result<f64, String> {
        let start = Instant::now();
        let a: Vec<&str> = args.iter().map(String::as_str).collect();
        monitor(&example, &a)?;
        Ok(start.elapsed().as_secs_f64())
    };
    let port = serve_dir(dist, 0)?;
    // Example, page, example: the best of each, on the same machine in the same run.
    let first = time_example()?;
    let page = node_script(
        "measure.mjs",
        &[
            ("MISALIGN_WEB_URL", format!("http://127.0.0.1:{port}/")),
            ("MISALIGN_WEB_TRACE", trace.to_string_lossy().into_owned()),
        ],
    )?;
    let second = time_example()?;
    let example_s = first.min(second);
    let field = |name: &str| -> Result<f64, String> {
        page.lines()
            .find_map(|l| l.strip_prefix(&format!("{name} ")))
            .and_then(|v| v.trim().parse().ok())
            .ok_or_else(|| format!("measure.mjs printed no {name}:\n{page}"))
    };
    let (ready_ms, page_s, pause_ms, idle_ms, samples) = (
        field("ready_ms")?,
        field("replay_s")?,
        field("longest_pause_ms")?,
        field("idle_longest_pause_ms")?,
        field("samples")?,
    );
    if samples as u64 != rows {
        return Err(format!("the page replayed {samples} samples of {rows}"));
    }
    let row = |quantity: &str, value: f64, unit: &str| WebRow {
        quantity: quantity.into(),
        value,
        unit: unit.into(),
    };
    let rate = |s: f64| (rows as f64 / s).round();
    let table = vec![
        row("download_wasm_gzip", wasm as f64, "B"),
        row("download_script_gzip", script as f64, "B"),
        row("ready", records::rounded(ready_ms), "ms"),
        row("replay_rows", rows as f64, "rows"),
        row("replay_page", rate(page_s), "rows/s"),
        row("replay_example", rate(example_s), "rows/s"),
        row("replay_longest_pause", records::rounded(pause_ms), "ms"),
        row("idle_longest_pause", records::rounded(idle_ms), "ms"),
    ];
    for r in &table {
        println!("{} {} {}", r.quantity, r.value, r.unit);
    }
    records::write(&table)?;
    crate::measurements::update()?;
    let total = wasm + script;
    let mut missed = Vec::new();
    if total > DOWNLOAD_TARGET {
        missed.push(format!("download {total} B > {DOWNLOAD_TARGET} B"));
    }
    if ready_ms >= READY_TARGET_MS {
        missed.push(format!("ready in {ready_ms} ms"));
    }
    if example_s / page_s < RATE_TARGET {
        missed.push(format!(
            "the page's rate {:.2} of the example's",
            example_s / page_s
        ));
    }
    if missed.is_empty() {
        Ok(())
    } else {
        Err(format!("targets missed: {}", missed.join("; ")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every kind of bad row is in the test trace, and the monitor example reads it
    /// as the browser tests expect: rows skipped, rows with a fault, events raised.
    #[test]
    fn the_bad_rows_trace_has_every_kind() {
        let bytes = bad_rows_trace();
        let mut trace = misalign_cli::monitor_input::Trace::new(&bytes[..]).unwrap();
        let samples = trace.by_ref().filter_map(Result::ok).count();
        assert!(samples > 5000, "{samples}");
        assert!(trace.skipped().count >= 5 * 12, "{:?}", trace.skipped());
        assert!(
            trace.unreadable().count >= 2 * 12,
            "{:?}",
            trace.unreadable()
        );
        let events =
            misalign_web::events_text(Some(&bytes), None, misalign_cli::replay::Model::F32)
                .unwrap();
        assert!(
            events.contains(",gross_slip,") && events.contains(",sensor_fault,"),
            "{events}"
        );
    }
}
