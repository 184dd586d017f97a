//! The Modbus node with its flash: `modbus_node`'s monitor, samples and server, which
//! also takes scenes over the bus (commissioning), with the node's storage
//! (`nodes/firmware/persist.rs`: the monitor's checkpoints, the committed
//! configuration, every event until a master acknowledges it) on the board's flash
//! (`nodes/firmware/flash.rs`: the micro:bit's through its NVMC on the Cortex-M0, RAM
//! on the MPS2 boards), serviced after every sample and request as the node's loop
//! does. The node a plant installs, less the firmware example's power-on self-test
//! and demo scenario; built in profile `node` as `modbus_node` is. `cargo xtask modbus
//! --measure` holds its program and the RAM it leaves free to the Cortex-M0's targets.
//!
//! It builds the server and opens the storage, restores what the flash holds, monitors
//! the samples (an event raised, a checkpoint and an event pushed), then answers a read
//! of 16 holding registers and a write of 20 samples (held until stored), and prints
//! `modbus_flash_node samples=... checkpoints=... events_stored=... stack_bytes=...`
//! (the deepest stack use from the stack's top, by painting). Exit 0 when every
//! request was answered as the specification says.
#![no_std]
#![no_main]

use misalign::Estimator;
use misalign::modbus::{Server, ServerConfig};
use misalign::monitor::{Config, Monitor, Sample};
use misalign_harness::node_samples::{ANGLES, LOADS, SAMPLES, frame, samples_request};
use misalign_harness::{io, prepared, support};
use misalign_logger as _;

#[allow(dead_code)] // The silence the serving node waits for: not used here.
#[path = "../../../../nodes/firmware/uart.rs"]
mod uart;

#[path = "../../../../nodes/firmware/flash.rs"]
mod flash;
#[cfg(not(target_has_atomic = "ptr"))]
#[path = "../../../../nodes/common/nvmc_flash.rs"]
mod nvmc_flash;
#[path = "../../../../nodes/firmware/persist.rs"]
mod persist;
#[cfg(target_has_atomic = "ptr")]
#[path = "../../../../nodes/common/ram_flash.rs"]
mod ram_flash;

misalign_harness::exit_on_panic!();

#[cortex_m_rt::entry]
fn main() -> ! {
    // Painted below `main`'s frame; measured from the stack's top (`main`'s frame
    // holds the server and the storage).
    support::stack::paint();
    let peripherals = cortex_m::Peripherals::take().expect("first and only take");
    #[cfg(target_abi = "eabihf")]
    let core = misalign::float::EllipticScene::from_bytes(&prepared::ELLIPTIC);
    #[cfg(not(target_abi = "eabihf"))]
    let core = misalign::fixed::FixedEllipticScene::from_bytes(&prepared::FIXED_ELLIPTIC);
    let Ok(core) = core else {
        defmt::error!("the build-time scene was refused");
        support::exit(2)
    };
    let mut uart = uart::Uart::for_this_board(&peripherals.CPUID);
    let mut server = server(core);
    let Some(server) = server.as_mut() else {
        support::exit(3)
    };
    let mut persist = persist::Persist::open();
    let Some(persist) = persist.as_mut() else {
        defmt::error!("the flash cannot be opened");
        support::exit(3)
    };
    let ran = run(server, persist, &mut uart);
    let stack = support::stack::used(support::stack::top());
    let Some(ran) = ran else {
        defmt::error!("a request was not answered as specified");
        support::exit(1)
    };
    defmt::println!(
        "modbus_flash_node samples={=u32} checkpoints={=u32} events_stored={=u32} stack_bytes={=usize}",
        SAMPLES,
        ran.checkpoints,
        ran.events_stored,
        stack
    );
    support::exit(0)
}

/// The server over a new monitor of `core`, taking scenes over the bus.
#[inline(never)]
fn server<E: Estimator + misalign::modbus::PreparedScene>(core: E) -> Option<Server<E>> {
    let monitor = Monitor::new(core, Config::default()).ok()?;
    let config = ServerConfig {
        external_samples: true,
        ..ServerConfig::default()
    };
    let mut server = Server::new(monitor, config).ok()?;
    server.accept_scenes();
    Some(server)
}

/// What the storage registers said at the end.
struct Ran {
    checkpoints: u32,
    events_stored: u32,
}

/// Feeds `request` to the server, the storage serviced after it (a write's answer
/// waits until what it changed is stored); whether it answered with function
/// `function` in a frame of `len` bytes.
fn request<E: Estimator>(
    server: &mut Server<E>,
    persist: &mut persist::Persist,
    request: &[u8],
    function: u8,
    len: usize,
) -> bool {
    for &b in request {
        server.receive(b);
    }
    persist.service(server);
    let ok = server
        .response()
        .is_some_and(|r| r.len() == len && r.get(1) == Some(&function));
    server.sent();
    ok
}

/// The node: what the flash holds restored, the samples through the server with the
/// UART polled and the storage serviced after each (as the node's loop does), then a
/// read and a write.
#[inline(never)]
fn run<E: Estimator>(
    server: &mut Server<E>,
    persist: &mut persist::Persist,
    uart: &mut uart::Uart,
) -> Option<Ran> {
    let (source, restored) = persist.start(server);
    defmt::println!(
        "storage: configuration from {}, state restored {=bool}",
        source,
        restored
    );
    let mut time_ms = 0;
    for i in 0..SAMPLES {
        let load = io::read(&LOADS[(i % 8) as usize]);
        let phi = io::read(&ANGLES[(i / 60 % 8) as usize]);
        time_ms = i * 1000;
        server.process(Sample::new(time_ms, load, phi).with_speed(2.0));
        // The UART as the node's loop polls it (nothing arrives here).
        let _ = server.poll(uart);
        persist.service(server);
    }
    let mut buf = [0u8; 256];
    // Function 3: holding registers 0-15. Answer: unit, function, count, 32 bytes, CRC.
    let n = frame(&mut buf, &[3, 0, 0, 0, 16]);
    let read = request(server, persist, &buf[..n], 3, 37);
    // Function 16: 20 samples, one a second after the last. Answer: 8 bytes.
    let n = samples_request(&mut buf, time_ms);
    let write = request(server, persist, &buf[..n], 16, 8);
    let storage = server.storage_status();
    (read && write).then_some(Ran {
        checkpoints: storage.checkpoints,
        events_stored: storage.events_stored,
    })
}
