//! The Modbus node's flash (feature `modbus-flash`): what a
//! node keeps through a reset or a power cut, through `misalign::storage` as a
//! firmware uses it (a blocking flash driver, `block_on`, no executor), on the board's
//! flash (`flash.rs`): the micro:bit's through its NVMC on the Cortex-M0, RAM kept
//! across a system reset on the MPS2 boards.
//!
//! Two regions: a [`Store`] of 4 KiB holding the monitor's state (checkpointed at each
//! event, when a master reset the statistics, and once a minute of monitored time) and
//! the configuration committed over the bus (`ConfigImage`, written once per commit or
//! switch of latching or the samples' source); an [`EventQueue`] of 2 KiB holding every
//! event until a master acknowledges it (`event_ack`). The answer to a master's write
//! waits until what it changed is stored (`Server::stored`). At boot: the committed
//! configuration restored (`config_source` says which ran), then the state under it
//! (numbering after the newest event stored), the event window fed from the queue, from
//! its oldest unacknowledged event on.

use crate::flash::{self, Board, EVENTS_SIZE, STORE_SIZE};
use misalign::Estimator;
use misalign::modbus::{BootSource, IMAGE_LEN, Server, StorageStatus, Stored};
use misalign::monitor::{Event, Monitor, MonitorState};
use misalign::storage::{
    BlockingFlash, ConfigImage, EventQueue, RestoreOutcome, StorageEvent, Store, block_on,
};

// Test builds (`_power-cut`): a power cut a test planned, armed at the start of the
// operation it names; nothing otherwise.
#[cfg(feature = "_power-cut")]
use crate::cut::{Op, arm_if_planned as cut, disarm as uncut};
#[cfg(not(feature = "_power-cut"))]
#[derive(Clone, Copy)]
enum Op {
    Commit,
    Push,
    Ack,
}
#[cfg(not(feature = "_power-cut"))]
#[inline(always)]
fn cut(_: Op) {}
#[cfg(not(feature = "_power-cut"))]
#[inline(always)]
fn uncut() {}

/// The periodic checkpoint's interval (s of monitored time).
const INTERVAL_S: u32 = 60;

type Flash = BlockingFlash<Board>;
const STATE_BUF: usize = Store::<Flash, 0>::buffer_len::<MonitorState>();
const IMAGE_BUF: usize = Store::<Flash, 0>::buffer_len::<ConfigImage<IMAGE_LEN>>();
/// The store's buffer: the larger of its two records'.
const BUF: usize = if STATE_BUF > IMAGE_BUF {
    STATE_BUF
} else {
    IMAGE_BUF
};
const EVENT_BUF: usize = EventQueue::<Flash, Event, 0>::buffer_len();

/// The node's storage, and what it last told the server.
pub struct Persist {
    store: Store<Flash, BUF>,
    events: EventQueue<Flash, Event, EVENT_BUF>,
    /// The acknowledgement made durable last.
    acked: Option<u32>,
    /// The next event number at the last checkpoint, and its monitored time (s).
    checkpointed_seq: u32,
    checkpointed_s: Option<u64>,
    /// The samples the statistics had counted at the last checkpoint: fewer now, and
    /// a master reset them.
    checkpointed_samples: u64,
    status: StorageStatus,
}

impl Persist {
    /// The two regions, opened once at boot; the event queue read through. `None` on
    /// a flash error.
    #[inline(never)]
    pub fn open() -> Option<Self> {
        let (store, events) = flash::regions()?;
        let store = Store::new(BlockingFlash(store), 0..STORE_SIZE as u32, INTERVAL_S).ok()?;
        let mut events = EventQueue::new(BlockingFlash(events), 0..EVENTS_SIZE as u32).ok()?;
        let found = block_on(events.open()).ok()?;
        defmt::println!(
            "storage: {=u32} events kept, acknowledged through {=?}, region erased {=bool}",
            found.unacknowledged,
            found.acknowledged,
            found.erased
        );
        Some(Persist {
            store,
            events,
            acked: found.acknowledged,
            checkpointed_seq: 0,
            checkpointed_s: None,
            checkpointed_samples: 0,
            status: StorageStatus::default(),
        })
    }

    /// At boot, before the first sample: the committed configuration restored into the
    /// server first (its `config_source`), then the monitor's last checkpoint under it
    /// (the other order would start the conditioning and the trend of a checkpoint
    /// afresh when the committed configuration is applied), numbering its events after
    /// the newest stored; the server told to store its events, its window fed from the
    /// queue. Returns where the configuration came from, and whether a checkpoint was
    /// restored (none, or a damaged one: the region is then erased and the monitor
    /// starts afresh).
    pub fn start<E: Estimator>(&mut self, server: &mut Server<E>) -> (BootSource, bool) {
        let source = self.restore_config(server);
        let restored = self.restore_state(server);
        server.store_events(self.events.state().first);
        self.service(server);
        (source, restored)
    }

    /// The committed configuration's image, if any, into the server.
    #[inline(never)]
    fn restore_config<E: Estimator>(&mut self, server: &mut Server<E>) -> BootSource {
        let mut image = ConfigImage::<IMAGE_LEN>::new();
        let outcome = block_on(self.store.restore_into(&mut image));
        if let Ok(RestoreOutcome::Rejected(why)) = outcome {
            defmt::println!("storage: configuration record rejected: {}", why);
        }
        let stored = match outcome {
            Ok(RestoreOutcome::Restored { .. } | RestoreOutcome::Migrated { .. }) => {
                Stored::Image(&image.0)
            }
            // A region that never held a record of ours (a first start on flash of
            // any contents, or a first record cut by a power loss) stored nothing.
            Ok(RestoreOutcome::Blank | RestoreOutcome::Rejected(StorageEvent::ForeignRegion)) => {
                Stored::Nothing
            }
            _ => Stored::Damaged,
        };
        server.restore(stored)
    }

    /// The monitor's last checkpoint into the server's monitor, under the
    /// configuration it runs; without one, the fresh monitor numbers its events after
    /// the newest stored.
    #[inline(never)]
    fn restore_state<E: Estimator>(&mut self, server: &mut Server<E>) -> bool {
        let mut state = MonitorState::default();
        let restored = match block_on(self.store.restore_into(&mut state)) {
            Ok(
                RestoreOutcome::Restored { sequence } | RestoreOutcome::Migrated { sequence, .. },
            ) => Some(sequence),
            _ => None,
        };
        let newest = self.events.state().newest;
        if let Some(n) = newest {
            state.continue_events_after(n);
        }
        if let Some(sequence) = restored {
            server.resume(&state);
            let elapsed_ms = server.monitor().elapsed_ms();
            self.status.checkpoints = sequence;
            self.status.last_checkpoint_ms = Some(elapsed_ms);
            self.checkpointed_s = Some(elapsed_ms / 1000);
        } else if let Some(n) = newest {
            // No state, but events kept: number on after them.
            let mut fresh = server.monitor().snapshot();
            fresh.continue_events_after(n);
            server.resume(&fresh);
        }
        self.checkpointed_seq = server.monitor().next_event_seq();
        self.checkpointed_samples = server.monitor().statistics().samples();
        restored.is_some()
    }

    /// After each sample and each request: new events onto the flash and into the
    /// window, the master's acknowledgement made durable, the window fed from the
    /// flash while it is behind, a committed configuration persisted, the state
    /// checkpointed at each event and at the interval, the storage registers told;
    /// then the server told that the write it holds the answer to is stored (or that
    /// a write failed: exception 04).
    pub fn service<E: Estimator>(&mut self, server: &mut Server<E>) {
        let mut ok = true;
        while let Some(e) = server.pop_event() {
            cut(Op::Push);
            if block_on(self.events.push(e.seq, &e)).is_err() {
                defmt::warn!("storage: event {=u32} not stored", e.seq);
                ok = false;
            }
            uncut();
            server.offer_event(e);
        }
        let ack = server.acknowledged_through();
        if let Some(k) = ack.filter(|_| ack != self.acked) {
            cut(Op::Ack);
            if block_on(self.events.acknowledge(k)).is_err() {
                defmt::warn!("storage: acknowledgement {=u32} not stored", k);
                ok = false;
            }
            uncut();
            self.acked = ack;
        }
        while let Some(wanted) = server.wanted_event() {
            let mut found = None;
            if block_on(self.events.read(wanted, |_, e| {
                found = Some(e);
                false
            }))
            .is_err()
            {
                break;
            }
            match found {
                Some(e) if server.offer_stored_event(e) => {}
                Some(_) => break,
                None => server.end_backlog(),
            }
        }
        let mut image = ConfigImage::<IMAGE_LEN>::new();
        if server.take_committed(&mut image.0) {
            cut(Op::Commit);
            if block_on(self.store.checkpoint(&image)).is_err() {
                defmt::warn!("storage: the committed configuration not stored");
                ok = false;
            }
            uncut();
        }
        ok &= self.checkpoint(server.monitor());
        let q = self.events.state();
        self.status.events_acknowledged = q.acknowledged;
        self.status.events_stored = q.unacknowledged;
        self.status.events_overwritten = self.events.dropped();
        server.set_storage_status(self.status);
        server.stored(ok);
    }

    /// The monitor's state checkpointed when it raised an event since the last
    /// checkpoint, when a master reset its statistics, or when [`INTERVAL_S`] of
    /// monitored time have passed. False if the checkpoint failed.
    fn checkpoint<E: Estimator>(&mut self, m: &Monitor<E>) -> bool {
        let now_s = m.elapsed_ms() / 1000;
        let due = self
            .checkpointed_s
            .is_none_or(|last| now_s.saturating_sub(last) >= u64::from(INTERVAL_S));
        let samples = m.statistics().samples();
        let reset = samples < self.checkpointed_samples;
        if m.next_event_seq() == self.checkpointed_seq && !due && !reset {
            return true;
        }
        self.checkpointed_seq = m.next_event_seq();
        self.checkpointed_s = Some(now_s);
        self.checkpointed_samples = samples;
        match block_on(self.store.checkpoint(&m.snapshot())) {
            Ok(sequence) => {
                self.status.checkpoints = sequence;
                self.status.last_checkpoint_ms = Some(m.elapsed_ms());
                true
            }
            Err(_) => {
                defmt::warn!("storage: checkpoint failed");
                false
            }
        }
    }
}
