//! The monitor's state and configuration as stored checkpoints (feature
//! `sequential-storage`): [`MonitorState`] under
//! [`kind::MONITOR_STATE`] and [`Config`] under [`kind::MONITOR_CONFIG`], field by
//! field, little-endian, in a fixed order and size.
//!
//! Decoding refuses ([`CodecError::InvalidValue`]) whatever no monitor can hold: an
//! unknown state, channel, sensor, fault or event code, a flag byte other than 0 or 1,
//! a buffer length above its capacity, the bytes of an absent value or of padding
//! other than zero, a NaN or infinite value where the monitor keeps finite ones, and a
//! configuration that fails [`Config::validate`]. A state whose fields, each valid,
//! contradict each other (a time after its own clock, a count above what it counts:
//! see `reachable`) is refused with [`CodecError::Inconsistent`]. So a restored state
//! is one the monitor could have reached, never a wrong value.

use super::checks::{Checks, StuckTracker};
use super::clock::Clock;
use super::config::{SPIKE_WINDOW_CAPACITY, TREND_CAPACITY};
use super::energy::{Energy, EnergySum};
use super::events::EVENT_CAPACITY;
use super::risk::Alarm;
use super::state::Saved;
use super::trend::TrendInterval;
use super::{
    Channel, Config, Event, EventKind, FaultCause, FaultCounts, FieldbusEvent, FrictionConfig,
    FrictionStatus, MonitorState, Reading, RiskState, SpikeFilter, Statistics, Thresholds,
    TrendConfig, TrendPoint,
};
use crate::sensor_fault::{FaultKind, SensorFault, SensorId};
use crate::storage::{Checkpoint, CodecError, Reader, Writer, kind};

const INVALID: CodecError = CodecError::InvalidValue;

/// `Ok(x)` if `ok`, else [`CodecError::InvalidValue`].
fn require<T>(ok: bool, x: T) -> Result<T, CodecError> {
    if ok { Ok(x) } else { Err(INVALID) }
}

/// A finite f32.
fn finite(r: &mut Reader<'_>) -> Result<f32, CodecError> {
    let x = r.f32()?;
    require(x.is_finite(), x)
}

/// An f32 that is not NaN and not negative (a slip ratio: +inf at P = 0, eq 16).
fn ratio(r: &mut Reader<'_>) -> Result<f32, CodecError> {
    let x = r.f32()?;
    require(x >= 0.0, x)
}

/// An optional value: a flag byte, then the value's bytes (zeros when absent).
fn put_option<T: Copy>(
    w: &mut Writer<'_>,
    x: Option<T>,
    absent: T,
    put: impl Fn(&mut Writer<'_>, T) -> Result<(), CodecError>,
) -> Result<(), CodecError> {
    w.bool(x.is_some())?;
    put(w, x.unwrap_or(absent))
}

/// Reads what [`put_option`] wrote; an absent value's bytes must be zeros.
fn get_option<T, const N: usize>(
    r: &mut Reader<'_>,
    get: impl Fn(&mut Reader<'_>) -> Result<T, CodecError>,
) -> Result<Option<T>, CodecError> {
    if r.bool()? {
        get(r).map(Some)
    } else {
        let bytes: [u8; N] = r.array()?;
        require(bytes == [0; N], None)
    }
}

fn put_opt_f32(w: &mut Writer<'_>, x: Option<f32>) -> Result<(), CodecError> {
    put_option(w, x, 0.0, |w, x| w.f32(x))
}

fn get_opt_finite(r: &mut Reader<'_>) -> Result<Option<f32>, CodecError> {
    get_option::<_, 4>(r, finite)
}

fn put_opt_u64(w: &mut Writer<'_>, x: Option<u64>) -> Result<(), CodecError> {
    put_option(w, x, 0, |w, x| w.u64(x))
}

fn get_opt_u64(r: &mut Reader<'_>) -> Result<Option<u64>, CodecError> {
    get_option::<_, 8>(r, |r| r.u64())
}

/// Zero padding of `n` bytes, refused when not zero.
fn put_zeros(w: &mut Writer<'_>, n: usize) -> Result<(), CodecError> {
    (0..n).try_for_each(|_| w.u8(0))
}

fn get_zeros(r: &mut Reader<'_>, n: usize) -> Result<(), CodecError> {
    (0..n).try_for_each(|_| require(r.u8()? == 0, ()))
}

/// A code from `all`, by its position.
fn code_of<T: Copy + PartialEq>(all: &[T], x: T) -> u8 {
    all.iter().position(|&a| a == x).unwrap_or(0) as u8
}

fn from_code<T: Copy>(all: &[T], code: u8) -> Result<T, CodecError> {
    all.get(usize::from(code)).copied().ok_or(INVALID)
}

const CHANNELS: [Channel; 4] = [
    Channel::Load,
    Channel::Angle,
    Channel::Speed,
    Channel::AxialForce,
];

fn put_state(w: &mut Writer<'_>, s: RiskState) -> Result<(), CodecError> {
    w.u8(code_of(&RiskState::ALL, s))
}

fn get_state(r: &mut Reader<'_>) -> Result<RiskState, CodecError> {
    from_code(&RiskState::ALL, r.u8()?)
}

/// A fault cause: a tag and two bytes (the channel, or the sensor and the kind).
const FAULT_SIZE: usize = 3;

fn put_fault(w: &mut Writer<'_>, f: FaultCause) -> Result<(), CodecError> {
    let ch = |c| code_of(&CHANNELS, c);
    let (tag, a, b) = match f {
        FaultCause::NonFinite(c) => (0, ch(c), 0),
        FaultCause::OutOfRange(c) => (1, ch(c), 0),
        FaultCause::Stuck(c) => (2, ch(c), 0),
        FaultCause::Gap => (3, 0, 0),
        FaultCause::TimeBackwards => (4, 0, 0),
        FaultCause::Driver(c) => (5, ch(c), 0),
        FaultCause::Estimator => (6, 0, 0),
        FaultCause::Sensor(s) => (
            7,
            code_of(&SensorId::ALL, s.sensor),
            code_of(&FaultKind::ALL, s.kind),
        ),
    };
    w.u8(tag)?;
    w.u8(a)?;
    w.u8(b)
}

fn get_fault(r: &mut Reader<'_>) -> Result<FaultCause, CodecError> {
    let (tag, a, b) = (r.u8()?, r.u8()?, r.u8()?);
    let ch = || from_code(&CHANNELS, a);
    // Bytes a variant does not use are zero.
    let unused = |used_a: bool| require(b == 0 && (used_a || a == 0), ());
    Ok(match tag {
        0 => unused(true).and(ch().map(FaultCause::NonFinite))?,
        1 => unused(true).and(ch().map(FaultCause::OutOfRange))?,
        2 => unused(true).and(ch().map(FaultCause::Stuck))?,
        3 => unused(false).map(|()| FaultCause::Gap)?,
        4 => unused(false).map(|()| FaultCause::TimeBackwards)?,
        5 => unused(true).and(ch().map(FaultCause::Driver))?,
        6 => unused(false).map(|()| FaultCause::Estimator)?,
        7 => FaultCause::Sensor(SensorFault {
            sensor: from_code(&SensorId::ALL, a)?,
            kind: from_code(&FaultKind::ALL, b)?,
        }),
        _ => return Err(INVALID),
    })
}

const READING_SIZE: usize = 4 * 4 + 2 * 5;

fn put_reading(w: &mut Writer<'_>, r: &Reading) -> Result<(), CodecError> {
    w.f32(r.load)?;
    w.f32(r.phi)?;
    w.f32(r.slip_ratio)?;
    w.f32(r.axial_force)?;
    put_opt_f32(w, r.critical_angle)?;
    put_opt_f32(w, r.margin)
}

fn get_reading(r: &mut Reader<'_>) -> Result<Reading, CodecError> {
    Ok(Reading {
        load: finite(r)?,
        phi: finite(r)?,
        slip_ratio: ratio(r)?,
        axial_force: finite(r)?,
        critical_angle: get_opt_finite(r)?,
        margin: get_opt_finite(r)?,
    })
}

/// An event's kind: a tag and 8 bytes whatever the variant (zeros where unused).
const KIND_SIZE: usize = 1 + 8;

fn put_kind(w: &mut Writer<'_>, k: &EventKind) -> Result<(), CodecError> {
    match *k {
        EventKind::StateChange { from, to, fault } => {
            w.u8(0)?;
            put_state(w, from)?;
            put_state(w, to)?;
            w.bool(fault.is_some())?;
            match fault {
                Some(f) => put_fault(w, f)?,
                None => put_zeros(w, FAULT_SIZE)?,
            }
            put_zeros(w, 2)
        }
        EventKind::Approaching { time_to_critical_s } => {
            w.u8(1)?;
            w.f32(time_to_critical_s)?;
            put_zeros(w, 4)
        }
        EventKind::Friction { mu, changed } => {
            w.u8(2)?;
            w.f32(mu)?;
            w.bool(changed)?;
            put_zeros(w, 3)
        }
        EventKind::Fieldbus(e) => {
            w.u8(3)?;
            w.u8(match e {
                FieldbusEvent::LineReverted => 0,
                FieldbusEvent::MasterLost => 1,
                FieldbusEvent::MasterBack => 2,
            })?;
            put_zeros(w, 7)
        }
    }
}

fn get_kind(r: &mut Reader<'_>) -> Result<EventKind, CodecError> {
    let kind = match r.u8()? {
        0 => {
            let (from, to) = (get_state(r)?, get_state(r)?);
            let fault = if r.bool()? {
                Some(get_fault(r)?)
            } else {
                get_zeros(r, FAULT_SIZE)?;
                None
            };
            get_zeros(r, 2)?;
            EventKind::StateChange { from, to, fault }
        }
        1 => {
            let t = ratio(r)?;
            get_zeros(r, 4)?;
            EventKind::Approaching {
                time_to_critical_s: require(t.is_finite(), t)?,
            }
        }
        2 => {
            let mu = finite(r)?;
            let changed = r.bool()?;
            get_zeros(r, 3)?;
            EventKind::Friction { mu, changed }
        }
        3 => {
            let e = match r.u8()? {
                0 => FieldbusEvent::LineReverted,
                1 => FieldbusEvent::MasterLost,
                2 => FieldbusEvent::MasterBack,
                _ => return Err(INVALID),
            };
            get_zeros(r, 7)?;
            EventKind::Fieldbus(e)
        }
        _ => return Err(INVALID),
    };
    Ok(kind)
}

const EVENT_SIZE: usize = 4 + 4 + 8 + KIND_SIZE + READING_SIZE;

fn put_event(w: &mut Writer<'_>, e: &Event) -> Result<(), CodecError> {
    w.u32(e.seq)?;
    w.u32(e.time_ms)?;
    w.u64(e.elapsed_ms)?;
    put_kind(w, &e.kind)?;
    put_reading(w, &e.reading)
}

fn get_event(r: &mut Reader<'_>) -> Result<Event, CodecError> {
    Ok(Event {
        seq: r.u32()?,
        time_ms: r.u32()?,
        elapsed_ms: r.u64()?,
        kind: get_kind(r)?,
        reading: get_reading(r)?,
    })
}

/// A saved buffer: every slot (used or not, so that a round trip is exact), then the
/// length, refused above the capacity.
fn put_saved<T: Copy, const N: usize>(
    w: &mut Writer<'_>,
    s: &Saved<T, N>,
    put: impl Fn(&mut Writer<'_>, &T) -> Result<(), CodecError>,
) -> Result<(), CodecError> {
    s.items.iter().try_for_each(|x| put(w, x))?;
    w.u8(s.len)
}

/// Reads what [`put_saved`] wrote into `saved`, item by item in place.
fn get_saved<T: Copy, const N: usize>(
    r: &mut Reader<'_>,
    saved: &mut Saved<T, N>,
    get: impl Fn(&mut Reader<'_>) -> Result<T, CodecError>,
) -> Result<(), CodecError> {
    for slot in &mut saved.items {
        *slot = get(r)?;
    }
    saved.len = r.u8()?;
    require(usize::from(saved.len) <= N, ())
}

const CLOCK_SIZE: usize = 5 + 8;
const ALARM_SIZE: usize = 1 + 8 + (1 + 1 + 8) + 9;
const STATS_SIZE: usize = 8 + 4 + 4 + 8 * 4 + 4 + 5 * 8 + 5 * 8 + 4 + 4 + 5;
const FRICTION_SIZE: usize = 4 + 4 + 1 + 4 + 4 + 4 + 1;
const STATUS_SIZE: usize = CLOCK_SIZE
    + ALARM_SIZE
    + (1 + 8)
    + 2 * (4 + 8)
    + (8 + 4 + 4)
    + 5
    + 1
    + 4
    + (1 + READING_SIZE)
    + 4
    + STATS_SIZE
    + FRICTION_SIZE;

/// The stages' states but the buffers, in the record's order (version 1).
fn put_status(w: &mut Writer<'_>, s: &MonitorState) -> Result<(), CodecError> {
    put_option(w, s.clock.last_time_ms, 0, |w, t| w.u32(t))?;
    w.u64(s.clock.elapsed_ms)?;
    let a = &s.alarm;
    put_state(w, a.state)?;
    w.u64(a.since_ms)?;
    put_option(w, a.pending, (RiskState::Stopped, 0), |w, (p, t)| {
        put_state(w, p)?;
        w.u64(t)
    })?;
    put_opt_u64(w, a.started_ms)?;
    put_option(w, s.smoothed, [0.0; 2], |w, x| w.each(&x, |w, v| w.f32(*v)))?;
    w.each(&s.checks.stuck, |w, t| {
        w.u32(t.bits)?;
        w.u64(t.since_ms)
    })?;
    let iv = &s.trend_interval;
    w.u64(iv.start_ms)?;
    w.f32(iv.sum)?;
    w.u32(iv.count)?;
    put_opt_f32(w, s.time_to_critical_s)?;
    w.bool(s.approaching_armed)?;
    w.u32(s.next_seq)?;
    put_option(w, s.reading, Reading::default(), |w, r| put_reading(w, &r))?;
    w.f32(s.energy.step_j)?;
    put_stats(w, &s.stats)?;
    let f = &s.friction;
    w.f32(f.mu)?;
    w.f32(f.baseline)?;
    w.bool(f.baseline_captured)?;
    w.u32(f.accepted)?;
    w.u32(f.rejected)?;
    w.u32(f.pending_ms)?;
    w.bool(f.changed)
}

/// Reads what [`put_status`] wrote into `s`.
fn get_status(r: &mut Reader<'_>, s: &mut MonitorState) -> Result<(), CodecError> {
    let clock = Clock {
        last_time_ms: get_option::<_, 4>(r, |r| r.u32())?,
        elapsed_ms: r.u64()?,
    };
    let alarm = Alarm {
        state: get_state(r)?,
        since_ms: r.u64()?,
        pending: get_option::<_, 9>(r, |r| Ok((get_state(r)?, r.u64()?)))?,
        started_ms: get_opt_u64(r)?,
    };
    let smoothed = get_option::<_, 8>(r, |r| Ok([finite(r)?, finite(r)?]))?;
    let stuck = r.array_of(|r| {
        Ok(StuckTracker {
            bits: r.u32()?,
            since_ms: r.u64()?,
        })
    })?;
    let trend_interval = TrendInterval {
        start_ms: r.u64()?,
        sum: finite(r)?,
        count: r.u32()?,
    };
    let time_to_critical_s = get_opt_finite(r)?;
    let approaching_armed = r.bool()?;
    let next_seq = r.u32()?;
    let reading = get_option::<_, READING_SIZE>(r, get_reading)?;
    let energy_step = finite(r)?;
    let stats = get_stats(r)?;
    let friction = FrictionStatus {
        mu: finite(r)?,
        baseline: finite(r)?,
        baseline_captured: r.bool()?,
        accepted: r.u32()?,
        rejected: r.u32()?,
        pending_ms: r.u32()?,
        changed: r.bool()?,
    };
    // A captured baseline divides the band test: it is positive.
    if friction.baseline_captured && friction.baseline <= 0.0 {
        return Err(INVALID);
    }
    s.clock = clock;
    s.alarm = alarm;
    s.smoothed = smoothed;
    s.checks = Checks { stuck };
    s.trend_interval = trend_interval;
    s.time_to_critical_s = time_to_critical_s;
    s.approaching_armed = approaching_armed;
    s.next_seq = next_seq;
    s.reading = reading;
    s.energy = Energy {
        step_j: energy_step,
    };
    s.stats = stats;
    s.friction = friction;
    Ok(())
}

fn put_stats(w: &mut Writer<'_>, s: &Statistics) -> Result<(), CodecError> {
    w.u64(s.samples)?;
    w.u32(s.repeated_timestamps)?;
    w.u32(s.spikes)?;
    for c in s.faults.by_cause() {
        w.u32(c)?;
    }
    w.u32(s.events_dropped)?;
    w.each(&s.time_in_state_ms, |w, t| w.u64(*t))?;
    w.each(&s.energy, |w, e| {
        w.f32(e.sum)?;
        w.f32(e.compensation)
    })?;
    w.f32(s.max_slip_ratio)?;
    w.f32(s.max_axial_force)?;
    put_opt_f32(w, s.min_margin)
}

fn get_stats(r: &mut Reader<'_>) -> Result<Statistics, CodecError> {
    let (samples, repeated_timestamps, spikes) = (r.u64()?, r.u32()?, r.u32()?);
    let [
        non_finite,
        out_of_range,
        stuck,
        gap,
        time_backwards,
        driver,
        estimator,
        sensor,
    ] = r.array_of(|r| r.u32())?;
    Ok(Statistics {
        samples,
        repeated_timestamps,
        spikes,
        faults: FaultCounts {
            non_finite,
            out_of_range,
            stuck,
            gap,
            time_backwards,
            driver,
            estimator,
            sensor,
        },
        events_dropped: r.u32()?,
        time_in_state_ms: r.array_of(|r| r.u64())?,
        energy: r.array_of(|r| {
            Ok(EnergySum {
                sum: finite(r)?,
                compensation: finite(r)?,
            })
        })?,
        max_slip_ratio: ratio(r)?,
        max_axial_force: finite(r)?,
        min_margin: get_opt_finite(r)?,
    })
}

/// The longest forward step of the clock (ms): a u32 counter difference below 2^31.
const MAX_STEP_MS: u64 = (1 << 31) - 1;

/// Events one sample can emit at most: a state change, `Approaching`, a friction
/// change, and the clearing of that change by a baseline captured on demand.
const MAX_EVENTS_PER_SAMPLE: u64 = 4;

/// Whether the fields of a decoded state hold together as a monitor's do
/// ([`CodecError::Inconsistent`] otherwise): every time against the state's own clock
/// (`elapsed_ms`), every count against what it counts.
///
/// - The clock: a last timestamp exactly when a sample was seen; the elapsed time at
///   most the samples' steps (each below 2^31 ms) and far enough below `u64::MAX` that
///   the next step cannot wrap it; the time per state sums to it.
/// - The state machine, stuck tracking, the trend's interval, the friction's pending
///   time, the events and the trend's points: no time after the clock; a pending state
///   differs from the reported one and began no earlier than it was entered.
/// - Counts: repeated timestamps and faults (one a sample) within the samples, spikes
///   within two a sample, estimates of mu (one a sample) within the samples, dropped
///   events within what the samples can emit, a trend interval's margins within the
///   samples; an empty interval holds no start and no sum.
/// - The events pending are numbered consecutively up to the next sequence number,
///   oldest first in time; the trend's points too.
/// - Friction: no mu before an accepted estimate, no baseline before it is captured,
///   no change raised without a baseline.
fn reachable(s: &MonitorState) -> Result<(), CodecError> {
    let ok = |c: bool| {
        if c {
            Ok(())
        } else {
            Err(CodecError::Inconsistent)
        }
    };
    let now = s.clock.elapsed_ms;
    let st = &s.stats;
    let n = st.samples;
    let at_most_now = |t: u64| t <= now;
    // The clock.
    ok(s.clock.last_time_ms.is_some() == (n > 0))?;
    ok(now <= n.saturating_sub(1).saturating_mul(MAX_STEP_MS) && now <= u64::MAX - MAX_STEP_MS)?;
    let in_states = st
        .time_in_state_ms
        .iter()
        .try_fold(0u64, |sum, &t| sum.checked_add(t));
    ok(in_states == Some(now))?;
    // Times against the clock.
    let a = &s.alarm;
    ok(at_most_now(a.since_ms) && a.started_ms.is_none_or(at_most_now))?;
    // A run of candidates begins after the state it would leave was entered.
    let after_entry = |t: u64| a.since_ms <= t && at_most_now(t);
    ok(a.pending
        .is_none_or(|(p, t)| p != a.state && after_entry(t)))?;
    ok(s.checks.stuck.iter().all(|t| at_most_now(t.since_ms)))?;
    let iv = &s.trend_interval;
    ok(at_most_now(iv.start_ms) && u64::from(iv.count) <= n)?;
    ok(iv.count > 0 || (iv.start_ms == 0 && iv.sum == 0.0))?;
    ok(u64::from(s.friction.pending_ms) <= now)?;
    // Counts against what they count.
    let repeated = u64::from(st.repeated_timestamps);
    ok(repeated <= n && st.faults.total() <= n - repeated)?;
    ok(u64::from(st.spikes) <= n.saturating_mul(2))?;
    ok(u64::from(st.events_dropped) <= n.saturating_mul(MAX_EVENTS_PER_SAMPLE))?;
    let f = &s.friction;
    ok(u64::from(f.accepted) + u64::from(f.rejected) <= n)?;
    ok(f.accepted > 0 || f.mu == 0.0)?;
    ok(f.baseline_captured || (f.baseline == 0.0 && !f.changed))?;
    ok(s.time_to_critical_s.is_none_or(|t| t >= 0.0))?;
    // The events: consecutive up to the next number, in time order, none after now.
    let count = u32::from(s.events.len.min(EVENT_CAPACITY as u8));
    let mut seq = s.next_seq.wrapping_sub(count);
    let mut previous = 0;
    for e in s.events.iter() {
        ok(e.seq == seq && previous <= e.elapsed_ms && at_most_now(e.elapsed_ms))?;
        seq = seq.wrapping_add(1);
        previous = e.elapsed_ms;
    }
    // The trend's points (low 32 bits of the clock): ages within the clock, oldest
    // first.
    let mut age = now;
    for p in s.trend.iter() {
        let this = u64::from((now as u32).wrapping_sub(p.time_ms));
        ok(this <= age)?;
        age = this;
    }
    Ok(())
}

/// The state of a monitor, stored under [`kind::MONITOR_STATE`]: everything
/// [`Monitor::restore`](super::Monitor::restore) needs to go on identically (energy
/// and time per state, counters, the clock, the state machine, the buffers, the
/// undelivered events, the friction baseline and filter).
impl Checkpoint for MonitorState {
    const KIND: u8 = kind::MONITOR_STATE;
    const VERSION: u16 = 1;
    const SIZE: usize = STATUS_SIZE
        + 2 * (SPIKE_WINDOW_CAPACITY * 4 + 1)
        + (TREND_CAPACITY * 8 + 1)
        + (EVENT_CAPACITY * EVENT_SIZE + 1);

    fn encode(&self, w: &mut Writer<'_>) -> Result<(), CodecError> {
        put_status(w, self)?;
        put_saved(w, &self.load_window, |w, x| w.f32(*x))?;
        put_saved(w, &self.angle_window, |w, x| w.f32(*x))?;
        put_saved(w, &self.trend, |w, p| {
            w.u32(p.time_ms)?;
            w.f32(p.margin)
        })?;
        put_saved(w, &self.events, put_event)
    }

    fn decode(r: &mut Reader<'_>) -> Result<Self, CodecError> {
        let mut state = MonitorState::default();
        state.decode_into(r)?;
        Ok(state)
    }

    /// Field by field into `self`: a restore holds one state, not three. Then the
    /// fields against each other ([`reachable`]).
    fn decode_into(&mut self, r: &mut Reader<'_>) -> Result<(), CodecError> {
        get_status(r, self)?;
        get_saved(r, &mut self.load_window, finite)?;
        get_saved(r, &mut self.angle_window, finite)?;
        get_saved(r, &mut self.trend, |r| {
            Ok(TrendPoint {
                time_ms: r.u32()?,
                margin: finite(r)?,
            })
        })?;
        get_saved(r, &mut self.events, get_event)?;
        reachable(self)
    }
}

/// One event as a record of its own, under [`kind::EVENT`]: what the flash event queue
/// (`storage::EventQueue`) holds, the record's sequence field the event's own number.
/// The payload is the event's bytes in the monitor's state (docs/formats.md).
impl Checkpoint for Event {
    const KIND: u8 = kind::EVENT;
    const VERSION: u16 = 1;
    const SIZE: usize = EVENT_SIZE;

    fn encode(&self, w: &mut Writer<'_>) -> Result<(), CodecError> {
        put_event(w, self)
    }

    fn decode(r: &mut Reader<'_>) -> Result<Self, CodecError> {
        get_event(r)
    }
}

impl MonitorState {
    /// Numbers the next event after `seq` (modulo 2^32) if this state would number it
    /// at or before `seq`: at start-up, after the newest event found stored elsewhere
    /// (the flash event queue), so that no number is given twice even when this state
    /// is older than the newest stored event.
    pub fn continue_events_after(&mut self, seq: u32) {
        let next = seq.wrapping_add(1);
        if next.wrapping_sub(self.next_seq) < 1 << 31 {
            self.next_seq = next;
        }
    }
}

/// The monitor's configuration, stored under [`kind::MONITOR_CONFIG`]; a decoded one
/// must pass [`Config::validate`].
impl Checkpoint for Config {
    const KIND: u8 = kind::MONITOR_CONFIG;
    const VERSION: u16 = 1;
    const SIZE: usize = 13 + 4 * 4 + 8 * 4 + (1 + 1 + 3 * 4) + 4 + 2 * 4 + (1 + 4 + 1 + 4) + 29;

    fn encode(&self, w: &mut Writer<'_>) -> Result<(), CodecError> {
        let (tag, a, b, c) = match self.thresholds {
            Thresholds::SlipRatio {
                warning,
                alarm,
                deadband,
            } => (0, warning, alarm, deadband),
            Thresholds::Margin {
                warning,
                alarm,
                deadband,
            } => (1, warning, alarm, deadband),
        };
        w.u8(tag)?;
        w.each(&[a, b, c], |w, x| w.f32(*x))?;
        w.each(
            &[
                self.on_delay_ms,
                self.off_delay_ms,
                self.fault_delay_ms,
                self.inhibit_ms,
            ],
            |w, x| w.u32(*x),
        )?;
        w.each(
            &[
                self.stop_load,
                self.stop_speed,
                self.nominal_speed,
                self.load_min,
                self.load_max,
                self.angle_max,
                self.speed_max,
                self.force_max,
            ],
            |w, x| w.f32(*x),
        )?;
        let no_spikes = SpikeFilter {
            window: 0,
            k: 0.0,
            load_floor: 0.0,
            angle_floor: 0.0,
        };
        put_option(w, self.spikes, no_spikes, |w, s| {
            w.u8(s.window)?;
            w.each(&[s.k, s.load_floor, s.angle_floor], |w, x| w.f32(*x))
        })?;
        w.f32(self.smoothing_tau_s)?;
        w.u32(self.stuck_ms)?;
        w.u32(self.gap_ms)?;
        let no_trend = TrendConfig {
            interval_ms: 0,
            points: 0,
            horizon_s: 0.0,
        };
        put_option(w, self.trend, no_trend, |w, t| {
            w.u32(t.interval_ms)?;
            w.u8(t.points)?;
            w.f32(t.horizon_s)
        })?;
        let no_friction = FrictionConfig {
            sensitivity_max: 0.0,
            tau_s: 0.0,
            baseline_after_ms: 0,
            baseline_after_estimates: 0,
            band: 0.0,
            deadband: 0.0,
            delay_ms: 0,
        };
        put_option(w, self.friction, no_friction, |w, f| {
            w.f32(f.sensitivity_max)?;
            w.f32(f.tau_s)?;
            w.u32(f.baseline_after_ms)?;
            w.u32(f.baseline_after_estimates)?;
            w.f32(f.band)?;
            w.f32(f.deadband)?;
            w.u32(f.delay_ms)
        })
    }

    fn decode(r: &mut Reader<'_>) -> Result<Self, CodecError> {
        let tag = r.u8()?;
        let [warning, alarm, deadband] = r.array_of(|r| r.f32())?;
        let thresholds =
            Thresholds::from_kind(u32::from(tag), warning, alarm, deadband).ok_or(INVALID)?;
        let [on_delay_ms, off_delay_ms, fault_delay_ms, inhibit_ms] = r.array_of(|r| r.u32())?;
        let [
            stop_load,
            stop_speed,
            nominal_speed,
            load_min,
            load_max,
            angle_max,
            speed_max,
            force_max,
        ] = r.array_of(|r| r.f32())?;
        let spikes = get_option::<_, 13>(r, |r| {
            let window = r.u8()?;
            let [k, load_floor, angle_floor] = r.array_of(|r| r.f32())?;
            Ok(SpikeFilter {
                window,
                k,
                load_floor,
                angle_floor,
            })
        })?;
        let smoothing_tau_s = r.f32()?;
        let (stuck_ms, gap_ms) = (r.u32()?, r.u32()?);
        let trend = get_option::<_, 9>(r, |r| {
            Ok(TrendConfig {
                interval_ms: r.u32()?,
                points: r.u8()?,
                horizon_s: r.f32()?,
            })
        })?;
        let friction = get_option::<_, 28>(r, |r| {
            Ok(FrictionConfig {
                sensitivity_max: r.f32()?,
                tau_s: r.f32()?,
                baseline_after_ms: r.u32()?,
                baseline_after_estimates: r.u32()?,
                band: r.f32()?,
                deadband: r.f32()?,
                delay_ms: r.u32()?,
            })
        })?;
        let config = Config {
            thresholds,
            on_delay_ms,
            off_delay_ms,
            fault_delay_ms,
            inhibit_ms,
            stop_load,
            stop_speed,
            nominal_speed,
            load_min,
            load_max,
            angle_max,
            speed_max,
            force_max,
            spikes,
            smoothing_tau_s,
            stuck_ms,
            gap_ms,
            trend,
            friction,
        };
        config.validate().map_err(|_| INVALID)?;
        Ok(config)
    }
}
