//! The Modbus server's cost per request: instructions from the request's first byte
//! handed to [`Server::receive`] to the answer ready in [`Server::response`] (every
//! byte received, one call each, as a UART's receive interrupt hands them over; the
//! UART's byte time is not in it), counted by SysTick under QEMU's `-icount`
//! (`lab/qemu-run`), over the node's monitor on the build-time demo scene: the
//! fixed-point core without an FPU, the f32 core with one (as `minimal_node`).
//!
//! Requests: function 3 of holding registers 0-15, function 4 of input registers 0-15,
//! function 16 of 20 external samples (its cost holds the monitor's 20 samples). Each
//! is repeated with one of the node's own samples processed between (outside the
//! count), so that each answer is computed from a monitor that has changed. One line
//! per request: `modbus f=<function> n=<registers> instr=<mean> max=<max> reps=<n>`;
//! exits 0 when every answer was a normal response of the expected length.
//!
//! `cargo build --manifest-path lab/harness/Cargo.toml --profile firmware --target
//! thumbv6m-none-eabi --bin modbus_cost`, then `lab/qemu-run microbit
//! target/thumbv6m-none-eabi/firmware/modbus_cost` (`mps2-an386` for thumbv7em).
#![no_std]
#![no_main]

use core::hint::black_box;
use misalign::Estimator;
use misalign::modbus::{Server, ServerConfig, crc16, map};
use misalign::monitor::{Config, Monitor, Sample};
use misalign_harness::prepared;
use misalign_harness::support::{
    self,
    counter::{Counter, Stats},
};
use misalign_logger as _;

misalign_harness::log_panics_and_faults!();

/// Repetitions of each request.
const REPS: u32 = 16;
/// Records in the function-16 write: the most one write carries (the map's block).
const RECORDS: usize = map::SAMPLES as usize;
/// Registers per basic external sample (time, P, phi).
const STRIDE: usize = map::SAMPLE_STRIDE as usize;
/// The function-16 request: 7 header bytes, the records, the CRC.
const WRITE_LEN: usize = 7 + 2 * STRIDE * RECORDS + 2;

/// `body` with its CRC appended (low byte first) into `out`; the frame's length.
fn frame(body: &[u8], out: &mut [u8]) -> usize {
    let n = body.len();
    out[..n].copy_from_slice(body);
    out[n..n + 2].copy_from_slice(&crc16(body).to_le_bytes());
    n + 2
}

/// One of the node's samples at `time_ms`: about 2.5 kN, 0.2 mrad, 2 m/s, varying.
fn sample(time_ms: u32) -> Sample {
    let i = time_ms / 1000;
    Sample::new(
        time_ms,
        2400.0 + (i % 7) as f32 * 20.0,
        2.0e-4 + (i % 5) as f32 * 1e-5,
    )
    .with_speed(2.0)
}

/// The measured span: every byte of `request` into the server, then its answer. Out of
/// line, as the application's receive path is; returns the answer's length (0: none).
#[inline(never)]
fn serve<E: Estimator>(server: &mut Server<E>, request: &[u8]) -> usize {
    for &byte in request {
        server.receive(byte);
    }
    server.response().map_or(0, <[u8]>::len)
}

/// `REPS` times: a sample of the node's own processed at `*time`, then `request(time)`
/// served and counted. `None` when an answer was not `answer_len` bytes of a normal
/// response to `function`.
fn measure<E: Estimator>(
    c: &Counter,
    server: &mut Server<E>,
    time: &mut u32,
    function: u8,
    answer_len: usize,
    request: impl Fn(u32, &mut [u8]) -> usize,
) -> Option<Stats> {
    let mut s = Stats::default();
    let mut buf = [0u8; WRITE_LEN];
    for _ in 0..REPS {
        *time += 1000;
        server.process(sample(*time));
        let n = request(*time, &mut buf);
        let bytes = black_box(&buf[..n]);
        let (len, instr) = c.measure(|| serve(server, bytes));
        let ok = len == answer_len && server.response().is_some_and(|r| r[1] == function);
        server.sent();
        if !ok {
            return None;
        }
        s.add(instr);
        // The written samples' timestamps end here.
        *time += (RECORDS as u32) * 1000;
    }
    Some(s)
}

fn run<E: Estimator>(c: &Counter, core: E) -> i32 {
    let Ok(monitor) = Monitor::new(core, black_box(Config::default())) else {
        return 2;
    };
    let config = ServerConfig {
        external_samples: true,
        ..ServerConfig::default()
    };
    let Ok(mut server) = Server::new(monitor, black_box(config)) else {
        return 2;
    };
    // A minute of samples: past the start-up inhibit, readings and statistics there.
    let mut time = 0;
    for _ in 0..64 {
        time += 1000;
        server.process(sample(time));
    }
    let read = |function: u8| move |_: u32, out: &mut [u8]| frame(&[1, function, 0, 0, 0, 16], out);
    let write = |t0: u32, out: &mut [u8]| {
        let mut body = [0u8; WRITE_LEN - 2];
        let quantity = (STRIDE * RECORDS) as u16;
        let [hi, lo] = map::SAMPLES_ADDRESS.to_be_bytes();
        body[..7].copy_from_slice(&[1, 16, hi, lo, 0, quantity as u8, 0]);
        body[6] = (2 * quantity) as u8;
        for (i, record) in body[7..].chunks_exact_mut(2 * STRIDE).enumerate() {
            let s = sample(t0 + 1000 * (i as u32 + 1));
            record[..4].copy_from_slice(&s.time_ms.to_be_bytes());
            record[4..8].copy_from_slice(&s.load.to_bits().to_be_bytes());
            record[8..].copy_from_slice(&s.phi.to_bits().to_be_bytes());
        }
        frame(&body, out)
    };
    // (function, registers, answer length, request)
    let reads = [(3u8, 16u16), (4, 16)];
    for (function, n) in reads {
        let Some(s) = measure(c, &mut server, &mut time, function, 5 + 32, read(function)) else {
            defmt::error!("modbus f={=u8}: not the expected answer", function);
            return 1;
        };
        print(function, n, &s);
    }
    let Some(s) = measure(c, &mut server, &mut time, 16, 8, write) else {
        defmt::error!("modbus f=16: not the expected answer");
        return 1;
    };
    print(16, (STRIDE * RECORDS) as u16, &s);
    if server.counters().external_accepted != REPS * RECORDS as u32 {
        defmt::error!("modbus f=16: external samples refused");
        return 1;
    }
    0
}

fn print(function: u8, registers: u16, s: &Stats) {
    defmt::println!(
        "modbus f={=u8} n={=u16} instr={=u64} max={=u32} reps={=u32}",
        function,
        registers,
        s.mean(),
        s.max,
        s.n
    );
}

#[cortex_m_rt::entry]
fn main() -> ! {
    let Some(peripherals) = cortex_m::Peripherals::take() else {
        support::exit(3)
    };
    let counter = Counter::new(peripherals.SYST);
    #[cfg(target_abi = "eabihf")]
    let (core, name) = (
        misalign::float::EllipticScene::from_bytes(&prepared::ELLIPTIC),
        "f32",
    );
    #[cfg(not(target_abi = "eabihf"))]
    let (core, name) = (
        misalign::fixed::FixedEllipticScene::from_bytes(&prepared::FIXED_ELLIPTIC),
        "fixed",
    );
    let Ok(core) = core else {
        defmt::error!("the build-time scene was refused");
        support::exit(2)
    };
    defmt::println!(
        "modbus core={=str} ticks_per_1000={=u32}",
        name,
        counter.ticks_per_1000()
    );
    support::exit(run(&counter, core))
}
