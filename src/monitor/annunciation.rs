//! Annunciation (ISA-18.2 / IEC 62682): the monitor's states as the four alarms an
//! operator sees, each with its acknowledgement and, when configured, latching. A
//! stage above the risk states: it reads the monitor only through its public
//! accessors, after each sample.
//!
//! Per alarm: *active* is the condition now; *unacknowledged* is set when the
//! condition becomes active and cleared only by an acknowledgement (so an alarm that
//! returned to normal unacknowledged stays visible as such); *indicated* is what an
//! annunciator shows: the condition, or for a **latching** alarm also the time after
//! it cleared until it is acknowledged. An acknowledgement while the condition holds
//! acknowledges it; the indication then ends with the condition.

use super::order::{ge, nan};
use super::{Monitor, RiskState};
use crate::Estimator;

/// A set of the four alarms, one bit each (the bit order is the Modbus map's).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AlarmSet(u8);

impl AlarmSet {
    /// No alarm.
    pub const NONE: AlarmSet = AlarmSet(0);
    /// The warning: the state is `Microslip` or `GrossSlip` (the slip at or above the
    /// warning level; like a high alarm, it stays active under the high-high one).
    pub const WARNING: AlarmSet = AlarmSet(1);
    /// The alarm: the state is `GrossSlip`.
    pub const ALARM: AlarmSet = AlarmSet(2);
    /// The sensors are not trusted: the state is `SensorFault`.
    pub const SENSOR_FAULT: AlarmSet = AlarmSet(4);
    /// Gross slip approaches: the time to critical is below the configured horizon
    /// while the contact still sticks (`Normal` or `Microslip`).
    pub const APPROACHING: AlarmSet = AlarmSet(8);
    /// All four.
    pub const ALL: AlarmSet = AlarmSet(15);
    /// Each alarm, in bit order.
    pub const EACH: [AlarmSet; 4] = [
        AlarmSet::WARNING,
        AlarmSet::ALARM,
        AlarmSet::SENSOR_FAULT,
        AlarmSet::APPROACHING,
    ];

    /// The set of bits `bits` (bits above the fourth are ignored).
    pub const fn from_bits(bits: u8) -> Self {
        AlarmSet(bits & 15)
    }

    /// The bits: warning 0, alarm 1, sensor fault 2, approaching 3.
    pub const fn bits(self) -> u8 {
        self.0
    }

    /// Whether every alarm of `other` is in the set.
    pub const fn contains(self, other: AlarmSet) -> bool {
        self.0 & other.0 == other.0
    }

    /// Whether the set is empty.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Both sets together.
    pub const fn union(self, other: AlarmSet) -> Self {
        AlarmSet(self.0 | other.0)
    }

    /// The set without the alarms of `other`.
    pub const fn without(self, other: AlarmSet) -> Self {
        AlarmSet(self.0 & !other.0)
    }

    /// The set with `other` in it (`on`) or out of it.
    pub const fn with(self, other: AlarmSet, on: bool) -> Self {
        if on {
            self.union(other)
        } else {
            self.without(other)
        }
    }

    /// The alarms a monitor's state and trend raise now.
    pub fn of<E: Estimator>(monitor: &Monitor<E>) -> Self {
        let state = monitor.state();
        let warning = matches!(state, RiskState::Microslip | RiskState::GrossSlip);
        let sticking = matches!(state, RiskState::Normal | RiskState::Microslip);
        let approaching = sticking
            && match (monitor.time_to_critical(), monitor.config().trend) {
                // t < horizon, by the bits where floats are soft (`order`): no
                // soft-float comparison linked for it (the horizon is validated finite).
                (Some(t), Some(trend)) => !nan(t) && !ge(t, trend.horizon_s),
                _ => false,
            };
        AlarmSet::NONE
            .with(AlarmSet::WARNING, warning)
            .with(AlarmSet::ALARM, state == RiskState::GrossSlip)
            .with(AlarmSet::SENSOR_FAULT, state == RiskState::SensorFault)
            .with(AlarmSet::APPROACHING, approaching)
    }
}

/// The four alarms' annunciation: conditions, acknowledgements, latching.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Annunciator {
    latching: AlarmSet,
    active: AlarmSet,
    unacknowledged: AlarmSet,
}

impl Annunciator {
    /// No alarm active or unacknowledged; the alarms of `latching` latch.
    pub const fn new(latching: AlarmSet) -> Self {
        Annunciator {
            latching,
            active: AlarmSet::NONE,
            unacknowledged: AlarmSet::NONE,
        }
    }

    /// Takes the conditions now (after each sample): an alarm that becomes active is
    /// unacknowledged until acknowledged.
    pub fn update(&mut self, active: AlarmSet) {
        let raised = active.without(self.active);
        self.unacknowledged = self.unacknowledged.union(raised);
        self.active = active;
    }

    /// Acknowledges the alarms of `which`: they are no longer unacknowledged, and a
    /// latched one whose condition cleared is no longer indicated.
    pub fn acknowledge(&mut self, which: AlarmSet) {
        self.unacknowledged = self.unacknowledged.without(which);
    }

    /// Sets which alarms latch (from now on; an alarm already unacknowledged and
    /// cleared is indicated again if it now latches).
    pub fn set_latching(&mut self, latching: AlarmSet) {
        self.latching = latching;
    }

    /// The alarms that latch.
    pub const fn latching(&self) -> AlarmSet {
        self.latching
    }

    /// The alarms whose condition holds now.
    pub const fn active(&self) -> AlarmSet {
        self.active
    }

    /// The alarms raised and not yet acknowledged (active or returned to normal).
    pub const fn unacknowledged(&self) -> AlarmSet {
        self.unacknowledged
    }

    /// What an annunciator shows: the active alarms and the latching ones that
    /// cleared unacknowledged.
    pub const fn indicated(&self) -> AlarmSet {
        self.active
            .union(AlarmSet(self.unacknowledged.0 & self.latching.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Over the built-in scenario, which raises `Approaching` (tests/monitor.rs), the
    /// approaching alarm is the float comparison of the time to critical with the
    /// horizon while the contact sticks, at every sample.
    #[test]
    fn approaching_is_the_time_to_critical_below_the_horizon() {
        use crate::monitor::{Config, scenario};
        let core = scenario::estimator::<crate::float::Auto>().unwrap();
        let mut m = Monitor::new(core, Config::default()).unwrap();
        let horizon = Config::default().trend.unwrap().horizon_s;
        let mut raised = 0;
        for s in scenario::Scenario::new() {
            m.process(s);
            let sticking = matches!(m.state(), RiskState::Normal | RiskState::Microslip);
            let below = m.time_to_critical().is_some_and(|t| t < horizon);
            let approaching = AlarmSet::of(&m).contains(AlarmSet::APPROACHING);
            assert_eq!(approaching, sticking && below, "at {} ms", s.time_ms);
            raised += usize::from(approaching);
        }
        assert!(raised > 0);
    }

    #[test]
    fn acknowledgement_and_latching() {
        let w = AlarmSet::WARNING;
        let mut a = Annunciator::new(AlarmSet::NONE);
        a.update(w);
        assert_eq!((a.indicated(), a.unacknowledged()), (w, w));
        // Returned to normal unacknowledged: not indicated (not latching), still
        // unacknowledged.
        a.update(AlarmSet::NONE);
        assert_eq!((a.indicated(), a.unacknowledged()), (AlarmSet::NONE, w));
        a.acknowledge(AlarmSet::ALL);
        assert_eq!(a.unacknowledged(), AlarmSet::NONE);

        // Latching: indicated after it cleared, until acknowledged.
        let mut a = Annunciator::new(w);
        a.update(w);
        a.update(AlarmSet::NONE);
        assert_eq!(a.indicated(), w);
        a.acknowledge(AlarmSet::ALARM);
        assert_eq!(a.indicated(), w, "acknowledging another alarm keeps it");
        a.acknowledge(w);
        assert_eq!(a.indicated(), AlarmSet::NONE);

        // Acknowledged while active: the indication ends with the condition; a new
        // rising edge is unacknowledged again.
        a.update(w);
        a.acknowledge(w);
        assert_eq!((a.indicated(), a.unacknowledged()), (w, AlarmSet::NONE));
        a.update(AlarmSet::NONE);
        assert_eq!(a.indicated(), AlarmSet::NONE);
        a.update(w);
        assert_eq!(a.unacknowledged(), w);
    }

    #[test]
    fn set_operations() {
        let s = AlarmSet::WARNING.union(AlarmSet::APPROACHING);
        assert_eq!(s.bits(), 9);
        assert!(s.contains(AlarmSet::APPROACHING) && !s.contains(AlarmSet::ALARM));
        assert_eq!(AlarmSet::from_bits(0xff), AlarmSet::ALL);
        assert!(s.without(s).is_empty());
    }
}
