//! The flash event queue (`misalign::storage::EventQueue`) on the mock NOR flash: the
//! monitor's events kept until acknowledged, through resets, a full region and power
//! loss at every byte written and every word erased of a push and of an
//! acknowledgement; the event record's bytes as docs/formats.md states them; the wear
//! figures of docs/formats.md.
//!
//! `MISALIGN_POWER_LOSS=full` sweeps every push and acknowledgement of four turns of
//! the ring (seconds) instead of the default's chosen ones (the first push on a
//! blank flash, the first that opens a sector, the first that erases a sector of
//! acknowledged events, the first that erases unacknowledged ones; the first
//! acknowledgement and the first that erases a sector).

use misalign::monitor::{Event, EventKind, Reading, RiskState};
use misalign::storage::codec;
use misalign::storage::endurance::{self, Geometry};
use misalign::storage::{
    BlockingFlash, Checkpoint, EventQueue, MockError, MockFlash, StorageError, StoreConfigError,
    block_on, kind,
};

const SECTORS: usize = 4;
const SECTOR: usize = 1024;
const WORD: usize = 4;
type Flash = MockFlash<SECTORS, SECTOR, WORD>;
const BUF: usize = 72;
type Q = EventQueue<BlockingFlash<Flash>, Event, BUF>;

fn event(seq: u32) -> Event {
    Event {
        seq,
        time_ms: seq.wrapping_mul(1000),
        elapsed_ms: u64::from(seq) * 1000 + 7,
        kind: EventKind::StateChange {
            from: RiskState::Normal,
            to: RiskState::Microslip,
            fault: None,
        },
        reading: Reading {
            load: 2000.0 + seq as f32,
            phi: 1e-4,
            slip_ratio: 0.3,
            axial_force: 12.5,
            critical_angle: Some(3e-4),
            margin: None,
        },
    }
}

fn new_queue(flash: Flash) -> Q {
    Q::new(BlockingFlash(flash), 0..(SECTORS * SECTOR) as u32).unwrap()
}

/// A start-up: the queue opened on `flash`.
fn boot(flash: Flash) -> Q {
    let mut q = new_queue(flash);
    block_on(q.open()).unwrap();
    q
}

fn flash_of(q: Q) -> Flash {
    q.into_flash().0
}

/// The unacknowledged events, read back in order from the oldest (numbers wrap), each
/// equal to what was pushed.
fn unacked(q: &mut Q) -> Vec<u32> {
    let mut out = Vec::new();
    let from = q.state().first.unwrap_or(0);
    block_on(q.read(from, |seq, e| {
        assert_eq!(e, event(seq));
        out.push(seq);
        true
    }))
    .unwrap();
    // What `open` counts agrees with what `read` gives.
    assert_eq!(q.state().unacknowledged as usize, out.len());
    assert_eq!(q.state().first, out.first().copied());
    out
}

fn push(q: &mut Q, seq: u32) -> u32 {
    block_on(q.push(seq, &event(seq))).unwrap().dropped
}

/// Records of events in one sector: measured on the mock flash, equal to the wear
/// helpers' figure for the event's payload.
fn per_sector() -> u32 {
    Geometry {
        payload: Event::SIZE,
        sector: SECTOR,
        sectors: SECTORS,
        word: WORD,
    }
    .checkpoints_per_sector() as u32
}

#[test]
fn events_come_back_after_a_reset_until_acknowledged_and_never_after() {
    let mut q = boot(Flash::new());
    assert_eq!(q.state(), Default::default());
    for seq in 0..5 {
        assert_eq!(push(&mut q, seq), 0);
    }
    let mut q = boot(flash_of(q));
    assert_eq!(unacked(&mut q), [0, 1, 2, 3, 4]);
    assert_eq!(q.state().newest, Some(4));
    // Not after the newest: refused, nothing written.
    let flash = flash_of(q);
    let points = flash.points();
    let mut q = boot(flash);
    assert_eq!(block_on(q.acknowledge(5)), Ok(false));
    let flash = flash_of(q);
    assert_eq!(flash.points(), points);
    let mut q = boot(flash);
    assert_eq!(block_on(q.acknowledge(2)), Ok(true));
    // Not after the acknowledgement held: refused.
    assert_eq!(block_on(q.acknowledge(2)), Ok(false));
    assert_eq!(block_on(q.acknowledge(1)), Ok(false));
    assert_eq!(unacked(&mut q), [3, 4]);
    let mut q = boot(flash_of(q));
    assert_eq!(q.acknowledged(), Some(2));
    assert_eq!(unacked(&mut q), [3, 4]);
    // `read` from a later number.
    let mut from_4 = Vec::new();
    block_on(q.read(4, |seq, _| {
        from_4.push(seq);
        true
    }))
    .unwrap();
    assert_eq!(from_4, [4]);
    push(&mut q, 5);
    assert_eq!(block_on(q.acknowledge(5)), Ok(true));
    let mut q = boot(flash_of(q));
    assert_eq!(unacked(&mut q), Vec::<u32>::new());
    assert_eq!((q.acknowledged(), q.state().newest), (Some(5), Some(5)));
}

#[test]
fn numbers_wrap_modulo_2_pow_32() {
    let mut q = boot(Flash::new());
    for seq in [u32::MAX - 1, u32::MAX, 0, 1] {
        push(&mut q, seq);
    }
    assert_eq!(block_on(q.acknowledge(u32::MAX)), Ok(true));
    let mut q = boot(flash_of(q));
    assert_eq!(unacked(&mut q), [0, 1]);
}

/// Only a number of a record held and not yet acknowledged acknowledges: after
/// records 0 to 8, a number never given (ahead of the newest, or half the number space
/// away, where a comparison modulo 2^32 alone reads it as an old one) writes nothing
/// and acknowledges nothing, at a fresh start and after an acknowledgement alike; so
/// do a number acknowledged already and any number on an empty queue. Around the wrap
/// of the numbers likewise.
#[test]
fn only_a_number_of_a_record_held_acknowledges() {
    let never = |newest: u32| {
        [
            1,
            2,
            0x7FFF_FFFF,
            0x8000_0000,
            0x8000_0001,
            0x9000_0000,
            0xFFFF_FFF0,
        ]
        .map(|d: u32| newest.wrapping_add(d))
    };
    let refused = |q: Q, through: u32| -> Q {
        let flash = flash_of(q);
        let points = flash.points();
        let mut q = boot(flash);
        let before = q.state();
        assert_eq!(block_on(q.acknowledge(through)), Ok(false), "{through:#x}");
        assert_eq!(q.state(), before, "{through:#x}");
        let flash = flash_of(q);
        assert_eq!(flash.points(), points, "{through:#x}: written");
        boot(flash)
    };
    let mut q = boot(Flash::new());
    for n in [0, 1, 0x9000_0000, u32::MAX] {
        q = refused(q, n);
    }
    for start in [0, u32::MAX - 3] {
        let mut q = boot(Flash::new());
        for k in 0..9u32 {
            push(&mut q, start.wrapping_add(k));
        }
        let newest = start.wrapping_add(8);
        for n in never(newest) {
            q = refused(q, n);
        }
        assert_eq!(q.acknowledged(), None);
        assert_eq!(unacked(&mut q).len(), 9);
        let through = start.wrapping_add(3);
        assert_eq!(block_on(q.acknowledge(through)), Ok(true));
        for n in never(newest)
            .into_iter()
            .chain([through, start, start.wrapping_sub(1)])
        {
            q = refused(q, n);
        }
        assert_eq!(q.acknowledged(), Some(through));
        assert_eq!(block_on(q.acknowledge(newest)), Ok(true));
        assert_eq!(unacked(&mut q), Vec::<u32>::new());
        q = refused(q, newest);
        let _ = q;
    }
}

#[test]
fn a_full_region_drops_the_oldest_unacknowledged_counted_as_the_sequence_gap() {
    let mut q = boot(Flash::new());
    let mut dropped = 0;
    let total = 4 * per_sector() * SECTORS as u32;
    for seq in 0..total {
        let d = push(&mut q, seq);
        // Only whole sectors go, and only when the ring is full.
        assert!(d == 0 || d == per_sector(), "{seq}: {d}");
        dropped += d;
        // Nothing was acknowledged: the first held is the count dropped.
        assert_eq!(q.state().first, Some(dropped), "{seq}");
        assert_eq!(q.state().unacknowledged, seq + 1 - dropped);
    }
    assert!(dropped > 0);
    assert_eq!(q.dropped(), dropped);
    let mut q = boot(flash_of(q));
    let held = unacked(&mut q);
    assert_eq!(held, (dropped..total).collect::<Vec<_>>());
    // The ring holds a sector less than the region at most, and at least that much
    // less one sector's worth.
    assert!(held.len() as u32 <= (SECTORS as u32 - 1) * per_sector() + per_sector());
}

#[test]
fn acknowledged_events_make_room_without_a_drop() {
    let mut q = boot(Flash::new());
    for seq in 0..10 * per_sector() * SECTORS as u32 {
        assert_eq!(push(&mut q, seq), 0, "{seq}");
        if seq % 7 == 6 {
            assert_eq!(block_on(q.acknowledge(seq)), Ok(true));
        }
    }
    assert_eq!(q.dropped(), 0);
    // Partly acknowledged: an acknowledgement that leaves some behind, then a full
    // region drops only those after it.
    let mut q = boot(flash_of(q));
    let last = q.state().newest.unwrap();
    let held = unacked(&mut q);
    assert!(held.iter().all(|&s| s > last - 7));
}

#[test]
fn wear_helpers_give_the_records_a_sector_holds() {
    // Pushing into a blank ring: the first erase comes when every sector is full, a
    // sector's worth of records in each, as the wear helpers count them.
    let mut flash = Flash::new();
    let mut seq = 0;
    while flash.erase_counts().iter().sum::<u32>() == 0 {
        let mut q = boot(flash);
        push(&mut q, seq);
        flash = flash_of(q);
        seq += 1;
    }
    assert_eq!(seq - 1, per_sector() * SECTORS as u32);
}

#[test]
fn configuration_errors() {
    assert_eq!(
        Q::new(BlockingFlash(Flash::new()), 0..SECTOR as u32).err(),
        Some(StoreConfigError::TooSmall)
    );
    assert_eq!(
        Q::new(BlockingFlash(Flash::new()), 1..(3 * SECTOR) as u32).err(),
        Some(StoreConfigError::Unaligned)
    );
    assert_eq!(
        Q::new(BlockingFlash(Flash::new()), 0..(8 * SECTOR) as u32).err(),
        Some(StoreConfigError::OutOfBounds)
    );
    assert_eq!(
        EventQueue::<BlockingFlash<Flash>, Event, 64>::new(
            BlockingFlash(Flash::new()),
            0..(2 * SECTOR) as u32
        )
        .err(),
        Some(StoreConfigError::Geometry)
    );
    assert_eq!(Q::buffer_len(), BUF);
}

// ---------------------------------------------------------------------------------
// Power loss.

/// An operation on the queue.
#[derive(Debug, Clone, Copy)]
enum Op {
    Push(u32),
    Ack(u32),
}

fn apply(q: &mut Q, op: Op) -> Result<(), StorageError<MockError>> {
    match op {
        Op::Push(seq) => block_on(q.push(seq, &event(seq))).map(|_| ()),
        Op::Ack(seq) => block_on(q.acknowledge(seq)).map(|_| ()),
    }
}

/// Points (bytes written, words erased) of booting on `base` and applying `op`.
fn points_of(base: &Flash, op: Op) -> u64 {
    let mut q = boot(base.clone());
    apply(&mut q, op).unwrap();
    flash_of(q).points() - base.points()
}

/// Cuts the power at every point of `op` on `base` (booted first), restarts and
/// opens: the acknowledgement is the old or the new one, the unacknowledged events
/// are those before or those after (a push that erases a sector may have dropped its
/// unacknowledged events, the oldest), never an acknowledged one back, never one lost
/// otherwise; then the queue goes on. Returns the points swept.
fn sweep(base: &Flash, op: Op) -> u64 {
    let before = {
        let mut q = boot(base.clone());
        (q.acknowledged(), unacked(&mut q))
    };
    let after = {
        let mut q = boot(base.clone());
        apply(&mut q, op).unwrap();
        let dropped = q.stats().dropped;
        (q.acknowledged(), unacked(&mut q), dropped)
    };
    let points = points_of(base, op);
    for p in 0..points {
        let what = format!("{op:?}, point {p} of {points}");
        let mut flash = base.clone();
        flash.cut_after(p);
        let mut q = boot(flash);
        assert_eq!(
            apply(&mut q, op),
            Err(StorageError::Flash(MockError::PowerLoss)),
            "{what}"
        );
        let mut flash = flash_of(q);
        flash.restart();
        let mut q = boot(flash);
        let ack = q.acknowledged();
        let held = unacked(&mut q);
        let old = (ack, &held) == (before.0, &before.1);
        let new = (ack, &held) == (after.0, &after.1);
        // A cut after the erase of a full sector and before the record is whole: the
        // sector's events are gone (as the push would have dropped them), the new
        // record not there.
        // (The sector may have held the acknowledgement: every event left is after it.)
        let erased = after.2 > 0
            && (ack == before.0 || ack == after.0)
            && held.len() + after.2 as usize >= before.1.len()
            && before.1.ends_with(&held);
        assert!(old || new || erased, "{what}: {ack:?} {held:?}");
        // Never an acknowledged event back.
        if let Some(k) = before.0 {
            assert!(held.iter().all(|&s| s.wrapping_sub(k) as i32 > 0), "{what}");
        }
        // The queue goes on: an acknowledgement again, the next event, after a reset.
        if let Op::Ack(_) = op {
            apply(&mut q, op).unwrap_or_else(|e| panic!("{what}: again {e:?}"));
        }
        let next = q.state().newest.map_or(0, |n| n + 1);
        push(&mut q, next);
        let mut q = boot(flash_of(q));
        assert_eq!(unacked(&mut q).last(), Some(&next), "{what}");
    }
    points
}

/// The default sweep: the chosen pushes of a run (the first on a blank flash, the first
/// that opens a new sector, the first that erases acknowledged events, the first that
/// erases unacknowledged ones) and acknowledgements (the first, the first that erases
/// a sector).
/// `MISALIGN_POWER_LOSS=full`: every push and acknowledgement of four turns of the ring.
#[test]
fn power_loss_at_every_point_of_a_push_and_an_acknowledgement() {
    let full = std::env::var("MISALIGN_POWER_LOSS").is_ok_and(|v| v == "full");
    let per_turn = per_sector() * SECTORS as u32;
    let mut flash = Flash::new();
    let mut swept = 0u64;
    let mut ops = 0u32;
    let (mut opening, mut erasing_acked, mut erasing_unacked) = (false, false, false);
    let mut plain = u64::MAX;
    let (mut ack_swept, mut ack_erasing) = (0, false);
    // Acknowledged every fourth event (all but the newest) for two turns, one of them
    // the item that erases a sector; then never: the region fills.
    let last = 4 * per_turn;
    for seq in 0..last {
        let op = Op::Push(seq);
        let base_erases: u32 = flash.erase_counts().iter().sum();
        let mut probe = boot(flash.clone());
        apply(&mut probe, op).unwrap();
        let dropped = probe.stats().dropped;
        let probed = flash_of(probe);
        let erases: u32 = probed.erase_counts().iter().sum();
        let points = probed.points() - flash.points();
        if seq == 1 {
            plain = points;
        }
        let chosen = seq == 0
            || (!opening && points > plain && erases == base_erases && {
                opening = true;
                true
            })
            || (!erasing_acked && erases > base_erases && dropped == 0 && {
                erasing_acked = true;
                true
            })
            || (!erasing_unacked && dropped > 0 && {
                erasing_unacked = true;
                true
            });
        let acking = seq < 2 * per_turn && seq % 4 == 3;
        if full || chosen {
            swept += sweep(&flash, op);
            ops += 1;
        }
        flash = probed;
        if acking {
            let op = Op::Ack(seq - 1);
            let mut q = boot(flash.clone());
            apply(&mut q, op).unwrap();
            let acked = flash_of(q);
            let erases = |f: &Flash| f.erase_counts().iter().sum::<u32>();
            let chosen = ack_swept == 0
                || (!ack_erasing && erases(&acked) > erases(&flash) && {
                    ack_erasing = true;
                    true
                });
            if full || chosen {
                swept += sweep(&flash, op);
                ops += 1;
                ack_swept += 1;
            }
            flash = acked;
        }
    }
    assert!(opening && erasing_acked && erasing_unacked);
    assert!(swept >= (SECTOR / WORD) as u64);
    assert!(ack_swept > 0 && ack_erasing);
    eprintln!(
        "power loss: {ops} operations swept ({ack_swept} acknowledgements, one that \
         erases a sector: {ack_erasing}), {swept} points"
    );
}

// ---------------------------------------------------------------------------------
// The record's bytes and the wear figures in docs/formats.md.

fn formats() -> String {
    std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/formats.md")).unwrap()
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// The event record and the acknowledgement, byte for byte as the page shows them.
#[test]
fn event_records_are_the_documented_bytes() {
    let spec = formats();
    let mut buf = [0u8; 128];
    let e = event(7);
    let n = codec::encode(&e, e.seq, &mut buf).unwrap();
    assert_eq!(n, codec::record_len(51));
    assert_eq!(
        (Event::KIND, Event::VERSION, Event::SIZE),
        (kind::EVENT, 1, 51)
    );
    let row = format!("`{}`", hex(&buf[..n]));
    assert!(
        spec.contains(&row),
        "docs/formats.md lacks the event record {row}"
    );
    assert_eq!(codec::decode::<Event>(&buf[..n]).unwrap().value, e);
    assert!(spec.contains(&format!(
        "### `monitor::Event` in the event queue, version 1 (kind {}, 51 bytes)",
        kind::EVENT
    )));
    assert!(spec.contains(&format!(
        "### Acknowledgement in the event queue, version 1 (kind {}, 0 bytes)",
        kind::EVENT_ACK
    )));
}

/// The wear table: each row's figures from the wear helpers.
#[test]
fn wear_figures_are_the_documented_ones() {
    let spec = formats();
    let g = Geometry {
        payload: Event::SIZE,
        ..endurance::REFERENCE
    };
    for (label, per_hour) in [("1", 1u32), ("10", 10), ("60", 60)] {
        let interval_s = 3600 / per_hour;
        let row = format!(
            "| {label} | {} | {} | {} |",
            endurance::SECONDS_PER_YEAR / u64::from(interval_s),
            g.cycles_per_year(interval_s),
            g.years_to(endurance::RATED_CYCLES, interval_s)
        );
        assert!(spec.contains(&row), "docs/formats.md lacks {row}");
    }
    // The queue's item: an 8-byte header, the record padded to the word.
    let item = |payload: usize| 8 + codec::record_len(payload).div_ceil(4) * 4;
    assert_eq!(item(Event::SIZE), g.item_bytes());
    let row = format!(
        "of {} bytes against an\nevent's {} (with 4-byte words)",
        item(0),
        g.item_bytes()
    );
    assert!(spec.contains(&row), "docs/formats.md lacks {row}");
    let row = format!(
        "{} events a sector, {} a turn of the ring",
        g.checkpoints_per_sector(),
        g.checkpoints_per_cycle()
    );
    assert!(spec.contains(&row), "docs/formats.md lacks {row}");
}

/// Garbage over the region (cold RAM, another program's data): no event comes out of
/// it; the region is erased and reported, and the queue works.
#[test]
fn garbage_gives_no_event_and_erase_recovers() {
    for seed in 0u64..12 {
        let mut flash = Flash::new();
        let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        for i in 0..SECTORS {
            for b in flash.sector_mut(i).unwrap().iter_mut() {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                *b = match seed {
                    10 => 0x00,
                    11 => 0x55,
                    _ => x as u8,
                };
            }
        }
        let mut q = new_queue(flash);
        let found = block_on(q.open()).unwrap();
        assert!(found.erased, "{seed}");
        assert_eq!((found.newest, found.acknowledged), (None, None), "{seed}");
        push(&mut q, 0);
        let mut q = boot(flash_of(q));
        assert!(!q.state().erased);
        assert_eq!(unacked(&mut q), [0], "{seed}");
    }
}

/// 8-byte words (ECC flash that programs a double word once, as on many Cortex-M0+
/// parts): the same behaviour, the buffer rounded up to the word.
#[test]
fn double_word_flash_keeps_and_acknowledges_alike() {
    type Wide = MockFlash<4, 2048, 8>;
    type WideQ = EventQueue<BlockingFlash<Wide>, Event, 72>;
    assert_eq!(WideQ::buffer_len(), 72);
    let open = |flash: Wide| {
        let mut q = WideQ::new(BlockingFlash(flash), 0..4 * 2048).unwrap();
        block_on(q.open()).unwrap();
        q
    };
    let mut q = open(Wide::new());
    let mut dropped = 0;
    for seq in 0..200 {
        dropped += block_on(q.push(seq, &event(seq))).unwrap().dropped;
        if seq % 10 == 9 && seq < 100 {
            assert_eq!(block_on(q.acknowledge(seq - 3)), Ok(true));
        }
    }
    let mut q = open(q.into_flash().0);
    let state = q.state();
    // The newest acknowledgement (through 96) went with its sector: every event left is
    // newer, and the gap after it is the count dropped.
    assert_eq!(state.acknowledged, None);
    let first = state.first.unwrap();
    assert_eq!(first - 97, dropped);
    let mut seqs = Vec::new();
    block_on(q.read(0, |seq, e| {
        assert_eq!(e, event(seq));
        seqs.push(seq);
        true
    }))
    .unwrap();
    assert_eq!(seqs, (first..200).collect::<Vec<_>>());
    assert!(dropped > 0, "{dropped} dropped, first {first}");
}
