//! The register map: one table in code, which [`registers_csv`] writes as
//! `docs/modbus/registers.csv` and from which the server reads and writes (through a
//! copy made at compile time without the text, so that a node links none of it).
//!
//! Each of the four Modbus tables is a run of single entries from address 0 without a
//! hole, then blocks of repeated records (the event window's slots, the external
//! samples) or a block of one record without a prefix (the line settings), in order;
//! between two blocks one run of reserved addresses at most (the holding registers
//! before [`LINE_ADDRESS`]), which a request refuses with exception 02. A 32-bit
//! value takes two registers, the high word first.

use super::config::{ConfigField, Reg};
use super::div::div_rem;
use crate::monitor::annunciation::AlarmSet;
use core::fmt;

/// The Modbus table an entry is in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Table {
    /// Coils (bits, read by function 1, written by 5 and 15).
    Coil,
    /// Discrete inputs (bits, read by function 2).
    Discrete,
    /// Input registers (read by function 4).
    Input,
    /// Holding registers (read by function 3, written by 6 and 16).
    Holding,
}

impl Table {
    /// The name in the CSV's `table` column.
    pub const fn as_str(self) -> &'static str {
        match self {
            Table::Coil => "coil",
            Table::Discrete => "discrete",
            Table::Input => "input",
            Table::Holding => "holding",
        }
    }
}

/// A value's type on the wire.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Type {
    /// Unsigned 16 bits (for a coil or discrete input: the bit, 0 or 1).
    U16,
    /// Signed 16 bits.
    I16,
    /// Unsigned 32 bits, two registers, high word first.
    U32,
    /// Signed 32 bits, two registers, high word first.
    I32,
    /// IEEE 754 binary32, two registers, high word first.
    F32,
}

impl Type {
    /// The name in the CSV's `type` column.
    pub const fn as_str(self) -> &'static str {
        match self {
            Type::U16 => "u16",
            Type::I16 => "i16",
            Type::U32 => "u32",
            Type::I32 => "i32",
            Type::F32 => "f32",
        }
    }

    /// Registers the value takes.
    pub const fn words(self) -> u16 {
        match self {
            Type::U16 | Type::I16 => 1,
            Type::U32 | Type::I32 | Type::F32 => 2,
        }
    }
}

/// Whether a master may write an entry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Access {
    /// Read only.
    R,
    /// Read and write.
    Rw,
}

impl Access {
    /// The name in the CSV's `access` column.
    pub const fn as_str(self) -> &'static str {
        match self {
            Access::R => "r",
            Access::Rw => "rw",
        }
    }
}

/// The values a master may write to an entry, in the register's unit (the CSV's
/// `min` and `max`, inclusive): a value outside them is refused, at the write
/// (exception 03: a switch, a command, a sample's flags) or at the commit (a staged
/// configuration value: `commit_error`, and an option that is off ignores its
/// values). Inside them a value is not always taken: the commit validates the
/// configuration whole (`Config::validate`: a d/b threshold positive, the warning
/// before the alarm, a spike window of 0 or 3 to 7, ...).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Domain {
    /// Read only: no master writes it (the CSV's `min` and `max` empty).
    ReadOnly,
    /// Any value of the type, for an `f32` NaN and the infinities too (a sample's
    /// value: counted as a sensor fault); empty `min` and `max`.
    Any,
    /// A whole number from `min` to `max`.
    Whole {
        /// The least.
        min: u32,
        /// The greatest.
        max: u32,
    },
    /// A finite number (never NaN or infinite) from `min` to `max`.
    Finite {
        /// The least.
        min: f32,
        /// The greatest.
        max: f32,
    },
}

impl Domain {
    /// Every value of an unsigned type of `words` registers.
    const fn unsigned(words: u16) -> Domain {
        Domain::Whole {
            min: 0,
            max: if words == 2 { u32::MAX } else { 0xFFFF },
        }
    }

    /// From 0 to `max`.
    const fn up_to(max: u32) -> Domain {
        Domain::Whole { min: 0, max }
    }

    /// Any finite f32 at or above `min`.
    const fn from(min: f32) -> Domain {
        Domain::Finite { min, max: f32::MAX }
    }
}

/// What an entry holds: the server computes it when it is read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Field {
    // Holding registers, first: the fields a read of holding registers computes
    // inline (`value_holding`) are then the first tags, which a Cortex-M0 dispatches
    // on without subtracting an offset.
    EventFrom,
    AcknowledgeAlarms,
    LatchingAlarms,
    ExternalMode,
    UnitId,
    MapVersion,
    EventAck,
    /// A commissioning register (`unlock`, `command`, the scene block, ...).
    Commission(Reg),
    /// A staged configuration register.
    Staged(ConfigField),
    /// An external sample's field (the basic or the full record).
    Sample(SampleField),
    /// A staged line setting (`config_unit_id`, ...).
    LineStaged(LineField),
    /// A line setting in force (`active_unit_id`, ...).
    LineActive(LineField),
    LineConfirmWindow,
    /// A staged sensor setting (`config_sample_period`, `config_load_zero`, ...).
    SensorStaged(SensorField),
    /// A sensor setting in force (`active_sample_period`, ...).
    SensorActive(SensorField),
    // Coils.
    Acknowledge,
    Latching(AlarmSet),
    ExternalSamples,
    // Discrete inputs.
    Indicated(AlarmSet),
    Unacknowledged(AlarmSet),
    Running,
    EventAvailable,
    SceneCommissioned,
    // Input registers.
    Status,
    Alarms,
    SlipRatio,
    AxialForce,
    CriticalAngle,
    Margin,
    Load,
    Misalignment,
    TimeToCritical,
    Friction,
    Samples,
    RepeatedTimestamps,
    Spikes,
    EventsDropped,
    EventSeqNext,
    /// Faults by cause, in the order of [`FaultCounts`](crate::monitor::FaultCounts).
    Faults(u8),
    /// Per risk state, by [`RiskState::index`](crate::monitor::RiskState::index).
    TimeInState(u8),
    Energy(u8),
    MaxSlipRatio,
    MaxAxialForce,
    MinMargin,
    Elapsed,
    LastSampleTime,
    ExternalAccepted,
    ExternalRefused,
    BusFrames,
    BusServerMessages,
    BusDiscarded,
    BusExceptions,
    EventFirst,
    EventCount,
    EventsMissed,
    /// An event slot's field.
    Event(EventField),
    // Store-and-forward and checkpoints.
    EventAcked,
    EventsStored,
    EventsOverwritten,
    Checkpoints,
    CheckpointAge,
    /// An active configuration register.
    Active(ConfigField),
    // The line's input registers.
    LineReverts,
    LineStatus,
    LineConfirmLeft,
}

/// The fields of an event slot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum EventField {
    Seq,
    TimeMs,
    ElapsedS,
    ElapsedMs,
    Kind,
    From,
    To,
    Fault,
    Value,
    Load,
    Phi,
    SlipRatio,
    AxialForce,
    CriticalAngle,
    Margin,
}

/// The fields of an external sample record (in this order: `sample_from_record`
/// keeps their values by it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum SampleField {
    Flags,
    TimeMs,
    Load,
    Phi,
    Speed,
    AxialForce,
}

/// One value of the map (in a block, one field of its record, at its offset).
#[derive(Debug, Clone, Copy)]
pub struct Entry {
    /// The table.
    pub table: Table,
    /// The 0-based address on the wire (in a block: the offset in the record).
    pub address: u16,
    /// The name (in a block, the field's; the CSV prefixes the record's).
    pub name: &'static str,
    /// The type on the wire.
    pub ty: Type,
    /// The physical value is the register's value times this.
    pub scale: &'static str,
    /// The SI unit of the physical value (empty: none).
    pub unit: &'static str,
    /// Whether a master may write it.
    pub access: Access,
    /// What it means.
    pub description: &'static str,
    pub(crate) field: Field,
}

impl Entry {
    /// The address after the value.
    pub const fn end(&self) -> u16 {
        self.address.saturating_add(self.ty.words())
    }

    /// The values a master may write ([`Domain`]).
    pub fn domain(&self) -> Domain {
        use crate::monitor::{SPIKE_WINDOW_CAPACITY, TREND_CAPACITY};
        let any = match self.ty {
            Type::U16 | Type::U32 => Domain::unsigned(self.ty.words()),
            Type::I16 | Type::I32 | Type::F32 => Domain::Any,
        };
        if self.access == Access::R {
            return Domain::ReadOnly;
        }
        let bit = Domain::up_to(1);
        let alarms = Domain::up_to(u32::from(AlarmSet::ALL.bits()));
        let finite = Domain::Finite {
            min: -f32::MAX,
            max: f32::MAX,
        };
        match self.field {
            // A coil: off or on.
            F::Acknowledge | F::Latching(_) | F::ExternalSamples => bit,
            F::AcknowledgeAlarms | F::LatchingAlarms => alarms,
            F::ExternalMode => bit,
            F::Commission(Reg::Command) => Domain::Whole {
                min: u32::from(super::config::command::COMMIT),
                max: u32::from(super::config::command::RESET_STATISTICS),
            },
            F::Sample(SampleField::Flags) => Domain::up_to(3),
            F::LineStaged(f) => match f {
                LineField::UnitId => Domain::Whole { min: 1, max: 247 },
                LineField::Baud => Domain::Whole {
                    min: BAUD_RATES[0],
                    max: BAUD_RATES[BAUD_RATES.len() - 1],
                },
                LineField::Parity => Domain::up_to(2),
                LineField::AnswerDelay => Domain::up_to(u32::from(ANSWER_DELAY_MAX_MS)),
                LineField::BusTimeout => any,
            },
            F::SensorStaged(f) => match f.bounds() {
                Bounds::Whole(min, max) => Domain::Whole { min, max },
                Bounds::Finite(min, max) => Domain::Finite { min, max },
                Bounds::NonZero(m) => Domain::Finite { min: -m, max: m },
            },
            F::Staged(f) => match f {
                G::ThresholdsOn | G::Friction => bit,
                G::SpikeWindow => Domain::up_to(SPIKE_WINDOW_CAPACITY as u32),
                G::TrendPoints => Domain::up_to(TREND_CAPACITY as u32),
                // Thresholds on the margin may be negative; on d/b the commit asks
                // them positive.
                G::Warning | G::Alarm | G::LoadMin | G::LoadMax => finite,
                G::Deadband
                | G::StopLoad
                | G::StopSpeed
                | G::NominalSpeed
                | G::AngleMax
                | G::SpeedMax
                | G::ForceMax
                | G::SpikeK
                | G::SpikeLoadFloor
                | G::SpikeAngleFloor
                | G::SmoothingTau
                | G::TrendHorizon
                | G::FrictionSensitivity
                | G::FrictionTau
                | G::FrictionBand
                | G::FrictionDeadband => Domain::from(0.0),
                G::OnDelay
                | G::OffDelay
                | G::FaultDelay
                | G::Inhibit
                | G::Stuck
                | G::Gap
                | G::TrendInterval
                | G::FrictionBaselineAfter
                | G::FrictionBaselineEstimates
                | G::FrictionDelay => any,
            },
            _ => any,
        }
    }
}

/// A block of `count` records of `stride` registers (or bits) from `address`.
#[derive(Debug, Clone, Copy)]
pub struct Block {
    /// The table.
    pub table: Table,
    /// The first record's address.
    pub address: u16,
    /// The records' name, `<prefix>_<index>_<field>` in the CSV; empty: one record,
    /// its fields' names bare.
    pub prefix: &'static str,
    /// Records.
    pub count: u16,
    /// Registers per record.
    pub stride: u16,
    /// The record's fields, their addresses offsets in the record, without a hole.
    pub fields: &'static [Entry],
}

impl Block {
    /// The address after the block.
    pub const fn end(&self) -> u16 {
        self.address
            .saturating_add(self.count.saturating_mul(self.stride))
    }
}

/// One table's map: its single entries from address 0, then its blocks.
#[derive(Debug, Clone, Copy)]
pub struct TableMap {
    /// The single entries, sorted by address, without a hole from 0.
    pub entries: &'static [Entry],
    /// The blocks, after the entries, in order; one run of reserved addresses at most
    /// between two of them.
    pub blocks: &'static [Block],
}

macro_rules! e {
    ($table:ident, $address:expr, $name:expr, $ty:ident, $unit:expr, $access:ident, $field:expr, $description:expr) => {
        Entry {
            table: Table::$table,
            address: $address,
            name: $name,
            ty: Type::$ty,
            scale: "1",
            unit: $unit,
            access: Access::$access,
            description: $description,
            field: $field,
        }
    };
}

use Field as F;

const W: AlarmSet = AlarmSet::WARNING;
const A: AlarmSet = AlarmSet::ALARM;
const S: AlarmSet = AlarmSet::SENSOR_FAULT;
const P: AlarmSet = AlarmSet::APPROACHING;

/// Coils.
#[rustfmt::skip]
pub static COILS: TableMap = TableMap {
    entries: &[
        e!(Coil, 0, "acknowledge", U16, "", Rw, F::Acknowledge,
            "write 1: acknowledge every alarm (ISA-18.2); reads 0"),
        e!(Coil, 1, "latch_warning", U16, "", Rw, F::Latching(W),
            "needs the unlock: 1: the warning latches (stays indicated after it clears until acknowledged)"),
        e!(Coil, 2, "latch_alarm", U16, "", Rw, F::Latching(A),
            "needs the unlock: 1: the alarm latches"),
        e!(Coil, 3, "latch_sensor_fault", U16, "", Rw, F::Latching(S),
            "needs the unlock: 1: the sensor fault latches"),
        e!(Coil, 4, "latch_approaching", U16, "", Rw, F::Latching(P),
            "needs the unlock: 1: the approaching warning latches"),
        e!(Coil, 5, "external_samples", U16, "", Rw, F::ExternalSamples,
            "needs the unlock: 1: samples written to the holding blocks sample_* and sample_full_* are processed; 0: they are refused with exception 01"),
    ],
    blocks: &[],
};

/// Discrete inputs.
#[rustfmt::skip]
pub static DISCRETES: TableMap = TableMap {
    entries: &[
        e!(Discrete, 0, "warning", U16, "", R, F::Indicated(W),
            "warning indicated: state microslip or gross slip, or latched and unacknowledged"),
        e!(Discrete, 1, "alarm", U16, "", R, F::Indicated(A),
            "alarm indicated: state gross slip, or latched and unacknowledged"),
        e!(Discrete, 2, "sensor_fault", U16, "", R, F::Indicated(S),
            "sensor fault indicated: state sensor fault, or latched and unacknowledged"),
        e!(Discrete, 3, "approaching", U16, "", R, F::Indicated(P),
            "approaching indicated: time to critical below the horizon while the contact sticks, or latched and unacknowledged"),
        e!(Discrete, 4, "warning_unacknowledged", U16, "", R, F::Unacknowledged(W),
            "the warning was raised and is not acknowledged"),
        e!(Discrete, 5, "alarm_unacknowledged", U16, "", R, F::Unacknowledged(A),
            "the alarm was raised and is not acknowledged"),
        e!(Discrete, 6, "sensor_fault_unacknowledged", U16, "", R, F::Unacknowledged(S),
            "the sensor fault was raised and is not acknowledged"),
        e!(Discrete, 7, "approaching_unacknowledged", U16, "", R, F::Unacknowledged(P),
            "the approaching warning was raised and is not acknowledged"),
        e!(Discrete, 8, "running", U16, "", R, F::Running,
            "the state is not stopped"),
        e!(Discrete, 9, "event_available", U16, "", R, F::EventAvailable,
            "the event window holds an event at or after event_from"),
        e!(Discrete, 10, "scene_commissioned", U16, "", R, F::SceneCommissioned,
            "the scene the monitor runs was committed over the bus, kept across resets (0: the build's scene; a node with its own sensors then monitors nothing and status reads NE 107 function check)"),
    ],
    blocks: &[],
};

/// The register map's version (holding register `map_version`): a change of an
/// address, a type or a meaning increments it.
pub const MAP_VERSION: u16 = 4;

/// Where the event window's header starts (input registers).
pub const EVENT_WINDOW_ADDRESS: u16 = 82;
/// Where the storage's registers start (input registers), after the window's header.
pub const STORAGE_ADDRESS: u16 = EVENT_WINDOW_ADDRESS + 5;
/// Where the event window's slots start (input registers).
pub const EVENT_SLOTS_ADDRESS: u16 = STORAGE_ADDRESS + 10;
/// Event slots in the window.
pub const EVENT_SLOTS: u16 = 4;
/// Registers per event slot.
pub const EVENT_STRIDE: u16 = 25;

/// Input registers.
#[rustfmt::skip]
pub static INPUTS: TableMap = TableMap {
    entries: &[
        e!(Input, 0, "status", U16, "", R, F::Status,
            "bits 0-7 risk state (0 stopped, 1 normal, 2 microslip, 3 gross slip, 4 sensor fault); bits 8-11 NAMUR NE 107 category (0 good, 1 maintenance required, 2 out of specification, 3 function check, 4 failure); bits 12-15 unacknowledged alarms (warning, alarm, sensor fault, approaching)"),
        e!(Input, 1, "alarms", U16, "", R, F::Alarms,
            "bits 0-3 alarms indicated, 4-7 active, 8-11 unacknowledged, 12-15 latching (each: warning, alarm, sensor fault, approaching)"),
        e!(Input, 2, "slip_ratio", F32, "", R, F::SlipRatio,
            "slip ratio d/b of the last valid running sample (eq 16; eq 23 for line contact); NaN none yet"),
        e!(Input, 4, "axial_force", F32, "N", R, F::AxialForce,
            "axial force F (eq 21, 27, 29; measured when the sample carries one); NaN none yet"),
        e!(Input, 6, "critical_angle", F32, "rad", R, F::CriticalAngle,
            "critical misalignment angle phi0 at this load; NaN none (no reading, or none exists at this load)"),
        e!(Input, 8, "margin", F32, "rad", R, F::Margin,
            "margin phi0 - |phi|; NaN none"),
        e!(Input, 10, "load", F32, "N", R, F::Load,
            "conditioned normal load P; NaN none yet"),
        e!(Input, 12, "misalignment", F32, "rad", R, F::Misalignment,
            "conditioned misalignment phi; NaN none yet"),
        e!(Input, 14, "time_to_critical", F32, "s", R, F::TimeToCritical,
            "time until gross slip at the margin's current drift; NaN none (the margin does not fall, or the trend is off)"),
        e!(Input, 16, "friction", F32, "", R, F::Friction,
            "filtered friction coefficient mu from a measured axial force; NaN none"),
        e!(Input, 18, "samples", U32, "", R, F::Samples,
            "samples processed (modulo 2^32)"),
        e!(Input, 20, "repeated_timestamps", U32, "", R, F::RepeatedTimestamps,
            "samples with the previous sample's timestamp, counted and ignored"),
        e!(Input, 22, "spikes", U32, "", R, F::Spikes,
            "spikes replaced by the window's median"),
        e!(Input, 24, "events_dropped", U32, "", R, F::EventsDropped,
            "events lost before a master read them (the monitor's queue and the event window)"),
        e!(Input, 26, "event_seq_next", U32, "", R, F::EventSeqNext,
            "the sequence number the next event will get"),
        e!(Input, 28, "faults_non_finite", U32, "", R, F::Faults(0),
            "samples refused: a value NaN or infinite"),
        e!(Input, 30, "faults_out_of_range", U32, "", R, F::Faults(1),
            "samples refused: a value outside the configured range"),
        e!(Input, 32, "faults_stuck", U32, "", R, F::Faults(2),
            "samples refused: a stuck sensor"),
        e!(Input, 34, "faults_gap", U32, "", R, F::Faults(3),
            "samples refused: a gap between samples"),
        e!(Input, 36, "faults_time_backwards", U32, "", R, F::Faults(4),
            "samples refused: the timestamp went backwards"),
        e!(Input, 38, "faults_driver", U32, "", R, F::Faults(5),
            "samples refused: a driver reported a fault"),
        e!(Input, 40, "faults_estimator", U32, "", R, F::Faults(6),
            "samples refused by the estimator"),
        e!(Input, 42, "faults_sensor", U32, "", R, F::Faults(7),
            "samples refused by the sensors' own fault detection"),
        e!(Input, 44, "time_stopped", U32, "s", R, F::TimeInState(0),
            "time in state stopped (whole seconds)"),
        e!(Input, 46, "time_normal", U32, "s", R, F::TimeInState(1),
            "time in state normal"),
        e!(Input, 48, "time_microslip", U32, "s", R, F::TimeInState(2),
            "time in state microslip"),
        e!(Input, 50, "time_gross_slip", U32, "s", R, F::TimeInState(3),
            "time in state gross slip"),
        e!(Input, 52, "time_sensor_fault", U32, "s", R, F::TimeInState(4),
            "time in state sensor fault"),
        e!(Input, 54, "energy_stopped", F32, "J", R, F::Energy(0),
            "energy dissipated in state stopped (F phi V integrated, section 7)"),
        e!(Input, 56, "energy_normal", F32, "J", R, F::Energy(1),
            "energy dissipated in state normal"),
        e!(Input, 58, "energy_microslip", F32, "J", R, F::Energy(2),
            "energy dissipated in state microslip"),
        e!(Input, 60, "energy_gross_slip", F32, "J", R, F::Energy(3),
            "energy dissipated in state gross slip"),
        e!(Input, 62, "energy_sensor_fault", F32, "J", R, F::Energy(4),
            "energy dissipated in state sensor fault"),
        e!(Input, 64, "max_slip_ratio", F32, "", R, F::MaxSlipRatio,
            "highest d/b of a valid running sample (0 before one)"),
        e!(Input, 66, "max_axial_force", F32, "N", R, F::MaxAxialForce,
            "highest |F| of a valid running sample (0 before one)"),
        e!(Input, 68, "min_margin", F32, "rad", R, F::MinMargin,
            "lowest margin; NaN none"),
        e!(Input, 70, "elapsed", U32, "s", R, F::Elapsed,
            "monotonic time since the first sample (whole seconds)"),
        e!(Input, 72, "last_sample_time", U32, "ms", R, F::LastSampleTime,
            "timestamp of the last sample offered (the sample's own u32 ms counter)"),
        e!(Input, 74, "external_accepted", U32, "", R, F::ExternalAccepted,
            "external samples taken from the bus and processed"),
        e!(Input, 76, "external_refused", U32, "", R, F::ExternalRefused,
            "writes of external samples refused with an exception (none of their samples processed)"),
        e!(Input, 78, "bus_frames", U16, "", R, F::BusFrames,
            "frames with a valid CRC seen on the bus, any unit (modulo 2^16)"),
        e!(Input, 79, "bus_server_messages", U16, "", R, F::BusServerMessages,
            "requests for this unit or broadcast (modulo 2^16)"),
        e!(Input, 80, "bus_discarded", U16, "", R, F::BusDiscarded,
            "bytes discarded: garbage, wrong CRC, truncated or oversized frames (modulo 2^16)"),
        e!(Input, 81, "bus_exceptions", U16, "", R, F::BusExceptions,
            "exception responses sent (modulo 2^16)"),
        e!(Input, EVENT_WINDOW_ADDRESS, "event_first", U32, "", R, F::EventFirst,
            "sequence number of event slot 0 (the first event held at or after event_from)"),
        e!(Input, EVENT_WINDOW_ADDRESS + 2, "event_count", U16, "", R, F::EventCount,
            "filled event slots (0 to 4), from slot 0"),
        e!(Input, EVENT_WINDOW_ADDRESS + 3, "events_missed", U32, "", R, F::EventsMissed,
            "events from event_from to event_first that were lost (the gap this read cannot fill)"),
        e!(Input, STORAGE_ADDRESS, "event_acked", U32, "", R, F::EventAcked,
            "events through this number are acknowledged on flash; 0xFFFFFFFF none"),
        e!(Input, STORAGE_ADDRESS + 2, "events_stored", U32, "", R, F::EventsStored,
            "unacknowledged events on flash"),
        e!(Input, STORAGE_ADDRESS + 4, "events_overwritten", U32, "", R, F::EventsOverwritten,
            "unacknowledged events dropped from full flash, the oldest (a gap as large in the numbers)"),
        e!(Input, STORAGE_ADDRESS + 6, "checkpoints", U32, "", R, F::Checkpoints,
            "number of the newest checkpoint of the monitor's state (0 none)"),
        e!(Input, STORAGE_ADDRESS + 8, "checkpoint_age", U32, "s", R, F::CheckpointAge,
            "monitor time since the newest checkpoint, power-off not counted; 0xFFFFFFFF none"),
    ],
    blocks: &[
        Block {
            table: Table::Input,
            address: EVENT_SLOTS_ADDRESS,
            prefix: "event",
            count: EVENT_SLOTS,
            stride: EVENT_STRIDE,
            fields: &EVENT_FIELDS,
        },
        Block {
            table: Table::Input,
            address: LINE_INPUTS_ADDRESS,
            prefix: "",
            count: 1,
            stride: 4,
            fields: &LINE_INPUT_FIELDS,
        },
    ],
};

/// Where the line's input registers start, after the event slots.
pub const LINE_INPUTS_ADDRESS: u16 = EVENT_SLOTS_ADDRESS + EVENT_SLOTS * EVENT_STRIDE;

#[rustfmt::skip]
static LINE_INPUT_FIELDS: [Entry; 3] = [
    e!(Input, 0, "line_reverts", U32, "", R, F::LineReverts,
        "changes of the line settings undone for want of a confirmation within line_confirm_window (each also an event, kind 5)"),
    e!(Input, 2, "line_status", U16, "", R, F::LineStatus,
        "bit 0 the master is lost: no request for this node within active_bus_timeout (shown until the answer to the next request); bit 1 a change of the line settings waits for its confirmation"),
    e!(Input, 3, "line_confirm_left", U16, "s", R, F::LineConfirmLeft,
        "seconds left for a request at the new line settings before the node goes back to the old ones (0 none waits)"),
];

use EventField as V;

#[rustfmt::skip]
static EVENT_FIELDS: [Entry; 15] = [
    e!(Input, 0, "seq", U32, "", R, F::Event(V::Seq),
        "sequence number"),
    e!(Input, 2, "time_ms", U32, "ms", R, F::Event(V::TimeMs),
        "the sample's own timestamp (u32 ms counter)"),
    e!(Input, 4, "elapsed_s", U32, "s", R, F::Event(V::ElapsedS),
        "monotonic time since the first sample, whole seconds"),
    e!(Input, 6, "elapsed_ms", U16, "ms", R, F::Event(V::ElapsedMs),
        "monotonic time since the first sample, the milliseconds (0-999)"),
    e!(Input, 7, "kind", U16, "", R, F::Event(V::Kind),
        "0 empty slot, 1 state change, 2 approaching, 3 friction changed, 4 friction back in band, 5 line settings reverted (not confirmed), 6 master lost (bus timeout), 7 master back"),
    e!(Input, 8, "from", U16, "", R, F::Event(V::From),
        "state change: the state left (risk state code as in status)"),
    e!(Input, 9, "to", U16, "", R, F::Event(V::To),
        "state change: the state entered"),
    e!(Input, 10, "fault", U16, "", R, F::Event(V::Fault),
        "the fault behind a change to sensor fault: bits 8-15 cause (0 none, 1 non-finite, 2 out of range, 3 stuck, 4 gap, 5 time backwards, 6 driver, 7 estimator, 8 sensor); bits 0-7 the channel (0 load, 1 angle, 2 speed, 3 axial force) or for cause 8 the sensor (bits 4-7: 0 load, 1 probe 1, 2 probe 2, 3 speed) and its fault kind (bits 0-3: 0 disconnected, 1 bus, 2 saturated, 3 stuck, 4 jump, 5 out of range)"),
    e!(Input, 11, "value", F32, "", R, F::Event(V::Value),
        "approaching: time to critical (s); friction: the filtered mu; NaN otherwise"),
    e!(Input, 13, "load", F32, "N", R, F::Event(V::Load),
        "P of the reading behind the event"),
    e!(Input, 15, "phi", F32, "rad", R, F::Event(V::Phi),
        "phi of the reading"),
    e!(Input, 17, "slip_ratio", F32, "", R, F::Event(V::SlipRatio),
        "d/b of the reading"),
    e!(Input, 19, "axial_force", F32, "N", R, F::Event(V::AxialForce),
        "F of the reading"),
    e!(Input, 21, "critical_angle", F32, "rad", R, F::Event(V::CriticalAngle),
        "phi0 of the reading; NaN none"),
    e!(Input, 23, "margin", F32, "rad", R, F::Event(V::Margin),
        "margin of the reading; NaN none"),
];

/// Where the basic external samples start (holding registers).
pub const SAMPLES_ADDRESS: u16 = 152;
/// Records of the basic block: the most one function-16 write carries.
pub const SAMPLES: u16 = 20;
/// Registers per basic record (time, P, phi).
pub const SAMPLE_STRIDE: u16 = 6;
/// Where the full external samples start (holding registers).
pub const SAMPLES_FULL_ADDRESS: u16 = SAMPLES_ADDRESS + SAMPLES * SAMPLE_STRIDE;
/// Records of the full block.
pub const SAMPLES_FULL: u16 = 11;
/// Registers per full record (flags, time, P, phi, V, F).
pub const SAMPLE_FULL_STRIDE: u16 = 11;
/// Where the scene block starts (holding registers): the prepared scene's bytes, two
/// a register, the first the high byte.
pub const SCENE_ADDRESS: u16 = SAMPLES_FULL_ADDRESS + SAMPLES_FULL * SAMPLE_FULL_STRIDE;
/// Registers of the scene block.
pub const SCENE_WORDS: u16 = (super::config::SCENE_BYTES_MAX / 2) as u16;

#[rustfmt::skip]
static SCENE_FIELDS: [Entry; 1] = [
    e!(Holding, 0, "word", U16, "", Rw, F::Commission(K::Scene),
        "needs the unlock: two bytes of the staged prepared scene (high byte first), from byte 0 at scene_0_word; reads 0"),
];

use ConfigField as G;
use Reg as K;
use SampleField as X;

#[rustfmt::skip]
static SAMPLE_FIELDS: [Entry; 3] = [
    e!(Holding, 0, "time_ms", U32, "ms", Rw, F::Sample(X::TimeMs),
        "the sample's timestamp (a u32 ms counter; wraps are forward steps)"),
    e!(Holding, 2, "load", F32, "N", Rw, F::Sample(X::Load),
        "normal load P"),
    e!(Holding, 4, "phi", F32, "rad", Rw, F::Sample(X::Phi),
        "misalignment phi"),
];

#[rustfmt::skip]
static SAMPLE_FULL_FIELDS: [Entry; 6] = [
    e!(Holding, 0, "flags", U16, "", Rw, F::Sample(X::Flags),
        "bit 0: speed measured, bit 1: axial force measured (other bits 0)"),
    e!(Holding, 1, "time_ms", U32, "ms", Rw, F::Sample(X::TimeMs),
        "the sample's timestamp"),
    e!(Holding, 3, "load", F32, "N", Rw, F::Sample(X::Load),
        "normal load P"),
    e!(Holding, 5, "phi", F32, "rad", Rw, F::Sample(X::Phi),
        "misalignment phi"),
    e!(Holding, 7, "speed", F32, "m/s", Rw, F::Sample(X::Speed),
        "rolling speed V (used when flags bit 0)"),
    e!(Holding, 9, "axial_force", F32, "N", Rw, F::Sample(X::AxialForce),
        "measured axial force F (used when flags bit 1)"),
];

/// Holding registers.
#[rustfmt::skip]
pub static HOLDINGS: TableMap = TableMap {
    entries: &[
        e!(Holding, 0, "event_from", U32, "", Rw, F::EventFrom,
            "the first event sequence number the event window shows; write event_first + event_count after a read"),
        e!(Holding, 2, "acknowledge_alarms", U16, "", Rw, F::AcknowledgeAlarms,
            "write a bit set: acknowledge those alarms (bits 0-3: warning, alarm, sensor fault, approaching); reads 0"),
        e!(Holding, 3, "latching", U16, "", Rw, F::LatchingAlarms,
            "needs the unlock: the alarms that latch, bits 0-3 as in acknowledge_alarms (the coils latch_* alike); applies at once, kept with the committed configuration"),
        e!(Holding, 4, "external_mode", U16, "", Rw, F::ExternalMode,
            "needs the unlock: 1: external samples are processed, 0: refused (the coil external_samples alike); applies at once, kept with the committed configuration"),
        e!(Holding, 5, "unit_id", U16, "", R, F::UnitId,
            "the unit id this node answers (read only)"),
        e!(Holding, 6, "map_version", U16, "", R, F::MapVersion,
            "the version of this register map (read only): a change of an address, type or meaning increments it"),
        e!(Holding, 7, "event_ack", U32, "", Rw, F::EventAck,
            "write n: acknowledge events through n (below event_seq_next), freeing them on flash; event_from moves past n; 0xFFFFFFFF none"),
        e!(Holding, 9, "unlock", U16, "s", Rw, F::Commission(K::Unlock),
            "write the site's code: commissioning writes are allowed until a commit, the command lock or 300 s after the last of them; 3 wrong codes in a row lock out every code for 300 s; reads the seconds the unlock has left (0 locked)"),
        e!(Holding, 10, "command", U16, "", Rw, F::Commission(K::Command),
            "needs the unlock: 1 commit the staged copy (validated, applied whole, then locked; refused with exception 03 and commit_error), 2 revert (discard it), 3 lock, 4 reset the statistics (counts, time and energy per state, extremes); reads 0"),
        e!(Holding, 11, "commit_error", U16, "", R, F::Commission(K::CommitError),
            "the last commit's reason: 0 applied, 1 nothing staged, 0x10 + the configuration's error, 0x20 + the scene's error (docs/modbus.md)"),
        e!(Holding, 12, "config_source", U16, "", R, F::Commission(K::Source),
            "the configuration running: 0 the build-time defaults (none stored), 1 the committed one, 2 the build-time defaults because the stored one was damaged"),
        e!(Holding, 13, "staged", U16, "", R, F::Commission(K::Staged),
            "what is staged: bit 0 the configuration, bit 1 the scene, bit 2 a new code, bit 3 the line settings, bit 4 the sensor settings (0: the staged copy is the active one)"),
        e!(Holding, 14, "staged_generation", U16, "", R, F::Commission(K::Generation),
            "values written into the staged copy (modulo 2^16): a change between a master's writes and its commit is another master's"),
        e!(Holding, 15, "lockout", U16, "s", R, F::Commission(K::Lockout),
            "seconds left of the lock-out after wrong codes (0 none)"),
        e!(Holding, 16, "unlock_failures", U16, "", R, F::Commission(K::UnlockFailures),
            "wrong codes, and codes written during a lock-out (modulo 2^16)"),
        e!(Holding, 17, "refused_writes", U16, "", R, F::Commission(K::Refused),
            "commissioning writes refused while locked (modulo 2^16)"),
        e!(Holding, 18, "new_code", U16, "", Rw, F::Commission(K::NewCode),
            "needs the unlock: stages a new site code, in force after the commit; reads 0"),
        e!(Holding, 19, "scene_bytes", U16, "", R, F::Commission(K::SceneBytes),
            "bytes of the prepared scene this node takes in the scene block (0: it takes none)"),
        e!(Holding, 20, "scene_staged_crc", U32, "", R, F::Commission(K::SceneStagedCrc),
            "the CRC-32 of the staged scene's bytes before their own CRC: equal to the prepared file's last four bytes when it was written whole"),
        e!(Holding, 22, "scene_active_crc", U32, "", R, F::Commission(K::SceneActiveCrc),
            "the same of the active scene (0: this node takes no scene)"),
        e!(Holding, 24, "config_thresholds_on", U16, "", Rw, F::Staged(G::ThresholdsOn),
            "needs the unlock; staged: what the thresholds are on: 0 the slip ratio d/b (eq 16; eq 23 for line contact), 1 the margin phi0 - |phi| (rad)"),
        e!(Holding, 25, "config_warning", F32, "", Rw, F::Staged(G::Warning),
            "needs the unlock; staged: warning threshold (microslip): d/b, or the margin (rad) at or below which it is raised"),
        e!(Holding, 27, "config_alarm", F32, "", Rw, F::Staged(G::Alarm),
            "needs the unlock; staged: alarm threshold (gross slip): d/b, or the margin (rad)"),
        e!(Holding, 29, "config_deadband", F32, "", Rw, F::Staged(G::Deadband),
            "needs the unlock; staged: clearing deadband of the thresholds (d/b, or rad)"),
        e!(Holding, 31, "config_on_delay", U32, "ms", Rw, F::Staged(G::OnDelay),
            "needs the unlock; staged: on-delay: a more severe state holds this long before it is entered"),
        e!(Holding, 33, "config_off_delay", U32, "ms", Rw, F::Staged(G::OffDelay),
            "needs the unlock; staged: off-delay: a less severe state holds this long before it is entered"),
        e!(Holding, 35, "config_fault_delay", U32, "ms", Rw, F::Staged(G::FaultDelay),
            "needs the unlock; staged: delay before a sensor fault is reported (0: at once)"),
        e!(Holding, 37, "config_inhibit", U32, "ms", Rw, F::Staged(G::Inhibit),
            "needs the unlock; staged: start-up inhibit: no warning or alarm this long after the machine starts"),
        e!(Holding, 39, "config_stop_load", F32, "N", Rw, F::Staged(G::StopLoad),
            "needs the unlock; staged: below this load the machine stands (state stopped)"),
        e!(Holding, 41, "config_stop_speed", F32, "m/s", Rw, F::Staged(G::StopSpeed),
            "needs the unlock; staged: below this measured speed the machine stands"),
        e!(Holding, 43, "config_nominal_speed", F32, "m/s", Rw, F::Staged(G::NominalSpeed),
            "needs the unlock; staged: rolling speed for the wear integral when a sample has none"),
        e!(Holding, 45, "config_load_min", F32, "N", Rw, F::Staged(G::LoadMin),
            "needs the unlock; staged: lowest accepted load"),
        e!(Holding, 47, "config_load_max", F32, "N", Rw, F::Staged(G::LoadMax),
            "needs the unlock; staged: highest accepted load"),
        e!(Holding, 49, "config_angle_max", F32, "rad", Rw, F::Staged(G::AngleMax),
            "needs the unlock; staged: highest accepted |phi|"),
        e!(Holding, 51, "config_speed_max", F32, "m/s", Rw, F::Staged(G::SpeedMax),
            "needs the unlock; staged: highest accepted speed"),
        e!(Holding, 53, "config_force_max", F32, "N", Rw, F::Staged(G::ForceMax),
            "needs the unlock; staged: highest accepted |F| of a measured axial force"),
        e!(Holding, 55, "config_spike_window", U16, "", Rw, F::Staged(G::SpikeWindow),
            "needs the unlock; staged: spike filter: window (samples, 3 to 7); 0: off"),
        e!(Holding, 56, "config_spike_k", F32, "", Rw, F::Staged(G::SpikeK),
            "needs the unlock; staged: spike filter: a spike is beyond k scaled MADs plus the floor from the median"),
        e!(Holding, 58, "config_spike_load_floor", F32, "N", Rw, F::Staged(G::SpikeLoadFloor),
            "needs the unlock; staged: spike filter: the load test's floor"),
        e!(Holding, 60, "config_spike_angle_floor", F32, "rad", Rw, F::Staged(G::SpikeAngleFloor),
            "needs the unlock; staged: spike filter: the angle test's floor"),
        e!(Holding, 62, "config_smoothing_tau", F32, "s", Rw, F::Staged(G::SmoothingTau),
            "needs the unlock; staged: time constant of the smoothing of load and angle; 0: off"),
        e!(Holding, 64, "config_stuck", U32, "ms", Rw, F::Staged(G::Stuck),
            "needs the unlock; staged: a value unchanged this long while running is a stuck sensor; 0: off"),
        e!(Holding, 66, "config_gap", U32, "ms", Rw, F::Staged(G::Gap),
            "needs the unlock; staged: a step between samples longer than this is a gap; 0: off"),
        e!(Holding, 68, "config_trend_interval", U32, "ms", Rw, F::Staged(G::TrendInterval),
            "needs the unlock; staged: time to critical: one trend point every this long; 0: the trend is off"),
        e!(Holding, 70, "config_trend_points", U16, "", Rw, F::Staged(G::TrendPoints),
            "needs the unlock; staged: time to critical: points in the fit (3 to 16)"),
        e!(Holding, 71, "config_trend_horizon", F32, "s", Rw, F::Staged(G::TrendHorizon),
            "needs the unlock; staged: time to critical: approaching is raised below this"),
        e!(Holding, 73, "config_friction", U16, "", Rw, F::Staged(G::Friction),
            "needs the unlock; staged: 1: friction tracking from a measured axial force on, 0: off"),
        e!(Holding, 74, "config_friction_sensitivity", F32, "", Rw, F::Staged(G::FrictionSensitivity),
            "needs the unlock; staged: friction: the highest sensitivity d ln mu / d ln F of an estimate that counts"),
        e!(Holding, 76, "config_friction_tau", F32, "s", Rw, F::Staged(G::FrictionTau),
            "needs the unlock; staged: friction: time constant of the filter of mu"),
        e!(Holding, 78, "config_friction_baseline_after", U32, "ms", Rw, F::Staged(G::FrictionBaselineAfter),
            "needs the unlock; staged: friction: the baseline is captured after running this long"),
        e!(Holding, 80, "config_friction_baseline_estimates", U32, "", Rw, F::Staged(G::FrictionBaselineEstimates),
            "needs the unlock; staged: friction: and after this many accepted estimates (at least 1)"),
        e!(Holding, 82, "config_friction_band", F32, "", Rw, F::Staged(G::FrictionBand),
            "needs the unlock; staged: friction: relative band around the baseline"),
        e!(Holding, 84, "config_friction_deadband", F32, "", Rw, F::Staged(G::FrictionDeadband),
            "needs the unlock; staged: friction: clearing deadband (below the band)"),
        e!(Holding, 86, "config_friction_delay", U32, "ms", Rw, F::Staged(G::FrictionDelay),
            "needs the unlock; staged: friction: a change is raised or cleared after this long"),
        e!(Holding, 88, "active_thresholds_on", U16, "", R, F::Active(G::ThresholdsOn),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 89, "active_warning", F32, "", R, F::Active(G::Warning),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 91, "active_alarm", F32, "", R, F::Active(G::Alarm),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 93, "active_deadband", F32, "", R, F::Active(G::Deadband),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 95, "active_on_delay", U32, "ms", R, F::Active(G::OnDelay),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 97, "active_off_delay", U32, "ms", R, F::Active(G::OffDelay),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 99, "active_fault_delay", U32, "ms", R, F::Active(G::FaultDelay),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 101, "active_inhibit", U32, "ms", R, F::Active(G::Inhibit),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 103, "active_stop_load", F32, "N", R, F::Active(G::StopLoad),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 105, "active_stop_speed", F32, "m/s", R, F::Active(G::StopSpeed),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 107, "active_nominal_speed", F32, "m/s", R, F::Active(G::NominalSpeed),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 109, "active_load_min", F32, "N", R, F::Active(G::LoadMin),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 111, "active_load_max", F32, "N", R, F::Active(G::LoadMax),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 113, "active_angle_max", F32, "rad", R, F::Active(G::AngleMax),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 115, "active_speed_max", F32, "m/s", R, F::Active(G::SpeedMax),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 117, "active_force_max", F32, "N", R, F::Active(G::ForceMax),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 119, "active_spike_window", U16, "", R, F::Active(G::SpikeWindow),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 120, "active_spike_k", F32, "", R, F::Active(G::SpikeK),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 122, "active_spike_load_floor", F32, "N", R, F::Active(G::SpikeLoadFloor),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 124, "active_spike_angle_floor", F32, "rad", R, F::Active(G::SpikeAngleFloor),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 126, "active_smoothing_tau", F32, "s", R, F::Active(G::SmoothingTau),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 128, "active_stuck", U32, "ms", R, F::Active(G::Stuck),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 130, "active_gap", U32, "ms", R, F::Active(G::Gap),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 132, "active_trend_interval", U32, "ms", R, F::Active(G::TrendInterval),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 134, "active_trend_points", U16, "", R, F::Active(G::TrendPoints),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 135, "active_trend_horizon", F32, "s", R, F::Active(G::TrendHorizon),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 137, "active_friction", U16, "", R, F::Active(G::Friction),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 138, "active_friction_sensitivity", F32, "", R, F::Active(G::FrictionSensitivity),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 140, "active_friction_tau", F32, "s", R, F::Active(G::FrictionTau),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 142, "active_friction_baseline_after", U32, "ms", R, F::Active(G::FrictionBaselineAfter),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 144, "active_friction_baseline_estimates", U32, "", R, F::Active(G::FrictionBaselineEstimates),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 146, "active_friction_band", F32, "", R, F::Active(G::FrictionBand),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 148, "active_friction_deadband", F32, "", R, F::Active(G::FrictionDeadband),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
        e!(Holding, 150, "active_friction_delay", U32, "ms", R, F::Active(G::FrictionDelay),
            "the value the monitor runs (read only); config_ with the same field name is its staged copy"),
    ],
    blocks: &[
        Block {
            table: Table::Holding,
            address: SAMPLES_ADDRESS,
            prefix: "sample",
            count: SAMPLES,
            stride: SAMPLE_STRIDE,
            fields: &SAMPLE_FIELDS,
        },
        Block {
            table: Table::Holding,
            address: SAMPLES_FULL_ADDRESS,
            prefix: "sample_full",
            count: SAMPLES_FULL,
            stride: SAMPLE_FULL_STRIDE,
            fields: &SAMPLE_FULL_FIELDS,
        },
        Block {
            table: Table::Holding,
            address: SCENE_ADDRESS,
            prefix: "scene",
            count: SCENE_WORDS,
            stride: 1,
            fields: &SCENE_FIELDS,
        },
        Block {
            table: Table::Holding,
            address: LINE_ADDRESS,
            prefix: "",
            count: 1,
            stride: 13,
            fields: &LINE_FIELDS,
        },
        Block {
            table: Table::Holding,
            address: SENSORS_ADDRESS,
            prefix: "",
            count: 1,
            stride: 2 * 2 * SENSOR_FIELDS_N as u16,
            fields: &SENSOR_FIELDS,
        },
    ],
};

/// Where the line settings start (holding registers); the addresses from the scene
/// block's end to here are reserved (exception 02).
pub const LINE_ADDRESS: u16 = 460;
const _: () = assert!(SCENE_ADDRESS + SCENE_WORDS <= LINE_ADDRESS);

use super::line::{ANSWER_DELAY_MAX_MS, BAUD_RATES, LineField};
use LineField as N;

#[rustfmt::skip]
static LINE_FIELDS: [Entry; 11] = [
    e!(Holding, 0, "config_unit_id", U16, "", Rw, F::LineStaged(N::UnitId),
        "needs the unlock; staged: the unit id (1 to 247); committed with command 1, then as every line setting answered at the old settings and in force after, kept only when a request addressed to the node at the new settings comes within line_confirm_window"),
    e!(Holding, 1, "config_baud", U32, "bit/s", Rw, F::LineStaged(N::Baud),
        "needs the unlock; staged: the baud rate: 9600, 19200, 38400, 57600 or 115200"),
    e!(Holding, 3, "config_parity", U16, "", Rw, F::LineStaged(N::Parity),
        "needs the unlock; staged: 0 none (two stop bits), 1 odd, 2 even (one stop bit)"),
    e!(Holding, 4, "config_answer_delay", U16, "ms", Rw, F::LineStaged(N::AnswerDelay),
        "needs the unlock; staged: the least time from a request's end to the answer's start (0 to 1000)"),
    e!(Holding, 5, "config_bus_timeout", U16, "s", Rw, F::LineStaged(N::BusTimeout),
        "needs the unlock; staged: the master is lost after this long without a request for this node (event, line_status bit 0, NE 107 out of specification); 0: off"),
    e!(Holding, 6, "active_unit_id", U16, "", R, F::LineActive(N::UnitId),
        "the line setting in force (read only); config_ with the same field name is its staged copy"),
    e!(Holding, 7, "active_baud", U32, "bit/s", R, F::LineActive(N::Baud),
        "the line setting in force (read only); config_ with the same field name is its staged copy"),
    e!(Holding, 9, "active_parity", U16, "", R, F::LineActive(N::Parity),
        "the line setting in force (read only); config_ with the same field name is its staged copy"),
    e!(Holding, 10, "active_answer_delay", U16, "ms", R, F::LineActive(N::AnswerDelay),
        "the line setting in force (read only); config_ with the same field name is its staged copy"),
    e!(Holding, 11, "active_bus_timeout", U16, "s", R, F::LineActive(N::BusTimeout),
        "the line setting in force (read only); config_ with the same field name is its staged copy"),
    e!(Holding, 12, "line_confirm_window", U16, "s", R, F::LineConfirmWindow,
        "how long a change of the line settings waits for a request at them before the node goes back to the settings before it (read only)"),
];

/// Where the sensor settings start (holding registers), after the line settings.
pub const SENSORS_ADDRESS: u16 = LINE_ADDRESS + 13;
const SENSOR_FIELDS_N: usize = SensorField::ALL.len();

use super::sensing::{Bounds, SensorField};
use SensorField as Z;

#[rustfmt::skip]
static SENSOR_FIELDS: [Entry; 2 * SENSOR_FIELDS_N] = [
    e!(Holding, 0, "config_sample_period", U32, "ms", Rw, F::SensorStaged(Z::SamplePeriod),
        "needs the unlock; staged: the sampling period: a sample is taken every this long (10 to 60000 ms); committed with command 1, in force at once"),
    e!(Holding, 2, "config_load_zero", F32, "", Rw, F::SensorStaged(Z::LoadZero),
        "needs the unlock; staged: the load cell's raw ADC code at zero load (counts; the tare); committed with command 1, in force at once"),
    e!(Holding, 4, "config_load_scale", F32, "N", Rw, F::SensorStaged(Z::LoadScale),
        "needs the unlock; staged: the load cell's scale, N per count (not 0; negative for a bridge wired the other way): P = (code - load_zero) * load_scale; committed with command 1, in force at once"),
    e!(Holding, 6, "config_load_capacity", F32, "N", Rw, F::SensorStaged(Z::LoadCapacity),
        "needs the unlock; staged: the load cell's rated capacity: loads beyond +- it are out of range; committed with command 1, in force at once"),
    e!(Holding, 8, "config_probe1_zero", F32, "", Rw, F::SensorStaged(Z::Probe1Zero),
        "needs the unlock; staged: probe 1's raw ADC code at displacement 0 (counts); committed with command 1, in force at once"),
    e!(Holding, 10, "config_probe1_scale", F32, "m", Rw, F::SensorStaged(Z::Probe1Scale),
        "needs the unlock; staged: probe 1's scale, m per count (not 0): d1 = (code - probe1_zero) * probe1_scale; committed with command 1, in force at once"),
    e!(Holding, 12, "config_probe2_zero", F32, "", Rw, F::SensorStaged(Z::Probe2Zero),
        "needs the unlock; staged: probe 2's raw ADC code at displacement 0 (counts); committed with command 1, in force at once"),
    e!(Holding, 14, "config_probe2_scale", F32, "m", Rw, F::SensorStaged(Z::Probe2Scale),
        "needs the unlock; staged: probe 2's scale, m per count (not 0); committed with command 1, in force at once"),
    e!(Holding, 16, "config_probe_span", F32, "m", Rw, F::SensorStaged(Z::ProbeSpan),
        "needs the unlock; staged: the probes' axial span: phi = atan2(d1 - d2 - probe_zero_offset, probe_span); committed with command 1, in force at once"),
    e!(Holding, 18, "config_probe_zero_offset", F32, "m", Rw, F::SensorStaged(Z::ProbeZeroOffset),
        "needs the unlock; staged: d1 - d2 in the known-aligned state; committed with command 1, in force at once"),
    e!(Holding, 20, "config_tacho_pulses_per_rev", U32, "", Rw, F::SensorStaged(Z::PulsesPerRev),
        "needs the unlock; staged: the tachometer's pulses per revolution of the roller it sees; committed with command 1, in force at once"),
    e!(Holding, 22, "config_tacho_radius", F32, "m", Rw, F::SensorStaged(Z::Radius),
        "needs the unlock; staged: that roller's surface radius: V = 2 pi r pulses / (tacho_pulses_per_rev dt); committed with command 1, in force at once"),
    e!(Holding, 24, "config_tacho_max_speed", F32, "m/s", Rw, F::SensorStaged(Z::MaxSpeed),
        "needs the unlock; staged: the highest plausible surface speed: above it the speed is out of range; committed with command 1, in force at once"),
    e!(Holding, 26, "active_sample_period", U32, "ms", R, F::SensorActive(Z::SamplePeriod),
        "the sensor setting in force (read only); config_ with the same field name is its staged copy"),
    e!(Holding, 28, "active_load_zero", F32, "", R, F::SensorActive(Z::LoadZero),
        "the sensor setting in force (read only); config_ with the same field name is its staged copy"),
    e!(Holding, 30, "active_load_scale", F32, "N", R, F::SensorActive(Z::LoadScale),
        "the sensor setting in force (read only); config_ with the same field name is its staged copy"),
    e!(Holding, 32, "active_load_capacity", F32, "N", R, F::SensorActive(Z::LoadCapacity),
        "the sensor setting in force (read only); config_ with the same field name is its staged copy"),
    e!(Holding, 34, "active_probe1_zero", F32, "", R, F::SensorActive(Z::Probe1Zero),
        "the sensor setting in force (read only); config_ with the same field name is its staged copy"),
    e!(Holding, 36, "active_probe1_scale", F32, "m", R, F::SensorActive(Z::Probe1Scale),
        "the sensor setting in force (read only); config_ with the same field name is its staged copy"),
    e!(Holding, 38, "active_probe2_zero", F32, "", R, F::SensorActive(Z::Probe2Zero),
        "the sensor setting in force (read only); config_ with the same field name is its staged copy"),
    e!(Holding, 40, "active_probe2_scale", F32, "m", R, F::SensorActive(Z::Probe2Scale),
        "the sensor setting in force (read only); config_ with the same field name is its staged copy"),
    e!(Holding, 42, "active_probe_span", F32, "m", R, F::SensorActive(Z::ProbeSpan),
        "the sensor setting in force (read only); config_ with the same field name is its staged copy"),
    e!(Holding, 44, "active_probe_zero_offset", F32, "m", R, F::SensorActive(Z::ProbeZeroOffset),
        "the sensor setting in force (read only); config_ with the same field name is its staged copy"),
    e!(Holding, 46, "active_tacho_pulses_per_rev", U32, "", R, F::SensorActive(Z::PulsesPerRev),
        "the sensor setting in force (read only); config_ with the same field name is its staged copy"),
    e!(Holding, 48, "active_tacho_radius", F32, "m", R, F::SensorActive(Z::Radius),
        "the sensor setting in force (read only); config_ with the same field name is its staged copy"),
    e!(Holding, 50, "active_tacho_max_speed", F32, "m/s", R, F::SensorActive(Z::MaxSpeed),
        "the sensor setting in force (read only); config_ with the same field name is its staged copy"),
];

/// The four tables in the CSV's order.
pub static MAP: [&TableMap; 4] = [&COILS, &DISCRETES, &INPUTS, &HOLDINGS];

impl TableMap {
    /// The map of `table`.
    pub fn of(table: Table) -> &'static TableMap {
        match table {
            Table::Coil => &COILS,
            Table::Discrete => &DISCRETES,
            Table::Input => &INPUTS,
            Table::Holding => &HOLDINGS,
        }
    }

    /// The address after the single entries.
    pub const fn entries_end(&self) -> u16 {
        match self.entries.last() {
            Some(e) => e.end(),
            None => 0,
        }
    }

    /// The address after the table.
    pub const fn end(&self) -> u16 {
        match self.blocks.last() {
            Some(b) => b.end(),
            None => self.entries_end(),
        }
    }

    /// The addresses the table holds, run by run in order: the single entries from 0,
    /// then each block. A read within a run is answered; one that takes in the reserved
    /// run between two blocks is refused (exception 02).
    pub fn runs(&self) -> impl Iterator<Item = core::ops::Range<u16>> + '_ {
        core::iter::once(0..self.entries_end())
            .chain(self.blocks.iter().map(|b| b.address..b.end()))
    }
}

// What the server reads and writes by: the tables above without their text.
//
// The server answers from the tables below, made from the ones above at compile time
// and holding no `name`, `unit`, `scale` or `description`. Only `registers_csv`, run on
// a PC, reads the tables above, so that a node's image links none of their text (about
// 6 KB) and none of their 40-byte entries.

/// An entry as the server holds it: where it is, its type, whether a master may write
/// it, and what it holds. Five bytes (bytes only: no padding), where the entry's
/// address and width as u16 made eight: the single entries end below address 256 and
/// a record is shorter (checked at compile time).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Slot {
    /// The 0-based address (in a block: the offset in the record).
    address: u8,
    /// Registers the value takes ([`Type::words`]).
    words: u8,
    pub access: Access,
    pub field: Field,
}

impl Slot {
    const fn of(e: &Entry) -> Slot {
        assert!(e.end() <= 256, "a served entry's address fits a byte");
        Slot {
            address: e.address as u8,
            words: e.ty.words() as u8,
            access: e.access,
            field: e.field,
        }
    }

    /// The 0-based address (in a block: the offset in the record).
    #[inline(always)]
    pub const fn address(&self) -> u16 {
        self.address as u16
    }

    /// Registers the value takes ([`Type::words`]).
    #[inline(always)]
    pub const fn words(&self) -> u16 {
        self.words as u16
    }

    /// The address after the value.
    pub const fn end(&self) -> u16 {
        self.address() + self.words()
    }
}

/// A [`Block`] as the server holds it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SlotBlock {
    pub address: u16,
    pub count: u16,
    pub stride: u16,
    pub fields: &'static [Slot],
}

impl SlotBlock {
    /// `b` with `fields`, which must be `b`'s fields as slots (checked at compile time).
    const fn of(b: &Block, fields: &'static [Slot]) -> SlotBlock {
        assert!(
            fields.len() == b.fields.len(),
            "a block's slots are its fields"
        );
        SlotBlock {
            address: b.address,
            count: b.count,
            stride: b.stride,
            fields,
        }
    }

    /// The address after the block.
    pub const fn end(&self) -> u16 {
        self.address
            .saturating_add(self.count.saturating_mul(self.stride))
    }
}

/// A [`TableMap`] as the server holds it, with the index of its single entries by
/// address and its ends.
#[derive(Debug)]
pub(crate) struct Served {
    pub entries: &'static [Slot],
    pub blocks: &'static [SlotBlock],
    /// The single entries' index by address.
    index: &'static [u8],
    /// The address after the single entries.
    pub entries_end: u16,
    /// The address after the table.
    pub end: u16,
    /// The reserved addresses between two blocks (`end..end`: none).
    pub hole: (u16, u16),
}

/// The reserved addresses between `map`'s blocks: at most one run (checked at compile
/// time); `(end, end)` for none.
const fn hole(map: &TableMap) -> (u16, u16) {
    let mut found = (map.end(), map.end());
    let mut prev = map.entries_end();
    let mut i = 0;
    while i < map.blocks.len() {
        let b = &map.blocks[i];
        assert!(b.address >= prev, "blocks in order, without an overlap");
        if b.address > prev {
            assert!(found.0 == map.end(), "one reserved run at most");
            found = (prev, b.address);
        }
        prev = b.end();
        i += 1;
    }
    found
}

/// The entries of a table as slots.
const fn slots<const N: usize>(entries: &[Entry]) -> [Slot; N] {
    let mut out = [Slot {
        address: 0,
        words: 1,
        access: Access::R,
        field: Field::Acknowledge,
    }; N];
    let mut i = 0;
    while i < N {
        out[i] = Slot::of(&entries[i]);
        i += 1;
    }
    out
}

/// The index of the single entry that holds each address of `entries` (sorted,
/// without a hole from 0), formed at compile time: a read finds its first value by one
/// load, not a search.
const fn index<const N: usize>(entries: &[Entry]) -> [u8; N] {
    let mut out = [0u8; N];
    let mut i = 0;
    while i < entries.len() {
        let e = &entries[i];
        let mut a = e.address as usize;
        let end = e.end() as usize;
        while a < end && a < N {
            out[a] = i as u8;
            a += 1;
        }
        i += 1;
    }
    out
}

/// `map`'s ends: its blocks must be `blocks` (checked at compile time).
const fn ends(map: &TableMap, blocks: &[SlotBlock]) -> (u16, u16) {
    assert!(
        blocks.len() == map.blocks.len(),
        "a table's served blocks are its blocks"
    );
    (map.entries_end(), map.end())
}

static SAMPLE_SLOTS: [Slot; SAMPLE_FIELDS.len()] = slots(&SAMPLE_FIELDS);
static SAMPLE_FULL_SLOTS: [Slot; SAMPLE_FULL_FIELDS.len()] = slots(&SAMPLE_FULL_FIELDS);
static EVENT_FIELD_SLOTS: [Slot; EVENT_FIELDS.len()] = slots(&EVENT_FIELDS);
static SCENE_SLOTS: [Slot; SCENE_FIELDS.len()] = slots(&SCENE_FIELDS);
static LINE_SLOTS: [Slot; LINE_FIELDS.len()] = slots(&LINE_FIELDS);
static SENSOR_SLOTS: [Slot; SENSOR_FIELDS.len()] = slots(&SENSOR_FIELDS);
static LINE_INPUT_SLOTS: [Slot; LINE_INPUT_FIELDS.len()] = slots(&LINE_INPUT_FIELDS);

/// One table as the server holds it: `$map`'s entries as slots, its index, its blocks
/// with their fields' slots.
macro_rules! served {
    ($map:ident, [$($block:expr),*]) => {{
        const N: usize = $map.entries.len();
        static ENTRIES: [Slot; N] = slots($map.entries);
        static INDEX: [u8; $map.entries_end() as usize] = index($map.entries);
        const BLOCKS: &[SlotBlock] = &[$($block),*];
        const ENDS: (u16, u16) = ends(&$map, BLOCKS);
        Served {
            entries: &ENTRIES,
            blocks: BLOCKS,
            index: &INDEX,
            entries_end: ENDS.0,
            end: ENDS.1,
            hole: hole(&$map),
        }
    }};
}

static COILS_SERVED: Served = served!(COILS, []);
static DISCRETES_SERVED: Served = served!(DISCRETES, []);
static INPUTS_SERVED: Served = served!(
    INPUTS,
    [
        SlotBlock::of(&INPUTS.blocks[0], &EVENT_FIELD_SLOTS),
        SlotBlock::of(&INPUTS.blocks[1], &LINE_INPUT_SLOTS)
    ]
);
static HOLDINGS_SERVED: Served = served!(
    HOLDINGS,
    [
        SlotBlock::of(&HOLDINGS.blocks[0], &SAMPLE_SLOTS),
        SlotBlock::of(&HOLDINGS.blocks[1], &SAMPLE_FULL_SLOTS),
        SlotBlock::of(&HOLDINGS.blocks[2], &SCENE_SLOTS),
        SlotBlock::of(&HOLDINGS.blocks[3], &LINE_SLOTS),
        SlotBlock::of(&HOLDINGS.blocks[4], &SENSOR_SLOTS)
    ]
);

impl Served {
    /// The served map of `table`.
    pub(crate) fn of(table: Table) -> &'static Served {
        match table {
            Table::Coil => &COILS_SERVED,
            Table::Discrete => &DISCRETES_SERVED,
            Table::Input => &INPUTS_SERVED,
            Table::Holding => &HOLDINGS_SERVED,
        }
    }

    /// The single entry that holds `address` (its index) and the word of it, if a
    /// single entry does.
    pub(crate) fn single(&self, address: u16) -> Option<(usize, u16)> {
        let i = usize::from(*self.index.get(usize::from(address))?);
        let entry = self.entries.get(i)?;
        Some((i, address.checked_sub(entry.address())?))
    }

    /// The entry that holds `address`: the entry, the record's index (0 for a single
    /// entry), and the register's word within the value (0 high, 1 low).
    pub(crate) fn locate(&self, address: u16) -> Option<Located> {
        if let Some((index, word)) = self.single(address) {
            return Some(Located {
                entry: self.entries.get(index)?,
                record: 0,
                word,
                block: None,
                index,
            });
        }
        let b = self.blocks.iter().position(|b| address < b.end())?;
        let block = self.blocks.get(b)?;
        let offset = address.checked_sub(block.address)?;
        let (record, at) = div_rem(offset, block.stride)?;
        let index = block.fields.partition_point(|e| e.end() <= at);
        let entry = block.fields.get(index)?;
        Some(Located {
            entry,
            record,
            word: at.checked_sub(entry.address())?,
            block: Some(b),
            index,
        })
    }
}

/// A bound of a [`Domain::Finite`] as the CSV writes it: a whole number as such, the
/// largest f32 in the shortest exponent form that reads back to it.
struct Bound(f32);

impl fmt::Display for Bound {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let whole = self.0 as i32;
        if whole as f32 == self.0 && -1e9 < self.0 && self.0 < 1e9 {
            write!(f, "{whole}")
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

/// An address located in the map.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Located {
    pub entry: &'static Slot,
    pub record: u16,
    pub word: u16,
    /// The block's index in the table, `None` for a single entry.
    pub block: Option<usize>,
    /// The entry's index in the single entries or the block's fields.
    pub index: usize,
}

/// Writes the map as CSV with the header
/// `table,address,name,type,scale,unit,access,description,min,max`: one row per value,
/// a block's records expanded (`event_0_seq`, ...); `min` and `max` the values a
/// master may write ([`Entry::domain`]; empty for a read-only value, and for an `f32`
/// that takes any value). `docs/modbus/registers.csv` is this
/// output (`cargo run --example modbus_registers --features modbus > docs/modbus/registers.csv`).
pub fn registers_csv(out: &mut impl fmt::Write) -> fmt::Result {
    writeln!(
        out,
        "table,address,name,type,scale,unit,access,description,min,max"
    )?;
    let row = |out: &mut dyn fmt::Write, e: &Entry, address: u16, prefix: Option<(&str, u16)>| {
        write!(out, "{},{},", e.table.as_str(), address)?;
        if let Some((p, i)) = prefix {
            write!(out, "{p}_{i}_")?;
        }
        // Descriptions hold commas: quoted, as CSV quotes (they hold no quote).
        write!(
            out,
            "{},{},{},{},{},\"{}\",",
            e.name,
            e.ty.as_str(),
            e.scale,
            e.unit,
            e.access.as_str(),
            e.description
        )?;
        match e.domain() {
            Domain::ReadOnly | Domain::Any => writeln!(out, ","),
            Domain::Whole { min, max } => writeln!(out, "{min},{max}"),
            Domain::Finite { min, max } => writeln!(out, "{},{}", Bound(min), Bound(max)),
        }
    };
    for table in MAP {
        for e in table.entries {
            row(out, e, e.address, None)?;
        }
        for b in table.blocks {
            for i in 0..b.count {
                for e in b.fields {
                    row(
                        out,
                        e,
                        b.address + i * b.stride + e.address,
                        Some((b.prefix, i)).filter(|(p, _)| !p.is_empty()),
                    )?;
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every table: entries from 0 without a hole or an overlap, blocks after them
    /// likewise but for the holding registers' one reserved run before the line
    /// settings, each block's fields filling its stride.
    #[test]
    fn tables_have_no_hole() {
        for t in MAP {
            let mut next = 0;
            for e in t.entries {
                assert_eq!(e.address, next, "{}", e.name);
                next += e.ty.words();
                if matches!(e.table, Table::Coil | Table::Discrete) {
                    assert_eq!(e.ty, Type::U16, "{}", e.name);
                }
            }
            for b in t.blocks {
                if b.address == LINE_ADDRESS && b.table == Table::Holding {
                    assert!(next <= LINE_ADDRESS);
                    next = LINE_ADDRESS;
                }
                assert_eq!(b.address, next, "{}", b.prefix);
                assert!(!b.prefix.is_empty() || b.count == 1);
                let mut at = 0;
                for e in b.fields {
                    assert_eq!((e.address, e.table), (at, b.table), "{}", e.name);
                    at += e.ty.words();
                }
                assert_eq!(at, b.stride, "{}", b.prefix);
                next = b.end();
            }
            assert_eq!(t.end(), next);
        }
    }

    /// The read of holding registers below the line settings writes the blocks' words
    /// as 0 without asking each field (`Core::fill`): they are all external samples'
    /// fields or the scene's, which read 0.
    #[test]
    fn holding_blocks_read_zero() {
        for b in HOLDINGS.blocks.iter().filter(|b| b.address < LINE_ADDRESS) {
            for e in b.fields {
                assert!(
                    matches!(e.field, Field::Sample(_) | Field::Commission(Reg::Scene)),
                    "{}",
                    e.name
                );
            }
        }
    }

    /// The served tables are the documented ones, slot for slot.
    #[test]
    fn served_tables_are_the_maps() {
        for (table, t) in [Table::Coil, Table::Discrete, Table::Input, Table::Holding]
            .into_iter()
            .zip(MAP)
        {
            let s = Served::of(table);
            let slots: std::vec::Vec<Slot> = t.entries.iter().map(Slot::of).collect();
            assert_eq!(s.entries, &slots[..]);
            assert_eq!((s.entries_end, s.end), (t.entries_end(), t.end()));
            assert_eq!(s.blocks.len(), t.blocks.len());
            for (sb, b) in s.blocks.iter().zip(t.blocks) {
                assert_eq!(
                    (sb.address, sb.count, sb.stride),
                    (b.address, b.count, b.stride)
                );
                let slots: std::vec::Vec<Slot> = b.fields.iter().map(Slot::of).collect();
                assert_eq!(sb.fields, &slots[..], "{}", b.prefix);
            }
        }
    }

    #[test]
    fn every_address_locates_its_entry() {
        for (table, t) in [Table::Coil, Table::Discrete, Table::Input, Table::Holding]
            .into_iter()
            .zip(MAP)
        {
            let s = Served::of(table);
            for a in 0..s.end {
                if (s.hole.0..s.hole.1).contains(&a) {
                    assert!(s.locate(a).is_none(), "{a} reserved");
                    continue;
                }
                let l = s.locate(a).expect("inside the table");
                assert!(l.word < l.entry.words());
            }
            assert!(s.locate(s.end).is_none());
            // The runs hold every address but the reserved ones.
            let held: std::vec::Vec<u16> = t.runs().flatten().collect();
            let located: std::vec::Vec<u16> =
                (0..s.end).filter(|&a| s.locate(a).is_some()).collect();
            assert_eq!(held, located);
            // The bit tables: one entry a bit, in address order, without blocks (a read
            // of bits takes the entries from its start, `Core::read_bits`).
            if matches!(table, Table::Coil | Table::Discrete) {
                assert!(t.blocks.is_empty());
                for (a, e) in (0..).zip(s.entries) {
                    assert_eq!((e.address(), e.words()), (a, 1));
                }
            }
        }
        let l = Served::of(Table::Input)
            .locate(EVENT_SLOTS_ADDRESS + EVENT_STRIDE + 12)
            .unwrap();
        assert_eq!(
            (l.entry.field, l.record, l.word),
            (Field::Event(EventField::Value), 1, 1)
        );
    }
}
