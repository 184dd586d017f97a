//! `cargo run --release --example monitor`: the condition monitor on the PC.
//!
//! Replays the built-in scenario (`misalign::monitor::scenario`: a press roller pair
//! over one shift whose misalignment drifts through the critical angle while the load
//! varies, with noise, spikes, a dropout, a stuck sensor and a stop) or a recorded
//! trace through `misalign::monitor::Monitor`; prints every event as it happens and a
//! summary table. The example is a thin `main` over [`run`].
//!
//! A trace is read twice, row by row, in memory that does not grow with its length: a
//! first pass checks its times and finds its load range (the model is chosen once for
//! it, section 9 of "The rolling contact of misaligned elastic cylinders"), the second
//! replays it. The events go to their file as they happen; the figures keep a bounded
//! summary of the replay ([`series`]).

mod plot;
pub mod series;

use crate::monitor_input as input;
use crate::monitor_output::{self as output, EventsWriter};
use crate::replay::{self, Model, Replay, Samples, Survey};
use crate::table;
use clap::Parser;
use misalign::monitor::{Event, EventKind, RiskState, scenario};
use series::{Decimated, Timeline};
use std::error::Error;
use std::fs::File;
use std::io::{BufReader, BufWriter, Write};
use std::path::{Path, PathBuf};

type Res<T> = Result<T, Box<dyn Error>>;

const AFTER_HELP: &str = "\
TRACE: a row without a usable time (t empty, not a number or not finite; a field count
    other than the header's; an unterminated quote) is skipped; the skipped rows are
    counted and the first few named in the summary and on stderr. A row with a time but
    a P, phi, V or F cell that is not a number becomes a sample with that value not
    finite, which the monitor counts as a sensor fault; an optional `fault` column names
    a sensor's own fault as a node reports it (load, probe1, probe2 or speed, a colon,
    and disconnected, bus, saturated, stuck, jump or out_of_range: what `cargo xtask
    pico --samples` writes). A time the monitor's clock cannot
    represent refuses the trace before the replay, naming the row: beyond 2^53 ms (t in
    ns, say), or a step of 2^31 ms (24.8 days) or more between rows, which the node's
    wrapping u32 millisecond counter cannot tell from a shorter one. Times within the
    counter's range (0 to 2^32 ms) are read as the counter: a wrap is a step forward.

FILES: read by the estimator's rules: each column once (a repeated one is an error
    naming it), any order, other columns ignored; a ';'-separated file is read so (said
    on stderr; numbers need a decimal point); a scene value that is not a number names
    its column and row.

EXIT STATUS: 0; 1 when a file cannot be read, lacks a column or repeats one, the scene
    is refused or a trace's time cannot be represented; 2 for bad options.";

/// Replays the built-in scenario (or a trace) through the condition monitor: risk
/// states, events, wear and time to critical.
#[derive(Parser, Debug)]
#[command(name = "monitor", long_about = None, after_help = AFTER_HELP)]
struct Args {
    /// A recorded trace instead of the built-in scenario: CSV with columns `t` (s),
    /// `P` (N), `phi` (rad) and optionally `V` (m/s) and `F` (N); an empty `V` or `F`
    /// cell is "not measured" (nominal speed, estimated F). See TRACE below.
    #[arg(long, value_name = "FILE.csv")]
    trace: Option<PathBuf>,
    /// The scene: CSV with one row of `R1,R2,G,nu,mu` (m, m, Pa, -, -) and an
    /// optional `length` (m). Default: the demo scene (steel rollers of 50 mm radius,
    /// G = 79.3 GPa, nu = 0.3, mu = 0.3).
    #[arg(long, value_name = "FILE.csv")]
    scene: Option<PathBuf>,
    /// The estimator core: f32 (Cortex-M4F), fixed (Cortex-M0/M3), or the f64
    /// reference (the PC only: the events of the physics without a core's rounding).
    #[arg(long, value_enum, default_value_t = Model::F32)]
    model: Model,
    /// Writes every event as a CSV row (t,seq,state,...).
    #[arg(long, value_name = "OUT.csv")]
    events: Option<PathBuf>,
    /// Draws d/b, the margin, F and the states over time with the events marked (SVG;
    /// each pixel column shows the lowest and highest value in it).
    #[arg(long, value_name = "OUT.svg")]
    plot: Option<PathBuf>,
    /// For the scene over a load range, the critical angle phi0(P) and the
    /// misalignment at which each state triggers and clears (CSV; with --plot, its
    /// figure is written beside the plot as *-thresholds.svg).
    #[arg(long, value_name = "OUT.csv")]
    thresholds: Option<PathBuf>,
}

/// stdout closed (`| head`): the run ends quietly.
#[derive(Debug)]
struct Closed;

impl std::fmt::Display for Closed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("stdout closed")
    }
}

impl Error for Closed {}

/// `writeln!` to the log, a failed write [`Closed`].
macro_rules! say {
    ($out:expr, $($arg:tt)*) => {
        writeln!($out, $($arg)*).map_err(|_| Closed)?
    };
}

fn event_line(e: &Event) -> String {
    let r = &e.reading;
    let mrad = |x: Option<f32>| x.map_or("-".into(), |x| format!("{:.3}", x * 1e3));
    let what = match e.kind {
        EventKind::StateChange { from, to, fault } => {
            let cause = fault.map_or(String::new(), |f| format!(" ({f:?})"));
            format!("{} -> {}{cause}", from.as_str(), to.as_str())
        }
        EventKind::Approaching { time_to_critical_s } => {
            format!(
                "approaching: gross slip in {:.0} min at this drift",
                time_to_critical_s / 60.0
            )
        }
        EventKind::Friction { mu, changed } => {
            let what = if changed { "changed" } else { "back in band" };
            format!("friction {what}: mu {mu:.3}")
        }
        EventKind::Fieldbus(f) => format!("fieldbus: {}", f.as_str()),
    };
    format!(
        "{:>9.1} s  #{:<3} {what:<42} d/b {:.3}  F {:.1} N  P {:.0} N  phi {:.3} mrad  phi0 {} mrad  margin {} mrad",
        e.elapsed_ms as f64 / 1e3,
        e.seq,
        r.slip_ratio,
        r.axial_force,
        r.load,
        r.phi * 1e3,
        mrad(r.critical_angle),
        mrad(r.margin),
    )
}

/// The samples of a run: the built-in scenario or `trace`, read from its start.
fn open(trace: Option<&Path>) -> Res<Samples<BufReader<File>>> {
    Ok(match trace {
        None => Samples::builtin(),
        Some(path) => {
            let file = File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
            Samples::trace(BufReader::new(file)).map_err(|e| format!("{}: {e}", path.display()))?
        }
    })
}

/// The first pass (`replay::Survey`), the trace's errors naming its file.
fn survey(args: &Args, err: &mut dyn Write) -> Res<Survey> {
    let samples = open(args.trace.as_deref())?;
    if samples.as_trace().is_some_and(|t| t.delimiter() == b';') {
        let _ = writeln!(err, "monitor: trace: {}", table::SEMICOLON_NOTE);
    }
    let at = |e: String| match &args.trace {
        Some(path) => format!("{}: {e}", path.display()),
        None => e,
    };
    Ok(Survey::of(samples, args.thresholds.is_some()).map_err(at)?)
}

fn hms(ms: u64) -> String {
    let s = ms / 1000;
    format!("{}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60)
}

fn summary(out: &mut dyn Write, m: &Replay) -> Res<()> {
    let s = m.statistics();
    let total_ms: u64 = RiskState::ALL
        .iter()
        .map(|&st| s.time_in_state_ms(st))
        .sum();
    say!(
        out,
        "\n{:<14} {:>10} {:>7} {:>14}",
        "state",
        "time",
        "%",
        "energy (J)"
    );
    for state in RiskState::ALL {
        let ms = s.time_in_state_ms(state);
        say!(
            out,
            "{:<14} {:>10} {:>6.1}% {:>14.3}",
            state.as_str(),
            hms(ms),
            100.0 * ms as f64 / total_ms.max(1) as f64,
            s.energy_j(state)
        );
    }
    say!(
        out,
        "{:<14} {:>10} {:>7} {:>14.3}",
        "total",
        hms(total_ms),
        "",
        s.total_energy()
    );
    let f = s.faults();
    say!(
        out,
        "\nsamples {}  repeated timestamps {}  spikes rejected {}  events dropped {}",
        s.samples(),
        s.repeated_timestamps(),
        s.spikes(),
        s.events_dropped()
    );
    say!(
        out,
        "faults {}: non-finite {}, out of range {}, stuck {}, gap {}, time backwards {}, driver {}, estimator {}, sensors {}",
        f.total(),
        f.non_finite,
        f.out_of_range,
        f.stuck,
        f.gap,
        f.time_backwards,
        f.driver,
        f.estimator,
        f.sensor
    );
    say!(
        out,
        "max d/b {:.3}  max |F| {:.1} N  min margin {}",
        s.max_slip_ratio(),
        s.max_axial_force(),
        s.min_margin()
            .map_or("-".into(), |m| format!("{:.3} mrad", m * 1e3))
    );
    // Only with a measured F on the f32 core.
    if let Some(mu) = m.friction() {
        let fs = m.friction_status();
        say!(
            out,
            "friction mu {mu:.4}  baseline {}  {} estimates used, {} ill-posed{}",
            m.friction_baseline()
                .map_or("- (not captured yet)".into(), |b| format!("{b:.4}")),
            fs.accepted(),
            fs.rejected(),
            if fs.changed() { "  CHANGED" } else { "" }
        );
    }
    say!(
        out,
        "final state {}  time to critical {}",
        m.state().as_str(),
        m.time_to_critical().map_or(
            "- (no credible fall of the margin ahead)".into(),
            |t| format!("{:.0} min", t / 60.0)
        )
    );
    Ok(())
}

/// Where the run writes: the log, diagnostics, and whether stderr shows a progress bar.
struct Io<'a> {
    out: &'a mut dyn Write,
    err: &'a mut dyn Write,
    progress: bool,
}

/// The example's side of the second pass: each event printed, written to `--events`
/// and marked on the timeline; each sample on the timeline; the progress bar.
struct Output<'a, 'b> {
    io: &'a mut Io<'b>,
    events: Option<EventsWriter<BufWriter<File>>>,
    timeline: Timeline,
    operating: Decimated<(f32, f32)>,
    /// Samples in the trace and done, the last percentage drawn; `None`: no bar.
    progress: Option<(u64, u64, u64)>,
}

impl replay::Sink for Output<'_, '_> {
    fn event(&mut self, e: &Event) -> Res<()> {
        say!(self.io.out, "{}", event_line(e));
        if let Some(w) = &mut self.events {
            w.event(e)?;
        }
        self.timeline.event(e.elapsed_ms, &e.kind);
        Ok(())
    }

    fn sample(&mut self, replay: &Replay, state: RiskState) -> Res<()> {
        let reading = replay.reading();
        if self.timeline.add(replay.elapsed_ms(), state, reading)
            && let Some(r) = reading
        {
            self.operating.add((r.load, r.phi.abs()));
        }
        if let Some((total, done, last_percent)) = &mut self.progress {
            *done += 1;
            let percent = *done * 100 / (*total).max(1);
            if percent != *last_percent {
                *last_percent = percent;
                let bar = "#".repeat(percent as usize / 4) + &" ".repeat(25 - percent as usize / 4);
                let _ = write!(self.io.err, "\r[{bar}] {percent:>3} %");
            }
        }
        Ok(())
    }
}

fn run_replay(mut replay: Replay, args: &Args, total: u64, io: &mut Io<'_>) -> Res<()> {
    if args.trace.is_none() {
        say!(
            io.out,
            "built-in scenario: one 8 h shift of a press roller pair (see misalign::monitor::scenario)"
        );
    }
    say!(io.out, "{:>9}    {:<4} {:<42}", "t", "seq", "event");
    let events = match &args.events {
        Some(path) => {
            let file = File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
            Some(EventsWriter::new(BufWriter::new(file))?)
        }
        None => None,
    };
    let progress = io.progress && total >= 10_000;
    let mut samples = open(args.trace.as_deref())?;
    let mut output = Output {
        io,
        events,
        timeline: Timeline::new(),
        operating: Decimated::default(),
        progress: progress.then_some((total, 0, u64::MAX)),
    };
    replay::run(&mut replay, &mut samples, &mut output)?;
    let Output {
        io,
        events,
        timeline,
        operating,
        ..
    } = output;
    if progress {
        let _ = writeln!(io.err);
    }
    summary(io.out, &replay)?;
    if let Some(t) = samples.as_trace() {
        let (skipped, unreadable) = (t.skipped(), t.unreadable());
        say!(
            io.out,
            "trace rows skipped (no usable time) {}\ntrace rows with a cell not a number (sensor faults) {}",
            skipped.describe(),
            unreadable.describe()
        );
        if skipped.count > 0 {
            let _ = writeln!(
                io.err,
                "monitor: skipped {} trace rows without a usable time: {}",
                skipped.count,
                skipped.describe()
            );
        }
    }
    if let (Some(w), Some(path)) = (events, &args.events) {
        w.into_inner()
            .into_inner()
            .map_err(|e| e.into_error())?
            .sync_all()?;
        let _ = writeln!(io.err, "wrote {}", path.display());
    }
    if let Some(path) = &args.plot {
        let source = match &args.trace {
            Some(trace) => trace.file_name().map_or_else(
                || trace.display().to_string(),
                |n| n.to_string_lossy().into_owned(),
            ),
            None => "the built-in 8 h scenario".to_string(),
        };
        plot::timeline(path, &timeline, &replay.config().thresholds, &source)?;
        let _ = writeln!(io.err, "wrote {}", path.display());
    }
    if let Some(path) = &args.thresholds {
        let plan = replay
            .thresholds()
            .ok_or("--thresholds: the loads were not counted")?
            .map_err(|e| format!("--thresholds: {e}"))?;
        if let Some(note) = &plan.note {
            let _ = writeln!(io.err, "monitor: --thresholds: {note}");
        }
        let table = plan.rows;
        std::fs::write(path, output::thresholds_csv(&table))?;
        let _ = writeln!(io.err, "wrote {}", path.display());
        // Its figure beside the run's plot, when there is one.
        if let Some(plot_path) = &args.plot {
            let svg = plot_path.with_file_name(format!(
                "{}-thresholds.svg",
                plot_path
                    .file_stem()
                    .and_then(|s| s.to_str())
                    .unwrap_or("monitor")
            ));
            plot::thresholds(&svg, &table, operating.points())?;
            let _ = writeln!(io.err, "wrote {}", svg.display());
        }
    }
    Ok(())
}

fn run_parsed(args: &Args, io: &mut Io<'_>) -> Res<()> {
    let scene = match &args.scene {
        Some(path) => {
            let file = File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
            let (scene, delimiter) =
                input::scene_and_delimiter(file).map_err(|e| format!("{}: {e}", path.display()))?;
            if delimiter == b';' {
                let _ = writeln!(io.err, "monitor: scene: {}", table::SEMICOLON_NOTE);
            }
            scene
        }
        None => scenario::scene()?,
    };
    let mut survey = survey(args, io.err)?;
    // One model for the trace's operating range (section 9, decided once), as the
    // node builds it for the built-in scenario.
    let replay = Replay::new(args.model, &scene, &mut survey)?;
    run_replay(replay, args, survey.total, io)
}

/// Runs the monitor example with `args` (without the program's name): the log to
/// `out`, diagnostics to `err`, a progress bar on `err` when `progress`; returns the
/// exit code.
pub fn run(args: &[String], out: &mut dyn Write, err: &mut dyn Write, progress: bool) -> i32 {
    let args =
        match Args::try_parse_from(std::iter::once("monitor".into()).chain(args.iter().cloned())) {
            Ok(a) => a,
            Err(e) => {
                let text = e.render().to_string();
                return match e.kind() {
                    clap::error::ErrorKind::DisplayHelp
                    | clap::error::ErrorKind::DisplayVersion => {
                        let _ = out.write_all(text.as_bytes());
                        0
                    }
                    _ => {
                        let _ = write!(err, "{text}");
                        2
                    }
                };
            }
        };
    let mut io = Io { out, err, progress };
    let result = run_parsed(&args, &mut io);
    let _ = io.out.flush();
    match result {
        Ok(()) => 0,
        Err(e) if e.is::<Closed>() => 0,
        Err(e) => {
            let _ = writeln!(io.err, "monitor: {e}");
            1
        }
    }
}
