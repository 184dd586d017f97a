//! [`Store`]: checkpoints of [`Checkpoint`] values in a NOR flash region, through
//! `sequential-storage`'s map (one key per record kind).

use core::cell::Cell;
use core::fmt;
use core::ops::Range;

use embedded_storage_async::nor_flash::NorFlash;
use sequential_storage::Error as SsError;
use sequential_storage::cache::{Cache, Uncached};
use sequential_storage::map::{MapConfig, MapConfigError, MapStorage, SerializationError, Value};

use super::Checkpoint;
use super::codec::{self, CodecError, Decoded};

/// The map's cache: none. A few reads more per operation, no RAM that could disagree
/// with the flash after a reset.
type NoCache = Cache<Uncached, Uncached, Uncached, u8>;

/// Why a [`Store`] could not be made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum StoreConfigError {
    /// The region does not start or end on a sector (erase-size) boundary.
    Unaligned,
    /// The region has fewer than two sectors: the map needs one to fill while it
    /// erases another.
    TooSmall,
    /// The flash's sectors are too small for the map's bookkeeping, or its word
    /// larger than 32 bytes.
    Geometry,
    /// The region reaches past the end of the flash.
    OutOfBounds,
    /// The checkpoint interval is zero.
    ZeroInterval,
}

impl fmt::Display for StoreConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            StoreConfigError::Unaligned => "region not on sector boundaries",
            StoreConfigError::TooSmall => "region needs at least two sectors",
            StoreConfigError::Geometry => "flash sectors too small or word too large",
            StoreConfigError::OutOfBounds => "region past the end of the flash",
            StoreConfigError::ZeroInterval => "checkpoint interval must be positive",
        })
    }
}

impl core::error::Error for StoreConfigError {}

/// Why a storage operation failed. `E` is the flash driver's error.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum StorageError<E> {
    /// The flash driver failed (or, on the mock flash, the power went).
    Flash(E),
    /// The region is full and nothing in it can be erased: more sectors are needed.
    Full,
    /// The region holds damage the map could not repair. [`Store::restore`] never
    /// returns this (it erases the region, starts fresh and reports it);
    /// [`Store::checkpoint`] does, and [`Store::erase`] is the remedy.
    Corrupted,
    /// The store's buffer is shorter than a record (`needed` bytes).
    BufferTooSmall {
        /// Bytes needed: the record, its key, rounded up to the flash word.
        needed: usize,
    },
    /// A record could not be encoded (the type's `encode` broke its `SIZE`).
    Codec(CodecError),
    /// The store's configuration is unusable.
    Config(StoreConfigError),
    /// `sequential-storage` reported an internal error it says should never happen.
    Internal,
}

impl<E: fmt::Debug> fmt::Display for StorageError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StorageError::Flash(e) => write!(f, "flash error: {e:?}"),
            StorageError::Full => f.write_str("storage region full"),
            StorageError::Corrupted => f.write_str("storage region corrupted"),
            StorageError::BufferTooSmall { needed } => {
                write!(f, "store buffer too small ({needed} bytes needed)")
            }
            StorageError::Codec(e) => write!(f, "record: {e}"),
            StorageError::Config(e) => write!(f, "configuration: {e}"),
            StorageError::Internal => f.write_str("sequential-storage internal error"),
        }
    }
}

/// The flash driver's error `E` need only be `Debug` (as `NorFlashError` asks), so it
/// is not a [`source`](core::error::Error::source); a record's or the configuration's
/// error is.
impl<E: fmt::Debug> core::error::Error for StorageError<E> {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            StorageError::Codec(e) => Some(e),
            StorageError::Config(e) => Some(e),
            _ => None,
        }
    }
}

impl<E> StorageError<E> {
    pub(super) fn from_ss(e: SsError<E>) -> Self {
        match e {
            SsError::Storage { value, .. } => StorageError::Flash(value),
            SsError::FullStorage => StorageError::Full,
            SsError::Corrupted { .. } => StorageError::Corrupted,
            SsError::BufferTooSmall(needed) => StorageError::BufferTooSmall { needed },
            SsError::ItemTooBig => StorageError::Full,
            _ => StorageError::Internal,
        }
    }
}

/// What [`Store::restore`] found, besides the value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RestoreOutcome {
    /// The latest checkpoint, in the current format.
    Restored {
        /// Its checkpoint number.
        sequence: u32,
    },
    /// The latest checkpoint, written by an older firmware in an older format and
    /// migrated.
    Migrated {
        /// Its checkpoint number.
        sequence: u32,
        /// The format version it was written in.
        from_version: u16,
    },
    /// Nothing of this kind was ever stored: a blank (erased) region, or one holding
    /// only records of other kinds. A first start: nothing to restore, nothing wrong.
    Blank,
    /// The region held something unusable: start from a fresh state. Count it and
    /// report it; [`Store::stats`] counts it too.
    Rejected(StorageEvent),
}

/// Why a restore started from a fresh state instead of the flash's contents.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum StorageEvent {
    /// The region's structure is damaged beyond the map's repair (e.g. garbage written
    /// over it), or the map lists a record of this kind it cannot fetch. The region
    /// was erased: checkpoint every kind you hold again.
    CorruptRegion,
    /// The region is not blank but holds no record of this kind: another program's
    /// data, garbage the map skipped over, or the very first checkpoint on a blank
    /// region cut by a power loss (nothing was lost then: there was nothing before
    /// it). The region was erased: checkpoint every kind you hold again.
    ForeignRegion,
    /// An item larger than this store's buffer sits in the region: a newer firmware's
    /// larger record (after a downgrade) or another program's. The region was erased:
    /// checkpoint every kind you hold again.
    OversizedRecord,
    /// A record of another program, or another record kind, sits under this kind's key.
    ForeignRecord,
    /// The record's CRC does not match.
    BadChecksum,
    /// The record was written by a newer firmware in a format this one cannot read
    /// (after a downgrade).
    NewerVersion {
        /// The version found.
        version: u16,
    },
    /// The record passed its CRC but does not decode: its length, an old version
    /// without a migration, or a value the type refuses.
    Undecodable,
}

impl StorageEvent {
    fn from_codec(e: CodecError, current: u16) -> Self {
        match e {
            CodecError::Foreign | CodecError::WrongKind { .. } => StorageEvent::ForeignRecord,
            CodecError::Checksum => StorageEvent::BadChecksum,
            CodecError::UnsupportedVersion { version } if version > current => {
                StorageEvent::NewerVersion { version }
            }
            _ => StorageEvent::Undecodable,
        }
    }
}

/// A restored value (if any) and what the restore found.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Restore<T> {
    /// The value, if a checkpoint was restored; start from a fresh state otherwise.
    pub value: Option<T>,
    /// What was found.
    pub outcome: RestoreOutcome,
}

/// Counts since this [`Store`] was made (RAM only: persist what matters, e.g. in the
/// monitor's counters, from [`RestoreOutcome::Rejected`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StorageStats {
    /// Checkpoints written.
    pub checkpoints: u32,
    /// Checkpoints that failed (flash error, power loss, full region).
    pub failed_checkpoints: u32,
    /// Restores that returned a value.
    pub restores: u32,
    /// Restores that found unusable contents and started fresh.
    pub rejected: u32,
    /// Times the region was erased because it was corrupt or foreign.
    pub region_erases: u32,
}

/// Sorts a map error met while restoring: a flash driver error is returned; anything
/// else says the region's contents are unusable, and which way.
fn unusable<E>(e: SsError<E>) -> Result<StorageEvent, StorageError<E>> {
    match e {
        SsError::Storage { value, .. } => Err(StorageError::Flash(value)),
        SsError::BufferTooSmall(_) => Ok(StorageEvent::OversizedRecord),
        _ => Ok(StorageEvent::CorruptRegion),
    }
}

/// What [`Store::restore`] found listed in the map when its key fetched nothing.
#[derive(Default)]
struct Held {
    /// An item under the key being restored.
    this_kind: bool,
    /// An item that is one of our records, of any kind.
    ours: bool,
}

/// A `sequential-storage` value that encodes a record straight into the map's buffer,
/// keeping the codec's error (the map only passes its own error type through).
struct Encoding<'a, T> {
    value: &'a T,
    sequence: u32,
    error: Cell<Option<CodecError>>,
}

impl<'a, T: Checkpoint> Value<'a> for Encoding<'_, T> {
    fn serialize_into(&self, buffer: &mut [u8]) -> Result<usize, SerializationError> {
        codec::encode(self.value, self.sequence, buffer).map_err(|e| {
            self.error.set(Some(e));
            SerializationError::InvalidData
        })
    }

    fn deserialize_from(_buffer: &'a [u8]) -> Result<(Self, usize), SerializationError> {
        // Records are read as bytes and decoded by `codec::decode`.
        Err(SerializationError::InvalidFormat)
    }
}

/// The store's buffer, word-aligned: some internal-flash drivers write only from
/// aligned RAM, and the map writes items straight from this buffer.
#[repr(C, align(4))]
struct Aligned<const N: usize>([u8; N]);

/// Checkpoints in a NOR flash region: each [`Checkpoint`] kind is one key of a
/// `sequential-storage` map, so a new checkpoint is appended, the old one stays valid
/// until the new one is complete, and sectors are erased in turn (wear levelling).
///
/// `BUF` is the store's buffer in bytes: at least [`Store::buffer_len`] for every
/// kind stored (the record plus one key byte, rounded up to the flash word).
pub struct Store<F: NorFlash, const BUF: usize> {
    map: MapStorage<u8, F, NoCache>,
    range: Range<u32>,
    buf: Aligned<BUF>,
    sequence: u32,
    interval_s: u32,
    last_s: Option<u64>,
    stats: StorageStats,
}

impl<F: NorFlash, const BUF: usize> fmt::Debug for Store<F, BUF> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Store")
            .field("range", &self.range)
            .field("sequence", &self.sequence)
            .field("interval_s", &self.interval_s)
            .field("last_s", &self.last_s)
            .field("stats", &self.stats)
            .finish_non_exhaustive()
    }
}

impl<F: NorFlash, const BUF: usize> Store<F, BUF> {
    /// The buffer a store of `T` needs: [`codec::record_len`]`(T::SIZE)` plus the key
    /// byte, rounded up to the flash word.
    #[must_use]
    pub const fn buffer_len<T: Checkpoint>() -> usize {
        let word = if F::WRITE_SIZE > F::READ_SIZE {
            F::WRITE_SIZE
        } else {
            F::READ_SIZE
        };
        let word = if word == 0 { 1 } else { word };
        (codec::record_len(T::SIZE) + 1).div_ceil(word) * word
    }

    /// A store on `range` of `flash` (whole sectors, at least two), checkpointing every
    /// `interval_s` seconds through [`Store::checkpoint_if_due`]. Reads nothing yet:
    /// call [`Store::restore`] at start-up.
    pub fn new(flash: F, range: Range<u32>, interval_s: u32) -> Result<Self, StoreConfigError> {
        if interval_s == 0 {
            return Err(StoreConfigError::ZeroInterval);
        }
        let capacity = u32::try_from(flash.capacity()).unwrap_or(u32::MAX);
        if range.end > capacity || range.start > range.end {
            return Err(StoreConfigError::OutOfBounds);
        }
        let config = MapConfig::<F>::try_new(range.clone()).map_err(|e| match e {
            MapConfigError::StartRangeNotAtPageBoundary
            | MapConfigError::EndRangeNotAtPageBoundary => StoreConfigError::Unaligned,
            MapConfigError::RangeTooSmall => StoreConfigError::TooSmall,
            _ => StoreConfigError::Geometry,
        })?;
        Ok(Store {
            map: MapStorage::new(flash, config, Cache::new_uncached()),
            range,
            buf: Aligned([0; BUF]),
            sequence: 0,
            interval_s,
            last_s: None,
            stats: StorageStats::default(),
        })
    }

    /// The flash back, e.g. to simulate a reset in a test or to hand it to a bootloader.
    pub fn into_flash(self) -> F {
        self.map.destroy().0
    }

    /// The counts since this store was made.
    #[must_use]
    pub fn stats(&self) -> StorageStats {
        self.stats
    }

    /// The number the next checkpoint will carry (one above the newest restored or
    /// written).
    #[must_use]
    pub fn next_sequence(&self) -> u32 {
        self.sequence.wrapping_add(1)
    }

    /// The checkpoint interval, seconds.
    #[must_use]
    pub fn interval_s(&self) -> u32 {
        self.interval_s
    }

    /// Changes the checkpoint interval (e.g. from a new configuration); the interval
    /// under way is measured against the new value.
    pub fn set_interval_s(&mut self, interval_s: u32) -> Result<(), StoreConfigError> {
        if interval_s == 0 {
            return Err(StoreConfigError::ZeroInterval);
        }
        self.interval_s = interval_s;
        Ok(())
    }

    fn check_buffer<T: Checkpoint>(&self) -> Result<(), StorageError<F::Error>> {
        let needed = Self::buffer_len::<T>();
        if needed > BUF {
            return Err(StorageError::BufferTooSmall { needed });
        }
        if T::SIZE > usize::from(u16::MAX) - codec::OVERHEAD {
            return Err(StorageError::Codec(CodecError::Length));
        }
        Ok(())
    }

    /// Restores the newest checkpoint of `T`, at start-up. Anything unusable in the
    /// region (damage, garbage, another program's data, a format this firmware cannot
    /// read) gives `value: None` and [`RestoreOutcome::Rejected`], never a wrong value;
    /// a damaged or foreign region is erased so that checkpoints can go on. `Err` only
    /// for a flash driver error or a store buffer too small for `T`.
    ///
    /// A state of most of a kilobyte (the monitor's) is better restored with
    /// [`Store::restore_into`], which does not hold it on the stack.
    pub async fn restore<T: Checkpoint>(&mut self) -> Result<Restore<T>, StorageError<F::Error>> {
        let mut value = None;
        let outcome = self
            .restore_with::<T>(|record| {
                codec::decode::<T>(record).map(|d| {
                    value = Some(d.value);
                    Decoded {
                        value: (),
                        sequence: d.sequence,
                        version: d.version,
                    }
                })
            })
            .await?;
        Ok(Restore { value, outcome })
    }

    /// [`Store::restore`] into `value`, decoded in place
    /// ([`Checkpoint::decode_into`]): the same outcomes, and no copy of the value on
    /// the stack. `value` holds the restored checkpoint when the outcome is
    /// [`RestoreOutcome::Restored`] or [`RestoreOutcome::Migrated`]; after any other
    /// outcome it may hold part of a refused record: start afresh.
    pub async fn restore_into<T: Checkpoint>(
        &mut self,
        value: &mut T,
    ) -> Result<RestoreOutcome, StorageError<F::Error>> {
        self.restore_with::<T>(|record| codec::decode_into(record, value))
            .await
    }

    /// The restore of the newest record of `T`, decoded by `decode`.
    async fn restore_with<T: Checkpoint>(
        &mut self,
        mut decode: impl FnMut(&[u8]) -> Result<Decoded<()>, CodecError>,
    ) -> Result<RestoreOutcome, StorageError<F::Error>> {
        self.check_buffer::<T>()?;
        let found = self
            .map
            .fetch_item::<&[u8]>(&mut self.buf.0, &T::KIND)
            .await;
        let event = match found {
            Ok(Some(bytes)) => match decode(bytes) {
                Ok(d) => {
                    self.sequence = self.sequence.max(d.sequence);
                    self.stats.restores = self.stats.restores.saturating_add(1);
                    return Ok(if d.version == T::VERSION {
                        RestoreOutcome::Restored {
                            sequence: d.sequence,
                        }
                    } else {
                        RestoreOutcome::Migrated {
                            sequence: d.sequence,
                            from_version: d.version,
                        }
                    });
                }
                Err(e) => StorageEvent::from_codec(e, T::VERSION),
            },
            Ok(None) => {
                // Nothing of this kind: a blank region, one holding only other kinds
                // of ours (calibration stored, state not yet), or something else.
                match self.records_held(T::KIND).await {
                    // The map lists a record of this kind it could not fetch: damage
                    // the map may not be able to write past either.
                    Ok(Held {
                        this_kind: true, ..
                    }) => {
                        self.erase_region().await?;
                        return Ok(self.rejected(StorageEvent::CorruptRegion));
                    }
                    Ok(Held { ours: true, .. }) => return Ok(RestoreOutcome::Blank),
                    Ok(_) => {}
                    Err(e) => {
                        let event = unusable(e)?;
                        self.erase_region().await?;
                        return Ok(self.rejected(event));
                    }
                }
                if self.region_is_blank().await? {
                    return Ok(RestoreOutcome::Blank);
                }
                self.erase_region().await?;
                StorageEvent::ForeignRegion
            }
            Err(e) => {
                let event = unusable(e)?;
                self.erase_region().await?;
                event
            }
        };
        Ok(self.rejected(event))
    }

    fn rejected(&mut self, event: StorageEvent) -> RestoreOutcome {
        self.stats.rejected = self.stats.rejected.saturating_add(1);
        RestoreOutcome::Rejected(event)
    }

    /// What records the map lists (every item it can read, old ones included).
    async fn records_held(&mut self, kind: u8) -> Result<Held, SsError<F::Error>> {
        let mut held = Held::default();
        let mut items = self.map.fetch_all_items(&mut self.buf.0).await?;
        while let Some((key, bytes)) = items.next::<&[u8]>(&mut self.buf.0).await? {
            held.this_kind |= key == kind;
            held.ours |= bytes.get(..4) == Some(&codec::MAGIC[..]);
        }
        Ok(held)
    }

    /// True if every byte of the region reads 0xFF.
    async fn region_is_blank(&mut self) -> Result<bool, StorageError<F::Error>> {
        // Read in chunks of the buffer, a multiple of the read size.
        let chunk = BUF - BUF % F::READ_SIZE.max(1);
        if chunk == 0 {
            return Err(StorageError::BufferTooSmall {
                needed: F::READ_SIZE,
            });
        }
        let buf = self.buf.0.get_mut(..chunk).ok_or(StorageError::Internal)?;
        read_blank(self.map.flash(), self.range.clone(), buf).await
    }

    /// Erases the whole region: every kind, every checkpoint. The remedy when
    /// [`Store::checkpoint`] keeps failing with [`StorageError::Corrupted`] (damage
    /// the map cannot write past); checkpoint every kind you hold again after it.
    pub async fn erase(&mut self) -> Result<(), StorageError<F::Error>> {
        self.erase_region().await
    }

    async fn erase_region(&mut self) -> Result<(), StorageError<F::Error>> {
        self.stats.region_erases = self.stats.region_erases.saturating_add(1);
        self.map.erase_all().await.map_err(StorageError::from_ss)
    }

    /// Writes a checkpoint of `value` now (on demand: before a firmware update, a
    /// planned shutdown, or after a rare event). The previous checkpoint stays the one
    /// restored until this one is complete on the flash.
    pub async fn checkpoint<T: Checkpoint>(
        &mut self,
        value: &T,
    ) -> Result<u32, StorageError<F::Error>> {
        self.check_buffer::<T>()?;
        let sequence = self.sequence.wrapping_add(1);
        // Encode once before touching the flash: a type that breaks its `SIZE` is
        // refused with nothing written.
        if let Err(e) = codec::encode(value, sequence, &mut self.buf.0) {
            self.stats.failed_checkpoints = self.stats.failed_checkpoints.saturating_add(1);
            return Err(StorageError::Codec(e));
        }
        let item = Encoding {
            value,
            sequence,
            error: Cell::new(None),
        };
        let result = self.map.store_item(&mut self.buf.0, &T::KIND, &item).await;
        match result {
            Ok(()) => {
                self.sequence = sequence;
                self.stats.checkpoints = self.stats.checkpoints.saturating_add(1);
                Ok(sequence)
            }
            Err(e) => {
                self.stats.failed_checkpoints = self.stats.failed_checkpoints.saturating_add(1);
                Err(match item.error.get() {
                    Some(codec_error) => StorageError::Codec(codec_error),
                    None => StorageError::from_ss(e),
                })
            }
        }
    }

    /// Writes a checkpoint if the interval has passed since the last one (`now_s`: a
    /// monotonic clock in seconds). The first call only starts the interval. Returns
    /// the checkpoint's number if one was written.
    pub async fn checkpoint_if_due<T: Checkpoint>(
        &mut self,
        now_s: u64,
        value: &T,
    ) -> Result<Option<u32>, StorageError<F::Error>> {
        let Some(last) = self.last_s else {
            self.last_s = Some(now_s);
            return Ok(None);
        };
        if now_s.saturating_sub(last) < u64::from(self.interval_s) {
            return Ok(None);
        }
        // The interval restarts even if the write fails: a failing flash is retried
        // one interval later, not on every sample.
        self.last_s = Some(now_s);
        self.checkpoint(value).await.map(Some)
    }
}

/// True if every byte of `range` reads 0xFF, read in chunks of `buf` (a multiple of
/// the flash's read size); false for an empty `buf`.
pub(super) async fn read_blank<F: NorFlash>(
    flash: &mut F,
    range: Range<u32>,
    buf: &mut [u8],
) -> Result<bool, StorageError<F::Error>> {
    if buf.is_empty() {
        return Ok(false);
    }
    let mut at = range.start;
    while at < range.end {
        let n = buf.len().min((range.end - at) as usize);
        let part = buf.get_mut(..n).ok_or(StorageError::Internal)?;
        flash.read(at, part).await.map_err(StorageError::Flash)?;
        if part.iter().any(|&b| b != 0xFF) {
            return Ok(false);
        }
        at += n as u32;
    }
    Ok(true)
}
