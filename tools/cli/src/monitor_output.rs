//! What `cargo run --example monitor` writes besides its log: every event as a row of
//! `--events` ([`event_record`], [`events_csv`]) and the threshold planner of
//! `--thresholds` ([`threshold_plan`], [`thresholds_csv`]). The Python package's replay
//! and planner call the same functions, so that their columns are these files' cells.

use misalign::Estimator;
use misalign::monitor::{Config, Event, EventKind, Reading, Thresholds};

/// The header of the `--events` CSV.
pub const EVENTS_HEADER: &str =
    "t,seq,state,from,kind,fault,P,phi,s,F,phi0,margin,time_to_critical,time_ms";

/// The header of the `--thresholds` CSV (P in N, the angles in rad).
pub const THRESHOLDS_HEADER: &str =
    "P,phi0,phi_warning,phi_warning_clear,phi_alarm,phi_alarm_clear";

/// One event as the cells of an `--events` row.
#[derive(Debug, Clone, PartialEq)]
pub struct EventRecord {
    /// Time since the start (s).
    pub t: f64,
    /// The event's sequence number.
    pub seq: u32,
    /// The state entered; for a friction event the filtered mu (`mu=0.3`).
    pub state: String,
    /// The state left (empty but for a state change).
    pub from: &'static str,
    /// `state`, `approaching`, `friction_changed` or `friction_cleared`.
    pub kind: &'static str,
    /// The fault that caused a state change (its `Debug` name), else empty.
    pub fault: String,
    /// The reading the event carries; `None` for a friction event, whose row leaves
    /// the reading's cells empty.
    pub reading: Option<Reading>,
    /// Time to critical (s) of an `approaching` event.
    pub time_to_critical_s: Option<f32>,
    /// The node's millisecond counter at the event.
    pub time_ms: u32,
}

/// The cells of `e`'s `--events` row.
pub fn event_record(e: &Event) -> EventRecord {
    let (state, from, kind, fault, time_to_critical_s, reading) = match e.kind {
        EventKind::StateChange { from, to, fault } => (
            to.as_str().to_string(),
            from.as_str(),
            "state",
            fault.map_or(String::new(), |f| format!("{f:?}")),
            None,
            Some(e.reading),
        ),
        EventKind::Approaching { time_to_critical_s } => (
            String::new(),
            "",
            "approaching",
            String::new(),
            Some(time_to_critical_s),
            Some(e.reading),
        ),
        // The filtered mu in the state column.
        EventKind::Friction { mu, changed } => (
            format!("mu={mu}"),
            "",
            if changed {
                "friction_changed"
            } else {
                "friction_cleared"
            },
            String::new(),
            None,
            None,
        ),
        // The link's, not the machine's: no reading of its own.
        EventKind::Fieldbus(f) => (String::new(), "", f.as_str(), String::new(), None, None),
    };
    EventRecord {
        t: e.elapsed_ms as f64 / 1e3,
        seq: e.seq,
        state,
        from,
        kind,
        fault,
        reading,
        time_to_critical_s,
        time_ms: e.time_ms,
    }
}

/// `e` as a row of the `--events` CSV (no line end): numbers as Rust prints them, an
/// absent value an empty cell.
pub fn event_row(e: &Event) -> String {
    let rec = event_record(e);
    let opt = |x: Option<f32>| x.map_or(String::new(), |x| x.to_string());
    let cells = rec.reading.map_or_else(
        || [const { String::new() }; 6],
        |r| {
            [
                r.load.to_string(),
                r.phi.to_string(),
                r.slip_ratio.to_string(),
                r.axial_force.to_string(),
                opt(r.critical_angle),
                opt(r.margin),
            ]
        },
    );
    format!(
        "{},{},{},{},{},{},{},{},{}",
        rec.t,
        rec.seq,
        rec.state,
        rec.from,
        rec.kind,
        rec.fault,
        cells.join(","),
        opt(rec.time_to_critical_s),
        rec.time_ms,
    )
}

/// The `--events` CSV: header and one line per event.
pub fn events_csv(events: &[Event]) -> String {
    let mut out = format!("{EVENTS_HEADER}\n");
    for e in events {
        out += &event_row(e);
        out.push('\n');
    }
    out
}

/// The `--events` file written as the events happen: the header first, then a line
/// per event.
#[derive(Debug)]
pub struct EventsWriter<W: std::io::Write>(W);

impl<W: std::io::Write> EventsWriter<W> {
    /// The file with its header.
    ///
    /// # Errors
    /// The writer's.
    pub fn new(mut out: W) -> std::io::Result<Self> {
        writeln!(out, "{EVENTS_HEADER}")?;
        Ok(EventsWriter(out))
    }

    /// One event's line.
    ///
    /// # Errors
    /// The writer's.
    pub fn event(&mut self, e: &Event) -> std::io::Result<()> {
        writeln!(self.0, "{}", event_row(e))
    }

    /// The writer, the file complete.
    pub fn into_inner(self) -> W {
        self.0
    }
}

/// The misalignment (rad) at which d/b reaches `target` at `load`, by bisection
/// (d/b grows with |phi|); `None` if it does not below `hi`.
pub fn angle_for_slip_ratio<E: Estimator>(
    core: &E,
    load: f32,
    target: f32,
    hi: f32,
) -> Option<f32> {
    let s = |phi: f32| core.estimate_si(load, phi).ok().map(|e| e.slip_ratio);
    if s(hi)? < target {
        return None;
    }
    let (mut lo, mut hi) = (0.0f32, hi);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if s(mid)? < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(hi)
}

/// A row of the threshold planner: P (N), phi0, and the misalignment (rad) at which
/// the warning is raised, cleared, the alarm raised, cleared (NaN where none is).
pub type ThresholdRow = [f64; 6];

/// Where the planner's loads end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PlanRange {
    /// Up to this load (N), as asked: refused unless above the stop load and within
    /// the configuration's `load_max`.
    UpTo(f32),
    /// Up to 1.2 times a trace's 99.9th percentile of load (N; `None` for a trace
    /// without a finite load), so that a spike does not stretch it; kept within the
    /// configuration's `load_max` (the plan's note says so); refused when it does not
    /// reach above the stop load.
    Trace(Option<f32>),
}

/// The planner's table and the load range it covers.
#[derive(Debug, Clone, PartialEq)]
pub struct ThresholdPlan {
    /// One row per load with a critical angle.
    pub rows: Vec<ThresholdRow>,
    /// The range's top (N); the rows start above the stop load.
    pub load_max: f32,
    /// What was changed from the range asked for, if anything (one sentence).
    pub note: Option<String>,
}

/// A load range the planner cannot honour.
#[derive(Debug, Clone, PartialEq)]
pub enum PlanError {
    /// The range asked for is not above the configuration's stop load (N): below it
    /// the machine stands and no state is raised.
    NotAboveStop {
        /// The top asked for (N), or the trace's 99.9th percentile's 1.2 times.
        load_max: f32,
        /// The stop load (N).
        stop_load: f32,
        /// Whether the top came from a trace.
        from_trace: bool,
    },
    /// The range asked for is above the configuration's `load_max` (N), beyond which
    /// a load is the monitor's sensor fault.
    AboveRange {
        /// The top asked for (N).
        load_max: f32,
        /// The configuration's maximum load (N).
        config_load_max: f32,
    },
    /// The trace has no finite load.
    NoLoad,
}

impl core::fmt::Display for PlanError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            PlanError::NotAboveStop {
                load_max,
                stop_load,
                from_trace,
            } => {
                if from_trace {
                    write!(
                        f,
                        "the trace's loads (1.2 x their 99.9th percentile: {load_max} N) do not \
                         reach above the stop load {stop_load} N: the machine stands there and \
                         no state is raised; no load range to plan over"
                    )
                } else {
                    write!(
                        f,
                        "load_max = {load_max} N is not above the stop load {stop_load} N: the \
                         machine stands there and no state is raised; no load range to plan over"
                    )
                }
            }
            PlanError::AboveRange {
                load_max,
                config_load_max,
            } => write!(
                f,
                "load_max = {load_max} N is above the configuration's load_max \
                 {config_load_max} N, beyond which a load is a sensor fault"
            ),
            PlanError::NoLoad => {
                f.write_str("the trace has no finite load (P): no load range to plan over")
            }
        }
    }
}

impl std::error::Error for PlanError {}

/// The threshold planner over 60 loads from above the stop load up to the top of
/// `range` (N): the critical angle phi0(P) and the misalignment (rad) at which each
/// state is raised and cleared. Loads without a critical angle give no row.
///
/// # Errors
/// [`PlanError`] for a range the table cannot honour; a trace's range above the
/// configuration's `load_max` is kept within it instead, and the plan's note says so.
pub fn threshold_plan<E: Estimator>(
    core: &E,
    config: &Config,
    range: PlanRange,
) -> Result<ThresholdPlan, PlanError> {
    let stop_load = config.stop_load;
    let (load_max, note) = match range {
        PlanRange::UpTo(top) => {
            // NaN is not above it either.
            if top.partial_cmp(&stop_load) != Some(core::cmp::Ordering::Greater) {
                return Err(PlanError::NotAboveStop {
                    load_max: top,
                    stop_load,
                    from_trace: false,
                });
            }
            if top > config.load_max {
                return Err(PlanError::AboveRange {
                    load_max: top,
                    config_load_max: config.load_max,
                });
            }
            (top, None)
        }
        PlanRange::Trace(None) => return Err(PlanError::NoLoad),
        PlanRange::Trace(Some(quantile)) => {
            let top = quantile * 1.2;
            // NaN is not above it either.
            if top.partial_cmp(&stop_load) != Some(core::cmp::Ordering::Greater) {
                return Err(PlanError::NotAboveStop {
                    load_max: top,
                    stop_load,
                    from_trace: true,
                });
            }
            if top > config.load_max {
                let note = format!(
                    "the trace's loads reach {top} N (1.2 x their 99.9th percentile); the table \
                     ends at the configuration's load_max, {} N",
                    config.load_max
                );
                (config.load_max, Some(note))
            } else {
                (top, None)
            }
        }
    };
    Ok(ThresholdPlan {
        rows: threshold_rows(core, config, load_max),
        load_max,
        note,
    })
}

/// The rows over 60 loads from above the stop load up to `load_max` (N), which
/// [`threshold_plan`] has checked.
fn threshold_rows<E: Estimator>(core: &E, config: &Config, load_max: f32) -> Vec<ThresholdRow> {
    let n = 60;
    let (w, a, d) = match config.thresholds {
        Thresholds::SlipRatio {
            warning,
            alarm,
            deadband,
        } => (warning, alarm, deadband),
        Thresholds::Margin {
            warning,
            alarm,
            deadband,
        } => (warning, alarm, -deadband),
    };
    (1..=n)
        .filter_map(|i| {
            let load = config.stop_load + (load_max - config.stop_load) * i as f32 / n as f32;
            let phi0 = core.estimate_si(load, 0.0).ok()?.critical_angle?;
            let at = |x: f32| -> f64 {
                let phi = match config.thresholds {
                    Thresholds::SlipRatio { .. } => {
                        angle_for_slip_ratio(core, load, x, config.angle_max)
                    }
                    Thresholds::Margin { .. } => Some(phi0 - x).filter(|p| *p >= 0.0),
                };
                phi.map_or(f64::NAN, f64::from)
            };
            Some([
                f64::from(load),
                f64::from(phi0),
                at(w),
                at(w - d),
                at(a),
                at(a - d),
            ])
        })
        .collect()
}

/// The `--thresholds` CSV: header and one line per row, NaN an empty cell.
pub fn thresholds_csv(rows: &[ThresholdRow]) -> String {
    let mut out = format!("{THRESHOLDS_HEADER}\n");
    for row in rows {
        let cells: Vec<String> = row
            .iter()
            .map(|x| {
                if x.is_nan() {
                    String::new()
                } else {
                    x.to_string()
                }
            })
            .collect();
        out += &cells.join(",");
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use misalign::monitor::{FaultCause, RiskState};

    fn event(kind: EventKind) -> Event {
        Event {
            seq: 7,
            time_ms: 4_000_123,
            elapsed_ms: 1_234_567,
            kind,
            reading: Reading {
                load: 2500.5,
                phi: 3.25e-4,
                slip_ratio: 0.875,
                axial_force: 650.25,
                critical_angle: Some(4.5e-4),
                margin: None,
            },
        }
    }

    /// Each kind of row, cell by cell as the files have always been written (the
    /// Python package's tests read them back bit for bit).
    #[test]
    fn rows_of_every_kind() {
        let fault = Some(FaultCause::TimeBackwards);
        let change = EventKind::StateChange {
            from: RiskState::Normal,
            to: RiskState::SensorFault,
            fault,
        };
        assert_eq!(
            event_row(&event(change)),
            "1234.567,7,sensor_fault,normal,state,TimeBackwards,2500.5,0.000325,0.875,650.25,0.00045,,,4000123"
        );
        let approaching = EventKind::Approaching {
            time_to_critical_s: 90.5,
        };
        assert_eq!(
            event_row(&event(approaching)),
            "1234.567,7,,,approaching,,2500.5,0.000325,0.875,650.25,0.00045,,90.5,4000123"
        );
        let friction = EventKind::Friction {
            mu: 0.25,
            changed: true,
        };
        assert_eq!(
            event_row(&event(friction)),
            "1234.567,7,mu=0.25,,friction_changed,,,,,,,,,4000123"
        );
        let csv = events_csv(&[event(friction)]);
        assert_eq!(csv.lines().next(), Some(EVENTS_HEADER));
        assert_eq!(csv.lines().count(), 2);
    }

    /// A range the table cannot honour is refused; a trace's range above the
    /// configuration's is kept within it and the note says so.
    #[test]
    fn the_planners_range() {
        let scene = misalign::Scene::DEMO;
        let core = misalign::float::Auto::new(&scene).unwrap();
        let config = Config::default();
        for top in [50.0, 1e-30, 0.0, -100.0, f32::NAN, 100.0] {
            let e = threshold_plan(&core, &config, PlanRange::UpTo(top)).unwrap_err();
            assert!(matches!(e, PlanError::NotAboveStop { .. }), "{top}: {e}");
            assert!(e.to_string().contains("stop load 100 N"), "{e}");
            let e = threshold_plan(&core, &config, PlanRange::Trace(Some(top / 1.2)));
            assert!(matches!(e, Err(PlanError::NotAboveStop { .. })), "{top}");
        }
        for top in [5e4 * 1.01, f32::INFINITY] {
            let e = threshold_plan(&core, &config, PlanRange::UpTo(top)).unwrap_err();
            assert!(matches!(e, PlanError::AboveRange { .. }), "{top}: {e}");
        }
        assert_eq!(
            threshold_plan(&core, &config, PlanRange::Trace(None)),
            Err(PlanError::NoLoad)
        );
        let plan = threshold_plan(&core, &config, PlanRange::UpTo(3e3)).unwrap();
        assert_eq!((plan.load_max, plan.note.as_deref()), (3e3, None));
        assert!(plan.rows[0][0] > 100.0 && plan.rows.last().unwrap()[0] == 3e3);
        let plan = threshold_plan(&core, &config, PlanRange::Trace(Some(1e6))).unwrap();
        assert_eq!(plan.load_max, 5e4);
        assert!(plan.note.unwrap().contains("load_max, 50000 N"));
        assert!(plan.rows.last().unwrap()[0] == 5e4);
    }

    #[test]
    fn empty_cells_for_nan() {
        let csv = thresholds_csv(&[[1e3, 4.5e-4, f64::NAN, 1e-4, 2e-4, f64::NAN]]);
        assert_eq!(
            csv,
            format!("{THRESHOLDS_HEADER}\n1000,0.00045,,0.0001,0.0002,\n")
        );
    }
}
