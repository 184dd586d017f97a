//! A single outlier never changes the monitor's state: over random streams of steady
//! running (at loads and angles well inside one state's band), dropouts, stops and
//! starts, restored checkpoints, new configurations and scenes, one sample's load or
//! angle replaced by any value, anywhere (right after a fault, a stop, a start or a
//! restore too), leaves every state the stream reports as it was.

use misalign::fixed::FixedEllipticScene;
use misalign::float::EllipticScene;
use misalign::monitor::{Config, Monitor, RiskState, Sample, SpikeFilter};
use misalign::{Estimator, Scene};
use proptest::prelude::*;

fn scene() -> Scene {
    Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3).unwrap()
}

fn f32_core() -> EllipticScene<'static> {
    EllipticScene::new(&scene()).unwrap()
}

fn fixed_core() -> FixedEllipticScene {
    let lsb = FixedEllipticScene::min_angle_lsb(&scene()).max(1e-10);
    FixedEllipticScene::new(&scene(), 1e-2, lsb).unwrap()
}

#[path = "common/slip.rs"]
mod slip;

/// The misalignment (rad) at which d/b = `target` at `load`.
fn angle_for(target: f32, load: f32) -> f32 {
    slip::angle_for(&f32_core(), target, load)
}

/// One part of a stream.
#[derive(Debug, Clone, Copy)]
enum Part {
    /// Running at `load` (N) at the d/b of `level` (0.4 normal, 0.9 microslip, 1.4
    /// gross slip: each at least 0.05 from the thresholds 0.8 and 1.0 and from their
    /// clearing levels 0.75 and 0.95), the angle's sign `negative`.
    Running {
        load: f32,
        level: u8,
        negative: bool,
    },
    /// A dropout: `P = NaN`.
    Dropout,
    /// The machine stands: `P` below the stop load.
    Stop,
}

/// What happens to the monitor before a part's first sample.
#[derive(Debug, Clone, Copy)]
enum Action {
    None,
    /// Its state taken out and put back into a new monitor (a node's reset).
    Restore,
    /// The same configuration set again (the conditioning and the trend start afresh).
    Reconfigure,
    /// The same scene set again (the conditioning and the trend start afresh).
    NewScene,
    ResetStatistics,
}

/// A stream: parts of `n` samples, each after its action; running parts only ever
/// next to a dropout or a stop, so that the level changes only across a restart.
#[derive(Debug, Clone)]
struct Stream {
    parts: Vec<(Action, Part, usize)>,
    /// Time step (ms) of each sample, cycled.
    steps: Vec<u32>,
}

fn action() -> impl Strategy<Value = Action> {
    prop_oneof![
        8 => Just(Action::None),
        1 => Just(Action::Restore),
        1 => Just(Action::Reconfigure),
        1 => Just(Action::NewScene),
        1 => Just(Action::ResetStatistics),
    ]
}

fn pause() -> impl Strategy<Value = Part> {
    prop_oneof![Just(Part::Dropout), Just(Part::Stop)]
}

/// Streams of running parts at the levels of `levels`, each followed by a pause.
fn streams(levels: std::ops::RangeInclusive<u8>) -> impl Strategy<Value = Stream> {
    let running =
        (1_500.0f32..4_000.0, levels, any::<bool>()).prop_map(|(load, level, negative)| {
            Part::Running {
                load,
                level,
                negative,
            }
        });
    let block = (
        (action(), running, 1usize..150),
        (action(), pause(), 1usize..60),
    );
    (
        prop::option::of((action(), pause(), 1usize..60)),
        prop::collection::vec(block, 1..6),
        prop::collection::vec(500u32..1_500, 1..8),
    )
        .prop_map(|(lead, blocks, steps)| {
            let mut parts: Vec<_> = lead.into_iter().collect();
            for (run, pause) in blocks {
                parts.push(run);
                parts.push(pause);
            }
            Stream { parts, steps }
        })
}

/// One element of a materialised stream.
#[derive(Debug, Clone, Copy)]
enum Item {
    Act(Action),
    /// A sample, and whether it is a running one (a running part's).
    Sample(Sample, bool),
}

/// The stream's samples with small noise (10 N, 0.1 urad: below the spike floors,
/// and never a stuck value), its actions between them.
fn materialise(stream: &Stream) -> Vec<Item> {
    let mut items = Vec::new();
    let mut t = 0u32;
    let mut i = 0u32;
    for &(action, part, n) in &stream.parts {
        items.push(Item::Act(action));
        let angle = match part {
            Part::Running { load, level, .. } => {
                angle_for([0.4, 0.9, 1.4][usize::from(level)], load)
            }
            _ => 1e-4,
        };
        for _ in 0..n {
            t = t.wrapping_add(stream.steps[i as usize % stream.steps.len()]);
            i += 1;
            // A small deterministic scatter in -1..1.
            let u = (i.wrapping_mul(2_654_435_761) >> 16) as f32 / 32_768.0 - 1.0;
            let sample = match part {
                Part::Running { load, negative, .. } => {
                    let phi = angle + 1e-7 * u;
                    Sample::new(t, load + 10.0 * u, if negative { -phi } else { phi })
                }
                Part::Dropout => Sample::new(t, f32::NAN, angle + 1e-7 * u),
                Part::Stop => Sample::new(t, 20.0 + 10.0 * u, angle + 1e-7 * u),
            };
            items.push(Item::Sample(sample, matches!(part, Part::Running { .. })));
        }
    }
    items
}

/// The state after every sample of `items`, through a monitor over `core`.
fn states<E: Estimator + Clone>(core: E, config: Config, items: &[Item]) -> Vec<RiskState> {
    let mut m = Monitor::new(core.clone(), config).unwrap();
    let mut out = Vec::new();
    for item in items {
        match *item {
            Item::Act(Action::None) => {}
            Item::Act(Action::Restore) => {
                m = Monitor::restore(core.clone(), config, &m.snapshot()).unwrap();
            }
            Item::Act(Action::Reconfigure) => m.set_config(config).unwrap(),
            Item::Act(Action::NewScene) => m.set_estimator(core.clone()),
            Item::Act(Action::ResetStatistics) => m.reset_statistics(),
            Item::Sample(s, _) => out.push(m.process(s)),
        }
        // Drained: a full queue is no part of this.
        while m.pop_event().is_some() {}
    }
    out
}

/// A replacement of one sample's load or angle: the channel and the value.
#[derive(Debug, Clone, Copy)]
enum Outlier {
    Load(f32),
    Angle(f32),
}

impl Outlier {
    fn apply(self, s: Sample) -> Sample {
        match self {
            Outlier::Load(load) => Sample { load, ..s },
            Outlier::Angle(phi) => Sample { phi, ..s },
        }
    }
}

/// A value from `lo` to `hi` of any size: the ends, uniform, or log-uniform of either
/// sign from the smallest normal f32.
fn any_size(lo: f32, hi: f32) -> impl Strategy<Value = f32> {
    let log =
        (-38.0f32..hi.abs().max(lo.abs()).log10(), any::<bool>()).prop_map(|(e, negative)| {
            if negative {
                -(10f32.powf(e))
            } else {
                10f32.powf(e)
            }
        });
    prop_oneof![Just(lo), Just(hi), Just(0.0f32), lo..hi, log]
        .prop_filter("in the range", move |x| (lo..=hi).contains(x))
}

/// An outlier a valid running sample can carry: a load from the stop load to the
/// highest accepted, an angle of either sign up to the highest accepted.
fn running_outlier(config: Config) -> impl Strategy<Value = Outlier> {
    prop_oneof![
        any_size(config.stop_load, config.load_max).prop_map(Outlier::Load),
        any_size(-config.angle_max, config.angle_max).prop_map(Outlier::Angle),
    ]
}

/// An outlier of any value at all: a running sample's, or NaN, infinite, beyond the
/// accepted ranges, below the stop load.
fn any_outlier(config: Config) -> impl Strategy<Value = Outlier> {
    let value = prop_oneof![
        4 => any_size(-1e6, 1e6),
        1 => Just(f32::NAN),
        1 => Just(f32::INFINITY),
        1 => Just(f32::NEG_INFINITY),
        1 => any::<f32>(),
    ];
    prop_oneof![
        2 => running_outlier(config),
        1 => value.clone().prop_map(Outlier::Load),
        1 => value.prop_map(Outlier::Angle)
    ]
}

prop_compose! {
    /// The defaults with random delays, inhibit, spike window and k, and smoothing.
    fn configs()(on in 0u32..20_000, off in 0u32..40_000, fault in prop_oneof![Just(0u32), 0u32..60_000],
                 inhibit in prop_oneof![Just(0u32), 0u32..60_000], window in 3u8..=7, k in 2.0f32..6.0,
                 tau in prop_oneof![Just(0.0f32), 0.5f32..10.0]) -> Config {
        let defaults = Config::default();
        let spikes = defaults.spikes.map(|s| SpikeFilter { window, k, ..s });
        Config {
            on_delay_ms: on,
            off_delay_ms: off,
            fault_delay_ms: fault,
            inhibit_ms: inhibit,
            spikes,
            smoothing_tau_s: tau,
            ..defaults
        }
    }
}

/// The stream with the outlier at its `at`-th sample (of those `eligible` picks).
fn with_outlier(
    items: &[Item],
    at: prop::sample::Index,
    eligible: impl Fn(bool) -> bool,
    outlier: Outlier,
) -> Option<Vec<Item>> {
    let positions: Vec<usize> = (0..items.len())
        .filter(|&i| matches!(items[i], Item::Sample(_, running) if eligible(running)))
        .collect();
    if positions.is_empty() {
        return None;
    }
    let i = positions[at.index(positions.len())];
    let mut changed = items.to_vec();
    if let Item::Sample(s, running) = changed[i] {
        changed[i] = Item::Sample(outlier.apply(s), running);
    }
    Some(changed)
}

/// A valid running outlier at any running sample of any stream changes no state.
fn running_outlier_changes_nothing<E: Estimator + Clone>(
    core: E,
    config: Config,
    stream: &Stream,
    at: prop::sample::Index,
    outlier: Outlier,
) -> Result<(), TestCaseError> {
    let items = materialise(stream);
    let Some(changed) = with_outlier(&items, at, |running| running, outlier) else {
        return Ok(());
    };
    let want = states(core.clone(), config, &items);
    let got = states(core, config, &changed);
    prop_assert_eq!(got, want, "{:?}", outlier);
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Normal, microslip and gross slip, each reached and left across restarts: one
    /// outlier in a running sample leaves every state as it was (f32 core).
    #[test]
    fn one_outlier_changes_no_state(
        (config, outlier) in configs().prop_flat_map(|c| (Just(c), running_outlier(c))),
        stream in streams(0..=2),
        at in any::<prop::sample::Index>(),
    ) {
        running_outlier_changes_nothing(f32_core(), config, &stream, at, outlier)?;
    }

    /// An outlier of any value (NaN, infinite, out of range, below the stop load) at
    /// any sample of a stream that runs normally never raises microslip or gross slip.
    #[test]
    fn no_outlier_raises_slip_in_a_normal_stream(
        (config, outlier) in configs().prop_flat_map(|c| (Just(c), any_outlier(c))),
        stream in streams(0..=0),
        at in any::<prop::sample::Index>(),
    ) {
        let items = materialise(&stream);
        let Some(changed) = with_outlier(&items, at, |_| true, outlier) else { return Ok(()) };
        for s in states(f32_core(), config, &changed) {
            prop_assert!(!matches!(s, RiskState::Microslip | RiskState::GrossSlip), "{:?}: {:?}", outlier, s);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// The same over the fixed-point core.
    #[test]
    fn one_outlier_changes_no_state_fixed(
        (config, outlier) in configs().prop_flat_map(|c| (Just(c), running_outlier(c))),
        stream in streams(0..=2),
        at in any::<prop::sample::Index>(),
    ) {
        running_outlier_changes_nothing(fixed_core(), config, &stream, at, outlier)?;
    }
}
