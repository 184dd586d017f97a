//! The sensor settings over Modbus (the sampling period and the sensors' calibration),
//! as a technician commissions them: staged under the unlock beside the values in
//! force, checked at the write (exception 03, nothing staged), committed or reverted
//! with the rest, kept in the committed image (version 4; older images restore with
//! the build's).

use misalign::float::Auto;
use misalign::modbus::map::{HOLDINGS, MAP_VERSION, SENSORS_ADDRESS};
use misalign::modbus::{
    BootSource, DEFAULT_UNLOCK_CODE, IMAGE_LEN, IMAGE_VERSION, SensorSettings, Server,
    ServerConfig, ServerConfigError, Stored, command, crc16, staged,
};
use misalign::monitor::{Config, Monitor, model_for_range};
use misalign::{Estimator, Scene};

fn server_with(config: ServerConfig) -> Result<Server<Auto>, ServerConfigError> {
    let scene = Scene::DEMO;
    let core = Auto::with_choice(&scene, model_for_range(&scene, 5e3, 1e-5).unwrap()).unwrap();
    let monitor = Monitor::new(core, Config::default()).unwrap();
    let mut s = Server::new(monitor, config)?;
    s.tick(0);
    Ok(s)
}

fn server() -> Server<Auto> {
    server_with(ServerConfig::default()).unwrap()
}

fn words_be(words: &[u16]) -> Vec<u8> {
    words.iter().flat_map(|w| w.to_be_bytes()).collect()
}

/// The PDU of the answer of unit 1 to a request.
fn ask<E: Estimator>(s: &mut Server<E>, function: u8, data: &[u8]) -> Vec<u8> {
    let mut adu = vec![1, function];
    adu.extend_from_slice(data);
    adu.extend_from_slice(&crc16(&adu).to_le_bytes());
    for b in adu {
        s.receive(b);
    }
    s.idle();
    let answer = s.response().expect("an answer").to_vec();
    s.sent();
    answer[1..answer.len() - 2].to_vec()
}

fn answer(pdu: &[u8], function: u8) -> Result<(), u8> {
    if pdu[0] == function {
        Ok(())
    } else {
        assert_eq!(pdu[0], function | 0x80, "{pdu:?}");
        Err(pdu[1])
    }
}

fn read<E: Estimator>(s: &mut Server<E>, address: u16, n: u16) -> Result<Vec<u16>, u8> {
    let pdu = ask(s, 3, &words_be(&[address, n]));
    answer(&pdu, 3)?;
    Ok(pdu[2..]
        .chunks_exact(2)
        .map(|c| u16::from_be_bytes([c[0], c[1]]))
        .collect())
}

fn write<E: Estimator>(s: &mut Server<E>, address: u16, words: &[u16]) -> Result<(), u8> {
    let mut data = words_be(&[address, words.len() as u16]);
    data.push((2 * words.len()) as u8);
    data.extend(words_be(words));
    answer(&ask(s, 16, &data), 16)
}

/// A holding register by name: its address and registers.
fn entry(name: &str) -> (u16, u16) {
    if let Some(e) = HOLDINGS.entries.iter().find(|e| e.name == name) {
        return (e.address, e.ty.words());
    }
    for b in HOLDINGS.blocks.iter().filter(|b| b.prefix.is_empty()) {
        if let Some(e) = b.fields.iter().find(|e| e.name == name) {
            return (b.address + e.address, e.ty.words());
        }
    }
    panic!("no {name}")
}

fn get<E: Estimator>(s: &mut Server<E>, name: &str) -> u32 {
    let (a, n) = entry(name);
    read(s, a, n)
        .unwrap()
        .iter()
        .fold(0, |v, &x| v << 16 | u32::from(x))
}

fn put<E: Estimator>(s: &mut Server<E>, name: &str, v: u32) -> Result<(), u8> {
    let (a, n) = entry(name);
    if n == 2 {
        write(s, a, &[(v >> 16) as u16, v as u16])
    } else {
        write(s, a, &[v as u16])
    }
}

fn unlock<E: Estimator>(s: &mut Server<E>) {
    put(s, "unlock", u32::from(DEFAULT_UNLOCK_CODE)).unwrap();
}

fn cmd<E: Estimator>(s: &mut Server<E>, c: u16) -> Result<(), u8> {
    put(s, "command", u32::from(c))
}

/// The registers' names after `config_`/`active_`, in the image's order.
const NAMES: [&str; 13] = [
    "sample_period",
    "load_zero",
    "load_scale",
    "load_capacity",
    "probe1_zero",
    "probe1_scale",
    "probe2_zero",
    "probe2_scale",
    "probe_span",
    "probe_zero_offset",
    "tacho_pulses_per_rev",
    "tacho_radius",
    "tacho_max_speed",
];

/// A site's own calibration, every value other than the default.
fn site() -> SensorSettings {
    SensorSettings {
        sample_period_ms: 250,
        load_zero_counts: -1234.5,
        load_newtons_per_count: -0.0061,
        load_capacity_n: 5e3,
        probe1_zero_counts: 5100.0,
        probe1_metres_per_count: 1.1e-7,
        probe2_zero_counts: 4700.0,
        probe2_metres_per_count: 0.9e-7,
        probe_span_m: 0.25,
        probe_zero_offset_m: 3e-6,
        tacho_pulses_per_rev: 360,
        tacho_radius_m: 0.08,
        tacho_max_speed_m_s: 6.0,
    }
}

/// `s`'s values as the registers' bits, in [`NAMES`]' order.
fn bits(s: &SensorSettings) -> [u32; 13] {
    let f = |x: f32| x.to_bits();
    [
        s.sample_period_ms,
        f(s.load_zero_counts),
        f(s.load_newtons_per_count),
        f(s.load_capacity_n),
        f(s.probe1_zero_counts),
        f(s.probe1_metres_per_count),
        f(s.probe2_zero_counts),
        f(s.probe2_metres_per_count),
        f(s.probe_span_m),
        f(s.probe_zero_offset_m),
        s.tacho_pulses_per_rev,
        f(s.tacho_radius_m),
        f(s.tacho_max_speed_m_s),
    ]
}

fn stage<E: Estimator>(s: &mut Server<E>, settings: &SensorSettings) {
    for (n, v) in NAMES.iter().zip(bits(settings)) {
        put(s, &format!("config_{n}"), v).unwrap();
    }
}

fn view<E: Estimator>(s: &mut Server<E>, prefix: &str) -> Vec<u32> {
    NAMES
        .iter()
        .map(|n| get(s, &format!("{prefix}_{n}")))
        .collect()
}

/// The block after the line settings: each staged value beside its active one, in the
/// image's order, 32 bits each; the map's version says it changed.
#[test]
fn the_sensor_registers_are_in_the_map() {
    let mut s = server();
    assert_eq!(get(&mut s, "map_version"), u32::from(MAP_VERSION));
    assert_eq!(MAP_VERSION, 4);
    assert_eq!(SENSORS_ADDRESS, 473);
    for (i, n) in NAMES.iter().enumerate() {
        let i = i as u16;
        assert_eq!(
            entry(&format!("config_{n}")),
            (SENSORS_ADDRESS + 2 * i, 2),
            "{n}"
        );
        assert_eq!(
            entry(&format!("active_{n}")),
            (SENSORS_ADDRESS + 26 + 2 * i, 2),
            "{n}"
        );
    }
    assert_eq!(HOLDINGS.end(), SENSORS_ADDRESS + 52);
    let defaults = bits(&SensorSettings::DEFAULT).to_vec();
    assert_eq!(view(&mut s, "config"), defaults, "staged reads the active");
    assert_eq!(view(&mut s, "active"), defaults);
    // One read of the whole block.
    assert_eq!(read(&mut s, SENSORS_ADDRESS, 52).unwrap().len(), 52);
    assert_eq!(
        read(&mut s, SENSORS_ADDRESS + 1, 52),
        Err(2),
        "past the end"
    );
}

/// Every write needs the unlock; a value outside its domain (NaN, an infinity, a
/// zero scale, a span of 0, a period of 5 ms, no pulse per revolution) is refused with
/// exception 03 and stages nothing.
#[test]
fn sensor_writes_are_guarded_and_checked() {
    let mut s = server();
    assert_eq!(put(&mut s, "config_sample_period", 200), Err(1), "locked");
    unlock(&mut s);
    let refused: [(&str, u32); 14] = [
        ("config_sample_period", 5),
        ("config_sample_period", 60_001),
        ("config_sample_period", 0),
        ("config_load_scale", 0f32.to_bits()),
        ("config_load_scale", (-0f32).to_bits()),
        ("config_load_scale", f32::NAN.to_bits()),
        ("config_load_zero", f32::INFINITY.to_bits()),
        ("config_load_capacity", (-1f32).to_bits()),
        ("config_probe1_scale", 0f32.to_bits()),
        ("config_probe2_zero", f32::NEG_INFINITY.to_bits()),
        ("config_probe_span", 0f32.to_bits()),
        ("config_tacho_pulses_per_rev", 0),
        ("config_tacho_radius", f32::NAN.to_bits()),
        ("config_tacho_max_speed", 0f32.to_bits()),
    ];
    for (name, v) in refused {
        assert_eq!(put(&mut s, name, v), Err(3), "{name} = {v:#x}");
    }
    assert_eq!(get(&mut s, "staged"), 0, "nothing staged");
    assert_eq!(cmd(&mut s, command::COMMIT), Err(3), "nothing to commit");
    assert_eq!(s.sensors(), SensorSettings::DEFAULT);
    // Half of a 32-bit value: exception 02 as for every other.
    assert_eq!(write(&mut s, SENSORS_ADDRESS + 1, &[0]), Err(2));
    // The active values are read only.
    assert_eq!(
        put(&mut s, "active_sample_period", 200),
        Err(2),
        "read only"
    );
}

/// Staged beside the active values until the commit, then in force at once
/// (`Server::sensors`); a revert discards them.
#[test]
fn a_commit_applies_the_sensor_settings_and_a_revert_discards_them() {
    let mut s = server();
    unlock(&mut s);
    stage(&mut s, &site());
    assert_eq!(
        get(&mut s, "staged"),
        u32::from(staged::SENSORS),
        "bit 4 alone"
    );
    assert_eq!(view(&mut s, "config"), bits(&site()).to_vec());
    assert_eq!(
        view(&mut s, "active"),
        bits(&SensorSettings::DEFAULT).to_vec()
    );
    assert_eq!(
        s.sensors(),
        SensorSettings::DEFAULT,
        "not before the commit"
    );
    cmd(&mut s, command::REVERT).unwrap();
    assert_eq!(
        view(&mut s, "config"),
        bits(&SensorSettings::DEFAULT).to_vec()
    );
    assert_eq!(get(&mut s, "staged"), 0);

    stage(&mut s, &site());
    cmd(&mut s, command::COMMIT).unwrap();
    assert_eq!(s.sensors(), site());
    assert_eq!(view(&mut s, "active"), bits(&site()).to_vec());
    assert_eq!(view(&mut s, "config"), bits(&site()).to_vec());
    assert_eq!(get(&mut s, "config_source"), 1);
}

/// A commit the configuration refuses applies none of the sensor settings either.
#[test]
fn a_refused_commit_applies_no_sensor_setting() {
    let mut s = server();
    unlock(&mut s);
    put(&mut s, "config_sample_period", 500).unwrap();
    put(&mut s, "config_spike_window", 9).unwrap();
    assert_eq!(cmd(&mut s, command::COMMIT), Err(3));
    assert_eq!(s.sensors(), SensorSettings::DEFAULT);
    assert_eq!(get(&mut s, "active_sample_period"), 100);
}

/// The committed image keeps them; a fresh server restores them; an image of version
/// 3 (without them) restores the rest and keeps the build's; an image whose sensor
/// settings are out of their domain is refused whole.
#[test]
fn the_committed_image_keeps_the_sensor_settings() {
    let mut s = server();
    unlock(&mut s);
    stage(&mut s, &site());
    put(&mut s, "config_on_delay", 4000).unwrap();
    cmd(&mut s, command::COMMIT).unwrap();
    let mut image = [0; IMAGE_LEN];
    assert!(s.take_committed(&mut image));
    assert_eq!(image[0], IMAGE_VERSION);
    assert_eq!(IMAGE_VERSION, 4);

    let mut booted = server();
    assert_eq!(booted.restore(Stored::Image(&image)), BootSource::Committed);
    assert_eq!(booted.sensors(), site());
    assert_eq!(booted.monitor().config().on_delay_ms, 4000);

    // Version 3: the first 272 bytes.
    let mut v3 = image[..IMAGE_LEN - 52].to_vec();
    v3[0] = 3;
    let mut old = server();
    assert_eq!(old.restore(Stored::Image(&v3)), BootSource::Committed);
    assert_eq!(old.sensors(), SensorSettings::DEFAULT);
    assert_eq!(old.monitor().config().on_delay_ms, 4000);
    // A version 4 image cut to version 3's length, and the other way round.
    let mut cut = v3.clone();
    cut[0] = 4;
    assert_eq!(
        server().restore(Stored::Image(&cut)),
        BootSource::DefaultsDamaged
    );
    let mut long = image;
    long[0] = 3;
    assert_eq!(
        server().restore(Stored::Image(&long)),
        BootSource::DefaultsDamaged
    );
    // Out of their domain: a NaN scale, a zero period.
    for (at, v) in [(280, f32::NAN.to_bits()), (272, 0)] {
        let mut bad = image;
        bad[at..at + 4].copy_from_slice(&v.to_le_bytes());
        let mut b = server();
        assert_eq!(b.restore(Stored::Image(&bad)), BootSource::DefaultsDamaged);
        assert_eq!(b.sensors(), SensorSettings::DEFAULT);
        assert_eq!(b.monitor().config(), &Config::default());
    }
}

/// The build's sensor settings are checked as a master's would be.
#[test]
fn the_builds_sensor_settings_are_checked() {
    let bad = SensorSettings {
        probe_span_m: f32::NAN,
        ..SensorSettings::DEFAULT
    };
    let config = ServerConfig {
        sensors: bad,
        ..ServerConfig::default()
    };
    assert_eq!(server_with(config).err(), Some(ServerConfigError::Sensors));
    let config = ServerConfig {
        sensors: site(),
        ..ServerConfig::default()
    };
    assert_eq!(server_with(config).unwrap().sensors(), site());
}

/// The default is the reference node's data sheets' calibration, as the sensors'
/// own constructors make it, value for value.
#[cfg(feature = "sensors")]
#[test]
fn the_default_is_the_data_sheets_calibration() {
    use misalign::sensors::{
        Hx711Channel, LoadCalibration, ProbeCalibration, ProbeSpec, SpeedCalibration,
    };
    let spec = ProbeSpec {
        min_m: 0.0,
        max_m: 2e-3,
        linearity_m: 4e-6,
    };
    let c = SensorSettings::DEFAULT
        .calibration(Hx711Channel::A128, spec)
        .unwrap();
    assert_eq!(
        c.load,
        LoadCalibration::from_rated_output(Hx711Channel::A128, 2.0, 20e3).unwrap()
    );
    let probe = ProbeCalibration::two_point((4800.0, 0.0), (24000.0, 2e-3), spec).unwrap();
    assert_eq!(
        (c.misalignment.probe1, c.misalignment.probe2),
        (probe, probe)
    );
    assert_eq!(
        (c.misalignment.span_m, c.misalignment.zero_offset_m),
        (0.4, 0.0)
    );
    assert_eq!(
        c.speed,
        Some(SpeedCalibration {
            pulses_per_rev: 1024,
            radius_m: 0.05,
            max_speed_m_s: 10.0,
        })
    );
    // A site's: what the drivers take.
    assert!(site().calibration(Hx711Channel::A128, spec).is_ok());
}
