//! Flash wear of a [`Store`](super::Store): erase cycles per sector per year, from the
//! record size, the flash geometry and the checkpoint interval.
//!
//! The store appends each checkpoint to the open sector; a sector is erased only when
//! the map needs it again, after every other sector has been filled in turn. So with
//! `k` checkpoints fitting in a sector and `s` sectors, each sector is erased once
//! every `k * s` checkpoints, and
//!
//! ```text
//! cycles per sector per year = ceil(checkpoints per year / (k * s))
//! k = floor((sector - 2 * word) / (round_up(8, word) + round_up(1 + record, word)))
//! ```
//!
//! (`sequential-storage`'s map: two marker words per sector; per item an 8-byte header
//! and the key byte, each padded to the flash word; `record` is
//! [`record_len`] of the payload.) The storage test
//! `wear_matches_the_mock_flash` checks this against the erase counts of the mock
//! flash. A kind written rarely (calibration) adds one item per turn of the ring, a
//! negligible share.

use super::codec::record_len;

/// Seconds in a year (365.25 days).
pub const SECONDS_PER_YEAR: u64 = 31_557_600;

/// The default checkpoint interval, seconds: one hour. What a brown-out can lose at
/// most is this much accumulation (the restored checkpoint is never older); checkpoint
/// on demand as well at every risk-state change, so that events are not lost.
pub const DEFAULT_INTERVAL_S: u32 = 3600;

/// The endurance the docs assume: 10 000 erase cycles per sector (typical of MCU
/// internal flash; serial NOR parts are usually rated 100 000).
pub const RATED_CYCLES: u32 = 10_000;

/// Flash geometry and record size, for the wear arithmetic.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Geometry {
    /// Payload bytes of the record ([`Checkpoint::SIZE`](super::Checkpoint::SIZE)).
    pub payload: usize,
    /// Sector (erase unit) bytes.
    pub sector: usize,
    /// Sectors in the store's region.
    pub sectors: usize,
    /// Flash word (write unit) bytes.
    pub word: usize,
}

/// The geometry of the figures in the docs: a 792-byte payload (the condition
/// monitor's whole state, events and trend included: `MonitorState`'s
/// `Checkpoint::SIZE`, version 1, held equal by `tests/monitor_storage.rs`) in
/// eight 4 KiB sectors (a 32 KiB region) of 4-byte words. Recompute with your type's
/// [`Checkpoint::SIZE`](super::Checkpoint::SIZE) and your region.
pub const REFERENCE: Geometry = Geometry {
    payload: 792,
    sector: 4096,
    sectors: 8,
    word: 4,
};

const fn round_up(n: usize, word: usize) -> usize {
    if word == 0 {
        n
    } else {
        n.div_ceil(word) * word
    }
}

impl Geometry {
    /// Flash bytes one checkpoint takes, with the map's item header and padding.
    #[must_use]
    pub const fn item_bytes(&self) -> usize {
        round_up(8, self.word) + round_up(1 + record_len(self.payload), self.word)
    }

    /// Checkpoints that fit in one sector (0 if not one does).
    #[must_use]
    pub const fn checkpoints_per_sector(&self) -> usize {
        let usable = self.sector.saturating_sub(2 * self.word);
        usable / self.item_bytes()
    }

    /// Checkpoints between two erases of the same sector.
    #[must_use]
    pub const fn checkpoints_per_cycle(&self) -> u64 {
        (self.checkpoints_per_sector() * self.sectors) as u64
    }

    /// Erase cycles each sector takes in a year at one checkpoint every `interval_s`
    /// seconds (rounded up; `u64::MAX` if a checkpoint does not fit or the interval is
    /// zero).
    #[must_use]
    pub const fn cycles_per_year(&self, interval_s: u32) -> u64 {
        let per_cycle = self.checkpoints_per_cycle();
        if per_cycle == 0 || interval_s == 0 {
            return u64::MAX;
        }
        let checkpoints = SECONDS_PER_YEAR / interval_s as u64;
        checkpoints.div_ceil(per_cycle)
    }

    /// Years until the sectors reach `rated` erase cycles at this interval.
    #[must_use]
    pub const fn years_to(&self, rated: u32, interval_s: u32) -> u64 {
        let per_year = self.cycles_per_year(interval_s);
        if per_year == 0 {
            return u64::MAX;
        }
        rated as u64 / per_year
    }

    /// The shortest interval, seconds, that keeps the sectors within `rated` cycles for
    /// `years` years (`u32::MAX` if no interval does: a checkpoint does not fit).
    #[must_use]
    pub const fn min_interval_s(&self, rated: u32, years: u32) -> u32 {
        let per_cycle = self.checkpoints_per_cycle();
        if per_cycle == 0 || rated == 0 {
            return u32::MAX;
        }
        // interval >= seconds(years) / (rated * per_cycle)
        let budget = rated as u64 * per_cycle;
        let s = (SECONDS_PER_YEAR * years as u64).div_ceil(budget);
        if s > u32::MAX as u64 {
            u32::MAX
        } else {
            s as u32
        }
    }
}
