//! The condition monitor: from a stream of noisy samples to risk states, events,
//! wear and time to critical, with no heap and no panic, on the node and on the PC.
//!
//! Per sample ([`Monitor::process`]): the clock steps (u32 ms wraps are forward
//! steps), the sensor checks run (non-finite, out of range, stuck, gap, time
//! backwards, a driver's report), spikes are replaced by the Hampel window's median,
//! load and angle are smoothed with a weight that follows the real time step, the
//! [`Estimator`] answers d/b, F, phi0 and the margin, the state machine applies
//! thresholds, deadband, on- and off-delays and the start-up inhibit, the
//! dissipated power F phi V (section 7) is integrated per state, and the margin's
//! trend gives the time to critical. State changes and `Approaching` warnings go to a
//! fixed queue that a consumer drains ([`Monitor::pop_event`]).
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
//! candidate state is `SensorFault`, and leaving that state waits the off-delay. A
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
//! while let Some(event) = monitor.pop_event() {
//!     assert_eq!(event.seq, 0); // Stopped -> Normal
//! }
//! # Ok::<(), misalign::Error>(())
//! ```

pub mod annunciation;
#[cfg(feature = "sequential-storage")]
mod checkpoint;
mod condition;
mod config;
mod events;
mod friction;
mod model;
mod risk;
mod sample;
pub mod scenario;
mod state;
mod stats;
mod trend;
mod wear;

pub use condition::StuckTracker;
pub use config::{
    Config, ConfigError, SPIKE_WINDOW_CAPACITY, SpikeFilter, TREND_CAPACITY, Thresholds,
    TrendConfig,
};
pub use events::{EVENT_CAPACITY, Event, EventKind, FaultCause, Reading};
pub use friction::{FrictionConfig, FrictionStatus};
pub use model::model_for_range;
pub use risk::{Alarm, RiskState};
pub use sample::{Channel, Clock, Sample};
pub use state::{MonitorState, STATE_BUDGET_BYTES, Saved, Status};
pub use stats::{FaultCounts, Statistics};
pub use trend::{TrendInterval, TrendPoint, time_to_critical};
pub use wear::{EnergySum, dissipated_power};
// Which sensor failed and why, as the sensors report it (feature `sensors`) and as
// the monitor's events name it (always).
pub use crate::sensor_fault::{FaultKind, SensorFault, SensorId};

use crate::recip::recip;
use crate::{Estimator, FrictionInverse};
use condition::{AtLeast, Range, finite, ge};
use sample::Step;

/// A sample that was estimated: its conditioned load (N) and angle (rad) and its time
/// step (ms), for the friction inverse.
#[derive(Clone, Copy)]
struct Estimated {
    load: f32,
    phi: f32,
    dt_ms: u32,
}

/// The condition monitor over one prepared scene of either core.
#[derive(Debug, Clone)]
pub struct Monitor<E> {
    estimator: E,
    config: Config,
    levels: risk::Levels,
    limits: Limits,
    status: Status,
    /// The spike windows of load and angle.
    windows: [condition::Window; 2],
    step_cache: condition::StepCache,
    trend: trend::TrendBuffer,
    events: events::EventQueue,
}

/// The monitor's state, time, status and undelivered events (the estimator, the
/// configuration and the buffers are left out).
#[cfg(feature = "defmt")]
impl<E> defmt::Format for Monitor<E> {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(
            f,
            "Monitor {{ state: {}, status: {}, pending_events: {} }}",
            self.status.alarm.state,
            self.status,
            self.events.len()
        );
    }
}

/// Bytes of a monitor's configuration: the [`Config`] and what is formed from it
/// once (the state budget leaves them out).
const CONFIGURATION_BYTES: usize = core::mem::size_of::<Config>()
    + core::mem::size_of::<Limits>()
    + core::mem::size_of::<risk::Levels>();

/// The configuration's limits as the per-sample checks compare them, formed once.
#[derive(Debug, Clone, Copy)]
struct Limits {
    load: Range,
    angle: Range,
    speed: Range,
    force: Range,
    stop_load: AtLeast,
    stop_speed: AtLeast,
    nominal_speed: f32,
    /// The gap (ms); `u32::MAX`, never exceeded, when off.
    gap_ms: u32,
    stuck_ms: u32,
    /// Whether the smoothing is on.
    smoothing: bool,
}

impl Limits {
    fn new(config: &Config) -> Self {
        Limits {
            load: Range::new(config.load_min, config.load_max),
            angle: Range::new(-config.angle_max, config.angle_max),
            speed: Range::new(0.0, config.speed_max),
            force: Range::new(-config.force_max, config.force_max),
            stop_load: AtLeast::new(config.stop_load),
            stop_speed: AtLeast::new(config.stop_speed),
            nominal_speed: config.nominal_speed,
            gap_ms: if config.gap_ms > 0 {
                config.gap_ms
            } else {
                u32::MAX
            },
            stuck_ms: config.stuck_ms,
            // Above zero, by the bits (validated finite and not negative).
            smoothing: config.smoothing_tau_s.to_bits() as i32 > 0,
        }
    }

    /// The first fault of a sample that failed the checks at speed `speed`: a
    /// sensor's report, a driver's, then load, angle, speed and axial force, each
    /// non-finite or out of range.
    #[cold]
    #[inline(never)]
    fn cause(&self, sample: &Sample, speed: f32) -> FaultCause {
        if let Some(f) = sample.sensor_fault {
            return FaultCause::Sensor(f);
        }
        if let Some(c) = sample.driver_fault {
            return FaultCause::Driver(c);
        }
        let force = sample.axial_force.unwrap_or(0.0);
        let checks = [
            (sample.load, &self.load, Channel::Load),
            (sample.phi, &self.angle, Channel::Angle),
            (speed, &self.speed, Channel::Speed),
            (force, &self.force, Channel::AxialForce),
        ];
        for (x, range, channel) in checks {
            if !range.contains(x) {
                return if finite(x) {
                    FaultCause::OutOfRange(channel)
                } else {
                    FaultCause::NonFinite(channel)
                };
            }
        }
        // Not reached: the sample failed one of the checks above.
        FaultCause::Estimator
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
            levels: risk::Levels::new(&config.thresholds),
            limits: Limits::new(&config),
            config,
            status: Status::new(),
            windows: [condition::Window::new(), condition::Window::new()],
            step_cache: condition::StepCache::new(),
            trend: trend::TrendBuffer::new(),
            events: events::EventQueue::new(),
        })
    }

    /// The reported state.
    pub fn state(&self) -> RiskState {
        self.status.alarm.state
    }

    /// The configuration.
    pub fn config(&self) -> &Config {
        &self.config
    }

    /// The estimator.
    pub fn estimator(&self) -> &E {
        &self.estimator
    }

    /// What the monitor has counted and integrated.
    pub fn statistics(&self) -> &Statistics {
        &self.status.stats
    }

    /// The last valid running reading, if any.
    pub fn reading(&self) -> Option<Reading> {
        self.status.reading
    }

    /// The latest estimate of the time until gross slip (s) at the current drift of
    /// the margin; `None` while the margin does not fall or the trend is off.
    pub fn time_to_critical(&self) -> Option<f32> {
        self.status.time_to_critical_s
    }

    /// Monotonic time since the first sample (ms).
    pub fn elapsed_ms(&self) -> u64 {
        self.status.clock.elapsed_ms
    }

    /// The oldest undelivered event.
    pub fn pop_event(&mut self) -> Option<Event> {
        self.events.pop_front()
    }

    /// Undelivered events.
    pub fn pending_events(&self) -> usize {
        self.events.len()
    }

    /// The sequence number the next event will get (the events so far, delivered,
    /// pending or dropped, took those before it).
    pub fn next_event_seq(&self) -> u32 {
        self.status.next_seq
    }

    fn emit(&mut self, kind: EventKind, time_ms: u32) {
        let event = Event {
            seq: self.status.next_seq,
            time_ms,
            elapsed_ms: self.status.clock.elapsed_ms,
            kind,
            reading: self.status.reading.unwrap_or_default(),
        };
        self.status.next_seq = self.status.next_seq.wrapping_add(1);
        if events::push(&mut self.events, event) {
            let d = &mut self.status.stats.events_dropped;
            *d = d.saturating_add(1);
        }
    }

    /// Clears the conditioning after a sample that was not estimated (a fault, a
    /// stop): the values before it say nothing about the ones after.
    fn restart_conditioning(&mut self) {
        for w in &mut self.windows {
            w.clear();
        }
        self.status.smoothed = None;
    }

    /// The filtered friction coefficient mu, `None` before the first well-posed
    /// estimate (always, over the fixed-point core: see
    /// [`process_with_friction`](Self::process_with_friction)).
    pub fn friction(&self) -> Option<f32> {
        self.status.friction.filtered()
    }

    /// The friction baseline captured at commissioning, if any.
    pub fn friction_baseline(&self) -> Option<f32> {
        self.status.friction.baseline()
    }

    /// The friction tracker's whole state (counts of accepted and rejected estimates,
    /// whether a change is raised).
    pub fn friction_status(&self) -> &FrictionStatus {
        &self.status.friction
    }

    /// Takes the filtered mu as the friction baseline now (commissioning on demand,
    /// e.g. after a change of lubricant); a raised friction change is cleared, with its
    /// event. Returns the baseline, `None` (nothing changes) before the first
    /// well-posed estimate.
    pub fn capture_friction_baseline(&mut self) -> Option<f32> {
        let (baseline, cleared) = self.status.friction.capture()?;
        if cleared {
            let time_ms = self.status.clock.last_time_ms.unwrap_or(0);
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
    /// never as slip. A measured axial force is checked and used in the wear integral;
    /// mu is tracked from it only by [`process_with_friction`](Self::process_with_friction).
    pub fn process(&mut self, sample: Sample) -> RiskState {
        self.step(sample).0
    }

    /// [`process`](Self::process), and the sample that was estimated, if it was.
    fn step(&mut self, sample: Sample) -> (RiskState, Option<Estimated>) {
        let st = &mut self.status;
        // The u64 counters and times add without saturating: at one sample a
        // microsecond, or in milliseconds, they cannot wrap in 500 000 years.
        st.stats.samples = st.stats.samples.wrapping_add(1);
        let held = st.alarm.state;
        let mut fault = None;
        let dt_ms = match st.clock.step(sample.time_ms) {
            Step::Forward(d) => d,
            Step::First => 0,
            Step::Repeated => {
                let r = &mut st.stats.repeated_timestamps;
                *r = r.saturating_add(1);
                return (held, None);
            }
            Step::Backwards => {
                fault = Some(FaultCause::TimeBackwards);
                0
            }
        };
        let now = st.clock.elapsed_ms;
        // Each step counts for the state held during it.
        if let Some(t) = st.stats.time_in_state_ms.get_mut(held.index()) {
            *t = t.wrapping_add(u64::from(dt_ms));
        }
        let limits = &self.limits;
        if dt_ms > limits.gap_ms {
            fault = Some(FaultCause::Gap);
        }
        // Sensor checks: one pass of comparisons on the usual path; which check
        // failed is found only for a faulty sample (the first found wins).
        let speed = sample.speed.unwrap_or(limits.nominal_speed);
        let valid = sample.sensor_fault.is_none()
            && sample.driver_fault.is_none()
            && limits.load.contains(sample.load)
            && limits.angle.contains(sample.phi)
            && limits.speed.contains(speed)
            && sample.axial_force.is_none_or(|f| limits.force.contains(f));
        if !valid && fault.is_none() {
            fault = Some(limits.cause(&sample, speed));
        }
        let running = limits.stop_load.reached(sample.load) && limits.stop_speed.reached(speed);
        if fault.is_none() && limits.stuck_ms > 0 {
            let (limit, reset) = (limits.stuck_ms, !running);
            let load_stuck = st.stuck[0].stuck(sample.load, now, limit, reset);
            let angle_stuck = st.stuck[1].stuck(sample.phi, now, limit, reset);
            if load_stuck {
                fault = Some(FaultCause::Stuck(Channel::Load));
            } else if angle_stuck {
                fault = Some(FaultCause::Stuck(Channel::Angle));
            }
        }
        let mut estimated = None;
        let candidate = match fault {
            Some(_) => RiskState::SensorFault,
            None if !running => RiskState::Stopped,
            None => {
                st.alarm.note_running(now);
                match self.estimate(&sample, speed, dt_ms, held, now) {
                    Ok((level, at)) => {
                        estimated = Some(at);
                        level
                    }
                    Err(f) => {
                        fault = Some(f);
                        RiskState::SensorFault
                    }
                }
            }
        };
        if let Some(f) = fault {
            self.not_estimated(f);
        } else if candidate == RiskState::Stopped {
            self.restart_conditioning();
        }
        let st = &mut self.status;
        let changed = st.alarm.offer(&self.config, candidate, now);
        // Above zero (by its bits: a soft-float comparison costs more).
        if st.energy_step.to_bits() as i32 > 0 {
            if let Some(sum) = st.stats.energy.get_mut(st.alarm.state.index()) {
                sum.add(st.energy_step);
            }
            st.energy_step = 0.0;
        }
        if let Some(from) = changed {
            self.state_changed(from, fault, sample.time_ms);
        }
        if self.status.time_to_critical_s.is_some() || !self.status.approaching_armed {
            self.approaching(sample.time_ms);
        }
        (self.status.alarm.state, estimated)
    }

    /// A sample that was not estimated for fault `f`: counted, and the conditioning
    /// starts afresh.
    #[cold]
    fn not_estimated(&mut self, f: FaultCause) {
        self.status.stats.faults.count(f);
        self.restart_conditioning();
    }

    /// The event of a state change from `from`, naming the fault behind a change to
    /// `SensorFault`.
    #[cold]
    fn state_changed(&mut self, from: RiskState, fault: Option<FaultCause>, time_ms: u32) {
        let to = self.status.alarm.state;
        let fault = if to == RiskState::SensorFault {
            fault
        } else {
            None
        };
        self.emit(EventKind::StateChange { from, to, fault }, time_ms);
    }

    /// Conditioning, estimate, wear and trend of a valid running sample at speed
    /// `speed`; the slip level it asks for and the conditioned sample, or the fault
    /// that stops it.
    #[inline(always)]
    fn estimate(
        &mut self,
        sample: &Sample,
        speed: f32,
        dt_ms: u32,
        held: RiskState,
        now: u64,
    ) -> Result<(RiskState, Estimated), FaultCause> {
        let config = &self.config;
        let st = &mut self.status;
        let (mut load, mut phi) = (sample.load, sample.phi);
        if let Some(filter) = &config.spikes {
            // One loop over both channels: one copy of the window's code in the image.
            let mut values = [load, phi];
            let floors = [filter.load_floor, filter.angle_floor];
            for ((w, x), floor) in self.windows.iter_mut().zip(&mut values).zip(floors) {
                if let Some(m) = w.hampel(*x, filter, floor) {
                    *x = m;
                    st.stats.spikes = st.stats.spikes.saturating_add(1);
                }
            }
            [load, phi] = values;
        }
        let step = self.step_cache.get(dt_ms, config.smoothing_tau_s);
        if self.limits.smoothing {
            if let Some([l, p]) = st.smoothed {
                load = l + step.weight * (load - l);
                phi = p + step.weight * (phi - p);
            }
            st.smoothed = Some([load, phi]);
        }
        // A load cell reads a little below zero at rest; the contact has none.
        let load = if ge(load, 0.0) { load } else { 0.0 };
        let e = self
            .estimator
            .estimate_si(load, phi)
            .map_err(|_| FaultCause::Estimator)?;
        // The cores answer finite d/b for a running load; anything else is refused,
        // never carried on as NaN.
        let nan = e.slip_ratio.to_bits() & 0x7fff_ffff > f32::INFINITY.to_bits();
        if nan || !finite(e.axial_force) {
            return Err(FaultCause::Estimator);
        }
        let margin = e.margin.filter(|&m| finite(m));
        let force = sample.axial_force.unwrap_or(e.axial_force);
        st.reading = Some(Reading {
            load,
            phi,
            slip_ratio: e.slip_ratio,
            axial_force: force,
            critical_angle: e.critical_angle.filter(|&c| finite(c)),
            margin,
        });
        let s = &mut st.stats;
        // Comparisons, not `max`/`min` (a libm call each on some targets); d/b is
        // not NaN here.
        if !ge(s.max_slip_ratio, e.slip_ratio) {
            s.max_slip_ratio = e.slip_ratio;
        }
        if !ge(s.max_axial_force, force.abs()) {
            s.max_axial_force = force.abs();
        }
        if let Some(m) = margin
            && s.min_margin.is_none_or(|x| !ge(m, x))
        {
            s.min_margin = Some(m);
        }
        // Wear (section 7): the power F phi V over the step ending here, for the
        // state reported after this sample (never `Stopped`: a running sample leaves it).
        st.energy_step = dissipated_power(force, phi, speed) * step.dt_s;
        let level = if st.alarm.inhibited(config, now) {
            RiskState::Normal
        } else {
            risk::slip_level(&self.levels, e.slip_ratio, margin, held)
        };
        let at = Estimated { load, phi, dt_ms };
        if let (Some(tc), Some(m)) = (config.trend, margin) {
            let iv = &mut st.trend_interval;
            if iv.count == 0 {
                iv.start_ms = now;
            }
            iv.sum += m;
            iv.count = iv.count.saturating_add(1);
            if now.wrapping_sub(iv.start_ms) >= u64::from(tc.interval_ms) {
                self.trend_point(tc, now);
            }
        }
        Ok((level, at))
    }

    /// Closes the trend's interval at `now`: its mean margin becomes a point, and
    /// with a full window the time to critical is fitted anew.
    #[cold]
    fn trend_point(&mut self, tc: TrendConfig, now: u64) {
        let st = &mut self.status;
        let iv = &mut st.trend_interval;
        let point = TrendPoint {
            time_ms: now as u32,
            margin: iv.sum * recip(iv.count as f32),
        };
        *iv = TrendInterval::default();
        // Points older than the window leave (after a stop, say).
        let window = u64::from(tc.interval_ms) * u64::from(tc.points);
        while let Some(old) = self.trend.front() {
            if u64::from((now as u32).wrapping_sub(old.time_ms)) > window {
                self.trend.pop_front();
            } else {
                break;
            }
        }
        trend::push(&mut self.trend, point, usize::from(tc.points));
        // The fit waits for a full window: a shorter one mistakes the load's
        // cycles for a drift.
        if self.trend.len() < usize::from(tc.points) {
            st.time_to_critical_s = None;
            return;
        }
        let mut points = [TrendPoint::default(); config::TREND_CAPACITY];
        for (slot, p) in points.iter_mut().zip(self.trend.iter()) {
            *slot = *p;
        }
        let n = self.trend.len().min(config::TREND_CAPACITY);
        st.time_to_critical_s = time_to_critical(&points[..n]);
    }

    /// The `Approaching` event: once when the time to critical falls below the
    /// horizon while the contact still sticks; re-armed above 1.5 horizons.
    fn approaching(&mut self, time_ms: u32) {
        let Some(tc) = self.config.trend else { return };
        let st = &mut self.status;
        let ttc = st.time_to_critical_s;
        match ttc {
            Some(t) if !ge(t, tc.horizon_s) => {
                let live = matches!(st.alarm.state, RiskState::Normal | RiskState::Microslip);
                if st.approaching_armed && live {
                    st.approaching_armed = false;
                    self.emit(
                        EventKind::Approaching {
                            time_to_critical_s: t,
                        },
                        time_ms,
                    );
                }
            }
            Some(t) if !ge(t, 1.5 * tc.horizon_s) => {}
            _ => st.approaching_armed = true,
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
        let (state, estimated) = self.step(sample);
        let (Some(config), Some(force), Some(at)) =
            (self.config.friction, sample.axial_force, estimated)
        else {
            return state;
        };
        let answer = self
            .estimator
            .friction_from_axial_force(at.load, at.phi, force)
            .ok();
        let st = &mut self.status;
        let running_ms = st
            .alarm
            .started_ms
            .map_or(0, |s| st.clock.elapsed_ms.saturating_sub(s));
        if let Some(changed) = st.friction.offer(&config, answer, at.dt_ms, running_ms) {
            let mu = st.friction.mu;
            self.emit(EventKind::Friction { mu, changed }, sample.time_ms);
        }
        state
    }
}
