//! What the server holds besides the framer ([`Core`]): the monitor, the alarms'
//! annunciation, the event window, the commissioning state, the counters and the
//! response being built; and the path of a sample through them. The answers to
//! requests are `pdu.rs`'s, the registers' values `values.rs`'s.

use super::config::Commissioning;
use super::events::{EventWindow, StorageStatus};
use super::ident::Identification;
use super::line::{Line, Raised};
use super::rtu::{ADU_MAX, FramingCounters};
use super::sensing::Sensing;
use crate::Estimator;
use crate::monitor::annunciation::{AlarmSet, Annunciator};
use crate::monitor::{Monitor, RiskState, Sample};

/// What the server has counted (besides the monitor's own statistics).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Counters {
    /// The framer's counts: frames with a valid CRC, bytes discarded.
    pub framing: FramingCounters,
    /// Requests for this unit or broadcast.
    pub server_messages: u32,
    /// Exception responses sent.
    pub exceptions: u32,
    /// Responses replaced by the answer to a later request before they were sent.
    pub responses_overwritten: u32,
    /// External samples taken from the bus and processed.
    pub external_accepted: u32,
    /// Writes of external samples refused (none of their samples processed).
    pub external_refused: u32,
}

/// How a sample reaches the monitor: `Monitor::process`, or
/// `Monitor::process_with_friction` (f32 scenes).
pub(super) type Step<E> = fn(&mut Monitor<E>, Sample) -> RiskState;

/// Everything but the framer (whose buffer holds the request being answered).
/// `repr(C)`: what every request touches first, the buffers and the monitor after.
#[derive(Debug, Clone)]
#[repr(C)]
pub(super) struct Core<E> {
    /// The response's length; 0: none due.
    pub(super) response_len: usize,
    /// The response waits for the application's storage ([`Server::stored`](super::Server::stored)).
    pub(super) held: bool,
    pub(super) unit: u8,
    pub(super) step: Step<E>,
    pub(super) ident: Identification,
    pub(super) model_name: &'static str,
    pub(super) annunciator: Annunciator,
    pub(super) events: EventWindow,
    pub(super) external: bool,
    /// [`ServerConfig::scene_required`](super::ServerConfig::scene_required).
    pub(super) scene_required: bool,
    /// The last sample's own timestamp.
    pub(super) last_time_ms: u32,
    pub(super) counters: Counters,
    /// The last acknowledgement a master wrote (`event_ack`).
    pub(super) ack: Option<u32>,
    pub(super) storage: StorageStatus,
    pub(super) response: [u8; ADU_MAX],
    pub(super) monitor: Monitor<E>,
    /// The staged configuration, the unlock, the commits.
    pub(super) commissioning: Commissioning<E>,
    /// The line settings: staged, in force, kept; the master's supervision.
    pub(super) line: Line,
    /// The sampling period and the sensors' calibration: staged, in force.
    pub(super) sensing: Sensing,
}

impl<E: Estimator> Core<E> {
    pub(super) fn process(&mut self, sample: Sample) -> RiskState {
        let state = (self.step)(&mut self.monitor, sample);
        self.last_time_ms = sample.time_ms;
        self.drain();
        state
    }

    /// An event of the link, raised through the monitor (numbered with its own).
    pub(super) fn raise(&mut self, raised: Raised) {
        use crate::monitor::FieldbusEvent as B;
        let event = match raised {
            Raised::Nothing => return,
            Raised::Reverted => B::LineReverted,
            Raised::MasterLost => B::MasterLost,
            Raised::MasterBack => B::MasterBack,
        };
        self.unit = self.line.active().unit_id;
        self.monitor.raise_fieldbus(event);
        self.drain();
    }

    /// After a request for this node (`addressed`) or a broadcast was handled: the
    /// master is back, a change is confirmed (and kept, as a commit is). A poll's case
    /// (nothing of it waits) costs a store and two tests; the rest is out of line.
    #[inline(always)]
    pub(super) fn line_request(&mut self, addressed: bool) {
        if !self.line.heard() {
            self.line_waiting(addressed);
        }
    }

    #[cold]
    #[inline(never)]
    fn line_waiting(&mut self, addressed: bool) {
        let (confirmed, raised) = self.line.request(addressed);
        if confirmed {
            self.commissioning.switched();
        }
        self.raise(raised);
    }

    /// The answer was sent (or none is due): a committed change takes effect.
    pub(super) fn line_sent(&mut self) {
        if self.line.sent() {
            self.unit = self.line.active().unit_id;
        }
    }

    /// The monitor's queued events into the window (unless the application takes
    /// them: [`Server::store_events`](super::Server::store_events)); the alarms from its state.
    pub(super) fn drain(&mut self) {
        // Every queued event is numbered already: `next` is after all of them.
        let next = self.monitor.next_event_seq();
        self.events.follow(next);
        while !self.events.stored
            && let Some(e) = self.monitor.pop_event()
        {
            self.events.push(e, next);
        }
        self.annunciator.update(AlarmSet::of(&self.monitor));
    }
}
