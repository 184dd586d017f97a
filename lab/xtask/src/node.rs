//! The monitoring node's check (`cargo xtask firmware`): its events are the host
//! replay's.
//!
//! The node (`nodes/firmware`, `node.rs`) logs one `event` line per event and
//! `summary` lines at the end; this module reads them back from the defmt log
//! (defmt-print prints f32 with Rust's shortest round-trip form, so the values come
//! back bit for bit), replays the same scenario through `misalign::monitor::Monitor`
//! on the host with the estimator built as the PC example (`examples/monitor`) builds
//! it, and compares: the same number of events, in the same order, with the same
//! sequence numbers, timestamps (raw and elapsed, to the ms), kinds, states and fault
//! causes, and every value (P, phi, d/b, F, phi0, margin, time to critical) within the
//! core's stated error (relative 2e-6 for the f32 core, 1e-4 for the fixed-point core;
//! the margin, which cancels, to that of phi0 or |phi|); then the summary: counts,
//! final state and time per state exactly, extremes and energies within the same
//! error. Any difference is a failure.
//!
//! With simulated sensors (`--features sim-sensors`), the host replay goes through the same
//! sensors: `nodes/firmware/sensors.rs` is compiled into xtask as it is into the
//! node, so quantisation and dither are the same on both sides. (Against the replay
//! of the bare scenario the sensors' events have the same states in the same order,
//! but their times move by a few seconds where a threshold is crossed within the
//! quantisation, and the stuck probe is reported by the sensor's own detector after 8
//! frozen codes instead of the monitor's 2 minutes: that comparison would have to be
//! loose, this one need not be.)

use crate::log::Fields;
use misalign::Estimator;
use misalign::fixed::FixedAuto;
use misalign::float::Auto;
use misalign::monitor::scenario::{self, Scenario};
use misalign::monitor::{Config, EventKind, Monitor, RiskState, Sample};

#[allow(dead_code)] // Shared with the firmware, which uses it all.
#[path = "../../../nodes/firmware/sensors.rs"]
mod sensors;

/// The relative error each core states (README "Firmware"; the self-test holds the
/// cores to it against the reference).
pub fn tolerance(fpu: bool) -> f64 {
    if fpu { 2e-6 } else { 1e-4 }
}

/// One event as the node logs it.
#[derive(Debug, Clone, PartialEq)]
pub struct Event {
    seq: u32,
    time_ms: u32,
    elapsed_ms: u64,
    /// `state` or `approaching`.
    kind: String,
    from: String,
    to: String,
    /// `None`, `Some(Gap)`, ...: Rust's Debug form, which defmt's derive mirrors.
    fault: String,
    ttc: Option<f64>,
    load: f64,
    phi: f64,
    slip_ratio: f64,
    force: f64,
    critical_angle: Option<f64>,
    margin: Option<f64>,
}

/// The summary's values.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Summary {
    /// samples, repeated, spikes, faults, dropped.
    counts: [u64; 5],
    final_state: String,
    max_slip_ratio: f64,
    max_force: f64,
    min_margin: Option<f64>,
    /// Per state: name, time (ms), energy (J).
    states: Vec<(String, u64, f64)>,
}

/// What a run logged (or the host replay gave).
#[derive(Debug, Clone, Default)]
pub struct Log {
    pub events: Vec<Event>,
    pub summary: Summary,
}

/// The `node core=...` line: what the node measured.
#[derive(Debug, Clone, Default)]
pub struct Measured {
    pub samples: u64,
    pub events: u64,
    pub stack: u64,
    pub instructions_mean: u64,
    pub instructions_max: u64,
}

fn parse_event(line: &str) -> Result<Event, String> {
    let (head, fault) = line
        .split_once(" fault=")
        .ok_or("an event line without `fault=`")?;
    let f = Fields::of(head, "event seq=").ok_or("not an event line")?;
    Ok(Event {
        seq: f.num("seq")?,
        time_ms: f.num("time_ms")?,
        elapsed_ms: f.num("elapsed_ms")?,
        kind: f.get("kind")?.into(),
        from: f.get("from")?.into(),
        to: f.get("to")?.into(),
        fault: fault.trim().into(),
        ttc: f.opt_f32("ttc")?,
        load: f.f32("P")?,
        phi: f.f32("phi")?,
        slip_ratio: f.f32("s")?,
        force: f.f32("F")?,
        critical_angle: f.opt_f32("phi0")?,
        margin: f.opt_f32("margin")?,
    })
}

/// The events and the summary in a node's log.
pub fn parse_log(log: &str) -> Result<Log, String> {
    let mut out = Log::default();
    let mut counts_seen = false;
    for line in log.lines() {
        let what = |e: String| format!("{e} in: {line}");
        if line.contains("event seq=") {
            out.events.push(parse_event(line).map_err(what)?);
        } else if let Some(f) = Fields::of(line, "summary samples=") {
            let s = &mut out.summary;
            s.counts = [
                f.num("samples").map_err(what)?,
                f.num("repeated").map_err(what)?,
                f.num("spikes").map_err(what)?,
                f.num("faults").map_err(what)?,
                f.num("dropped").map_err(what)?,
            ];
            s.final_state = f.get("final").map_err(what)?.into();
            s.max_slip_ratio = f.f32("max_s").map_err(what)?;
            s.max_force = f.f32("max_F").map_err(what)?;
            s.min_margin = f.opt_f32("min_margin").map_err(what)?;
            counts_seen = true;
        } else if let Some(f) = Fields::of(line, "summary state=") {
            out.summary.states.push((
                f.get("state").map_err(what)?.into(),
                f.num("time_ms").map_err(what)?,
                f.num("energy_j").map_err(what)?,
            ));
        }
    }
    if !counts_seen || out.summary.states.len() != RiskState::ALL.len() {
        return Err("no complete summary in the node's log".into());
    }
    Ok(out)
}

/// The `node core=... stack_bytes=...` line.
pub fn parse_measured(log: &str) -> Result<Measured, String> {
    let f = Fields::first(log, "node core=")?;
    Ok(Measured {
        samples: f.num("samples")?,
        events: f.num("events")?,
        stack: f.num("stack_bytes")?,
        instructions_mean: f.num("instructions_mean")?,
        instructions_max: f.num("instructions_max")?,
    })
}

/// The node's estimator: the f32 core where there is an FPU, else the fixed-point one.
pub enum Core {
    F32(Auto),
    Fixed(FixedAuto),
}

/// The node's estimator for the scenario, built as the node builds it
/// (`scenario::estimator`): the f32 core (`fpu`) or the fixed-point one.
pub fn core(fpu: bool) -> Result<Core, String> {
    let err = |e: misalign::Error| e.to_string();
    Ok(if fpu {
        Core::F32(scenario::estimator::<Auto>().map_err(err)?)
    } else {
        Core::Fixed(scenario::estimator::<FixedAuto>().map_err(err)?)
    })
}

/// The host's replay of the scenario, on the f32 core (`fpu`) or the fixed-point one,
/// straight or through the simulated sensors: what the node must log.
pub fn host_replay(fpu: bool, through_sensors: bool) -> Result<Log, String> {
    match core(fpu)? {
        Core::F32(core) => replay(core, through_sensors),
        Core::Fixed(core) => replay(core, through_sensors),
    }
}

fn replay<E: Estimator>(core: E, through_sensors: bool) -> Result<Log, String> {
    let mut monitor = Monitor::new(core, Config::default()).map_err(|e| e.to_string())?;
    let mut out = Log::default();
    let mut step = |monitor: &mut Monitor<E>, sample: Sample| {
        monitor.process(sample);
        while let Some(e) = monitor.pop_event() {
            out.events.push(event(&e));
        }
    };
    if through_sensors {
        let clock = misalign::sensors::sim::SimClock::new();
        let chip = misalign::sensors::sim::SimHx711::new(&clock, sensors::HX711_PERIOD_NS, &[]);
        let mut rig = sensors::Sensors::new(&clock, &chip).map_err(|e| e.to_string())?;
        for sample in Scenario::new() {
            step(&mut monitor, rig.read(sample));
        }
    } else {
        for sample in Scenario::new() {
            step(&mut monitor, sample);
        }
    }
    let s = monitor.statistics();
    out.summary = Summary {
        counts: [
            s.samples(),
            s.repeated_timestamps().into(),
            s.spikes().into(),
            s.faults().total(),
            s.events_dropped().into(),
        ],
        final_state: monitor.state().as_str().into(),
        max_slip_ratio: s.max_slip_ratio().into(),
        max_force: s.max_axial_force().into(),
        min_margin: s.min_margin().map(f64::from),
        states: RiskState::ALL
            .iter()
            .map(|st| {
                (
                    st.as_str().to_string(),
                    s.time_in_state_ms(*st),
                    s.energy_j(*st),
                )
            })
            .collect(),
    };
    Ok(out)
}

fn event(e: &misalign::monitor::Event) -> Event {
    let (kind, from, to, fault, ttc) = match e.kind {
        EventKind::StateChange { from, to, fault } => (
            "state",
            from.as_str(),
            to.as_str(),
            format!("{fault:?}"),
            None,
        ),
        EventKind::Approaching { time_to_critical_s } => (
            "approaching",
            "-",
            "-",
            "None".into(),
            Some(time_to_critical_s.into()),
        ),
        // As the node logs it (it measures no axial force, so it raises none).
        EventKind::Friction { changed, .. } => (
            "friction",
            if changed { "band" } else { "baseline" },
            "-",
            "None".into(),
            None,
        ),
        // Raised by a fieldbus server only: never in the logged node.
        EventKind::Fieldbus(f) => (f.as_str(), "-", "-", "None".into(), None),
    };
    let r = &e.reading;
    Event {
        seq: e.seq,
        time_ms: e.time_ms,
        elapsed_ms: e.elapsed_ms,
        kind: kind.into(),
        from: from.into(),
        to: to.into(),
        fault,
        ttc,
        load: r.load.into(),
        phi: r.phi.into(),
        slip_ratio: r.slip_ratio.into(),
        force: r.axial_force.into(),
        critical_angle: r.critical_angle.map(f64::from),
        margin: r.margin.map(f64::from),
    }
}

/// The worst difference found, relative to what each value is held to (1 = at the
/// tolerance), and every mismatch.
pub struct Comparison {
    pub worst: f64,
    pub mismatches: Vec<String>,
}

/// Compares the node's log with the host's replay, values to the relative `tol`.
pub fn compare(node: &Log, host: &Log, tol: f64) -> Comparison {
    let mut c = Comparison {
        worst: 0.0,
        mismatches: Vec::new(),
    };
    // |got - want| against tol * scale: the share of the tolerance used.
    let mut value = |what: &str, got: f64, want: f64, scale: f64| {
        let used = if got == want {
            0.0
        } else {
            (got - want).abs() / (tol * scale.abs())
        };
        c.worst = c
            .worst
            .max(if used.is_nan() { f64::INFINITY } else { used });
        if used.is_nan() || used > 1.0 {
            c.mismatches.push(format!(
                "{what}: node {got}, host {want} (tolerance {tol:e})"
            ));
        }
    };
    let mut exact = Vec::new();
    if node.events.len() != host.events.len() {
        exact.push(format!(
            "{} events on the node, {} in the host replay",
            node.events.len(),
            host.events.len()
        ));
    }
    for (n, h) in node.events.iter().zip(&host.events) {
        let at = format!("event #{} ({} ms)", h.seq, h.elapsed_ms);
        let key = |e: &Event| {
            (
                e.seq,
                e.time_ms,
                e.elapsed_ms,
                e.kind.clone(),
                e.from.clone(),
                e.to.clone(),
                e.fault.clone(),
            )
        };
        if key(n) != key(h) {
            exact.push(format!("{at}: node {:?}, host {:?}", key(n), key(h)));
            continue;
        }
        value(&format!("{at} P"), n.load, h.load, h.load);
        value(&format!("{at} phi"), n.phi, h.phi, h.phi);
        value(
            &format!("{at} d/b"),
            n.slip_ratio,
            h.slip_ratio,
            h.slip_ratio,
        );
        value(&format!("{at} F"), n.force, h.force, h.force);
        let pairs = [
            ("phi0", n.critical_angle, h.critical_angle, h.critical_angle),
            // The margin phi0 - |phi| cancels: held to the error of the larger term.
            (
                "margin",
                n.margin,
                h.margin,
                h.critical_angle.map(|c| c.max(h.phi.abs())),
            ),
            ("time to critical", n.ttc, h.ttc, h.ttc),
        ];
        for (name, got, want, scale) in pairs {
            match (got, want) {
                (Some(g), Some(w)) => value(&format!("{at} {name}"), g, w, scale.unwrap_or(w)),
                (None, None) => {}
                _ => exact.push(format!("{at} {name}: node {got:?}, host {want:?}")),
            }
        }
    }
    let (n, h) = (&node.summary, &host.summary);
    if n.counts != h.counts || n.final_state != h.final_state {
        exact.push(format!(
            "summary: node samples/repeated/spikes/faults/dropped {:?} final {}, host {:?} final {}",
            n.counts, n.final_state, h.counts, h.final_state
        ));
    }
    value(
        "summary max d/b",
        n.max_slip_ratio,
        h.max_slip_ratio,
        h.max_slip_ratio,
    );
    value("summary max |F|", n.max_force, h.max_force, h.max_force);
    match (n.min_margin, h.min_margin) {
        (Some(g), Some(w)) => value("summary min margin", g, w, w),
        (None, None) => {}
        (g, w) => exact.push(format!("summary min margin: node {g:?}, host {w:?}")),
    }
    for (ns, hs) in n.states.iter().zip(&h.states) {
        if (&ns.0, ns.1) != (&hs.0, hs.1) {
            exact.push(format!("summary time in state: node {ns:?}, host {hs:?}"));
        } else {
            value(&format!("summary energy in {}", hs.0), ns.2, hs.2, hs.2);
        }
    }
    c.mismatches.extend(exact);
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A node log line reads back into the very event the host replay makes, and a
    /// changed time, state or value is caught.
    #[test]
    fn a_logged_event_reads_back_and_differences_are_caught() {
        let host = host_replay(true, false).unwrap();
        assert!(host.events.len() > 10);
        let line = |e: &Event| {
            let o = |x: Option<f64>| x.map_or("None".into(), |x| format!("Some({})", x as f32));
            format!(
                "event seq={} time_ms={} elapsed_ms={} kind={} from={} to={} ttc={} P={} phi={} s={} F={} phi0={} margin={} fault={}",
                e.seq,
                e.time_ms,
                e.elapsed_ms,
                e.kind,
                e.from,
                e.to,
                o(e.ttc),
                e.load as f32,
                e.phi as f32,
                e.slip_ratio as f32,
                e.force as f32,
                o(e.critical_angle),
                o(e.margin),
                e.fault
            )
        };
        let mut log: String = host.events.iter().map(|e| line(e) + "\n").collect();
        let s = &host.summary;
        log += &format!(
            "summary samples={} repeated={} spikes={} faults={} dropped={} max_s={} max_F={} min_margin={} final={} ttc=None\n",
            s.counts[0],
            s.counts[1],
            s.counts[2],
            s.counts[3],
            s.counts[4],
            s.max_slip_ratio as f32,
            s.max_force as f32,
            s.min_margin
                .map_or("None".into(), |m| format!("Some({})", m as f32)),
            s.final_state
        );
        for (name, t, e) in &s.states {
            log += &format!("summary state={name} time_ms={t} energy_j={e}\n");
        }
        let node = parse_log(&log).unwrap();
        let same = compare(&node, &host, tolerance(true));
        assert!(same.mismatches.is_empty(), "{:?}", same.mismatches);
        assert_eq!(same.worst, 0.0);

        let mut later = node.clone();
        later.events[3].elapsed_ms += 1000;
        assert_eq!(compare(&later, &host, 2e-6).mismatches.len(), 1);
        let mut other = node.clone();
        other.events[1].to = "normal".into();
        assert_eq!(compare(&other, &host, 2e-6).mismatches.len(), 1);
        let mut off = node.clone();
        off.events[5].slip_ratio *= 1.0 + 1e-5;
        assert_eq!(compare(&off, &host, 2e-6).mismatches.len(), 1);
        assert!(compare(&off, &host, 1e-4).mismatches.is_empty());
        let mut fewer = node;
        fewer.events.pop();
        assert!(!compare(&fewer, &host, 2e-6).mismatches.is_empty());
    }

    /// Through the simulated sensors the host sees the same states in the same order
    /// as straight from the scenario (quantisation moves times, not what happens).
    #[test]
    fn the_sensors_replay_has_the_bare_replays_states() {
        let bare = host_replay(true, false).unwrap();
        let sensed = host_replay(true, true).unwrap();
        let states = |l: &Log| -> Vec<(String, String)> {
            l.events
                .iter()
                .map(|e| (e.kind.clone(), e.to.clone()))
                .collect()
        };
        assert_eq!(states(&bare), states(&sensed));
        assert_eq!(sensed.summary.counts[0], bare.summary.counts[0]);
    }
}
