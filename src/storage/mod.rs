//! Durable monitoring state on NOR flash (feature `sequential-storage`): versioned,
//! checksummed checkpoints that survive a power loss at any moment, restored at
//! start-up.
//!
//! - [`Checkpoint`]: a type that encodes to a fixed-size payload (little-endian fields
//!   through [`Writer`] / [`Reader`]), with a format version and [`Checkpoint::migrate`]
//!   from older versions, so that a newer firmware reads what an older one wrote.
//! - [`codec`]: the record around the payload: magic, kind, version, checkpoint number,
//!   CRC-32. A damaged, foreign or unknown record decodes to an error, never a value.
//! - [`Store`]: checkpoints in a flash region through `sequential-storage`'s map (one
//!   key per [`Checkpoint::KIND`]; the old checkpoint stays valid until the new one is
//!   complete; sectors erased in turn). [`Store::checkpoint`] on demand,
//!   [`Store::checkpoint_if_due`] at the configured interval, [`Store::restore`] at
//!   start-up ([`Store::restore_into`] decodes in place, for a large state on a small
//!   stack). A corrupt or foreign region restores nothing and reports a
//!   [`StorageEvent`] ([`RestoreOutcome::Rejected`]), counted in [`Store::stats`].
//! - [`EventQueue`]: numbered records (the monitor's `Event`s) in a region of their
//!   own, kept until a master acknowledges them, through a reset and a power loss at
//!   any moment; a full region drops the oldest unacknowledged ones, counted.
//! - [`BlockingFlash`] and [`block_on`]: the store on bare metal without an executor
//!   (see [`blocking`]). The store owns its flash; to share a driver, hand it
//!   `&mut driver` (the flash traits are implemented for `&mut F`) or take it back with
//!   [`Store::into_flash`].
//!
//! One store holds several kinds in one region (the monitor's state, the sensors'
//! calibration: [`kind`]); its buffer `BUF` must be at least
//! [`Store::buffer_len`] of the largest. At start-up restore each kind; after a
//! [`RestoreOutcome::Rejected`] with [`StorageEvent::CorruptRegion`],
//! [`StorageEvent::ForeignRegion`] or [`StorageEvent::OversizedRecord`] the region was
//! erased: checkpoint every kind held in RAM again.
//! - [`ConfigImage`]: a configuration committed over the fieldbus (the Modbus server's
//!   image of its configuration, site code and scene) under [`kind::COMMITTED_CONFIG`],
//!   old or new after a power loss, never a mix.
//! - `SensorCalibration` (with the feature `sensors`): the sensors' calibration (load
//!   cell, misalignment probes, tachometer) as one record of [`kind::CALIBRATION`],
//!   put back only if every part passes its `validate`.
//! - `MockFlash` (feature `_mock-flash`, semver-exempt): NOR flash in RAM with
//!   power-loss injection at every byte written and every word erased.
//!
//! # A power loss
//!
//! A power loss during a checkpoint leaves the previous checkpoint or the new one,
//! never a mix and never an older one (the storage tests sweep every point of every
//! write and erase of a checkpoint). So a restart loses at most one interval of
//! monitoring: choose the interval as the loss you accept, then check the wear.
//!
//! # Flash wear
//!
//! Each sector is erased once every `k * s` checkpoints (`k` checkpoints per sector,
//! `s` sectors; the arithmetic is in [`endurance`]). For the [`endurance::REFERENCE`] geometry
//! (a 792-byte payload, the monitor's whole state, `MonitorState`, version 1; eight
//! 4 KiB sectors; 4-byte words: 4 checkpoints per sector) at the default interval of
//! one hour ([`endurance::DEFAULT_INTERVAL_S`]):
//!
//! | interval | checkpoints a year | erase cycles per sector a year | years to 10 000 cycles |
//! | --- | --- | --- | --- |
//! | 1 h (default) | 8 766 | 274 | 36 |
//! | 15 min | 35 064 | 1 096 | 9 |
//! | 5 min | 105 192 | 3 288 | 3 |
//!
//! To choose the interval: pick the longest loss of accumulation (energy, time per
//! state, counters) you accept on a power failure, and checkpoint on demand at the rare
//! moments that must not be lost (a risk-state change, before a planned reset or a
//! firmware update); compute [`endurance::Geometry::cycles_per_year`] for your record
//! ([`Checkpoint::SIZE`]) and region; if the part's rated cycles (10 000 for typical
//! MCU internal flash) last fewer years than the product's life, lengthen the interval
//! or give the region more sectors ([`endurance::Geometry::min_interval_s`] gives the
//! shortest interval for a life: 987 s for ten years at the reference geometry).
//! Doubling the sectors halves the wear; so does halving the record.

pub mod blocking;
#[cfg(feature = "sensors")]
mod calibration;
pub mod codec;
mod config;
pub mod endurance;
mod event_queue;
#[cfg(feature = "_mock-flash")]
mod mock_flash;
mod store;

#[cfg(feature = "sensors")]
pub use crate::sensors::SensorCalibration;
pub use blocking::{BlockingFlash, block_on};
pub use codec::{CodecError, Reader, Writer};
pub use config::ConfigImage;
pub use event_queue::{EventQueue, Pushed, QueueStats, Recovered};
#[cfg(feature = "_mock-flash")]
pub use mock_flash::{MockError, MockFlash};
pub use store::{
    Restore, RestoreOutcome, StorageError, StorageEvent, StorageStats, Store, StoreConfigError,
};

/// The record kinds ([`Checkpoint::KIND`]) of this crate's state types, fixed here so
/// that two types never share a key in a region (a kind is never reused for another
/// type: an old record would be read as the new type's).
pub mod kind {
    /// The condition monitor's state.
    pub const MONITOR_STATE: u8 = 1;
    /// The sensors' calibration.
    pub const CALIBRATION: u8 = 2;
    /// The monitor's configuration.
    pub const MONITOR_CONFIG: u8 = 3;
    /// One event of the monitor, in the flash event queue ([`EventQueue`](super::EventQueue)).
    pub const EVENT: u8 = 8;
    /// An acknowledgement in the flash event queue: every record up to its sequence
    /// number is acknowledged.
    pub const EVENT_ACK: u8 = 9;
    /// A configuration committed over a fieldbus, as its server's image
    /// ([`ConfigImage`](super::ConfigImage)).
    pub const COMMITTED_CONFIG: u8 = 4;
}

/// A value stored as a checkpoint: a fixed-size, versioned payload.
///
/// Implement it with little-endian fields, in a fixed order:
///
/// ```
/// use misalign::storage::{Checkpoint, CodecError, Reader, Writer};
///
/// struct Wear {
///     energy_j: [f64; 3],
///     events: u32,
/// }
///
/// impl Checkpoint for Wear {
///     const KIND: u8 = 1;
///     const VERSION: u16 = 1;
///     const SIZE: usize = 3 * 8 + 4;
///
///     fn encode(&self, w: &mut Writer<'_>) -> Result<(), CodecError> {
///         w.each(&self.energy_j, |w, e| w.f64(*e))?;
///         w.u32(self.events)
///     }
///
///     fn decode(r: &mut Reader<'_>) -> Result<Self, CodecError> {
///         let energy_j = r.array_of(|r| r.f64())?;
///         if energy_j.iter().any(|e: &f64| !(*e >= 0.0)) {
///             return Err(CodecError::InvalidValue); // never restore a wrong value
///         }
///         Ok(Wear { energy_j, events: r.u32()? })
///     }
/// }
/// ```
///
/// When the layout changes: raise `VERSION`, update `SIZE`, `encode` and `decode`, and
/// read the old layout in [`Checkpoint::migrate`]; keep a test that decodes a record
/// of the old version (bytes frozen in the test), so that a newer firmware always
/// reads what the fleet wrote.
pub trait Checkpoint: Sized {
    /// The record kind: one per type stored in a region (the map's key). The monitor's
    /// state and the sensors' calibration, say, take two kinds.
    const KIND: u8;
    /// The format version `encode` writes and `decode` reads.
    const VERSION: u16;
    /// The payload bytes `encode` writes (at most 65 515).
    const SIZE: usize;

    /// Writes the payload: exactly [`Checkpoint::SIZE`] bytes.
    fn encode(&self, w: &mut Writer<'_>) -> Result<(), CodecError>;

    /// Reads a payload of the current version. Refuse ([`CodecError::InvalidValue`])
    /// any field no encoded value can hold.
    fn decode(r: &mut Reader<'_>) -> Result<Self, CodecError>;

    /// [`Checkpoint::decode`] into `self`, in place, for [`Store::restore_into`] and
    /// [`codec::decode_into`]: a type of some hundred bytes overrides it field by
    /// field, so that a restore does not build the value on the stack and copy it
    /// (on a Cortex-M0 with 16 KiB of RAM that matters). The default decodes a value
    /// and moves it in. On an error `self` may hold part of the payload.
    fn decode_into(&mut self, r: &mut Reader<'_>) -> Result<(), CodecError> {
        *self = Self::decode(r)?;
        Ok(())
    }

    /// Reads a payload of an older `version` (below [`Checkpoint::VERSION`]) into the
    /// current type, all of the payload. The default knows no older version.
    fn migrate(version: u16, r: &mut Reader<'_>) -> Result<Self, CodecError> {
        let _ = r;
        Err(CodecError::UnsupportedVersion { version })
    }
}
