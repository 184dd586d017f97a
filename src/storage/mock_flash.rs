//! A NOR flash in RAM with power-loss injection, for tests (feature `_mock-flash`,
//! semver-exempt).
//!
//! It behaves as NOR flash does: erase sets a whole sector to 0xFF; a write only
//! clears bits (a write that would set a 0 bit back to 1 is refused with
//! [`MockError::ZeroToOne`], so a store that rewrites a word is caught); reads,
//! writes and erases outside the flash or off the word grid are refused.
//!
//! Power loss is injected at a *point*: every byte a write programs is one point,
//! every word an erase clears is one point, counted from the flash's making
//! ([`MockFlash::points`]). [`MockFlash::cut_after`]`(n)` makes the power fail at the
//! `n`-th point from now: a write stops at that byte (the bytes before it programmed,
//! that byte half programmed, the rest untouched); an erase stops at that word (the
//! words before it erased, that word garbage, the rest of the sector as it was). The
//! failing call returns [`MockError::PowerLoss`] and every call after it
//! [`MockError::PoweredOff`], until [`MockFlash::restart`]. Sweeping `n` over every
//! point an operation consumes visits every way the power can fail during it, as
//! littlefs's test runner does.

use core::fmt;

use embedded_storage::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash, check_erase, check_read,
    check_write,
};

/// Why the mock flash refused an operation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum MockError {
    /// Outside the flash.
    OutOfBounds,
    /// Not on the word (write) or sector (erase) grid.
    NotAligned,
    /// The write would set a 0 bit back to 1 at this address: a write to a word
    /// that was not erased.
    ZeroToOne {
        /// The first offending address.
        offset: u32,
    },
    /// The power failed during this operation (injected).
    PowerLoss,
    /// The power failed earlier; [`MockFlash::restart`] first.
    PoweredOff,
}

impl fmt::Display for MockError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MockError::OutOfBounds => f.write_str("outside the flash"),
            MockError::NotAligned => f.write_str("not on the word or sector grid"),
            MockError::ZeroToOne { offset } => {
                write!(f, "write to a word not erased (0 bit to 1 at {offset:#x})")
            }
            MockError::PowerLoss => f.write_str("power lost during the operation"),
            MockError::PoweredOff => f.write_str("powered off: restart first"),
        }
    }
}

impl core::error::Error for MockError {}

impl NorFlashError for MockError {
    fn kind(&self) -> NorFlashErrorKind {
        match self {
            MockError::OutOfBounds => NorFlashErrorKind::OutOfBounds,
            MockError::NotAligned => NorFlashErrorKind::NotAligned,
            _ => NorFlashErrorKind::Other,
        }
    }
}

fn kind_to_error(kind: NorFlashErrorKind) -> MockError {
    match kind {
        NorFlashErrorKind::NotAligned => MockError::NotAligned,
        _ => MockError::OutOfBounds,
    }
}

/// `SECTORS` sectors of `SECTOR` bytes, written in words of `WORD` bytes; all erased
/// (0xFF) when made. Implements the blocking `embedded-storage` NOR flash traits;
/// wrap it in [`BlockingFlash`](super::BlockingFlash) for a [`Store`](super::Store).
#[derive(Debug, Clone, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MockFlash<const SECTORS: usize, const SECTOR: usize, const WORD: usize> {
    sectors: [[u8; SECTOR]; SECTORS],
    erases: [u32; SECTORS],
    points: u64,
    cut_at: Option<u64>,
    off: bool,
}

impl<const SECTORS: usize, const SECTOR: usize, const WORD: usize> Default
    for MockFlash<SECTORS, SECTOR, WORD>
{
    fn default() -> Self {
        Self::new()
    }
}

impl<const SECTORS: usize, const SECTOR: usize, const WORD: usize>
    MockFlash<SECTORS, SECTOR, WORD>
{
    /// An erased flash (every byte 0xFF), powered, with no cut armed.
    #[must_use]
    pub fn new() -> Self {
        MockFlash {
            sectors: [[0xFF; SECTOR]; SECTORS],
            erases: [0; SECTORS],
            points: 0,
            cut_at: None,
            off: false,
        }
    }

    /// The power-loss points consumed since the flash was made (bytes written plus
    /// words erased).
    #[must_use]
    pub fn points(&self) -> u64 {
        self.points
    }

    /// Arms a power loss at the `n`-th point from now (0: the very next byte written
    /// or word erased).
    pub fn cut_after(&mut self, n: u64) {
        self.cut_at = Some(self.points.saturating_add(n));
    }

    /// Powers the flash up again after a loss, and disarms any cut not yet reached.
    pub fn restart(&mut self) {
        self.off = false;
        self.cut_at = None;
    }

    /// True after an injected power loss, until [`MockFlash::restart`].
    #[must_use]
    pub fn is_off(&self) -> bool {
        self.off
    }

    /// How many times each sector was erased (fully or not).
    #[must_use]
    pub fn erase_counts(&self) -> &[u32; SECTORS] {
        &self.erases
    }

    /// Sector `index`'s bytes, to inspect or to damage (e.g. garbage in a sector).
    pub fn sector_mut(&mut self, index: usize) -> Option<&mut [u8; SECTOR]> {
        self.sectors.get_mut(index)
    }

    /// Sector `index`'s bytes.
    #[must_use]
    pub fn sector(&self, index: usize) -> Option<&[u8; SECTOR]> {
        self.sectors.get(index)
    }

    /// Consumes one point; true if the power fails at it.
    fn tick(&mut self) -> bool {
        let cut = self.cut_at == Some(self.points);
        self.points = self.points.saturating_add(1);
        if cut {
            self.off = true;
            self.cut_at = None;
        }
        cut
    }

    /// A byte that looks like what a cut leaves: fixed by the point, so reruns agree.
    fn garbage(&self) -> u8 {
        let mut x = self.points.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0x5851_F42D_4C95_7F2D;
        x ^= x >> 29;
        x = x.wrapping_mul(0xBF58_476D_1CE4_E5B9);
        x ^= x >> 32;
        x.to_le_bytes()[0]
    }

    fn byte_mut(&mut self, offset: usize) -> Result<&mut u8, MockError> {
        self.sectors
            .get_mut(offset / SECTOR)
            .and_then(|s| s.get_mut(offset % SECTOR))
            .ok_or(MockError::OutOfBounds)
    }

    fn byte(&self, offset: usize) -> Result<u8, MockError> {
        self.sectors
            .get(offset / SECTOR)
            .and_then(|s| s.get(offset % SECTOR))
            .copied()
            .ok_or(MockError::OutOfBounds)
    }

    fn powered(&self) -> Result<(), MockError> {
        if self.off {
            Err(MockError::PoweredOff)
        } else {
            Ok(())
        }
    }
}

impl<const SECTORS: usize, const SECTOR: usize, const WORD: usize> ErrorType
    for MockFlash<SECTORS, SECTOR, WORD>
{
    type Error = MockError;
}

impl<const SECTORS: usize, const SECTOR: usize, const WORD: usize> ReadNorFlash
    for MockFlash<SECTORS, SECTOR, WORD>
{
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        self.powered()?;
        check_read(self, offset, bytes.len()).map_err(kind_to_error)?;
        for (i, b) in bytes.iter_mut().enumerate() {
            *b = self.byte(offset as usize + i)?;
        }
        Ok(())
    }

    fn capacity(&self) -> usize {
        SECTORS * SECTOR
    }
}

impl<const SECTORS: usize, const SECTOR: usize, const WORD: usize> NorFlash
    for MockFlash<SECTORS, SECTOR, WORD>
{
    const WRITE_SIZE: usize = WORD;
    const ERASE_SIZE: usize = SECTOR;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        self.powered()?;
        check_erase(self, from, to).map_err(kind_to_error)?;
        let (from, to) = (from as usize, to as usize);
        for sector in from / SECTOR..to / SECTOR {
            if let Some(count) = self.erases.get_mut(sector) {
                *count = count.saturating_add(1);
            }
            for word in (sector * SECTOR..(sector + 1) * SECTOR).step_by(WORD.max(1)) {
                let cut = self.tick();
                let garbage = self.garbage();
                for offset in word..word + WORD.max(1) {
                    let byte = self.byte_mut(offset)?;
                    // A word caught mid-erase: some bits already 1, the others as before.
                    *byte = if cut { *byte | garbage } else { 0xFF };
                }
                if cut {
                    return Err(MockError::PowerLoss);
                }
            }
        }
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        self.powered()?;
        check_write(self, offset, bytes.len()).map_err(kind_to_error)?;
        let offset = offset as usize;
        for (i, &new) in bytes.iter().enumerate() {
            let old = self.byte(offset + i)?;
            if new & !old != 0 {
                return Err(MockError::ZeroToOne {
                    offset: u32::try_from(offset + i).unwrap_or(u32::MAX),
                });
            }
        }
        for (i, &new) in bytes.iter().enumerate() {
            let cut = self.tick();
            let garbage = self.garbage();
            let byte = self.byte_mut(offset + i)?;
            // A byte caught mid-program: some of its cleared bits cleared, not all.
            *byte &= if cut { new | garbage } else { new };
            if cut {
                return Err(MockError::PowerLoss);
            }
        }
        Ok(())
    }
}
