//! The Modbus node, written once for every board: `misalign::modbus::Server` over the
//! monitor (framing, CRC, the register map, the event window), polled over any UART
//! implementing the `embedded-io` 0.7 traits: the QEMU images' register-level drivers
//! (`uart.rs`) and a real board's HAL (`nodes/pico`) alike. What a board adds (its own
//! sensors sampled on its timer, sleeping between requests and samples, a watchdog)
//! comes through [`Board`]; the QEMU images have none of it but their UART's settings
//! (`main.rs`).

use embedded_io::{ErrorType, Read, ReadReady, Write};
use misalign::Estimator;
use misalign::modbus::{
    Identification, LineSettings, PreparedScene, SensorSettings, Server, ServerConfig,
};
use misalign::monitor::scenario::Scenario;
use misalign::monitor::{Config, Monitor, Sample};

/// The node's model names (function 43/14): the core and the scene.
pub const MODEL_F32: &str = "f32 core (float::Auto), the built-in scenario's scene";
pub const MODEL_FIXED: &str = "fixed-point core (fixed::FixedAuto), the built-in scenario's scene";

/// Whether this image takes its samples from a Modbus master (written to the server's
/// sample block) instead of monitoring the built-in scenario: chosen at build time,
/// `MISALIGN_MODBUS_EXTERNAL=1` (any value) in the environment of the build.
pub const EXTERNAL_SAMPLES: bool = option_env!("MISALIGN_MODBUS_EXTERNAL").is_some();

/// The line's clock: `ticks` a free-running count (wrapping), `silence` how many of its
/// ticks without a byte end a frame (3.5 character times on a real line,
/// `misalign::modbus::silence_us`).
pub struct LineClock<T: FnMut() -> u32> {
    pub ticks: T,
    pub silence: u32,
    /// Ticks in a millisecond: the commissioning's clock (`Server::tick`).
    pub per_ms: u32,
}

/// What a board adds to the node.
pub trait Board {
    /// Whether the board samples its own sensors ([`sample`](Self::sample)) instead of
    /// monitoring the built-in scenario when it takes no external samples.
    const SENSORS: bool;
    /// The board's sample if one is due now (its own timer), read through its sensors'
    /// drivers; `None` when none is due.
    fn sample(&mut self) -> Option<Sample>;
    /// Nothing to do for `wait` line ticks unless a byte comes: the board may sleep
    /// until then, its next sample or a byte (`pending`, checked with interrupts
    /// masked, says whether one came in meanwhile).
    fn idle(&mut self, wait: u32, pending: &mut dyn FnMut() -> bool);
    /// Once per pass of the loop: the node is alive (a board feeds its watchdog).
    fn alive(&mut self);
    /// The line settings in force, at the start (the committed configuration's) and
    /// whenever they change (a commit after its answer, a revert): a board sets its
    /// UART's rate and frame to them here. The node has logged them.
    fn line(&mut self, _settings: &LineSettings) {}
    /// The sampling period and the sensors' calibration in force: at the start (the
    /// committed image's, or the build's) and after each commit that changed them. A
    /// board without sensors (the QEMU images: their built-in scenario keeps its own
    /// timestamps and simulated sensors) ignores them.
    fn sensors(&mut self, _settings: &SensorSettings) {}
}

/// The Modbus node: a `misalign::modbus::Server` over the monitor of `core`
/// (`model`: its name and the scene's, function 43/14's model name), answering on
/// `uart` forever, told of the line's silences by `clock`. With its own samples
/// (the default) it first monitors the whole built-in scenario, so that every register
/// holds the end of the shift, the state a host replay of the same samples reaches;
/// with external samples it starts fresh and monitors what a master writes. On a board
/// with sensors ([`Board::SENSORS`]) it monitors the board's samples once the site's
/// scene was committed over the bus (before that it serves only, to be commissioned,
/// and reports "not commissioned": `ServerConfig::scene_required`), each monitored
/// sample logged as a `sample` line.
/// `None` if the monitor refuses its configuration.
///
/// The server and the storage are built once, where the node keeps them (each step
/// out of line, so that no copy of them or of what built them stays on the stack
/// while the node serves); the deepest stack is then the serving loop's frame and a
/// request's or a checkpoint's calls, on top of these two.
pub fn node<
    E: Estimator + PreparedScene,
    U: Read + ReadReady + Write,
    T: FnMut() -> u32,
    B: Board,
>(
    core: E,
    model: &'static str,
    uart: &mut U,
    clock: LineClock<T>,
    board: &mut B,
) -> Option<core::convert::Infallible> {
    let mut server = server::<E, B>(core, model);
    let server = server.as_mut()?;
    #[cfg(feature = "modbus-flash")]
    let mut persist = crate::persist::Persist::open();
    #[cfg(feature = "modbus-flash")]
    let Some(persist) = persist.as_mut() else {
        defmt::error!("node: the flash cannot be opened");
        return None;
    };
    // With flash (`modbus-flash`): the committed configuration, then the monitor's
    // last checkpoint under it.
    #[cfg(feature = "modbus-flash")]
    start_storage(server, persist);
    if !EXTERNAL_SAMPLES && !B::SENSORS {
        scenario(
            server,
            #[cfg(feature = "modbus-flash")]
            persist,
        );
    }
    defmt::println!(
        "modbus: serving, {=str}, samples from {=str}, {=u64} processed",
        model,
        if EXTERNAL_SAMPLES {
            "the master"
        } else if B::SENSORS {
            "the board's sensors, once the site's scene is committed"
        } else {
            "the built-in scenario"
        },
        server.monitor().statistics().samples()
    );
    serve(
        server,
        #[cfg(feature = "modbus-flash")]
        persist,
        uart,
        clock,
        board,
    )
}

/// The server over a new monitor of `core`, taking scenes of its core type over the
/// bus (commissioning); `None` if the monitor or the server refuses its configuration.
#[inline(never)]
fn server<E: Estimator + PreparedScene, B: Board>(
    core: E,
    model: &'static str,
) -> Option<Server<E>> {
    let monitor = match Monitor::new(core, Config::default()) {
        Ok(m) => m,
        Err(e) => {
            defmt::error!("node: configuration refused: {}", e);
            return None;
        }
    };
    let config = ServerConfig {
        external_samples: EXTERNAL_SAMPLES,
        scene_required: B::SENSORS && !EXTERNAL_SAMPLES,
        ident: Identification {
            model_name: model,
            ..Identification::default()
        },
        ..ServerConfig::default()
    };
    match Server::new(monitor, config) {
        Ok(mut s) => {
            s.accept_scenes();
            Some(s)
        }
        Err(e) => {
            defmt::error!("node: server configuration refused: {}", e);
            None
        }
    }
}

/// The committed configuration and the monitor's last checkpoint, from the flash.
#[cfg(feature = "modbus-flash")]
#[inline(never)]
fn start_storage<E: Estimator>(server: &mut Server<E>, persist: &mut crate::persist::Persist) {
    let (source, restored) = persist.start(server);
    defmt::println!(
        "storage: configuration from {}, state restored {=bool}, {=u64} samples monitored",
        source,
        restored,
        server.monitor().statistics().samples()
    );
}

/// The built-in scenario's samples not yet monitored (after a restored checkpoint,
/// those after it).
#[inline(never)]
fn scenario<E: Estimator>(
    server: &mut Server<E>,
    #[cfg(feature = "modbus-flash")] persist: &mut crate::persist::Persist,
) {
    let done = server.monitor().statistics().samples() as usize;
    for sample in Scenario::new().skip(done) {
        server.process(sample);
        #[cfg(feature = "modbus-flash")]
        persist.service(server);
    }
}

/// Serves forever: the board's samples, the requests, the storage, the line's clock.
#[inline(never)]
fn serve<E: Estimator, U: Read + ReadReady + Write, T: FnMut() -> u32, B: Board>(
    server: &mut Server<E>,
    #[cfg(feature = "modbus-flash")] persist: &mut crate::persist::Persist,
    uart: &mut U,
    mut clock: LineClock<T>,
    board: &mut B,
) -> Option<core::convert::Infallible> {
    // When the last byte came, and whether a frame may be waiting for the silence that
    // ends it (garbage, a truncated frame, a function the server does not know: the
    // server drops or answers it then).
    let per_ms = clock.per_ms.max(1);
    let mut last_byte = (clock.ticks)();
    let mut waiting = false;
    // The line settings the UART runs: set again when the server's change (a commit
    // after its answer, a revert); the answer delay in force held before each answer.
    let mut line = server.line();
    log_line(&line);
    board.line(&line);
    let mut sensors = server.sensors();
    board.sensors(&sensors);
    let mut uart = Watched {
        uart,
        seen: false,
        clock,
        last_read: last_byte,
        delay: u32::from(line.answer_delay_ms).saturating_mul(per_ms),
        held: None,
    };
    // The commissioning's milliseconds, from the line's ticks.
    let (mut ms, mut ticked) = (0u32, last_byte);
    loop {
        board.alive();
        if let Some(sample) = board.sample()
            && !server.external_samples()
            && server.scene_commissioned()
        {
            server.process(sample);
            log_sample(&sample);
        }
        if server.poll(&mut uart).is_err() {
            // A framing, parity or overrun error: bytes lost, which the framer's CRC
            // and resynchronisation deal with; the master retries.
            defmt::warn!("modbus: a UART error");
        }
        #[cfg(feature = "modbus-flash")]
        persist.service(server);
        if let Some(waited) = uart.held.take() {
            defmt::println!(
                "modbus: answered {=u32} ms after the request (answer delay {=u16} ms)",
                waited / per_ms,
                line.answer_delay_ms
            );
        }
        if server.line() != line {
            line = server.line();
            log_line(&line);
            board.line(&line);
            uart.delay = u32::from(line.answer_delay_ms).saturating_mul(per_ms);
        }
        if server.sensors() != sensors {
            sensors = server.sensors();
            board.sensors(&sensors);
        }
        let now = (uart.clock.ticks)();
        let step = now.wrapping_sub(ticked);
        if step >= per_ms {
            ms = ms.wrapping_add(step / per_ms);
            ticked = ticked.wrapping_add(step - step % per_ms);
            server.tick(ms);
        }
        if core::mem::take(&mut uart.seen) {
            (last_byte, waiting) = (now, true);
        } else if waiting && now.wrapping_sub(last_byte) >= uart.clock.silence {
            server.idle();
            waiting = false;
        }
        if !uart.uart.read_ready().unwrap_or(true) {
            // Until the silence ends a frame, else at least once a second (the
            // commissioning's clock).
            let wait = if waiting {
                uart.clock
                    .silence
                    .saturating_sub(now.wrapping_sub(last_byte))
                    .max(1)
            } else {
                per_ms.saturating_mul(1000)
            };
            board.idle(wait, &mut || uart.uart.read_ready().unwrap_or(true));
        }
    }
}

/// The line settings in force, as a log line.
fn log_line(l: &misalign::modbus::LineSettings) {
    defmt::println!(
        "modbus: unit {=u8}, {=u32} baud, parity {=u8} (0 none, 1 odd, 2 even), answer delay {=u16} ms, bus timeout {=u16} s",
        l.unit_id,
        l.baud,
        l.parity as u8,
        l.answer_delay_ms,
        l.bus_timeout_s
    );
}

/// One `sample` line: what the board's sensors delivered and the monitor took, every
/// value as its bits (the emulator's harness writes them back as a trace, lab/pico):
/// the time (ms), P and phi, whether a speed was measured and its bits, and the
/// sensor fault (sensor index times 16 plus the fault kind's index; 255 none).
fn log_sample(s: &Sample) {
    let fault = s.sensor_fault.map_or(255u8, |f| {
        let kind = misalign::monitor::FaultKind::ALL
            .iter()
            .position(|&k| k == f.kind)
            .unwrap_or(15) as u8;
        (f.sensor.index() as u8) << 4 | kind
    });
    defmt::println!(
        "sample t={=u32} P={=u32} phi={=u32} measured={=bool} V={=u32} fault={=u8}",
        s.time_ms,
        s.load.to_bits(),
        s.phi.to_bits(),
        s.speed.is_some(),
        s.speed.map_or(0, f32::to_bits),
        fault
    );
}

/// A UART that notes whether a read took a byte, and when; and holds the first write
/// after a read (an answer's start) until `delay` ticks of the line's clock have passed
/// since that read (the answer delay in force), noting in `held` how long it was.
struct Watched<'a, U, T: FnMut() -> u32> {
    uart: &'a mut U,
    seen: bool,
    clock: LineClock<T>,
    last_read: u32,
    delay: u32,
    held: Option<u32>,
}

impl<U: ErrorType, T: FnMut() -> u32> ErrorType for Watched<'_, U, T> {
    type Error = U::Error;
}

impl<U: ReadReady, T: FnMut() -> u32> ReadReady for Watched<'_, U, T> {
    fn read_ready(&mut self) -> Result<bool, U::Error> {
        self.uart.read_ready()
    }
}

impl<U: Read, T: FnMut() -> u32> Read for Watched<'_, U, T> {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, U::Error> {
        let n = self.uart.read(buf)?;
        if n > 0 {
            self.seen = true;
            self.last_read = (self.clock.ticks)();
        }
        Ok(n)
    }
}

impl<U: Write, T: FnMut() -> u32> Write for Watched<'_, U, T> {
    fn write(&mut self, buf: &[u8]) -> Result<usize, U::Error> {
        if self.delay > 0 && self.held.is_none() {
            // Busy: the line's clock runs on the core's (SysTick in QEMU).
            let mut waited = (self.clock.ticks)().wrapping_sub(self.last_read);
            while waited < self.delay {
                waited = (self.clock.ticks)().wrapping_sub(self.last_read);
            }
            self.held = Some(waited);
        }
        self.uart.write(buf)
    }

    fn flush(&mut self) -> Result<(), U::Error> {
        self.uart.flush()
    }
}
