//! The line settings over Modbus, as a master and a technician drive them: staged
//! under the unlock, committed, answered at the old settings and applied after, kept
//! once a request reaches the node at the new ones within the window, reverted (an
//! event, `line_reverts`) otherwise; kept in the committed image; the master's
//! supervision by the bus timeout.

use misalign::float::Auto;
use misalign::modbus::map::{
    EVENT_SLOTS_ADDRESS, LINE_ADDRESS, LINE_INPUTS_ADDRESS, SCENE_ADDRESS, SCENE_WORDS, Table,
    TableMap,
};
use misalign::modbus::{
    BootSource, DEFAULT_UNLOCK_CODE, IMAGE_LEN, LINE_CONFIRM_WINDOW_S, LineError, LineSettings,
    Parity, Server, ServerConfig, ServerConfigError, Stored, command, crc16, staged,
};
use misalign::monitor::{Config, Monitor, model_for_range};
use misalign::{Estimator, Scene};

fn server_with(config: ServerConfig) -> Server<Auto> {
    let scene = Scene::DEMO;
    let core = Auto::with_choice(&scene, model_for_range(&scene, 5e3, 1e-5).unwrap()).unwrap();
    let monitor = Monitor::new(core, Config::default()).unwrap();
    let mut s = Server::new(monitor, config).unwrap();
    s.tick(0);
    s
}

fn server() -> Server<Auto> {
    server_with(ServerConfig::default())
}

fn words_be(words: &[u16]) -> Vec<u8> {
    words.iter().flat_map(|w| w.to_be_bytes()).collect()
}

/// The answer (unit, PDU) to a request to `unit`, sent; `None` when none is due.
fn request<E: Estimator>(
    s: &mut Server<E>,
    unit: u8,
    function: u8,
    data: &[u8],
) -> Option<(u8, Vec<u8>)> {
    let mut adu = vec![unit, function];
    adu.extend_from_slice(data);
    adu.extend_from_slice(&crc16(&adu).to_le_bytes());
    for b in adu {
        s.receive(b);
    }
    s.idle();
    let answer = s.response()?.to_vec();
    s.sent();
    let (body, crc) = answer.split_at(answer.len() - 2);
    assert_eq!(crc16(body).to_le_bytes(), [crc[0], crc[1]]);
    Some((body[0], body[1..].to_vec()))
}

/// The PDU of the answer from `unit`, which must answer as `unit`.
fn ask<E: Estimator>(s: &mut Server<E>, unit: u8, function: u8, data: &[u8]) -> Vec<u8> {
    let (from, pdu) = request(s, unit, function, data).expect("an answer");
    assert_eq!(from, unit);
    pdu
}

/// Function 16 to `unit`; `Err(code)` for an exception.
fn write<E: Estimator>(s: &mut Server<E>, unit: u8, address: u16, words: &[u16]) -> Result<(), u8> {
    let mut data = words_be(&[address, words.len() as u16]);
    data.push((2 * words.len()) as u8);
    data.extend(words_be(words));
    answer(&ask(s, unit, 16, &data), 16)
}

fn answer(pdu: &[u8], function: u8) -> Result<(), u8> {
    if pdu[0] == function {
        Ok(())
    } else {
        assert_eq!(pdu[0], function | 0x80, "{pdu:?}");
        Err(pdu[1])
    }
}

/// Function 3 or 4 to `unit`; `Err(code)` for an exception.
fn read_table<E: Estimator>(
    s: &mut Server<E>,
    unit: u8,
    function: u8,
    address: u16,
    n: u16,
) -> Result<Vec<u16>, u8> {
    let pdu = ask(s, unit, function, &words_be(&[address, n]));
    answer(&pdu, function)?;
    Ok(pdu[2..]
        .chunks_exact(2)
        .map(|c| u16::from_be_bytes([c[0], c[1]]))
        .collect())
}

/// A holding register by name, single or in the line block.
fn entry(name: &str) -> (u16, u16) {
    let t = TableMap::of(Table::Holding);
    if let Some(e) = t.entries.iter().find(|e| e.name == name) {
        return (e.address, e.ty.words());
    }
    let b = t.blocks.iter().find(|b| b.address == LINE_ADDRESS).unwrap();
    let e = b
        .fields
        .iter()
        .find(|e| e.name == name)
        .unwrap_or_else(|| panic!("no {name}"));
    (LINE_ADDRESS + e.address, e.ty.words())
}

fn get<E: Estimator>(s: &mut Server<E>, unit: u8, name: &str) -> u32 {
    let (a, n) = entry(name);
    let w = read_table(s, unit, 3, a, n).unwrap();
    w.iter().fold(0, |v, &x| v << 16 | u32::from(x))
}

fn put<E: Estimator>(s: &mut Server<E>, unit: u8, name: &str, v: u32) -> Result<(), u8> {
    let (a, n) = entry(name);
    if n == 2 {
        write(s, unit, a, &[(v >> 16) as u16, v as u16])
    } else {
        write(s, unit, a, &[v as u16])
    }
}

fn unlock<E: Estimator>(s: &mut Server<E>, unit: u8) {
    put(s, unit, "unlock", u32::from(DEFAULT_UNLOCK_CODE)).unwrap();
}

fn commit<E: Estimator>(s: &mut Server<E>, unit: u8) -> Result<(), u8> {
    put(s, unit, "command", u32::from(command::COMMIT))
}

/// `line_reverts`, `line_status`, `line_confirm_left`.
fn line_inputs<E: Estimator>(s: &mut Server<E>, unit: u8) -> (u32, u16, u16) {
    let w = read_table(s, unit, 4, LINE_INPUTS_ADDRESS, 4).unwrap();
    (u32::from(w[0]) << 16 | u32::from(w[1]), w[2], w[3])
}

/// The kinds of the events in the window, from event_from on.
fn event_kinds<E: Estimator>(s: &mut Server<E>, unit: u8) -> Vec<u16> {
    let w = read_table(s, unit, 4, EVENT_SLOTS_ADDRESS, 100).unwrap();
    w.chunks_exact(25)
        .map(|slot| slot[7])
        .filter(|&k| k != 0)
        .collect()
}

/// The names, at 460 on, with the types they ask.
#[test]
fn the_line_registers_are_in_the_map() {
    let mut csv = String::new();
    misalign::modbus::registers_csv(&mut csv).unwrap();
    for (name, ty) in [
        ("config_unit_id", "u16"),
        ("config_baud", "u32"),
        ("config_parity", "u16"),
        ("config_answer_delay", "u16"),
        ("config_bus_timeout", "u16"),
        ("active_unit_id", "u16"),
        ("active_baud", "u32"),
        ("active_parity", "u16"),
        ("active_answer_delay", "u16"),
        ("active_bus_timeout", "u16"),
        ("line_confirm_window", "u16"),
    ] {
        let (a, _) = entry(name);
        assert!((LINE_ADDRESS..LINE_ADDRESS + 13).contains(&a), "{name}");
        assert!(csv.contains(&format!("holding,{a},{name},{ty},")), "{name}");
    }
    assert!(csv.contains(&format!("input,{LINE_INPUTS_ADDRESS},line_reverts,u32,")));
}

/// The addresses between the scene block and the line settings are reserved: every
/// read or write that touches them is refused with exception 02.
#[test]
fn the_reserved_addresses_are_refused() {
    let mut s = server();
    let scene_end = SCENE_ADDRESS + SCENE_WORDS;
    assert!(scene_end < LINE_ADDRESS);
    for a in scene_end..LINE_ADDRESS {
        assert_eq!(read_table(&mut s, 1, 3, a, 1), Err(2), "{a}");
        assert_eq!(write(&mut s, 1, a, &[0]), Err(2), "{a}");
    }
    assert_eq!(read_table(&mut s, 1, 3, scene_end - 1, 5), Err(2));
    assert!(read_table(&mut s, 1, 3, scene_end - 4, 4).is_ok());
    let all = read_table(&mut s, 1, 3, LINE_ADDRESS, 13).unwrap();
    assert_eq!(all[0], 1, "config_unit_id reads the active one");
    assert_eq!(u32::from(all[1]) << 16 | u32::from(all[2]), 19_200);
    assert_eq!(all[3], Parity::Even as u16);
    assert_eq!(all[12], LINE_CONFIRM_WINDOW_S);
    let end = misalign::modbus::map::HOLDINGS.end();
    assert!(read_table(&mut s, 1, 3, LINE_ADDRESS + 12, 2).is_ok());
    assert_eq!(read_table(&mut s, 1, 3, end - 1, 2), Err(2), "past the end");
}

/// Every line setting needs the unlock; a value outside its domain is refused at the
/// write (03) and stages nothing.
#[test]
fn line_writes_are_guarded_and_checked() {
    let mut s = server();
    assert_eq!(put(&mut s, 1, "config_unit_id", 7), Err(1), "locked");
    assert_eq!(put(&mut s, 1, "active_unit_id", 7), Err(2), "read only");
    unlock(&mut s, 1);
    for (name, bad) in [
        ("config_unit_id", 0),
        ("config_unit_id", 248),
        ("config_baud", 12_345),
        ("config_baud", 0),
        ("config_parity", 3),
        ("config_answer_delay", 1001),
    ] {
        assert_eq!(put(&mut s, 1, name, bad), Err(3), "{name} {bad}");
    }
    assert_eq!(get(&mut s, 1, "staged"), 0, "nothing staged");
    put(&mut s, 1, "config_unit_id", 7).unwrap();
    put(&mut s, 1, "config_baud", 9_600).unwrap();
    assert_eq!(get(&mut s, 1, "staged"), u32::from(staged::LINE));
    assert_eq!(get(&mut s, 1, "config_unit_id"), 7);
    assert_eq!(get(&mut s, 1, "active_unit_id"), 1);
    assert_eq!(get(&mut s, 1, "unit_id"), 1);
    put(&mut s, 1, "command", u32::from(command::REVERT)).unwrap();
    assert_eq!(get(&mut s, 1, "config_unit_id"), 1, "reverted");
    assert_eq!(get(&mut s, 1, "config_baud"), 19_200);
}

/// Committed: answered at the old settings, in force after; the old unit id gets no
/// answer, the new one confirms; the confirmed settings go into the committed image
/// and a reset starts at them.
#[test]
fn a_confirmed_change_is_kept_through_a_reset() {
    let mut s = server();
    unlock(&mut s, 1);
    put(&mut s, 1, "config_unit_id", 17).unwrap();
    put(&mut s, 1, "config_baud", 38_400).unwrap();
    put(&mut s, 1, "config_parity", Parity::None as u32).unwrap();
    put(&mut s, 1, "config_answer_delay", 5).unwrap();
    commit(&mut s, 1).expect("answered by unit 1");
    let expected = LineSettings {
        unit_id: 17,
        baud: 38_400,
        parity: Parity::None,
        answer_delay_ms: 5,
        bus_timeout_s: 0,
    };
    assert_eq!(s.line(), expected, "in force once the answer is sent");
    assert_eq!(s.unit_id(), 17);
    // The commit's image keeps the settings before it until the confirmation.
    let mut image = [0; IMAGE_LEN];
    assert!(s.take_committed(&mut image));
    let mut before = server();
    assert_eq!(before.restore(Stored::Image(&image)), BootSource::Committed);
    assert_eq!(before.line(), LineSettings::DEFAULT);
    // The old unit id is not this node any more.
    assert!(request(&mut s, 1, 3, &words_be(&[5, 1])).is_none());
    // The first request at the new unit id is answered as the window stood, then
    // confirms it.
    let (_, status, left) = line_inputs(&mut s, 17);
    assert_eq!((status & 2, left), (2, LINE_CONFIRM_WINDOW_S));
    let (_, status, left) = line_inputs(&mut s, 17);
    assert_eq!((status & 2, left), (0, 0), "confirmed");
    assert!(
        s.take_committed(&mut image),
        "the confirmed settings to keep"
    );
    s.tick(u32::from(LINE_CONFIRM_WINDOW_S) * 1000 + 1);
    assert_eq!(s.line(), expected, "confirmed: no revert");
    assert_eq!(get(&mut s, 17, "unit_id"), 17);
    assert_eq!(get(&mut s, 17, "active_baud"), 38_400);
    let mut after = server();
    assert_eq!(after.restore(Stored::Image(&image)), BootSource::Committed);
    assert_eq!(
        after.line(),
        expected,
        "a reset starts at the confirmed settings"
    );
    assert_eq!(get(&mut after, 17, "active_parity"), 0);
}

/// Not confirmed within the window: the settings before, an event (kind 5), and
/// `line_reverts`; a broadcast at the new settings confirms nothing; a request at the
/// new ones just inside the window would have.
#[test]
fn an_unconfirmed_change_goes_back() {
    let window_ms = u32::from(LINE_CONFIRM_WINDOW_S) * 1000;
    for confirm_at in [None, Some(window_ms - 1)] {
        let mut s = server();
        unlock(&mut s, 1);
        put(&mut s, 1, "config_unit_id", 9).unwrap();
        commit(&mut s, 1).unwrap();
        // A broadcast write (acknowledge nothing) at the new settings: no confirmation.
        assert!(request(&mut s, 0, 6, &words_be(&[2, 0])).is_none());
        s.tick(window_ms - 1);
        assert_eq!(s.unit_id(), 9, "still waiting");
        if confirm_at.is_some() {
            assert_eq!(get(&mut s, 9, "unit_id"), 9);
        }
        s.tick(window_ms);
        if confirm_at.is_some() {
            assert_eq!(s.unit_id(), 9, "confirmed in time");
            assert_eq!(s.line_reverts(), 0);
            continue;
        }
        assert_eq!(s.unit_id(), 1, "back to the settings before");
        assert_eq!(s.line(), LineSettings::DEFAULT);
        assert_eq!(s.line_reverts(), 1);
        let (reverts, status, left) = line_inputs(&mut s, 1);
        assert_eq!((reverts, status, left), (1, 0, 0));
        assert_eq!(event_kinds(&mut s, 1), [5], "line settings reverted");
    }
}

/// A commit of the configuration alone leaves the line as it is; a commit of both
/// applies the configuration at once and the line after the answer.
#[test]
fn a_commit_of_both_applies_each_at_its_time() {
    let mut s = server();
    unlock(&mut s, 1);
    let on_delay = get(&mut s, 1, "config_on_delay");
    put(&mut s, 1, "config_on_delay", on_delay + 1).unwrap();
    put(&mut s, 1, "config_unit_id", 3).unwrap();
    commit(&mut s, 1).unwrap();
    assert_eq!(s.monitor().config().on_delay_ms, on_delay + 1);
    assert_eq!(get(&mut s, 3, "active_on_delay"), on_delay + 1);
    unlock(&mut s, 3);
    put(&mut s, 3, "config_on_delay", on_delay).unwrap();
    commit(&mut s, 3).unwrap();
    assert_eq!(s.unit_id(), 3);
    assert_eq!(get(&mut s, 3, "staged"), 0);
}

/// The bus timeout: no request for that long raises `master_lost` (an event, kind 6,
/// `line_status` bit 0, NE 107 out of specification in `status`), shown in the answer
/// to the next request, which clears it (an event, kind 7).
#[test]
fn a_lost_master_is_raised_and_cleared() {
    let mut s = server_with(ServerConfig {
        line: LineSettings {
            bus_timeout_s: 5,
            ..LineSettings::DEFAULT
        },
        ..ServerConfig::default()
    });
    s.tick(4_999);
    assert!(!s.master_lost());
    s.tick(5_000);
    assert!(s.master_lost());
    s.tick(9_000);
    let status = read_table(&mut s, 1, 4, 0, 1).unwrap()[0];
    assert!(
        status >> 8 & 15 >= 2,
        "NE 107 out of specification or graver: {status:#x}"
    );
    assert!(!s.master_lost(), "cleared by the request");
    let (_, line_status, _) = line_inputs(&mut s, 1);
    assert_eq!(line_status & 1, 0);
    assert_eq!(event_kinds(&mut s, 1), [6, 7]);
    // Requests for another unit do not keep it.
    s.tick(10_000);
    let mut other = vec![2, 3, 0, 0, 0, 1];
    other.extend_from_slice(&crc16(&other).to_le_bytes());
    for t in (10_000..=15_000).step_by(500) {
        for &b in &other {
            s.receive(b);
        }
        s.idle();
        assert!(s.response().is_none());
        s.tick(t);
    }
    assert!(s.master_lost());
    // Set over the bus, kept as a line setting; 0 turns it off.
    unlock(&mut s, 1);
    put(&mut s, 1, "config_bus_timeout", 0).unwrap();
    commit(&mut s, 1).unwrap();
    get(&mut s, 1, "unit_id");
    s.tick(100_000);
    assert!(!s.master_lost());
}

/// The build's line settings are checked like the bus's.
#[test]
fn the_builds_line_settings_are_checked() {
    for (line, e) in [
        (
            LineSettings {
                baud: 14_400,
                ..LineSettings::DEFAULT
            },
            LineError::Baud,
        ),
        (
            LineSettings {
                answer_delay_ms: 2000,
                ..LineSettings::DEFAULT
            },
            LineError::AnswerDelay,
        ),
    ] {
        let scene = Scene::DEMO;
        let core = Auto::with_choice(&scene, model_for_range(&scene, 5e3, 1e-5).unwrap()).unwrap();
        let monitor = Monitor::new(core, Config::default()).unwrap();
        let config = ServerConfig {
            line,
            ..ServerConfig::default()
        };
        assert_eq!(
            Server::new(monitor, config).err(),
            Some(ServerConfigError::Line(e))
        );
    }
    assert_eq!(Parity::None.stop_bits(), 2);
    assert_eq!(Parity::Even.stop_bits(), 1);
}
