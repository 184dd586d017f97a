//! Friction tracking in the monitor: with a measured axial force F the
//! monitor tracks mu through the f32 inverse (eqs 16, 21), uses only well-posed
//! answers, captures a baseline at commissioning and raises a friction-change event
//! when the filtered mu leaves the band around it, without chattering. F is generated
//! with the forward f32 model at the true (drifting) mu.

use misalign::monitor::{
    Config, ConfigError, EventKind, FrictionConfig, Monitor, RiskState, Sample, model_for_range,
};
use misalign::reference::inverse::Inverse;
use misalign::{Estimator, FrictionInverse, Scene, fixed::FixedAuto, float::Auto};

const LOAD_N: f32 = 2000.0;
/// d/b about 0.5 at mu = 0.3: the inverse's sensitivity about 2.
const PHI_RAD: f32 = 2e-4;
const DESIGN_MU: f64 = 0.3;

fn scene(mu: f64) -> Scene {
    Scene::new(0.05, 0.05, 79.3e9, 0.3, mu).unwrap()
}

/// The f32 core of the demo scene at friction `mu`, with the monitor's model choice.
fn core(mu: f64) -> Auto {
    let s = scene(mu);
    Auto::with_choice(&s, model_for_range(&s, 5e3, 1e-5).unwrap()).unwrap()
}

/// Deterministic noise in [-1, 1] (xorshift32).
struct Noise(u32);
impl Noise {
    fn next(&mut self) -> f32 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.0 = x;
        (x as f64 / u32::MAX as f64 * 2.0 - 1.0) as f32
    }
}

/// One sample a second at time `t_s` whose measured F is the forward model's at the
/// true friction `mu`, each channel with relative noise `noise`.
fn sample(t_s: u32, mu: f64, noise: f32, rng: &mut Noise) -> Sample {
    let (p, phi) = (
        LOAD_N * (1.0 + noise * rng.next()),
        PHI_RAD * (1.0 + noise * rng.next()),
    );
    let f = core(mu).estimate_si(p, phi).unwrap().axial_force;
    Sample::new(t_s * 1000, p, phi).with_axial_force(f * (1.0 + noise * rng.next()))
}

/// The friction events of a monitor, as (time s, mu, changed).
/// Samples the conditioning settles on after a start afresh, which estimate nothing:
/// those that fill the spike window.
fn settling() -> u32 {
    u32::from(Config::default().spikes.unwrap().window)
}

fn friction_events<E: Estimator>(m: &mut Monitor<E>, out: &mut Vec<(f64, f32, bool)>) {
    while let Some(e) = m.pop_event() {
        if let EventKind::Friction { mu, changed } = e.kind {
            out.push((e.elapsed_ms as f64 / 1e3, mu, changed));
        }
    }
}

/// mu: 0.30 for 20 min, down to 0.18 over 40 min, 10 min there, back to 0.30 over
/// 10 min, 30 min there.
fn drifting_mu(t: u32) -> f64 {
    let t = f64::from(t);
    let ramp = |t0: f64, t1: f64, a: f64, b: f64| a + (b - a) * ((t - t0) / (t1 - t0));
    match t {
        t if t < 1200.0 => 0.30,
        t if t < 3600.0 => ramp(1200.0, 3600.0, 0.30, 0.18),
        t if t < 4200.0 => 0.18,
        t if t < 4800.0 => ramp(4200.0, 4800.0, 0.18, 0.30),
        _ => 0.30,
    }
}

#[test]
fn a_drifting_friction_is_raised_and_cleared_at_the_right_time() {
    let config = Config::default();
    let fc = config.friction.unwrap();
    let mut m = Monitor::new(core(DESIGN_MU), config).unwrap();
    let mut rng = Noise(0x1234_5678);
    let mut events = Vec::new();
    let mut baseline_at = None;
    for t in 1..=6600u32 {
        m.process_with_friction(sample(t, drifting_mu(t), 0.005, &mut rng));
        friction_events(&mut m, &mut events);
        if baseline_at.is_none() && m.friction_baseline().is_some() {
            baseline_at = Some(t);
        }
        // While mu is steady (after the filter's settling), the filtered mu is the
        // true one within the noise's share.
        if (900..1200).contains(&t) || (6000..6600).contains(&t) {
            let mu = m.friction().unwrap();
            assert!((mu - 0.3).abs() < 0.003, "{t} s: mu {mu}");
        }
        assert!(!matches!(m.state(), RiskState::SensorFault));
    }
    // The baseline: once the machine has run baseline_after_ms (from its start, at the
    // sample the conditioning settled on) with enough accepted estimates, near 0.3.
    let at = baseline_at.unwrap();
    let started = 1 + settling();
    assert_eq!(
        u64::from(at - started) * 1000,
        u64::from(fc.baseline_after_ms)
    );
    let baseline = m.friction_baseline().unwrap();
    assert!((baseline - 0.3).abs() < 0.003, "{baseline}");
    let status = m.friction_status();
    assert_eq!(status.rejected(), 0);
    assert_eq!(status.accepted(), 6600 - settling());

    // Raised once, cleared once.
    assert_eq!(events.len(), 2, "{events:?}");
    let ((t_up, mu_up, up), (t_down, mu_down, down)) = (events[0], events[1]);
    assert!(up && !down);
    let band = f64::from(fc.band);
    let clear = band - f64::from(fc.deadband);
    assert!(f64::from((mu_up / baseline - 1.0).abs()) > band);
    assert!(f64::from((mu_down / baseline - 1.0).abs()) < clear);
    // The true mu leaves the band at t1 and comes back within the deadband at t2; the
    // filter lags a ramp by tau, then the delay: each event between `delay` and
    // `delay + 3 tau` after its crossing.
    let b = f64::from(baseline);
    let crossing = |range: std::ops::Range<u32>, inside: &dyn Fn(f64) -> bool| {
        range
            .into_iter()
            .find(|&t| inside(drifting_mu(t)))
            .map(f64::from)
            .unwrap()
    };
    let t1 = crossing(1200..3600, &|mu| (mu / b - 1.0).abs() > band);
    let t2 = crossing(4200..4800, &|mu| (mu / b - 1.0).abs() < clear);
    let (delay, tau) = (f64::from(fc.delay_ms) / 1e3, f64::from(fc.tau_s));
    for (event, cross) in [(t_up, t1), (t_down, t2)] {
        assert!(
            event >= cross + delay && event <= cross + delay + 3.0 * tau,
            "event at {event} s, crossing at {cross} s"
        );
    }
    // The slip states never saw the friction (the installation's scene keeps mu = 0.3).
    assert_eq!(m.state(), RiskState::Normal);
}

#[test]
fn noise_at_the_band_edge_does_not_chatter() {
    let config = Config::default();
    let fc = config.friction.unwrap();
    let mut m = Monitor::new(core(DESIGN_MU), config).unwrap();
    let mut rng = Noise(0xDEAD_BEEF);
    let mut events = Vec::new();
    for t in 1..=900u32 {
        m.process_with_friction(sample(t, 0.3, 0.01, &mut rng));
    }
    let baseline = f64::from(m.friction_baseline().unwrap());
    // Two hours exactly at the band's edge, with 1 % noise on P, phi and F (about 2 %
    // on each sample's mu).
    let edge = baseline * (1.0 - f64::from(fc.band));
    for t in 901..=8100u32 {
        m.process_with_friction(sample(t, edge, 0.01, &mut rng));
        friction_events(&mut m, &mut events);
    }
    // At most one change, and never cleared again: clearing needs the deadband.
    assert!(events.len() <= 1, "{events:?}");
    assert!(events.iter().all(|e| e.2));
    assert_eq!(m.friction_status().rejected(), 0);
}

/// The inverse as the monitor calls it (through the trait).
fn through_trait<E: FrictionInverse>(core: &E, force: f32) -> Inverse<f32> {
    core.friction_from_axial_force(LOAD_N, PHI_RAD, force)
        .unwrap()
}

#[test]
fn every_f32_scene_inverts_through_the_trait() {
    let s = scene(DESIGN_MU);
    let f = core(DESIGN_MU)
        .estimate_si(LOAD_N, PHI_RAD)
        .unwrap()
        .axial_force;
    let elliptic = misalign::float::EllipticScene::new(&s).unwrap();
    let mu = |a: Inverse<f32>| a.value().unwrap();
    assert!((mu(through_trait(&elliptic, f)) - 0.3).abs() < 1e-5);
    assert!((mu(through_trait(&core(DESIGN_MU), f)) - 0.3).abs() < 1e-5);
    // Line contact, per unit length: its own forward F at the same P (N/m) and phi.
    let line = misalign::float::LineScene::new(&s).unwrap();
    let f_line = line.estimate_si(LOAD_N, PHI_RAD).unwrap().axial_force;
    assert!((mu(through_trait(&line, f_line)) - 0.3).abs() < 1e-5);
}

#[test]
fn ill_posed_answers_are_not_used() {
    let mut m = Monitor::new(core(DESIGN_MU), Config::default()).unwrap();
    let mut rng = Noise(7);
    for t in 1..=300u32 {
        m.process_with_friction(sample(t, 0.3, 0.005, &mut rng));
    }
    let before = *m.friction_status();
    assert_eq!(before.accepted(), 300 - settling());
    let estimator = core(DESIGN_MU);
    let cap = Config::default().friction.unwrap().sensitivity_max;
    // The measured F of three ill-posed kinds, each checked against the inverse itself:
    // a very high mu (F near the no-slip limit: too sensitive), F at the no-slip limit
    // (a lower bound only), F above anything the model gives (inconsistent).
    let f_of = |mu: f64| core(mu).estimate_si(LOAD_N, PHI_RAD).unwrap().axial_force;
    // The no-slip limit: just above the F of mu = 100, found by stepping up F until
    // the inverse says "at least".
    let near_limit = (0..10_000)
        .map(|k| f_of(100.0) * (1.0 + 1e-6 * k as f32))
        .find(|&f| {
            matches!(
                estimator.friction_from_axial_force(LOAD_N, PHI_RAD, f),
                Ok(Inverse::AtLeast { .. })
            )
        })
        .unwrap();
    let cases = [f_of(3.0), near_limit, f_of(3.0) * 1.05];
    let answers = cases.map(|f| through_trait(&estimator, f));
    assert!(matches!(answers[0], Inverse::Exact { sensitivity, .. } if sensitivity > cap));
    assert!(
        matches!(answers[1], Inverse::AtLeast { .. }),
        "{:?}",
        answers[1]
    );
    assert!(matches!(answers[2], Inverse::Inconsistent(_)));
    let mut t = 300u32;
    for f in cases {
        for i in 0..100 {
            t += 1;
            let phi = PHI_RAD * (1.0 + 1e-4 * (i % 5) as f32);
            m.process_with_friction(
                Sample::new(t * 1000, LOAD_N + i as f32 * 0.1, phi).with_axial_force(f),
            );
        }
    }
    let after = m.friction_status();
    assert_eq!(after.accepted(), before.accepted());
    assert_eq!(after.rejected(), before.rejected() + 300);
    assert_eq!(after.filtered().unwrap(), before.filtered().unwrap());
    // Gross slip is not ill-posed for mu: F = mu P there (eq 21 saturates), mu = F/P
    // exactly, with sensitivity 1.
    let gross = estimator
        .friction_from_axial_force(LOAD_N, 2e-3, 0.3 * LOAD_N)
        .unwrap();
    assert!(
        matches!(gross, Inverse::Exact { value, sensitivity } if (value - 0.3).abs() < 1e-6 && sensitivity == 1.0)
    );
}

#[test]
fn baseline_on_demand_and_recapture_clear_the_change() {
    let config = Config {
        friction: Some(FrictionConfig {
            baseline_after_ms: u32::MAX,
            ..FrictionConfig::default()
        }),
        ..Config::default()
    };
    let mut m = Monitor::new(core(DESIGN_MU), config).unwrap();
    assert_eq!(m.capture_friction_baseline(), None);
    let mut rng = Noise(99);
    for t in 1..=600u32 {
        m.process_with_friction(sample(t, 0.3, 0.005, &mut rng));
    }
    assert_eq!(
        m.friction_baseline(),
        None,
        "never by itself with this configuration"
    );
    let b = m.capture_friction_baseline().unwrap();
    assert_eq!(Some(b), m.friction());
    assert_eq!(m.friction_baseline(), Some(b));
    let mut events = Vec::new();
    // A new lubricant: mu 0.2 from now on. Raised; a recapture takes the new value as
    // the baseline and clears the change, with its event.
    for t in 601..=1200u32 {
        m.process_with_friction(sample(t, 0.2, 0.005, &mut rng));
    }
    friction_events(&mut m, &mut events);
    assert_eq!(events.iter().map(|e| e.2).collect::<Vec<_>>(), [true]);
    assert!(m.friction_status().changed());
    let b2 = m.capture_friction_baseline().unwrap();
    assert!((b2 - 0.2).abs() < 0.003, "{b2}");
    friction_events(&mut m, &mut events);
    assert_eq!(
        events.iter().map(|e| e.2).collect::<Vec<_>>(),
        [true, false]
    );
    assert!(!m.friction_status().changed());
}

#[test]
fn the_fixed_point_monitor_and_process_are_unaffected() {
    let s = scene(DESIGN_MU);
    let choice = model_for_range(&s, 5e3, 1e-5).unwrap();
    let fixed = FixedAuto::with_choice(&s, 1e-3, 1e-11, choice).unwrap();
    let no_friction = Config {
        friction: None,
        ..Config::default()
    };
    let mut with = Monitor::new(fixed, Config::default()).unwrap();
    let mut without = Monitor::new(fixed, no_friction).unwrap();
    let mut f32_tracking = Monitor::new(core(DESIGN_MU), Config::default()).unwrap();
    let mut f32_plain = Monitor::new(core(DESIGN_MU), Config::default()).unwrap();
    let mut rng = Noise(3);
    for t in 1..=3000u32 {
        // mu falls, and the misalignment grows into gross slip and back.
        let mu = 0.3 - 1e-4 * f64::from(t / 10);
        let mut s = sample(t, mu, 0.005, &mut rng);
        s.phi *= 1.0 + 3.0 * ((t as f32) / 500.0).sin().max(0.0);
        with.process(s);
        without.process(s);
        f32_tracking.process_with_friction(s);
        f32_plain.process(s);
    }
    // The fixed-point core has no inverse: no mu, no friction event, and the same
    // states and events as with friction tracking off.
    assert_eq!(with.friction(), None);
    assert_eq!(with.snapshot(), without.snapshot());
    // The f32 monitor's slip states and their events are the same with tracking; it
    // only adds the friction events.
    assert!(f32_tracking.friction().is_some());
    let states = |m: &mut Monitor<Auto>| {
        let mut out = Vec::new();
        while let Some(e) = m.pop_event() {
            if !matches!(e.kind, EventKind::Friction { .. }) {
                out.push((e.elapsed_ms, e.kind));
            }
        }
        out
    };
    assert_eq!(states(&mut f32_tracking), states(&mut f32_plain));
    assert_eq!(f32_tracking.statistics(), f32_plain.statistics());
}

#[test]
fn friction_configuration_is_validated() {
    let bad = [
        FrictionConfig {
            band: 0.0,
            ..FrictionConfig::default()
        },
        FrictionConfig {
            deadband: 0.2,
            ..FrictionConfig::default()
        },
        FrictionConfig {
            deadband: -0.01,
            ..FrictionConfig::default()
        },
        FrictionConfig {
            tau_s: f32::NAN,
            ..FrictionConfig::default()
        },
        FrictionConfig {
            sensitivity_max: 0.0,
            ..FrictionConfig::default()
        },
        FrictionConfig {
            baseline_after_estimates: 0,
            ..FrictionConfig::default()
        },
    ];
    for f in bad {
        let config = Config {
            friction: Some(f),
            ..Config::default()
        };
        assert_eq!(config.validate(), Err(ConfigError::Friction), "{f:?}");
        assert!(Monitor::new(core(DESIGN_MU), config).is_err());
    }
    assert_eq!(Config::default().validate(), Ok(()));
}
