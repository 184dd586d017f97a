//! The storage layer (`misalign::storage`) on the mock NOR flash: the record codec and
//! its versions, power loss at every byte written and every word erased during a
//! checkpoint, garbage and foreign data, a full region, wrap-around, and the wear
//! figures of the docs.
//!
//! `MISALIGN_POWER_LOSS=full` sweeps every checkpoint of three turns of the ring
//! instead of the default's four chosen ones (the first write on a blank flash; beside
//! a stored calibration, the first, the first that closes a sector, the first that
//! erases one), and a second power loss at every point of each recovery from the
//! chosen ones (about 25 s; the default takes well under a second).

use misalign::storage::codec::{self, CodecError, Decoded};
use misalign::storage::endurance::{self, Geometry};
use misalign::storage::kind;
use misalign::storage::{
    BlockingFlash, Checkpoint, MockError, MockFlash, Reader, Restore, RestoreOutcome, StorageError,
    StorageEvent, Store, StoreConfigError, Writer, block_on,
};

// ---------------------------------------------------------------------------------
// A stand-in for the monitor's state: energies and times per state, counters, the
// last events, a friction baseline. Version 2; version 1 had no baseline.

#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Event {
    at_s: u32,
    code: u8,
    value: f32,
}

#[derive(Debug, Clone, PartialEq)]
struct State {
    energy_j: [f64; 4],
    time_s: [u32; 4],
    samples: u32,
    alarms: u32,
    events: [Event; 3],
    baseline_mu: Option<f64>,
}

const EVENTS_SIZE: usize = 3 * (4 + 1 + 4);
const V1_SIZE: usize = 4 * 8 + 4 * 4 + 4 + 4 + EVENTS_SIZE;

fn put_common(s: &State, w: &mut Writer<'_>) -> Result<(), CodecError> {
    w.each(&s.energy_j, |w, e| w.f64(*e))?;
    w.each(&s.time_s, |w, t| w.u32(*t))?;
    w.u32(s.samples)?;
    w.u32(s.alarms)?;
    w.each(&s.events, |w, e| {
        w.u32(e.at_s)?;
        w.u8(e.code)?;
        w.f32(e.value)
    })
}

fn get_common(r: &mut Reader<'_>) -> Result<State, CodecError> {
    let energy_j: [f64; 4] = r.array_of(|r| r.f64())?;
    if energy_j.iter().any(|e| !(e.is_finite() && *e >= 0.0)) {
        return Err(CodecError::InvalidValue);
    }
    Ok(State {
        energy_j,
        time_s: r.array_of(|r| r.u32())?,
        samples: r.u32()?,
        alarms: r.u32()?,
        events: r.array_of(|r| {
            Ok(Event {
                at_s: r.u32()?,
                code: r.u8()?,
                value: r.f32()?,
            })
        })?,
        baseline_mu: None,
    })
}

impl Checkpoint for State {
    const KIND: u8 = kind::MONITOR_STATE;
    const VERSION: u16 = 2;
    const SIZE: usize = V1_SIZE + 1 + 8;

    fn encode(&self, w: &mut Writer<'_>) -> Result<(), CodecError> {
        put_common(self, w)?;
        w.bool(self.baseline_mu.is_some())?;
        w.f64(self.baseline_mu.unwrap_or(0.0))
    }

    fn decode(r: &mut Reader<'_>) -> Result<Self, CodecError> {
        let mut s = get_common(r)?;
        let known = r.bool()?;
        let mu = r.f64()?;
        s.baseline_mu = known.then_some(mu);
        Ok(s)
    }

    fn migrate(version: u16, r: &mut Reader<'_>) -> Result<Self, CodecError> {
        match version {
            // Version 1: no friction baseline yet; it is learned again.
            1 => get_common(r),
            _ => Err(CodecError::UnsupportedVersion { version }),
        }
    }
}

/// What the firmware of format version 1 wrote (kept to write version-1 records).
struct StateV1(State);

impl Checkpoint for StateV1 {
    const KIND: u8 = kind::MONITOR_STATE;
    const VERSION: u16 = 1;
    const SIZE: usize = V1_SIZE;

    fn encode(&self, w: &mut Writer<'_>) -> Result<(), CodecError> {
        put_common(&self.0, w)
    }

    fn decode(r: &mut Reader<'_>) -> Result<Self, CodecError> {
        get_common(r).map(StateV1)
    }
}

/// A future firmware's format (version 3), to test a downgrade.
struct StateV3(State);

impl Checkpoint for StateV3 {
    const KIND: u8 = kind::MONITOR_STATE;
    const VERSION: u16 = 3;
    const SIZE: usize = State::SIZE + 4;

    fn encode(&self, w: &mut Writer<'_>) -> Result<(), CodecError> {
        self.0.encode(w)?;
        w.u32(0xDEAD_BEEF)
    }

    fn decode(r: &mut Reader<'_>) -> Result<Self, CodecError> {
        let s = State::decode(r)?;
        r.u32()?;
        Ok(StateV3(s))
    }
}

/// Which checkpoint a state is (see [`state`]).
fn which(s: &State) -> u32 {
    s.time_s[2]
}

/// The state after `n` checkpoints: each value tells which checkpoint it is.
fn state(n: u32) -> State {
    let k = f64::from(n);
    State {
        energy_j: [k * 1.5, k * 0.25 + 1e-3, k * k, 1e6 + k],
        time_s: [n.wrapping_mul(60), n.wrapping_mul(7), n, 3],
        samples: n.wrapping_mul(1000),
        alarms: n / 3,
        events: [
            Event {
                at_s: n,
                code: (n % 7) as u8,
                value: n as f32 * 0.5,
            },
            Event {
                at_s: n.saturating_sub(1),
                code: 2,
                value: -1.0,
            },
            Event::default(),
        ],
        baseline_mu: n.is_multiple_of(2).then_some(0.3 + k * 1e-3),
    }
}

// ---------------------------------------------------------------------------------
// The flash: 4 sectors of 1 KiB, 4-byte words (8 checkpoints of `State` a sector).

const SECTORS: usize = 4;
const SECTOR: usize = 1024;
const WORD: usize = 4;
type Flash = MockFlash<SECTORS, SECTOR, WORD>;
const BUF: usize = 128;
type S = Store<BlockingFlash<Flash>, BUF>;
const INTERVAL_S: u32 = 60;

fn open(flash: Flash) -> S {
    Store::new(
        BlockingFlash(flash),
        0..(SECTORS * SECTOR) as u32,
        INTERVAL_S,
    )
    .unwrap()
}

/// A start-up: a store on the flash and its restore of `State`.
fn boot(flash: Flash) -> (S, Restore<State>) {
    // `restore_into` on a copy of the flash must find the same and count the same.
    let mut twin = open(flash.clone());
    let mut store = open(flash);
    let restored = block_on(store.restore::<State>()).unwrap();
    let mut value = state(0);
    let outcome = block_on(twin.restore_into(&mut value)).unwrap();
    assert_eq!(outcome, restored.outcome);
    if let Some(v) = &restored.value {
        assert_eq!(&value, v);
    }
    assert_eq!(twin.stats(), store.stats());
    (store, restored)
}

fn flash_of(store: S) -> Flash {
    store.into_flash().0
}

/// A flash holding checkpoints 1..=n of `state`.
fn written(n: u32) -> Flash {
    let (mut store, _) = boot(Flash::new());
    for i in 1..=n {
        assert_eq!(block_on(store.checkpoint(&state(i))).unwrap(), i);
    }
    flash_of(store)
}

/// Splitmix64: the garbage of the tests, repeatable.
fn rng(seed: u64) -> impl FnMut() -> u8 {
    let mut x = seed;
    move || {
        x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = x;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        (z ^ (z >> 31)) as u8
    }
}

// ---------------------------------------------------------------------------------
// The codec.

#[test]
fn crc32_is_zlibs() {
    // The check value of CRC-32/ISO-HDLC (zlib's crc32).
    assert_eq!(codec::crc32(b"123456789"), 0xCBF4_3926);
    assert_eq!(codec::crc32(b""), 0);
}

/// A storage error says what failed and chains the record's or the configuration's
/// error as its source, with no feature (`core::error::Error`).
#[test]
fn storage_errors_chain_their_cause() {
    use std::error::Error as _;
    let codec = StorageError::<MockError>::Codec(CodecError::Checksum);
    let source = codec.source().expect("a record error is the source");
    assert_eq!(source.downcast_ref(), Some(&CodecError::Checksum));
    assert_eq!(codec.to_string(), "record: record checksum mismatch");
    let config = StorageError::<MockError>::Config(StoreConfigError::TooSmall);
    assert_eq!(
        config.source().and_then(|e| e.downcast_ref()),
        Some(&StoreConfigError::TooSmall)
    );
    let flash = StorageError::Flash(MockError::PowerLoss);
    assert!(flash.source().is_none());
    assert_eq!(
        flash.to_string(),
        "flash error: PowerLoss",
        "the driver's error by its Debug form"
    );
}

#[test]
fn records_round_trip_bit_for_bit() {
    for n in [0, 1, 2, 17, u32::MAX] {
        let mut buf = [0u8; BUF];
        let len = codec::encode(&state(n), n, &mut buf).unwrap();
        assert_eq!(len, codec::record_len(State::SIZE));
        let d: Decoded<State> = codec::decode(&buf[..len]).unwrap();
        assert_eq!((d.value, d.sequence, d.version), (state(n), n, 2));
    }
    // f64 fields come back bit for bit, -0.0 and subnormals included.
    let mut s = state(3);
    s.energy_j = [0.0, f64::MIN_POSITIVE / 4.0, f64::MAX, 1.0 / 3.0];
    s.events[0].value = -0.0;
    let mut buf = [0u8; BUF];
    let len = codec::encode(&s, 9, &mut buf).unwrap();
    let back: State = codec::decode(&buf[..len]).unwrap().value;
    assert_eq!(back.events[0].value.to_bits(), (-0.0f32).to_bits());
    assert_eq!(back, s);
}

#[test]
fn encode_refuses_a_short_buffer() {
    let mut buf = [0u8; 40];
    assert_eq!(
        codec::encode(&state(1), 1, &mut buf),
        Err(CodecError::BufferTooSmall {
            needed: codec::record_len(State::SIZE)
        })
    );
}

/// Every single-bit flip of a record, every truncation and every extension is refused:
/// a damaged record never decodes to a value.
#[test]
fn damaged_records_never_decode() {
    let mut buf = [0u8; BUF];
    let len = codec::encode(&state(5), 5, &mut buf).unwrap();
    let record = &buf[..len];
    for bit in 0..len * 8 {
        let mut bad = record.to_vec();
        bad[bit / 8] ^= 1 << (bit % 8);
        let got = codec::decode::<State>(&bad);
        assert!(got.is_err(), "bit {bit} flipped decoded to {got:?}");
    }
    for cut in 0..len {
        assert!(
            codec::decode::<State>(&record[..cut]).is_err(),
            "cut at {cut}"
        );
    }
    let mut longer = record.to_vec();
    longer.push(0);
    assert_eq!(codec::decode::<State>(&longer), Err(CodecError::Length));
    // Random bytes: foreign.
    let mut next = rng(7);
    for _ in 0..1000 {
        let junk: Vec<u8> = (0..len).map(|_| next()).collect();
        assert!(codec::decode::<State>(&junk).is_err());
    }
}

#[test]
fn values_the_type_refuses_are_not_restored() {
    let mut s = state(4);
    s.energy_j[2] = f64::NAN;
    let mut buf = [0u8; BUF];
    let len = codec::encode(&s, 4, &mut buf).unwrap();
    assert_eq!(
        codec::decode::<State>(&buf[..len]),
        Err(CodecError::InvalidValue)
    );
}

/// A version-1 record, as the version-1 firmware wrote it (frozen: if this changes,
/// the fleet's flash no longer matches what the code reads).
const V1_RECORD: &str = "\
4d534c4701010100530000002a000000000000000000004000000000000014400000000000003040\
000000000000c03f100e00003c00000001000000030000004a0000000a000000b004000004000040\
3f3d00000001000020c00000000000000000009eff2181";

fn hex(s: &str) -> Vec<u8> {
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
        .collect()
}

fn v1_fixture_state() -> State {
    State {
        energy_j: [2.0, 5.0, 16.0, 0.125],
        time_s: [3600, 60, 1, 3],
        samples: 74,
        alarms: 10,
        events: [
            Event {
                at_s: 1200,
                code: 4,
                value: 0.75,
            },
            Event {
                at_s: 61,
                code: 1,
                value: -2.5,
            },
            Event::default(),
        ],
        baseline_mu: None,
    }
}

#[test]
fn the_version_1_encoder_still_writes_the_frozen_record() {
    let mut buf = [0u8; BUF];
    let len = codec::encode(&StateV1(v1_fixture_state()), 42, &mut buf).unwrap();
    assert_eq!(buf[..len].to_vec(), hex(V1_RECORD));
}

/// A newer firmware reads the older format: the frozen version-1 record decodes into
/// the version-2 type, the new field at its "unknown" value.
#[test]
fn newer_firmware_reads_the_older_format() {
    let d = codec::decode::<State>(&hex(V1_RECORD)).unwrap();
    assert_eq!((d.sequence, d.version), (42, 1));
    assert_eq!(d.value, v1_fixture_state());

    // And through the flash: a version-1 firmware's checkpoints, restored by version 2.
    let (mut old, _) = boot(Flash::new());
    for i in 1..=5 {
        block_on(old.checkpoint(&StateV1(state(i)))).unwrap();
    }
    let (mut new, restored) = boot(flash_of(old));
    let mut expected = state(5);
    expected.baseline_mu = None;
    assert_eq!(restored.value, Some(expected));
    assert_eq!(
        restored.outcome,
        RestoreOutcome::Migrated {
            sequence: 5,
            from_version: 1
        }
    );
    // It goes on in the new format.
    assert_eq!(block_on(new.checkpoint(&state(6))).unwrap(), 6);
    let (_, restored) = boot(flash_of(new));
    assert_eq!(restored.value, Some(state(6)));
    assert_eq!(restored.outcome, RestoreOutcome::Restored { sequence: 6 });
}

#[test]
fn an_older_firmware_refuses_a_newer_format() {
    let (mut future, _) = boot(Flash::new());
    block_on(future.checkpoint(&StateV3(state(8)))).unwrap();
    let (mut store, restored) = boot(flash_of(future));
    assert_eq!(restored.value, None);
    assert_eq!(
        restored.outcome,
        RestoreOutcome::Rejected(StorageEvent::NewerVersion { version: 3 })
    );
    assert_eq!(store.stats().rejected, 1);
    // A fresh state checkpoints over it.
    block_on(store.checkpoint(&state(1))).unwrap();
    assert_eq!(boot(flash_of(store)).1.value, Some(state(1)));
}

/// A type whose `encode` writes `W` bytes but declares `SIZE = 8`: a programming error,
/// caught as a typed error at the first checkpoint, with nothing written.
struct Liar<const W: usize>;

impl<const W: usize> Checkpoint for Liar<W> {
    const KIND: u8 = 9;
    const VERSION: u16 = 1;
    const SIZE: usize = 8;

    fn encode(&self, w: &mut Writer<'_>) -> Result<(), CodecError> {
        w.bytes(&[0; W])
    }

    fn decode(r: &mut Reader<'_>) -> Result<Self, CodecError> {
        r.array::<8>().map(|_| Liar)
    }
}

#[test]
fn an_encode_that_breaks_its_size_is_a_typed_error() {
    let (mut store, _) = boot(Flash::new());
    assert_eq!(
        block_on(store.checkpoint(&Liar::<4>)),
        Err(StorageError::Codec(CodecError::TrailingBytes))
    );
    assert_eq!(
        block_on(store.checkpoint(&Liar::<12>)),
        Err(StorageError::Codec(CodecError::Truncated))
    );
    assert_eq!(store.stats().failed_checkpoints, 2);
    let (_, restored) = boot(flash_of(store));
    assert_eq!(restored.outcome, RestoreOutcome::Blank);
}

// ---------------------------------------------------------------------------------
// The store: configuration, schedule, restarts.

#[test]
fn bad_configurations_are_typed_errors() {
    let bad = |range: core::ops::Range<u32>, interval| {
        Store::<_, BUF>::new(BlockingFlash(Flash::new()), range, interval).err()
    };
    assert_eq!(bad(0..4096, 0), Some(StoreConfigError::ZeroInterval));
    assert_eq!(bad(100..4096, 60), Some(StoreConfigError::Unaligned));
    assert_eq!(bad(0..1024, 60), Some(StoreConfigError::TooSmall));
    assert_eq!(bad(0..8192, 60), Some(StoreConfigError::OutOfBounds));
    assert_eq!(bad(0..4096, 60), None);

    // A buffer too small for the record: a typed error, on restore and on checkpoint.
    let mut small = Store::<_, 64>::new(BlockingFlash(Flash::new()), 0..4096, 60).unwrap();
    let needed = Store::<BlockingFlash<Flash>, 64>::buffer_len::<State>();
    assert_eq!(needed, 116);
    assert_eq!(
        block_on(small.restore::<State>()),
        Err(StorageError::BufferTooSmall { needed })
    );
    assert_eq!(
        block_on(small.checkpoint(&state(1))),
        Err(StorageError::BufferTooSmall { needed })
    );
}

#[test]
fn blank_flash_is_a_first_start() {
    let (store, restored) = boot(Flash::new());
    assert_eq!(restored.value, None);
    assert_eq!(restored.outcome, RestoreOutcome::Blank);
    assert_eq!(store.stats().rejected, 0);
    assert_eq!(store.next_sequence(), 1);
}

#[test]
fn checkpoints_follow_the_interval_and_on_demand() {
    let (mut store, _) = boot(Flash::new());
    // The first call starts the interval.
    assert_eq!(block_on(store.checkpoint_if_due(1000, &state(1))), Ok(None));
    assert_eq!(block_on(store.checkpoint_if_due(1059, &state(1))), Ok(None));
    assert_eq!(
        block_on(store.checkpoint_if_due(1060, &state(1))),
        Ok(Some(1))
    );
    assert_eq!(block_on(store.checkpoint_if_due(1100, &state(2))), Ok(None));
    // On demand, between intervals.
    assert_eq!(block_on(store.checkpoint(&state(2))), Ok(2));
    assert_eq!(
        block_on(store.checkpoint_if_due(1120, &state(3))),
        Ok(Some(3))
    );
    assert_eq!(store.stats().checkpoints, 3);
    let (mut store, restored) = boot(flash_of(store));
    assert_eq!(restored.value, Some(state(3)));
    // The numbering goes on after a restart.
    assert_eq!(store.next_sequence(), 4);
    // A new interval applies to the interval under way; zero is refused.
    assert_eq!(store.set_interval_s(0), Err(StoreConfigError::ZeroInterval));
    assert_eq!(store.interval_s(), INTERVAL_S);
    store.set_interval_s(10).unwrap();
    assert_eq!(block_on(store.checkpoint_if_due(5000, &state(4))), Ok(None));
    assert_eq!(block_on(store.checkpoint_if_due(5009, &state(4))), Ok(None));
    assert_eq!(
        block_on(store.checkpoint_if_due(5010, &state(4))),
        Ok(Some(4))
    );
    // Erasing on purpose empties the region.
    block_on(store.erase()).unwrap();
    assert_eq!(boot(flash_of(store)).1.outcome, RestoreOutcome::Blank);
}

// ---------------------------------------------------------------------------------
// Power loss.

/// Power-loss points (bytes written + words erased) checkpoint `n` consumes on `base`
/// (which holds checkpoints 1..n), and how many of them are erased words.
fn points_of(base: &Flash, n: u32) -> (u64, u64) {
    let (mut store, restored) = boot(base.clone());
    assert_eq!(
        restored.value.as_ref(),
        (n > 1).then(|| state(n - 1)).as_ref()
    );
    block_on(store.checkpoint(&state(n))).unwrap();
    let flash = flash_of(store);
    let erases = |f: &Flash| f.erase_counts().iter().sum::<u32>();
    let erased_words = u64::from(erases(&flash) - erases(base)) * (SECTOR / WORD) as u64;
    (flash.points() - base.points(), erased_words)
}

/// The sensors' calibration, stored once in the same region as the state (kind 2):
/// the map copies it forward each time the sector holding it is recycled.
#[derive(Debug, Clone, PartialEq)]
struct Calibration {
    offset: [f32; 3],
    gain: [f32; 3],
    serial: u32,
}

impl Checkpoint for Calibration {
    const KIND: u8 = kind::CALIBRATION;
    const VERSION: u16 = 1;
    const SIZE: usize = 6 * 4 + 4;

    fn encode(&self, w: &mut Writer<'_>) -> Result<(), CodecError> {
        w.each(&self.offset, |w, x| w.f32(*x))?;
        w.each(&self.gain, |w, x| w.f32(*x))?;
        w.u32(self.serial)
    }

    fn decode(r: &mut Reader<'_>) -> Result<Self, CodecError> {
        Ok(Calibration {
            offset: r.array_of(|r| r.f32())?,
            gain: r.array_of(|r| r.f32())?,
            serial: r.u32()?,
        })
    }
}

fn calibration() -> Calibration {
    Calibration {
        offset: [0.01, -0.02, 0.5],
        gain: [1.001, 0.998, 1.0],
        serial: 0x00C0_FFEE,
    }
}

/// A blank flash, or one holding the calibration only.
fn base(calibrated: bool) -> Flash {
    let (mut store, _) = boot(Flash::new());
    if calibrated {
        block_on(store.checkpoint(&calibration())).unwrap();
    }
    flash_of(store)
}

fn assert_calibration(store: &mut S, calibrated: bool, what: &str) {
    let got = block_on(store.restore::<Calibration>()).unwrap();
    let expected = calibrated.then(calibration);
    assert_eq!(got.value, expected, "{what}: calibration");
}

/// Cuts the power at every point of checkpoint `n` (`base` holds 1..n, and the
/// calibration if `calibrated`), restarts and restores: exactly checkpoint n - 1 or n,
/// never anything else, and the calibration intact; then the store goes on. Returns
/// the points swept.
fn sweep(base: &Flash, n: u32, calibrated: bool, second_faults: bool) -> (u64, u64) {
    let (points, _) = points_of(base, n);
    let mut first_write_rejects = 0;
    let mut second_points = 0;
    for p in 0..points {
        let what = format!("checkpoint {n}, point {p}, calibrated {calibrated}");
        let mut flash = base.clone();
        flash.cut_after(p);
        let (mut store, before) = boot(flash);
        assert_eq!(
            before.value.as_ref(),
            (n > 1).then(|| state(n - 1)).as_ref()
        );
        let cut = block_on(store.checkpoint(&state(n)));
        assert_eq!(
            cut,
            Err(StorageError::Flash(MockError::PowerLoss)),
            "{what}"
        );
        let mut flash = flash_of(store);
        assert!(flash.is_off());
        flash.restart();
        if second_faults {
            second_points += sweep_recovery(&flash, calibrated, &what);
        }

        let (mut store, after) = boot(flash);
        match after.outcome {
            RestoreOutcome::Restored { .. } => {}
            RestoreOutcome::Blank if n == 1 => {}
            // A cut in the very first checkpoint on a blank region leaves a region
            // that is neither blank nor holds a record, as foreign data does:
            // reported, erased, nothing restored, which is the previous state (none).
            RestoreOutcome::Rejected(StorageEvent::ForeignRegion) if n == 1 && !calibrated => {
                first_write_rejects += 1;
            }
            other => panic!("{what}: {other:?}"),
        }
        // Which checkpoint came back (0: none), and it is whole.
        let got = after.value.as_ref().map_or(0, which);
        assert!(got == n || got + 1 == n, "{what}: restored {got}");
        if got > 0 {
            assert_eq!(after.value, Some(state(got)), "{what}");
        }
        assert_calibration(&mut store, calibrated, &what);
        // The store goes on after the loss.
        block_on(store.checkpoint(&state(got + 1)))
            .unwrap_or_else(|e| panic!("{what}: after restart {e:?}"));
        let (mut store, again) = boot(flash_of(store));
        assert_eq!(again.value, Some(state(got + 1)), "{what}");
        assert_calibration(&mut store, calibrated, &what);
    }
    if first_write_rejects > 0 {
        eprintln!("checkpoint 1: {first_write_rejects} of {points} cuts reported as foreign");
    }
    (points, second_points)
}

/// A second power loss at every point of the recovery from a first one (the restores,
/// then the next checkpoint): the restart after it restores the checkpoint the first
/// restart restored, or the recovery's new one, and the calibration intact.
fn sweep_recovery(after_cut: &Flash, calibrated: bool, what: &str) -> u64 {
    let (mut store, first) = boot(after_cut.clone());
    let got = first.value.as_ref().map_or(0, which);
    block_on(store.restore::<Calibration>()).unwrap();
    block_on(store.checkpoint(&state(got + 1))).unwrap();
    let points = flash_of(store).points() - after_cut.points();
    for q in 0..points {
        let what = format!("{what}, second cut {q}");
        let mut flash = after_cut.clone();
        flash.cut_after(q);
        let mut store = open(flash);
        let recovery = block_on(async {
            store.restore::<State>().await?;
            store.restore::<Calibration>().await?;
            store.checkpoint(&state(got + 1)).await
        });
        assert_eq!(
            recovery,
            Err(StorageError::Flash(MockError::PowerLoss)),
            "{what}"
        );
        let mut flash = flash_of(store);
        flash.restart();
        let (mut store, again) = boot(flash);
        let k = again.value.as_ref().map_or(0, which);
        assert!(k == got || k == got + 1, "{what}: restored {k} after {got}");
        if k > 0 {
            assert_eq!(again.value, Some(state(k)), "{what}");
        }
        assert_calibration(&mut store, calibrated, &what);
        block_on(store.checkpoint(&state(k + 1))).unwrap_or_else(|e| panic!("{what}: {e:?}"));
        assert_eq!(boot(flash_of(store)).1.value, Some(state(k + 1)), "{what}");
    }
    points
}

/// The default sweep: every byte and every erased word of four checkpoints: the first
/// on a blank flash, and, with the calibration stored beside the state, the first,
/// the first that closes a sector, and the first that erases one (copying the
/// calibration forward). `MISALIGN_POWER_LOSS=full`: every checkpoint of three turns
/// of the ring, and for the four above a second power loss at every point of the
/// recovery from each first one.
#[test]
fn power_loss_at_every_point_restores_the_previous_or_the_new_checkpoint() {
    let full = std::env::var("MISALIGN_POWER_LOSS").is_ok_and(|v| v == "full");
    let per_turn = (Geometry {
        payload: State::SIZE,
        sector: SECTOR,
        sectors: SECTORS,
        word: WORD,
    })
    .checkpoints_per_cycle() as u32;
    let last = 3 * per_turn + 2;

    let (mut swept_points, mut second) = sweep(&base(false), 1, false, full);
    let mut steps = 1u32;
    let mut base = base(true);
    let (mut chosen, mut closing, mut erasing) = (vec![1], None, None);
    let mut swept_erase_words = 0u64;
    for n in 1..=last {
        let (points, erased_words) = points_of(&base, n);
        let record = codec::record_len(State::SIZE) as u64;
        if closing.is_none() && points > record + 16 {
            closing = Some(n);
            chosen.push(n);
        }
        if erasing.is_none() && erased_words > 0 {
            erasing = Some(n);
            chosen.push(n);
        }
        if full || chosen.contains(&n) {
            let (first, then) = sweep(&base, n, true, full && chosen.contains(&n));
            swept_points += first;
            second += then;
            swept_erase_words += erased_words;
            steps += 1;
        }
        let (mut store, _) = boot(base);
        block_on(store.checkpoint(&state(n))).unwrap();
        base = flash_of(store);
    }
    // The default covers at least one whole write and one whole erase.
    assert!(erasing.is_some() && closing.is_some());
    assert!(swept_erase_words >= (SECTOR / WORD) as u64);
    assert!(swept_points >= swept_erase_words + codec::record_len(State::SIZE) as u64);
    eprintln!(
        "power loss: {steps} checkpoints swept, {swept_points} points \
         ({swept_erase_words} erased words), {second} second-fault points; \
         closing at {closing:?}, erasing at {erasing:?}"
    );
}

// ---------------------------------------------------------------------------------
// Garbage, foreign data, a full region, wrap-around.

#[test]
fn garbage_over_the_whole_region_starts_fresh_and_is_reported() {
    // Random bytes (20 seeds), then all zeros and all 0x55 (cold RAM, a fill pattern).
    for seed in 0..22 {
        let mut flash = written(10);
        let mut next = rng(seed);
        for i in 0..SECTORS {
            flash.sector_mut(i).unwrap().iter_mut().for_each(|b| {
                *b = match seed {
                    20 => 0x00,
                    21 => 0x55,
                    _ => next(),
                }
            });
        }
        let (mut store, restored) = boot(flash);
        assert_eq!(restored.value, None, "seed {seed}");
        assert!(
            matches!(
                restored.outcome,
                RestoreOutcome::Rejected(StorageEvent::CorruptRegion | StorageEvent::ForeignRegion)
            ),
            "seed {seed}: {:?}",
            restored.outcome
        );
        assert_eq!(store.stats().rejected, 1);
        assert_eq!(store.stats().region_erases, 1);
        // The region works again.
        block_on(store.checkpoint(&state(1))).unwrap();
        assert_eq!(boot(flash_of(store)).1.value, Some(state(1)));
    }
}

/// Garbage in one sector: the restore gives a checkpoint that is whole (its value is
/// the one written with its number), the newest if the garbage missed it, or nothing
/// and an event; never a mix.
#[test]
fn garbage_in_one_sector_never_restores_a_wrong_value() {
    let (mut newest_kept, mut erased) = (0, 0);
    for sector in 0..SECTORS {
        for seed in 0..10 {
            let mut flash = written(20);
            let mut next = rng(seed * 31 + sector as u64);
            flash
                .sector_mut(sector)
                .unwrap()
                .iter_mut()
                .for_each(|b| *b = next());
            let (mut store, restored) = boot(flash);
            match restored.outcome {
                RestoreOutcome::Restored { sequence } => {
                    assert_eq!(restored.value, Some(state(sequence)));
                    assert!(sequence <= 20);
                    if sequence == 20 {
                        newest_kept += 1;
                    }
                }
                RestoreOutcome::Rejected(_) => assert_eq!(restored.value, None),
                other => panic!("sector {sector}, seed {seed}: {other:?}"),
            }
            // After the restore (which erased the region if it had to), checkpoints work.
            block_on(store.checkpoint(&state(21)))
                .unwrap_or_else(|e| panic!("sector {sector}, seed {seed}: {e:?}"));
            if store.stats().region_erases > 0 {
                erased += 1;
            }
            assert_eq!(boot(flash_of(store)).1.value, Some(state(21)));
        }
    }
    // Checkpoint 20 lives in sector 2 (8 a sector): garbage elsewhere keeps it.
    assert!(newest_kept >= 10, "{newest_kept}");
    eprintln!("garbage in one sector: newest kept {newest_kept} of 40, region erased {erased}");
}

#[test]
fn a_foreign_region_starts_fresh_and_is_reported() {
    // Another program's bytes (a text file, say) at the start of the region.
    let mut flash = Flash::new();
    let text = b"littlefs superblock? no: somebody else's data.";
    flash.sector_mut(0).unwrap()[..text.len()].copy_from_slice(text);
    let (mut store, restored) = boot(flash);
    assert_eq!(restored.value, None);
    assert!(matches!(restored.outcome, RestoreOutcome::Rejected(_)));
    assert_eq!(store.stats().rejected, 1);
    block_on(store.checkpoint(&state(2))).unwrap();
    assert_eq!(boot(flash_of(store)).1.value, Some(state(2)));
}

#[test]
fn a_foreign_record_under_our_key_is_rejected() {
    // Another program's sequential-storage map using the same key.
    let mut store = sequential_storage::map::MapStorage::<u8, _, _>::new(
        BlockingFlash(Flash::new()),
        sequential_storage::map::MapConfig::new(0..(SECTORS * SECTOR) as u32),
        sequential_storage::cache::Cache::new_uncached(),
    );
    let mut buf = [0u8; BUF];
    block_on(store.store_item(&mut buf, &State::KIND, &0x1234_5678u32)).unwrap();
    let (mut store, restored) = boot(store.destroy().0.0);
    assert_eq!(restored.value, None);
    assert_eq!(
        restored.outcome,
        RestoreOutcome::Rejected(StorageEvent::ForeignRecord)
    );
    block_on(store.checkpoint(&state(3))).unwrap();
    assert_eq!(boot(flash_of(store)).1.value, Some(state(3)));
}

/// A flash holding another program's map with one item of `len` bytes under `key`.
fn foreign_item(key: u8, len: usize) -> Flash {
    let mut map = sequential_storage::map::MapStorage::<u8, _, _>::new(
        BlockingFlash(Flash::new()),
        sequential_storage::map::MapConfig::new(0..(SECTORS * SECTOR) as u32),
        sequential_storage::cache::Cache::new_uncached(),
    );
    let mut buf = [0u8; 512];
    let item = vec![0xA5u8; len];
    block_on(map.store_item(&mut buf, &key, &item.as_slice())).unwrap();
    map.destroy().0.0
}

/// An item larger than the store's buffer (a newer firmware's larger record after a
/// downgrade, or another program's), under this kind's key or another: no error, no
/// value, a reported event, and the region usable again.
#[test]
fn an_oversized_item_is_rejected_not_an_error() {
    for (key, expected) in [
        (State::KIND, StorageEvent::OversizedRecord),
        (7, StorageEvent::OversizedRecord),
    ] {
        let (mut store, restored) = boot(foreign_item(key, 300));
        assert_eq!(restored.value, None, "key {key}");
        assert_eq!(
            restored.outcome,
            RestoreOutcome::Rejected(expected),
            "key {key}"
        );
        assert_eq!(store.stats().region_erases, 1, "key {key}");
        block_on(store.checkpoint(&state(4))).unwrap();
        assert_eq!(boot(flash_of(store)).1.value, Some(state(4)), "key {key}");
    }
    // A small foreign item under another key: a foreign region.
    let (_, restored) = boot(foreign_item(7, 10));
    assert_eq!(
        restored.outcome,
        RestoreOutcome::Rejected(StorageEvent::ForeignRegion)
    );
}

/// A fixed-size blob of kind `K`: many kinds fill a region.
#[derive(Debug, PartialEq)]
struct Blob<const K: u8, const N: usize>([u8; N]);

impl<const K: u8, const N: usize> Checkpoint for Blob<K, N> {
    const KIND: u8 = K;
    const VERSION: u16 = 1;
    const SIZE: usize = N;

    fn encode(&self, w: &mut Writer<'_>) -> Result<(), CodecError> {
        w.bytes(&self.0)
    }

    fn decode(r: &mut Reader<'_>) -> Result<Self, CodecError> {
        r.array().map(Blob)
    }
}

#[test]
fn a_full_region_is_a_typed_error_and_keeps_what_it_holds() {
    type B<const K: u8> = Blob<K, 200>;
    let mut store = Store::<_, 256>::new(BlockingFlash(Flash::new()), 0..4096, 60).unwrap();
    block_on(store.checkpoint(&state(1))).unwrap();
    let mut results = Vec::new();
    macro_rules! fill {
        ($($k:literal)*) => {$(
            results.push(block_on(store.checkpoint(&Blob::<$k, 200>([$k; 200]))).map(|_| $k));
        )*};
    }
    fill!(10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25);
    let full = results
        .iter()
        .position(|r| *r == Err(StorageError::Full))
        .expect("16 live blobs of 229 bytes do not fit in 4 KiB");
    assert!(results[..full].iter().all(Result::is_ok), "{results:?}");
    assert!(store.stats().failed_checkpoints >= 1);
    // What the region holds is intact.
    assert_eq!(
        block_on(store.restore::<State>()).unwrap().value,
        Some(state(1))
    );
    assert_eq!(
        block_on(store.restore::<B<10>>()).unwrap().value,
        Some(Blob([10; 200]))
    );

    // A record larger than a sector never fits: a typed error too.
    let mut store = Store::<_, 2048>::new(BlockingFlash(Flash::new()), 0..4096, 60).unwrap();
    assert_eq!(
        block_on(store.checkpoint(&Blob::<3, 1500>([1; 1500]))),
        Err(StorageError::Full)
    );
}

/// Many checkpoints through the small flash: the ring wraps around many times, every
/// restart restores the newest, and the sectors wear evenly, as `endurance` computes.
#[test]
fn wrap_around_and_wear_matches_the_mock_flash() {
    let geometry = Geometry {
        payload: State::SIZE,
        sector: SECTOR,
        sectors: SECTORS,
        word: WORD,
    };
    assert_eq!(geometry.checkpoints_per_sector(), 8);
    let n = 2000u32;
    let (mut store, _) = boot(Flash::new());
    for i in 1..=n {
        block_on(store.checkpoint(&state(i))).unwrap();
        if i % 97 == 0 {
            let (s, restored) = boot(flash_of(store));
            assert_eq!(restored.value, Some(state(i)));
            store = s;
        }
    }
    let flash = flash_of(store);
    let counts = flash.erase_counts();
    let expected = u64::from(n) / geometry.checkpoints_per_cycle();
    for &c in counts {
        // The first turn of the ring finds its sectors blank: one erase fewer at most.
        assert!(
            u64::from(c).abs_diff(expected) <= 1,
            "{counts:?}, expected {expected} each"
        );
    }
    assert_eq!(boot(flash).1.value, Some(state(n)));
}

// ---------------------------------------------------------------------------------
// The wear figures of the docs.

fn grouped(n: u64) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i).is_multiple_of(3) {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

#[test]
fn the_docs_wear_figures_are_the_computed_ones() {
    let g = endurance::REFERENCE;
    assert_eq!(g.checkpoints_per_sector(), 4);
    let rows = [
        ("1 h (default)", endurance::DEFAULT_INTERVAL_S),
        ("15 min", 900),
        ("5 min", 300),
    ];
    let module =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/src/storage/mod.rs"))
            .unwrap();
    for (name, interval) in rows {
        let row = format!(
            "| {name} | {} | {} | {} |",
            grouped(endurance::SECONDS_PER_YEAR / u64::from(interval)),
            grouped(g.cycles_per_year(interval)),
            g.years_to(endurance::RATED_CYCLES, interval)
        );
        assert!(module.contains(&row), "module docs lack {row}");
    }
    let ten_years = g.min_interval_s(endurance::RATED_CYCLES, 10);
    assert!(module.contains(&format!("{ten_years} s for ten years")));
    // The shortest interval for ten years is just that: the erases of ten years at
    // it fit the rating, one second less does not.
    let erases_in_ten_years = |interval: u32| {
        10 * endurance::SECONDS_PER_YEAR / u64::from(interval) / g.checkpoints_per_cycle()
    };
    assert!(erases_in_ten_years(ten_years) <= u64::from(endurance::RATED_CYCLES));
    assert!(erases_in_ten_years(ten_years - 1) >= u64::from(endurance::RATED_CYCLES));

    let guide =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/firmware.md")).unwrap();
    let guide = guide.split_whitespace().collect::<Vec<_>>().join(" ");
    let sentences = [
        format!(
            "{} erase cycles per sector a year, {} years to 10 000 cycles",
            g.cycles_per_year(endurance::DEFAULT_INTERVAL_S),
            g.years_to(endurance::RATED_CYCLES, endurance::DEFAULT_INTERVAL_S)
        ),
        format!(
            "every 15 minutes it would take {}, {} years",
            grouped(g.cycles_per_year(900)),
            g.years_to(endurance::RATED_CYCLES, 900)
        ),
        format!("({ten_years} s for ten years here)"),
    ];
    for sentence in sentences {
        assert!(
            guide.contains(&sentence),
            "docs/firmware.md lacks \"{sentence}\""
        );
    }
}

// ---------------------------------------------------------------------------------
// The mock flash itself.

#[test]
fn the_mock_flash_behaves_as_nor_flash() {
    use embedded_storage::nor_flash::{NorFlash, ReadNorFlash};
    let mut f = Flash::new();
    let mut b = [0u8; 8];
    f.read(0, &mut b).unwrap();
    assert_eq!(b, [0xFF; 8]);
    f.write(0, &[0x0F, 0xF0, 0x00, 0xFF]).unwrap();
    // 1 -> 0 only: clearing more bits is fine, setting one back is refused.
    f.write(0, &[0x0E, 0xF0, 0x00, 0xFF]).unwrap();
    assert_eq!(
        f.write(0, &[0x1E, 0xF0, 0x00, 0xFF]),
        Err(MockError::ZeroToOne { offset: 0 })
    );
    assert_eq!(f.write(2, &[0; 4]), Err(MockError::NotAligned));
    assert_eq!(f.write(4096, &[0; 4]), Err(MockError::OutOfBounds));
    assert_eq!(f.erase(0, 100), Err(MockError::NotAligned));
    f.erase(0, 1024).unwrap();
    f.read(0, &mut b).unwrap();
    assert_eq!(b, [0xFF; 8]);
    assert_eq!(f.erase_counts(), &[1, 0, 0, 0]);

    // A cut at the 6th byte of a write: 5 bytes programmed, the 6th partly, the rest not.
    let mut g = f.clone();
    g.cut_after(5);
    assert_eq!(g.write(0, &[0u8; 8]), Err(MockError::PowerLoss));
    assert!(g.is_off());
    assert_eq!(g.read(0, &mut b), Err(MockError::PoweredOff));
    g.restart();
    g.read(0, &mut b).unwrap();
    assert_eq!(&b[..5], &[0; 5]);
    assert_eq!(&b[6..], &[0xFF; 2]);

    // A cut at word 3 of an erase: words 0..3 erased, word 3 garbage, the rest intact.
    let mut g = f.clone();
    g.write(0, &[0u8; 1024]).unwrap();
    g.cut_after(3);
    assert_eq!(g.erase(0, 1024), Err(MockError::PowerLoss));
    g.restart();
    let s = g.sector(0).unwrap();
    assert_eq!(&s[..12], &[0xFF; 12]);
    assert!(s[16..].iter().all(|&x| x == 0));
    // A sweep is repeatable: the same cut leaves the same bytes.
    let mut h = f.clone();
    h.write(0, &[0u8; 1024]).unwrap();
    h.cut_after(3);
    let _ = h.erase(0, 1024);
    assert_eq!(h.sector(0), g.sector(0));
}

// ---------------------------------------------------------------------------------
// The sensors' calibration as a stored record (with the feature `sensors`).

#[cfg(feature = "sensors")]
mod sensor_calibration {
    use super::*;
    use misalign::sensors::{
        Hx711Channel, LoadCalibration, MisalignmentCalibration, ProbeCalibration, ProbeSpec,
        SpeedCalibration,
    };
    use misalign::storage::SensorCalibration;

    const SPEC: ProbeSpec = ProbeSpec {
        min_m: 0.0,
        max_m: 2e-3,
        linearity_m: 10e-6,
    };

    /// A calibration as the sensors' own constructors make it on site.
    fn on_site(speed: bool) -> SensorCalibration {
        SensorCalibration {
            load: LoadCalibration::two_point(Hx711Channel::A64, 8_400.0, 91_000.0, 98.0665, 5e3)
                .unwrap(),
            misalignment: MisalignmentCalibration {
                probe1: ProbeCalibration::two_point((1000.0, 0.0), (21000.0, 2e-3), SPEC).unwrap(),
                probe2: ProbeCalibration::two_point((900.0, 0.0), (20500.0, 2e-3), SPEC).unwrap(),
                span_m: 0.25,
                zero_offset_m: 3e-6,
            },
            speed: speed.then_some(SpeedCalibration {
                pulses_per_rev: 360,
                radius_m: 0.05,
                max_speed_m_s: 20.0,
            }),
        }
    }

    fn record(cal: &SensorCalibration) -> Vec<u8> {
        let mut buf = [0u8; BUF];
        let len = codec::encode(cal, 1, &mut buf).unwrap();
        buf[..len].to_vec()
    }

    /// Rewrites the CRC after a test changed a payload byte: the record is then whole,
    /// and only the type's own checks can refuse it.
    fn reseal(mut rec: Vec<u8>) -> Vec<u8> {
        let n = rec.len() - 4;
        let crc = codec::crc32(&rec[..n]);
        rec[n..].copy_from_slice(&crc.to_le_bytes());
        rec
    }

    #[test]
    fn the_calibration_round_trips_beside_the_state() {
        for speed in [true, false] {
            let (mut store, _) = boot(Flash::new());
            block_on(store.checkpoint(&on_site(speed))).unwrap();
            for n in 1..=40 {
                block_on(store.checkpoint(&state(n))).unwrap();
            }
            let (mut store, restored) = boot(flash_of(store));
            assert_eq!(restored.value, Some(state(40)));
            let cal = block_on(store.restore::<SensorCalibration>()).unwrap();
            assert_eq!(cal.value, Some(on_site(speed)));
        }
    }

    /// Version 1 of the record, frozen.
    const V1_CALIBRATION: &str = "\
4d534c47020101004e0000000100000001004003465b9d9b3a00409cc500409c4500007a4496bfd6\
33000000006f12033bacc52737000061448921db33000000006f12033bacc527370000803e9c5349\
360168010000cdcc4c3d0000a041324cb51d";

    #[test]
    fn the_frozen_version_1_record_still_decodes() {
        let frozen = hex(V1_CALIBRATION);
        assert_eq!(record(&on_site(true)), frozen);
        let d = codec::decode::<SensorCalibration>(&frozen).unwrap();
        assert_eq!(d.value, on_site(true));
    }

    #[test]
    fn a_calibration_that_fails_its_checks_is_not_restored() {
        let good = record(&on_site(false));
        let payload = codec::HEADER_LEN;
        let mut cases = Vec::new();
        // An unknown HX711 channel code.
        let mut rec = good.clone();
        rec[payload] = 3;
        cases.push(rec);
        // A zero load scale (bytes 5..9 of the payload).
        let mut rec = good.clone();
        rec[payload + 5..payload + 9].copy_from_slice(&0f32.to_le_bytes());
        cases.push(rec);
        // A negative probe span.
        let span = payload + 17 + 40;
        let mut rec = good.clone();
        rec[span..span + 4].copy_from_slice(&(-0.25f32).to_le_bytes());
        cases.push(rec);
        // "No tachometer" with tachometer values behind it.
        let speed = payload + 17 + 48;
        let mut rec = good.clone();
        rec[speed + 1] = 7;
        cases.push(rec);
        for (i, rec) in cases.into_iter().enumerate() {
            assert_eq!(
                codec::decode::<SensorCalibration>(&reseal(rec)),
                Err(CodecError::InvalidValue),
                "case {i}"
            );
        }
        // And through the store: a calibration that fails its checks is reported, not
        // restored. (Built by hand, as a broken firmware might have stored it.)
        let mut bad = on_site(true);
        bad.speed = Some(SpeedCalibration {
            pulses_per_rev: 0,
            radius_m: 0.05,
            max_speed_m_s: 20.0,
        });
        let (mut store, _) = boot(Flash::new());
        block_on(store.checkpoint(&bad)).unwrap();
        let (mut store, _) = boot(flash_of(store));
        let restored = block_on(store.restore::<SensorCalibration>()).unwrap();
        assert_eq!(restored.value, None);
        assert_eq!(
            restored.outcome,
            RestoreOutcome::Rejected(StorageEvent::Undecodable)
        );
    }
}
