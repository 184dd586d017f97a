//! Commissioning over Modbus, driven as a master drives it: the staged and active
//! configuration, the scene block, `command` (commit, revert, lock), the unlock with
//! its timeout, wrong codes and lock-out, two masters interleaving, the committed image
//! restored at boot, and (feature `_mock-flash`) a power cut at every byte written and
//! every word erased of a commit's record.

use misalign::float::Auto;
use misalign::modbus::map::{Access, Domain, SAMPLES_ADDRESS, SCENE_ADDRESS, Table, TableMap};
use misalign::modbus::{
    AlarmSet, BootSource, DEFAULT_UNLOCK_CODE, IMAGE_LEN, LOCKOUT_S, Server, ServerConfig, Stored,
    UNLOCK_TIMEOUT_S, WRONG_CODES_MAX, command, crc16, reason, staged,
};
use misalign::monitor::{Config, Monitor, Sample, Thresholds, model_for_range};
use misalign::prepared::crc32;
use misalign::{Estimator, Scene};

fn core(scene: &Scene) -> Auto {
    Auto::with_choice(scene, model_for_range(scene, 5e3, 1e-5).unwrap()).unwrap()
}

/// A server over the demo scene with the default configuration, taking scenes.
fn server() -> Server<Auto> {
    let monitor = Monitor::new(core(&Scene::DEMO), Config::default()).unwrap();
    let mut s = Server::new(monitor, ServerConfig::default()).unwrap();
    s.accept_scenes();
    s.tick(0);
    s
}

/// The answer PDU (unit and CRC checked and removed) to a request to unit 1.
fn request<E: Estimator>(s: &mut Server<E>, function: u8, data: &[u8]) -> Vec<u8> {
    let mut adu = vec![1, function];
    adu.extend_from_slice(data);
    adu.extend_from_slice(&crc16(&adu).to_le_bytes());
    for b in adu {
        s.receive(b);
    }
    let answer = s.response().expect("an answer").to_vec();
    s.sent();
    let (body, crc) = answer.split_at(answer.len() - 2);
    assert_eq!(crc16(body).to_le_bytes(), [crc[0], crc[1]]);
    assert_eq!(body[0], 1);
    body[1..].to_vec()
}

fn words_be(words: &[u16]) -> Vec<u8> {
    words.iter().flat_map(|w| w.to_be_bytes()).collect()
}

/// Function 16; `Err(code)` for an exception.
fn write<E: Estimator>(s: &mut Server<E>, address: u16, words: &[u16]) -> Result<(), u8> {
    let mut data = words_be(&[address, words.len() as u16]);
    data.push((2 * words.len()) as u8);
    data.extend(words_be(words));
    answer(&request(s, 16, &data), 16)
}

/// Function 6; `Err(code)` for an exception.
fn write1<E: Estimator>(s: &mut Server<E>, address: u16, word: u16) -> Result<(), u8> {
    answer(&request(s, 6, &words_be(&[address, word])), 6)
}

fn answer(pdu: &[u8], function: u8) -> Result<(), u8> {
    if pdu[0] == function {
        Ok(())
    } else {
        assert_eq!(pdu[0], function | 0x80, "{pdu:?}");
        Err(pdu[1])
    }
}

/// Function 3.
fn read<E: Estimator>(s: &mut Server<E>, address: u16, n: u16) -> Vec<u16> {
    let pdu = request(s, 3, &words_be(&[address, n]));
    assert_eq!(pdu[0], 3, "{pdu:?}");
    pdu[2..]
        .chunks_exact(2)
        .map(|c| u16::from_be_bytes([c[0], c[1]]))
        .collect()
}

fn at(name: &str) -> u16 {
    let e = TableMap::of(Table::Holding)
        .entries
        .iter()
        .find(|e| e.name == name)
        .unwrap_or_else(|| panic!("no holding register {name}"));
    e.address
}

/// A holding register's value (one or two registers, as the map says).
fn get<E: Estimator>(s: &mut Server<E>, name: &str) -> u32 {
    let e = TableMap::of(Table::Holding)
        .entries
        .iter()
        .find(|e| e.name == name)
        .unwrap();
    let w = read(s, e.address, e.ty.words());
    w.iter().fold(0, |v, &x| v << 16 | u32::from(x))
}

fn put<E: Estimator>(s: &mut Server<E>, name: &str, v: u32) -> Result<(), u8> {
    let e = TableMap::of(Table::Holding)
        .entries
        .iter()
        .find(|e| e.name == name)
        .unwrap();
    if e.ty.words() == 2 {
        write(s, e.address, &[(v >> 16) as u16, v as u16])
    } else {
        write(s, e.address, &[v as u16])
    }
}

fn unlock<E: Estimator>(s: &mut Server<E>) {
    write1(s, at("unlock"), DEFAULT_UNLOCK_CODE).unwrap();
}

fn cmd<E: Estimator>(s: &mut Server<E>, c: u16) -> Result<(), u8> {
    write1(s, at("command"), c)
}

/// The configuration block of a view (`config` staged, `active`).
fn view<E: Estimator>(s: &mut Server<E>, prefix: &str) -> Vec<u16> {
    read(s, at(&format!("{prefix}_thresholds_on")), 64)
}

#[test]
fn staged_and_active_views_and_a_commit() {
    let mut s = server();
    assert_eq!(get(&mut s, "config_source"), 0);
    let defaults = view(&mut s, "active");
    assert_eq!(view(&mut s, "config"), defaults);
    assert_eq!(get(&mut s, "active_warning"), 0.8f32.to_bits());
    assert_eq!(get(&mut s, "active_on_delay"), 5_000);

    // Locked: refused, nothing staged, counted.
    assert_eq!(put(&mut s, "config_warning", 0.7f32.to_bits()), Err(1));
    assert_eq!(cmd(&mut s, command::COMMIT), Err(1));
    assert_eq!(get(&mut s, "refused_writes"), 2);
    assert_eq!(view(&mut s, "config"), defaults);

    unlock(&mut s);
    assert!(s.unlocked());
    assert_eq!(get(&mut s, "unlock"), UNLOCK_TIMEOUT_S);
    put(&mut s, "config_warning", 0.7f32.to_bits()).unwrap();
    put(&mut s, "config_on_delay", 1_000).unwrap();
    assert_eq!(get(&mut s, "config_warning"), 0.7f32.to_bits());
    assert_eq!(get(&mut s, "active_warning"), 0.8f32.to_bits());
    assert_eq!(get(&mut s, "staged"), u32::from(staged::CONFIG));
    assert_eq!(get(&mut s, "staged_generation"), 2);
    assert_eq!(s.monitor().config(), &Config::default());

    cmd(&mut s, command::COMMIT).unwrap();
    let expected = Config {
        thresholds: Thresholds::SlipRatio {
            warning: 0.7,
            alarm: 1.0,
            deadband: 0.05,
        },
        on_delay_ms: 1_000,
        ..Config::default()
    };
    assert_eq!(s.monitor().config(), &expected);
    assert_eq!(view(&mut s, "active"), view(&mut s, "config"));
    assert_eq!(get(&mut s, "staged"), 0);
    assert_eq!(get(&mut s, "commit_error"), u32::from(reason::NONE));
    assert_eq!(get(&mut s, "config_source"), BootSource::Committed as u32);
    // The commit ends the unlock.
    assert!(!s.unlocked());
    assert_eq!(put(&mut s, "config_warning", 0.6f32.to_bits()), Err(1));
    // Once to persist, then nothing.
    let mut image = [0; IMAGE_LEN];
    assert!(s.take_committed(&mut image));
    assert!(!s.take_committed(&mut image));
    assert_eq!(s.commissioning().commits, 1);

    // A revert discards what is staged and keeps the unlock.
    unlock(&mut s);
    put(&mut s, "config_gap", 20_000).unwrap();
    cmd(&mut s, command::REVERT).unwrap();
    assert_eq!(view(&mut s, "config"), view(&mut s, "active"));
    assert_eq!(get(&mut s, "staged"), 0);
    assert!(s.unlocked());
    cmd(&mut s, command::LOCK).unwrap();
    assert!(!s.unlocked());
    // Reading and acknowledging need no code.
    write1(&mut s, at("acknowledge_alarms"), 15).unwrap();
}

#[test]
fn commits_refused_with_their_reason_and_nothing_applied() {
    let mut s = server();
    unlock(&mut s);
    // Nothing staged.
    assert_eq!(cmd(&mut s, command::COMMIT), Err(3));
    assert_eq!(
        get(&mut s, "commit_error"),
        u32::from(reason::NOTHING_STAGED)
    );
    assert_eq!(get(&mut s, "config_source"), BootSource::Defaults as u32);
    // An unknown command.
    assert_eq!(cmd(&mut s, 9), Err(3));

    let refused = |s: &mut Server<Auto>, name: &str, v: u32, why: u16| {
        put(s, name, v).unwrap();
        assert_eq!(cmd(s, command::COMMIT), Err(3), "{name} = {v}");
        assert_eq!(get(s, "commit_error"), u32::from(why), "{name} = {v}");
        assert_eq!(s.monitor().config(), &Config::default(), "{name} = {v}");
        // Still staged, still unlocked: the master corrects it or reverts.
        assert!(s.unlocked());
        cmd(s, command::REVERT).unwrap();
    };
    use misalign::monitor::ConfigError as E;
    refused(
        &mut s,
        "config_warning",
        1.5f32.to_bits(),
        reason::config(E::WarningAboveAlarm),
    );
    refused(
        &mut s,
        "config_warning",
        f32::NAN.to_bits(),
        reason::config(E::Threshold),
    );
    refused(
        &mut s,
        "config_deadband",
        (-0.1f32).to_bits(),
        reason::config(E::Deadband),
    );
    refused(&mut s, "config_stop_load", 0, reason::config(E::Stop));
    refused(
        &mut s,
        "config_load_max",
        f32::INFINITY.to_bits(),
        reason::config(E::Range),
    );
    refused(
        &mut s,
        "config_spike_window",
        8,
        reason::config(E::SpikeWindow),
    );
    refused(
        &mut s,
        "config_spike_window",
        2,
        reason::config(E::SpikeWindow),
    );
    refused(&mut s, "config_trend_points", 17, reason::config(E::Trend));
    refused(&mut s, "config_trend_points", 300, reason::config(E::Trend));
    refused(
        &mut s,
        "config_smoothing_tau",
        (-1f32).to_bits(),
        reason::config(E::Smoothing),
    );
    refused(
        &mut s,
        "config_friction_deadband",
        0.3f32.to_bits(),
        reason::config(E::Friction),
    );
    refused(
        &mut s,
        "config_nominal_speed",
        0,
        reason::config(E::NominalSpeed),
    );

    // A switch outside its domain is refused at the write (03), nothing staged.
    assert_eq!(put(&mut s, "config_thresholds_on", 2), Err(3));
    assert_eq!(put(&mut s, "config_friction", 7), Err(3));
    assert_eq!(get(&mut s, "staged"), 0);
    // A write of several values that fails on one writes none of them.
    let first = at("config_thresholds_on");
    let generation = get(&mut s, "staged_generation");
    assert_eq!(write(&mut s, first, &[5, 0x3F33, 0x3333]), Err(3));
    assert_eq!(get(&mut s, "staged_generation"), generation);
    assert_eq!(view(&mut s, "config"), view(&mut s, "active"));

    // At the limits: accepted, and every option off.
    put(&mut s, "config_spike_window", 3).unwrap();
    put(&mut s, "config_trend_points", 16).unwrap();
    cmd(&mut s, command::COMMIT).unwrap();
    assert_eq!(s.monitor().config().spikes.unwrap().window, 3);
    assert_eq!(s.monitor().config().trend.unwrap().points, 16);
    unlock(&mut s);
    put(&mut s, "config_spike_window", 0).unwrap();
    put(&mut s, "config_trend_interval", 0).unwrap();
    put(&mut s, "config_friction", 0).unwrap();
    put(&mut s, "config_thresholds_on", 1).unwrap();
    put(&mut s, "config_warning", 1e-4f32.to_bits()).unwrap();
    put(&mut s, "config_alarm", 0).unwrap();
    put(&mut s, "config_deadband", 2e-5f32.to_bits()).unwrap();
    put(&mut s, "config_on_delay", u32::MAX).unwrap();
    cmd(&mut s, command::COMMIT).unwrap();
    let c = s.monitor().config();
    assert_eq!((c.spikes, c.trend, c.friction), (None, None, None));
    assert_eq!(
        c.thresholds,
        Thresholds::Margin {
            warning: 1e-4,
            alarm: 0.0,
            deadband: 2e-5
        }
    );
    assert_eq!(c.on_delay_ms, u32::MAX);
    // The options off read 0 in their values too; the views agree.
    assert_eq!(get(&mut s, "active_spike_k"), 0);
    assert_eq!(view(&mut s, "active"), view(&mut s, "config"));
}

/// A scene other than the demo's, prepared as the PC prepares it.
fn other_scene() -> (Auto, Vec<u8>) {
    let scene = Scene::new(0.04, 0.08, 79.3e9, 0.3, 0.25).unwrap();
    let c = core(&scene);
    let bytes = c.to_bytes().to_vec();
    (c, bytes)
}

/// The scene's bytes as registers, high byte first, the last odd byte padded.
fn scene_words(bytes: &[u8]) -> Vec<u16> {
    bytes
        .chunks(2)
        .map(|c| u16::from_be_bytes([c[0], c.get(1).copied().unwrap_or(0)]))
        .collect()
}

#[test]
fn a_scene_written_in_blocks_replaces_the_estimators() {
    let mut s = server();
    let (new_core, bytes) = other_scene();
    assert_eq!(get(&mut s, "scene_bytes") as usize, Auto::BYTES);
    let words = scene_words(&bytes);
    // Locked: refused.
    assert_eq!(write(&mut s, SCENE_ADDRESS, &words), Err(1));
    unlock(&mut s);
    // In two writes, the second first.
    let half = words.len() / 2;
    write(&mut s, SCENE_ADDRESS + half as u16, &words[half..]).unwrap();
    write(&mut s, SCENE_ADDRESS, &words[..half]).unwrap();
    let own_crc = u32::from_le_bytes(bytes[bytes.len() - 4..].try_into().unwrap());
    assert_eq!(get(&mut s, "scene_staged_crc"), own_crc);
    assert_ne!(get(&mut s, "scene_active_crc"), own_crc);
    assert_eq!(get(&mut s, "staged"), u32::from(staged::SCENE));
    // The block reads 0 (its CRC says what is held); past its end is no register.
    assert_eq!(read(&mut s, SCENE_ADDRESS, 2), vec![0, 0]);
    assert_eq!(write(&mut s, SCENE_ADDRESS + 64, &[1]), Err(2));

    // Samples before and after: the next reading is the new scene's.
    for i in 0..5 {
        s.process(Sample::new(i * 1000, 2e3, 1e-4).with_speed(2.0));
    }
    cmd(&mut s, command::COMMIT).unwrap();
    assert_eq!(s.monitor().estimator().to_bytes().to_vec(), bytes);
    assert_eq!(get(&mut s, "scene_active_crc"), own_crc);
    assert_eq!(s.monitor().config(), &Config::default());
    // The conditioning starts afresh with the new scene: its reading comes once 7
    // samples have filled the spike window, at the 8th.
    for i in 5..13 {
        s.process(Sample::new(i * 1000, 3e3 + i as f32, 2e-4).with_speed(2.0));
    }
    let r = s.monitor().reading().unwrap();
    let e = new_core.estimate_si(r.load, r.phi).unwrap();
    assert_eq!(r.slip_ratio.to_bits(), e.slip_ratio.to_bits());
    assert_eq!(s.monitor().statistics().samples(), 13);
}

#[test]
fn damaged_and_foreign_scenes_are_refused_whole() {
    let mut s = server();
    let before = s.monitor().estimator().to_bytes();
    let (_, good) = other_scene();
    let try_scene = |s: &mut Server<Auto>, bytes: &[u8], why: u16| {
        unlock(s);
        write(s, SCENE_ADDRESS, &scene_words(bytes)).unwrap();
        assert_eq!(cmd(s, command::COMMIT), Err(3));
        assert_eq!(get(s, "commit_error"), u32::from(why));
        assert_eq!(s.monitor().estimator().to_bytes(), before);
        cmd(s, command::REVERT).unwrap();
    };
    use misalign::prepared::PreparedError as P;
    // A valid CRC over nonsense: the risk threshold (the f32 before the CRC) made
    // negative, the CRC made anew.
    let mut nonsense = good.clone();
    let n = nonsense.len();
    nonsense[n - 5] |= 0x80;
    let crc = crc32(&nonsense[..n - 4]);
    nonsense[n - 4..].copy_from_slice(&crc.to_le_bytes());
    try_scene(&mut s, &nonsense, reason::scene(P::Value));
    // A byte changed under the old CRC.
    let mut damaged = good.clone();
    damaged[20] ^= 1;
    try_scene(&mut s, &damaged, reason::scene(P::Checksum));
    // Another core's scene.
    let fixed = misalign::fixed::FixedAuto::new(&Scene::DEMO, 1e-3, 1e-11)
        .unwrap()
        .to_bytes();
    try_scene(&mut s, &fixed[..Auto::BYTES], reason::scene(P::Kind));
    let mut version = good.clone();
    version[3] = 9;
    try_scene(&mut s, &version, reason::scene(P::Version));
    try_scene(&mut s, &[0; 8], reason::scene(P::Magic));
    // A server that takes no scene refuses the block.
    let monitor = Monitor::new(core(&Scene::DEMO), Config::default()).unwrap();
    let mut plain = Server::new(monitor, ServerConfig::default()).unwrap();
    unlock(&mut plain);
    assert_eq!(get(&mut plain, "scene_bytes"), 0);
    assert_eq!(write(&mut plain, SCENE_ADDRESS, &[0x4D53]), Err(1));
}

#[test]
fn unlock_times_out_and_wrong_codes_lock_out() {
    let mut s = server();
    let timeout = UNLOCK_TIMEOUT_S * 1000;
    unlock(&mut s);
    s.tick(timeout - 1);
    assert!(s.unlocked());
    // A write the unlock allows renews it.
    put(&mut s, "config_gap", 20_000).unwrap();
    s.tick(2 * timeout - 2);
    assert!(s.unlocked());
    s.tick(2 * timeout - 1);
    assert!(!s.unlocked());
    assert_eq!(put(&mut s, "config_gap", 30_000), Err(1));
    assert_eq!(get(&mut s, "unlock"), 0);

    // A wrap of the millisecond counter is a step forward; a step back is none.
    s.tick(u32::MAX - 500);
    unlock(&mut s);
    s.tick(500);
    assert!(s.unlocked());
    // 1001 ms so far; back to 0 counts none, the time goes on from there.
    s.tick(0);
    s.tick(timeout - 1002);
    assert!(s.unlocked());
    s.tick(timeout - 1001);
    assert!(!s.unlocked());

    // Wrong codes: 03 each, counted; a right one in between starts the count again.
    let mut now = 10_000;
    s.tick(now);
    let wrong = DEFAULT_UNLOCK_CODE.wrapping_add(1);
    for _ in 1..WRONG_CODES_MAX {
        assert_eq!(write1(&mut s, at("unlock"), wrong), Err(3));
    }
    unlock(&mut s);
    cmd(&mut s, command::LOCK).unwrap();
    assert_eq!(
        get(&mut s, "unlock_failures"),
        u32::from(WRONG_CODES_MAX) - 1
    );

    // A burst: the lock-out after WRONG_CODES_MAX, then every code refused (01), the
    // right one too, each answered and counted; nothing changes.
    let generation = get(&mut s, "staged_generation");
    let burst = 50;
    for i in 0..burst {
        let expect = if i < WRONG_CODES_MAX { 3 } else { 1 };
        assert_eq!(write1(&mut s, at("unlock"), wrong), Err(expect), "{i}");
    }
    assert_eq!(write1(&mut s, at("unlock"), DEFAULT_UNLOCK_CODE), Err(1));
    assert!(!s.unlocked());
    assert_eq!(s.commissioning().lockouts, 1);
    assert_eq!(
        s.commissioning().unlock_failures,
        u32::from(WRONG_CODES_MAX) - 1 + burst as u32 + 1
    );
    assert_eq!(get(&mut s, "lockout"), LOCKOUT_S);
    now += LOCKOUT_S * 1000 - 1;
    s.tick(now);
    assert_eq!(get(&mut s, "lockout"), 1);
    assert_eq!(write1(&mut s, at("unlock"), DEFAULT_UNLOCK_CODE), Err(1));
    s.tick(now + 1);
    unlock(&mut s);
    assert_eq!(s.monitor().config(), &Config::default());
    assert_eq!(get(&mut s, "staged_generation"), generation);

    // `unlock` and `command` are written alone.
    assert_eq!(
        write(&mut s, at("unlock"), &[DEFAULT_UNLOCK_CODE, command::LOCK]),
        Err(2)
    );
}

#[test]
fn a_new_code_is_in_force_after_the_commit() {
    let mut s = server();
    unlock(&mut s);
    put(&mut s, "new_code", 4321).unwrap();
    assert_eq!(get(&mut s, "new_code"), 0);
    assert_eq!(get(&mut s, "staged"), u32::from(staged::CODE));
    // Not before the commit.
    cmd(&mut s, command::LOCK).unwrap();
    unlock(&mut s);
    cmd(&mut s, command::COMMIT).unwrap();
    assert_eq!(write1(&mut s, at("unlock"), DEFAULT_UNLOCK_CODE), Err(3));
    write1(&mut s, at("unlock"), 4321).unwrap();
}

#[test]
fn two_masters_interleaving_see_each_others_writes_and_commit_one_whole_copy() {
    let mut s = server();
    // Master A unlocks and writes the thresholds; master B, on the same node, writes
    // the delays between A's writes. One node, one unlock, one staged copy.
    unlock(&mut s);
    let a_first = get(&mut s, "staged_generation");
    write(
        &mut s,
        at("config_warning"),
        &[0x3F33, 0x3333, 0x3F70, 0x0000],
    )
    .unwrap();
    put(&mut s, "config_on_delay", 2_000).unwrap();
    put(&mut s, "config_deadband", 0.1f32.to_bits()).unwrap();
    // A wrote 3 values; the generation says another master wrote too.
    let a_last = get(&mut s, "staged_generation");
    assert_eq!(a_last - a_first, 4);
    let staged_view = view(&mut s, "config");
    cmd(&mut s, command::COMMIT).unwrap();
    // What was committed is exactly the staged copy, validated whole.
    assert_eq!(view(&mut s, "active"), staged_view);
    let c = s.monitor().config();
    assert_eq!(c.on_delay_ms, 2_000);
    assert_eq!(
        c.thresholds,
        Thresholds::SlipRatio {
            warning: 0.7,
            alarm: 0.9375,
            deadband: 0.1
        }
    );
    // B's commit after A's finds it locked (the commit ended the unlock).
    assert_eq!(cmd(&mut s, command::COMMIT), Err(1));
}

#[test]
fn the_committed_image_restores_at_boot() {
    let mut s = server();
    let (_, bytes) = other_scene();
    unlock(&mut s);
    put(&mut s, "config_alarm", 1.2f32.to_bits()).unwrap();
    put(&mut s, "new_code", 777).unwrap();
    write(&mut s, SCENE_ADDRESS, &scene_words(&bytes)).unwrap();
    cmd(&mut s, command::COMMIT).unwrap();
    let mut image = [0; IMAGE_LEN];
    assert!(s.take_committed(&mut image));

    let mut booted = server();
    assert_eq!(booted.restore(Stored::Image(&image)), BootSource::Committed);
    assert_eq!(booted.monitor().config(), s.monitor().config());
    assert_eq!(booted.monitor().estimator().to_bytes().to_vec(), bytes);
    assert_eq!(get(&mut booted, "config_source"), 1);
    assert_eq!(view(&mut booted, "config"), view(&mut booted, "active"));
    assert_eq!(
        write1(&mut booted, at("unlock"), DEFAULT_UNLOCK_CODE),
        Err(3)
    );
    write1(&mut booted, at("unlock"), 777).unwrap();
    // Nothing persisted by a restore.
    assert!(!booted.take_committed(&mut [0; IMAGE_LEN]));

    let mut fresh = server();
    assert_eq!(fresh.restore(Stored::Nothing), BootSource::Defaults);
    assert_eq!(fresh.restore(Stored::Damaged), BootSource::DefaultsDamaged);
    assert_eq!(get(&mut fresh, "config_source"), 2);
    // Images that are not one: nothing applied, the defaults run, said so.
    let demo = fresh.monitor().estimator().to_bytes();
    let mut cases: Vec<Vec<u8>> = vec![image[..IMAGE_LEN - 1].to_vec(), vec![0; IMAGE_LEN]];
    let mut bad = image;
    bad[0] = misalign::modbus::IMAGE_VERSION + 1; // a newer image version
    cases.push(bad.to_vec());
    let mut bad = image;
    bad[1] |= 8; // a flag no version has
    cases.push(bad.to_vec());
    let mut bad = image;
    bad[4 + 2 * 31] = 0; // spike_window 9: the configuration fails validate
    bad[4 + 2 * 31] = 9;
    cases.push(bad.to_vec());
    let mut bad = image;
    bad[4 + 128 + 2 + 20] ^= 1; // the scene's CRC fails
    cases.push(bad.to_vec());
    for (i, case) in cases.iter().enumerate() {
        let mut b = server();
        assert_eq!(
            b.restore(Stored::Image(case)),
            BootSource::DefaultsDamaged,
            "{i}"
        );
        assert_eq!(b.monitor().config(), &Config::default(), "{i}");
        assert_eq!(b.monitor().estimator().to_bytes(), demo, "{i}");
        write1(&mut b, at("unlock"), DEFAULT_UNLOCK_CODE).unwrap();
    }
}

/// Which alarms latch and where samples come from are switched at once (behind the
/// unlock) and kept as a commit is: each switch hands the application an image to
/// store, and a node booted from it switches as it did. A version 1 image (from before
/// the image kept them) still restores its configuration, the switches the build's.
#[test]
fn latching_and_the_samples_source_are_kept_through_a_reset() {
    let mut s = server();
    let mut image = [0; IMAGE_LEN];
    unlock(&mut s);
    coil(&mut s, at_coil("latch_alarm"), true).unwrap();
    assert!(s.take_committed(&mut image), "a switch is kept");
    assert!(!s.take_committed(&mut [0; IMAGE_LEN]), "once");
    assert_eq!(get(&mut s, "config_source"), 1);
    write1(&mut s, at("external_mode"), 1).unwrap();
    write1(&mut s, at("latching"), 0b1001).unwrap();
    assert!(s.take_committed(&mut image));
    // The same values again (a master writing them cyclically): nothing to store.
    write1(&mut s, at("latching"), 0b1001).unwrap();
    coil(&mut s, at_coil("external_samples"), true).unwrap();
    assert!(!s.take_committed(&mut [0; IMAGE_LEN]));
    let mut booted = server();
    assert_eq!(booted.restore(Stored::Image(&image)), BootSource::Committed);
    assert_eq!(
        booted.annunciator().latching(),
        AlarmSet::WARNING.union(AlarmSet::APPROACHING)
    );
    assert!(booted.external_samples());

    // A commit keeps them too; switched off, they stay off.
    unlock(&mut booted);
    coil(&mut booted, at_coil("external_samples"), false).unwrap();
    put(&mut booted, "config_on_delay", 4000).unwrap();
    cmd(&mut booted, command::COMMIT).unwrap();
    assert!(booted.take_committed(&mut image));
    let mut again = server();
    assert_eq!(again.restore(Stored::Image(&image)), BootSource::Committed);
    assert_eq!(again.monitor().config().on_delay_ms, 4000);
    assert_eq!(
        again.annunciator().latching(),
        booted.annunciator().latching()
    );
    assert!(!again.external_samples());

    // Version 1: the configuration, and the build's switches.
    // Versions 1 and 2 are 62 bytes shorter: no line settings, no sensor settings.
    let mut v1 = image[..IMAGE_LEN - 62].to_vec();
    v1[0] = 1;
    v1[1] &= 1;
    let monitor = Monitor::new(core(&Scene::DEMO), Config::default()).unwrap();
    let built = ServerConfig {
        latching: AlarmSet::SENSOR_FAULT,
        external_samples: true,
        ..ServerConfig::default()
    };
    let mut old = Server::new(monitor, built).unwrap();
    old.accept_scenes();
    assert_eq!(old.restore(Stored::Image(&v1)), BootSource::Committed);
    assert_eq!(old.monitor().config().on_delay_ms, 4000);
    assert_eq!(old.annunciator().latching(), AlarmSet::SENSOR_FAULT);
    assert!(old.external_samples());
    let mut bad = v1.clone();
    bad[1] = 0x11; // switches in a version 1 image
    assert_eq!(
        server().restore(Stored::Image(&bad)),
        BootSource::DefaultsDamaged
    );
}

/// Resetting the statistics (command 4) changes state: refused while locked, counted,
/// nothing reset; after the unlock the counts, times and energies start afresh while
/// the state, the events and the unlock go on.
#[test]
fn resetting_the_statistics_needs_the_unlock_and_keeps_state_and_events() {
    let mut s = server();
    for i in 0..400u32 {
        let phi = if i < 200 { 1e-4 } else { 3e-3 };
        let noise = (i % 7) as f32;
        s.process(Sample::new(i * 1000, 2e3 + noise, phi + 1e-8 * noise).with_speed(2.0));
    }
    let stats = *s.monitor().statistics();
    assert!(stats.samples() == 400 && stats.total_energy() > 0.0);
    let (state, next) = (s.monitor().state(), s.monitor().next_event_seq());
    assert!(next > 0, "events raised");

    let refused = get(&mut s, "refused_writes");
    assert_eq!(cmd(&mut s, command::RESET_STATISTICS), Err(1));
    assert_eq!(get(&mut s, "refused_writes"), refused + 1);
    assert_eq!(*s.monitor().statistics(), stats);

    unlock(&mut s);
    cmd(&mut s, command::RESET_STATISTICS).unwrap();
    let fresh = s.monitor().statistics();
    assert_eq!(fresh.samples(), 0);
    assert_eq!(fresh.total_energy(), 0.0);
    assert_eq!(fresh.time_in_state_ms(state), 0);
    assert_eq!(s.monitor().state(), state);
    assert_eq!(s.monitor().next_event_seq(), next);
    assert!(s.unlocked());
    // Counting goes on from zero.
    s.process(Sample::new(400_000, 2e3, 3e-3).with_speed(2.0));
    assert_eq!(s.monitor().statistics().samples(), 1);
    assert!(s.monitor().statistics().total_energy() > 0.0);
}

/// `events_dropped` (the monitor's queue and the event window) is a statistic: it
/// starts afresh with the others, while the events' numbers go on.
#[test]
fn resetting_the_statistics_starts_events_dropped_afresh() {
    let mut s = server();
    let dropped = |s: &mut Server<Auto>| {
        let e = TableMap::of(Table::Input)
            .entries
            .iter()
            .find(|e| e.name == "events_dropped")
            .unwrap();
        let pdu = request(s, 4, &words_be(&[e.address, 2]));
        u32::from_be_bytes([pdu[2], pdu[3], pdu[4], pdu[5]])
    };
    // A sensor fault every 40 s, cleared after the off-delay: an event in and one
    // out, never read.
    let mut i = 0u32;
    let mut sample = |s: &mut Server<Auto>| {
        let noise = (i % 7) as f32;
        let load = if i % 40 == 39 { f32::NAN } else { 1e3 + noise };
        s.process(Sample::new(i * 1000, load, 5e-5 + 1e-8 * noise).with_speed(2.0));
        i += 1;
    };
    while s.monitor().next_event_seq() < 20 {
        sample(&mut s);
    }
    assert!(dropped(&mut s) >= 12, "{}", dropped(&mut s));
    unlock(&mut s);
    cmd(&mut s, command::RESET_STATISTICS).unwrap();
    assert_eq!(dropped(&mut s), 0);
    assert_eq!(s.monitor().next_event_seq(), 20);
    while s.monitor().next_event_seq() < 22 {
        sample(&mut s);
    }
    assert_eq!(dropped(&mut s), 2, "counted again from 0");
}

fn at_coil(name: &str) -> u16 {
    TableMap::of(Table::Coil)
        .entries
        .iter()
        .find(|e| e.name == name)
        .unwrap_or_else(|| panic!("no coil {name}"))
        .address
}

/// The commit's record on the mock flash: a power cut at every byte written and every
/// word erased while the new image is stored leaves the old image or the new, whole,
/// and the server runs the one it finds.
#[cfg(feature = "_mock-flash")]
mod power_loss {
    use super::*;
    use misalign::storage::{
        BlockingFlash, ConfigImage, MockError, MockFlash, RestoreOutcome, StorageError, Store,
        block_on,
    };

    type Flash = MockFlash<4, 1024, 4>;
    type S = Store<BlockingFlash<Flash>, 348>;
    type Image = ConfigImage<IMAGE_LEN>;

    fn open(flash: Flash) -> S {
        Store::new(BlockingFlash(flash), 0..4096, 3600).unwrap()
    }

    /// The image of the `n`-th commit: on-delay n seconds (0: none committed).
    fn image(n: u32) -> Image {
        let mut s = server();
        unlock(&mut s);
        put(&mut s, "config_on_delay", n * 1000).unwrap();
        cmd(&mut s, command::COMMIT).unwrap();
        let mut out = ConfigImage::new();
        assert!(s.take_committed(&mut out.0));
        out
    }

    /// Boots a server from the flash: the commit it runs (0: the defaults).
    fn boot(flash: Flash) -> (S, u32) {
        let mut store = open(flash);
        let restored = block_on(store.restore::<Image>()).unwrap();
        let stored = match (&restored.value, restored.outcome) {
            (Some(v), _) => Stored::Image(&v.0),
            (None, RestoreOutcome::Blank) => Stored::Nothing,
            (None, _) => Stored::Damaged,
        };
        let mut s = server();
        let source = s.restore(stored);
        let on_delay = s.monitor().config().on_delay_ms;
        let n = match source {
            BootSource::Committed => on_delay / 1000,
            _ => {
                assert_eq!(s.monitor().config(), &Config::default());
                0
            }
        };
        (store, n)
    }

    /// The image and its record as docs/formats.md lays them out.
    #[test]
    fn the_image_is_the_documented_one() {
        use misalign::storage::{Checkpoint, codec, kind};
        let spec = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/formats.md"))
            .unwrap();
        let row = format!(
            "| {} (`storage::kind::COMMITTED_CONFIG`) | `storage::ConfigImage<N>` | {} | N (the Modbus server's image: {IMAGE_LEN}) |",
            kind::COMMITTED_CONFIG,
            Image::VERSION
        );
        assert!(spec.contains(&row), "docs/formats.md lacks {row}");
        assert_eq!(Image::KIND, kind::COMMITTED_CONFIG);

        let mut s = server();
        let (_, bytes) = other_scene();
        unlock(&mut s);
        put(&mut s, "new_code", 0xBEEF).unwrap();
        put(&mut s, "config_on_delay", 0x0102_0304).unwrap();
        write(&mut s, SCENE_ADDRESS, &scene_words(&bytes)).unwrap();
        cmd(&mut s, command::COMMIT).unwrap();
        let mut image = ConfigImage::new();
        assert!(s.take_committed(&mut image.0));
        let i = &image.0;
        // Flags: a scene follows (bit 0), committed over the bus (bit 2).
        assert_eq!(i[..4], [misalign::modbus::IMAGE_VERSION, 1 | 4, 0xEF, 0xBE]);
        let version = format!(
            "| 0 | 1 | image version: {} |",
            misalign::modbus::IMAGE_VERSION
        );
        assert!(spec.contains(&version), "docs/formats.md lacks {version}");
        // The registers from config_thresholds_on, each u16 little-endian.
        let offset = usize::from(at("config_on_delay") - at("config_thresholds_on"));
        assert_eq!(i[4 + 2 * offset..][..4], [0x02, 0x01, 0x04, 0x03]);
        assert_eq!(
            at("config_friction_delay") + 2 - at("config_thresholds_on"),
            64
        );
        assert_eq!(i[132..134], (Auto::BYTES as u16).to_le_bytes());
        assert_eq!(i[134..134 + bytes.len()], bytes[..]);
        assert!(i[134 + bytes.len()..262].iter().all(|&b| b == 0));
        // The line settings: the defaults (unit 1, even parity, 19200 baud, no answer
        // delay, no bus timeout).
        assert_eq!(i[262..272], [1, 2, 0x00, 0x4B, 0, 0, 0, 0, 0, 0]);
        assert!(spec.contains("| 262 | 1 | the unit id"));
        // The sensor settings: the defaults, each register's bits u32 little-endian,
        // the sample period (ms) first.
        assert_eq!(i[272..276], 100u32.to_le_bytes());
        assert_eq!(i[276..280], 0f32.to_bits().to_le_bytes());
        assert_eq!(IMAGE_LEN, 324);
        assert!(spec.contains("| 272 | 4 | the sample period"));
        // In its record: the frame of every checkpoint record, this payload.
        let mut record = vec![0; codec::record_len(IMAGE_LEN)];
        codec::encode(&image, 9, &mut record).unwrap();
        assert_eq!(&record[..6], &[b'M', b'S', b'L', b'G', 4, 1]);
        assert_eq!(record[16..16 + IMAGE_LEN], image.0);
        assert_eq!(codec::decode::<Image>(&record).unwrap().value, image);
    }

    #[test]
    fn a_power_cut_at_every_point_of_a_commit_leaves_the_old_or_the_new() {
        let mut base = Flash::new();
        let mut points_total = 0;
        // Enough commits for the map to erase sectors (2 records a sector).
        for n in 1..=10u32 {
            let new = image(n);
            // How many points the write takes.
            let mut probe = open(base.clone());
            block_on(probe.restore::<Image>()).unwrap();
            let start = probe.into_flash().0.points();
            let mut probe = open(base.clone());
            block_on(probe.restore::<Image>()).unwrap();
            block_on(probe.checkpoint(&new)).unwrap();
            let points = probe.into_flash().0.points() - start;
            for p in 0..points {
                let mut flash = base.clone();
                flash.cut_after(p);
                let (mut store, before) = boot(flash);
                assert_eq!(before, n - 1, "commit {n}, point {p}");
                assert_eq!(
                    block_on(store.checkpoint(&new)),
                    Err(StorageError::Flash(MockError::PowerLoss)),
                    "commit {n}, point {p}"
                );
                let mut flash = store.into_flash().0;
                flash.restart();
                let (_, after) = boot(flash);
                assert!(
                    after == n || after + 1 == n,
                    "commit {n}, point {p}: {after}"
                );
            }
            points_total += points;
            let mut store = open(base);
            block_on(store.restore::<Image>()).unwrap();
            block_on(store.checkpoint(&new)).unwrap();
            base = store.into_flash().0;
            assert_eq!(boot(base.clone()).1, n);
        }
        eprintln!("{points_total} power cuts over 10 commits");
        assert!(points_total > 10 * IMAGE_LEN as u64, "{points_total}");
    }

    use misalign::monitor::MonitorState;

    /// The node's store (nodes/firmware/persist.rs): the committed image beside the
    /// monitor's state checkpoints, one map, one buffer for the larger record.
    const BOTH_BUF: usize = {
        let state = Store::<BlockingFlash<Flash>, 0>::buffer_len::<MonitorState>();
        let image = Store::<BlockingFlash<Flash>, 0>::buffer_len::<Image>();
        if state > image { state } else { image }
    };
    type Both = Store<BlockingFlash<Flash>, BOTH_BUF>;

    fn open_both(flash: Flash) -> Both {
        Store::new(BlockingFlash(flash), 0..4096, 60).unwrap()
    }

    /// What a boot finds: the commit it runs (0: none) and the state restored.
    fn boot_both(flash: Flash) -> (Both, u32, Option<MonitorState>) {
        let mut store = open_both(flash);
        let image = block_on(store.restore::<Image>()).unwrap();
        let commit = match image.value {
            Some(image) => {
                let mut s = server();
                assert_eq!(s.restore(Stored::Image(&image.0)), BootSource::Committed);
                s.monitor().config().on_delay_ms / 1000
            }
            None => 0,
        };
        let mut state = MonitorState::default();
        let restored = matches!(
            block_on(store.restore_into(&mut state)).unwrap(),
            RestoreOutcome::Restored { .. }
        );
        (store, commit, restored.then_some(state))
    }

    /// The store as the node writes it: a state checkpoint and a commit in turn. A
    /// power cut at every point of each leaves the other record as it was and its own
    /// old or new, whole, through the sectors the map erases and the records it moves.
    #[test]
    fn a_power_cut_in_a_store_of_state_and_commits_spares_the_other_record() {
        let mut monitor = Monitor::new(core(&Scene::DEMO), Config::default()).unwrap();
        let mut base = Flash::new();
        let (mut commit, mut state) = (0u32, None::<MonitorState>);
        let mut cuts = 0u64;
        for turn in 0..8u32 {
            for i in 0..30 {
                let t = turn * 30 + i;
                monitor.process(Sample::new(t * 1000, 2e3 + t as f32, 1e-4).with_speed(2.0));
            }
            let new_state = monitor.snapshot();
            let new_image = image(turn + 1);
            // A state checkpoint cut anywhere: the commit as it was, the state old or new.
            cuts += cut_everywhere(&base, &|s| block_on(s.checkpoint(&new_state)), &|c, st| {
                assert_eq!(c, commit, "state {turn}: the commit");
                assert!(st == state || st == Some(new_state), "state {turn}");
            });
            base = written(base, &|s| block_on(s.checkpoint(&new_state)));
            state = Some(new_state);
            // A commit cut anywhere: the state as it was, the commit old or new.
            cuts += cut_everywhere(&base, &|s| block_on(s.checkpoint(&new_image)), &|c, st| {
                assert!(c == commit || c == turn + 1, "commit {}: {c}", turn + 1);
                assert_eq!(st, state, "commit {}: the state", turn + 1);
            });
            base = written(base, &|s| block_on(s.checkpoint(&new_image)));
            commit = turn + 1;
            assert_eq!(boot_both(base.clone()).1, commit);
        }
        let erases: u32 = base.erase_counts().iter().sum();
        eprintln!(
            "{cuts} power cuts over 8 state checkpoints and 8 commits, {erases} sector erases"
        );
        assert!(
            erases > 0,
            "the map erased no sector: the moves were not swept"
        );
    }

    type Write<'a> = &'a dyn Fn(&mut Both) -> Result<u32, StorageError<MockError>>;

    /// `base` booted and `write` done.
    fn written(base: Flash, write: Write) -> Flash {
        let (mut store, ..) = boot_both(base);
        write(&mut store).unwrap();
        store.into_flash().0
    }

    /// `write` on `base` (booted) cut at each of its points; `check` of what the boot
    /// after each cut finds (the commit, the state). The number of cuts.
    fn cut_everywhere(
        base: &Flash,
        write: Write,
        check: &dyn Fn(u32, Option<MonitorState>),
    ) -> u64 {
        let (probe, ..) = boot_both(base.clone());
        let start = probe.into_flash().0.points();
        let points = written(base.clone(), write).points() - start;
        for p in 0..points {
            let mut flash = base.clone();
            flash.cut_after(p);
            let (mut store, ..) = boot_both(flash);
            assert!(write(&mut store).is_err(), "point {p}");
            let mut flash = store.into_flash().0;
            flash.restart();
            let (_, c, st) = boot_both(flash);
            check(c, st);
        }
        points
    }
}

/// Without the code, no write changes the configuration, the scene or the code:
/// thousands of random writes (functions 6 and 16, any address of the holding table,
/// any values, wrong codes among them) to a locked node, each answered.
#[test]
fn random_writes_without_the_code_change_nothing() {
    let mut s = server();
    let before = view(&mut s, "active");
    let scene = s.monitor().estimator().to_bytes();
    let end = TableMap::of(Table::Holding).end();
    let unlock_at = at("unlock");
    let mut x = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    for i in 0..5000 {
        let r = next();
        let mut address = (r % u64::from(end)) as u16;
        let value = (r >> 20) as u16;
        // Never the right code.
        let value = if address == unlock_at && value == DEFAULT_UNLOCK_CODE {
            value ^ 1
        } else {
            value
        };
        let result = if r >> 60 & 1 == 0 {
            write1(&mut s, address, value)
        } else {
            let n = 1 + (r >> 40) as u16 % 8;
            address = address.min(end - n);
            let words: Vec<u16> = (0..n).map(|k| value.wrapping_add(k * 7919)).collect();
            write(&mut s, address, &words)
        };
        // Refusals are typed; a write the table allows without the code may pass.
        if let Err(code) = result {
            assert!((1..=3).contains(&code), "{i}: exception {code}");
        }
        s.tick(i * 10);
    }
    assert_eq!(view(&mut s, "active"), before);
    assert_eq!(s.monitor().config(), &Config::default());
    assert_eq!(s.monitor().estimator().to_bytes(), scene);
    assert_eq!(s.annunciator().latching(), AlarmSet::NONE);
    assert!(!s.external_samples());
    assert_eq!(get(&mut s, "staged"), 0);
    assert_eq!(get(&mut s, "config_source"), 0);
    assert!(s.commissioning().refused > 0);
    assert_eq!(s.commissioning().commits, 0);
    // The code is still the one it was.
    s.tick(5000 * 10 + LOCKOUT_S * 1000);
    unlock(&mut s);
}

/// The writes a locked node takes: an operator's acknowledgement, a master's reading
/// position and receipt of events, the code itself, and a PLC's samples.
const FREE: [&str; 5] = [
    "acknowledge",
    "acknowledge_alarms",
    "event_from",
    "event_ack",
    "unlock",
];

/// Function 5; `Err(code)` for an exception.
fn coil<E: Estimator>(s: &mut Server<E>, address: u16, on: bool) -> Result<(), u8> {
    let value = if on { 0xFF00 } else { 0 };
    answer(&request(s, 5, &words_be(&[address, value])), 5)
}

/// What a configuration write could change, beside the staged copy's registers.
fn settings<E: Estimator>(s: &mut Server<E>) -> (AlarmSet, bool, Vec<u16>, u32) {
    let latching = s.annunciator().latching();
    let external = s.external_samples();
    (latching, external, view(s, "config"), get(s, "staged"))
}

/// Every writable entry of the map (coils and holding registers), written while
/// locked with a value in its domain: refused with exception 01, counted, nothing
/// changed, unless it is one of the writes made in normal running ([`FREE`]); after
/// the unlock the same writes are taken. A new writable entry is refused unless it is
/// named here.
#[test]
fn every_configuration_write_needs_the_unlock() {
    let mut s = server();
    let mut guarded = Vec::new();
    for table in [Table::Coil, Table::Holding] {
        let writable = TableMap::of(table)
            .entries
            .iter()
            .filter(|e| e.access == Access::Rw && !FREE.contains(&e.name));
        for e in writable {
            let before = settings(&mut s);
            let refused = get(&mut s, "refused_writes");
            let result = match (table, e.ty.words()) {
                (Table::Coil, _) => coil(&mut s, e.address, true),
                (_, 2) => write(&mut s, e.address, &[0, 1]),
                _ => write1(&mut s, e.address, 1),
            };
            assert_eq!(result, Err(1), "{} written while locked", e.name);
            assert_eq!(get(&mut s, "refused_writes"), refused + 1, "{}", e.name);
            assert_eq!(settings(&mut s), before, "{}", e.name);
            guarded.push(e.name);
        }
    }
    for name in [
        "latch_warning",
        "external_samples",
        "latching",
        "external_mode",
    ] {
        assert!(guarded.contains(&name), "{name}");
    }
    // Several coils at once (function 15): an acknowledgement beside a latch is
    // refused whole, counted once.
    let refused = get(&mut s, "refused_writes");
    let pdu = request(&mut s, 15, &[0, 0, 0, 2, 1, 0b11]);
    assert_eq!(answer(&pdu, 15), Err(1));
    assert_eq!(get(&mut s, "refused_writes"), refused + 1);
    assert_eq!(s.annunciator().latching(), AlarmSet::NONE);

    // Free while locked.
    coil(&mut s, 0, true).unwrap();
    write1(&mut s, at("acknowledge_alarms"), 15).unwrap();
    write(&mut s, at("event_from"), &[0, 0]).unwrap();
    // An acknowledgement needs a number given (03 before any event), not the code.
    assert_eq!(write(&mut s, at("event_ack"), &[0, 0]), Err(3));
    let mut t = 0;
    while s.monitor().next_event_seq() == 0 {
        s.process(Sample::new(t, 2e3, 1e-4).with_speed(2.0));
        t += 1000;
    }
    write(&mut s, at("event_ack"), &[0, 0]).unwrap();
    assert!(!s.unlocked());

    // Unlocked: taken, each renewing the unlock as a staged write does.
    unlock(&mut s);
    s.tick(200_000);
    coil(&mut s, 1, true).unwrap();
    assert_eq!(s.annunciator().latching(), AlarmSet::WARNING);
    s.tick(400_000);
    assert!(s.unlocked(), "renewed by the write 200 s ago");
    write1(&mut s, at("latching"), 0b0110).unwrap();
    assert_eq!(
        s.annunciator().latching(),
        AlarmSet::ALARM.union(AlarmSet::SENSOR_FAULT)
    );
    let pdu = request(&mut s, 15, &[0, 0, 0, 2, 1, 0b11]);
    assert_eq!(answer(&pdu, 15), Ok(()));
    write1(&mut s, at("external_mode"), 1).unwrap();
    assert!(s.external_samples());
    coil(&mut s, 5, false).unwrap();
    assert!(!s.external_samples());
}

/// A PLC's samples are process data, not configuration: with external samples on,
/// a locked node takes them.
#[test]
fn external_samples_need_no_code() {
    let monitor = Monitor::new(core(&Scene::DEMO), Config::default()).unwrap();
    let config = ServerConfig {
        external_samples: true,
        ..ServerConfig::default()
    };
    let mut s = Server::new(monitor, config).unwrap();
    s.tick(0);
    assert!(!s.unlocked());
    let (p, phi) = (2e3f32.to_bits(), 1e-4f32.to_bits());
    let record = [
        0,
        1000,
        (p >> 16) as u16,
        p as u16,
        (phi >> 16) as u16,
        phi as u16,
    ];
    write(&mut s, SAMPLES_ADDRESS, &record).unwrap();
    assert_eq!(s.monitor().statistics().samples(), 1);
    assert_eq!(s.commissioning().refused, 0);
}

/// Every writable holding register refuses what its domain (the map's, the CSV's
/// `min` and `max`) leaves out: at the write (exception 03) or at the commit (refused,
/// its reason in `commit_error`), from the default configuration (every option on);
/// and takes its bounds at the write, but where the value has a meaning of its own:
/// `event_ack` takes the numbers given only (the event window's tests), `unlock` the
/// site's code, `command` a commit with something staged.
#[test]
fn every_register_refuses_what_its_domain_leaves_out() {
    let mut checked = 0;
    for e in TableMap::of(Table::Holding).entries {
        let (mut outside, mut bounds) = (Vec::new(), Vec::new());
        match e.domain() {
            Domain::ReadOnly | Domain::Any => continue,
            Domain::Whole { min, max } => {
                let top = if e.ty.words() == 2 { u32::MAX } else { 0xFFFF };
                outside.extend(min.checked_sub(1));
                outside.extend((max < top).then(|| max + 1));
                bounds.extend([min, max]);
            }
            Domain::Finite { min, max } => {
                outside.extend([f32::NAN, f32::INFINITY, f32::NEG_INFINITY].map(f32::to_bits));
                if min > -f32::MAX {
                    outside.push((min - 1e-30_f32.max(min.abs() * 1e-6)).to_bits());
                }
                bounds.extend([min.to_bits(), max.to_bits()]);
            }
        }
        if matches!(e.name, "event_ack" | "unlock" | "command") {
            bounds.clear();
        }
        for v in outside {
            let mut s = server();
            unlock(&mut s);
            let refused = match put(&mut s, e.name, v) {
                Err(x) => x == 3,
                Ok(()) => cmd(&mut s, command::COMMIT) == Err(3),
            };
            assert!(refused, "{} = {v:#x} taken", e.name);
            checked += 1;
        }
        for v in bounds {
            let mut s = server();
            unlock(&mut s);
            assert_eq!(
                put(&mut s, e.name, v),
                Ok(()),
                "{} = {v:#x} at the write",
                e.name
            );
        }
    }
    assert!(checked > 40, "{checked}");
}

/// `status`'s NE 107 category (bits 8-11) and the discrete input `scene_commissioned`.
fn commissioning_state<E: Estimator>(s: &mut Server<E>) -> (u16, bool) {
    let status = request(s, 4, &words_be(&[0, 1]));
    assert_eq!(&status[..2], &[4, 2], "{status:?}");
    let category = u16::from_be_bytes([status[2], status[3]]) >> 8 & 0xF;
    let address = TableMap::of(Table::Discrete)
        .entries
        .iter()
        .find(|e| e.name == "scene_commissioned")
        .expect("the discrete input scene_commissioned")
        .address;
    let bits = request(s, 2, &words_be(&[address, 1]));
    assert_eq!(&bits[..2], &[2, 1], "{bits:?}");
    (category, bits[2] & 1 == 1)
}

const FUNCTION_CHECK: u16 = 3;

/// A node that needs its site's scene (`scene_required`: the Pico with its own
/// sensors) reports "not commissioned" until a scene is committed over the bus: NE 107
/// function check whatever it is fed, `scene_commissioned` 0. A commit of the
/// configuration alone does not commission it; a scene's commit does, and that is kept
/// in the committed image through a restart (an image claiming it without a scene is
/// refused). A node that needs none reports its state as before.
#[test]
fn a_node_needing_its_scene_reports_not_commissioned_until_one_is_committed() {
    let needing = || {
        let monitor = Monitor::new(core(&Scene::DEMO), Config::default()).unwrap();
        let config = ServerConfig {
            scene_required: true,
            ..ServerConfig::default()
        };
        let mut s = Server::new(monitor, config).unwrap();
        s.accept_scenes();
        s.tick(0);
        s
    };
    let feed = |s: &mut Server<Auto>, from: u32| {
        for i in from..from + 20 {
            s.process(Sample::new(i * 1000, 2e3, 1e-5).with_speed(2.0));
        }
    };
    // Without the need: the build's scene is not a commissioned one, yet the state is
    // reported once it settles.
    let mut plain = server();
    feed(&mut plain, 0);
    let (category, commissioned) = commissioning_state(&mut plain);
    assert!(!commissioned);
    assert_ne!(category, FUNCTION_CHECK);

    let mut s = needing();
    assert!(!s.scene_commissioned());
    assert_eq!(commissioning_state(&mut s), (FUNCTION_CHECK, false));
    feed(&mut s, 0);
    assert_eq!(commissioning_state(&mut s), (FUNCTION_CHECK, false));
    // The configuration alone.
    unlock(&mut s);
    put(&mut s, "config_on_delay", 3000).unwrap();
    cmd(&mut s, command::COMMIT).unwrap();
    assert_eq!(s.config_source(), BootSource::Committed);
    assert!(!s.scene_commissioned());
    feed(&mut s, 20);
    assert_eq!(commissioning_state(&mut s), (FUNCTION_CHECK, false));
    let mut image = [0; IMAGE_LEN];
    assert!(s.take_committed(&mut image));
    let mut booted = needing();
    assert_eq!(booted.restore(Stored::Image(&image)), BootSource::Committed);
    assert!(!booted.scene_commissioned());

    // The site's scene.
    let (_, bytes) = other_scene();
    unlock(&mut s);
    write(&mut s, SCENE_ADDRESS, &scene_words(&bytes)).unwrap();
    cmd(&mut s, command::COMMIT).unwrap();
    assert!(s.scene_commissioned());
    assert!(commissioning_state(&mut s).1);
    feed(&mut s, 40);
    let (category, commissioned) = commissioning_state(&mut s);
    assert!(commissioned);
    assert_ne!(category, FUNCTION_CHECK);
    assert!(s.take_committed(&mut image));
    let mut booted = needing();
    assert_eq!(booted.restore(Stored::Image(&image)), BootSource::Committed);
    assert!(booted.scene_commissioned());
    assert_eq!(booted.monitor().estimator().to_bytes().to_vec(), bytes);
    feed(&mut booted, 0);
    assert_ne!(commissioning_state(&mut booted).0, FUNCTION_CHECK);
    // A later commit of the configuration alone keeps the scene commissioned.
    unlock(&mut booted);
    put(&mut booted, "config_on_delay", 4000).unwrap();
    cmd(&mut booted, command::COMMIT).unwrap();
    assert!(booted.scene_commissioned());
    assert!(booted.take_committed(&mut image));
    let mut again = needing();
    assert_eq!(again.restore(Stored::Image(&image)), BootSource::Committed);
    assert!(again.scene_commissioned());

    // An image claiming a committed scene but holding none is not one.
    let mut bad = image;
    bad[1] &= !1;
    let mut b = needing();
    assert_eq!(b.restore(Stored::Image(&bad)), BootSource::DefaultsDamaged);
    assert!(!b.scene_commissioned());
    // Nothing stored: not commissioned.
    let mut b = needing();
    assert_eq!(b.restore(Stored::Nothing), BootSource::Defaults);
    assert_eq!(commissioning_state(&mut b), (FUNCTION_CHECK, false));
}
