//! Store-and-forward over Modbus: the server's `event_ack` and storage registers, and
//! the application's loop between the server and the flash event queue
//! (`storage::EventQueue` on the mock flash): every event read in order with its own
//! number, across resets, beyond the window's capacity, and an acknowledged event
//! never read again.

use misalign::float::Auto;
use misalign::modbus::map::{EVENT_SLOTS, EVENT_SLOTS_ADDRESS, EVENT_STRIDE, EVENT_WINDOW_ADDRESS};
use misalign::modbus::{
    EVENT_WINDOW, Server, ServerConfig, StorageStatus, crc16, event_from_registers,
};
use misalign::monitor::{Config, Event, Monitor, MonitorState, Sample, model_for_range};
use misalign::storage::{BlockingFlash, EventQueue, MockFlash, RestoreOutcome, Store, block_on};
use misalign::{Estimator, Scene};

type Flash = MockFlash<4, 1024, 4>;
type Q = EventQueue<BlockingFlash<Flash>, Event, 72>;

fn monitor(state: Option<&MonitorState>) -> Monitor<Auto> {
    let scene = Scene::DEMO;
    let core = Auto::with_choice(&scene, model_for_range(&scene, 5e3, 1e-5).unwrap()).unwrap();
    // A fault clears at once: an event in and one out every few samples.
    let config = Config {
        off_delay_ms: 0,
        ..Config::default()
    };
    match state {
        Some(s) => Monitor::restore(core, config, s).unwrap(),
        None => Monitor::new(core, config).unwrap(),
    }
}

/// Sample `i`: running, a sensor fault every ten samples (an event in, and one out
/// once 7 samples have filled the spike window again and the 8th decides).
fn sample(i: u32) -> Sample {
    // Noise enough that no sensor reads as stuck.
    let noise = (i % 7) as f32;
    let mut s = Sample::new(i * 1000, 1e3 + noise, 5e-5 + 1e-8 * noise).with_speed(2.0);
    if i % 10 == 9 {
        s.load = f32::NAN;
    }
    s
}

/// A fresh monitor's state that numbers its next event `start`: the numbers before it
/// given, up from 0 (two steps of less than 2^31, as events are numbered).
fn numbering_from(start: u32) -> MonitorState {
    let mut state = monitor(None).snapshot();
    if start != 0 {
        state.continue_events_after(start / 2);
        state.continue_events_after(start - 1);
    }
    assert_eq!(state.next_event_seq(), start);
    state
}

/// A request of `function` with `data` to unit 1.
fn send<E: Estimator>(s: &mut Server<E>, function: u8, data: &[u8]) {
    let mut f = vec![1, function];
    f.extend_from_slice(data);
    f.extend_from_slice(&crc16(&f).to_le_bytes());
    f.iter().for_each(|&b| s.receive(b));
}

/// The answer's PDU, sent.
fn take<E: Estimator>(s: &mut Server<E>) -> Vec<u8> {
    let answer = s.response().expect("an answer").to_vec();
    s.sent();
    answer[1..answer.len() - 2].to_vec()
}

/// A request of `function` with `data` to unit 1; the answer's PDU.
fn pdu<E: Estimator>(s: &mut Server<E>, function: u8, data: &[u8]) -> Vec<u8> {
    send(s, function, data);
    take(s)
}

/// A write under store-and-forward: its answer held until the application's part has
/// run (`service`); the answer's PDU.
fn write_stored(s: &mut Server<Auto>, q: &mut Q, function: u8, data: &[u8]) -> Vec<u8> {
    send(s, function, data);
    assert!(s.response().is_none(), "answered before it was stored");
    service(s, q);
    take(s)
}

fn words(pdu: &[u8]) -> Vec<u16> {
    pdu[2..]
        .chunks_exact(2)
        .map(|c| u16::from_be_bytes([c[0], c[1]]))
        .collect()
}

fn u32_at(w: &[u16], i: usize) -> u32 {
    u32::from(w[i]) << 16 | u32::from(w[i + 1])
}

fn input<E: Estimator>(s: &mut Server<E>, name: &str) -> u32 {
    let mut csv = String::new();
    misalign::modbus::registers_csv(&mut csv).unwrap();
    let row = csv
        .lines()
        .find(|l| l.starts_with("input,") && l.split(',').nth(2) == Some(name))
        .unwrap_or_else(|| panic!("{name} in the map"));
    let address: u16 = row.split(',').nth(1).unwrap().parse().unwrap();
    let [a, b] = address.to_be_bytes();
    u32_at(&words(&pdu(s, 4, &[a, b, 0, 2])), 0)
}

/// The request writing `event_ack` (holding 7, two registers) with `n`.
fn ack_request(n: u32) -> [u8; 9] {
    let [a, b, c, d] = n.to_be_bytes();
    [0, 7, 0, 2, 4, a, b, c, d]
}

/// Writes `event_ack`; the answer's PDU.
fn ack<E: Estimator>(s: &mut Server<E>, n: u32) -> Vec<u8> {
    pdu(s, 16, &ack_request(n))
}

/// Writes `event_ack` under store-and-forward; the answer's PDU.
fn ack_stored(s: &mut Server<Auto>, q: &mut Q, n: u32) -> Vec<u8> {
    write_stored(s, q, 16, &ack_request(n))
}

/// The master's read of the window under store-and-forward: `event_from` written (the
/// number after the last event it read, if any), then the events and the missed count.
fn read_window(s: &mut Server<Auto>, q: &mut Q, from: Option<u32>) -> (Vec<Event>, u32) {
    if let Some(from) = from {
        let [a, b, c, d] = from.to_be_bytes();
        assert_eq!(write_stored(s, q, 16, &[0, 0, 0, 2, 4, a, b, c, d])[0], 16);
    }
    let n = EVENT_SLOTS_ADDRESS - EVENT_WINDOW_ADDRESS + EVENT_SLOTS * EVENT_STRIDE;
    let [a, b] = EVENT_WINDOW_ADDRESS.to_be_bytes();
    let [c, d] = n.to_be_bytes();
    let w = words(&pdu(s, 4, &[a, b, c, d]));
    let slots = usize::from(EVENT_SLOTS_ADDRESS - EVENT_WINDOW_ADDRESS);
    let events = w[slots..]
        .chunks_exact(usize::from(EVENT_STRIDE))
        .map_while(|slot| event_from_registers(slot).unwrap())
        .collect();
    (events, u32_at(&w, 3))
}

/// The application's part after each sample or request: new events onto flash and
/// into the window, the master's acknowledgement made durable, the window fed from
/// flash while it is behind, the registers told, the held answer released.
fn service(s: &mut Server<Auto>, q: &mut Q) {
    while let Some(e) = s.pop_event() {
        block_on(q.push(e.seq, &e)).unwrap();
        s.offer_event(e);
    }
    if let Some(k) = s.acknowledged_through() {
        block_on(q.acknowledge(k)).unwrap();
    }
    while let Some(wanted) = s.wanted_event() {
        let mut found = None;
        block_on(q.read(wanted, |_, e| {
            found = Some(e);
            false
        }))
        .unwrap();
        match found {
            Some(e) if s.offer_stored_event(e) => {}
            Some(_) => break,
            None => s.end_backlog(),
        }
    }
    let st = q.state();
    s.set_storage_status(StorageStatus {
        events_acknowledged: st.acknowledged,
        events_stored: st.unacknowledged,
        events_overwritten: q.dropped(),
        ..s.storage_status()
    });
    s.stored(true);
}

fn open_queue(flash: Flash) -> Q {
    let mut q = Q::new(BlockingFlash(flash), 0..4096).unwrap();
    block_on(q.open()).unwrap();
    q
}

/// A start-up: the queue read through, the monitor from its checkpoint numbering after
/// the newest stored event, the server fed from flash.
fn boot(flash: Flash, checkpoint: &MonitorState) -> (Server<Auto>, Q) {
    let mut q = open_queue(flash);
    let mut state = *checkpoint;
    if let Some(n) = q.state().newest {
        state.continue_events_after(n);
    }
    let mut s = Server::new(monitor(Some(&state)), ServerConfig::default()).unwrap();
    s.store_events(q.state().first);
    service(&mut s, &mut q);
    (s, q)
}

#[test]
fn event_ack_takes_only_numbers_given_and_moves_event_from() {
    let mut s = Server::new(monitor(None), ServerConfig::default()).unwrap();
    // No event yet: nothing to acknowledge.
    assert_eq!(ack(&mut s, 0), [0x90, 3]);
    assert_eq!(s.acknowledged_through(), None);
    let mut i = 0;
    while s.monitor().next_event_seq() < 5 {
        s.process(sample(i));
        i += 1;
    }
    let next = s.monitor().next_event_seq();
    assert_eq!(ack(&mut s, next), [0x90, 3], "a number not yet given");
    assert_eq!(ack(&mut s, 2), [16, 0, 7, 0, 2]);
    assert_eq!(s.acknowledged_through(), Some(2));
    // event_from moved past it; event_ack reads back.
    assert_eq!(u32_at(&words(&pdu(&mut s, 3, &[0, 0, 0, 2])), 0), 3);
    assert_eq!(u32_at(&words(&pdu(&mut s, 3, &[0, 7, 0, 2])), 0), 2);
    // Half of it: 02.
    assert_eq!(pdu(&mut s, 6, &[0, 8, 0, 1]), [0x86, 2]);
    // The storage registers: none until the application says.
    assert_eq!(input(&mut s, "event_acked"), u32::MAX);
    assert_eq!(input(&mut s, "checkpoint_age"), u32::MAX);
    assert_eq!(input(&mut s, "checkpoints"), 0);
    let elapsed = s.monitor().elapsed_ms();
    s.set_storage_status(StorageStatus {
        events_acknowledged: Some(2),
        events_stored: 3,
        events_overwritten: 4,
        checkpoints: 9,
        last_checkpoint_ms: Some(elapsed - 2500),
    });
    assert_eq!(input(&mut s, "event_acked"), 2);
    assert_eq!(input(&mut s, "events_stored"), 3);
    assert_eq!(input(&mut s, "events_overwritten"), 4);
    assert_eq!(input(&mut s, "checkpoints"), 9);
    assert_eq!(input(&mut s, "checkpoint_age"), 2);
}

/// Only a number the node gave is acknowledged: on a fresh server none; after nine
/// events 0 to 8. A number never given is exception 03 and changes nothing, whether it
/// lies ahead or half the number space away (where a comparison modulo 2^32 alone
/// would read it as an old one).
#[test]
fn event_ack_refuses_every_number_never_given() {
    let mut s = Server::new(monitor(None), ServerConfig::default()).unwrap();
    for n in [
        0,
        1,
        9,
        0x7FFF_FFFF,
        0x8000_0000,
        0x9000_0000,
        0xFFFF_FFFE,
        u32::MAX,
    ] {
        assert_eq!(ack(&mut s, n), [0x90, 3], "{n:#x} on a fresh server");
    }
    assert_eq!(s.acknowledged_through(), None);
    let mut i = 0;
    while s.monitor().next_event_seq() < 9 {
        s.process(sample(i));
        i += 1;
    }
    assert_eq!(s.monitor().next_event_seq(), 9);
    let never = [
        9,
        10,
        0x8000_0000,
        0x8000_0008,
        0x8000_0009,
        0x9000_0000,
        u32::MAX,
    ];
    for n in never {
        assert_eq!(ack(&mut s, n), [0x90, 3], "{n:#x} after nine events");
    }
    assert_eq!(s.acknowledged_through(), None);
    assert_eq!(
        u32_at(&words(&pdu(&mut s, 3, &[0, 0, 0, 2])), 0),
        0,
        "event_from"
    );
    for n in 0..9 {
        assert_eq!(ack(&mut s, n), [16, 0, 7, 0, 2], "{n}");
        assert_eq!(s.acknowledged_through(), Some(n));
    }
    assert_eq!(
        u32_at(&words(&pdu(&mut s, 3, &[0, 0, 0, 2])), 0),
        9,
        "event_from"
    );
}

/// The event window's header after writing `event_from`: event_first, event_count,
/// events_missed, and the discrete input event_available.
fn window_from(s: &mut Server<Auto>, from: u32) -> (u32, u16, u32, bool) {
    let [a, b, c, d] = from.to_be_bytes();
    assert_eq!(pdu(s, 16, &[0, 0, 0, 2, 4, a, b, c, d])[0], 16);
    let [x, y] = EVENT_WINDOW_ADDRESS.to_be_bytes();
    let w = words(&pdu(s, 4, &[x, y, 0, 5]));
    let available = pdu(s, 2, &[0, 9, 0, 1])[2] & 1 != 0;
    (u32_at(&w, 0), w[2], u32_at(&w, 3), available)
}

/// `event_from` at a number never given shows nothing (the events after it are none
/// yet), and misses nothing; at a number given, the events from it. Around the wrap of
/// the numbering the same, on both sides of it.
#[test]
fn event_from_at_a_number_never_given_shows_nothing() {
    for start in [0, u32::MAX - 4] {
        let state = numbering_from(start);
        let mut s = Server::new(monitor(Some(&state)), ServerConfig::default()).unwrap();
        let mut i = 0;
        while s.monitor().next_event_seq() != start.wrapping_add(9) {
            s.process(sample(i));
            i += 1;
        }
        let next = s.monitor().next_event_seq();
        for never in [next, next + 1, next + 1000, next.wrapping_add(0x7FFF_FFFF)] {
            assert_eq!(
                window_from(&mut s, never),
                (next, 0, 0, false),
                "{start:#x} {never:#x}"
            );
        }
        // Fresh numbers from 0 on: those below 0x8000_0000 behind the newest are not
        // given either.
        if start == 0 {
            for never in [0x9000_0000, 0xFFFF_FFF0, u32::MAX] {
                assert_eq!(
                    window_from(&mut s, never),
                    (next, 0, 0, false),
                    "{never:#x}"
                );
            }
        }
        // The last four, from the first of them.
        let first = next.wrapping_sub(4);
        assert_eq!(window_from(&mut s, first), (first, 4, 0, true));
        // The window holds eight of the nine: the first one missed.
        assert_eq!(
            window_from(&mut s, start),
            (start.wrapping_add(1), 4, 1, true)
        );
        assert_eq!(
            window_from(&mut s, next.wrapping_sub(1)),
            (next.wrapping_sub(1), 1, 0, true)
        );
        // Acknowledged on both sides of the wrap; one ahead refused.
        assert_eq!(ack(&mut s, start), [16, 0, 7, 0, 2]);
        assert_eq!(ack(&mut s, next.wrapping_sub(1)), [16, 0, 7, 0, 2]);
        assert_eq!(ack(&mut s, next), [0x90, 3]);
    }
}

/// Events raised while the master reads slowly, resets between, the master
/// acknowledging what it read: every event read once, in order, with its own number,
/// none missed, none acknowledged read again.
#[test]
fn every_event_is_read_once_in_order_across_resets_and_beyond_the_window() {
    read_once_in_order_from(0);
}

/// The same across the wrap of the numbering (modulo 2^32): the events numbered from
/// just below 2^32 on, through 0.
#[test]
fn every_event_is_read_once_in_order_across_the_numbers_wrap() {
    read_once_in_order_from(u32::MAX - 20);
}

/// The master's reads and acknowledgements against the node's resets and bursts, the
/// monitor numbering its events from `start`.
fn read_once_in_order_from(start: u32) {
    let mut checkpoint = numbering_from(start);
    let (mut s, mut q) = boot(Flash::new(), &checkpoint);
    let mut read: Vec<u32> = Vec::new();
    let mut i = 0u32;
    let mut resets = 0;
    for round in 0..40u32 {
        // A burst of samples: several windows' worth of events when the round says.
        let burst = if round % 5 == 2 { 40 } else { 3 };
        for _ in 0..burst {
            s.process(sample(i));
            service(&mut s, &mut q);
            i += 1;
        }
        // The master: reads the window twice, acknowledges what it read.
        for _ in 0..2 {
            let from = read.last().map(|l| l.wrapping_add(1)).or(Some(start));
            let (events, missed) = read_window(&mut s, &mut q, from);
            assert_eq!(missed, 0, "round {round}");
            for e in &events {
                if let Some(&last) = read.last() {
                    let next = last.wrapping_add(1);
                    assert_eq!(e.seq, next, "round {round}: in order, none missed");
                }
                read.push(e.seq);
            }
            if let Some(last) = events.last() {
                assert_eq!(ack_stored(&mut s, &mut q, last.seq)[0], 16);
            }
        }
        // A reset every few rounds, from a checkpoint taken then or one older (its
        // numbering behind the events stored since).
        if round % 3 == 1 {
            if round % 2 == 0 {
                checkpoint = s.monitor().snapshot();
            }
            drop(s);
            let flash = q.into_flash().0;
            (s, q) = boot(flash, &checkpoint);
            resets += 1;
            assert_eq!(
                input(&mut s, "event_acked"),
                *read.last().unwrap_or(&u32::MAX)
            );
        }
    }
    // Drain what is left.
    loop {
        let (events, _) = read_window(&mut s, &mut q, read.last().map(|l| l.wrapping_add(1)));
        let Some(last) = events.last() else { break };
        for e in &events {
            assert_eq!(e.seq, read.last().map_or(start, |l| l.wrapping_add(1)));
            read.push(e.seq);
        }
        ack_stored(&mut s, &mut q, last.seq);
    }
    let raised = s.monitor().next_event_seq().wrapping_sub(start);
    let numbers: Vec<u32> = (0..raised).map(|k| start.wrapping_add(k)).collect();
    assert_eq!(read, numbers);
    assert!(
        raised as usize > 4 * EVENT_WINDOW && resets > 10,
        "{raised} events"
    );
    eprintln!("{raised} events read through {resets} resets");
    assert_eq!(q.state().unacknowledged, 0);
    assert_eq!(q.dropped(), 0);
}

type StateFlash = MockFlash<4, 4096, 4>;
type States = Store<BlockingFlash<StateFlash>, 1024>;

/// The monitor's state checkpointed at each event and once a minute, restored at
/// start-up; `checkpoints` and `checkpoint_age` say which and how old.
#[test]
fn checkpoints_at_each_event_and_periodically_show_in_the_map() {
    let mut states = States::new(BlockingFlash(StateFlash::new()), 0..4 * 4096, 60).unwrap();
    let mut q = open_queue(Flash::new());
    let mut s = Server::new(monitor(None), ServerConfig::default()).unwrap();
    s.store_events(None);
    let mut written = 0u32;
    for i in 0..400u32 {
        // Faults in the first 40 samples only: then a quiet run, periodic checkpoints.
        let x = if i < 40 { sample(i) } else { sample(4 * i) };
        let x = Sample {
            time_ms: i * 1000,
            ..x
        };
        let before = s.monitor().next_event_seq();
        s.process(x);
        service(&mut s, &mut q);
        let state = s.monitor().snapshot();
        let now_ms = s.monitor().elapsed_ms();
        let done = if s.monitor().next_event_seq() != before {
            Some(block_on(states.checkpoint(&state)).unwrap())
        } else {
            block_on(states.checkpoint_if_due(now_ms / 1000, &state)).unwrap()
        };
        let mut status = s.storage_status();
        if let Some(n) = done {
            written += 1;
            status.checkpoints = n;
            status.last_checkpoint_ms = Some(now_ms);
        }
        s.set_storage_status(status);
        assert_eq!(input(&mut s, "checkpoints"), written);
        // None yet (the first event comes once the conditioning has settled): all ones.
        let age = status
            .last_checkpoint_ms
            .map_or(u32::MAX, |t| ((now_ms - t) / 1000) as u32);
        assert_eq!(input(&mut s, "checkpoint_age"), age);
    }
    let events = s.monitor().next_event_seq();
    // One at each event and one a minute between (the first call starts the period).
    assert!(
        written >= events && written < events + 400 / 60 + 1,
        "{written}"
    );
    assert!(input(&mut s, "checkpoint_age") > 0);
    // A reset: the newest checkpoint restored, its number shown, its age 0.
    let mut states = States::new(states.into_flash(), 0..4 * 4096, 60).unwrap();
    let mut state = MonitorState::default();
    let outcome = block_on(states.restore_into(&mut state)).unwrap();
    assert_eq!(outcome, RestoreOutcome::Restored { sequence: written });
    let mut s = Server::new(monitor(Some(&state)), ServerConfig::default()).unwrap();
    s.set_storage_status(StorageStatus {
        checkpoints: written,
        last_checkpoint_ms: Some(state.elapsed_ms()),
        ..StorageStatus::default()
    });
    assert_eq!(input(&mut s, "checkpoints"), written);
    assert_eq!(input(&mut s, "checkpoint_age"), 0);
}

/// A master that stays away while the flash fills: the oldest unacknowledged events
/// are dropped from flash, counted in `events_overwritten`; the master then reads on
/// in order, the gap it finds (`events_missed`) no larger than that count, and never
/// an event twice or out of order.
#[test]
fn a_full_flash_drops_the_oldest_and_the_master_sees_the_gap() {
    let mut q = Q::new(BlockingFlash(Flash::new()), 0..2048).unwrap();
    block_on(q.open()).unwrap();
    let mut s = Server::new(monitor(None), ServerConfig::default()).unwrap();
    s.store_events(None);
    let mut i = 0;
    while s.monitor().next_event_seq() < 80 {
        s.process(sample(i));
        service(&mut s, &mut q);
        i += 1;
    }
    let overwritten = input(&mut s, "events_overwritten");
    assert!(overwritten > 0 && overwritten == q.dropped());
    assert_eq!(input(&mut s, "events_stored"), q.state().unacknowledged);
    let (mut gaps, mut last) = (0, None::<u32>);
    loop {
        let expected = last.map_or(0, |l| l + 1);
        let (events, missed) = read_window(&mut s, &mut q, last.map(|l| l + 1));
        // The gap before slot 0 is the one counted as missed.
        if let Some(first) = events.first() {
            assert_eq!(missed, first.seq - expected);
        }
        let Some(newest) = events.last().map(|e| e.seq) else {
            break;
        };
        for e in &events {
            // In order, once; a jump in the numbers where flash dropped events.
            let expected = last.map_or(0, |l| l + 1);
            assert!(e.seq >= expected, "in order, once");
            gaps += e.seq - expected;
            last = Some(e.seq);
        }
        assert_eq!(ack_stored(&mut s, &mut q, newest)[0], 16);
    }
    assert_eq!(last, Some(s.monitor().next_event_seq() - 1));
    // The numbers jump by no more than flash dropped (some of those the window still
    // held in RAM, and the master read).
    assert!(gaps > 0 && gaps <= overwritten, "{gaps} of {overwritten}");
    assert_eq!(input(&mut s, "events_stored"), 0);
}

/// Under store-and-forward a write is answered only once the application has stored
/// what it changed: a master that has the answer has it on flash. A write the storage
/// failed is answered with exception 04; reads are answered at once.
#[test]
fn a_write_is_answered_once_stored() {
    let (mut s, mut q) = boot(Flash::new(), &monitor(None).snapshot());
    let mut i = 0;
    while s.monitor().next_event_seq() < 3 {
        s.process(sample(i));
        service(&mut s, &mut q);
        i += 1;
    }
    // A read: at once.
    assert_eq!(pdu(&mut s, 3, &[0, 7, 0, 2])[0], 3);
    // The acknowledgement: held until stored, then on flash when answered.
    send(&mut s, 16, &ack_request(1));
    assert!(s.response().is_none());
    assert_eq!(q.state().acknowledged, None);
    service(&mut s, &mut q);
    assert_eq!(q.state().acknowledged, Some(1));
    assert_eq!(take(&mut s), [16, 0, 7, 0, 2]);
    // A failed store: exception 04, counted.
    let exceptions = s.counters().exceptions;
    send(&mut s, 16, &ack_request(2));
    assert!(s.response().is_none());
    s.stored(false);
    assert_eq!(take(&mut s), [0x90, 4]);
    assert_eq!(s.counters().exceptions, exceptions + 1);
    // An exception stays itself: a number not yet given is 03.
    send(&mut s, 16, &ack_request(1000));
    s.stored(false);
    assert_eq!(take(&mut s), [0x90, 3]);
    // Without store-and-forward every answer is due at once.
    let mut plain = Server::new(monitor(None), ServerConfig::default()).unwrap();
    assert_eq!(pdu(&mut plain, 16, &[0, 0, 0, 2, 4, 0, 0, 0, 0])[0], 16);
}
