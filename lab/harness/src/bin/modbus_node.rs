//! The Modbus monitoring node on a build-time scene: `minimal_node`'s monitor and
//! samples, with `misalign::modbus::Server` over it (register map, event window, RTU
//! framer) polled over the board's UART driver of the firmware example
//! (`nodes/firmware/uart.rs`, through `embedded-io`), built in profile `node` as
//! `minimal_node` is. `cargo xtask modbus --measure` weighs it against `minimal_node`
//! (what the server adds) and reads its counts.
//!
//! After the samples it measures, by SysTick under QEMU's `-icount` (harness
//! `Counter`), the instructions of whole requests taken from memory byte by byte
//! (`Server::receive` for every byte, then `response` and `sent`; the UART's byte time
//! excluded): function 3 reading 16 holding registers, function 4 reading the 16 input
//! registers from `status` on, function 16 writing 20 samples (their processing by
//! the monitor included), and of functions 3 and 16 the framing alone (every byte but
//! the last, which completes the frame and gets it answered). It prints `modbus_node
//! fc3_16=... fc3_16_framing=... fc4_16=... fc16_20=... fc16_20_framing=... samples=...
//! stack_bytes=... server_bytes=... monitor_bytes=...` (the last two: `size_of` the
//! server, the monitor in it included, and of the monitor; `stack_built=...
//! stack_samples=...`, the deepest stack use once the server was built and once the
//! samples were processed) and exits 0 when every request was answered as the specification
//! says.
#![no_std]
#![no_main]

use misalign::Estimator;
use misalign::modbus::{Server, ServerConfig};
use misalign::monitor::{Config, Monitor, Sample};
use misalign_harness::support::counter::Counter;
use misalign_harness::{io, prepared, support};
use misalign_logger as _;

#[allow(dead_code)] // The silence the serving node waits for: not measured here.
#[path = "../../../../nodes/firmware/uart.rs"]
mod uart;

use misalign_harness::node_samples::{ANGLES, LOADS, SAMPLES, frame, samples_request};

misalign_harness::exit_on_panic!();

#[cortex_m_rt::entry]
fn main() -> ! {
    let peripherals = cortex_m::Peripherals::take().expect("first and only take");
    let counter = Counter::new(peripherals.SYST);
    #[cfg(target_abi = "eabihf")]
    let core = misalign::float::EllipticScene::from_bytes(&prepared::ELLIPTIC);
    #[cfg(not(target_abi = "eabihf"))]
    let core = misalign::fixed::FixedEllipticScene::from_bytes(&prepared::FIXED_ELLIPTIC);
    let Ok(core) = core else {
        defmt::error!("the build-time scene was refused");
        support::exit(2)
    };
    let mut uart = uart::Uart::for_this_board(&peripherals.CPUID);
    let sp = support::stack::paint();
    let costs = run(core, &counter, &mut uart, sp);
    let stack = support::stack::used(sp);
    let Some(costs) = costs else {
        defmt::error!("a request was not answered as specified");
        support::exit(1)
    };
    let [fc3, fc4, fc16] = costs.requests;
    defmt::println!(
        "modbus_node fc3_16={=u32} fc3_16_framing={=u32} fc4_16={=u32} fc16_20={=u32} fc16_20_framing={=u32} samples={=u32} stack_bytes={=usize} server_bytes={=usize} monitor_bytes={=usize} stack_built={=usize} stack_samples={=usize}",
        fc3.0,
        fc3.1,
        fc4.0,
        fc16.0,
        fc16.1,
        SAMPLES,
        stack,
        costs.server,
        costs.monitor,
        costs.stack_built,
        costs.stack_samples
    );
    support::exit(0)
}

/// Feeds `request` to the server under the counter; the instructions, if it answered
/// with function `function` (not an exception) and a frame of `len` bytes: the whole,
/// and of them the bytes before the last (framing alone: the last byte completes the
/// frame, and the server answers it within that byte's `receive`).
fn measure<E: Estimator>(
    server: &mut Server<E>,
    counter: &Counter,
    request: &[u8],
    function: u8,
    len: usize,
) -> Option<(u32, u32)> {
    let (head, last) = request.split_at(request.len().saturating_sub(1));
    let ((), framing) = counter.measure(|| {
        for &b in head {
            server.receive(b);
        }
    });
    let (answered, rest) = counter.measure(|| {
        for &b in last {
            server.receive(b);
        }
        let ok = server
            .response()
            .is_some_and(|r| r.len() == len && r.get(1) == Some(&function));
        server.sent();
        ok
    });
    answered.then_some((framing + rest, framing))
}

/// The node: the samples through the server, the UART polled after each (as the
/// node's loop does), then the three requests measured.
#[inline(never)]
fn run<E: Estimator>(
    core: E,
    counter: &Counter,
    uart: &mut uart::Uart,
    sp: usize,
) -> Option<Costs> {
    let config = ServerConfig {
        external_samples: true,
        ..ServerConfig::default()
    };
    let Ok(monitor) = Monitor::new(core, Config::default()) else {
        return None;
    };
    let Ok(mut server) = Server::new(monitor, config) else {
        return None;
    };
    let stack_built = support::stack::used(sp);
    let mut time_ms = 0;
    for i in 0..SAMPLES {
        let load = io::read(&LOADS[(i % 8) as usize]);
        let phi = io::read(&ANGLES[(i / 60 % 8) as usize]);
        time_ms = i * 1000;
        server.process(Sample::new(time_ms, load, phi).with_speed(2.0));
        // The UART as the node's loop polls it (nothing arrives here).
        let _ = server.poll(uart);
    }
    let stack_samples = support::stack::used(sp);
    let mut buf = [0u8; 256];
    // Function 3: holding registers 0-15. Answer: unit, function, count, 32 bytes, CRC.
    let n = frame(&mut buf, &[3, 0, 0, 0, 16]);
    let fc3 = measure(&mut server, counter, &buf[..n], 3, 37)?;
    // Function 4: input registers 0-15 (status, alarms, the readings).
    let n = frame(&mut buf, &[4, 0, 0, 0, 16]);
    let fc4 = measure(&mut server, counter, &buf[..n], 4, 37)?;
    // Function 16: 20 samples, one a second after the last. Answer: 8 bytes.
    let n = samples_request(&mut buf, time_ms);
    let fc16 = measure(&mut server, counter, &buf[..n], 16, 8)?;
    Some(Costs {
        requests: [fc3, fc4, fc16],
        server: core::mem::size_of::<Server<E>>(),
        monitor: core::mem::size_of::<Monitor<E>>(),
        stack_built,
        stack_samples,
    })
}

/// What `run` measured: per request the instructions and those of its framing; the
/// bytes of the server (the monitor in it) and of the monitor alone.
struct Costs {
    requests: [(u32, u32); 3],
    server: usize,
    monitor: usize,
    /// The deepest stack use once the server was built, and once the samples were
    /// processed (the requests come after).
    stack_built: usize,
    stack_samples: usize,
}
