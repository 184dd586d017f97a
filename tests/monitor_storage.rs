//! The monitor's state and configuration as stored checkpoints: field by
//! field through the storage codec, a frozen version-1 record that every later firmware
//! must read, corrupted payloads refused, and the whole through a store on the mock
//! flash beside the sensors' calibration.

use misalign::monitor::scenario::Scenario;
use misalign::monitor::{
    Channel, Config, EVENT_CAPACITY, EventKind, FaultCause, FaultKind, FrictionConfig, Monitor,
    MonitorState, RiskState, SPIKE_WINDOW_CAPACITY, Sample, SensorFault, SensorId, TREND_CAPACITY,
    Thresholds, model_for_range,
};
use misalign::sensors::{Hx711Channel, LoadCalibration, SpeedCalibration};
use misalign::storage::codec::{self, CodecError};
use misalign::storage::{
    BlockingFlash, Checkpoint, MockFlash, Reader, RestoreOutcome, SensorCalibration, Store, Writer,
    block_on, kind,
};
use misalign::{Estimator, Scene, float::Auto};

#[path = "common/probes.rs"]
mod probes;

fn core(mu: f64) -> Auto {
    let s = Scene::new(0.05, 0.05, 79.3e9, 0.3, mu).unwrap();
    Auto::with_choice(&s, model_for_range(&s, 5e3, 1e-5).unwrap()).unwrap()
}

/// The built-in scenario's samples with a measured axial force from the forward model
/// at mu = 0.3 (none where the forward model refuses the sample, e.g. at rest).
fn scenario_with_force() -> impl Iterator<Item = Sample> {
    let forward = core(0.3);
    Scenario::new().map(move |s| match forward.estimate_si(s.load.max(0.0), s.phi) {
        Ok(e) if e.axial_force.is_finite() => s.with_axial_force(e.axial_force),
        _ => s,
    })
}

/// The payload of a value, as its `encode` writes it.
fn payload<T: Checkpoint>(value: &T) -> Vec<u8> {
    let mut out = vec![0u8; T::SIZE];
    let mut w = Writer::new(&mut out);
    value.encode(&mut w).unwrap();
    assert_eq!(w.written(), T::SIZE);
    out
}

/// Decodes a payload, every byte of it.
fn decode<T: Checkpoint>(bytes: &[u8]) -> Result<T, CodecError> {
    let mut r = Reader::new(bytes);
    let value = T::decode(&mut r)?;
    r.finish()?;
    Ok(value)
}

/// The state four hours into the scenario (trend, events, faults, energy, friction
/// all in use), the monitor that holds it, and the rest of the samples.
fn mid_scenario() -> (Monitor<Auto>, Vec<Sample>) {
    let mut m = Monitor::new(core(0.3), Config::default()).unwrap();
    let mut samples = scenario_with_force();
    for s in samples.by_ref().take(4 * 3600) {
        m.process_with_friction(s);
    }
    (m, samples.collect())
}

#[test]
fn a_restored_state_goes_on_identically() {
    let (mut original, rest) = mid_scenario();
    let state = original.snapshot();
    // The state is a real one: every part is in use.
    assert!(state.friction_status().baseline().is_some());
    assert!(!state.trend_points().is_empty() && !state.events().is_empty());
    assert!(state.statistics().faults().total() > 0);
    let mut record = vec![0u8; codec::record_len(MonitorState::SIZE)];
    let n = codec::encode(&state, 41, &mut record).unwrap();
    let decoded = codec::decode::<MonitorState>(&record[..n]).unwrap();
    assert_eq!((decoded.sequence, decoded.version), (41, 1));
    assert_eq!(decoded.value, state);
    let config = decode::<Config>(&payload(original.config())).unwrap();
    let mut restored = Monitor::restore(core(0.3), config, &decoded.value).unwrap();
    for s in rest {
        assert_eq!(
            original.process_with_friction(s),
            restored.process_with_friction(s)
        );
        assert_eq!(original.pop_event(), restored.pop_event());
    }
    assert_eq!(original.snapshot(), restored.snapshot());
    assert_eq!(original.statistics().samples(), 8 * 3600 - 180);
}

/// A version-1 record of a monitor's state, written once by the version-1 encoder
/// (checkpoint 7): 342 s of samples at 2 kN with a measured F, a saturated probe 2, a
/// driver's fault on the speed, a friction baseline taken on demand and a fall of mu
/// to 0.2. A newer firmware must go on reading it (migrate, once VERSION is raised).
const V1_RECORD: &[&str] = &[
    "4d534c4701010100180300000700000001f0370500083405000000000001a00302000000000000000000000000000000",
    "010000000000000000018095fb44cde551390040fc440834050000000000c7ec51390834050000000000c89704000000",
    "0000c885813c2900000000000000000106000000018095fb44cde5513905befe3e0790c2430157b7193a01c87bca3900",
    "000000560100000000000000000000000000000000000000000000000000000000000000000000010000000000000001",
    "000000000000000000000000000000d8410400000000000000000000000000000000000000000030f200000000000000",
    "00000000000000efd63942000064b500000000000000000000000000000000d87b3b410000f8b41c17ff3e63d1f44301",
    "12c3c9396578503e959d993e01540100000000000000000000010000fa440060fa4400c0fa440020fb440080fb4400e0",
    "fb440040fc4407efd15139c7ec51399f0752397722523917b75139efd15139c7ec513907e09304008f2fca3900000000",
    "000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000",
    "000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000",
    "00000000000000000000000000000000000000000100000000e803000000000000000000000000010000000000000060",
    "fa44efd151391c17ff3e3635f343010556193a0112c3c9390100000048ee000060ea0000000000000001040107020200",
    "00e519fb44cee95139f8eafe3e180cf443017f90193a01172cca39020000006067010078630100000000000004010000",
    "000000006aebfa44cde5513988f7fe3ebe40f34301e281193a01de10ca3903000000708e0100888a0100000000000001",
    "0401050200000080f1fa440ae351394af3fe3e39ccf34301cc83193a011316ca390400000088070200a0030200000000",
    "000004010000000000009022fb4463ef513970ecfe3eac00f343013993193a01c02eca390500000000e8030018e40300",
    "00000000024c1a5c3e01000000e519fb440ae351399de5fe3edd04c243017f90193a01792fca3906baf52f32",
];

fn v1_record() -> Vec<u8> {
    let hex = V1_RECORD.concat();
    (0..hex.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap())
        .collect()
}

#[test]
fn newer_firmware_reads_the_version_1_record() {
    let record = v1_record();
    assert_eq!(record.len(), codec::record_len(MonitorState::SIZE));
    let decoded = codec::decode::<MonitorState>(&record).unwrap();
    assert_eq!((decoded.sequence, decoded.version), (7, 1));
    let s = decoded.value;
    assert_eq!(s.elapsed_ms(), 341_000);
    assert_eq!(s.last_time_ms(), Some(342_000));
    assert_eq!(s.state(), RiskState::Normal);
    assert_eq!(s.statistics().samples(), 342);
    assert_eq!(
        (
            s.statistics().faults().driver,
            s.statistics().faults().sensor
        ),
        (1, 1)
    );
    let f = s.friction_status();
    assert!(f.changed());
    assert_eq!((f.accepted(), f.rejected()), (340, 0));
    assert_eq!(
        (f.baseline(), f.filtered()),
        (Some(0.30003038), Some(0.20358427))
    );
    let kinds: Vec<EventKind> = s.events().iter().map(|e| e.kind).collect();
    let change = |from, to, fault| EventKind::StateChange { from, to, fault };
    let probe2 = SensorFault {
        sensor: SensorId::Probe2,
        kind: FaultKind::Saturated,
    };
    use RiskState::{Normal, SensorFault as Fault, Stopped};
    assert_eq!(
        kinds,
        [
            change(Stopped, Normal, None),
            change(Normal, Fault, Some(FaultCause::Sensor(probe2))),
            change(Fault, Normal, None),
            change(Normal, Fault, Some(FaultCause::Driver(Channel::Speed))),
            change(Fault, Normal, None),
            EventKind::Friction {
                mu: 0.21494406,
                changed: true
            },
        ]
    );
    // The version-1 encoder still writes exactly these bytes.
    let mut again = vec![0u8; record.len()];
    codec::encode(&s, 7, &mut again).unwrap();
    assert_eq!(again, record);
    // And a monitor goes on from it.
    let mut m = Monitor::restore(core(0.3), Config::default(), &s).unwrap();
    assert_eq!(m.friction_baseline(), Some(0.30003038));
    let next = Sample::new(343_000, 2000.0, 2e-4).with_speed(2.0);
    assert_eq!(m.process(next), RiskState::Normal);
}

/// Where the fields sit in the version-1 payload (the layout `checkpoint.rs` writes).
const CLOCK: usize = 1 + 4 + 8;
const EVENT: usize = 4 + 4 + 8 + 9 + 26;
const BUFFERS: usize =
    2 * (SPIKE_WINDOW_CAPACITY * 4 + 1) + TREND_CAPACITY * 8 + 1 + EVENT_CAPACITY * EVENT + 1;

#[test]
fn corrupted_payloads_are_refused() {
    let (m, _) = mid_scenario();
    let good = payload(&m.snapshot());
    let status = MonitorState::SIZE - BUFFERS;
    let windows = status;
    let events = status + 2 * (SPIKE_WINDOW_CAPACITY * 4 + 1) + TREND_CAPACITY * 8 + 1;
    let smoothed = CLOCK + 1 + 8 + 10 + 9;
    assert_eq!(
        good[smoothed], 1,
        "the state mid-run holds a smoothed value"
    );
    let nan = f32::NAN.to_le_bytes();
    let inf = f32::INFINITY.to_le_bytes();
    let cases: [(&str, usize, &[u8]); 9] = [
        ("a flag byte of 2 (the clock's)", 0, &[2]),
        ("an unknown risk state", CLOCK, &[5]),
        ("a NaN smoothed load", smoothed + 1, &nan),
        ("an infinite smoothed angle", smoothed + 5, &inf),
        (
            "a load window longer than its capacity",
            windows + SPIKE_WINDOW_CAPACITY * 4,
            &[8],
        ),
        (
            "an event queue longer than its capacity",
            MonitorState::SIZE - 1,
            &[7],
        ),
        ("an unknown event kind", events + 16, &[3]),
        ("an unknown state in an event", events + 17, &[9]),
        ("a NaN in an event's reading", events + 25, &nan),
    ];
    for (what, at, bytes) in cases {
        let mut bad = good.clone();
        bad[at..at + bytes.len()].copy_from_slice(bytes);
        assert_eq!(
            decode::<MonitorState>(&bad),
            Err(CodecError::InvalidValue),
            "{what}"
        );
    }
    // Every byte set to a few values: refused, or decoded to a value that encodes to
    // exactly those bytes (nothing read is dropped or changed), and a monitor goes on
    // from it without a panic.
    let mut accepted = 0;
    for at in 0..good.len() {
        for v in [0x00, 0x01, 0x02, 0x7F, 0x80, 0xFF] {
            let mut bad = good.clone();
            bad[at] = v;
            if let Ok(state) = decode::<MonitorState>(&bad) {
                accepted += 1;
                assert_eq!(payload(&state), bad, "byte {at} = {v:#x}");
                let mut m = Monitor::restore(core(0.3), Config::default(), &state).unwrap();
                m.process_with_friction(Sample::new(0, 2000.0, 2e-4).with_axial_force(480.0));
            }
        }
    }
    assert!(accepted > 0);
    // A record whose bytes were damaged on the flash fails its CRC first.
    let mut record = vec![0u8; codec::record_len(MonitorState::SIZE)];
    codec::encode(&m.snapshot(), 1, &mut record).unwrap();
    record[100] ^= 0x10;
    assert_eq!(
        codec::decode::<MonitorState>(&record),
        Err(CodecError::Checksum)
    );
}

/// Where the state's fields sit in its payload (version 1, docs/formats.md), with their
/// sizes: the fields a mutation test rewrites.
const FIELDS: [(&str, usize, usize); 44] = [
    ("clock: last timestamp flag", 0, 1),
    ("clock: last timestamp", 1, 4),
    ("clock: elapsed", 5, 8),
    ("alarm: state", 13, 1),
    ("alarm: since", 14, 8),
    ("alarm: pending flag", 22, 1),
    ("alarm: pending state", 23, 1),
    ("alarm: pending since", 24, 8),
    ("alarm: started flag", 32, 1),
    ("alarm: started", 33, 8),
    ("smoothing: load", 42, 4),
    ("smoothing: angle", 46, 4),
    ("stuck: load bits", 50, 4),
    ("stuck: load since", 54, 8),
    ("stuck: angle since", 66, 8),
    ("trend interval: start", 74, 8),
    ("trend interval: sum", 82, 4),
    ("trend interval: count", 86, 4),
    ("time to critical flag", 90, 1),
    ("time to critical", 91, 4),
    ("approaching armed", 95, 1),
    ("next event sequence", 96, 4),
    ("statistics: samples", 131, 8),
    ("statistics: repeated", 139, 4),
    ("statistics: spikes", 143, 4),
    ("statistics: stuck faults", 155, 4),
    ("statistics: events dropped", 179, 4),
    ("statistics: time normal", 191, 8),
    ("statistics: time gross slip", 207, 8),
    ("friction: mu", 276, 4),
    ("friction: baseline", 280, 4),
    ("friction: captured", 284, 1),
    ("friction: accepted", 285, 4),
    ("friction: rejected", 289, 4),
    ("friction: pending", 293, 4),
    ("friction: changed", 297, 1),
    ("spike window: a load", 298 + 12, 4),
    ("spike window: an angle", 327 + 12, 4),
    ("spike window: angle length", 327 + 28, 1),
    ("trend point 0: margin", 356 + 4, 4),
    ("trend point 0: time", 356, 4),
    ("trend point 15: time", 356 + 15 * 8, 4),
    ("event 0: sequence", 485, 4),
    ("event 0: elapsed", 485 + 8, 8),
];

/// The record of `state` with `bytes` written into its payload at `at`, and its CRC
/// made valid again: what a writer with a bug, not a damaged flash, would store.
fn record_with(state: &MonitorState, at: usize, bytes: &[u8]) -> Vec<u8> {
    let mut record = vec![0u8; codec::record_len(MonitorState::SIZE)];
    let n = codec::encode(state, 1, &mut record).unwrap();
    record.truncate(n);
    let at = n - 4 - MonitorState::SIZE + at;
    record[at..at + bytes.len()].copy_from_slice(bytes);
    let crc = codec::crc32(&record[..n - 4]);
    record[n - 4..].copy_from_slice(&crc.to_le_bytes());
    record
}

/// States no monitor reaches are refused, CRC or not: an alarm start-up time of
/// u64::MAX (a monitor that would never raise gross slip again), a clock so near
/// u64::MAX that the next sample wraps it, pending, stuck-tracking and trend times
/// after the state's own clock, a time per state that does not sum to it.
#[test]
fn unreachable_states_are_refused() {
    let (m, _) = mid_scenario();
    let state = m.snapshot();
    let elapsed = state.elapsed_ms();
    assert!(codec::decode::<MonitorState>(&record_with(&state, 0, &[1])).is_ok());
    let later = (elapsed + 1).to_le_bytes();
    let cases: [(&str, usize, &[u8]); 9] = [
        (
            "an alarm start-up time of u64::MAX",
            32,
            &[[1].as_slice(), &u64::MAX.to_le_bytes()].concat(),
        ),
        ("a clock near u64::MAX", 5, &(u64::MAX - 1000).to_le_bytes()),
        ("a state entered after the clock", 14, &later),
        (
            "a pending state since after the clock",
            22,
            &[[1, 3].as_slice(), &later].concat(),
        ),
        (
            "a pending state since before its state was entered",
            22,
            &[1, 3, 0, 0, 0, 0, 0, 0, 0, 0],
        ),
        ("a load stuck since after the clock", 54, &later),
        ("an angle stuck since after the clock", 66, &later),
        ("a trend interval begun after the clock", 74, &later),
        ("more time in gross slip than elapsed", 207, &later),
    ];
    for (what, at, bytes) in cases {
        assert_eq!(
            codec::decode::<MonitorState>(&record_with(&state, at, bytes)).map(|d| d.value),
            Err(CodecError::Inconsistent),
            "{what}"
        );
    }
}

#[test]
fn the_configuration_round_trips_and_is_validated_on_decode() {
    let custom = Config {
        thresholds: Thresholds::Margin {
            warning: 1e-4,
            alarm: 0.0,
            deadband: 2e-5,
        },
        spikes: None,
        trend: None,
        friction: Some(FrictionConfig {
            band: 0.1,
            deadband: 0.02,
            ..FrictionConfig::default()
        }),
        ..Config::default()
    };
    let no_friction = Config {
        friction: None,
        ..Config::default()
    };
    for config in [Config::default(), custom, no_friction] {
        assert_eq!(decode::<Config>(&payload(&config)), Ok(config));
    }
    assert_eq!(Config::KIND, kind::MONITOR_CONFIG);
    // The docs' wear figures are those of the monitor's real record.
    assert_eq!(
        misalign::storage::endurance::REFERENCE.payload,
        MonitorState::SIZE
    );
    assert_eq!(MonitorState::KIND, kind::MONITOR_STATE);
    // An inconsistent configuration encodes (encode does not judge) but never decodes.
    let inconsistent = Config {
        friction: Some(FrictionConfig {
            band: 0.0,
            ..FrictionConfig::default()
        }),
        ..Config::default()
    };
    let bad = payload(&inconsistent);
    assert_eq!(decode::<Config>(&bad), Err(CodecError::InvalidValue));
    // An unknown threshold kind; bytes behind an absent option.
    let mut bad = payload(&Config::default());
    bad[0] = 2;
    assert_eq!(decode::<Config>(&bad), Err(CodecError::InvalidValue));
    let mut bad = payload(&no_friction);
    let last = bad.len() - 1;
    bad[last] = 1;
    assert_eq!(decode::<Config>(&bad), Err(CodecError::InvalidValue));
}

type Flash = MockFlash<4, 4096, 4>;
const BUF: usize = Store::<BlockingFlash<Flash>, 1024>::buffer_len::<MonitorState>();

fn sensor_calibration() -> SensorCalibration {
    SensorCalibration {
        load: LoadCalibration::from_rated_output(Hx711Channel::A128, 2.0, 5000.0).unwrap(),
        misalignment: probes::probe_calibration(-30e-6),
        speed: Some(SpeedCalibration {
            pulses_per_rev: 60,
            radius_m: 0.05,
            max_speed_m_s: 50.0,
        }),
    }
}

#[test]
fn state_configuration_and_calibration_through_the_mock_flash() {
    assert!(BUF >= Store::<BlockingFlash<Flash>, 1024>::buffer_len::<Config>());
    assert!(BUF >= Store::<BlockingFlash<Flash>, 1024>::buffer_len::<SensorCalibration>());
    let open =
        |flash: Flash| Store::<_, BUF>::new(BlockingFlash(flash), 0..4 * 4096, 3600).unwrap();
    let (mut m, rest) = mid_scenario();
    let config = *m.config();
    let calibration = sensor_calibration();
    let mut store = open(Flash::new());
    block_on(store.checkpoint(&calibration)).unwrap();
    block_on(store.checkpoint(&config)).unwrap();
    // A checkpoint a minute (4 records fit a sector): many turns of the ring.
    let mut last = m.snapshot();
    for (i, s) in rest.iter().enumerate() {
        m.process_with_friction(*s);
        if i % 60 == 59 {
            last = m.snapshot();
            block_on(store.checkpoint(&last)).unwrap();
        }
    }
    // A reset: everything comes back.
    let mut store = open(store.into_flash().0);
    let state = block_on(store.restore::<MonitorState>()).unwrap();
    assert!(
        matches!(state.outcome, RestoreOutcome::Restored { .. }),
        "{:?}",
        state.outcome
    );
    assert_eq!(state.value, Some(last));
    let restored_config = block_on(store.restore::<Config>()).unwrap().value;
    assert_eq!(restored_config, Some(config));
    let restored_calibration = block_on(store.restore::<SensorCalibration>())
        .unwrap()
        .value;
    assert_eq!(restored_calibration, Some(calibration));
    // The last checkpoint was of the last sample: the restored monitor goes on as the
    // one that never stopped.
    assert_eq!(m.snapshot(), last);
    let mut again = Monitor::restore(core(0.3), config, &last).unwrap();
    let next = last.last_time_ms().unwrap().wrapping_add(1000);
    let sample = Sample::new(next, 2000.0, 2e-4).with_speed(2.0);
    assert_eq!(again.process(sample), m.process(sample));
    assert_eq!(again.snapshot(), m.snapshot());
}

/// A restore in place, as a node with little RAM does it: the state decoded into one
/// value (`restore_into`) and a monitor that resumes from it. The same state as
/// `restore` and `Monitor::restore` give, also over a monitor that had run (resume
/// replaces everything it held), and a fresh state is the default one.
#[test]
fn a_state_restored_in_place_is_the_same() {
    assert_eq!(
        MonitorState::default(),
        Monitor::new(core(0.3), Config::default())
            .unwrap()
            .snapshot()
    );
    let (mut m, rest) = mid_scenario();
    let mut store = Store::<_, BUF>::new(BlockingFlash(Flash::new()), 0..4 * 4096, 3600).unwrap();
    let saved = m.snapshot();
    let sequence = block_on(store.checkpoint(&saved)).unwrap();
    let mut store = Store::<_, BUF>::new(store.into_flash(), 0..4 * 4096, 3600).unwrap();
    let mut state = MonitorState::default();
    let outcome = block_on(store.restore_into(&mut state)).unwrap();
    assert_eq!(outcome, RestoreOutcome::Restored { sequence });
    assert_eq!(state, saved);
    // Over a fresh monitor and over one that ran on, then was reset to the state.
    let mut fresh = Monitor::new(core(0.3), Config::default()).unwrap();
    fresh.resume(&state);
    let mut ran = Monitor::new(core(0.3), Config::default()).unwrap();
    for s in Scenario::new().skip(9000).take(400) {
        ran.process(s);
    }
    ran.resume(&state);
    for resumed in [&mut fresh, &mut ran] {
        assert_eq!(resumed.snapshot(), saved);
    }
    for s in rest.iter().take(3600) {
        let want = m.process_with_friction(*s);
        assert_eq!(fresh.process_with_friction(*s), want);
        assert_eq!(ran.process_with_friction(*s), want);
        let event = m.pop_event();
        assert_eq!(fresh.pop_event(), event);
        assert_eq!(ran.pop_event(), event);
    }
    assert_eq!(fresh.snapshot(), m.snapshot());
    assert_eq!(ran.snapshot(), m.snapshot());
    // A region that holds no state: the outcome says so, and the state is not used.
    let mut blank = Store::<_, BUF>::new(BlockingFlash(Flash::new()), 0..4 * 4096, 3600).unwrap();
    let mut untouched = MonitorState::default();
    let outcome = block_on(blank.restore_into(&mut untouched)).unwrap();
    assert_eq!(outcome, RestoreOutcome::Blank);
    assert_eq!(untouched, MonitorState::default());
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(256))]

    /// A valid payload with up to 8 bytes overwritten, and any bytes at all: refused,
    /// or a value that encodes to exactly those bytes; never a panic.
    #[test]
    fn any_payload_is_refused_or_canonical(
        edits in proptest::collection::vec(
            (0..MonitorState::SIZE, proptest::prelude::any::<u8>()),
            1..8,
        ),
        garbage in proptest::collection::vec(proptest::prelude::any::<u8>(), MonitorState::SIZE),
        config in proptest::collection::vec(proptest::prelude::any::<u8>(), Config::SIZE),
    ) {
        let fresh = Monitor::new(core(0.3), Config::default()).unwrap().snapshot();
        let mut edited = payload(&fresh);
        for (at, v) in edits {
            edited[at] = v;
        }
        for bytes in [edited, garbage] {
            if let Ok(state) = decode::<MonitorState>(&bytes) {
                proptest::prop_assert_eq!(payload(&state), bytes);
            }
        }
        if let Ok(c) = decode::<Config>(&config) {
            proptest::prop_assert_eq!(payload(&c), config);
            proptest::prop_assert!(c.validate().is_ok());
        }
    }
}

/// Runs a restored monitor on 2 mrad at about 2 kN, one sample a second from the
/// state's last timestamp, for 10 minutes: its clock never runs backwards, the time per
/// state sums to it, and gross slip is entered within the delays that can stand in its
/// way (start-up inhibit, the off-delay out of a fault or a stop, the on-delay) and a
/// minute for the conditioning to settle. Returns the time it took (ms).
fn raises_gross_slip(state: &MonitorState) -> Result<u64, String> {
    let config = Config::default();
    let mut m = Monitor::restore(core(0.3), config, state).unwrap();
    let t0 = state.last_time_ms().unwrap_or(0);
    let start = m.elapsed_ms();
    let mut entered = None;
    for i in 1..=600u32 {
        let before = m.elapsed_ms();
        let load = 2000.0 + (i % 7) as f32;
        let phi = 2e-3 + (i % 5) as f32 * 1e-7;
        let sample = Sample::new(t0.wrapping_add(i * 1000), load, phi).with_speed(2.0);
        if m.process(sample) == RiskState::GrossSlip && entered.is_none() {
            entered = Some(m.elapsed_ms() - start);
        }
        if m.elapsed_ms() < before {
            return Err(format!("the clock ran backwards at sample {i}"));
        }
    }
    let st = m.statistics();
    let in_states: u64 = RiskState::ALL.iter().map(|&s| st.time_in_state_ms(s)).sum();
    if in_states != m.elapsed_ms() {
        return Err(format!(
            "{in_states} ms in states, {} elapsed",
            m.elapsed_ms()
        ));
    }
    let bound = u64::from(config.inhibit_ms + config.off_delay_ms + config.on_delay_ms) + 60_000;
    match entered {
        Some(t) if t <= bound => Ok(t),
        t => Err(format!("gross slip after {t:?} ms, bound {bound} ms")),
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(256))]

    /// Each field of a real state (four hours into the scenario) rewritten with values
    /// around its own clock, at the ends of its type, or at random, the CRC made valid
    /// again: what still decodes runs as a reachable state (gross slip within its
    /// delays, a clock that goes forward, time per state that sums to it).
    #[test]
    fn a_mutated_state_that_decodes_is_reachable(
        field in 0..FIELDS.len(),
        choice in 0usize..9,
        random in proptest::prelude::any::<u64>(),
    ) {
        let state = mid_scenario_state();
        let now = state.elapsed_ms();
        let (what, at, size) = FIELDS[field];
        let value: u64 = [0, 1, now - 1, now, now + 1, now + (1 << 31), u64::MAX - 1, u64::MAX, random][choice];
        let record = record_with(&state, at, &value.to_le_bytes()[..size]);
        if let Ok(decoded) = codec::decode::<MonitorState>(&record) {
            let took = raises_gross_slip(&decoded.value);
            proptest::prop_assert!(took.is_ok(), "{} = {:#x}: {:?}", what, value, took);
        }
    }
}

/// The state of [`mid_scenario`], computed once.
fn mid_scenario_state() -> MonitorState {
    static STATE: std::sync::OnceLock<MonitorState> = std::sync::OnceLock::new();
    *STATE.get_or_init(|| mid_scenario().0.snapshot())
}

/// The untouched state raises gross slip within the bound too, after the on-delay.
#[test]
fn the_untouched_state_raises_gross_slip() {
    let took = raises_gross_slip(&mid_scenario_state()).unwrap();
    assert!(
        took >= u64::from(Config::default().on_delay_ms),
        "{took} ms"
    );
}

use proptest::prelude::Strategy as _;

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(128))]

    /// The other way round: whatever a monitor reaches over a random stream (repeated
    /// and backward timestamps, gaps, wraps, faults, stops, slip, a measured F, a
    /// baseline captured on demand) passes every check and decodes to itself.
    #[test]
    fn every_reached_state_decodes(
        steps in proptest::collection::vec(proptest::prop_oneof![
            8 => 1u32..3_000,
            1 => proptest::prelude::Just(0u32),
            1 => (1u32..100_000).prop_map(|d| d.wrapping_neg()),
            1 => 10_000u32..10_000_000,
            1 => proptest::prelude::any::<u32>(),
        ], 1..400),
        loads in proptest::collection::vec(proptest::prop_oneof![
            8 => 1e3f32..4e3,
            1 => proptest::prelude::Just(f32::NAN),
            1 => 0.0f32..150.0,
        ], 400),
        phis in proptest::collection::vec(0.0f32..2.5e-3, 400),
        forced in proptest::collection::vec(proptest::prelude::any::<bool>(), 400),
        start in proptest::prelude::any::<u32>(),
        fast in proptest::prelude::any::<bool>(),
    ) {
        let config = if fast {
            Config { on_delay_ms: 1_000, off_delay_ms: 2_000, inhibit_ms: 3_000, fault_delay_ms: 1_500, ..Config::default() }
        } else {
            Config::default()
        };
        let mut m = Monitor::new(core(0.3), config).unwrap();
        let forward = core(0.3);
        let mut t = start;
        for (i, d) in steps.iter().enumerate() {
            t = t.wrapping_add(*d);
            let mut s = Sample::new(t, loads[i], phis[i]).with_speed(2.0);
            if forced[i]
                && let Ok(e) = forward.estimate_si(loads[i].max(0.0), phis[i])
                && e.axial_force.is_finite()
            {
                s = s.with_axial_force(e.axial_force * 0.8);
            }
            m.process_with_friction(s);
            if i % 97 == 96 {
                m.capture_friction_baseline();
            }
            if i % 3 == 0 {
                m.pop_event();
            }
            let state = m.snapshot();
            let mut record = vec![0u8; codec::record_len(MonitorState::SIZE)];
            let n = codec::encode(&state, 1, &mut record).unwrap();
            let decoded = codec::decode::<MonitorState>(&record[..n]).map(|d| d.value);
            proptest::prop_assert_eq!(decoded, Ok(state), "after sample {}", i);
        }
    }
}

/// The fieldbus link's events (raised by a Modbus server through the monitor) are
/// numbered with the monitor's own and kept in its checkpoint like them; a byte that
/// names no link event is refused.
#[test]
fn the_links_events_are_kept_in_the_checkpoint() {
    use misalign::monitor::FieldbusEvent as B;
    let (mut m, _) = mid_scenario();
    while m.pop_event().is_some() {}
    let next = m.next_event_seq();
    for e in [B::MasterLost, B::MasterBack, B::LineReverted] {
        m.raise_fieldbus(e);
    }
    let state = m.snapshot();
    let kinds: Vec<(u32, EventKind)> = state.events().iter().map(|e| (e.seq, e.kind)).collect();
    assert_eq!(
        kinds,
        [
            (next, EventKind::Fieldbus(B::MasterLost)),
            (next + 1, EventKind::Fieldbus(B::MasterBack)),
            (next + 2, EventKind::Fieldbus(B::LineReverted)),
        ]
    );
    let bytes = payload(&state);
    assert_eq!(decode::<MonitorState>(&bytes).unwrap(), state);
    // The kind's tag (3) and its byte, in the first event of the queue (after its
    // number, time and elapsed time).
    let queue = MonitorState::SIZE - EVENT_CAPACITY * EVENT - 1;
    let at = (queue..queue + 2)
        .find(|&q| bytes[q + 16..q + 18] == [3, 1])
        .expect("the tag of a link event and master lost");
    let mut bad = bytes.clone();
    bad[at + 17] = 3;
    assert!(decode::<MonitorState>(&bad).is_err());
}
