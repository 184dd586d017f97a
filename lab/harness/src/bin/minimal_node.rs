//! The monitoring node on a build-time scene: the demo scene prepared on the host
//! (`misalign_harness::prepared`, written by the build script; loaded with `from_bytes`,
//! integer checks only: no f64 preparation, no libm), the condition monitor
//! ([`Monitor`]: conditioning, estimator, risk states, event queue, wear and trend) over
//! a sensor's samples, and every event logged through defmt. The scene is the ellipse,
//! the model the monitor's rule (`model_for_range`) picks for the demo's operating
//! range: the fixed-point core without an FPU, the f32 core with one. Built in profile
//! `node` (the firmware profile at opt-level "s"), as a node with 16 KiB of flash is.
//!
//! It prints `node samples=... events=... stack_bytes=...` (the deepest stack use of
//! the monitor's loop, by painting) and exits 0 when the monitor reported events. A
//! panic exits 101 without a message: no `core::fmt` in the image.
#![no_std]
#![no_main]

use misalign::Estimator;
use misalign::monitor::{Config, Event, EventKind, Monitor, Sample};
use misalign_harness::node_samples::{ANGLES, LOADS, SAMPLES};
use misalign_harness::{io, prepared, support};
use misalign_logger as _;

misalign_harness::exit_on_panic!();

#[cortex_m_rt::entry]
fn main() -> ! {
    // The bytes as the build script wrote them (the compiler may fold what it can).
    #[cfg(target_abi = "eabihf")]
    let core = misalign::float::EllipticScene::from_bytes(&prepared::ELLIPTIC);
    #[cfg(not(target_abi = "eabihf"))]
    let core = misalign::fixed::FixedEllipticScene::from_bytes(&prepared::FIXED_ELLIPTIC);
    let Ok(core) = core else {
        defmt::error!("the build-time scene was refused");
        support::exit(2)
    };
    let sp = support::stack::paint();
    let events = run(core);
    let stack = support::stack::used(sp);
    defmt::println!(
        "node samples={=u32} events={=u32} stack_bytes={=usize}",
        SAMPLES,
        events,
        stack
    );
    support::exit(if events > 0 { 0 } else { 1 })
}

/// The node's loop: one sample in, the events out to the log. Returns how many.
#[inline(never)]
fn run<E: Estimator>(core: E) -> u32 {
    let Ok(mut monitor) = Monitor::new(core, Config::default()) else {
        defmt::error!("the configuration was refused");
        support::exit(3)
    };
    let mut events = 0;
    for i in 0..SAMPLES {
        let load = io::read(&LOADS[(i % 8) as usize]);
        let phi = io::read(&ANGLES[(i / 60 % 8) as usize]);
        monitor.process(Sample::new(i * 1000, load, phi).with_speed(2.0));
        while let Some(event) = monitor.pop_event() {
            log(&event);
            events += 1;
        }
    }
    events
}

/// One event on the log: its number, time, what happened and the d/b and margin that
/// caused it (the whole `Event` through its derived `Format` costs 1 KB more flash).
fn log(event: &Event) {
    let r = &event.reading;
    match event.kind {
        EventKind::StateChange { from, to, .. } => defmt::info!(
            "event {=u32} at {=u32} ms: {} -> {}, d/b {=f32}, margin {=f32}",
            event.seq,
            event.time_ms,
            from,
            to,
            r.slip_ratio,
            r.margin.unwrap_or(f32::NAN)
        ),
        EventKind::Approaching { time_to_critical_s } => defmt::info!(
            "event {=u32} at {=u32} ms: gross slip in {=f32} s, d/b {=f32}",
            event.seq,
            event.time_ms,
            time_to_critical_s,
            r.slip_ratio
        ),
        // Not raised: this node measures no axial force (`Monitor::process`).
        EventKind::Friction { mu, changed } => defmt::info!(
            "event {=u32} at {=u32} ms: friction {=f32}, outside the band {=bool}",
            event.seq,
            event.time_ms,
            mu,
            changed
        ),
        // Not raised: no fieldbus server here.
        EventKind::Fieldbus(_) => {}
    }
}
