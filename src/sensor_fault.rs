//! Which sensor failed and why: shared by the sensors (feature `sensors`), which find
//! the faults, and the condition monitor, which reports them (always compiled, so
//! that a monitor fed by other drivers names the sensor the same way).

use core::fmt;

/// Which sensor of a node a fault or a reading belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SensorId {
    /// The load cell (load P).
    Load,
    /// Displacement probe 1 (displacement d1, the first of phi = atan2(d1 - d2, span)).
    Probe1,
    /// Displacement probe 2 (displacement d2).
    Probe2,
    /// The tachometer or encoder (rolling speed V).
    Speed,
}

impl SensorId {
    /// Every sensor, in the order of [`SensorId::index`].
    pub const ALL: [SensorId; 4] = [
        SensorId::Load,
        SensorId::Probe1,
        SensorId::Probe2,
        SensorId::Speed,
    ];

    /// The sensor's index in per-sensor arrays (0 to 3, the order of
    /// [`SensorId::ALL`]).
    pub const fn index(self) -> usize {
        self as usize
    }

    /// A short name for logs and event records.
    pub const fn name(self) -> &'static str {
        match self {
            SensorId::Load => "load",
            SensorId::Probe1 => "probe1",
            SensorId::Probe2 => "probe2",
            SensorId::Speed => "speed",
        }
    }
}

/// What is wrong with a sensor's reading.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum FaultKind {
    /// No conversion was ready within the bounded wait: the chip or probe is unplugged
    /// or unpowered.
    Disconnected,
    /// The bus or a pin reported an error.
    Bus,
    /// The raw code is at (or beyond) a rail of the ADC: the input is over range, a wire
    /// is broken, or the bus reads all ones.
    Saturated,
    /// The same raw code several times in a row where noise is expected: a frozen ADC, a
    /// bus that reads all zeros or all ones, a shorted input.
    Stuck,
    /// The raw code moved by more than a real signal can between two readings (a value
    /// that jumps by the full scale).
    Jump,
    /// The calibrated value is outside the sensor's calibrated physical range (or is not
    /// finite).
    OutOfRange,
}

impl FaultKind {
    /// Every kind, in the order of the sensors' fault counters (`sensors::SensorFaultCounts`).
    pub const ALL: [FaultKind; 6] = [
        FaultKind::Disconnected,
        FaultKind::Bus,
        FaultKind::Saturated,
        FaultKind::Stuck,
        FaultKind::Jump,
        FaultKind::OutOfRange,
    ];

    /// The reason, in words, for logs and event records.
    pub const fn reason(self) -> &'static str {
        match self {
            FaultKind::Disconnected => "disconnected: no data ready within the timeout",
            FaultKind::Bus => "bus or pin error",
            FaultKind::Saturated => "saturated: raw value at the ADC's rail",
            FaultKind::Stuck => "stuck: identical raw values where noise is expected",
            FaultKind::Jump => "jump: raw value moved by more than a signal can",
            FaultKind::OutOfRange => "out of the calibrated physical range",
        }
    }
}

/// A sensor fault: the sensor and the kind. A condition monitor maps it to its
/// sensor-fault state and an event naming the sensor; it is never a slip alarm.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SensorFault {
    /// The faulty sensor.
    pub sensor: SensorId,
    /// What is wrong.
    pub kind: FaultKind,
}

impl fmt::Display for SensorFault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.sensor.name(), self.kind.reason())
    }
}

impl core::error::Error for SensorFault {}
