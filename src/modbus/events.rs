//! The event window: the monitor's events kept for the bus, read from a sequence
//! number the master chooses, with what it can no longer read counted.

use crate::monitor::Event;
use heapless::Deque;

/// Events the window holds (the monitor's queue is drained into it after each
/// sample).
pub const EVENT_WINDOW: usize = 8;

/// Whether sequence number `a` is at or after `b` (modulo 2^32).
pub(crate) fn at_or_after(a: u32, b: u32) -> bool {
    a.wrapping_sub(b) < 1 << 31
}

/// The window.
#[derive(Debug, Clone)]
pub(crate) struct EventWindow {
    events: Deque<Event, EVENT_WINDOW>,
    /// The first sequence number a master wants (holding register `event_from`).
    pub from: u32,
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
    pub(crate) const fn new(from: u32) -> Self {
        EventWindow {
            events: Deque::new(),
            from,
            dropped: 0,
            stored: false,
            backlog: None,
        }
    }

    /// Whether an event fits without dropping one the master has not read.
    pub(crate) fn has_room(&self) -> bool {
        !self.events.is_full()
            || self
                .events
                .front()
                .is_some_and(|e| !at_or_after(e.seq, self.from))
    }

    /// Store-and-forward: takes `event` if it is the next the window wants and fits
    /// without dropping an unread event. While the window is behind (`backlog`) it
    /// wants that event: a new one (`from_store` false) only if it is that one; one
    /// read from the store may be later (the store lost some: the gap counts as
    /// missed). An event that does not fit stays in the store only: the window wants
    /// it later. `next` is the next event's number.
    pub(crate) fn offer(&mut self, event: Event, next: u32, from_store: bool) -> bool {
        if let Some(b) = self.backlog {
            let wanted = if from_store {
                at_or_after(event.seq, b)
            } else {
                event.seq == b
            };
            if !wanted {
                return false;
            }
        }
        if !self.has_room() {
            self.backlog.get_or_insert(event.seq);
            return false;
        }
        self.push(event);
        let after = event.seq.wrapping_add(1);
        self.backlog = self.backlog.map(|_| after).filter(|&b| b != next);
        true
    }

    /// Keeps `event`; a full window drops its oldest, counted when the master had
    /// not read it yet.
    pub(crate) fn push(&mut self, event: Event) {
        if self.events.is_full()
            && let Some(old) = self.events.pop_front()
            && at_or_after(old.seq, self.from)
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
    pub(crate) fn slot(&self, i: u16) -> Option<&Event> {
        let (older, newer) = self.events.as_slices();
        let mut left = i;
        for part in [older, newer] {
            for e in part {
                if at_or_after(e.seq, self.from) {
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
    pub(crate) fn unread(&self, slots: u16) -> u16 {
        (0..slots)
            .position(|i| self.slot(i).is_none())
            .map_or(slots, |n| n as u16)
    }

    /// The sequence number of slot 0: the first event held at or after `from`, or
    /// `next` (the next event's) when none is.
    pub(crate) fn first(&self, next: u32) -> u32 {
        self.slot(0).map_or(next, |e| e.seq)
    }

    /// Events from `from` to slot 0 that are lost; `next` is the next event's
    /// sequence number.
    pub(crate) fn missed(&self, next: u32) -> u32 {
        let first = self.first(next);
        if at_or_after(first, self.from) && at_or_after(next, self.from) {
            first.wrapping_sub(self.from)
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
    /// its capacity) and `from` before, inside and after it, each slot is the event
    /// that filtering the window's events in order gives, and none past them.
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
        for pushed in 0..3 * EVENT_WINDOW as u32 {
            let mut w = EventWindow::new(0);
            for seq in 0..pushed {
                w.push(event(seq));
            }
            for from in 0..pushed + 2 {
                w.from = from;
                let unread: Vec<u32> = w
                    .events
                    .iter()
                    .map(|e| e.seq)
                    .filter(|&s| at_or_after(s, from))
                    .collect();
                for i in 0..EVENT_WINDOW as u16 + 2 {
                    let slot = w.slot(i).map(|e| e.seq);
                    assert_eq!(
                        slot,
                        unread.get(usize::from(i)).copied(),
                        "{pushed} {from} {i}"
                    );
                }
                let slots = crate::modbus::map::EVENT_SLOTS;
                assert_eq!(
                    usize::from(w.unread(slots)),
                    unread.len().min(usize::from(slots))
                );
                assert_eq!(w.first(pushed), unread.first().copied().unwrap_or(pushed));
            }
        }
    }
}
