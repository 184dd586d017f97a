//! Property tests of the condition monitor over random sample streams (bad
//! input): never a panic, never a NaN, no event lost without being counted, no state
//! change faster than its delay allows, and a bad sample never raises slip.

use misalign::fixed::FixedEllipticScene;
use misalign::float::EllipticScene;
use misalign::monitor::{Config, EventKind, Monitor, RiskState, Sample, SpikeFilter, TrendConfig};
use misalign::{Estimator, Scene};
use proptest::prelude::*;

fn scene() -> Scene {
    Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3).unwrap()
}

/// Any f32 a broken sensor may send, and plausible ones more often.
fn value(lo: f32, hi: f32) -> impl Strategy<Value = f32> {
    prop_oneof![
        6 => lo..hi,
        1 => Just(f32::NAN),
        1 => Just(f32::INFINITY),
        1 => Just(f32::NEG_INFINITY),
        1 => Just(-0.0f32),
        1 => any::<f32>(),
        1 => Just(f32::MAX),
        1 => Just(f32::MIN_POSITIVE / 4.0),
    ]
}

/// A time step: mostly forward, sometimes repeated, backwards, a gap, or a wrap.
fn step() -> impl Strategy<Value = u32> {
    prop_oneof![
        8 => 1u32..3_000,
        1 => Just(0u32),
        1 => (1u32..100_000).prop_map(|d| d.wrapping_neg()),
        1 => 10_000u32..10_000_000,
        1 => any::<u32>(),
    ]
}

prop_compose! {
    fn samples()(steps in prop::collection::vec(step(), 1..300),
                 loads in prop::collection::vec(value(-500.0, 8_000.0), 300),
                 phis in prop::collection::vec(value(-2e-3, 2e-3), 300),
                 speeds in prop::collection::vec(prop::option::of(value(-1.0, 5.0)), 300),
                 forces in prop::collection::vec(prop::option::weighted(0.2, value(-3e3, 3e3)), 300),
                 drivers in prop::collection::vec(prop::option::weighted(0.05, 0u8..4), 300),
                 start in any::<u32>()) -> Vec<Sample> {
        let mut t = start;
        steps.iter().enumerate().map(|(i, &d)| {
            t = t.wrapping_add(d);
            let channel = drivers[i].map(|c| [misalign::monitor::Channel::Load, misalign::monitor::Channel::Angle,
                misalign::monitor::Channel::Speed, misalign::monitor::Channel::AxialForce][usize::from(c)]);
            Sample { time_ms: t, load: loads[i], phi: phis[i], speed: speeds[i], axial_force: forces[i], driver_fault: channel, sensor_fault: None }
        }).collect()
    }
}

prop_compose! {
    /// Configurations at and near their limits (some invalid: refused, not panicking).
    fn configs()(on in prop_oneof![Just(0u32), 0u32..20_000, Just(u32::MAX)],
                 off in prop_oneof![Just(0u32), 0u32..60_000, Just(u32::MAX)],
                 fault in prop_oneof![Just(0u32), 0u32..5_000],
                 inhibit in prop_oneof![Just(0u32), 0u32..30_000],
                 window in 0u8..12, tau in prop_oneof![Just(0.0f32), 0.0f32..100.0, Just(f32::NAN)],
                 stuck in prop_oneof![Just(0u32), 1u32..20_000], gap in prop_oneof![Just(0u32), 1u32..20_000],
                 points in 0u8..20, interval in 0u32..20_000, deadband in -0.1f32..0.5) -> Config {
        Config {
            on_delay_ms: on,
            off_delay_ms: off,
            fault_delay_ms: fault,
            inhibit_ms: inhibit,
            spikes: (window > 0).then_some(SpikeFilter { window, k: 3.0, load_floor: 50.0, angle_floor: 1e-5 }),
            smoothing_tau_s: tau,
            stuck_ms: stuck,
            gap_ms: gap,
            trend: (points > 0).then_some(TrendConfig { interval_ms: interval, points, horizon_s: 600.0 }),
            thresholds: misalign::monitor::Thresholds::SlipRatio { warning: 0.8, alarm: 1.0, deadband },
            ..Config::default()
        }
    }
}

/// The delay (ms) the documented rules give a change from `from` to `to`.
fn delay(c: &Config, from: RiskState, to: RiskState) -> u64 {
    u64::from(if to == RiskState::SensorFault {
        c.fault_delay_ms
    } else if from == RiskState::Stopped && to == RiskState::Normal {
        0
    } else if to.index() > from.index() {
        c.on_delay_ms
    } else {
        c.off_delay_ms
    })
}

fn bad(s: &Sample) -> bool {
    let finite = s.load.is_finite()
        && s.phi.is_finite()
        && s.speed.is_none_or(f32::is_finite)
        && s.axial_force.is_none_or(f32::is_finite);
    !finite || s.driver_fault.is_some()
}

fn no_nan(x: f32) -> bool {
    !x.is_nan()
}

/// Runs the stream, draining after every sample, and checks every property.
fn check<E: Estimator>(core: E, config: Config, samples: &[Sample]) -> Result<(), TestCaseError> {
    let Ok(mut m) = Monitor::new(core, config) else {
        prop_assert!(config.validate().is_err());
        return Ok(());
    };
    let mut last_change_ms = 0u64;
    let mut next_seq = 0u32;
    for s in samples {
        let before = m.state();
        let after = m.process(*s);
        prop_assert_eq!(after, m.state());
        if bad(s) {
            // A bad sample never raises slip.
            prop_assert!(
                after == before || after == RiskState::SensorFault,
                "{:?} -> {:?} on {:?}",
                before,
                after,
                s
            );
        }
        let mut changed = false;
        while let Some(e) = m.pop_event() {
            prop_assert_eq!(e.seq, next_seq);
            next_seq += 1;
            let r = e.reading;
            prop_assert!(
                [r.load, r.phi, r.slip_ratio, r.axial_force]
                    .into_iter()
                    .all(no_nan)
            );
            prop_assert!(r.critical_angle.is_none_or(no_nan) && r.margin.is_none_or(no_nan));
            match e.kind {
                EventKind::StateChange { from, to, fault } => {
                    prop_assert!(!changed, "one change per sample");
                    changed = true;
                    prop_assert_eq!((from, to), (before, after));
                    prop_assert_eq!(fault.is_some(), to == RiskState::SensorFault);
                    // Never faster than the delay of this change.
                    prop_assert!(
                        e.elapsed_ms - last_change_ms >= delay(&config, from, to),
                        "{:?} -> {:?} after {} ms",
                        from,
                        to,
                        e.elapsed_ms - last_change_ms
                    );
                    last_change_ms = e.elapsed_ms;
                }
                EventKind::Approaching { time_to_critical_s } => {
                    prop_assert!(time_to_critical_s > 0.0)
                }
                EventKind::Friction { .. } => {
                    prop_assert!(false, "no friction without process_with_friction")
                }
                EventKind::Fieldbus(link) => {
                    prop_assert!(false, "the link's {:?} raised by the monitor alone", link)
                }
            }
        }
        prop_assert_eq!(changed, before != after, "every change has its event");
    }
    let st = m.statistics();
    prop_assert_eq!(st.events_dropped(), 0);
    prop_assert!(
        no_nan(st.max_slip_ratio())
            && no_nan(st.max_axial_force())
            && st.min_margin().is_none_or(no_nan)
    );
    prop_assert!(
        RiskState::ALL
            .iter()
            .all(|&state| st.energy_j(state).is_finite() && st.energy_j(state) >= 0.0)
    );
    prop_assert!(m.time_to_critical().is_none_or(|t| t > 0.0));
    let time: u64 = RiskState::ALL
        .iter()
        .map(|&state| st.time_in_state_ms(state))
        .sum();
    prop_assert_eq!(time, m.elapsed_ms());
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn f32_core_streams(samples in samples(), config in configs()) {
        check(EllipticScene::new(&scene()).unwrap(), config, &samples)?;
    }

    #[test]
    fn fixed_core_streams(samples in samples(), config in configs()) {
        let core = FixedEllipticScene::new(&scene(), 1e-2, FixedEllipticScene::min_angle_lsb(&scene()).max(1e-10)).unwrap();
        check(core, config, &samples)?;
    }

    /// The state taken out anywhere in a bad stream and put back goes on identically.
    #[test]
    fn restored_state_goes_on_identically(samples in samples(), config in configs(), cut in 0usize..300) {
        let core = EllipticScene::new(&scene()).unwrap();
        let Ok(mut whole) = Monitor::new(core, config) else { return Ok(()) };
        let mut resumed = Monitor::new(core, config).unwrap();
        let cut = cut.min(samples.len());
        for s in &samples[..cut] {
            whole.process(*s);
            resumed.process(*s);
        }
        let mut resumed = Monitor::restore(core, config, &resumed.snapshot()).unwrap();
        for s in &samples[cut..] {
            prop_assert_eq!(whole.process(*s), resumed.process(*s));
        }
        prop_assert_eq!(whole.snapshot(), resumed.snapshot());
    }

    /// Undrained, the queue keeps the newest events and counts every other one.
    #[test]
    fn no_event_is_lost_without_a_count(samples in samples(), drain_every in 1usize..50) {
        let config = Config { on_delay_ms: 0, off_delay_ms: 0, ..Config::default() };
        let mut m = Monitor::new(EllipticScene::new(&scene()).unwrap(), config).unwrap();
        let mut delivered = 0u64;
        let mut last_seq = None;
        for (i, s) in samples.iter().enumerate() {
            m.process(*s);
            if i % drain_every == 0 {
                while let Some(e) = m.pop_event() {
                    prop_assert!(last_seq.is_none_or(|l| e.seq > l));
                    last_seq = Some(e.seq);
                    delivered += 1;
                }
            }
        }
        let pending = m.pending_events() as u64;
        let emitted = u64::from(m.next_event_seq());
        prop_assert_eq!(m.snapshot().next_event_seq(), m.next_event_seq());
        prop_assert_eq!(delivered + pending + u64::from(m.statistics().events_dropped()), emitted);
    }
}

/// A stream in segments: each a run of samples at one load and angle (running, slow,
/// a dropout with `P = NaN`, or an angle anywhere from normal to gross slip at 2 kN),
/// with the time steps of `step` (repeated, backwards, gaps and wraps too).
fn segmented() -> impl Strategy<Value = Vec<Sample>> {
    let segment = (
        prop_oneof![
            6 => (0.0f32..2.5e-3).prop_map(|phi| (2e3f32, phi)),
            1 => Just((f32::NAN, 1e-4f32)),
            1 => Just((50.0f32, 1e-4f32)),
        ],
        1usize..40,
    );
    (
        prop::collection::vec(segment, 1..20),
        prop::collection::vec(step(), 400),
        any::<u32>(),
    )
        .prop_map(|(segments, steps, start)| {
            let mut t = start;
            let mut steps = steps.into_iter().cycle();
            let mut out = Vec::new();
            for ((load, phi), n) in segments {
                for i in 0..n {
                    t = t.wrapping_add(steps.next().unwrap_or(1000));
                    // Noise, so that a steady angle is not one value.
                    let noise = (i % 5) as f32 * 1e-7;
                    out.push(Sample::new(t, load, phi + noise));
                }
            }
            out
        })
}

prop_compose! {
    /// Random delays and inhibit, a random deadband; conditioning, stuck detection and
    /// trend off (so that a test can tell each sample's candidate from the sample).
    fn delay_configs()(on in prop_oneof![Just(0u32), 0u32..20_000],
                       off in prop_oneof![Just(0u32), 0u32..40_000],
                       fault in prop_oneof![Just(0u32), 0u32..40_000],
                       inhibit in prop_oneof![Just(0u32), 0u32..20_000],
                       gap in prop_oneof![Just(0u32), 1u32..20_000],
                       deadband in 0.0f32..0.3) -> Config {
        Config {
            on_delay_ms: on,
            off_delay_ms: off,
            fault_delay_ms: fault,
            inhibit_ms: inhibit,
            spikes: None,
            smoothing_tau_s: 0.0,
            stuck_ms: 0,
            gap_ms: gap,
            trend: None,
            friction: None,
            thresholds: misalign::monitor::Thresholds::SlipRatio { warning: 0.8, alarm: 1.0, deadband },
            ..Config::default()
        }
    }
}

/// The state a sample asks for, found from the sample and what the monitor counted
/// (with conditioning off): a fault, `Stopped`, `Normal` in the start-up inhibit, or
/// the slip level of its d/b with the deadband on clearing from `before`.
fn candidate(
    config: &Config,
    s: &Sample,
    faulted: bool,
    inhibited: bool,
    before: RiskState,
) -> RiskState {
    let speed = s.speed.unwrap_or(config.nominal_speed);
    if faulted {
        return RiskState::SensorFault;
    }
    if !(s.load >= config.stop_load && speed >= config.stop_speed) {
        return RiskState::Stopped;
    }
    if inhibited {
        return RiskState::Normal;
    }
    let misalign::monitor::Thresholds::SlipRatio {
        warning,
        alarm,
        deadband,
    } = config.thresholds
    else {
        unreachable!("the strategy sets d/b thresholds")
    };
    let x = EllipticScene::new(&scene())
        .unwrap()
        .estimate_si(s.load, s.phi)
        .unwrap()
        .slip_ratio;
    let gross = x >= alarm || (before == RiskState::GrossSlip && x >= alarm - deadband);
    let raised = matches!(before, RiskState::Microslip | RiskState::GrossSlip);
    let micro = x >= warning || (raised && x >= warning - deadband);
    if gross {
        RiskState::GrossSlip
    } else if micro {
        RiskState::Microslip
    } else {
        RiskState::Normal
    }
}

/// Since when (ms) candidates have stood without a break for `target` seen from
/// `from`: faults for `SensorFault`, slip levels at or beyond `target` on its side of
/// `from` for the others (one start per state and side, kept in `runs`).
#[derive(Default)]
struct Runs {
    /// Per state: at or above it (slip levels only).
    up: [Option<u64>; 5],
    /// Per state: at or below it (slip levels only).
    down: [Option<u64>; 5],
    fault: Option<u64>,
}

impl Runs {
    fn note(&mut self, c: RiskState, now: u64) {
        let start = |run: &mut Option<u64>, holds: bool| {
            *run = if holds {
                Some(run.unwrap_or(now))
            } else {
                None
            };
        };
        let slip = c != RiskState::SensorFault;
        for x in RiskState::ALL {
            start(&mut self.up[x.index()], slip && c.index() >= x.index());
            start(&mut self.down[x.index()], slip && c.index() <= x.index());
        }
        start(&mut self.fault, !slip);
    }

    fn since(&self, from: RiskState, target: RiskState) -> Option<u64> {
        if target == RiskState::SensorFault {
            self.fault
        } else if target.index() > from.index() {
            self.up[target.index()]
        } else {
            self.down[target.index()]
        }
    }
}

/// Every state is entered only after its own candidates stood for its own delay
/// (counted from the first of them, whatever came before: a fault's time never counts
/// toward slip, nor slip's toward a fault), and once some state's candidates have
/// stood for its delay since the last change, the state does change.
fn delays_hold(config: Config, samples: &[Sample]) -> Result<(), TestCaseError> {
    let core = EllipticScene::new(&scene()).unwrap();
    let mut m = Monitor::new(core, config).unwrap();
    // Runs over the whole stream (safety) and since the last change (liveness).
    let (mut whole, mut since_change) = (Runs::default(), Runs::default());
    let mut started: Option<u64> = None;
    for s in samples {
        let before = m.state();
        let (repeated, faults, refused) = {
            let st = m.statistics();
            (
                st.repeated_timestamps(),
                st.faults().total(),
                st.faults().estimator,
            )
        };
        let after = m.process(*s);
        let st = m.statistics();
        if st.repeated_timestamps() > repeated {
            prop_assert_eq!(after, before, "a repeated timestamp changes nothing");
            continue;
        }
        let now = m.elapsed_ms();
        let faulted = st.faults().total() > faults;
        // The start-up inhibit runs from the first running sample the checks passed
        // (the estimator may still refuse it) since the start or `Stopped`.
        let running_valid = st.faults().estimator > refused || !faulted;
        let speed = s.speed.unwrap_or(config.nominal_speed);
        if running_valid && s.load >= config.stop_load && speed >= config.stop_speed {
            started.get_or_insert(now);
        }
        let inhibited = started.is_none_or(|t| now - t < u64::from(config.inhibit_ms));
        let c = candidate(&config, s, faulted, inhibited, before);
        whole.note(c, now);
        since_change.note(c, now);
        if after != before {
            let since = whole.since(before, after);
            prop_assert!(
                since.is_some_and(|t| now - t >= delay(&config, before, after)),
                "{:?} -> {:?} at {} ms, its candidates since {:?}",
                before,
                after,
                now,
                since
            );
            since_change = Runs::default();
            if after == RiskState::Stopped {
                started = None;
            }
        } else {
            for x in RiskState::ALL.into_iter().filter(|&x| x != before) {
                let due = since_change
                    .since(before, x)
                    .is_some_and(|t| now - t >= delay(&config, before, x));
                prop_assert!(
                    !due,
                    "{:?} held its delay from {:?} at {} ms",
                    x,
                    before,
                    now
                );
            }
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Over random streams and random delays, no state is entered before its own delay
    /// since its own candidate began, and none is held back beyond it.
    #[test]
    fn each_state_waits_its_own_delay(samples in segmented(), config in delay_configs()) {
        delays_hold(config, &samples)?;
    }
}
