//! The monitor example's events file (`cargo run --example monitor -- --events
//! OUT.csv`, `docs/formats.md`): one row per event, written by the example and by
//! `cargo xtask modbus --trace`, which reads the same events back from the node over
//! Modbus.

use misalign::monitor::{Event, EventKind};

/// The header row.
pub const HEADER: &str =
    "t,seq,state,from,kind,fault,P,phi,s,F,phi0,margin,time_to_critical,time_ms\n";

/// One event as a row: `t` in seconds from the first sample, f32 values in Rust's
/// shortest round-trip form (equal rows are equal bits), an empty cell for a value
/// that is not there.
pub fn event_row(e: &Event) -> String {
    let opt = |x: Option<f32>| x.map_or(String::new(), |x| x.to_string());
    let (state, from, kind, fault, ttc) = match e.kind {
        EventKind::StateChange { from, to, fault } => (
            to.as_str(),
            from.as_str(),
            "state",
            fault.map_or(String::new(), |f| format!("{f:?}")),
            String::new(),
        ),
        EventKind::Approaching { time_to_critical_s } => (
            "",
            "",
            "approaching",
            String::new(),
            time_to_critical_s.to_string(),
        ),
        // The filtered mu in the state column.
        EventKind::Friction { mu, changed } => {
            let kind = if changed {
                "friction_changed"
            } else {
                "friction_cleared"
            };
            return format!(
                "{},{},mu={mu},,{kind},,,,,,,,,{}",
                e.elapsed_ms as f64 / 1e3,
                e.seq,
                e.time_ms
            );
        }
    };
    let r = &e.reading;
    format!(
        "{},{},{state},{from},{kind},{fault},{},{},{},{},{},{},{ttc},{}",
        e.elapsed_ms as f64 / 1e3,
        e.seq,
        r.load,
        r.phi,
        r.slip_ratio,
        r.axial_force,
        opt(r.critical_angle),
        opt(r.margin),
        e.time_ms,
    )
}
