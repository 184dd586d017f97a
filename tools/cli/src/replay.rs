//! The monitor example's replay, written once for each of its front ends (the example,
//! `cargo run --example monitor`, and the web page's WebAssembly binding,
//! `tools/web/wasm`): the samples ([`Samples`]: the built-in scenario, or a trace read
//! row by row), the first pass's [`Survey`] (how many samples, the load range the model
//! is chosen for, the loads' 99.9th percentile for the planner), the core of a
//! [`Model`] for that range with the monitor over it ([`Replay`]), the second pass
//! handing every event to a [`Sink`] as it happens ([`run`]), and the planner's table
//! over the trace's loads ([`Replay::thresholds`]). What a front end writes from it
//! (`monitor_output`'s rows) is then the same bytes in each.

use crate::monitor_input::Trace;
use crate::monitor_output::{self as output, PlanError, PlanRange, ThresholdPlan};
use crate::reference_core::ReferenceCore;
use misalign::fixed::FixedAuto;
use misalign::float::Auto;
use misalign::monitor::{
    Config, Event, FrictionStatus, Monitor, Reading, RiskState, Sample, Statistics, scenario,
};
use misalign::reference::ModelChoice;
use misalign::{Error, Estimator, Scene};
use std::io::BufRead;

type Res<T> = Result<T, Box<dyn std::error::Error>>;

/// The estimator core a replay runs on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Model {
    /// The f32 core (Cortex-M4F), model chosen for the operating range (section 9).
    F32,
    /// The fixed-point core (Cortex-M0/M3).
    Fixed,
    /// The f64 reference of the whole paper, rounded to f32 (PC only).
    Reference,
}

impl Model {
    /// Its name in the tools' options (`f32`, `fixed`, `reference`).
    pub const fn as_str(self) -> &'static str {
        match self {
            Model::F32 => "f32",
            Model::Fixed => "fixed",
            Model::Reference => "reference",
        }
    }

    /// The model named `name`, or the message listing the names.
    pub fn parse(name: &str) -> Result<Model, String> {
        [Model::F32, Model::Fixed, Model::Reference]
            .into_iter()
            .find(|m| m.as_str() == name)
            .ok_or_else(|| format!("model {name:?}: f32, fixed or reference"))
    }
}

impl scenario::Core for ReferenceCore {
    fn with_model(scene: &Scene, choice: ModelChoice) -> Result<Self, Error> {
        ReferenceCore::with_choice(scene, choice)
    }
}

/// The samples of a replay: the built-in scenario or a trace, read from its start.
#[derive(Debug)]
pub enum Samples<R> {
    /// `misalign::monitor::scenario`: one 8 h shift of a press roller pair.
    Builtin(scenario::Scenario),
    /// A recorded trace (the monitor example's `--trace` format).
    Trace(Box<Trace<R>>),
}

impl<R: BufRead> Samples<R> {
    /// The built-in scenario.
    pub fn builtin() -> Self {
        Samples::Builtin(scenario::Scenario::new())
    }

    /// A trace: `Err` when its header lacks a column or repeats one.
    pub fn trace(input: R) -> Res<Self> {
        Ok(Samples::Trace(Box::new(Trace::new(input)?)))
    }

    /// The trace, if it is one (its delimiter, its skipped and unreadable rows).
    pub fn as_trace(&self) -> Option<&Trace<R>> {
        match self {
            Samples::Trace(t) => Some(t),
            Samples::Builtin(_) => None,
        }
    }
}

impl<R: BufRead> Iterator for Samples<R> {
    type Item = Result<Sample, String>;

    fn next(&mut self) -> Option<Self::Item> {
        match self {
            Samples::Builtin(s) => s.next().map(Ok),
            Samples::Trace(t) => t.next(),
        }
    }
}

/// What the first pass learns: how many samples, the largest finite load (N, at least
/// the scenario's), and (for the planner) the first pass of the loads' 99.9th
/// percentile.
#[derive(Debug, Clone)]
pub struct Survey {
    /// Samples in the trace.
    pub total: u64,
    /// The largest finite load (N), at least [`scenario::LOAD_MAX`]: the range the
    /// model is chosen for, once (section 9).
    pub load_max: f64,
    loads: Option<Quantile>,
}

impl Survey {
    /// The first pass over `samples`; with `planner`, the loads are counted for the
    /// planner's range. `Err`: the trace's message why the monitor cannot take it.
    pub fn of(
        samples: impl Iterator<Item = Result<Sample, String>>,
        planner: bool,
    ) -> Result<Survey, String> {
        let mut s = Survey {
            total: 0,
            load_max: scenario::LOAD_MAX,
            loads: planner.then(Quantile::default),
        };
        for sample in samples {
            let load = sample?.load;
            s.total += 1;
            if load.is_finite() {
                s.load_max = s.load_max.max(f64::from(load));
                if let Some(q) = &mut s.loads {
                    q.count(load);
                }
            }
        }
        Ok(s)
    }
}

/// How a monitor takes a sample: `Monitor::process_with_friction` where the core has
/// an inverse (mu from a measured F), `Monitor::process` on the fixed-point core.
type Step<E> = fn(&mut Monitor<E>, Sample) -> RiskState;

/// The monitor over one core with the default configuration, and what the planner
/// needs of the second pass.
#[derive(Debug)]
pub struct Core<E: Estimator> {
    monitor: Monitor<E>,
    step: Step<E>,
    core: E,
    config: Config,
    loads: Option<Quantile>,
}

impl<E: Estimator + Copy> Core<E> {
    fn new(core: E, step: Step<E>, loads: Option<Quantile>) -> Res<Self> {
        let config = Config::default();
        let monitor = Monitor::new(core, config).map_err(|e| format!("configuration: {e}"))?;
        // The planner's range is the loads' 99.9th percentile, so that a spike does
        // not stretch it (none without a finite load: the planner's lowest range).
        let loads = loads.map(|mut q| {
            q.aim(|n| n * 999 / 1000);
            q
        });
        Ok(Core {
            monitor,
            step,
            core,
            config,
            loads,
        })
    }

    fn process(&mut self, sample: Sample) -> RiskState {
        if let Some(q) = &mut self.loads
            && sample.load.is_finite()
        {
            q.refine(sample.load);
        }
        (self.step)(&mut self.monitor, sample)
    }

    fn thresholds(&self) -> Option<Result<ThresholdPlan, PlanError>> {
        let range = PlanRange::Trace(self.loads.as_ref()?.value());
        Some(output::threshold_plan(&self.core, &self.config, range))
    }
}

/// A replay on one of the three cores: the monitor over the model chosen once for the
/// survey's load range (`scenario::estimator_for`, as the node is built), fed the
/// second pass's samples.
#[derive(Debug)]
pub enum Replay {
    /// The f32 core (`float::Auto`), mu tracked from a measured F.
    F32(Box<Core<Auto>>),
    /// The fixed-point core (`fixed::FixedAuto`), no inverse.
    Fixed(Box<Core<FixedAuto>>),
    /// The reference ([`ReferenceCore`]), mu tracked from a measured F.
    Reference(Box<Core<ReferenceCore>>),
}

/// `$body` with `$m` the replay's [`Core`], whatever its estimator.
macro_rules! each {
    ($replay:expr, $m:ident => $body:expr) => {
        match $replay {
            Replay::F32($m) => $body,
            Replay::Fixed($m) => $body,
            Replay::Reference($m) => $body,
        }
    };
}

impl Replay {
    /// The monitor on `model`'s core for `scene` over the survey's load range (the
    /// survey's count of the loads goes with it, to the planner).
    ///
    /// # Errors
    /// The model choice's and the core's errors for the scene, a refused configuration.
    pub fn new(model: Model, scene: &Scene, survey: &mut Survey) -> Res<Replay> {
        let (load_max, loads) = (survey.load_max, survey.loads.take());
        Ok(match model {
            Model::F32 => Replay::F32(Box::new(Core::new(
                scenario::estimator_for::<Auto>(scene, load_max)?,
                Monitor::process_with_friction,
                loads,
            )?)),
            Model::Fixed => Replay::Fixed(Box::new(Core::new(
                scenario::estimator_for::<FixedAuto>(scene, load_max)?,
                Monitor::process,
                loads,
            )?)),
            Model::Reference => Replay::Reference(Box::new(Core::new(
                scenario::estimator_for::<ReferenceCore>(scene, load_max)?,
                Monitor::process_with_friction,
                loads,
            )?)),
        })
    }

    /// One sample through the monitor; its state after it.
    pub fn process(&mut self, sample: Sample) -> RiskState {
        each!(self, m => m.process(sample))
    }

    /// The oldest event not taken yet.
    pub fn pop_event(&mut self) -> Option<Event> {
        each!(self, m => m.monitor.pop_event())
    }

    /// The last valid reading (`Monitor::reading`).
    pub fn reading(&self) -> Option<Reading> {
        each!(self, m => m.monitor.reading())
    }

    /// Monotonic time since the first sample (ms).
    pub fn elapsed_ms(&self) -> u64 {
        each!(self, m => m.monitor.elapsed_ms())
    }

    /// The monitor's state.
    pub fn state(&self) -> RiskState {
        each!(self, m => m.monitor.state())
    }

    /// What the monitor counted.
    pub fn statistics(&self) -> &Statistics {
        each!(self, m => m.monitor.statistics())
    }

    /// Time to critical (s) at the margin's drift.
    pub fn time_to_critical(&self) -> Option<f32> {
        each!(self, m => m.monitor.time_to_critical())
    }

    /// The filtered mu (with a measured F, on a core with an inverse).
    pub fn friction(&self) -> Option<f32> {
        each!(self, m => m.monitor.friction())
    }

    /// The captured mu baseline.
    pub fn friction_baseline(&self) -> Option<f32> {
        each!(self, m => m.monitor.friction_baseline())
    }

    /// Friction tracking's counts.
    pub fn friction_status(&self) -> &FrictionStatus {
        each!(self, m => m.monitor.friction_status())
    }

    /// The monitor's configuration (its thresholds, as a plot draws them).
    pub fn config(&self) -> &Config {
        each!(self, m => &m.config)
    }

    /// The planner's table (the monitor example's `--thresholds`) over loads up to
    /// 1.2 times the trace's 99.9th percentile (`PlanRange::Trace`), on the replay's
    /// core and configuration; `None` unless the survey counted the loads.
    pub fn thresholds(&self) -> Option<Result<ThresholdPlan, PlanError>> {
        each!(self, m => m.thresholds())
    }
}

/// The planner's table (`monitor_output::threshold_plan`) on `model`'s core for
/// `scene`, its contact model chosen once for loads up to `range_max` (N, as a replay
/// chooses it for its trace), under `config`, over `range`.
///
/// # Errors
/// The model choice's and the core's errors for the scene; a range the planner
/// cannot honour ([`PlanError`]).
pub fn plan(
    model: Model,
    scene: &Scene,
    config: &Config,
    range_max: f64,
    range: PlanRange,
) -> Res<ThresholdPlan> {
    Ok(match model {
        Model::F32 => output::threshold_plan(
            &scenario::estimator_for::<Auto>(scene, range_max)?,
            config,
            range,
        )?,
        Model::Fixed => output::threshold_plan(
            &scenario::estimator_for::<FixedAuto>(scene, range_max)?,
            config,
            range,
        )?,
        Model::Reference => output::threshold_plan(
            &scenario::estimator_for::<ReferenceCore>(scene, range_max)?,
            config,
            range,
        )?,
    })
}

/// Where the second pass's output goes, as it happens.
pub trait Sink {
    /// An event, in the order the monitor raised it.
    ///
    /// # Errors
    /// The sink's own (a file that cannot be written): the replay stops.
    fn event(&mut self, event: &Event) -> Res<()>;

    /// After each sample (its events already given): the replay as it stands.
    ///
    /// # Errors
    /// The sink's own: the replay stops.
    fn sample(&mut self, replay: &Replay, state: RiskState) -> Res<()> {
        let _ = (replay, state);
        Ok(())
    }
}

/// The second pass: every sample of `samples` through `replay`, its events and then
/// itself to `sink`.
///
/// # Errors
/// The trace's message why the monitor cannot take it (naming the row), the sink's.
pub fn run(
    replay: &mut Replay,
    samples: impl Iterator<Item = Result<Sample, String>>,
    sink: &mut dyn Sink,
) -> Res<()> {
    for sample in samples {
        let state = replay.process(sample?);
        while let Some(e) = replay.pop_event() {
            sink.event(&e)?;
        }
        sink.sample(replay, state)?;
    }
    Ok(())
}

/// An order statistic of f32 values (the same as sorting them by `total_cmp` and
/// taking one) in two passes over them and fixed memory: the first counts the values
/// by the high 16 bits of their order key, the second, within the bin that holds the
/// wanted rank, by the low 16.
#[derive(Debug, Clone)]
pub struct Quantile {
    high: Vec<u64>,
    low: Vec<u64>,
    count: u64,
    /// After the first pass: the wanted high bits and the rank within them.
    target: Option<(u32, u64)>,
}

/// A key whose unsigned order is `f32::total_cmp`'s.
fn key(x: f32) -> u32 {
    let b = x.to_bits();
    if b >> 31 == 1 { !b } else { b | 1 << 31 }
}

fn from_key(k: u32) -> f32 {
    f32::from_bits(if k >> 31 == 1 { k & !(1 << 31) } else { !k })
}

impl Default for Quantile {
    fn default() -> Self {
        Quantile {
            high: vec![0; 1 << 16],
            low: vec![0; 1 << 16],
            count: 0,
            target: None,
        }
    }
}

impl Quantile {
    /// First pass: a value.
    pub fn count(&mut self, x: f32) {
        self.high[(key(x) >> 16) as usize] += 1;
        self.count += 1;
    }

    /// Between the passes: the rank wanted, as `rank(n)` of the n values counted (0
    /// the smallest). `false` when no value was counted.
    pub fn aim(&mut self, rank: impl FnOnce(u64) -> u64) -> bool {
        if self.count == 0 {
            return false;
        }
        let mut r = rank(self.count).min(self.count - 1);
        for (h, &n) in self.high.iter().enumerate() {
            if r < n {
                self.target = Some((h as u32, r));
                return true;
            }
            r -= n;
        }
        false
    }

    /// Second pass: the same values again.
    pub fn refine(&mut self, x: f32) {
        let k = key(x);
        if let Some((h, _)) = self.target
            && k >> 16 == h
        {
            self.low[(k & 0xffff) as usize] += 1;
        }
    }

    /// After the second pass: the value of the rank aimed at.
    pub fn value(&self) -> Option<f32> {
        let (h, mut r) = self.target?;
        for (l, &n) in self.low.iter().enumerate() {
            if r < n {
                return Some(from_key(h << 16 | l as u32));
            }
            r -= n;
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_quantile_is_the_sorted_values_own() {
        let values: Vec<f32> = (0..20_001)
            .map(|i| ((i * 7919) % 20_001) as f32 * 0.37 - 100.0)
            .chain([f32::MAX, -0.0, 0.0, 1e-42])
            .collect();
        let mut sorted = values.clone();
        sorted.sort_by(f32::total_cmp);
        for rank in [
            |n: u64| n * 999 / 1000,
            |_| 0,
            |n: u64| n - 1,
            |n: u64| n / 2,
        ] {
            let mut q = Quantile::default();
            values.iter().for_each(|&x| q.count(x));
            assert!(q.aim(rank));
            values.iter().for_each(|&x| q.refine(x));
            let want = sorted[rank(sorted.len() as u64) as usize];
            assert_eq!(q.value().map(f32::to_bits), Some(want.to_bits()));
        }
        assert!(!Quantile::default().aim(|n| n));
    }
}
