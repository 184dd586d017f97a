//! The condition monitor: from a stream of noisy samples to risk states, events,
//! wear and time to critical, with no heap and no panic, on the node and on the PC.
//!
//! Per sample ([`Monitor::process`]) the stages run once each, in this order, each in
//! its own file with its own state:
//!
//! 1. **clock** (`clock.rs`): the u32 ms counter made monotonic (a wrap is a forward
//!    step, a jump back a fault);
//! 2. **checks** (`checks.rs`): a sensor's or driver's report, non-finite or out of
//!    range values, stuck values, gaps; whether the machine runs;
//! 3. **conditioning** (`conditioning.rs`): spikes replaced by the Hampel window's
//!    median, load and angle smoothed with a weight that follows the real time step;
//!    after a restart it settles first ([`Monitor::settling`]);
//! 4. **estimate** (`estimate.rs`): the [`Estimator`]'s d/b, F, phi0 and margin, the
//!    [`Reading`];
//! 5. **energy** (`energy.rs`): the dissipated power F phi V (section 7) over the step;
//! 6. **trend** (`trend.rs`): the margin's trend gives the time to critical;
//! 7. **risk** (`risk.rs`): thresholds with deadband, on- and off-delays and the
//!    start-up inhibit decide the [`RiskState`];
//! 8. **friction** (`friction.rs`, [`Monitor::process_with_friction`] only): mu from a
//!    measured axial force;
//! 9. **events** (`events.rs`): state changes, the `Approaching` warning (a credible
//!    fit of the margin crosses zero ahead, sooner than the horizon, while the contact
//!    still sticks) and friction changes go to a fixed queue that a consumer drains
//!    ([`Monitor::pop_event`]);
//! 10. **statistics** (`statistics.rs`): the step's energy added to the state
//!     reported after it.
//!
//! **Settling.** No single sample decides a state after the conditioning starts
//! afresh (at the first sample, after a fault, a stop, a new configuration or scene,
//! a restored state it cannot take): the first valid running samples, as many as the
//! spike window holds, only fill its windows and ask for no change (the state is
//! held, and any change pending ends: they are valid and running); the next, the
//! first the spike test can test against them, decides. A start and its start-up
//! inhibit wait for it.
//!
//! Conditioning, estimate, energy and trend see only a valid running sample. The
//! stages count what they see into the [`Statistics`] (time per state, spikes,
//! extremes, faults, dropped events); they compare values through `order.rs` (order
//! and finiteness by the bits where floats are soft), which imports nothing from the
//! monitor.
//!
//! **Model choice (section 9).** The elliptic and the line-contact solutions differ
//! by up to 22 % in d/b where the ellipse reaches the rollers' ends; switching per
//! sample would make the states chatter there. The monitor *fixes the model for the
//! scene's operating range*: it is generic over one prepared [`Estimator`], to be
//! given a scene with one model: [`model_for_range`] chooses it once, from the
//! declared highest load and smallest misalignment, for
//! [`float::Auto::with_choice`](crate::float::Auto::with_choice) or
//! [`fixed::FixedAuto::with_choice`](crate::fixed::FixedAuto::with_choice) (or an
//! elliptic or line scene directly). d/b is then continuous in the samples, and the
//! deadband handles the noise. (An `Auto` scene left at `ModelChoice::Section9` would
//! switch per sample: not for a monitor.)
//!
//! **Sensor faults are never slip.** A faulted sample is not estimated; its
//! candidate state is `SensorFault`, and leaving that state waits the off-delay. Each
//! state waits its own delay from its own first candidate: a fault's time never counts
//! toward a slip state's on-delay, nor slip's toward the fault delay. A
//! fault the sensors' own detection found ([`Sample::sensor_fault`]; with the
//! `sensors` feature `Sample::from_sensors` carries it over) is counted and the
//! state change names the sensor and the reason
//! ([`FaultCause::Sensor`]).
//!
//! **Friction from a measured axial force.** With an f32 scene (which
//! implements [`FrictionInverse`]) and samples carrying a measured F,
//! [`Monitor::process_with_friction`] also tracks mu: the inverse of eqs (16, 21) or
//! (23, 27) at the conditioned load and angle, only where it is well-posed (exact, its
//! sensitivity at most [`FrictionConfig::sensitivity_max`]), filtered over the time
//! step, against a baseline captured at commissioning (or on demand,
//! [`Monitor::capture_friction_baseline`]); an [`EventKind::Friction`] when it leaves
//! the band, with deadband and delay. The fixed-point core has no inverse: its monitor
//! has only [`Monitor::process`] and never tracks mu.
//!
//! ```
//! use misalign::monitor::{Config, Monitor, RiskState, Sample, model_for_range};
//! use misalign::{Scene, float::Auto};
//!
//! let scene = Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3)?;
//! // One model for loads up to 5 kN and misalignments from 10 urad.
//! let core = Auto::with_choice(&scene, model_for_range(&scene, 5e3, 1e-5)?)?;
//! let mut monitor = Monitor::new(core, Config::default()).expect("the defaults are valid");
//! for i in 0..300u32 {
//!     // About 2 kN and 0.1 mrad with some noise (a value exactly constant for two
//!     // minutes is a stuck sensor), one sample a second.
//!     let noise = (i % 7) as f32;
//!     let (load, phi) = (2e3 + noise, 1e-4 + 1e-7 * noise);
//!     monitor.process(Sample::new(i * 1000, load, phi).with_speed(2.0));
//! }
//! assert_eq!(monitor.state(), RiskState::Normal);
//! assert!(monitor.statistics().total_energy() > 0.0);
//! assert_eq!(monitor.statistics().samples(), 300);
//! while let Some(event) = monitor.pop_event() {
//!     assert_eq!(event.seq, 0); // Stopped -> Normal
//! }
//! # Ok::<(), misalign::Error>(())
//! ```

pub mod annunciation;
#[cfg(feature = "sequential-storage")]
mod checkpoint;
mod checks;
mod clock;
mod conditioning;
mod config;
mod energy;
mod estimate;
mod events;
mod friction;
mod model;
mod order;
mod risk;
mod sample;
pub mod scenario;
mod state;
mod statistics;
mod trend;

pub use config::{
    Config, ConfigError, FrictionConfig, SPIKE_WINDOW_CAPACITY, SpikeFilter, TREND_CAPACITY,
    TREND_SLOPE_STANDARD_ERRORS, Thresholds, TrendConfig,
};
pub use energy::dissipated_power;
pub use events::{EVENT_CAPACITY, Event, EventKind, FaultCause, FieldbusEvent, Reading};
pub use friction::FrictionStatus;
pub use model::model_for_range;
pub use risk::RiskState;
pub use sample::{Channel, Sample};
pub use state::{MonitorState, STATE_BUDGET_BYTES};
pub use statistics::{FaultCounts, Statistics};
pub use trend::{TrendPoint, time_to_critical};
// Which sensor failed and why, as the sensors report it (feature `sensors`) and as
// the monitor's events name it (always).
pub use crate::sensor_fault::{FaultKind, SensorFault, SensorId};

use crate::reference::inverse::Inverse;
use crate::{Estimator, FrictionInverse};
use clock::{Clock, Step};

/// The condition monitor over one prepared scene of either core.
#[derive(Debug, Clone)]
pub struct Monitor<E> {
    estimator: E,
    config: Config,
    limits: checks::Limits,
    levels: risk::Levels,
    // Each stage's state, in the order a sample visits them.
    clock: Clock,
    checks: checks::Checks,
    conditioning: conditioning::Conditioning,
    /// The estimate stage's: the last valid running reading.
    reading: Option<Reading>,
    alarm: risk::Alarm,
    energy: energy::Energy,
    trend: trend::Trend,
    friction: FrictionStatus,
    events: events::Events,
    stats: Statistics,
}

/// The monitor's state, statistics and undelivered events (the estimator, the
/// configuration and the buffers are left out).
#[cfg(feature = "defmt")]
impl<E> defmt::Format for Monitor<E> {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(
            f,
            "Monitor {{ state: {}, statistics: {}, pending_events: {} }}",
            self.alarm.state,
            self.stats,
            self.events.queue.len()
        );
    }
}

/// Bytes of a monitor's configuration: the [`Config`] and what is formed from it
/// once (the state budget leaves them out).
const CONFIGURATION_BYTES: usize = core::mem::size_of::<Config>()
    + core::mem::size_of::<checks::Limits>()
    + core::mem::size_of::<risk::Levels>();

/// The friction stage's inverse: mu from the estimator at a conditioned load (N) and
/// angle (rad) and a measured axial force (N).
type FrictionOf<E> = fn(&E, f32, f32, f32) -> Option<Inverse<f32>>;

/// What a sample asks the risk stage for.
enum Asked {
    /// `SensorFault`, for this fault (of the checks, or the estimator's refusal).
    Fault(FaultCause),
    /// `Stopped`: the load or the speed is below its stop threshold.
    Stopped,
    /// No change: a valid running sample while the conditioning settles (it breaks
    /// every pending run, the sample being valid and running, and decides no level).
    Settling,
    /// The risk level of a valid running sample's reading, conditioned as `at`.
    Level {
        level: RiskState,
        at: conditioning::Conditioned,
    },
}

impl Asked {
    fn fault(&self) -> Option<FaultCause> {
        match *self {
            Asked::Fault(f) => Some(f),
            _ => None,
        }
    }
}

impl<E: Estimator> Monitor<E> {
    /// A monitor at rest (`Stopped`) over `estimator`.
    ///
    /// # Errors
    /// The [`ConfigError`] of an inconsistent configuration.
    pub fn new(estimator: E, config: Config) -> Result<Self, ConfigError> {
        config.validate()?;
        Ok(Monitor {
            estimator,
            limits: checks::Limits::new(&config),
            levels: risk::Levels::new(&config.thresholds),
            clock: Clock::new(),
            checks: checks::Checks::new(),
            conditioning: conditioning::Conditioning::new(&config),
            reading: None,
            alarm: risk::Alarm::new(),
            energy: energy::Energy::default(),
            trend: trend::Trend::new(),
            friction: FrictionStatus::new(),
            events: events::Events::new(),
            stats: Statistics::new(),
            config,
        })
    }

    /// The reported state.
    pub fn state(&self) -> RiskState {
        self.alarm.state
    }

    /// The configuration.
    pub fn config(&self) -> &Config {
        &self.config
    }

    /// The estimator.
    pub fn estimator(&self) -> &E {
        &self.estimator
    }

    /// Replaces the configuration between two samples, checked first: on an error
    /// nothing changes. State, statistics and events go on; the conditioning and the
    /// trend start afresh, their windows being formed under the old configuration
    /// (the conditioning settles again: [`settling`](Self::settling)).
    ///
    /// # Errors
    /// The [`ConfigError`] of an inconsistent configuration.
    pub fn set_config(&mut self, config: Config) -> Result<(), ConfigError> {
        config.validate()?;
        self.limits = checks::Limits::new(&config);
        self.levels = risk::Levels::new(&config.thresholds);
        self.conditioning = conditioning::Conditioning::new(&config);
        self.trend = trend::Trend::new();
        self.config = config;
        Ok(())
    }

    /// Replaces the scene between two samples. State, statistics and events go on; the
    /// conditioning and the trend start afresh (the trend's margins are the old
    /// scene's; the conditioning settles again: [`settling`](Self::settling)).
    pub fn set_estimator(&mut self, estimator: E) {
        self.estimator = estimator;
        self.conditioning.restart();
        self.trend = trend::Trend::new();
    }

    /// What the monitor has counted and integrated.
    pub fn statistics(&self) -> &Statistics {
        &self.stats
    }

    /// Starts the statistics afresh (after a roller change, say): the counts, the time
    /// and energy per state, the extremes. The state, the events and their numbers, the
    /// conditioning, the trend and the clock go on.
    pub fn reset_statistics(&mut self) {
        self.stats = Statistics::new();
    }

    /// The last valid running reading, if any: the conditioned load P (N) and
    /// misalignment phi (rad), d/b, the axial force F (N), the critical angle phi0
    /// (rad) and the margin phi0 - |phi| (rad).
    pub fn reading(&self) -> Option<Reading> {
        self.reading
    }

    /// The latest estimate of the time until gross slip (s) at the current drift of
    /// the margin: the time until the trend's fitted line crosses zero, ahead of its
    /// newest point; `None` while the trend is off or its window not full, and while
    /// the fit predicts no crossing ahead (the margin does not fall, its fall is within
    /// the scatter, see [`TREND_SLOPE_STANDARD_ERRORS`], or the fit is already at or
    /// below zero).
    pub fn time_to_critical(&self) -> Option<f32> {
        self.trend.time_to_critical_s
    }

    /// Whether the `Approaching` warning stands: it was raised (the time to critical
    /// fell below the horizon while the contact still stuck) and the time to critical
    /// has not since risen above 1.5 horizons or gone.
    pub fn approaching(&self) -> bool {
        !self.events.approaching_armed
    }

    /// Whether the conditioning is settling: since it started afresh (a new monitor, a
    /// fault, a stop, a new configuration or scene, a restored state it could not
    /// take) valid running samples have come, and the last of them was still filling
    /// the spike window (7 samples by default). Meanwhile no sample decides a state:
    /// the reported state is held; the next sample after the window is full decides.
    /// Never with spike rejection off.
    pub fn settling(&self) -> bool {
        self.conditioning.settling
    }

    /// Monotonic time since the first sample (ms).
    pub fn elapsed_ms(&self) -> u64 {
        self.clock.elapsed_ms
    }

    /// The oldest undelivered event.
    pub fn pop_event(&mut self) -> Option<Event> {
        self.events.queue.pop_front()
    }

    /// Undelivered events.
    pub fn pending_events(&self) -> usize {
        self.events.queue.len()
    }

    /// The sequence number the next event will carry (consecutive from 0, wrapping):
    /// every event so far was delivered, is pending, or was dropped
    /// ([`Statistics::events_dropped`]).
    pub fn next_event_seq(&self) -> u32 {
        self.events.next_seq
    }

    /// Raises an event of the node's fieldbus link (its server's: a reverted line
    /// change, the master lost or back), numbered after the monitor's own, at the last
    /// sample's time (0 before any) with the last reading.
    pub fn raise_fieldbus(&mut self, event: FieldbusEvent) {
        let time_ms = self.clock.last_time_ms.unwrap_or(0);
        self.emit(EventKind::Fieldbus(event), time_ms);
    }

    fn emit(&mut self, kind: EventKind, time_ms: u32) {
        let elapsed_ms = self.clock.elapsed_ms;
        if self.events.emit(kind, time_ms, elapsed_ms, self.reading) {
            self.stats.count_dropped_event();
        }
    }

    /// The filtered friction coefficient mu, `None` before the first well-posed
    /// estimate (always, over the fixed-point core: see
    /// [`process_with_friction`](Self::process_with_friction)).
    pub fn friction(&self) -> Option<f32> {
        self.friction.filtered()
    }

    /// The friction baseline captured at commissioning, if any.
    pub fn friction_baseline(&self) -> Option<f32> {
        self.friction.baseline()
    }

    /// The friction tracker's whole state (counts of accepted and rejected estimates,
    /// whether a change is raised).
    pub fn friction_status(&self) -> &FrictionStatus {
        &self.friction
    }

    /// Takes the filtered mu as the friction baseline now (commissioning on demand,
    /// e.g. after a change of lubricant); a raised friction change is cleared, with its
    /// event. Returns the baseline, `None` (nothing changes) before the first
    /// well-posed estimate.
    pub fn capture_friction_baseline(&mut self) -> Option<f32> {
        let (baseline, cleared) = self.friction.capture()?;
        if cleared {
            let time_ms = self.clock.last_time_ms.unwrap_or(0);
            self.emit(
                EventKind::Friction {
                    mu: baseline,
                    changed: false,
                },
                time_ms,
            );
        }
        Some(baseline)
    }

    /// Processes one sample and returns the state after it. Never panics; whatever
    /// the input, bad values are counted as faults and reported as `SensorFault`,
    /// never as slip. A measured axial force is checked and used in the energy
    /// integral; mu is tracked from it only by
    /// [`process_with_friction`](Self::process_with_friction).
    pub fn process(&mut self, sample: Sample) -> RiskState {
        self.pipeline(sample, None)
    }

    /// One sample through the stages, each once, in order; the friction stage only
    /// with `friction` (the estimator's inverse).
    fn pipeline(&mut self, sample: Sample, friction: Option<FrictionOf<E>>) -> RiskState {
        self.stats.count_sample();
        let held = self.alarm.state;
        let Some((dt_ms, clock_fault)) = self.clock_step(sample.time_ms) else {
            return held; // a repeated timestamp, counted
        };
        let now = self.clock.elapsed_ms;
        // Each step counts for the state held during it.
        self.stats.add_time(held, dt_ms);
        let checked = self
            .checks
            .check(&self.limits, &sample, dt_ms, now, clock_fault);
        let asked = match checked.fault {
            Some(f) => Asked::Fault(f),
            None if !checked.running => Asked::Stopped,
            None => self.running(&sample, checked.speed, dt_ms, now),
        };
        let changed = self.risk(&asked, now);
        let friction = match (friction, &asked) {
            (Some(inverse), Asked::Level { at, .. }) => {
                self.friction_step(inverse, at, sample.axial_force, dt_ms, now)
            }
            _ => None,
        };
        self.events_step(changed, &asked, friction, sample.time_ms, now);
        self.statistics_step()
    }

    /// Clock: the step (ms) since the previous sample and the clock's fault (time
    /// backwards), or `None` for a repeated timestamp (counted, ignored).
    #[inline(always)]
    fn clock_step(&mut self, time_ms: u32) -> Option<(u32, Option<FaultCause>)> {
        match self.clock.step(time_ms) {
            Step::Forward(d) => Some((d, None)),
            Step::First => Some((0, None)),
            Step::Repeated => {
                self.stats.count_repeated();
                None
            }
            Step::Backwards => Some((0, Some(FaultCause::TimeBackwards))),
        }
    }

    /// Conditioning, estimate, energy and trend of a valid running sample after a step
    /// of `dt_ms` at speed `speed` (m/s), and the risk level its reading asks for (a
    /// fault when the estimator refuses it; no change while the conditioning settles:
    /// the machine's start and its start-up inhibit wait for the settled sample).
    #[inline(always)]
    fn running(&mut self, sample: &Sample, speed: f32, dt_ms: u32, now: u64) -> Asked {
        let (config, stats) = (&self.config, &mut self.stats);
        let Some(at) = self
            .conditioning
            .condition(config, sample.load, sample.phi, dt_ms, stats)
        else {
            return Asked::Settling;
        };
        self.alarm.note_running(now);
        let r = match estimate::estimate(&self.estimator, &at, sample.axial_force) {
            Ok(r) => r,
            Err(f) => return Asked::Fault(f),
        };
        self.reading = Some(r);
        self.stats.note_reading(&r);
        // Energy over the step ending here (for the state reported after it).
        self.energy.note(r.axial_force, r.phi, speed, at.dt_s);
        if let (Some(tc), Some(m)) = (self.config.trend, r.margin) {
            self.trend.add(tc, m, now);
        }
        let (config, levels) = (&self.config, &self.levels);
        let level = self
            .alarm
            .level(config, levels, r.slip_ratio, r.margin, now);
        Asked::Level { level, at }
    }

    /// Risk: the state machine offered what the sample asks for; returns the state
    /// left when it changes. A sample that was not estimated restarts the
    /// conditioning (a fault is counted).
    #[inline(always)]
    fn risk(&mut self, asked: &Asked, now: u64) -> Option<RiskState> {
        let candidate = match *asked {
            Asked::Fault(f) => {
                self.not_estimated(f);
                RiskState::SensorFault
            }
            Asked::Stopped => {
                self.conditioning.restart();
                RiskState::Stopped
            }
            Asked::Settling => self.alarm.state,
            Asked::Level { level, .. } => level,
        };
        self.alarm.offer(&self.config, candidate, now)
    }

    /// Friction: mu from the measured axial force `force` (N) at the conditioned
    /// sample `at` through `inverse`; `Some((mu, changed))` when a friction change is
    /// raised or cleared.
    #[inline(always)]
    fn friction_step(
        &mut self,
        inverse: FrictionOf<E>,
        at: &conditioning::Conditioned,
        force: Option<f32>,
        dt_ms: u32,
        now: u64,
    ) -> Option<(f32, bool)> {
        let (config, force) = (self.config.friction?, force?);
        let answer = inverse(&self.estimator, at.load, at.phi, force);
        let running_ms = self.alarm.started_ms.map_or(0, |s| now.saturating_sub(s));
        self.friction
            .offer(&config, answer, dt_ms, running_ms)
            .map(|changed| (self.friction.mu, changed))
    }

    /// Events: the state change (from `changed`), the `Approaching` warning, the
    /// friction change, for the sample stamped `time_ms` at monotonic time `now`.
    #[inline(always)]
    fn events_step(
        &mut self,
        changed: Option<RiskState>,
        asked: &Asked,
        friction: Option<(f32, bool)>,
        time_ms: u32,
        now: u64,
    ) {
        if let Some(from) = changed {
            self.state_changed(from, asked.fault(), time_ms);
        }
        let (trend, ttc) = (&self.trend, self.trend.time_to_critical_s);
        let fit_age_s = || trend.fit_age_s(now);
        let state = self.alarm.state;
        if let Some(t) = self
            .events
            .approaching(self.config.trend, ttc, fit_age_s, state)
        {
            let kind = EventKind::Approaching {
                time_to_critical_s: t,
            };
            self.emit(kind, time_ms);
        }
        if let Some((mu, changed)) = friction {
            self.emit(EventKind::Friction { mu, changed }, time_ms);
        }
    }

    /// Statistics: the step's energy for the state reported after it, which is
    /// returned.
    #[inline(always)]
    fn statistics_step(&mut self) -> RiskState {
        let state = self.alarm.state;
        if let Some(j) = self.energy.take() {
            self.stats.add_energy(state, j);
        }
        state
    }

    /// A sample that was not estimated for fault `f`: counted, and the conditioning
    /// starts afresh.
    #[cold]
    fn not_estimated(&mut self, f: FaultCause) {
        self.stats.count_fault(f);
        self.conditioning.restart();
    }

    /// The event of a state change from `from`, naming the fault behind a change to
    /// `SensorFault`.
    #[cold]
    fn state_changed(&mut self, from: RiskState, fault: Option<FaultCause>, time_ms: u32) {
        let to = self.alarm.state;
        let fault = if to == RiskState::SensorFault {
            fault
        } else {
            None
        };
        self.emit(EventKind::StateChange { from, to, fault }, time_ms);
    }
}

impl<E: Estimator> Monitor<E> {
    /// The whole state as a plain value.
    pub fn snapshot(&self) -> MonitorState {
        let [load_window, angle_window] = &self.conditioning.windows;
        MonitorState {
            clock: self.clock,
            alarm: self.alarm,
            smoothed: self.conditioning.smoothed,
            checks: self.checks,
            trend_interval: self.trend.interval,
            time_to_critical_s: self.trend.time_to_critical_s,
            approaching_armed: self.events.approaching_armed,
            next_seq: self.events.next_seq,
            reading: self.reading,
            energy: self.energy,
            stats: self.stats,
            friction: self.friction,
            load_window: state::Saved::from_iter(0.0, load_window.iter()),
            angle_window: state::Saved::from_iter(0.0, angle_window.iter()),
            trend: state::Saved::from_iter(
                TrendPoint::default(),
                self.trend.points.iter().copied(),
            ),
            events: state::Saved::from_iter(state::NO_EVENT, self.events.queue.iter().copied()),
        }
    }

    /// A monitor over `estimator` and `config` that goes on from `state`.
    ///
    /// # Errors
    /// The [`ConfigError`] of an inconsistent configuration.
    pub fn restore(
        estimator: E,
        config: Config,
        state: &MonitorState,
    ) -> Result<Self, ConfigError> {
        let mut m = Monitor::new(estimator, config)?;
        m.resume(state);
        Ok(m)
    }

    /// Goes on from `state` (a snapshot of a monitor with this configuration) in
    /// place of whatever this monitor held: [`restore`](Self::restore) without a
    /// second monitor on the stack. With `storage::Store::restore_into` (feature
    /// `sequential-storage`) a node restores its state at start-up holding one monitor
    /// and one state.
    ///
    /// The conditioning holds only values this configuration accepts: a smoothed
    /// value, or a spike window holding a value, outside its load and angle ranges (a
    /// state of another configuration, or no monitor's) is left out, and the
    /// conditioning starts afresh there, as after a fault (and settles again). A state
    /// taken while the conditioning settled goes on settling (read from its windows:
    /// taken just after the sample that filled them, `settling` reads false, and the
    /// next sample decides either way).
    pub fn resume(&mut self, state: &MonitorState) {
        self.clock = state.clock;
        self.alarm = state.alarm;
        let limits = &self.limits;
        self.conditioning.smoothed = state.smoothed.filter(|&[l, p]| limits.accepts([l], [p]));
        self.checks = state.checks;
        self.trend.interval = state.trend_interval;
        self.trend.time_to_critical_s = state.time_to_critical_s;
        self.events.approaching_armed = state.approaching_armed;
        self.events.next_seq = state.next_seq;
        self.reading = state.reading;
        self.energy = state.energy;
        self.stats = state.stats;
        self.friction = state.friction;
        // The buffers were filled from at most their own capacity: the pushes fit.
        let n = self
            .config
            .spikes
            .map_or(SPIKE_WINDOW_CAPACITY, |s| usize::from(s.window));
        let saved = [&state.load_window, &state.angle_window];
        let accepted = limits.accepts(saved[0].iter(), saved[1].iter());
        for (window, saved) in self.conditioning.windows.iter_mut().zip(saved) {
            window.clear();
            for x in saved.iter().filter(|_| accepted) {
                window.push_back(x, n);
            }
        }
        let window = self.config.spikes.map(|s| usize::from(s.window));
        self.conditioning.resumed(window);
        self.trend.points.clear();
        for p in state.trend.iter() {
            let _ = self.trend.points.push_back(p);
        }
        self.events.queue.clear();
        for e in state.events.iter() {
            let _ = self.events.queue.push_back(e);
        }
    }
}

impl<E: Estimator + FrictionInverse> Monitor<E> {
    /// [`process`](Self::process), and with a measured axial force F on a sample that
    /// was estimated, the friction coefficient mu from it: the
    /// inverse of eqs (16, 21) or (23, 27) at the conditioned load and angle
    /// ([`FrictionInverse`], the f32 scenes only). Only a well-posed answer counts (an
    /// exact mu with its sensitivity at most the configured cap; never a lower bound,
    /// as in gross slip where F = mu P only bounds it, nor an inconsistent one); it is
    /// filtered with the weight of its time step, the baseline is captured once the
    /// machine has run and enough estimates were accepted
    /// ([`FrictionConfig`]), and a [`EventKind::Friction`] event is raised when the
    /// filtered mu leaves the band around it for the delay, and cleared when it comes
    /// back inside the band less the deadband for the delay.
    ///
    /// A monitor over the fixed-point core (no inverse) has only `process` and never
    /// tracks mu.
    pub fn process_with_friction(&mut self, sample: Sample) -> RiskState {
        self.pipeline(
            sample,
            Some(|e: &E, load, phi, force| e.friction_from_axial_force(load, phi, force).ok()),
        )
    }
}

// The live monitor without its estimator and its configuration fits the state's RAM
// budget too, on every target.
const _: () =
    assert!(core::mem::size_of::<Monitor<()>>() - CONFIGURATION_BYTES <= STATE_BUDGET_BYTES);
