//! A Modbus RTU server over a [`Monitor`] of either core (feature `modbus`): `no_std`,
//! no heap, no panic on any input, transport-agnostic.
//!
//! ```
//! use misalign::modbus::{Server, ServerConfig};
//! use misalign::monitor::{Config, Monitor, Sample, model_for_range};
//! use misalign::{Scene, float::Auto};
//!
//! let scene = Scene::DEMO;
//! let core = Auto::with_choice(&scene, model_for_range(&scene, 5e3, 1e-5)?)?;
//! let monitor = Monitor::new(core, Config::default()).expect("the defaults are valid");
//! let mut server = Server::new(monitor, ServerConfig::default()).expect("unit 1");
//! // About 2 kN and 0.1 mrad, one sample a second: the first 7 fill the spike window
//! // (NE 107 function check meanwhile), the 8th starts the machine.
//! for i in 0..8u32 {
//!     server.process(Sample::new(i * 1000, 2e3 + i as f32, 1e-4).with_speed(2.0));
//! }
//! // Read input register 0 (`status`), one register, from unit 1.
//! for byte in [0x01, 0x04, 0x00, 0x00, 0x00, 0x01, 0x31, 0xCA] {
//!     server.receive(byte);
//! }
//! let answer = server.response().expect("a complete request");
//! assert_eq!(&answer[..5], &[0x01, 0x04, 0x02, 0x00, 0x01]); // normal, NE 107 good
//! server.sent();
//! # Ok::<(), misalign::Error>(())
//! ```
//!
//! **The application's part.** It owns the UART and the clock. Each received byte
//! goes to [`Server::receive`]; after it, [`Server::response`] holds a complete answer
//! when one is due: send it, then call [`Server::sent`]. When the application can
//! see 3.5 character times of silence on the line ([`silence_us`]) it calls
//! [`Server::idle`]; without a clock the framer still finds every frame of a known
//! function code from its length and CRC, resynchronising after garbage, and answers
//! a function code it does not know (exception 01) only at a silence. The node's own
//! sensors' samples go through [`Server::process`], so that the map follows them. With
//! the feature `embedded-io`, `Server::poll` (without blocking) and `Server::serve`
//! (blocking, one request) do the byte loop over any UART implementing the
//! `embedded-io` 0.7 traits.
//!
//! The whole API: [`Server::new`] (or [`Server::with_friction`] for an f32 scene, mu
//! tracked from a measured axial force) with a [`ServerConfig`] (unit id,
//! [`Identification`], external samples on or off, the latching [`AlarmSet`]);
//! `receive`, `idle`, `response`, `sent` for the bus; `process` for samples;
//! `monitor`, `annunciator`, `acknowledge`, `external_samples`, `unit_id`,
//! `counters`, `into_monitor`; for events kept on flash until acknowledged
//! (store-and-forward, docs/modbus.md) `store_events`, `pop_event`, `offer_event`,
//! `wanted_event`, `offer_stored_event`, `end_backlog`, `acknowledged_through`,
//! `stored`, `set_storage_status` ([`StorageStatus`]), `storage_status`; for commissioning
//! `accept_scenes`, `tick`, `unlocked`, `commissioning`, `config_source`,
//! `take_committed`, `restore` (see below). The server stores nothing itself (it does
//! not depend on `misalign::storage`): the application moves the events and the
//! committed image between it and its flash. Beside it: [`registers_csv`],
//! [`silence_us`], the map's addresses in [`map`], and for a master written in Rust
//! [`event_from_registers`]
//! and [`fault_from_code`].
//!
//! **External samples** written by a master over the bus (holding blocks `sample_*`,
//! up to 20 in one function-16 write, and `sample_full_*` with speed and axial force)
//! are processed by the server itself, in order, before it answers the write, exactly
//! as [`Server::process`] processes the node's own (the same monitor, clock checks and
//! counters). Whether they are accepted is chosen at build time
//! ([`ServerConfig::external_samples`]) and at run time by the coil
//! `external_samples` or the holding register `external_mode`; while off, such a write
//! is refused with exception 01 and counted (`external_refused`).
//!
//! **Commissioning** (the `config_*`, `active_*` and `scene_*` holding registers,
//! `unlock`, `command`): writes go to a staged copy of the monitor's configuration and
//! scene, shown beside the active one; a commit validates it (`ConfigError`,
//! `PreparedError`: exception 03 and the reason in `commit_error`) and applies it whole
//! between two samples; every such write needs the site's code written to `unlock`
//! first, which lasts until the commit or [`UNLOCK_TIMEOUT_S`] on the application's
//! clock ([`Server::tick`]), with a lock-out after [`WRONG_CODES_MAX`] wrong codes. The
//! committed configuration goes to the application as bytes
//! ([`Server::take_committed`]) to persist (the storage layer's `ConfigImage`), and
//! comes back at boot through [`Server::restore`], which `config_source` reports.
//!
//! **The map** ([`map`]) is one table in code: the server reads and writes through it,
//! and [`registers_csv`] writes it as `docs/modbus/registers.csv`
//! (`cargo run --example modbus_registers --features modbus > docs/modbus/registers.csv`). 32-bit
//! values take two registers, high word first; a value with none reads as the quiet
//! NaN `0x7FC0_0000` ([`NONE`]). `docs/modbus.md` is the integrator's page.
//!
//! **Functions**: 1, 2, 3, 4 (reads), 5, 6, 15, 16 (writes), 43/14 (read device
//! identification: basic and regular objects, stream and individual access).
//! Exceptions: 01 for an unknown function (or a MEI type other than 14, or external
//! samples while they are off), 02 for an address outside the map, a write to a
//! read-only value, half of a 32-bit value or part of a sample record, 03 for a
//! quantity or byte count out of range or a value outside a register's domain. No
//! answer to a wrong CRC, to another unit's frame, or to a broadcast (unit 0), whose
//! writes are applied.
//!
//! The server does not use rmodbus: its frame handling needs the whole frame found
//! first (the boundaries are this module's work anyway), and its storage model keeps
//! a copy of every register, where this map computes each value from the monitor when
//! it is read (no second copy to keep in step, no RAM for it).

mod config;
mod crc;
mod div;
mod events;
mod exception;
mod ident;
#[cfg(feature = "embedded-io")]
mod io;
mod line;
pub mod map;
mod pdu;
pub mod rtu;
mod sensing;
mod state;
mod values;

pub use crate::monitor::annunciation::{AlarmSet, Annunciator};
pub use config::{
    BootSource, CONFIG_WORDS, CommissioningCounts, DEFAULT_UNLOCK_CODE, IMAGE_LEN, IMAGE_VERSION,
    LOCKOUT_S, PreparedScene, SCENE_BYTES_MAX, Stored, UNLOCK_TIMEOUT_S, WRONG_CODES_MAX, command,
    reason, staged,
};
pub use crc::crc16;
pub use events::{EVENT_WINDOW, StorageStatus};
pub use exception::Exception;
pub use ident::Identification;
pub use line::{
    ANSWER_DELAY_MAX_MS, BAUD_RATES, LINE_CONFIRM_WINDOW_S, LineError, LineSettings, Parity,
};
pub use map::registers_csv;
pub use rtu::{ADU_MAX, FramingCounters};
pub use sensing::{SAMPLE_PERIOD_MS, SensorSettings};
pub use state::Counters;
pub use values::{DecodeError, NONE, event_from_registers, fault_code, fault_from_code};

use crate::monitor::{Event, Monitor, MonitorState, RiskState, Sample};
use crate::{Estimator, FrictionInverse};
use config::Commissioning;
use core::fmt;
use events::EventWindow;
use line::Line;
use rtu::Framer;
use sensing::Sensing;
use state::{Core, Step};

/// The default unit id.
pub const DEFAULT_UNIT_ID: u8 = 1;

/// 3.5 character times (us) at `baud` with 11-bit characters (start, 8 data, parity
/// or a second stop bit, stop), and 1750 us above 19200 baud, as the RTU specification
/// fixes it: the silence that ends a frame. A `baud` of 0 gives 1750.
pub const fn silence_us(baud: u32) -> u32 {
    if baud > 19_200 || baud == 0 {
        1_750
    } else {
        // 3.5 * 11 bits = 38.5 bit times.
        (38_500_000 / baud) + 1
    }
}

/// The server's configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ServerConfig {
    /// The unit id (1 to 247; default 1).
    pub unit_id: u8,
    /// What function 43/14 answers.
    pub ident: Identification,
    /// Whether external samples written over the bus are processed from the start
    /// (the coil `external_samples` changes it at run time).
    pub external_samples: bool,
    /// The alarms that latch from the start (the coils `latch_*` change it).
    pub latching: AlarmSet,
    /// The site's code that `unlock` takes before any commissioning write, until a
    /// committed `new_code` replaces it (default [`DEFAULT_UNLOCK_CODE`]).
    pub unlock_code: u16,
    /// Whether the node monitors only a scene committed over the bus (a node with its
    /// own sensors on a site's rollers): until one is, `status` reports NE 107
    /// function check and the discrete input `scene_commissioned` reads 0, and the
    /// application processes no sample ([`Server::scene_commissioned`]). Default
    /// false: the build's scene is a site's (a demonstrator, a test).
    pub scene_required: bool,
    /// The line settings but the unit id, until a committed image's replace them
    /// ([`LineSettings::DEFAULT`]'s: 19200 baud, even parity, no answer delay, no bus
    /// timeout); their `unit_id` is ignored: `unit_id` above is the node's.
    pub line: LineSettings,
    /// The sampling period and the sensors' calibration, until a committed image's
    /// replace them ([`SensorSettings::DEFAULT`]: the reference node's).
    pub sensors: SensorSettings,
}

impl ServerConfig {
    /// The line settings it starts with: `line` with `unit_id`.
    pub const fn line_settings(&self) -> LineSettings {
        LineSettings {
            unit_id: self.unit_id,
            ..self.line
        }
    }
}

impl Default for ServerConfig {
    fn default() -> Self {
        ServerConfig {
            unit_id: DEFAULT_UNIT_ID,
            ident: Identification::default(),
            external_samples: false,
            latching: AlarmSet::NONE,
            unlock_code: DEFAULT_UNLOCK_CODE,
            scene_required: false,
            line: LineSettings::DEFAULT,
            sensors: SensorSettings::DEFAULT,
        }
    }
}

/// A configuration the server refuses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ServerConfigError {
    /// The unit id is 0 (broadcast) or above 247 (reserved).
    UnitId,
    /// A line setting the node does not take.
    Line(LineError),
    /// A sensor setting outside its register's domain.
    Sensors,
}

impl fmt::Display for ServerConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ServerConfigError::UnitId => f.write_str("the unit id must be 1 to 247"),
            ServerConfigError::Line(e) => write!(f, "line settings: {e}"),
            ServerConfigError::Sensors => {
                f.write_str("a sensor setting is outside its register's domain")
            }
        }
    }
}

impl core::error::Error for ServerConfigError {}

/// The Modbus RTU server: the monitor, the register map's state, the framer.
#[derive(Debug, Clone)]
#[repr(C)]
pub struct Server<E> {
    framer: Framer,
    core: Core<E>,
}

impl<E: Estimator> Server<E> {
    /// A server answering as `config.unit_id` over `monitor`; its events still queued
    /// are taken into the event window, and `event_from` starts at the first of them.
    ///
    /// # Errors
    /// [`ServerConfigError::UnitId`] for a unit id of 0 or above 247.
    pub fn new(monitor: Monitor<E>, config: ServerConfig) -> Result<Self, ServerConfigError> {
        Self::with_step(monitor, config, Monitor::process)
    }

    fn with_step(
        monitor: Monitor<E>,
        config: ServerConfig,
        step: Step<E>,
    ) -> Result<Self, ServerConfigError> {
        if !(1..=247).contains(&config.unit_id) {
            return Err(ServerConfigError::UnitId);
        }
        let line = config.line_settings();
        line.validate().map_err(ServerConfigError::Line)?;
        if !config.sensors.is_valid() {
            return Err(ServerConfigError::Sensors);
        }
        let pending = monitor.pending_events() as u32;
        let monitor_next = monitor.next_event_seq();
        let from = monitor_next.wrapping_sub(pending);
        let model_name = if config.ident.model_name.is_empty() {
            core::any::type_name::<E>()
        } else {
            config.ident.model_name
        };
        let mut server = Server {
            framer: Framer::new(),
            core: Core {
                commissioning: Commissioning::new(config.unlock_code),
                line: Line::new(line),
                sensing: Sensing::new(config.sensors),
                monitor,
                step,
                unit: config.unit_id,
                ident: config.ident,
                model_name,
                annunciator: Annunciator::new(config.latching),
                events: EventWindow::new(from, monitor_next),
                external: config.external_samples,
                scene_required: config.scene_required,
                last_time_ms: 0,
                counters: Counters::default(),
                ack: None,
                storage: StorageStatus::default(),
                response: [0; ADU_MAX],
                response_len: 0,
                held: false,
            },
        };
        server.core.drain();
        Ok(server)
    }

    /// Takes one received byte; a request it completes is answered at once (see
    /// [`response`](Self::response)).
    pub fn receive(&mut self, byte: u8) {
        if !self.framer.push_waiting(byte) && !self.framer.push_request_head(byte, self.core.unit) {
            self.receive_deciding(byte);
        }
    }

    /// [`receive`](Self::receive) of a byte that can decide the candidate: out of
    /// line, so that the usual byte of a frame costs no set-up of the frame's handling.
    #[inline(never)]
    fn receive_deciding(&mut self, byte: u8) {
        self.framer.push(byte);
        while let Some(range) = self.framer.next(self.core.unit, false) {
            self.core.counters.framing = self.framer.counters();
            self.core.handle(self.framer.bytes(range));
        }
    }

    /// The application saw at least 3.5 character times of silence ([`silence_us`])
    /// after the last byte: what waits is a frame now or never.
    pub fn idle(&mut self) {
        let unit = self.core.unit;
        if let Some(range) = self.framer.silence(unit) {
            self.core.counters.framing = self.framer.counters();
            self.core.handle(self.framer.bytes(range));
        }
        while let Some(range) = self.framer.next(unit, true) {
            self.core.counters.framing = self.framer.counters();
            self.core.handle(self.framer.bytes(range));
        }
        self.framer.clear();
    }

    /// The answer to send, CRC included; `None` while none is due, or while a write's
    /// answer waits for [`stored`](Self::stored). Send it, then call
    /// [`sent`](Self::sent). A request completed before then replaces it (counted:
    /// [`Counters::responses_overwritten`]).
    pub fn response(&self) -> Option<&[u8]> {
        match self.core.response_len {
            _ if self.core.held => None,
            0 => None,
            n => self.core.response.get(..n),
        }
    }

    /// Store-and-forward ([`store_events`](Self::store_events)): the application has
    /// stored what the last requests changed (the events they raised, the
    /// acknowledgement, a committed image), `ok` if every write reached its flash.
    /// A write's answer waits for this call, so a master that got the answer knows it
    /// is stored; when `ok` is false the answer becomes exception 04 (what the write
    /// changed in RAM stays, but would not survive a reset).
    pub fn stored(&mut self, ok: bool) {
        let c = &mut self.core;
        if core::mem::take(&mut c.held) && !ok {
            let function = c.response[1];
            if function & 0x80 == 0 {
                let len = c.exception(function, Exception::ServerDeviceFailure);
                c.seal(len);
            }
        }
    }

    /// The response was sent. After the answer to a commit that changed the line
    /// settings, they are in force now: set the UART to [`line`](Self::line).
    pub fn sent(&mut self) {
        self.core.response_len = 0;
        self.core.line_sent();
    }

    /// The sampling period and sensor calibration in force (`active_sample_period`,
    /// `active_load_zero`, ...): committed over the bus, restored from the committed
    /// image, or the build's. Read it after each request and at boot, and recalibrate
    /// the sensors' drivers when it changed.
    pub fn sensors(&self) -> SensorSettings {
        self.core.sensing.active()
    }

    /// The line settings in force (`active_*`): after each [`sent`](Self::sent) and
    /// [`tick`](Self::tick) the application sets its UART to them when they changed,
    /// and waits `answer_delay_ms` before each answer.
    pub fn line(&self) -> LineSettings {
        self.core.line.active()
    }

    /// Whether the master is lost: no request for this node within the bus timeout
    /// (`line_status` bit 0); the answer to the next request clears it.
    pub fn master_lost(&self) -> bool {
        self.core.line.master_lost()
    }

    /// Changes of the line settings undone for want of a confirmation
    /// (`line_reverts`).
    pub fn line_reverts(&self) -> u32 {
        self.core.line.reverts()
    }

    /// Processes one of the node's own samples (`Monitor::process`, or
    /// `Monitor::process_with_friction` for a server made by
    /// [`with_friction`](Self::with_friction)); the event window and the alarms
    /// follow. Returns the state after it.
    pub fn process(&mut self, sample: Sample) -> RiskState {
        self.core.process(sample)
    }

    /// The monitor.
    pub fn monitor(&self) -> &Monitor<E> {
        &self.core.monitor
    }

    /// The alarms' annunciation.
    pub fn annunciator(&self) -> &Annunciator {
        &self.core.annunciator
    }

    /// Acknowledges the alarms of `which` (a local button; the bus acknowledges with
    /// the coil `acknowledge` or the register `acknowledge_alarms`).
    pub fn acknowledge(&mut self, which: AlarmSet) {
        self.core.annunciator.acknowledge(which);
    }

    /// Whether external samples are processed now.
    pub fn external_samples(&self) -> bool {
        self.core.external
    }

    /// The unit id.
    pub fn unit_id(&self) -> u8 {
        self.core.unit
    }

    /// What the server has counted.
    pub fn counters(&self) -> Counters {
        Counters {
            framing: self.framer.counters(),
            ..self.core.counters
        }
    }

    /// The application's clock for commissioning: `now_ms` a free-running millisecond
    /// counter (u32, wrapping). The unlock's timeout ([`UNLOCK_TIMEOUT_S`]) and the
    /// lock-out ([`LOCKOUT_S`]) run on it alone; call it at least once a second (without
    /// it, neither ends by itself).
    ///
    /// The line settings run on it too: a change not confirmed within
    /// [`LINE_CONFIRM_WINDOW_S`] goes back to the settings before it (an event, kind
    /// `LineReverted`, and `line_reverts`; set the UART to [`line`](Self::line) again),
    /// and no request for [`LineSettings::bus_timeout_s`] raises `MasterLost`.
    pub fn tick(&mut self, now_ms: u32) {
        self.core.commissioning.tick(now_ms);
        let raised = self.core.line.tick(now_ms);
        self.core.raise(raised);
    }

    /// Whether commissioning writes are unlocked now.
    pub fn unlocked(&self) -> bool {
        self.core.commissioning.unlocked()
    }

    /// What commissioning has counted.
    pub fn commissioning(&self) -> CommissioningCounts {
        self.core.commissioning.counts()
    }

    /// Where the configuration the monitor runs came from (the register
    /// `config_source`).
    pub fn config_source(&self) -> BootSource {
        self.core.commissioning.source()
    }

    /// Whether the scene the monitor runs was committed over the bus (now, or before
    /// a restart: kept in the committed image), not the build's (the discrete input
    /// `scene_commissioned`). A node with [`ServerConfig::scene_required`] monitors
    /// nothing until it is.
    pub fn scene_commissioned(&self) -> bool {
        self.core.commissioning.scene_commissioned()
    }

    /// The image of the configuration committed over the bus ([`IMAGE_LEN`] bytes: its
    /// configuration, the site's code, the alarms that latch, whether external samples
    /// are taken and, with [`accept_scenes`](Self::accept_scenes), the scene's prepared
    /// bytes) into `out`, once per commit and once per write that switched latching or
    /// the samples' source: `true` when such a change awaits being persisted. Call it
    /// after each request, and store `out` (the storage layer's `ConfigImage` record)
    /// before the next change.
    pub fn take_committed(&mut self, out: &mut [u8; IMAGE_LEN]) -> bool {
        let c = &mut self.core;
        let switches = config::Switches {
            latching: c.annunciator.latching(),
            external: c.external,
        };
        c.commissioning
            .take_committed(&c.monitor, switches, c.line.kept(), c.sensing.active(), out)
    }

    /// At boot: applies the configuration the application restored from its storage,
    /// or says why the build-time defaults run. A stored image that does not decode,
    /// whose configuration fails `Config::validate` or whose scene fails to load, changes
    /// nothing and gives [`BootSource::DefaultsDamaged`]. Returns what `config_source`
    /// reads after it.
    pub fn restore(&mut self, stored: Stored<'_>) -> BootSource {
        let c = &mut self.core;
        let (source, switches, kept) = c.commissioning.restore(stored, &mut c.monitor);
        if let Some(s) = switches {
            c.annunciator.set_latching(s.latching);
            c.external = s.external;
        }
        if let Some(l) = kept.line {
            c.line.restore(l);
            c.unit = l.unit_id;
        }
        if let Some(s) = kept.sensors {
            c.sensing.restore(s);
        }
        source
    }

    /// At boot, after [`restore`](Self::restore): the monitor goes on from its
    /// checkpoint ([`Monitor::resume`]) under the configuration and scene it now runs.
    /// In the other order a committed configuration or scene, applied after, would
    /// start the conditioning and the trend afresh.
    pub fn resume(&mut self, state: &MonitorState) {
        self.core.monitor.resume(state);
        let next = self.core.monitor.next_event_seq();
        self.core.events.follow(next);
    }

    /// The monitor back, the server given up.
    pub fn into_monitor(self) -> Monitor<E> {
        self.core.monitor
    }

    /// Store-and-forward (docs/modbus.md): from now on the application takes each
    /// event ([`pop_event`](Self::pop_event)), stores it, and hands it to the event
    /// window ([`offer_event`](Self::offer_event)); the window never drops an event a
    /// master has not read, and falls behind instead, fed from the store
    /// ([`wanted_event`](Self::wanted_event)). `first`: the oldest unacknowledged event
    /// the store holds at start-up, which the window wants first and `event_from`
    /// points at. Call it once, before the first sample. From then on every write
    /// (functions 5, 6, 15, 16) is answered only after [`stored`](Self::stored).
    pub fn store_events(&mut self, first: Option<u32>) {
        let next = self.core.monitor.next_event_seq();
        let w = &mut self.core.events;
        w.stored = true;
        if let Some(f) = first {
            w.know(f, next);
            w.from = f;
            w.backlog = Some(f).filter(|&f| f != next);
        }
    }

    /// Store-and-forward: the monitor's next new event, to store, then to
    /// [`offer_event`](Self::offer_event). `None` without [`store_events`](Self::store_events)
    /// (the server takes the events itself).
    pub fn pop_event(&mut self) -> Option<Event> {
        if self.core.events.stored {
            self.core.monitor.pop_event()
        } else {
            None
        }
    }

    /// Store-and-forward: a new event, stored, into the window; false if the window
    /// does not take it now (it is behind, or full of unread events): it wants it
    /// from the store later.
    pub fn offer_event(&mut self, event: Event) -> bool {
        let next = self.core.monitor.next_event_seq();
        self.core.events.offer(event, next, false)
    }

    /// Store-and-forward: the number of the event the window wants from the store
    /// (the first unacknowledged event at or after it), while it is behind and has
    /// room; hand it to [`offer_stored_event`](Self::offer_stored_event). If the store
    /// holds none at or after it, call [`end_backlog`](Self::end_backlog).
    pub fn wanted_event(&self) -> Option<u32> {
        let w = &self.core.events;
        let next = self.core.monitor.next_event_seq();
        w.backlog.filter(|_| w.has_room(next))
    }

    /// Store-and-forward: an event read from the store, the first at or after
    /// [`wanted_event`](Self::wanted_event), into the window.
    pub fn offer_stored_event(&mut self, event: Event) -> bool {
        let next = self.core.monitor.next_event_seq();
        self.core.events.offer(event, next, true)
    }

    /// Store-and-forward: the store holds no event at or after
    /// [`wanted_event`](Self::wanted_event) (they were lost): the window takes new
    /// events again; the gap counts as missed.
    pub fn end_backlog(&mut self) {
        self.core.events.backlog = None;
    }

    /// The number through which a master acknowledged the events (holding register
    /// `event_ack`), for the application to make durable; `None` before any.
    pub fn acknowledged_through(&self) -> Option<u32> {
        self.core.ack
    }

    /// What the application's storage reports (the registers `event_acked`,
    /// `events_stored`, `events_overwritten`, `checkpoints`, `checkpoint_age`).
    pub fn set_storage_status(&mut self, status: StorageStatus) {
        self.core.storage = status;
    }

    /// What [`set_storage_status`](Self::set_storage_status) set last.
    pub fn storage_status(&self) -> StorageStatus {
        self.core.storage
    }
}

impl<E: Estimator + PreparedScene> Server<E> {
    /// Takes scenes over the bus: the scene block and a commit load `E`'s prepared
    /// bytes ([`PreparedScene`]); without it the scene block refuses writes (exception
    /// 01) and a scene is never part of a committed image.
    pub fn accept_scenes(&mut self) {
        self.core.commissioning.accept_scenes(config::SceneIo::of());
    }
}

impl<E: Estimator + FrictionInverse> Server<E> {
    /// [`new`](Self::new), with every sample (the node's own and external ones) going
    /// through `Monitor::process_with_friction`: mu tracked from a measured axial force.
    ///
    /// # Errors
    /// As [`new`](Self::new).
    pub fn with_friction(
        monitor: Monitor<E>,
        config: ServerConfig,
    ) -> Result<Self, ServerConfigError> {
        Self::with_step(monitor, config, Monitor::process_with_friction)
    }
}
