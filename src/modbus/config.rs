//! Commissioning over the bus: the monitor's configuration and the scene written to a
//! staged copy, shown beside the active one, committed whole or reverted by the
//! register `command`; every such write guarded by the site's code written to `unlock`;
//! the committed configuration handed to the application as bytes to persist, and
//! restored from them at boot. `docs/modbus.md` (Commissioning) is the master's side.
//!
//! The configuration's registers (staged `config_*`, active `active_*`) are [`Config`]
//! field by field, in [`ConfigField`]'s order; an option that is off reads 0 in its
//! switch (`spike_window`, `trend_interval`, `friction`) and in its values. The staged
//! copy is held as those registers' words (filled from the active configuration at its
//! first write; until then it reads as the active one) and decoded at the commit; the
//! active view is computed from the monitor's [`Config`] when it is read.
//!
//! Time is the application's: [`Server::tick`](super::Server::tick) with a
//! millisecond counter (u32, wrapping). Without ticks no unlock expires and no lock-out
//! ends, so an application calls it at least once a second.

use super::div::div1000;
use super::exception::Exception;
use super::line::{LINE_BYTES, Line, LineSettings};
use super::sensing::{SENSOR_BYTES, Sensing, SensorField, SensorSettings};
use crate::monitor::annunciation::AlarmSet;
use crate::monitor::{
    Config, ConfigError, FrictionConfig, Monitor, SpikeFilter, Thresholds, TrendConfig,
};
use crate::prepared::{PreparedError, crc32};
use crate::{Estimator, fixed, float};

/// Registers of the configuration, staged or active.
pub const CONFIG_WORDS: usize = 64;
/// The most bytes of a prepared scene the scene block holds.
pub const SCENE_BYTES_MAX: usize = 128;
/// The default site code ([`ServerConfig::unlock_code`](super::ServerConfig)): change
/// it at commissioning (`new_code`).
pub const DEFAULT_UNLOCK_CODE: u16 = 1234;
/// An unlock lasts this long (s) after the unlock or the last write it allowed, unless
/// a commit or the command `lock` ends it first.
pub const UNLOCK_TIMEOUT_S: u32 = 300;
/// Wrong codes in a row after which `unlock` refuses every code for [`LOCKOUT_S`].
pub const WRONG_CODES_MAX: u8 = 3;
/// The lock-out's length (s).
pub const LOCKOUT_S: u32 = 300;
/// Bytes of the committed configuration's image ([`Server::take_committed`](super::Server::take_committed)).
pub const IMAGE_LEN: usize = IMAGE_V3_LEN + SENSOR_BYTES;
/// Bytes of an image of version 1 or 2 (without the line settings).
const IMAGE_V2_LEN: usize = 4 + 2 * CONFIG_WORDS + 2 + SCENE_BYTES_MAX;
/// Bytes of an image of version 3 (without the sensor settings).
const IMAGE_V3_LEN: usize = IMAGE_V2_LEN + LINE_BYTES;
/// The image's format version (its byte 0). Version 1 held no switches: its
/// latching and samples' source stay the build's; versions 1 and 2 (10 bytes
/// shorter than 3) held no line settings, versions 1 to 3 (52 bytes shorter than 4)
/// no sensor settings: the build's stay.
pub const IMAGE_VERSION: u8 = 4;

/// The image's byte 1: bit 0 a scene follows, bit 1 external samples are taken, bit 2
/// the scene was committed over the bus (not the build's), bits 4-7 the alarms that
/// latch ([`AlarmSet`]'s bits).
mod flags {
    pub const SCENE: u8 = 1;
    pub const EXTERNAL: u8 = 2;
    pub const SCENE_COMMISSIONED: u8 = 4;
    /// Bit 3: 0 in every image.
    pub const RESERVED: u8 = 0x08;
    pub const LATCHING_SHIFT: u8 = 4;
}

/// The server's switches an image keeps beside the configuration: which alarms latch,
/// whether external samples are taken.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Switches {
    pub(crate) latching: AlarmSet,
    pub(crate) external: bool,
}

/// The values of the register `command`.
pub mod command {
    /// Validate the staged copy and apply it whole; the unlock ends.
    pub const COMMIT: u16 = 1;
    /// Discard the staged copy (it reads as the active one again).
    pub const REVERT: u16 = 2;
    /// End the unlock now.
    pub const LOCK: u16 = 3;
    /// Start the monitor's statistics afresh (`Monitor::reset_statistics`); the
    /// unlock stays.
    pub const RESET_STATISTICS: u16 = 4;
}

/// Where the configuration the monitor runs came from (the register `config_source`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BootSource {
    /// 0: the build-time defaults; none was stored.
    Defaults = 0,
    /// 1: a committed configuration (restored at boot, or committed since).
    Committed = 1,
    /// 2: the build-time defaults, because the stored configuration was damaged.
    DefaultsDamaged = 2,
}

/// What the application found in its storage at boot, for
/// [`Server::restore`](super::Server::restore).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stored<'a> {
    /// Nothing stored.
    Nothing,
    /// Something was stored but could not be read back (a checksum, a version, a
    /// length the storage layer refused).
    Damaged,
    /// The image a [`take_committed`](super::Server::take_committed) gave.
    Image(&'a [u8]),
}

/// A scene type whose prepared bytes ([`crate::prepared`]) a server loads at a commit
/// ([`Server::accept_scenes`](super::Server::accept_scenes)).
pub trait PreparedScene: Sized {
    /// The length of its prepared bytes (at most [`SCENE_BYTES_MAX`]).
    const BYTES: usize;
    /// The scene of `bytes` (`from_bytes`).
    ///
    /// # Errors
    /// The [`PreparedError`] of bytes that are not this type's scene.
    fn from_prepared(bytes: &[u8]) -> Result<Self, PreparedError>;
    /// Its prepared bytes into the start of `out` (`to_bytes`).
    fn to_prepared(&self, out: &mut [u8]);
}

macro_rules! prepared_scene {
    ($($t:ty),*) => {$(
        impl PreparedScene for $t {
            const BYTES: usize = <$t>::BYTES;
            fn from_prepared(bytes: &[u8]) -> Result<Self, PreparedError> {
                <$t>::from_bytes(bytes)
            }
            fn to_prepared(&self, out: &mut [u8]) {
                if let Some(o) = out.get_mut(..<$t>::BYTES) {
                    o.copy_from_slice(&self.to_bytes());
                }
            }
        }
        const _: () = assert!(<$t>::BYTES <= SCENE_BYTES_MAX);
    )*};
}

prepared_scene!(
    fixed::FixedEllipticScene,
    fixed::FixedLineScene,
    fixed::FixedAuto,
    float::EllipticScene<'static>,
    float::LineScene,
    float::Auto
);

/// How a server loads and writes its scene type's prepared bytes.
#[derive(Debug)]
pub(crate) struct SceneIo<E> {
    bytes: usize,
    load: fn(&[u8]) -> Result<E, PreparedError>,
    save: fn(&E, &mut [u8]),
}

impl<E> Clone for SceneIo<E> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<E> Copy for SceneIo<E> {}

impl<E: PreparedScene> SceneIo<E> {
    pub(crate) fn of() -> Self {
        SceneIo {
            bytes: E::BYTES,
            load: E::from_prepared,
            save: E::to_prepared,
        }
    }
}

/// One value of the configuration's registers; the discriminant is its first
/// register's offset in the block.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub(crate) enum ConfigField {
    ThresholdsOn = 0,
    Warning = 1,
    Alarm = 3,
    Deadband = 5,
    OnDelay = 7,
    OffDelay = 9,
    FaultDelay = 11,
    Inhibit = 13,
    StopLoad = 15,
    StopSpeed = 17,
    NominalSpeed = 19,
    LoadMin = 21,
    LoadMax = 23,
    AngleMax = 25,
    SpeedMax = 27,
    ForceMax = 29,
    SpikeWindow = 31,
    SpikeK = 32,
    SpikeLoadFloor = 34,
    SpikeAngleFloor = 36,
    SmoothingTau = 38,
    Stuck = 40,
    Gap = 42,
    TrendInterval = 44,
    TrendPoints = 46,
    TrendHorizon = 47,
    Friction = 49,
    FrictionSensitivity = 50,
    FrictionTau = 52,
    FrictionBaselineAfter = 54,
    FrictionBaselineEstimates = 56,
    FrictionBand = 58,
    FrictionDeadband = 60,
    FrictionDelay = 62,
}

use ConfigField as C;

impl ConfigField {
    /// Every field, in register order.
    const ALL: [ConfigField; 34] = [
        C::ThresholdsOn,
        C::Warning,
        C::Alarm,
        C::Deadband,
        C::OnDelay,
        C::OffDelay,
        C::FaultDelay,
        C::Inhibit,
        C::StopLoad,
        C::StopSpeed,
        C::NominalSpeed,
        C::LoadMin,
        C::LoadMax,
        C::AngleMax,
        C::SpeedMax,
        C::ForceMax,
        C::SpikeWindow,
        C::SpikeK,
        C::SpikeLoadFloor,
        C::SpikeAngleFloor,
        C::SmoothingTau,
        C::Stuck,
        C::Gap,
        C::TrendInterval,
        C::TrendPoints,
        C::TrendHorizon,
        C::Friction,
        C::FrictionSensitivity,
        C::FrictionTau,
        C::FrictionBaselineAfter,
        C::FrictionBaselineEstimates,
        C::FrictionBand,
        C::FrictionDeadband,
        C::FrictionDelay,
    ];

    /// Registers it takes: the switches and counts one, the rest two.
    const fn words(self) -> usize {
        match self {
            C::ThresholdsOn | C::SpikeWindow | C::TrendPoints | C::Friction => 1,
            _ => 2,
        }
    }

    /// Its value in `config`, as the register's bits (a one-register value in the low
    /// half).
    fn of(self, config: &Config) -> u32 {
        let (margin, [warning, alarm, deadband]) = match config.thresholds {
            Thresholds::SlipRatio {
                warning,
                alarm,
                deadband,
            } => (false, [warning, alarm, deadband]),
            Thresholds::Margin {
                warning,
                alarm,
                deadband,
            } => (true, [warning, alarm, deadband]),
        };
        let s = config.spikes;
        let t = config.trend;
        let f = config.friction;
        let f32s = |x: Option<f32>| x.map_or(0, f32::to_bits);
        match self {
            C::ThresholdsOn => u32::from(margin),
            C::Warning => warning.to_bits(),
            C::Alarm => alarm.to_bits(),
            C::Deadband => deadband.to_bits(),
            C::OnDelay => config.on_delay_ms,
            C::OffDelay => config.off_delay_ms,
            C::FaultDelay => config.fault_delay_ms,
            C::Inhibit => config.inhibit_ms,
            C::StopLoad => config.stop_load.to_bits(),
            C::StopSpeed => config.stop_speed.to_bits(),
            C::NominalSpeed => config.nominal_speed.to_bits(),
            C::LoadMin => config.load_min.to_bits(),
            C::LoadMax => config.load_max.to_bits(),
            C::AngleMax => config.angle_max.to_bits(),
            C::SpeedMax => config.speed_max.to_bits(),
            C::ForceMax => config.force_max.to_bits(),
            C::SpikeWindow => s.map_or(0, |s| u32::from(s.window)),
            C::SpikeK => f32s(s.map(|s| s.k)),
            C::SpikeLoadFloor => f32s(s.map(|s| s.load_floor)),
            C::SpikeAngleFloor => f32s(s.map(|s| s.angle_floor)),
            C::SmoothingTau => config.smoothing_tau_s.to_bits(),
            C::Stuck => config.stuck_ms,
            C::Gap => config.gap_ms,
            C::TrendInterval => t.map_or(0, |t| t.interval_ms),
            C::TrendPoints => t.map_or(0, |t| u32::from(t.points)),
            C::TrendHorizon => f32s(t.map(|t| t.horizon_s)),
            C::Friction => u32::from(f.is_some()),
            C::FrictionSensitivity => f32s(f.map(|f| f.sensitivity_max)),
            C::FrictionTau => f32s(f.map(|f| f.tau_s)),
            C::FrictionBaselineAfter => f.map_or(0, |f| f.baseline_after_ms),
            C::FrictionBaselineEstimates => f.map_or(0, |f| f.baseline_after_estimates),
            C::FrictionBand => f32s(f.map(|f| f.band)),
            C::FrictionDeadband => f32s(f.map(|f| f.deadband)),
            C::FrictionDelay => f.map_or(0, |f| f.delay_ms),
        }
    }

    /// Its value in `words`.
    fn get(self, words: &[u16; CONFIG_WORDS]) -> u32 {
        let at = usize::from(self as u8);
        let w = |i: usize| u32::from(words.get(i).copied().unwrap_or(0));
        if self.words() == 2 {
            w(at) << 16 | w(at + 1)
        } else {
            w(at)
        }
    }

    /// Sets its value in `words`.
    fn put(self, words: &mut [u16; CONFIG_WORDS], v: u32) {
        let at = usize::from(self as u8);
        let pair = [(v >> 16) as u16, v as u16];
        let src = if self.words() == 2 {
            &pair[..]
        } else {
            &pair[1..]
        };
        if let Some(dest) = words.get_mut(at..at + src.len()) {
            dest.copy_from_slice(src);
        }
    }
}

/// `config` as the configuration's registers.
pub(crate) fn config_words(config: &Config) -> [u16; CONFIG_WORDS] {
    let mut words = [0; CONFIG_WORDS];
    for f in ConfigField::ALL {
        f.put(&mut words, f.of(config));
    }
    words
}

/// The configuration in `words`, validated.
pub(crate) fn config_from_words(words: &[u16; CONFIG_WORDS]) -> Result<Config, ConfigError> {
    let u = |f: ConfigField| f.get(words);
    let x = |f: ConfigField| f32::from_bits(u(f));
    let (warning, alarm, deadband) = (x(C::Warning), x(C::Alarm), x(C::Deadband));
    let thresholds = Thresholds::from_kind(u(C::ThresholdsOn), warning, alarm, deadband)
        .ok_or(ConfigError::Threshold)?;
    let spikes = match u(C::SpikeWindow) {
        0 => None,
        w => Some(SpikeFilter {
            window: u8::try_from(w).map_err(|_| ConfigError::SpikeWindow)?,
            k: x(C::SpikeK),
            load_floor: x(C::SpikeLoadFloor),
            angle_floor: x(C::SpikeAngleFloor),
        }),
    };
    let trend = match u(C::TrendInterval) {
        0 => None,
        interval_ms => Some(TrendConfig {
            interval_ms,
            points: u8::try_from(u(C::TrendPoints)).map_err(|_| ConfigError::Trend)?,
            horizon_s: x(C::TrendHorizon),
        }),
    };
    let friction = match u(C::Friction) {
        0 => None,
        1 => Some(FrictionConfig {
            sensitivity_max: x(C::FrictionSensitivity),
            tau_s: x(C::FrictionTau),
            baseline_after_ms: u(C::FrictionBaselineAfter),
            baseline_after_estimates: u(C::FrictionBaselineEstimates),
            band: x(C::FrictionBand),
            deadband: x(C::FrictionDeadband),
            delay_ms: u(C::FrictionDelay),
        }),
        _ => return Err(ConfigError::Friction),
    };
    let config = Config {
        thresholds,
        on_delay_ms: u(C::OnDelay),
        off_delay_ms: u(C::OffDelay),
        fault_delay_ms: u(C::FaultDelay),
        inhibit_ms: u(C::Inhibit),
        stop_load: x(C::StopLoad),
        stop_speed: x(C::StopSpeed),
        nominal_speed: x(C::NominalSpeed),
        load_min: x(C::LoadMin),
        load_max: x(C::LoadMax),
        angle_max: x(C::AngleMax),
        speed_max: x(C::SpeedMax),
        force_max: x(C::ForceMax),
        spikes,
        smoothing_tau_s: x(C::SmoothingTau),
        stuck_ms: u(C::Stuck),
        gap_ms: u(C::Gap),
        trend,
        friction,
    };
    config.validate()?;
    Ok(config)
}

/// The reason codes of the register `commit_error`.
pub mod reason {
    use crate::monitor::ConfigError;
    use crate::prepared::PreparedError;

    /// The last commit was applied (or none was asked).
    pub const NONE: u16 = 0;
    /// A commit with nothing staged.
    pub const NOTHING_STAGED: u16 = 1;

    /// `0x10 +` the configuration's error: 0 threshold, 1 warning not before the
    /// alarm, 2 deadband, 3 stop, 4 nominal speed, 5 range, 6 spike filter, 7
    /// smoothing, 8 trend, 9 friction.
    pub const fn config(e: ConfigError) -> u16 {
        0x10 + match e {
            ConfigError::Threshold => 0,
            ConfigError::WarningAboveAlarm => 1,
            ConfigError::Deadband => 2,
            ConfigError::Stop => 3,
            ConfigError::NominalSpeed => 4,
            ConfigError::Range => 5,
            ConfigError::SpikeWindow => 6,
            ConfigError::Smoothing => 7,
            ConfigError::Trend => 8,
            ConfigError::Friction => 9,
        }
    }

    /// `0x20 +` the scene's error: 0 length, 1 magic, 2 kind (another scene type),
    /// 3 version, 4 checksum, 5 a constant out of range.
    pub const fn scene(e: PreparedError) -> u16 {
        0x20 + match e {
            PreparedError::Length => 0,
            PreparedError::Magic => 1,
            PreparedError::Kind => 2,
            PreparedError::Version => 3,
            PreparedError::Checksum => 4,
            PreparedError::Value => 5,
        }
    }
}

/// What is staged (the register `staged`).
pub mod staged {
    /// The configuration's registers were written.
    pub const CONFIG: u16 = 1;
    /// The scene block was written.
    pub const SCENE: u16 = 2;
    /// A new site code was written.
    pub const CODE: u16 = 4;
    /// The line settings were written.
    pub const LINE: u16 = 8;
    /// The sensor settings (sample period, calibration) were written.
    pub const SENSORS: u16 = 16;
}

/// The commissioning registers that are not the configuration's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Reg {
    Unlock,
    Command,
    CommitError,
    Source,
    Staged,
    Generation,
    Lockout,
    UnlockFailures,
    Refused,
    NewCode,
    SceneBytes,
    SceneStagedCrc,
    SceneActiveCrc,
    /// A word of the scene block.
    Scene,
}

/// What commissioning has counted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CommissioningCounts {
    /// Wrong codes written to `unlock`, and codes written during a lock-out.
    pub unlock_failures: u32,
    /// Lock-outs begun.
    pub lockouts: u32,
    /// Protected writes refused while locked.
    pub refused: u32,
    /// Commits applied.
    pub commits: u32,
}

/// The staged copy, the unlock and the persistence of commits.
#[derive(Debug, Clone)]
pub(crate) struct Commissioning<E> {
    staged: [u16; CONFIG_WORDS],
    scene: [u8; SCENE_BYTES_MAX],
    pending: u16,
    generation: u16,
    code: u16,
    new_code: u16,
    /// Time left of the unlock and of the lock-out (ms).
    unlock_ms: u32,
    lockout_ms: u32,
    wrong_in_row: u8,
    last_tick: Option<u32>,
    commit_error: u16,
    source: BootSource,
    /// The active scene was committed over the bus (now or before a restart): not the
    /// build's.
    scene_commissioned: bool,
    /// A commit the application has not taken to persist.
    unsaved: bool,
    counts: CommissioningCounts,
    io: Option<SceneIo<E>>,
}

impl<E: Estimator> Commissioning<E> {
    /// Locked, with `code`, nothing staged.
    pub(crate) const fn new(code: u16) -> Self {
        Commissioning {
            staged: [0; CONFIG_WORDS],
            scene: [0; SCENE_BYTES_MAX],
            pending: 0,
            generation: 0,
            code,
            new_code: code,
            unlock_ms: 0,
            lockout_ms: 0,
            wrong_in_row: 0,
            last_tick: None,
            commit_error: reason::NONE,
            source: BootSource::Defaults,
            scene_commissioned: false,
            unsaved: false,
            counts: CommissioningCounts {
                unlock_failures: 0,
                lockouts: 0,
                refused: 0,
                commits: 0,
            },
            io: None,
        }
    }

    pub(crate) fn accept_scenes(&mut self, io: SceneIo<E>) {
        self.io = Some(io);
    }

    pub(crate) fn counts(&self) -> CommissioningCounts {
        self.counts
    }

    pub(crate) fn source(&self) -> BootSource {
        self.source
    }

    pub(crate) fn scene_commissioned(&self) -> bool {
        self.scene_commissioned
    }

    pub(crate) fn unlocked(&self) -> bool {
        self.unlock_ms > 0
    }

    /// The application's clock: `now_ms` a wrapping millisecond counter. A step back
    /// (or of more than 2^31 ms) counts as none.
    pub(crate) fn tick(&mut self, now_ms: u32) {
        let dt = match self.last_tick {
            Some(last) => now_ms.wrapping_sub(last),
            None => 0,
        };
        self.last_tick = Some(now_ms);
        if dt < 1 << 31 {
            self.unlock_ms = self.unlock_ms.saturating_sub(dt);
            self.lockout_ms = self.lockout_ms.saturating_sub(dt);
        }
    }

    /// The register's value: cheap but for the scenes' CRCs (out of line), and inline
    /// in a read (a call per register costs a Cortex-M0 a tenth of a poll).
    #[inline(always)]
    pub(crate) fn value(&self, reg: Reg, monitor: &Monitor<E>) -> u32 {
        // No division while locked and not locked out (a poll's usual case).
        let seconds = |ms: u32| if ms == 0 { 0 } else { seconds(ms) };
        match reg {
            Reg::Unlock => seconds(self.unlock_ms),
            Reg::Command | Reg::NewCode | Reg::Scene => 0,
            Reg::CommitError => u32::from(self.commit_error),
            Reg::Source => self.source as u32,
            Reg::Staged => u32::from(self.pending),
            Reg::Generation => u32::from(self.generation),
            Reg::Lockout => seconds(self.lockout_ms),
            Reg::UnlockFailures => self.counts.unlock_failures & 0xFFFF,
            Reg::Refused => self.counts.refused & 0xFFFF,
            Reg::SceneBytes => self.io.map_or(0, |io| io.bytes as u32),
            Reg::SceneStagedCrc => self.io.map_or(0, |io| staged_crc(io, &self.scene)),
            Reg::SceneActiveCrc => self.io.map_or(0, |io| active_crc(io, monitor.estimator())),
        }
    }

    /// A staged register's value: the active one while the configuration is not
    /// staged (the staged words are filled at the first write).
    pub(crate) fn staged(&self, f: ConfigField, active: &Config) -> u32 {
        if self.pending & staged::CONFIG != 0 {
            f.get(&self.staged)
        } else {
            f.of(active)
        }
    }

    /// Whether a write to a protected register may go ahead: refused (01, counted)
    /// while locked; allowed, it renews the unlock.
    pub(crate) fn guard(&mut self) -> Result<(), Exception> {
        if self.unlocked() {
            self.unlock_ms = UNLOCK_TIMEOUT_S * 1000;
            Ok(())
        } else {
            self.counts.refused = self.counts.refused.wrapping_add(1);
            Err(Exception::IllegalFunction)
        }
    }

    /// A write into the staged copy was made: counted, the unlock renewed.
    fn touched(&mut self, what: u16) {
        self.pending |= what;
        self.generation = self.generation.wrapping_add(1);
        self.unlock_ms = UNLOCK_TIMEOUT_S * 1000;
    }

    pub(crate) fn write_staged(&mut self, f: ConfigField, v: u32, active: &Config) {
        if self.pending & staged::CONFIG == 0 {
            for g in ConfigField::ALL {
                g.put(&mut self.staged, g.of(active));
            }
        }
        f.put(&mut self.staged, v);
        self.touched(staged::CONFIG);
    }

    /// A sensor setting written (the guard passed, the value in its domain).
    pub(crate) fn write_sensor(&mut self, sensing: &mut Sensing, f: SensorField, v: u32) {
        sensing.write_staged(f, v);
        self.touched(staged::SENSORS);
    }

    /// A line setting written (the guard passed, the value in its domain).
    pub(crate) fn write_line(&mut self, line: &mut Line, f: super::line::LineField, v: u32) {
        if line.write_staged(f, v) {
            self.touched(staged::LINE);
        }
    }

    pub(crate) fn write_new_code(&mut self, v: u16) {
        self.new_code = v;
        self.touched(staged::CODE);
    }

    /// Bytes written into the scene block from byte `at`, after the checks.
    pub(crate) fn write_scene(&mut self, at: usize, data: &[u8]) -> Result<(), Exception> {
        self.io.ok_or(Exception::IllegalFunction)?;
        self.guard()?;
        let dest = self
            .scene
            .get_mut(at..at + data.len())
            .ok_or(Exception::IllegalDataAddress)?;
        dest.copy_from_slice(data);
        self.touched(staged::SCENE);
        Ok(())
    }

    /// A code written to `unlock`.
    pub(crate) fn unlock(&mut self, code: u16) -> Result<(), Exception> {
        if self.lockout_ms > 0 {
            self.counts.unlock_failures = self.counts.unlock_failures.wrapping_add(1);
            return Err(Exception::IllegalFunction);
        }
        if code != self.code {
            self.counts.unlock_failures = self.counts.unlock_failures.wrapping_add(1);
            self.wrong_in_row = self.wrong_in_row.saturating_add(1);
            if self.wrong_in_row >= WRONG_CODES_MAX {
                self.wrong_in_row = 0;
                self.lockout_ms = LOCKOUT_S * 1000;
                self.unlock_ms = 0;
                self.counts.lockouts = self.counts.lockouts.wrapping_add(1);
            }
            return Err(Exception::IllegalDataValue);
        }
        self.wrong_in_row = 0;
        self.unlock_ms = UNLOCK_TIMEOUT_S * 1000;
        Ok(())
    }

    /// The staged copy back to the active configuration and scene.
    fn revert(&mut self) {
        self.scene = [0; SCENE_BYTES_MAX];
        self.new_code = self.code;
        self.pending = 0;
    }

    /// A value written to `command` (the guard passed). Out of line: the commit's
    /// configuration and scene are on the stack only while a command runs.
    #[inline(never)]
    pub(crate) fn command(
        &mut self,
        v: u16,
        monitor: &mut Monitor<E>,
        line: &mut Line,
        sensing: &mut Sensing,
    ) -> Result<(), Exception> {
        match v {
            command::COMMIT => {
                let result = self.commit(monitor);
                self.commit_error = result.err().unwrap_or(reason::NONE);
                if result.is_ok() {
                    line.commit();
                    sensing.commit();
                }
                result.map_err(|_| Exception::IllegalDataValue)
            }
            command::REVERT => {
                self.revert();
                line.revert_staged();
                sensing.revert_staged();
                self.unlock_ms = UNLOCK_TIMEOUT_S * 1000;
                Ok(())
            }
            command::LOCK => {
                self.unlock_ms = 0;
                Ok(())
            }
            command::RESET_STATISTICS => {
                monitor.reset_statistics();
                Ok(())
            }
            _ => Err(Exception::IllegalDataValue),
        }
    }

    /// Validates what is staged, then applies it whole; the reason code otherwise.
    fn commit(&mut self, monitor: &mut Monitor<E>) -> Result<(), u16> {
        if self.pending == 0 {
            return Err(reason::NOTHING_STAGED);
        }
        let config = if self.pending & staged::CONFIG != 0 {
            Some(config_from_words(&self.staged).map_err(reason::config)?)
        } else {
            None
        };
        let scene = match self.io {
            Some(io) if self.pending & staged::SCENE != 0 => {
                let bytes = self.scene.get(..io.bytes).unwrap_or(&[]);
                Some((io.load)(bytes).map_err(reason::scene)?)
            }
            _ => None,
        };
        // Checked: nothing below fails.
        if let Some(config) = config {
            monitor.set_config(config).map_err(reason::config)?;
        }
        if let Some(scene) = scene {
            monitor.set_estimator(scene);
            self.scene_commissioned = true;
        }
        if self.pending & staged::CODE != 0 {
            self.code = self.new_code;
        }
        self.revert();
        self.unlock_ms = 0;
        self.source = BootSource::Committed;
        self.unsaved = true;
        self.counts.commits = self.counts.commits.wrapping_add(1);
        Ok(())
    }

    /// A write switched latching or the samples' source (the guard passed): applied
    /// at once, and kept as a commit is.
    pub(crate) fn switched(&mut self) {
        self.source = BootSource::Committed;
        self.unsaved = true;
    }

    /// The committed configuration's image, with `switches`, into `out`, if a commit
    /// or a switch awaits being persisted.
    pub(crate) fn take_committed(
        &mut self,
        monitor: &Monitor<E>,
        switches: Switches,
        line: LineSettings,
        sensors: SensorSettings,
        out: &mut [u8; IMAGE_LEN],
    ) -> bool {
        if !self.unsaved {
            return false;
        }
        self.unsaved = false;
        out.fill(0);
        out[0] = IMAGE_VERSION;
        out[1] = switches.latching.bits() << flags::LATCHING_SHIFT
            | if switches.external {
                flags::EXTERNAL
            } else {
                0
            };
        out[2..4].copy_from_slice(&self.code.to_le_bytes());
        let words = config_words(monitor.config());
        for (o, w) in out[4..4 + 2 * CONFIG_WORDS].chunks_exact_mut(2).zip(words) {
            o.copy_from_slice(&w.to_le_bytes());
        }
        if let Some(io) = self.io {
            out[1] |= flags::SCENE;
            if self.scene_commissioned {
                out[1] |= flags::SCENE_COMMISSIONED;
            }
            let at = 4 + 2 * CONFIG_WORDS;
            out[at..at + 2].copy_from_slice(&(io.bytes as u16).to_le_bytes());
            (io.save)(monitor.estimator(), &mut out[at + 2..IMAGE_V2_LEN]);
        }
        out[IMAGE_V2_LEN..IMAGE_V3_LEN].copy_from_slice(&line.to_bytes());
        out[IMAGE_V3_LEN..].copy_from_slice(&sensors.to_bytes());
        true
    }

    /// Applies what the application found stored at boot; the switches an image
    /// kept, for the server to apply.
    pub(crate) fn restore(
        &mut self,
        stored: Stored<'_>,
        monitor: &mut Monitor<E>,
    ) -> (BootSource, Option<Switches>, Kept) {
        let (mut switches, mut kept) = (None, Kept::default());
        self.scene_commissioned = false;
        self.source = match stored {
            Stored::Nothing => BootSource::Defaults,
            Stored::Damaged => BootSource::DefaultsDamaged,
            Stored::Image(image) => match self.apply_image(image, monitor) {
                Some((s, k)) => {
                    (switches, kept) = (s, k);
                    BootSource::Committed
                }
                None => BootSource::DefaultsDamaged,
            },
        };
        self.revert();
        (self.source, switches, kept)
    }

    /// An image's configuration, code, scene, line and sensor settings checked, then
    /// applied, and its switches (none in a version 1 image), line settings (none
    /// before version 3) and sensor settings (none before version 4); `None` (and
    /// nothing applied) for an image that is not one.
    fn apply_image(
        &mut self,
        image: &[u8],
        monitor: &mut Monitor<E>,
    ) -> Option<(Option<Switches>, Kept)> {
        let (&[version, flags], _) = image.split_first_chunk::<2>()?;
        let mut kept = Kept::default();
        let image = match (version, image.len()) {
            (1 | 2, IMAGE_V2_LEN) => image,
            (3, IMAGE_V3_LEN) | (IMAGE_VERSION, IMAGE_LEN) => {
                let (v2, rest) = image.split_at_checked(IMAGE_V2_LEN)?;
                let (line, sensors) = rest.split_at_checked(LINE_BYTES)?;
                kept.line = Some(LineSettings::from_bytes(line.try_into().ok()?)?);
                if version == IMAGE_VERSION {
                    kept.sensors = Some(SensorSettings::from_bytes(sensors.try_into().ok()?)?);
                }
                v2
            }
            _ => return None,
        };
        let image: &[u8; IMAGE_V2_LEN] = image.try_into().ok()?;
        let (_, rest) = image.split_first_chunk::<2>()?;
        let switches = match version {
            1 if flags <= flags::SCENE => None,
            2..=IMAGE_VERSION
                if flags & flags::RESERVED == 0
                    && (flags & flags::SCENE_COMMISSIONED == 0 || flags & flags::SCENE != 0) =>
            {
                Some(Switches {
                    latching: AlarmSet::from_bits(flags >> flags::LATCHING_SHIFT),
                    external: flags & flags::EXTERNAL != 0,
                })
            }
            _ => return None,
        };
        let (code, rest) = rest.split_first_chunk::<2>()?;
        let (config, rest) = rest.split_first_chunk::<{ 2 * CONFIG_WORDS }>()?;
        let (len, scene) = rest.split_first_chunk::<2>()?;
        let mut words = [0; CONFIG_WORDS];
        for (w, b) in words.iter_mut().zip(config.chunks_exact(2)) {
            *w = u16::from_le_bytes([b[0], b[1]]);
        }
        let config = config_from_words(&words).ok()?;
        let estimator = match (flags & flags::SCENE, self.io) {
            (0, _) => None,
            (_, Some(io)) if usize::from(u16::from_le_bytes(*len)) == io.bytes => {
                Some((io.load)(scene.get(..io.bytes)?).ok()?)
            }
            _ => return None,
        };
        monitor.set_config(config).ok()?;
        if let Some(e) = estimator {
            monitor.set_estimator(e);
        }
        self.scene_commissioned = flags & flags::SCENE_COMMISSIONED != 0;
        self.code = u16::from_le_bytes(*code);
        Some((switches, kept))
    }
}

/// What a committed image keeps beside the configuration: the line settings (from
/// version 3) and the sensor settings (from version 4).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Kept {
    pub line: Option<LineSettings>,
    pub sensors: Option<SensorSettings>,
}

/// Whole seconds in `ms`, rounded up.
#[inline(never)]
fn seconds(ms: u32) -> u32 {
    let s = div1000(ms);
    s + u32::from(s.wrapping_mul(1000) != ms)
}

/// `scene_staged_crc`.
#[inline(never)]
fn staged_crc<E>(io: SceneIo<E>, scene: &[u8; SCENE_BYTES_MAX]) -> u32 {
    crc32(scene.get(..io.bytes.saturating_sub(4)).unwrap_or(&[]))
}

/// `scene_active_crc`: the scene's bytes on the stack only while it is read.
#[inline(never)]
fn active_crc<E>(io: SceneIo<E>, estimator: &E) -> u32 {
    let mut bytes = [0; SCENE_BYTES_MAX];
    (io.save)(estimator, &mut bytes);
    crc32(bytes.get(..io.bytes.saturating_sub(4)).unwrap_or(&[]))
}

/// An active configuration register's value.
#[inline(never)]
pub(crate) fn active(f: ConfigField, config: &Config) -> u32 {
    f.of(config)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::modbus::map::{Field, HOLDINGS};
    use std::vec::Vec;

    /// The map's `config_*` and `active_*` entries sit where [`ConfigField`] says, with
    /// its number of registers, every field once, in one run of [`CONFIG_WORDS`].
    #[test]
    fn the_maps_configuration_entries_are_the_fields() {
        for view in [Field::Staged as fn(ConfigField) -> Field, Field::Active] {
            let entries: Vec<_> = HOLDINGS
                .entries
                .iter()
                .filter(|e| ConfigField::ALL.iter().any(|&f| e.field == view(f)))
                .collect();
            assert_eq!(entries.len(), ConfigField::ALL.len());
            let first = entries[0].address;
            for (e, f) in entries.iter().zip(ConfigField::ALL) {
                assert_eq!(e.field, view(f), "{}", e.name);
                assert_eq!(e.address - first, u16::from(f as u8), "{}", e.name);
                assert_eq!(usize::from(e.ty.words()), f.words(), "{}", e.name);
            }
            let last = entries[entries.len() - 1];
            assert_eq!(usize::from(last.end() - first), CONFIG_WORDS);
        }
    }

    /// Every configuration goes through the registers and back unchanged.
    #[test]
    fn configurations_round_trip_through_the_registers() {
        let d = Config::default();
        let margin = Config {
            thresholds: Thresholds::Margin {
                warning: 2e-4,
                alarm: -1e-5,
                deadband: 0.0,
            },
            spikes: None,
            trend: None,
            friction: None,
            smoothing_tau_s: 0.0,
            ..d
        };
        let extremes = Config {
            on_delay_ms: u32::MAX,
            off_delay_ms: 0,
            load_min: f32::MIN,
            load_max: f32::MAX,
            spikes: Some(SpikeFilter {
                window: 3,
                k: f32::MIN_POSITIVE,
                load_floor: f32::MAX,
                angle_floor: 1e-30,
            }),
            trend: Some(TrendConfig {
                interval_ms: 1,
                points: 16,
                horizon_s: f32::MAX,
            }),
            ..d
        };
        for c in [d, margin, extremes] {
            assert_eq!(config_from_words(&config_words(&c)), Ok(c));
        }
    }
}
