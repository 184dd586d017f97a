//! What `cargo run --example monitor` writes besides its log: every event as a row of
//! `--events` ([`event_record`], [`events_csv`]) and the threshold planner of
//! `--thresholds` ([`threshold_rows`], [`thresholds_csv`]). The Python package's replay
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

/// The threshold planner over 60 loads from the stop load up to `load_max` (N),
/// which is first kept within the configuration's load range (at least twice the stop
/// load). Loads without a critical angle give no row.
pub fn threshold_rows<E: Estimator>(core: &E, config: &Config, load_max: f32) -> Vec<ThresholdRow> {
    let load_max = load_max.min(config.load_max).max(2.0 * config.stop_load);
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

    #[test]
    fn empty_cells_for_nan() {
        let csv = thresholds_csv(&[[1e3, 4.5e-4, f64::NAN, 1e-4, 2e-4, f64::NAN]]);
        assert_eq!(
            csv,
            format!("{THRESHOLDS_HEADER}\n1000,0.00045,,0.0001,0.0002,\n")
        );
    }
}
