//! The event window: the monitor's events kept for the bus, read from a sequence
//! number the master chooses, with what it can no longer read counted.

use crate::monitor::Event;
use heapless::Deque;

/// Events the window holds (the monitor's queue is drained into it after each
/// sample).
pub const EVENT_WINDOW: usize = 8;

/// Numbers a window can tell apart: at most 2^31 back from the next one (modulo 2^32,
/// a number further back is also one ahead).
const SPAN_MAX: u32 = 1 << 31;

/// The window.
///
/// Sequence numbers count modulo 2^32, so that two numbers alone do not say which
/// came first. Every comparison here is made by the distance back from the monitor's
/// next number, within the numbers given so far ([`span`](Self::span): from `base`,
/// the oldest the window knows of). A number never given, ahead of the next one or
/// older than any given, has no place among them: as `event_from` it means "after
/// the newest", and as `event_ack` it is refused.
#[derive(Debug, Clone)]
pub(crate) struct EventWindow {
    events: Deque<Event, EVENT_WINDOW>,
    /// The first sequence number a master wants (holding register `event_from`).
    pub from: u32,
    /// The oldest number known to have been given: 0, where the monitor's numbering
    /// starts, until a number before it (across a wrap) is seen; kept within
    /// [`SPAN_MAX`] of the next number.
    base: u32,
    /// Events dropped from the full window before the master read them.
    pub dropped: u32,
    /// Store-and-forward: the application hands the events in, and the window never
    /// drops one the master has not read ([`offer`](Self::offer)).
    pub stored: bool,
    /// Store-and-forward: the next event the window wants from the application's
    /// store (the window fell behind: it was full of unread events, or a reset left
    /// events on flash). `None`: it takes new events as they come.
    pub backlog: Option<u32>,
}

impl EventWindow {
    /// The window of a monitor whose next event is `next`, its events from `from`
    /// (its queued events) still to come.
    pub(crate) fn new(from: u32, next: u32) -> Self {
        let mut w = EventWindow {
            events: Deque::new(),
            from,
            base: 0,
            dropped: 0,
            stored: false,
            backlog: None,
        };
        w.know(from, next);
        w
    }

    /// How many numbers before `next` were given, as far as the window can tell (at
    /// most [`SPAN_MAX`] once `base` followed `next`).
    fn span(&self, next: u32) -> u32 {
        next.wrapping_sub(self.base)
    }

    /// `base` follows `next` within [`SPAN_MAX`]: called whenever new events came.
    pub(crate) fn follow(&mut self, next: u32) {
        if self.span(next) > SPAN_MAX {
            self.base = next.wrapping_sub(SPAN_MAX);
        }
    }

    /// Whether `seq` was given before `next` (an event was numbered so): at most
    /// [`span`](Self::span) numbers back from `next`.
    pub(crate) fn given(&self, seq: u32, next: u32) -> bool {
        next.wrapping_sub(seq).wrapping_sub(1) < self.span(next)
    }

    /// `seq` was given, or is `next`: the window's numbers reach back to it (a number
    /// from before a wrap, restored at start-up); and `base` follows `next` within
    /// [`SPAN_MAX`]. Called whenever `next` may have moved.
    pub(crate) fn know(&mut self, seq: u32, next: u32) {
        if next.wrapping_sub(seq) > self.span(next) {
            self.base = seq;
        }
        self.follow(next);
    }

    /// Whether `event_from` is a number given, or `next`: a place among the numbers.
    fn event_from_placed(&self, next: u32) -> bool {
        next.wrapping_sub(self.from) <= self.span(next)
    }

    /// How many numbers from `event_from` up to `next` are to be read: none for an
    /// `event_from` never given (it means "after the newest").
    fn unread_span(&self, next: u32) -> u32 {
        if self.event_from_placed(next) {
            next.wrapping_sub(self.from)
        } else {
            0
        }
    }

    /// Whether `seq` is at or after `event_from` and before `next` (to be read), given
    /// the window's [`unread_span`](Self::unread_span).
    fn unread_in(&self, seq: u32, unread_span: u32) -> bool {
        seq.wrapping_sub(self.from) < unread_span
    }

    /// Whether `seq` is to be read.
    fn unread(&self, seq: u32, next: u32) -> bool {
        self.unread_in(seq, self.unread_span(next))
    }

    /// A master acknowledged the events through `seq` (a number given): `event_from`
    /// moves past it if it was at or before it.
    pub(crate) fn acknowledge(&mut self, seq: u32, next: u32) {
        if self.unread(seq, next) {
            self.from = seq.wrapping_add(1);
        }
    }

    /// Whether an event fits without dropping one the master has not read.
    pub(crate) fn has_room(&self, next: u32) -> bool {
        !self.events.is_full()
            || self
                .events
                .front()
                .is_some_and(|e| !self.unread(e.seq, next))
    }

    /// Store-and-forward: takes `event` if it is the next the window wants and fits
    /// without dropping an unread event. While the window is behind (`backlog`) it
    /// wants that event: a new one (`from_store` false) only if it is that one; one
    /// read from the store may be later (the store lost some: the gap counts as
    /// missed). An event that does not fit stays in the store only: the window wants
    /// it later. `next` is the next event's number.
    pub(crate) fn offer(&mut self, event: Event, next: u32, from_store: bool) -> bool {
        self.know(event.seq, next);
        if let Some(b) = self.backlog {
            let wanted = if from_store {
                // As far back from `next` as `b` or less: at or after it.
                next.wrapping_sub(event.seq) <= next.wrapping_sub(b)
            } else {
                event.seq == b
            };
            if !wanted {
                return false;
            }
        }
        if !self.has_room(next) {
            self.backlog.get_or_insert(event.seq);
            return false;
        }
        self.push(event, next);
        let after = event.seq.wrapping_add(1);
        self.backlog = self.backlog.map(|_| after).filter(|&b| b != next);
        true
    }

    /// Keeps `event`; a full window drops its oldest, counted when the master had
    /// not read it yet. `next` is the next event's number, which `base` has followed
    /// ([`follow`](Self::follow)).
    pub(crate) fn push(&mut self, event: Event, next: u32) {
        if self.events.is_full()
            && let Some(old) = self.events.pop_front()
            && self.unread(old.seq, next)
        {
            self.dropped = self.dropped.saturating_add(1);
        }
        // Not full after the pop above.
        let _ = self.events.push_back(event);
    }

    /// The `i`-th event at or after `from`, oldest first: the one walk through the
    /// window every register of it takes, over the deque's two slices in order (a
    /// smaller loop on a Cortex-M0 than the deque's chained iterator).
    #[inline(never)]
    pub(crate) fn slot(&self, i: u16, next: u32) -> Option<&Event> {
        let (older, newer) = self.events.as_slices();
        let unread = self.unread_span(next);
        let mut left = i;
        for part in [older, newer] {
            for e in part {
                if self.unread_in(e.seq, unread) {
                    if left == 0 {
                        return Some(e);
                    }
                    left -= 1;
                }
            }
        }
        None
    }

    /// The events in the slots (at most `slots`).
    pub(crate) fn count(&self, slots: u16, next: u32) -> u16 {
        (0..slots)
            .position(|i| self.slot(i, next).is_none())
            .map_or(slots, |n| n as u16)
    }

    /// The sequence number of slot 0: the first event held at or after `from`, or
    /// `next` (the next event's) when none is.
    pub(crate) fn first(&self, next: u32) -> u32 {
        self.slot(0, next).map_or(next, |e| e.seq)
    }

    /// Events from `from` to slot 0 that are lost (none from a number never given);
    /// `next` is the next event's sequence number.
    pub(crate) fn missed(&self, next: u32) -> u32 {
        if self.event_from_placed(next) {
            self.first(next).wrapping_sub(self.from)
        } else {
            0
        }
    }
}

/// What the application's storage reports to the map (store-and-forward events,
/// checkpoints), through `Server::set_storage_status`. The server itself stores
/// nothing: it shows these values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StorageStatus {
    /// The acknowledgement on flash: every event through this number (register
    /// `event_acked`; `None` reads `0xFFFF_FFFF`).
    pub events_acknowledged: Option<u32>,
    /// Unacknowledged events on flash (`events_stored`).
    pub events_stored: u32,
    /// Unacknowledged events dropped from flash because its region was full
    /// (`events_overwritten`).
    pub events_overwritten: u32,
    /// The number of the newest checkpoint of the monitor's state (`checkpoints`).
    pub checkpoints: u32,
    /// The monitor's monotonic time (`Monitor::elapsed_ms`) at the newest checkpoint;
    /// `checkpoint_age` is the time since (`None`: none, reads `0xFFFF_FFFF`).
    pub last_checkpoint_ms: Option<u64>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::monitor::{EventKind, Reading};
    use std::vec::Vec;

    /// With the window wrapped round its storage at every offset (events pushed past
    /// its capacity), the monitor's numbers from 0, from just below 2^31 and from
    /// just below 2^32 (wrapping), and `from` before, inside and after the window,
    /// given or never given: each slot is the next event at or after `from` in order,
    /// none past them, and the gap before slot 0 is counted as missed. A `from` never
    /// given (ahead of the next number, before 0, half the number space away) shows
    /// nothing and misses nothing.
    #[test]
    fn slots_are_the_unread_events_in_order() {
        let event = |seq| Event {
            seq,
            time_ms: seq,
            elapsed_ms: u64::from(seq),
            kind: EventKind::Approaching {
                time_to_critical_s: 1.0,
            },
            reading: Reading::default(),
        };
        let window = EVENT_WINDOW as i64;
        for start in [0u32, 0x7FFF_FFF0, u32::MAX - 10] {
            for pushed in 0..3 * window {
                let next = start.wrapping_add(pushed as u32);
                let mut w = EventWindow::new(start, start);
                // As the server does after each sample: `base` follows, then the
                // new event.
                for k in 0..pushed {
                    let after = start.wrapping_add(k as u32 + 1);
                    w.follow(after);
                    w.push(event(start.wrapping_add(k as u32)), after);
                }
                // The window holds the last EVENT_WINDOW, from offset `held`.
                let held = (pushed - window).max(0);
                for d in (-3..pushed + 2).chain([1 << 31, 0x9000_0000]) {
                    w.from = start.wrapping_add(d as u32);
                    // Given: among the numbers from 0 up to the next one, at most 2^31
                    // back; unread from its place on.
                    let next_abs = i64::from(start) + pushed;
                    let back = i64::from(next.wrapping_sub(w.from));
                    let given = back >= 1 && back <= next_abs.min(1 << 31);
                    let d = pushed - back;
                    let unread: Vec<u32> = (held.max(d)..pushed)
                        .filter(|_| given)
                        .map(|k| start.wrapping_add(k as u32))
                        .collect();
                    let at = format!("{start:#x} {pushed} {:#x}", w.from);
                    for i in 0..EVENT_WINDOW as u16 + 2 {
                        let slot = w.slot(i, next).map(|e| e.seq);
                        assert_eq!(slot, unread.get(usize::from(i)).copied(), "{at} {i}");
                    }
                    let slots = crate::modbus::map::EVENT_SLOTS;
                    let count = unread.len().min(usize::from(slots));
                    assert_eq!(usize::from(w.count(slots, next)), count, "{at}");
                    assert_eq!(
                        w.first(next),
                        unread.first().copied().unwrap_or(next),
                        "{at}"
                    );
                    let missed = if given { held.max(d) - d } else { 0 };
                    assert_eq!(i64::from(w.missed(next)), missed, "{at}");
                }
            }
        }
    }
}
