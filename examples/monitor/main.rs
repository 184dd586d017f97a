//! `cargo run --release --example monitor`: the condition monitor on the PC.
//!
//! Replays the built-in scenario (`misalign::monitor::scenario`: a press roller pair
//! over one shift whose misalignment drifts through the critical angle while the load
//! varies, with noise, spikes, a dropout, a stuck sensor and a stop) or a recorded
//! trace through `misalign::monitor::Monitor`; prints every event as it happens and a
//! summary table. See `--help`.

mod plot;

use misalign_cli::monitor_input as input;
use misalign_cli::monitor_output::{self as output, ThresholdRow};

use clap::{Parser, ValueEnum};
use misalign::Estimator;
use misalign::fixed::FixedAuto;
use misalign::float::Auto;
use misalign::monitor::{Config, Event, EventKind, Monitor, RiskState, Sample, scenario};
use std::error::Error;
use std::io::{IsTerminal, Write};
use std::path::PathBuf;

type Res<T> = Result<T, Box<dyn Error>>;

/// `println!` that ends the program quietly when stdout is closed (`| head`).
macro_rules! say {
    ($($arg:tt)*) => {{
        let mut out = std::io::stdout().lock();
        if writeln!(out, $($arg)*).is_err() {
            std::process::exit(0);
        }
    }};
}

/// Replays the built-in scenario (or a trace) through the condition monitor: risk
/// states, events, wear and time to critical.
#[derive(Parser, Debug)]
#[command(name = "monitor", about, long_about = None)]
struct Args {
    /// A recorded trace instead of the built-in scenario: CSV with columns `t` (s),
    /// `P` (N), `phi` (rad) and optionally `V` (m/s) and `F` (N); an empty `V` or `F`
    /// cell is "not measured" (nominal speed, estimated F), anything unreadable a
    /// sensor fault.
    #[arg(long, value_name = "FILE.csv")]
    trace: Option<PathBuf>,
    /// The scene: CSV with one row of `R1,R2,G,nu,mu` (m, m, Pa, -, -) and an
    /// optional `length` (m). Default: the demo scene (steel rollers of 50 mm radius,
    /// G = 79.3 GPa, nu = 0.3, mu = 0.3).
    #[arg(long, value_name = "FILE.csv")]
    scene: Option<PathBuf>,
    /// The estimator core: f32 (Cortex-M4F) or fixed (Cortex-M0/M3).
    #[arg(long, value_enum, default_value_t = Model::F32)]
    model: Model,
    /// Writes every event as a CSV row (t,seq,state,...).
    #[arg(long, value_name = "OUT.csv")]
    events: Option<PathBuf>,
    /// Draws d/b, the margin, F and the states over time with the events marked (SVG).
    #[arg(long, value_name = "OUT.svg")]
    plot: Option<PathBuf>,
    /// With --plot: for the scene over a load range, the critical angle phi0(P) and
    /// the misalignment at which each state triggers and clears (CSV; its figure is
    /// written beside the plot as *-thresholds.svg).
    #[arg(long, value_name = "OUT.csv", requires = "plot")]
    thresholds: Option<PathBuf>,
}

#[derive(Clone, Copy, Debug, PartialEq, ValueEnum)]
enum Model {
    /// The f32 core, model chosen for the operating range (section 9).
    F32,
    /// The fixed-point core.
    Fixed,
}

/// One point of the plotted series.
#[derive(Clone, Copy, Debug)]
pub struct Point {
    /// Time since the start (s).
    pub t: f64,
    pub slip_ratio: f32,
    pub margin: Option<f32>,
    pub force: f32,
    pub state: RiskState,
    /// Whether this sample gave a new reading (not stopped, not faulted).
    pub fresh: bool,
    pub load: f32,
    pub phi: f32,
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

/// What a replay leaves: the events, the series and the final monitor.
struct Replay<E> {
    monitor: Monitor<E>,
    events: Vec<Event>,
    points: Vec<Point>,
}

/// How a monitor takes a sample: `Monitor::process_with_friction` on the f32 core
/// (mu from a measured F), `Monitor::process` on the fixed-point core (no inverse).
type Step<E> = fn(&mut Monitor<E>, Sample) -> RiskState;

fn replay<E: Estimator>(
    mut monitor: Monitor<E>,
    step: Step<E>,
    samples: impl Iterator<Item = Sample>,
    total: usize,
) -> Replay<E> {
    let progress = std::io::stderr().is_terminal() && total >= 10_000;
    let mut events = Vec::new();
    let mut points = Vec::new();
    let mut last_percent = usize::MAX;
    let mut last_reading = None;
    for (i, sample) in samples.enumerate() {
        let state = step(&mut monitor, sample);
        while let Some(e) = monitor.pop_event() {
            say!("{}", event_line(&e));
            events.push(e);
        }
        // A point only for a new reading (not while stopped or faulted): the figure
        // shows gaps there, not the last value held.
        let reading = monitor.reading();
        let fresh = reading.is_some() && reading != last_reading;
        last_reading = reading;
        let r = reading.unwrap_or_default();
        {
            points.push(Point {
                fresh,
                t: monitor.elapsed_ms() as f64 / 1e3,
                slip_ratio: r.slip_ratio,
                margin: r.margin,
                force: r.axial_force,
                state,
                load: r.load,
                phi: r.phi,
            });
        }
        if progress {
            let percent = (i + 1) * 100 / total.max(1);
            if percent != last_percent {
                last_percent = percent;
                let bar = "#".repeat(percent / 4) + &" ".repeat(25 - percent / 4);
                eprint!("\r[{bar}] {percent:>3} %");
            }
        }
    }
    if progress {
        eprintln!();
    }
    Replay {
        monitor,
        events,
        points,
    }
}

fn hms(ms: u64) -> String {
    let s = ms / 1000;
    format!("{}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60)
}

fn summary<E: Estimator>(m: &Monitor<E>) {
    let s = m.statistics();
    let total_ms: u64 = RiskState::ALL
        .iter()
        .map(|&st| s.time_in_state_ms(st))
        .sum();
    say!(
        "\n{:<14} {:>10} {:>7} {:>14}",
        "state",
        "time",
        "%",
        "energy (J)"
    );
    for state in RiskState::ALL {
        let ms = s.time_in_state_ms(state);
        say!(
            "{:<14} {:>10} {:>6.1}% {:>14.3}",
            state.as_str(),
            hms(ms),
            100.0 * ms as f64 / total_ms.max(1) as f64,
            s.energy_j(state)
        );
    }
    say!(
        "{:<14} {:>10} {:>7} {:>14.3}",
        "total",
        hms(total_ms),
        "",
        s.total_energy()
    );
    let f = s.faults();
    say!(
        "\nsamples {}  repeated timestamps {}  spikes rejected {}  events dropped {}",
        s.samples(),
        s.repeated_timestamps(),
        s.spikes(),
        s.events_dropped()
    );
    say!(
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
            "friction mu {mu:.4}  baseline {}  {} estimates used, {} ill-posed{}",
            m.friction_baseline()
                .map_or("- (not captured yet)".into(), |b| format!("{b:.4}")),
            fs.accepted(),
            fs.rejected(),
            if fs.changed() { "  CHANGED" } else { "" }
        );
    }
    say!(
        "final state {}  time to critical {}",
        m.state().as_str(),
        m.time_to_critical()
            .map_or("- (margin not falling)".into(), |t| format!(
                "{:.0} min",
                t / 60.0
            ))
    );
}

fn run<E: Estimator>(
    core: E,
    step: Step<E>,
    args: &Args,
    samples: Vec<Sample>,
    builtin: bool,
) -> Res<()> {
    let config = Config::default();
    let total = samples.len();
    let table = args.thresholds.as_ref().map(|_| {
        // The load range the trace covers: up to its 99.9th percentile, so that a
        // spike does not stretch it.
        let mut loads: Vec<f32> = samples
            .iter()
            .map(|s| s.load)
            .filter(|l| l.is_finite())
            .collect();
        loads.sort_by(f32::total_cmp);
        let load_max = loads.get(loads.len() * 999 / 1000).copied().unwrap_or(0.0) * 1.2;
        output::threshold_rows(&core, &config, load_max)
    });
    let monitor = Monitor::new(core, config).map_err(|e| format!("configuration: {e}"))?;
    if builtin {
        say!(
            "built-in scenario: one 8 h shift of a press roller pair (see misalign::monitor::scenario)"
        );
    }
    say!("{:>9}    {:<4} {:<42}", "t", "seq", "event");
    let r = replay(monitor, step, samples.into_iter(), total);
    summary(&r.monitor);
    if let Some(path) = &args.events {
        let out = output::events_csv(&r.events);
        std::fs::write(path, out)?;
        eprintln!("wrote {}", path.display());
    }
    if let Some(path) = &args.plot {
        plot::timeline(path, &r.points, &r.events)?;
        eprintln!("wrote {}", path.display());
    }
    if let (Some(path), Some(table)) = (&args.thresholds, table) {
        let out = output::thresholds_csv(&table);
        std::fs::write(path, out)?;
        eprintln!("wrote {}", path.display());
        if let Some(plot_path) = &args.plot {
            let svg = plot_path.with_file_name(format!(
                "{}-thresholds.svg",
                plot_path
                    .file_stem()
                    .and_then(|s| s.to_str())
                    .unwrap_or("monitor")
            ));
            plot::thresholds(&svg, &table, &r.points)?;
            eprintln!("wrote {}", svg.display());
        }
    }
    Ok(())
}

fn main() -> std::process::ExitCode {
    let args = Args::parse();
    let result = (|| -> Res<()> {
        let scene = match &args.scene {
            Some(path) => input::read_scene(std::fs::File::open(path)?)?,
            None => scenario::scene()?,
        };
        let (samples, builtin) = match &args.trace {
            Some(path) => (input::read_trace(std::fs::File::open(path)?)?, false),
            None => (scenario::Scenario::new().collect::<Vec<_>>(), true),
        };
        let load_max = samples
            .iter()
            .map(|s| f64::from(s.load))
            .filter(|l| l.is_finite())
            .fold(scenario::LOAD_MAX, f64::max);
        // One model for the trace's operating range (section 9, decided once), as the
        // node builds it for the built-in scenario.
        match args.model {
            Model::F32 => run(
                scenario::estimator_for::<Auto>(&scene, load_max)?,
                Monitor::process_with_friction,
                &args,
                samples,
                builtin,
            ),
            Model::Fixed => run(
                scenario::estimator_for::<FixedAuto>(&scene, load_max)?,
                Monitor::process,
                &args,
                samples,
                builtin,
            ),
        }
    })();
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            let _ = std::io::stdout().flush();
            eprintln!("monitor: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}
