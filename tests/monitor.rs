//! The condition monitor (`misalign::monitor`): states, delays, deadband, inhibit,
//! faults, events, wear, trend, configuration and persistence.

use misalign::float::EllipticScene;
use misalign::monitor::{
    Channel, Config, ConfigError, EventKind, FaultCause, Monitor, RiskState, Sample, Thresholds,
    TrendConfig, scenario,
};
use misalign::{Estimator, Scene};

const LOAD: f32 = 2000.0;

fn core() -> EllipticScene<'static> {
    EllipticScene::new(&Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3).unwrap()).unwrap()
}

/// The defaults with conditioning, trend and inhibit off: states follow the raw samples.
fn plain() -> Config {
    Config {
        spikes: None,
        smoothing_tau_s: 0.0,
        stuck_ms: 0,
        gap_ms: 0,
        trend: None,
        inhibit_ms: 0,
        ..Config::default()
    }
}

#[path = "common/slip.rs"]
mod slip;

/// The misalignment (rad) at which d/b = `target` at `load`.
fn angle_for(target: f32, load: f32) -> f32 {
    slip::angle_for(&core(), target, load)
}

/// Feeds one sample a second at `phi` from `t0` (s) for `n` samples; returns the
/// states after each.
fn feed<E: Estimator>(m: &mut Monitor<E>, t0: u32, n: u32, phi: f32) -> Vec<RiskState> {
    (0..n)
        .map(|i| m.process(Sample::new((t0 + i) * 1000, LOAD, phi)))
        .collect()
}

fn changes<E: Estimator>(m: &mut Monitor<E>) -> Vec<(u64, RiskState, RiskState)> {
    let mut v = Vec::new();
    while let Some(e) = m.pop_event() {
        if let EventKind::StateChange { from, to, .. } = e.kind {
            v.push((e.elapsed_ms, from, to));
        }
    }
    v
}

#[test]
fn states_follow_the_slip_ratio_thresholds() {
    let mut m = Monitor::new(
        core(),
        Config {
            on_delay_ms: 0,
            off_delay_ms: 0,
            ..plain()
        },
    )
    .unwrap();
    assert_eq!(
        feed(&mut m, 0, 1, angle_for(0.5, LOAD))[0],
        RiskState::Normal
    );
    assert_eq!(
        feed(&mut m, 1, 1, angle_for(0.85, LOAD))[0],
        RiskState::Microslip
    );
    assert_eq!(
        feed(&mut m, 2, 1, angle_for(1.05, LOAD))[0],
        RiskState::GrossSlip
    );
    let r = m.reading().unwrap();
    assert!(r.slip_ratio >= 1.0 && r.margin.unwrap() < 0.0);
    let c = changes(&mut m);
    let to: Vec<_> = c.iter().map(|x| x.2).collect();
    assert_eq!(
        to,
        [
            RiskState::Normal,
            RiskState::Microslip,
            RiskState::GrossSlip
        ]
    );
}

#[test]
fn margin_thresholds_raise_on_the_margin() {
    let thresholds = Thresholds::Margin {
        warning: 1e-4,
        alarm: 0.0,
        deadband: 1e-5,
    };
    let mut m = Monitor::new(
        core(),
        Config {
            on_delay_ms: 0,
            off_delay_ms: 0,
            thresholds,
            ..plain()
        },
    )
    .unwrap();
    let phi0 = core()
        .estimate_si(LOAD, 0.0)
        .unwrap()
        .critical_angle
        .unwrap();
    assert_eq!(feed(&mut m, 0, 1, phi0 - 2e-4)[0], RiskState::Normal);
    assert_eq!(feed(&mut m, 1, 1, phi0 - 0.5e-4)[0], RiskState::Microslip);
    assert_eq!(feed(&mut m, 2, 1, phi0 + 1e-5)[0], RiskState::GrossSlip);
}

#[test]
fn on_delay_holds_a_raise_back_and_short_excursions_raise_nothing() {
    let mut m = Monitor::new(core(), plain()).unwrap(); // on-delay 5 s
    feed(&mut m, 0, 10, angle_for(0.5, LOAD));
    // 4 s above the alarm: shorter than the on-delay.
    assert!(
        feed(&mut m, 10, 4, angle_for(1.1, LOAD))
            .iter()
            .all(|&s| s == RiskState::Normal)
    );
    feed(&mut m, 14, 10, angle_for(0.5, LOAD));
    // Held: raised exactly 5 s after the first alarm-level sample.
    let states = feed(&mut m, 24, 8, angle_for(1.1, LOAD));
    assert_eq!(states[4], RiskState::Normal);
    assert_eq!(states[5], RiskState::GrossSlip);
    let c = changes(&mut m);
    assert_eq!(
        c.last().unwrap(),
        &(29_000, RiskState::Normal, RiskState::GrossSlip)
    );
}

#[test]
fn deadband_and_off_delay_clear_late() {
    let mut m = Monitor::new(core(), plain()).unwrap(); // deadband 0.05, off-delay 30 s
    feed(&mut m, 0, 10, angle_for(0.85, LOAD));
    assert_eq!(m.state(), RiskState::Microslip);
    // 0.78: below the warning but inside its deadband: stays raised however long.
    assert!(
        feed(&mut m, 10, 100, angle_for(0.78, LOAD))
            .iter()
            .all(|&s| s == RiskState::Microslip)
    );
    // 0.7: below the deadband; clears after the 30 s off-delay, not before.
    let states = feed(&mut m, 110, 40, angle_for(0.7, LOAD));
    assert_eq!(states[29], RiskState::Microslip);
    assert_eq!(states[30], RiskState::Normal);
}

#[test]
fn start_up_inhibit_suppresses_alarms_after_a_start() {
    let config = Config {
        inhibit_ms: 20_000,
        on_delay_ms: 0,
        ..plain()
    };
    let mut m = Monitor::new(core(), config).unwrap();
    let states = feed(&mut m, 0, 30, angle_for(1.2, LOAD));
    assert!(states[..20].iter().all(|&s| s == RiskState::Normal));
    assert_eq!(states[20], RiskState::GrossSlip);
    // A stop, then a start: inhibited again.
    for i in 30..80 {
        m.process(Sample::new(i * 1000, 0.0, 1e-4));
    }
    assert_eq!(m.state(), RiskState::Stopped);
    let states = feed(&mut m, 80, 30, angle_for(1.2, LOAD));
    assert!(states[..20].iter().all(|&s| s == RiskState::Normal));
    assert_eq!(states[20], RiskState::GrossSlip);
}

#[test]
fn a_load_dip_shorter_than_the_off_delay_neither_stops_nor_clears_an_alarm() {
    // An inhibit (60 s) longer than the off-delay (30 s): were the dip a start, the
    // inhibit would clear the alarm.
    let config = Config {
        inhibit_ms: 60_000,
        on_delay_ms: 0,
        ..plain()
    };
    let mut m = Monitor::new(core(), config).unwrap();
    feed(&mut m, 0, 70, angle_for(1.2, LOAD));
    assert_eq!(m.state(), RiskState::GrossSlip);
    // Two samples below the stop load, then the alarm condition goes on.
    m.process(Sample::new(70_000, 10.0, angle_for(1.2, LOAD)));
    m.process(Sample::new(71_000, 10.0, angle_for(1.2, LOAD)));
    let states = feed(&mut m, 72, 90, angle_for(1.2, LOAD));
    assert!(states.iter().all(|&s| s == RiskState::GrossSlip));
}

#[test]
fn stopped_has_no_alarm_and_no_wear() {
    let mut m = Monitor::new(core(), plain()).unwrap();
    feed(&mut m, 0, 60, angle_for(0.5, LOAD));
    // Load below the stop load, then standing still at full load (speed 0).
    for i in 60..200 {
        let s = if i < 130 {
            Sample::new(i * 1000, 50.0, 3e-3).with_speed(2.0)
        } else {
            Sample::new(i * 1000, LOAD, 3e-3).with_speed(0.0)
        };
        m.process(s);
    }
    assert_eq!(m.state(), RiskState::Stopped);
    let s = m.statistics();
    assert_eq!(s.energy_j(RiskState::Stopped), 0.0);
    assert!(s.time_in_state_ms(RiskState::Stopped) >= 100_000);
    let c = changes(&mut m);
    assert!(
        c.iter()
            .all(|x| x.2 != RiskState::GrossSlip && x.2 != RiskState::Microslip)
    );
}

#[test]
fn sensor_faults_are_never_slip() {
    let config = Config {
        stuck_ms: 10_000,
        gap_ms: 5_000,
        on_delay_ms: 0,
        ..plain()
    };
    let bad: [(Sample, FaultCause); 7] = [
        (
            Sample::new(0, LOAD, f32::NAN),
            FaultCause::NonFinite(Channel::Angle),
        ),
        (
            Sample::new(0, f32::INFINITY, 1e-3),
            FaultCause::NonFinite(Channel::Load),
        ),
        (
            Sample::new(0, -5e3, 1e-3),
            FaultCause::OutOfRange(Channel::Load),
        ),
        (
            Sample::new(0, LOAD, 0.5),
            FaultCause::OutOfRange(Channel::Angle),
        ),
        (
            Sample::new(0, LOAD, 1e-3).with_speed(-1.0),
            FaultCause::OutOfRange(Channel::Speed),
        ),
        (
            Sample::new(0, LOAD, 1e-3).with_axial_force(f32::NAN),
            FaultCause::NonFinite(Channel::AxialForce),
        ),
        (
            Sample {
                driver_fault: Some(Channel::Angle),
                ..Sample::new(0, LOAD, 1e-3)
            },
            FaultCause::Driver(Channel::Angle),
        ),
    ];
    for (sample, cause) in bad {
        let mut m = Monitor::new(core(), config).unwrap();
        feed(&mut m, 0, 10, angle_for(1.2, LOAD)); // gross slip
        assert_eq!(m.state(), RiskState::GrossSlip);
        changes(&mut m);
        let state = m.process(Sample {
            time_ms: 10_000,
            ..sample
        });
        assert_eq!(state, RiskState::SensorFault, "{cause:?}");
        let e = m.pop_event().unwrap();
        assert_eq!(
            e.kind,
            EventKind::StateChange {
                from: RiskState::GrossSlip,
                to: RiskState::SensorFault,
                fault: Some(cause)
            }
        );
        // The values reported are the last valid ones, never the bad sample's.
        assert!(e.reading.slip_ratio.is_finite() && e.reading.phi.is_finite());
        assert_eq!(m.statistics().faults().total(), 1);
    }
    // Stuck: the same raw angle for longer than 10 s while running.
    let mut m = Monitor::new(core(), config).unwrap();
    let states = feed(&mut m, 0, 15, angle_for(0.5, LOAD));
    assert_eq!(states[10], RiskState::Normal);
    assert_eq!(states[11], RiskState::SensorFault);
    assert!(m.statistics().faults().stuck > 0);
    // A gap, then time going backwards.
    let mut m = Monitor::new(core(), config).unwrap();
    m.process(Sample::new(0, LOAD, 1e-4));
    assert_eq!(
        m.process(Sample::new(6_000, LOAD, 1.1e-4)),
        RiskState::SensorFault
    );
    assert_eq!(m.statistics().faults().gap, 1);
    m.process(Sample::new(3_000, LOAD, 1.2e-4));
    assert_eq!(m.statistics().faults().time_backwards, 1);
    // ... the clock goes on from the new value.
    m.process(Sample::new(4_000, LOAD, 1.3e-4));
    assert_eq!(m.elapsed_ms(), 7_000);
}

#[test]
fn fault_clears_only_after_the_off_delay_of_good_samples() {
    let mut m = Monitor::new(core(), plain()).unwrap();
    feed(&mut m, 0, 5, angle_for(0.5, LOAD));
    m.process(Sample::new(5_000, f32::NAN, 1e-4));
    let states = feed(&mut m, 6, 40, angle_for(0.5, LOAD));
    // Off-delay 30 s from the first good sample (t = 6 s).
    assert_eq!(states[29], RiskState::SensorFault);
    assert_eq!(states[30], RiskState::Normal);
}

#[test]
fn a_wrapping_clock_is_not_time_going_backwards() {
    let mut m = Monitor::new(
        core(),
        Config {
            gap_ms: 5_000,
            ..plain()
        },
    )
    .unwrap();
    let start = u32::MAX - 2_500;
    for i in 0..10u32 {
        m.process(Sample::new(start.wrapping_add(i * 1000), LOAD, 1e-4));
    }
    assert_eq!(m.elapsed_ms(), 9_000);
    assert_eq!(m.statistics().faults().total(), 0);
    assert_eq!(m.state(), RiskState::Normal);
}

#[test]
fn repeated_timestamps_are_counted_and_ignored() {
    let mut m = Monitor::new(core(), plain()).unwrap();
    m.process(Sample::new(1000, LOAD, 1e-4));
    m.process(Sample::new(1000, f32::NAN, 1e-4));
    m.process(Sample::new(1000, LOAD, 1e-4));
    let s = m.statistics();
    assert_eq!(
        (s.samples(), s.repeated_timestamps(), s.faults().total()),
        (3, 2, 0)
    );
    assert_eq!(m.state(), RiskState::Normal);
}

#[test]
fn a_full_event_queue_drops_the_oldest_and_counts() {
    let config = Config {
        on_delay_ms: 0,
        off_delay_ms: 0,
        ..plain()
    };
    let mut m = Monitor::new(core(), config).unwrap();
    let (lo, hi) = (angle_for(0.5, LOAD), angle_for(1.2, LOAD));
    for i in 0..40u32 {
        m.process(Sample::new(
            i * 1000,
            LOAD,
            if i % 2 == 0 { lo } else { hi },
        ));
    }
    // 40 changes (the first is the start); the newest EVENT_CAPACITY kept.
    let capacity = misalign::monitor::EVENT_CAPACITY as u32;
    let kept: Vec<_> = std::iter::from_fn(|| m.pop_event()).collect();
    assert_eq!(kept.len() as u32, capacity);
    assert_eq!(m.statistics().events_dropped(), 40 - capacity);
    let seqs: Vec<u32> = kept.iter().map(|e| e.seq).collect();
    assert_eq!(seqs, (40 - capacity..40).collect::<Vec<_>>());
}

/// 1e9 small increments of the compensated sum stay within 1e-6 (relative) of the
/// exact sum, where a plain f32 sum stalls. Increments cycle over 1..=7 mJ-like
/// binary fractions, so that the exact sum is an integer count; the release-
/// optimised test profile runs the loop in a few seconds.
#[test]
fn wear_integrates_f_phi_v_over_time() {
    let mut m = Monitor::new(core(), plain()).unwrap();
    let phi = angle_for(0.6, LOAD);
    let f = core().estimate_si(LOAD, phi).unwrap().axial_force;
    for i in 0..=3600u32 {
        m.process(Sample::new(i * 1000, LOAD, phi).with_speed(1.5));
    }
    // One hour at F phi V (section 7); the first sample has no step before it.
    let expected = f64::from(f) * f64::from(phi) * 1.5 * 3600.0;
    let got = m.statistics().energy_j(RiskState::Normal);
    assert!(
        (got / expected - 1.0).abs() < 1e-5,
        "{got} J vs {expected} J"
    );
    // Without a measured speed, the nominal one (2 m/s).
    let mut m = Monitor::new(core(), plain()).unwrap();
    for i in 0..=100u32 {
        m.process(Sample::new(i * 1000, LOAD, phi));
    }
    let expected = f64::from(f) * f64::from(phi) * 2.0 * 100.0;
    assert!((m.statistics().total_energy() / expected - 1.0).abs() < 1e-5);
}

#[test]
fn time_to_critical_follows_a_linear_drift() {
    let trend = TrendConfig {
        interval_ms: 10_000,
        points: 10,
        horizon_s: 600.0,
    };
    let config = Config {
        trend: Some(trend),
        ..plain()
    };
    let mut m = Monitor::new(core(), config).unwrap();
    let phi0 = core()
        .estimate_si(LOAD, 0.0)
        .unwrap()
        .critical_angle
        .unwrap();
    // Drift 1e-7 rad/s from phi0 - 2e-4: gross slip 2000 s after the start.
    let rate = 1e-7f32;
    let mut approaching = None;
    for i in 0..1800u32 {
        let phi = phi0 - 2e-4 + rate * i as f32;
        m.process(Sample::new(i * 1000, LOAD, phi));
        while let Some(e) = m.pop_event() {
            if let EventKind::Approaching { time_to_critical_s } = e.kind {
                approaching.get_or_insert((i, time_to_critical_s));
            }
        }
        if i == 1000 {
            let ttc = m
                .time_to_critical()
                .expect("a falling margin has a time to critical");
            // The fit is over 10 s means: the exact answer within their spread.
            assert!((ttc - 1000.0).abs() < 15.0, "{ttc} s");
        }
    }
    let (i, ttc) = approaching.expect("an Approaching event below the horizon");
    assert!(ttc < 600.0 && (1390..=1420).contains(&i), "{i} {ttc}");
}

#[test]
fn inconsistent_configurations_are_refused() {
    let bad: [(Config, ConfigError); 8] = [
        (
            Config {
                thresholds: Thresholds::SlipRatio {
                    warning: 1.1,
                    alarm: 1.0,
                    deadband: 0.05,
                },
                ..plain()
            },
            ConfigError::WarningAboveAlarm,
        ),
        (
            Config {
                thresholds: Thresholds::SlipRatio {
                    warning: 0.8,
                    alarm: 1.0,
                    deadband: -0.1,
                },
                ..plain()
            },
            ConfigError::Deadband,
        ),
        (
            Config {
                thresholds: Thresholds::SlipRatio {
                    warning: f32::NAN,
                    alarm: 1.0,
                    deadband: 0.0,
                },
                ..plain()
            },
            ConfigError::Threshold,
        ),
        (
            Config {
                thresholds: Thresholds::Margin {
                    warning: 0.0,
                    alarm: 1e-4,
                    deadband: 0.0,
                },
                ..plain()
            },
            ConfigError::WarningAboveAlarm,
        ),
        (
            Config {
                stop_load: 0.0,
                ..plain()
            },
            ConfigError::Stop,
        ),
        (
            Config {
                spikes: Some(misalign::monitor::SpikeFilter {
                    window: 0,
                    k: 3.0,
                    load_floor: 1.0,
                    angle_floor: 1e-6,
                }),
                ..plain()
            },
            ConfigError::SpikeWindow,
        ),
        (
            Config {
                trend: Some(TrendConfig {
                    interval_ms: 1000,
                    points: 0,
                    horizon_s: 60.0,
                }),
                ..plain()
            },
            ConfigError::Trend,
        ),
        (
            Config {
                smoothing_tau_s: -1.0,
                ..plain()
            },
            ConfigError::Smoothing,
        ),
    ];
    for (config, error) in bad {
        assert_eq!(config.validate(), Err(error));
        assert_eq!(Monitor::new(core(), config).err(), Some(error));
    }
    assert_eq!(Config::default().validate(), Ok(()));
}

fn replay_scenario<E: Estimator>(
    m: &mut Monitor<E>,
    samples: &[Sample],
) -> Vec<misalign::monitor::Event> {
    let mut events = Vec::new();
    for &s in samples {
        m.process(s);
        events.extend(std::iter::from_fn(|| m.pop_event()));
    }
    events
}

#[test]
fn state_taken_out_and_put_back_goes_on_identically() {
    let samples: Vec<Sample> = scenario::Scenario::new().collect();
    let mut whole = Monitor::new(core(), Config::default()).unwrap();
    let all = replay_scenario(&mut whole, &samples);
    let half = samples.len() / 2;
    let mut first = Monitor::new(core(), Config::default()).unwrap();
    let mut events = replay_scenario(&mut first, &samples[..half]);
    // Leave events undelivered, to see them carried over too.
    first.process(samples[half]);
    let state = first.snapshot();
    let copy = state; // a plain Copy value
    let mut second = Monitor::restore(core(), Config::default(), &copy).unwrap();
    assert_eq!(second.snapshot(), state);
    events.extend(std::iter::from_fn(|| second.pop_event()));
    events.extend(replay_scenario(&mut second, &samples[half + 1..]));
    assert_eq!(events, all);
    assert_eq!(second.statistics(), whole.statistics());
    // The whole state within its 1 KiB budget.
    assert!(core::mem::size_of::<misalign::monitor::MonitorState>() <= 1024);
}

#[test]
fn the_scenario_shows_every_condition_and_is_deterministic() {
    let a: Vec<Sample> = scenario::Scenario::new().collect();
    let b: Vec<Sample> = scenario::Scenario::new().collect();
    assert_eq!(a, b);
    assert_eq!(a.len() as u32, scenario::SHIFT_S - 180); // the 3 min dropout
    let mut m = Monitor::new(core(), Config::default()).unwrap();
    let events = replay_scenario(&mut m, &a);
    let s = m.statistics();
    assert_eq!((s.faults().gap, s.events_dropped()), (1, 0));
    assert!(s.faults().stuck > 0);
    // Every injected spike is rejected, and nothing else.
    let injected = (0..scenario::SHIFT_S)
        .filter(|t| t % scenario::SPIKE_EVERY_S == scenario::SPIKE_EVERY_S - 1)
        .filter(|t| !(scenario::STOP_S.0..scenario::STOP_S.1).contains(t))
        .filter(|t| !(scenario::DROPOUT_S.0..scenario::DROPOUT_S.1).contains(t))
        .count();
    assert_eq!(s.spikes() as usize, injected);
    assert!(s.time_in_state_ms(RiskState::Stopped) >= 1_200_000 - 60_000);
    for state in [
        RiskState::Microslip,
        RiskState::GrossSlip,
        RiskState::SensorFault,
    ] {
        assert!(
            events
                .iter()
                .any(|e| matches!(e.kind, EventKind::StateChange { to, .. } if to == state))
        );
    }
    assert!(
        events
            .iter()
            .any(|e| matches!(e.kind, EventKind::Approaching { .. }))
    );
    // The clock wrapped an hour in, unnoticed.
    assert_eq!(s.faults().time_backwards, 0);
    assert_eq!(m.elapsed_ms(), u64::from(scenario::SHIFT_S - 1) * 1000);
}

#[test]
fn hampel_rejects_a_spike_but_follows_a_real_step() {
    let spikes = Some(misalign::monitor::SpikeFilter {
        window: 7,
        k: 4.0,
        load_floor: 50.0,
        angle_floor: 1e-5,
    });
    let mut m = Monitor::new(core(), Config { spikes, ..plain() }).unwrap();
    let phi = |i: u32| 1e-4 + 1e-7 * (i % 5) as f32;
    for i in 0..20 {
        m.process(Sample::new(i * 1000, LOAD + (i % 3) as f32, phi(i)));
    }
    // One sample at three times the load: replaced by the window's median.
    m.process(Sample::new(20_000, 3.0 * LOAD, phi(20)));
    assert_eq!(m.statistics().spikes(), 1);
    assert!((m.reading().unwrap().load - LOAD).abs() < 5.0);
    // A lasting step to 1.5 times the load: rejected only until it fills half the window.
    for i in 21..40 {
        m.process(Sample::new(i * 1000, 1.5 * LOAD + (i % 3) as f32, phi(i)));
    }
    assert!(
        m.statistics().spikes() <= 1 + 4,
        "{}",
        m.statistics().spikes()
    );
    assert!((m.reading().unwrap().load - 1.5 * LOAD).abs() < 5.0);
}

#[test]
fn smoothing_weight_follows_the_real_time_step() {
    let config = Config {
        smoothing_tau_s: 3.0,
        ..plain()
    };
    let (a, b) = (1e-4f32, 2e-4f32);
    // One step of 3 s: 1 - 1/e of the way.
    let mut m = Monitor::new(core(), config).unwrap();
    m.process(Sample::new(0, LOAD, a));
    m.process(Sample::new(3_000, LOAD + 1.0, b));
    let one = m.reading().unwrap().phi;
    assert!(((one - a) / (b - a) - (1.0 - (-1.0f32).exp())).abs() < 1e-5);
    // Two steps of 1.5 s at the same value: the same place, whatever the sampling.
    let mut m = Monitor::new(core(), config).unwrap();
    m.process(Sample::new(0, LOAD, a));
    m.process(Sample::new(1_500, LOAD + 1.0, b));
    m.process(Sample::new(3_000, LOAD + 2.0, b));
    assert!((m.reading().unwrap().phi - one).abs() < 1e-9);
}

#[test]
fn the_model_is_chosen_once_for_the_operating_range() {
    use misalign::monitor::model_for_range;
    use misalign::reference::{self, ModelChoice};
    let steel = Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3).unwrap();
    assert_eq!(
        model_for_range(&steel, 5e3, 1e-5),
        Ok(ModelChoice::Elliptic)
    );
    let plane = Scene::new(0.05, f64::INFINITY, 79.3e9, 0.3, 0.3).unwrap();
    assert_eq!(model_for_range(&plane, 5e3, 1e-5), Ok(ModelChoice::Line));
    // Short rollers: the ellipse at the heaviest load and smallest angle is longer.
    let short = steel.with_length(0.02).unwrap();
    assert!(
        reference::elliptic(&short, 5e3, 1e-5)
            .unwrap()
            .validity
            .longer_than_rollers
    );
    assert_eq!(model_for_range(&short, 5e3, 1e-5), Ok(ModelChoice::Line));
    let long = steel.with_length(2.0).unwrap();
    assert!(
        !reference::elliptic(&long, 5e3, 1e-3)
            .unwrap()
            .validity
            .longer_than_rollers
    );
    assert_eq!(model_for_range(&long, 5e3, 1e-3), Ok(ModelChoice::Elliptic));
    assert_eq!(
        model_for_range(&steel, f64::NAN, 1e-5),
        Err(misalign::Error::Load)
    );
    assert_eq!(
        model_for_range(&steel, 5e3, 0.0),
        Err(misalign::Error::Angle)
    );
}

/// A dropout's sensor-fault candidate hands no time to a slip candidate that follows
/// it: with a fault delay longer than the dropout, 120 s at 2 kN and 0.1 mrad (with
/// some noise: a constant value is a stuck sensor), 10 s of `P = NaN` and then one
/// sample at 3 mrad leave the state `Normal`; gross slip that lasts is entered after
/// the conditioning settled (7 samples fill the spike window) and the on-delay from
/// the first sample that decided it.
#[test]
fn a_pending_fault_hands_no_time_to_a_slip_candidate() {
    let config = Config {
        fault_delay_ms: 60_000,
        ..Config::default()
    };
    let noisy = |t: u32, phi: f32| Sample::new(t * 1000, LOAD + (t % 7) as f32, phi);
    let mut m = Monitor::new(core(), config).unwrap();
    for t in 0..120u32 {
        m.process(noisy(t, 1e-4));
    }
    assert_eq!(m.state(), RiskState::Normal);
    for t in 120..130u32 {
        let state = m.process(Sample::new(t * 1000, f32::NAN, 1e-4));
        assert_eq!(state, RiskState::Normal);
    }
    let states: Vec<RiskState> = (130..150u32).map(|t| m.process(noisy(t, 3e-3))).collect();
    let entered = states.iter().position(|&s| s == RiskState::GrossSlip);
    // The window filled by 136 s, the first sample that decides at 137 s: entered at
    // 142 s, not before.
    assert_eq!(entered, Some(12), "{states:?}");
}

/// The fit's slope over its standard error (f64), from the trend's points.
fn slope_over_its_error(points: &[misalign::monitor::TrendPoint]) -> f64 {
    let newest = points.last().unwrap().time_ms;
    let x: Vec<f64> = points
        .iter()
        .map(|p| -f64::from(newest.wrapping_sub(p.time_ms)) * 1e-3)
        .collect();
    let y: Vec<f64> = points.iter().map(|p| f64::from(p.margin)).collect();
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxx: f64 = x.iter().map(|x| (x - mx).powi(2)).sum();
    let sxy: f64 = x.iter().zip(&y).map(|(x, y)| (x - mx) * (y - my)).sum();
    let slope = sxy / sxx;
    let ssr: f64 = x
        .iter()
        .zip(&y)
        .map(|(x, y)| (y - my - slope * (x - mx)).powi(2))
        .sum();
    slope / (ssr / (n - 2.0) / sxx).sqrt()
}

/// `Approaching` predicts: in the built-in scenario every one has its zero crossing
/// ahead (a positive time to critical) and a credible fit (the slope at least
/// `TREND_SLOPE_STANDARD_ERRORS` below zero); none where the fit already crossed, as
/// at 24365 s, where gross slip had just cleared with a margin of +0.071 mrad.
#[test]
fn approaching_only_ahead_of_a_credible_fit() {
    let mut m = Monitor::new(core(), Config::default()).unwrap();
    let mut approaching = 0;
    for s in scenario::Scenario::new() {
        m.process(s);
        while let Some(e) = m.pop_event() {
            if let EventKind::Approaching { time_to_critical_s } = e.kind {
                approaching += 1;
                let at = e.elapsed_ms / 1000;
                assert!(time_to_critical_s > 0.0, "{time_to_critical_s} s at {at} s");
                let t = slope_over_its_error(m.snapshot().trend_points());
                let limit = f64::from(misalign::monitor::TREND_SLOPE_STANDARD_ERRORS);
                assert!(t <= -limit, "slope {t} standard errors at {at} s");
            }
        }
        // Past the fit's crossing there is no time to critical, never 0.
        assert!(m.time_to_critical().is_none_or(|t| t > 0.0));
    }
    assert!(approaching > 0);
}

/// The fit's answer on its own: a clean fall gives the time to its crossing; a fit
/// already at or below zero, a rising margin, and a fall hidden in the scatter give
/// none.
#[test]
fn time_to_critical_needs_a_crossing_ahead_and_a_credible_fall() {
    use misalign::monitor::{TrendPoint, time_to_critical};
    let line = |m0: f32, rate: f32, wobble: f32| -> Vec<TrendPoint> {
        (0..16u32)
            .map(|i| TrendPoint {
                time_ms: i * 300_000,
                margin: m0 + rate * (i * 300) as f32 + if i % 2 == 0 { wobble } else { -wobble },
            })
            .collect()
    };
    // 0.2 mrad at the newest point, falling 1e-8 rad/s: 20 000 s ahead.
    let t = time_to_critical(&line(2e-4 + 4.5e-5, -1e-8, 0.0)).unwrap();
    assert!((t / 20_000.0 - 1.0).abs() < 1e-3, "{t} s");
    // Already crossed at the newest point.
    assert_eq!(time_to_critical(&line(2e-5, -1e-8, 0.0)), None);
    // Rising.
    assert_eq!(time_to_critical(&line(2e-4, 1e-8, 0.0)), None);
    // The same fall under a scatter of +-0.1 mrad: the slope is a fraction of its
    // standard error.
    assert_eq!(time_to_critical(&line(2e-4 + 4.5e-5, -1e-8, 1e-4)), None);
}

/// A fit's crossing that has passed by the time the contact sticks again predicts
/// nothing: the margin falls linearly to cross zero at 260 s, the fit made at 302 s
/// (the third point; over interval means, half an interval behind) crosses at about
/// 310 s while the contact slips; a dropout at 303 s and a smaller angle after it bring
/// `Normal` back at 334 s, after that crossing and before the next fit: no
/// `Approaching` then.
#[test]
fn approaching_never_for_a_crossing_already_past() {
    let config = Config {
        on_delay_ms: 0,
        trend: Some(TrendConfig {
            interval_ms: 100_000,
            points: 3,
            horizon_s: 3_600.0,
        }),
        ..plain()
    };
    let mut m = Monitor::new(core(), config).unwrap();
    let phi0 = core()
        .estimate_si(LOAD, 0.0)
        .unwrap()
        .critical_angle
        .unwrap();
    let mut approaching = Vec::new();
    for t in 0..400u32 {
        let sample = match t {
            0..303 => Sample::new(t * 1000, LOAD, phi0 - 1e-6 * (260.0 - t as f32)),
            303 => Sample {
                driver_fault: Some(Channel::Angle),
                ..Sample::new(t * 1000, LOAD, 1e-4)
            },
            _ => Sample::new(t * 1000, LOAD, 1e-4),
        };
        m.process(sample);
        if t == 302 {
            let ttc = m.time_to_critical().expect("a credible fall at 302 s");
            assert!((5.0..15.0).contains(&ttc), "{ttc} s");
        }
        if t == 334 {
            assert_eq!(m.state(), RiskState::Normal);
        }
        while let Some(e) = m.pop_event() {
            if let EventKind::Approaching { time_to_critical_s } = e.kind {
                approaching.push((e.elapsed_ms, time_to_critical_s));
            }
        }
    }
    assert_eq!(approaching, []);
}

/// Normal running at 2 kN and 0.1 mrad with some noise, one sample a second from `t0`
/// (s) for `n` samples; the states after each.
fn normal_run<E: Estimator>(m: &mut Monitor<E>, t0: u32, n: u32) -> Vec<RiskState> {
    (t0..t0 + n)
        .map(|t| {
            let noise = (t % 7) as f32;
            m.process(Sample::new(t * 1000, LOAD + noise, 1e-4 + 1e-7 * noise))
        })
        .collect()
}

/// One glitch after a dropout: with the defaults and a minute's fault delay, 120 s
/// normal, 10 s with a NaN load, one sample at 3 mrad, then normal samples again. The
/// conditioning starts afresh after the dropout and settles on fresh samples before
/// any of them decides a state: the glitch never raises anything.
#[test]
fn one_glitch_after_a_dropout_raises_nothing() {
    let config = Config {
        fault_delay_ms: 60_000,
        ..Config::default()
    };
    let mut m = Monitor::new(core(), config).unwrap();
    normal_run(&mut m, 0, 120);
    assert_eq!(m.state(), RiskState::Normal);
    for t in 120..130 {
        assert_eq!(
            m.process(Sample::new(t * 1000, f32::NAN, 1e-4)),
            RiskState::Normal
        );
    }
    assert_eq!(
        m.process(Sample::new(130_000, LOAD, 3e-3)),
        RiskState::Normal
    );
    assert!(m.settling());
    let after = normal_run(&mut m, 131, 120);
    assert!(after.iter().all(|&s| s == RiskState::Normal), "{after:?}");
    let changes = changes(&mut m);
    assert_eq!(
        changes,
        [(7_000, RiskState::Stopped, RiskState::Normal)],
        "only the start"
    );
}

type Demo = Monitor<EllipticScene<'static>>;
/// A restart of the demo monitor at `t` s; returns the time of the next sample (s).
type Restart = fn(&mut Demo, u32) -> u32;

/// Every path that starts the conditioning afresh settles before a sample decides
/// again: after a dropout, a stop, a new configuration or scene, and a checkpoint
/// restored mid-settling or taken under other accepted ranges, one sample at 3 mrad
/// (gross slip) and then normal ones raise nothing. The state is held, and
/// `settling()` says so, while 7 valid running samples fill the spike window; the 8th,
/// the first tested, decides. A reset of the statistics leaves the conditioning as it
/// is.
#[test]
fn every_restart_settles_before_a_sample_decides() {
    let config = Config {
        fault_delay_ms: 60_000,
        ..Config::default()
    };
    let restarts: [(&str, Restart); 6] = [
        ("a dropout", |m, t| {
            (t..t + 10).for_each(|t| {
                m.process(Sample::new(t * 1000, f32::NAN, 1e-4));
            });
            t + 10
        }),
        ("a stop", |m, t| {
            (t..t + 60).for_each(|t| {
                m.process(Sample::new(t * 1000, 20.0, 1e-4));
            });
            t + 60
        }),
        ("a new configuration", |m, t| {
            m.set_config(*m.config()).unwrap();
            t
        }),
        ("a new scene", |m, t| {
            m.set_estimator(core());
            t
        }),
        ("a checkpoint of other accepted ranges", |m, t| {
            // Taken from a monitor that accepts loads up to 60 kN and ran at 55 kN:
            // this one's conditioning cannot take its windows.
            let wide = Config {
                load_max: 60_000.0,
                ..*m.config()
            };
            let mut other = Monitor::new(core(), wide).unwrap();
            for i in 0..t {
                other.process(Sample::new(i * 1000, 55e3 + (i % 7) as f32, 1e-4));
            }
            *m = Monitor::restore(core(), *m.config(), &other.snapshot()).unwrap();
            t
        }),
        ("a checkpoint taken while settling", |m, t| {
            (t..t + 10).for_each(|t| {
                m.process(Sample::new(t * 1000, f32::NAN, 1e-4));
            });
            m.process(Sample::new((t + 10) * 1000, LOAD, 1e-4));
            *m = Monitor::restore(core(), *m.config(), &m.snapshot()).unwrap();
            t + 11
        }),
    ];
    for (restart, go) in restarts {
        let mut m = Monitor::new(core(), config).unwrap();
        normal_run(&mut m, 0, 120);
        let t = go(&mut m, 120);
        let held = m.state();
        m.process(Sample::new(t * 1000, LOAD, 3e-3));
        assert_eq!(m.state(), held, "{restart}");
        assert!(m.settling(), "{restart}");
        // The glitch is the first fresh sample (the second after the checkpoint taken
        // while settling); the 8th decides.
        let fresh = if restart.contains("while settling") {
            2
        } else {
            1
        };
        let deciding = 8 - fresh - 1;
        let mut states = Vec::new();
        for t in t + 1..t + 61 {
            states.push(normal_run(&mut m, t, 1)[0]);
            assert_eq!(
                m.settling(),
                states.len() < deciding + 1,
                "{restart} at {t} s"
            );
        }
        assert!(
            states[..deciding].iter().all(|&s| s == held),
            "{restart}: {states:?}"
        );
        assert!(
            states[deciding..].iter().all(|&s| s == RiskState::Normal),
            "{restart}: {states:?}"
        );
        // A reset of the statistics is no restart.
        m.reset_statistics();
        assert!(!m.settling());
        assert_eq!(m.statistics().spikes(), 0);
        assert_eq!(
            m.process(Sample::new((t + 61) * 1000, LOAD, 3e-3)),
            RiskState::Normal
        );
        assert_eq!(m.statistics().spikes(), 1, "{restart}: tested as a spike");
    }
}
