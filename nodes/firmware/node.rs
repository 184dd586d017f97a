//! The monitoring node (Cortex-M only): `misalign::monitor::Monitor` over the built-in
//! scenario (`misalign::monitor::scenario`: one 8 h shift of a press roller pair, one
//! sample a second), every event logged as it is drained, a summary at the end.
//!
//! The estimator is the scenario's (`misalign::monitor::scenario::estimator`), as the PC
//! example (`examples/monitor`) and the host replay build it, so that the node's events
//! are the host replay's: the f32 core `Auto` where there is an FPU, else the
//! fixed-point `FixedAuto`. `cargo xtask firmware` parses the `event` and
//! `summary` lines below and compares them with the host's replay.
//!
//! With the feature `sim-sensors` the samples come through simulated sensors (`sensors.rs`)
//! instead of straight from the scenario.

use misalign::fixed::FixedAuto;
use misalign::float::Auto;
use misalign::monitor::scenario::{self, Scenario};
use misalign::monitor::{Config, Event, EventKind, Monitor, RiskState};
use misalign::{Error, Estimator};

/// What the node measured.
pub struct Measured {
    pub samples: u32,
    pub events: u32,
    /// Instructions of `Monitor::process` per sample (the whole per-sample pipeline:
    /// checks, conditioning, estimate, states, wear, trend), mean and max.
    pub instructions_mean: u32,
    pub instructions_max: u32,
}

/// The f32 core, as `examples/monitor --model f32`.
pub fn f32_core() -> Result<Auto, Error> {
    scenario::estimator()
}

/// The fixed-point core, as `examples/monitor --model fixed`.
pub fn fixed_core() -> Result<FixedAuto, Error> {
    scenario::estimator()
}

/// An instruction counter (the harness's SysTick counter in the QEMU images): what a
/// call returns and the instructions it took.
pub trait Count {
    fn count<R>(&self, f: impl FnOnce() -> R) -> (R, u32);
}

/// Runs the node over the whole scenario with `core`; `None` if the monitor refuses
/// its configuration.
#[inline(never)]
pub fn run<E: Estimator>(core: E, number: &str, counter: &impl Count) -> Option<Measured> {
    let mut monitor = match Monitor::new(core, Config::default()) {
        Ok(m) => m,
        Err(e) => {
            defmt::error!("node: configuration refused: {}", e);
            return None;
        }
    };
    let sensors = if cfg!(feature = "sim-sensors") {
        "simulated sensors (HX711 load cell, two probes on a 16-bit ADC, tachometer)"
    } else {
        "the scenario's values"
    };
    defmt::println!(
        "node: monitoring the built-in scenario (8 h, one sample a second), {=str} core, from {=str}",
        number,
        sensors
    );
    #[cfg(feature = "sim-sensors")]
    let clock = misalign::sensors::sim::SimClock::new();
    #[cfg(feature = "sim-sensors")]
    let chip = misalign::sensors::sim::SimHx711::new(&clock, crate::sensors::HX711_PERIOD_NS, &[]);
    #[cfg(feature = "sim-sensors")]
    let mut sensors = match crate::sensors::Sensors::new(&clock, &chip) {
        Ok(s) => s,
        Err(e) => {
            defmt::error!("node: sensor calibration refused: {}", e);
            return None;
        }
    };
    let (mut samples, mut events, mut sum, mut max) = (0u32, 0u32, 0u64, 0u32);
    for sample in Scenario::new() {
        #[cfg(feature = "sim-sensors")]
        let sample = sensors.read(sample);
        let (_, n) = counter.count(|| monitor.process(core::hint::black_box(sample)));
        samples += 1;
        sum += u64::from(n);
        max = max.max(n);
        while let Some(e) = monitor.pop_event() {
            log_event(&e);
            events += 1;
        }
    }
    summary(&monitor);
    Some(Measured {
        samples,
        events,
        instructions_mean: (sum / u64::from(samples.max(1))) as u32,
        instructions_max: max,
    })
}

/// One `event` line: `cargo xtask firmware` reads every field back (`fault=` last, as
/// it may hold spaces).
fn log_event(e: &Event) {
    let (kind, from, to, fault, ttc) = match e.kind {
        EventKind::StateChange { from, to, fault } => {
            ("state", from.as_str(), to.as_str(), fault, None)
        }
        EventKind::Approaching { time_to_critical_s } => {
            ("approaching", "-", "-", None, Some(time_to_critical_s))
        }
        // Not raised here: the node measures no axial force (`Monitor::process`).
        EventKind::Friction { changed, .. } => (
            "friction",
            if changed { "band" } else { "baseline" },
            "-",
            None,
            None,
        ),
        // Raised by the Modbus server only (`serve.rs`): never on this log.
        EventKind::Fieldbus(f) => (f.as_str(), "-", "-", None, None),
    };
    let r = &e.reading;
    defmt::println!(
        "event seq={=u32} time_ms={=u32} elapsed_ms={=u64} kind={=str} from={=str} to={=str} ttc={} P={=f32} phi={=f32} s={=f32} F={=f32} phi0={} margin={} fault={}",
        e.seq,
        e.time_ms,
        e.elapsed_ms,
        kind,
        from,
        to,
        ttc,
        r.load,
        r.phi,
        r.slip_ratio,
        r.axial_force,
        r.critical_angle,
        r.margin,
        fault
    );
}

/// The summary: counts, then time and energy per state.
fn summary<E: Estimator>(m: &Monitor<E>) {
    let s = m.statistics();
    defmt::println!(
        "summary samples={=u64} repeated={=u32} spikes={=u32} faults={=u64} dropped={=u32} max_s={=f32} max_F={=f32} min_margin={} final={=str} ttc={}",
        s.samples(),
        s.repeated_timestamps(),
        s.spikes(),
        s.faults().total(),
        s.events_dropped(),
        s.max_slip_ratio(),
        s.max_axial_force(),
        s.min_margin(),
        m.state().as_str(),
        m.time_to_critical()
    );
    for state in RiskState::ALL {
        defmt::println!(
            "summary state={=str} time_ms={=u64} energy_j={=f64}",
            state.as_str(),
            s.time_in_state_ms(state),
            s.energy_j(state)
        );
    }
}
