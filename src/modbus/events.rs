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
}

impl EventWindow {
    pub(crate) const fn new(from: u32) -> Self {
        EventWindow {
            events: Deque::new(),
            from,
            dropped: 0,
        }
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

    /// The events at or after `from`, oldest first.
    pub(crate) fn unread(&self) -> impl Iterator<Item = &Event> {
        let from = self.from;
        self.events.iter().filter(move |e| at_or_after(e.seq, from))
    }

    /// The `i`-th event at or after `from`.
    pub(crate) fn slot(&self, i: u16) -> Option<&Event> {
        self.unread().nth(usize::from(i))
    }

    /// The sequence number of slot 0: the first event held at or after `from`, or
    /// `next` (the next event's) when none is.
    pub(crate) fn first(&self, next: u32) -> u32 {
        self.unread().next().map_or(next, |e| e.seq)
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
