//! [`EventQueue`]: numbered records (the monitor's events) kept on flash until a master
//! acknowledges them, through `sequential-storage`'s queue.
//!
//! The region is one append-only log of two kinds of record, each a [`codec`] record
//! (magic, kind, version, sequence number, CRC-32; docs/formats.md):
//!
//! - a record of `T` ([`kind::EVENT`] for the monitor's `Event`), its sequence field the
//!   event's own number;
//! - an acknowledgement ([`kind::EVENT_ACK`], no payload), its sequence field the number
//!   through which every record is acknowledged.
//!
//! Nothing is ever popped (no word is written twice, so flash without multiple writes
//! per word, ECC flash, serves): what is acknowledged is what the newest
//! acknowledgement in the log says, and [`EventQueue::open`] finds it again after a
//! reset by reading the log through. A power loss while an acknowledgement is written
//! leaves the old one or the new one (the queue's item CRC refuses a half-written
//! item), so an acknowledged record never comes back and an unacknowledged one is
//! never taken for acknowledged. A power loss while a record is pushed leaves the log
//! with or without it.
//!
//! The log's space is taken back by `sequential-storage` itself: when the region is
//! full, a push erases the oldest sector. Records there that were acknowledged cost
//! nothing; unacknowledged ones are dropped, counted ([`Pushed::dropped`],
//! [`EventQueue::dropped`]), and leave a gap in the sequence numbers of equal size.
//! Numbers are compared modulo 2^32 (a record is acknowledged when its number is at
//! or before the acknowledged one, within 2^31).
//!
//! Cost: the queue keeps no index in RAM (nothing that could disagree with the flash
//! after a reset): [`open`](EventQueue::open), each push and each acknowledgement read
//! the log through (twice, checking every record's CRC), so their time grows with the
//! region. Events are rare (a risk state changes a few times a day); size the region
//! for the backlog a master may leave, not larger.

use core::fmt;
use core::marker::PhantomData;
use core::ops::Range;

use embedded_storage_async::nor_flash::NorFlash;
use sequential_storage::cache::{Cache, Uncached};
use sequential_storage::queue::{QueueConfig, QueueConfigError, QueueStorage};

use super::codec::{self, CodecError};
use super::store::{StorageError, StoreConfigError};
use super::{Checkpoint, Reader, Writer, kind};

/// The queue's cache: none (no RAM that could disagree with the flash after a reset).
type NoCache = Cache<Uncached, Uncached, Uncached, ()>;

/// Whether sequence number `a` is at or after `b` (modulo 2^32, within 2^31).
const fn at_or_after(a: u32, b: u32) -> bool {
    a.wrapping_sub(b) < 1 << 31
}

/// Whether record `seq` is acknowledged by `ack`.
const fn acknowledged_by(seq: u32, ack: Option<u32>) -> bool {
    match ack {
        Some(k) => at_or_after(k, seq),
        None => false,
    }
}

/// The acknowledgement record: no payload; its sequence field says through which
/// number.
struct Ack;

impl Checkpoint for Ack {
    const KIND: u8 = kind::EVENT_ACK;
    const VERSION: u16 = 1;
    const SIZE: usize = 0;

    fn encode(&self, _w: &mut Writer<'_>) -> Result<(), CodecError> {
        Ok(())
    }

    fn decode(_r: &mut Reader<'_>) -> Result<Self, CodecError> {
        Ok(Ack)
    }
}

/// What [`EventQueue::open`] found in the region.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Recovered {
    /// The newest acknowledgement: every record through this number is acknowledged.
    /// `None`: none stored (or it was in a sector erased to make room, after which
    /// every record held is newer than it).
    pub acknowledged: Option<u32>,
    /// The oldest record not acknowledged: the first a master reads.
    pub first: Option<u32>,
    /// The newest record: number the next one after it.
    pub newest: Option<u32>,
    /// Records not acknowledged.
    pub unacknowledged: u32,
    /// Items that are not records of this queue (damaged, foreign, another version),
    /// skipped.
    pub skipped: u32,
    /// The region held no record of this queue and was not blank (another program's
    /// data, garbage), or damage `sequential-storage` could not repair: it was erased
    /// (no event of this queue was in it).
    pub erased: bool,
}

/// What one push did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Pushed {
    /// Unacknowledged records erased to make room (the region was full of them): the
    /// oldest ones.
    pub dropped: u32,
}

/// The queue's counts since [`EventQueue::open`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct QueueStats {
    /// Records pushed.
    pub pushed: u32,
    /// Acknowledgements written.
    pub acknowledgements: u32,
    /// Unacknowledged records dropped because the region was full.
    pub dropped: u32,
}

/// The queue's buffer, word-aligned (the queue writes items straight from it).
#[repr(C, align(4))]
struct Aligned<const N: usize>([u8; N]);

/// What one item of the log is.
enum Item {
    Record(u32),
    Ack(u32),
    Other,
}

/// Records of `T` on a NOR flash region, kept until acknowledged (module docs).
/// `BUF`: at least [`EventQueue::buffer_len`].
pub struct EventQueue<F: NorFlash, T, const BUF: usize> {
    queue: QueueStorage<F, NoCache>,
    buf: Aligned<BUF>,
    state: Recovered,
    stats: QueueStats,
    _records: PhantomData<fn() -> T>,
}

impl<F: NorFlash, T, const BUF: usize> fmt::Debug for EventQueue<F, T, BUF> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("EventQueue")
            .field("state", &self.state)
            .field("stats", &self.stats)
            .finish_non_exhaustive()
    }
}

impl<F: NorFlash, T: Checkpoint, const BUF: usize> EventQueue<F, T, BUF> {
    /// The buffer a queue of `T` needs: a record of `T`, rounded up to the flash word.
    #[must_use]
    pub const fn buffer_len() -> usize {
        let word = if F::WRITE_SIZE > F::READ_SIZE {
            F::WRITE_SIZE
        } else {
            F::READ_SIZE
        };
        let word = if word == 0 { 1 } else { word };
        codec::record_len(T::SIZE).div_ceil(word) * word
    }

    /// A queue on `range` of `flash` (whole sectors, at least two). Reads nothing yet:
    /// call [`EventQueue::open`] at start-up.
    pub fn new(flash: F, range: Range<u32>) -> Result<Self, StoreConfigError> {
        let capacity = u32::try_from(flash.capacity()).unwrap_or(u32::MAX);
        if range.end > capacity || range.start > range.end {
            return Err(StoreConfigError::OutOfBounds);
        }
        let sector = u32::try_from(F::ERASE_SIZE).unwrap_or(u32::MAX).max(1);
        if (range.end - range.start) / sector < 2 {
            // One sector: a full region would erase every record to make room.
            return Err(StoreConfigError::TooSmall);
        }
        let config = QueueConfig::<F>::try_new(range).map_err(|e| match e {
            QueueConfigError::StartRangeNotAtPageBoundary
            | QueueConfigError::EndRangeNotAtPageBoundary => StoreConfigError::Unaligned,
            QueueConfigError::RangeTooSmall => StoreConfigError::TooSmall,
            _ => StoreConfigError::Geometry,
        })?;
        if Self::buffer_len() > BUF {
            return Err(StoreConfigError::Geometry);
        }
        Ok(EventQueue {
            queue: QueueStorage::new(flash, config, Cache::new_uncached()),
            buf: Aligned([0; BUF]),
            state: Recovered::default(),
            stats: QueueStats::default(),
            _records: PhantomData,
        })
    }

    /// The flash back (a reset in a test, or to hand it on).
    pub fn into_flash(self) -> F {
        self.queue.destroy().0
    }

    /// Reads the log through at start-up: the acknowledgement, the records not
    /// acknowledged. A region that holds no record of this queue and is not blank, or
    /// that `sequential-storage` cannot read, is erased and reported
    /// ([`Recovered::erased`]): pushing onto garbage could lose the record. `Err` for a
    /// flash driver error.
    pub async fn open(&mut self) -> Result<Recovered, StorageError<F::Error>> {
        let found = match self.scan().await {
            Ok(found) if found.newest.is_some() || found.acknowledged.is_some() => found,
            Ok(found) if self.region_is_blank().await? => found,
            Ok(_) | Err(StorageError::Corrupted) => {
                self.erase().await?;
                Recovered {
                    erased: true,
                    ..Recovered::default()
                }
            }
            Err(e) => return Err(e),
        };
        self.state = found;
        Ok(found)
    }

    /// True if every byte of the region reads 0xFF.
    async fn region_is_blank(&mut self) -> Result<bool, StorageError<F::Error>> {
        let range = self.queue.flash_range();
        let chunk = BUF - BUF % F::READ_SIZE.max(1);
        let buf = self.buf.0.get_mut(..chunk).ok_or(StorageError::Internal)?;
        super::store::read_blank(self.queue.flash(), range, buf).await
    }

    /// What the log holds now (as [`EventQueue::open`] found it, kept up to date).
    #[must_use]
    pub fn state(&self) -> Recovered {
        self.state
    }

    /// The counts since this queue was made.
    #[must_use]
    pub fn stats(&self) -> QueueStats {
        self.stats
    }

    /// The number through which records are acknowledged on flash.
    #[must_use]
    pub fn acknowledged(&self) -> Option<u32> {
        self.state.acknowledged
    }

    /// Unacknowledged records dropped since this queue was made.
    #[must_use]
    pub fn dropped(&self) -> u32 {
        self.stats.dropped
    }

    /// Appends `value` numbered `seq` (after every record held). When the region is
    /// full the oldest sector is erased first: its unacknowledged records are dropped
    /// and counted. The record is on flash when this returns `Ok`.
    pub async fn push(&mut self, seq: u32, value: &T) -> Result<Pushed, StorageError<F::Error>> {
        let len = codec::encode(value, seq, &mut self.buf.0).map_err(StorageError::Codec)?;
        let before = self.state.unacknowledged.saturating_add(1);
        self.append(len).await?;
        self.stats.pushed = self.stats.pushed.saturating_add(1);
        self.state = self.scan().await?;
        Ok(self.count_dropped(before))
    }

    /// Acknowledges every record through `through`: appends an acknowledgement, which
    /// is durable when this returns `Ok(true)`. `Ok(false)`, nothing written, unless
    /// `through` acknowledges a record held: a number from the oldest record not
    /// acknowledged ([`Recovered::first`]) to the newest. A number not yet given (after
    /// the newest), one acknowledged already, and one that modulo 2^32 alone would
    /// pass for either (half the number space away) acknowledge nothing.
    pub async fn acknowledge(&mut self, through: u32) -> Result<bool, StorageError<F::Error>> {
        if !self.acknowledges_a_record(through) {
            return Ok(false);
        }
        // The records left after this acknowledgement, if nothing is erased for it.
        let mut left = 0u32;
        self.each(|item| {
            if let Item::Record(seq) = item {
                left += u32::from(!at_or_after(through, seq));
            }
            true
        })
        .await?;
        let len = codec::encode(&Ack, through, &mut self.buf.0).map_err(StorageError::Codec)?;
        self.append(len).await?;
        self.stats.acknowledgements = self.stats.acknowledgements.saturating_add(1);
        self.state = self.scan().await?;
        self.count_dropped(left);
        Ok(true)
    }

    /// Whether `through` lies from the oldest unacknowledged record to the newest: its
    /// distance back from the newest no more than the oldest's. Every comparison is a
    /// distance back from the newest number given (within the records held), never
    /// two numbers compared modulo 2^32 alone, which reads a number half the number
    /// space ahead as an old one.
    fn acknowledges_a_record(&self, through: u32) -> bool {
        match (self.state.first, self.state.newest) {
            (Some(first), Some(newest)) => {
                newest.wrapping_sub(through) <= newest.wrapping_sub(first)
            }
            _ => false,
        }
    }

    /// Calls `f` with every record not acknowledged whose number is at or after
    /// `from`, oldest first, until `f` returns false. Returns how many it was given.
    /// Records that do not decode are skipped (counted in [`Recovered::skipped`]).
    pub async fn read(
        &mut self,
        from: u32,
        mut f: impl FnMut(u32, T) -> bool,
    ) -> Result<u32, StorageError<F::Error>> {
        let ack = self.state.acknowledged;
        let mut given = 0u32;
        let mut iter = self.queue.iter().await.map_err(StorageError::from_ss)?;
        while let Some(entry) = iter
            .next(&mut self.buf.0)
            .await
            .map_err(StorageError::from_ss)?
        {
            let Ok(d) = codec::decode::<T>(&entry) else {
                continue;
            };
            if acknowledged_by(d.sequence, ack) || !at_or_after(d.sequence, from) {
                continue;
            }
            given = given.saturating_add(1);
            if !f(d.sequence, d.value) {
                break;
            }
        }
        Ok(given)
    }

    /// Erases the whole region: every record and acknowledgement. The remedy for
    /// [`StorageError::Corrupted`].
    pub async fn erase(&mut self) -> Result<(), StorageError<F::Error>> {
        self.queue
            .erase_all()
            .await
            .map_err(StorageError::from_ss)?;
        self.state = Recovered::default();
        Ok(())
    }

    /// The record in the buffer's first `len` bytes onto the log; a full region gives
    /// up its oldest sector.
    async fn append(&mut self, len: usize) -> Result<(), StorageError<F::Error>> {
        let bytes = self.buf.0.get(..len).ok_or(StorageError::Internal)?;
        self.queue
            .push(bytes, true)
            .await
            .map_err(StorageError::from_ss)
    }

    /// Counts the records dropped by an append after which `expected` were to be left
    /// unacknowledged.
    fn count_dropped(&mut self, expected: u32) -> Pushed {
        let dropped = expected.saturating_sub(self.state.unacknowledged);
        self.stats.dropped = self.stats.dropped.saturating_add(dropped);
        Pushed { dropped }
    }

    /// Calls `f` with each item, oldest first, until it returns false.
    async fn each(
        &mut self,
        mut f: impl FnMut(Item) -> bool,
    ) -> Result<(), StorageError<F::Error>> {
        let mut iter = self.queue.iter().await.map_err(StorageError::from_ss)?;
        while let Some(entry) = iter
            .next(&mut self.buf.0)
            .await
            .map_err(StorageError::from_ss)?
        {
            if !f(classify::<T>(&entry)) {
                break;
            }
        }
        Ok(())
    }

    /// The log read through twice: the newest acknowledgement and record first, then
    /// the records after the acknowledgement.
    async fn scan(&mut self) -> Result<Recovered, StorageError<F::Error>> {
        let mut found = Recovered::default();
        self.each(|item| {
            match item {
                Item::Ack(seq) => found.acknowledged = Some(seq),
                Item::Record(seq) => found.newest = Some(seq),
                Item::Other => found.skipped += 1,
            }
            true
        })
        .await?;
        let ack = found.acknowledged;
        self.each(|item| {
            if let Item::Record(seq) = item
                && !acknowledged_by(seq, ack)
            {
                found.first.get_or_insert(seq);
                found.unacknowledged += 1;
            }
            true
        })
        .await?;
        Ok(found)
    }
}

/// An item's kind and number, its CRC checked.
fn classify<T: Checkpoint>(bytes: &[u8]) -> Item {
    if let Ok(d) = codec::decode::<Ack>(bytes) {
        return Item::Ack(d.sequence);
    }
    match codec::decode::<T>(bytes) {
        Ok(d) => Item::Record(d.sequence),
        Err(_) => Item::Other,
    }
}
