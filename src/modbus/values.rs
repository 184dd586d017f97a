//! The map's values: each computed from the monitor when it is read; the codes of
//! states, event kinds and faults; external sample records decoded; and the decoding
//! of an event slot for a master written in Rust.

use super::div::div1000;
use super::map::{EventField, Field, SlotBlock};
use super::state::{Core, Counters};
use crate::Estimator;
use crate::monitor::annunciation::AlarmSet;
use crate::monitor::{
    Channel, Event, EventKind, FaultCause, FieldbusEvent, Reading, RiskState, Sample,
};
use crate::sensor_fault::{FaultKind, SensorFault, SensorId};
use core::fmt;

/// What a register holds for a value that is not there (no reading yet, no critical
/// angle at this load, no time to critical): the quiet NaN, `0x7FC0_0000`.
pub const NONE: u32 = 0x7FC0_0000;

/// The bits of an optional f32: [`NONE`] for none.
fn opt(x: Option<f32>) -> u32 {
    x.map_or(NONE, f32::to_bits)
}

/// Whole seconds in `ms` (saturated at `u32::MAX`) and the milliseconds left over, by
/// long division in 16-bit digits ([`div1000`]), so that no 64-bit division is linked
/// into a Cortex-M0 node; the digits by constant shifts (no 64-bit shift routine).
fn split_seconds(ms: u64) -> (u32, u32) {
    let mut seconds = 0u64;
    let mut rest = 0u32;
    let (high, low) = ((ms >> 32) as u32, ms as u32);
    for digit in [high >> 16, high & 0xFFFF, low >> 16, low & 0xFFFF] {
        // rest < 1000, so the digit fits in 26 bits.
        let digit = rest << 16 | digit;
        let q = div1000(digit);
        seconds = seconds << 16 | u64::from(q);
        // q * 1000 <= digit < 2^26: neither wraps.
        rest = digit.wrapping_sub(q.wrapping_mul(1000));
    }
    (u32::try_from(seconds).unwrap_or(u32::MAX), rest)
}

/// The NAMUR NE 107 category in `status` (bits 8-11).
mod ne107 {
    pub const GOOD: u32 = 0;
    pub const MAINTENANCE_REQUIRED: u32 = 1;
    pub const OUT_OF_SPECIFICATION: u32 = 2;
    pub const FUNCTION_CHECK: u32 = 3;
    pub const FAILURE: u32 = 4;
}

const fn channel_code(c: Channel) -> u16 {
    match c {
        Channel::Load => 0,
        Channel::Angle => 1,
        Channel::Speed => 2,
        Channel::AxialForce => 3,
    }
}

const CHANNELS: [Channel; 4] = [
    Channel::Load,
    Channel::Angle,
    Channel::Speed,
    Channel::AxialForce,
];

const fn kind_code(k: FaultKind) -> u16 {
    match k {
        FaultKind::Disconnected => 0,
        FaultKind::Bus => 1,
        FaultKind::Saturated => 2,
        FaultKind::Stuck => 3,
        FaultKind::Jump => 4,
        FaultKind::OutOfRange => 5,
    }
}

/// The code of an event's fault (the event slot's `fault`): bits 8-15 the cause (0
/// none, 1 non-finite, 2 out of range, 3 stuck, 4 gap, 5 time backwards, 6 driver, 7
/// estimator, 8 sensor); bits 0-7 the channel (0 load, 1 angle, 2 speed, 3 axial force),
/// or for a sensor's fault the sensor in bits 4-7 ([`SensorId::index`]) and the kind in
/// bits 0-3 (in the order of [`FaultKind::ALL`]).
pub const fn fault_code(fault: Option<FaultCause>) -> u16 {
    let (cause, low) = match fault {
        None => (0, 0),
        Some(FaultCause::NonFinite(c)) => (1, channel_code(c)),
        Some(FaultCause::OutOfRange(c)) => (2, channel_code(c)),
        Some(FaultCause::Stuck(c)) => (3, channel_code(c)),
        Some(FaultCause::Gap) => (4, 0),
        Some(FaultCause::TimeBackwards) => (5, 0),
        Some(FaultCause::Driver(c)) => (6, channel_code(c)),
        Some(FaultCause::Estimator) => (7, 0),
        Some(FaultCause::Sensor(s)) => (8, (s.sensor.index() as u16) << 4 | kind_code(s.kind)),
    };
    cause << 8 | low
}

/// The fault of a code [`fault_code`] gave (`Some(None)`: no fault); `None` for a code
/// it never gives.
pub fn fault_from_code(code: u16) -> Option<Option<FaultCause>> {
    let low = code & 0xFF;
    let channel = || CHANNELS.get(usize::from(low)).copied();
    let fault = match code >> 8 {
        0 if low == 0 => None,
        1 => Some(FaultCause::NonFinite(channel()?)),
        2 => Some(FaultCause::OutOfRange(channel()?)),
        3 => Some(FaultCause::Stuck(channel()?)),
        4 if low == 0 => Some(FaultCause::Gap),
        5 if low == 0 => Some(FaultCause::TimeBackwards),
        6 => Some(FaultCause::Driver(channel()?)),
        7 if low == 0 => Some(FaultCause::Estimator),
        8 => Some(FaultCause::Sensor(SensorFault {
            sensor: *SensorId::ALL.get(usize::from(low >> 4))?,
            kind: *FaultKind::ALL.get(usize::from(low & 15))?,
        })),
        _ => return None,
    };
    Some(fault)
}

/// An event slot's `kind`.
const fn event_kind_code(kind: &EventKind) -> u32 {
    match kind {
        EventKind::StateChange { .. } => 1,
        EventKind::Approaching { .. } => 2,
        EventKind::Friction { changed: true, .. } => 3,
        EventKind::Friction { changed: false, .. } => 4,
        EventKind::Fieldbus(FieldbusEvent::LineReverted) => 5,
        EventKind::Fieldbus(FieldbusEvent::MasterLost) => 6,
        EventKind::Fieldbus(FieldbusEvent::MasterBack) => 7,
    }
}

/// An event slot's field.
fn event_value(e: &Event, field: EventField) -> u32 {
    let r = &e.reading;
    let (from, to, fault) = match e.kind {
        EventKind::StateChange { from, to, fault } => {
            (from.index() as u32, to.index() as u32, fault_code(fault))
        }
        _ => (0, 0, 0),
    };
    match field {
        EventField::Seq => e.seq,
        EventField::TimeMs => e.time_ms,
        EventField::ElapsedS => split_seconds(e.elapsed_ms).0,
        EventField::ElapsedMs => split_seconds(e.elapsed_ms).1,
        EventField::Kind => event_kind_code(&e.kind),
        EventField::From => from,
        EventField::To => to,
        EventField::Fault => u32::from(fault),
        EventField::Value => match e.kind {
            EventKind::Approaching { time_to_critical_s } => time_to_critical_s.to_bits(),
            EventKind::Friction { mu, .. } => mu.to_bits(),
            EventKind::StateChange { .. } | EventKind::Fieldbus(_) => NONE,
        },
        EventField::Load => r.load.to_bits(),
        EventField::Phi => r.phi.to_bits(),
        EventField::SlipRatio => r.slip_ratio.to_bits(),
        EventField::AxialForce => r.axial_force.to_bits(),
        EventField::CriticalAngle => opt(r.critical_angle),
        EventField::Margin => opt(r.margin),
    }
}

/// Why registers are not an event.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DecodeError {
    /// Fewer registers than a slot.
    Short,
    /// A kind, state or fault code the server never writes.
    Code,
}

impl fmt::Display for DecodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            DecodeError::Short => "fewer registers than an event slot",
            DecodeError::Code => "a kind, state or fault code the server never writes",
        })
    }
}

impl core::error::Error for DecodeError {}

/// The event in one event slot's registers (as read, `event_0_seq` first); `Ok(None)`
/// for an empty slot. What a master written in Rust uses to get the monitor's own
/// [`Event`] back, bit for bit.
///
/// # Errors
/// [`DecodeError`] for fewer registers than a slot or a code the server never writes.
pub fn event_from_registers(regs: &[u16]) -> Result<Option<Event>, DecodeError> {
    let r = regs
        .get(..usize::from(super::map::EVENT_STRIDE))
        .ok_or(DecodeError::Short)?;
    let u32_at = |i: usize| u32::from(r[i]) << 16 | u32::from(r[i + 1]);
    let f32_at = |i: usize| f32::from_bits(u32_at(i));
    let opt_at = |i: usize| Some(u32_at(i)).filter(|&b| b != NONE).map(f32::from_bits);
    let state = |i: usize| {
        RiskState::ALL
            .get(usize::from(r[i]))
            .copied()
            .ok_or(DecodeError::Code)
    };
    let kind = match r[7] {
        0 => return Ok(None),
        1 => EventKind::StateChange {
            from: state(8)?,
            to: state(9)?,
            fault: fault_from_code(r[10]).ok_or(DecodeError::Code)?,
        },
        2 => EventKind::Approaching {
            time_to_critical_s: f32_at(11),
        },
        3 | 4 => EventKind::Friction {
            mu: f32_at(11),
            changed: r[7] == 3,
        },
        5 => EventKind::Fieldbus(FieldbusEvent::LineReverted),
        6 => EventKind::Fieldbus(FieldbusEvent::MasterLost),
        7 => EventKind::Fieldbus(FieldbusEvent::MasterBack),
        _ => return Err(DecodeError::Code),
    };
    Ok(Some(Event {
        seq: u32_at(0),
        time_ms: u32_at(2),
        elapsed_ms: u64::from(u32_at(4)) * 1000 + u64::from(r[6]),
        kind,
        reading: Reading {
            load: f32_at(13),
            phi: f32_at(15),
            slip_ratio: f32_at(17),
            axial_force: f32_at(19),
            critical_angle: opt_at(21),
            margin: opt_at(23),
        },
    }))
}

/// The sample in one record of an external samples block (big-endian register
/// bytes); `None` for flags with bits other than speed (0) and axial force (1).
pub(crate) fn sample_from_record(block: &SlotBlock, record: &[u8]) -> Option<Sample> {
    // Each field's bits by its `SampleField` (flags, time, P, phi, V, F), a record's
    // fields read by one loop; a basic record has no flags (0: no V, no F).
    let mut v = [0u32; 6];
    for e in block.fields {
        let Field::Sample(f) = e.field else {
            return None;
        };
        let at = 2 * usize::from(e.address());
        let bytes = record.get(at..at + 2 * usize::from(e.words()))?;
        *v.get_mut(f as usize)? = bytes.iter().fold(0, |x, &b| x << 8 | u32::from(b));
    }
    let [flags, time_ms, load, phi, speed, force] = v;
    if flags & !3 != 0 {
        return None;
    }
    let mut sample = Sample::new(time_ms, f32::from_bits(load), f32::from_bits(phi));
    sample.speed = (flags & 1 != 0).then_some(f32::from_bits(speed));
    sample.axial_force = (flags & 2 != 0).then_some(f32::from_bits(force));
    Some(sample)
}

impl<E: Estimator> Core<E> {
    /// `status`: the risk state, the NE 107 category, the unacknowledged alarms.
    fn status(&self) -> u32 {
        let state = self.monitor.state();
        let a = &self.annunciator;
        // Function check before the first sample and while the conditioning settles
        // (the state is held, no sample decides it); a failure before it.
        let checking = self.monitor.statistics().samples == 0 || self.monitor.settling();
        // Function check, too, while a node that needs its site's scene has none.
        let uncommissioned = self.scene_required && !self.commissioning.scene_commissioned();
        let category = match state {
            _ if uncommissioned => ne107::FUNCTION_CHECK,
            RiskState::SensorFault => ne107::FAILURE,
            _ if checking => ne107::FUNCTION_CHECK,
            RiskState::GrossSlip => ne107::OUT_OF_SPECIFICATION,
            RiskState::Microslip => ne107::MAINTENANCE_REQUIRED,
            _ if a.active().contains(AlarmSet::APPROACHING) => ne107::MAINTENANCE_REQUIRED,
            _ => ne107::GOOD,
        };
        // A lost master: out of specification (docs/modbus.md, Line settings), unless
        // the monitor's own category is graver.
        let category = if self.line.master_lost() {
            category.max(ne107::OUT_OF_SPECIFICATION)
        } else {
            category
        };
        state.index() as u32 | category << 8 | u32::from(a.unacknowledged().bits()) << 12
    }

    /// The value of `field` (of record `record` in a block) as the bits on the wire:
    /// a 16-bit value in the low half. The values of every poll (the first 16 input
    /// registers) here, small enough to stay cheap; the others out of line.
    #[inline]
    pub(super) fn value(&self, field: Field, record: u16) -> u32 {
        let reading =
            |f: fn(&Reading) -> Option<f32>| opt(self.monitor.reading().as_ref().and_then(f));
        match field {
            Field::Status => self.status(),
            Field::SlipRatio => reading(|r| Some(r.slip_ratio)),
            Field::AxialForce => reading(|r| Some(r.axial_force)),
            Field::CriticalAngle => reading(|r| r.critical_angle),
            Field::Margin => reading(|r| r.margin),
            Field::Load => reading(|r| Some(r.load)),
            Field::Misalignment => reading(|r| Some(r.phi)),
            Field::TimeToCritical => opt(self.monitor.time_to_critical()),
            _ => self.value_other(field, record),
        }
    }

    /// [`value`](Self::value) of a holding register, as cheap as the poll's.
    #[inline]
    pub(super) fn value_holding(&self, field: Field, record: u16) -> u32 {
        match field {
            Field::Sample(_) | Field::AcknowledgeAlarms => 0,
            Field::EventFrom => self.events.from,
            Field::LatchingAlarms => u32::from(self.annunciator.latching().bits()),
            Field::ExternalMode => u32::from(self.external),
            Field::UnitId => u32::from(self.unit),
            Field::MapVersion => u32::from(super::map::MAP_VERSION),
            Field::EventAck => self.ack.unwrap_or(u32::MAX),
            Field::Commission(reg) => self.commissioning.value(reg, &self.monitor),
            Field::Staged(f) => self.commissioning.staged(f, self.monitor.config()),
            _ => self.value_other(field, record),
        }
    }

    /// [`value`](Self::value) of the other fields: every field of the coils, the
    /// discrete inputs and the input registers, and the holding registers'
    /// configuration (`active_*`); the other holding registers are
    /// [`value_holding`](Self::value_holding)'s.
    #[inline(never)]
    pub(super) fn value_other(&self, field: Field, record: u16) -> u32 {
        let m = &self.monitor;
        let s = m.statistics();
        // The reading's values, copied only where one is read.
        let r = || m.reading();
        let a = &self.annunciator;
        let bit = |set: AlarmSet, which: AlarmSet| u32::from(set.contains(which));
        let per_state = |i: u8| RiskState::ALL.get(usize::from(i)).copied();
        match field {
            Field::Acknowledge | Field::AcknowledgeAlarms | Field::Sample(_) => 0,
            Field::Latching(w) => bit(a.latching(), w),
            Field::ExternalSamples | Field::ExternalMode => u32::from(self.external),
            Field::Indicated(w) => bit(a.indicated(), w),
            Field::Unacknowledged(w) => bit(a.unacknowledged(), w),
            Field::Running => u32::from(m.state() != RiskState::Stopped),
            Field::EventAvailable => u32::from(self.events.slot(0, m.next_event_seq()).is_some()),
            Field::SceneCommissioned => u32::from(self.commissioning.scene_commissioned()),
            Field::Status => self.status(),
            Field::Alarms => {
                u32::from(a.indicated().bits())
                    | u32::from(a.active().bits()) << 4
                    | u32::from(a.unacknowledged().bits()) << 8
                    | u32::from(a.latching().bits()) << 12
            }
            Field::LatchingAlarms => u32::from(a.latching().bits()),
            Field::SlipRatio => opt(r().map(|r| r.slip_ratio)),
            Field::AxialForce => opt(r().map(|r| r.axial_force)),
            Field::CriticalAngle => opt(r().and_then(|r| r.critical_angle)),
            Field::Margin => opt(r().and_then(|r| r.margin)),
            Field::Load => opt(r().map(|r| r.load)),
            Field::Misalignment => opt(r().map(|r| r.phi)),
            Field::TimeToCritical => opt(m.time_to_critical()),
            Field::Friction => opt(m.friction()),
            Field::Samples => s.samples() as u32,
            Field::RepeatedTimestamps => s.repeated_timestamps(),
            Field::Spikes => s.spikes(),
            Field::EventsDropped => s.events_dropped().saturating_add(self.events.dropped),
            Field::EventSeqNext => m.next_event_seq(),
            Field::Faults(i) => s
                .faults()
                .by_cause()
                .get(usize::from(i))
                .copied()
                .unwrap_or(0),
            Field::TimeInState(i) => {
                per_state(i).map_or(0, |state| split_seconds(s.time_in_state_ms(state)).0)
            }
            // The compensated sum rounded to f32, added in f32: the same bits as the
            // f64 total (`energy_j`) rounded to f32, for the compensation is below half
            // an ulp of the sum, so that one rounding of the exact sum gives both, and no
            // f64 arithmetic is linked into a node without an FPU for f64.
            Field::Energy(i) => s
                .energy
                .get(usize::from(i))
                .map_or(0, |e| (e.sum + e.compensation).to_bits()),
            Field::MaxSlipRatio => s.max_slip_ratio().to_bits(),
            Field::MaxAxialForce => s.max_axial_force().to_bits(),
            Field::MinMargin => opt(s.min_margin()),
            Field::Elapsed => split_seconds(m.elapsed_ms()).0,
            Field::LastSampleTime => self.last_time_ms,
            Field::ExternalAccepted => self.counters.external_accepted,
            Field::ExternalRefused => self.counters.external_refused,
            Field::BusFrames => self.bus(|c| c.framing.frames),
            Field::BusServerMessages => self.bus(|c| c.server_messages),
            Field::BusDiscarded => self.bus(|c| c.framing.discarded),
            Field::BusExceptions => self.bus(|c| c.exceptions),
            Field::EventFirst => self.events.first(m.next_event_seq()),
            Field::EventCount => u32::from(
                self.events
                    .count(super::map::EVENT_SLOTS, m.next_event_seq()),
            ),
            Field::EventsMissed => self.events.missed(m.next_event_seq()),
            Field::Event(f) => self
                .events
                .slot(record, m.next_event_seq())
                .map_or(0, |e| event_value(e, f)),
            Field::EventFrom => self.events.from,
            Field::UnitId => u32::from(self.unit),
            Field::MapVersion => u32::from(super::map::MAP_VERSION),
            Field::EventAck => self.ack.unwrap_or(u32::MAX),
            Field::EventAcked => self.storage.events_acknowledged.unwrap_or(u32::MAX),
            Field::EventsStored => self.storage.events_stored,
            Field::EventsOverwritten => self.storage.events_overwritten,
            Field::Checkpoints => self.storage.checkpoints,
            Field::CheckpointAge => self.storage.last_checkpoint_ms.map_or(u32::MAX, |t| {
                split_seconds(m.elapsed_ms().saturating_sub(t))
                    .0
                    .min(u32::MAX - 1)
            }),
            // Holding registers that only `value_holding` reads (every read of holding
            // registers inlines it): not read here too, so that the image holds one
            // copy of the commissioning registers' reading, not two.
            Field::Commission(_) | Field::Staged(_) => 0,
            Field::Active(f) => super::config::active(f, self.monitor.config()),
            Field::LineStaged(f) => self.line.staged_value(f),
            Field::SensorStaged(f) => self.sensing.staged_value(f),
            Field::SensorActive(f) => self.sensing.active().get(f),
            Field::LineActive(f) => self.line.active().get(f),
            Field::LineConfirmWindow => u32::from(super::line::LINE_CONFIRM_WINDOW_S),
            Field::LineReverts => self.line.reverts(),
            Field::LineStatus => {
                u32::from(self.line.master_lost()) | u32::from(self.line.confirm_left_ms() > 0) << 1
            }
            Field::LineConfirmLeft => div1000(self.line.confirm_left_ms().saturating_add(999)),
        }
    }

    /// A bus counter, modulo 2^16 (its register is 16 bits).
    fn bus(&self, f: impl Fn(&Counters) -> u32) -> u32 {
        f(&self.counters) & 0xFFFF
    }
}

#[cfg(test)]
mod tests {
    use super::split_seconds;

    /// The long division gives what u64 division gives, saturated where the seconds
    /// pass u32.
    #[test]
    fn split_seconds_is_division_by_1000() {
        let edges = [
            0,
            1,
            999,
            1000,
            1001,
            65_535_999,
            u64::from(u32::MAX),
            u64::from(u32::MAX) * 1000 + 999,
            u64::from(u32::MAX) * 1000 + 1000,
            u64::MAX,
        ];
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        let random = (0..10_000).map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x >> (x % 64)
        });
        for ms in edges.into_iter().chain(random) {
            let seconds = u32::try_from(ms / 1000).unwrap_or(u32::MAX);
            assert_eq!(split_seconds(ms), (seconds, (ms % 1000) as u32), "{ms}");
        }
    }
}
