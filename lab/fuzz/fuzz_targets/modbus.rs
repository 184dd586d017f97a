//! The Modbus server's framing and register map on any input: never a panic (debug
//! assertions, so overflow checks, on), every answer well-formed (unit 1, a valid CRC,
//! at most 256 bytes, the request's function or an exception 01 to 04), and afterwards
//! the server still answers a read of every register of the map, with every event slot
//! decodable and `status` holding a state and an NE 107 category it defines.
//!
//! The input is a script of steps, each a tag byte and its operands: `tag % 4 == 0`:
//! a length byte and that many raw bytes; `1`: a length byte and that many bytes of a
//! frame (unit first) sent with its CRC and then the silence, so that the fuzzer
//! reaches every function without guessing CRCs; `2`: the silence; `3`: twelve bytes
//! of a sample (time ms u32, P f32, phi f32, little-endian) processed as the node's own.
#![no_main]

use libfuzzer_sys::fuzz_target;
use misalign::Scene;
use misalign::float::Auto;
use misalign::modbus::map::{EVENT_SLOTS_ADDRESS, EVENT_STRIDE, Table, TableMap};
use misalign::modbus::{Server, ServerConfig, crc16, event_from_registers};
use misalign::monitor::{Config, Monitor, Sample, model_for_range};
use std::sync::OnceLock;

fn well_formed(answer: &[u8]) -> bool {
    let n = answer.len();
    (5..=256).contains(&n)
        && answer[0] == 1
        && crc16(&answer[..n - 2]).to_le_bytes() == [answer[n - 2], answer[n - 1]]
        && (answer[1] & 0x80 == 0 || (n == 5 && (1..=4).contains(&answer[2])))
}

fn take_answer(s: &mut Server<Auto>) -> Option<Vec<u8>> {
    let answer = s.response().map(<[u8]>::to_vec);
    if let Some(a) = &answer {
        assert!(well_formed(a), "{a:02x?}");
    }
    s.sent();
    answer
}

fn send(s: &mut Server<Auto>, body: &[u8]) -> Option<Vec<u8>> {
    for &b in body.iter().chain(&crc16(body).to_le_bytes()) {
        s.receive(b);
    }
    if s.response().is_none() {
        s.idle();
    }
    take_answer(s)
}

/// The monitor at rest, prepared once (the model choice solves the reference).
fn fresh_monitor() -> Monitor<Auto> {
    static MONITOR: OnceLock<Monitor<Auto>> = OnceLock::new();
    MONITOR
        .get_or_init(|| {
            let scene = Scene::DEMO;
            let choice = model_for_range(&scene, 5e3, 1e-5).unwrap();
            Monitor::new(
                Auto::with_choice(&scene, choice).unwrap(),
                Config::default(),
            )
            .unwrap()
        })
        .clone()
}

fuzz_target!(|data: &[u8]| {
    let monitor = fresh_monitor();
    let config = ServerConfig {
        external_samples: true,
        ..ServerConfig::default()
    };
    let mut s = Server::new(monitor, config).unwrap();
    let mut rest = data;
    while let Some((&tag, tail)) = rest.split_first() {
        rest = tail;
        match tag % 4 {
            0 | 1 => {
                let Some((&n, tail)) = rest.split_first() else {
                    break;
                };
                let n = usize::from(n).min(tail.len());
                let (bytes, tail) = tail.split_at(n);
                rest = tail;
                if tag % 4 == 0 {
                    for &b in bytes {
                        s.receive(b);
                        take_answer(&mut s);
                    }
                } else {
                    send(&mut s, bytes);
                }
            }
            2 => {
                s.idle();
                take_answer(&mut s);
            }
            _ => {
                let Some((b, tail)) = rest.split_first_chunk::<12>() else {
                    break;
                };
                rest = tail;
                let word = |i: usize| u32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
                let sample = Sample::new(word(0), f32::from_bits(word(4)), f32::from_bits(word(8)));
                s.process(sample);
            }
        }
    }
    // The server still answers, at the unit id in force (the stream may have
    // commissioned another): every register and bit of the map.
    s.idle();
    s.sent();
    let unit = s.line().unit_id;
    for (function, table, chunk) in [
        (1u8, Table::Coil, 2000u16),
        (2, Table::Discrete, 2000),
        (4, Table::Input, 125),
        (3, Table::Holding, 125),
    ] {
        // Every address the map holds, run by run (a read across the reserved run
        // between two blocks is refused).
        for run in TableMap::of(table).runs() {
            let (mut address, end) = (run.start, run.end);
            while address < end {
                let n = chunk.min(end - address);
                let [a1, a0] = address.to_be_bytes();
                let [n1, n0] = n.to_be_bytes();
                let answer = send(&mut s, &[unit, function, a1, a0, n1, n0]).expect("answered");
                assert_eq!(answer[1], function, "{answer:02x?}");
                if function == 4 && address == 0 {
                    let status = u16::from_be_bytes([answer[3], answer[4]]);
                    assert!(
                        status & 0xFF <= 4 && (status >> 8) & 0xF <= 4,
                        "{status:#06x}"
                    );
                }
                address += n;
            }
        }
    }
    let slots = send(
        &mut s,
        &[
            unit,
            4,
            (EVENT_SLOTS_ADDRESS >> 8) as u8,
            EVENT_SLOTS_ADDRESS as u8,
            0,
            100,
        ],
    )
    .expect("answered");
    let regs: Vec<u16> = slots[3..slots.len() - 2]
        .chunks_exact(2)
        .map(|c| u16::from_be_bytes([c[0], c[1]]))
        .collect();
    for slot in regs.chunks_exact(usize::from(EVENT_STRIDE)) {
        assert!(event_from_registers(slot).is_ok(), "{slot:?}");
    }
});
