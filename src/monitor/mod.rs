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
use condition::{finite, ge};
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
    status: Status,
    load_window: condition::Window,
    angle_window: condition::Window,
    weight: condition::WeightCache,
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

/// Checks one channel's value: non-finite, then out of `[lo, hi]`.
#[inline(always)]
fn check(x: f32, lo: f32, hi: f32, channel: Channel) -> Option<FaultCause> {
    // One pair of comparisons on the usual path: a NaN lies outside.
    if condition::within(x, lo, hi) {
        None
    } else {
        Some(out_of_range(x, channel))
    }
}

#[cold]
fn out_of_range(x: f32, channel: Channel) -> FaultCause {
    if x.is_finite() {
        FaultCause::OutOfRange(channel)
    } else {
        FaultCause::NonFinite(channel)
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
            config,
            status: Status::new(),
            load_window: condition::Window::new(),
            angle_window: condition::Window::new(),
            weight: condition::WeightCache::new(),
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
        self.load_window.clear();
        self.angle_window.clear();
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
        // Borrowed, not copied: a copy of the whole configuration costs more per
        // sample than the fields read.
        let config = &self.config;
        let st = &mut self.status;
        // The u64 counters and times add without saturating: at one sample a
        // microsecond, or in milliseconds, they cannot wrap in 500 000 years.
        st.stats.samples = st.stats.samples.wrapping_add(1);
        let held = st.alarm.state;
        let mut fault = None;
        let dt_ms = match st.clock.step(sample.time_ms) {
            Step::First => 0,
            Step::Forward(d) => d,
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
        let t = &mut st.stats.time_in_state_ms[held.index()];
        *t = t.wrapping_add(u64::from(dt_ms));
        if config.gap_ms > 0 && dt_ms > config.gap_ms {
            fault = Some(FaultCause::Gap);
        }
        let st = &mut self.status;
        // Sensor checks, the first fault found wins.
        let speed = sample.speed.unwrap_or(config.nominal_speed);
        fault = fault
            .or(sample.sensor_fault.map(FaultCause::Sensor))
            .or(sample.driver_fault.map(FaultCause::Driver))
            .or_else(|| check(sample.load, config.load_min, config.load_max, Channel::Load))
            .or_else(|| {
                check(
                    sample.phi,
                    -config.angle_max,
                    config.angle_max,
                    Channel::Angle,
                )
            })
            .or_else(|| check(speed, 0.0, config.speed_max, Channel::Speed))
            .or_else(|| {
                let f = sample.axial_force?;
                check(f, -config.force_max, config.force_max, Channel::AxialForce)
            });
        let running = ge(sample.load, config.stop_load) && ge(speed, config.stop_speed);
        if fault.is_none() && config.stuck_ms > 0 {
            let load_stuck = st.stuck[0].stuck(sample.load, now, config.stuck_ms, !running);
            let angle_stuck = st.stuck[1].stuck(sample.phi, now, config.stuck_ms, !running);
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
                match self.estimate(sample, dt_ms, held, now) {
                    Ok(c) => {
                        estimated = self.status.reading.map(|r| Estimated {
                            load: r.load,
                            phi: r.phi,
                            dt_ms,
                        });
                        c
                    }
                    Err(f) => {
                        fault = Some(f);
                        RiskState::SensorFault
                    }
                }
            }
        };
        if let Some(f) = fault {
            self.status.stats.faults.count(f);
        }
        if candidate == RiskState::SensorFault || candidate == RiskState::Stopped {
            // Not estimated: what the windows and the filter hold is stale now.
            self.restart_conditioning();
        }
        let changed = self.status.alarm.offer(&self.config, candidate, now);
        let st = &mut self.status;
        // Above zero (by its bits: a soft-float comparison costs more).
        if st.energy_step.to_bits() as i32 > 0 {
            st.stats.energy[st.alarm.state.index()].add(st.energy_step);
            st.energy_step = 0.0;
        }
        if let Some(from) = changed {
            let to = self.status.alarm.state;
            let cause = if to == RiskState::SensorFault {
                fault
            } else {
                None
            };
            self.emit(
                EventKind::StateChange {
                    from,
                    to,
                    fault: cause,
                },
                sample.time_ms,
            );
        }
        self.approaching(sample.time_ms);
        (self.status.alarm.state, estimated)
    }

    /// Conditioning, estimate, wear and trend of a valid running sample; the slip
    /// level it asks for, or the fault that stops it.
    fn estimate(
        &mut self,
        sample: Sample,
        dt_ms: u32,
        held: RiskState,
        now: u64,
    ) -> Result<RiskState, FaultCause> {
        let config = &self.config;
        let st = &mut self.status;
        let (mut load, mut phi) = (sample.load, sample.phi);
        if let Some(filter) = &config.spikes {
            if let Some(m) = self.load_window.hampel(load, filter, filter.load_floor) {
                load = m;
                st.stats.spikes = st.stats.spikes.saturating_add(1);
            }
            if let Some(m) = self.angle_window.hampel(phi, filter, filter.angle_floor) {
                phi = m;
                st.stats.spikes = st.stats.spikes.saturating_add(1);
            }
        }
        let dt_s = dt_ms as f32 * 1e-3;
        // Above zero, by the bits (validated finite and not negative).
        if config.smoothing_tau_s.to_bits() as i32 > 0 {
            if let Some([l, p]) = st.smoothed {
                let w = self.weight.weight(dt_ms, config.smoothing_tau_s);
                load = l + w * (load - l);
                phi = p + w * (phi - p);
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
        let speed = sample.speed.unwrap_or(config.nominal_speed);
        st.energy_step = dissipated_power(force, phi, speed) * dt_s;
        let level = if st.alarm.inhibited(config, now) {
            RiskState::Normal
        } else {
            risk::slip_level(&self.levels, e.slip_ratio, margin, held)
        };
        if let (Some(tc), Some(m)) = (config.trend, margin) {
            let iv = &mut st.trend_interval;
            if iv.count == 0 {
                iv.start_ms = now;
            }
            iv.sum += m;
            iv.count = iv.count.saturating_add(1);
            if now.saturating_sub(iv.start_ms) >= u64::from(tc.interval_ms) {
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
                    return Ok(level);
                }
                let mut points = [TrendPoint::default(); config::TREND_CAPACITY];
                for (slot, p) in points.iter_mut().zip(self.trend.iter()) {
                    *slot = *p;
                }
                let n = self.trend.len().min(config::TREND_CAPACITY);
                st.time_to_critical_s = time_to_critical(&points[..n]);
            }
        }
        Ok(level)
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
