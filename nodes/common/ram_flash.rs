//! NOR flash over RAM that survives a system reset, for the Cortex-M examples in QEMU
//! (the storage node, the Modbus node with `sequential-storage`): a region of
//! cortex-m-rt's `.uninit` section is not zeroed at start and not reloaded by QEMU's
//! reset, so it keeps what was written across a reset as flash would. Erase sets
//! 0xFF, writes only clear bits. With a cut armed, the driver resets the core at the
//! `cut`-th point, a byte written or a word erased (the ones before it done, that one
//! and the rest not): a power cut at that point; with the feature `_power-cut` a cut
//! can also be armed at run time ([`armed`]). Included by `#[path]` from each example.

use embedded_storage::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash, check_erase, check_read,
    check_write,
};

/// The erase unit (bytes).
pub const SECTOR: usize = 1024;

/// NOR flash over `bytes`, with a power cut armed or not.
pub struct RamFlash {
    bytes: &'static mut [u8],
    points: u32,
    cut: Option<u32>,
}

impl RamFlash {
    /// The flash over `bytes`, cut at point `cut` if any.
    pub fn new(bytes: &'static mut [u8], cut: Option<u32>) -> Self {
        RamFlash {
            bytes,
            points: 0,
            cut,
        }
    }

    fn tick(&mut self) {
        if self.cut == Some(self.points) {
            cortex_m::peripheral::SCB::sys_reset();
        }
        #[cfg(feature = "_power-cut")]
        if armed::due() {
            cortex_m::peripheral::SCB::sys_reset();
        }
        self.points += 1;
    }
}

/// A power cut armed at run time, for every flash driver of the image (`RamFlash`,
/// `NvmcFlash`; feature `_power-cut`, test builds only): [`arm`](armed::arm) before an
/// operation, [`disarm`](armed::disarm) after it.
#[cfg(feature = "_power-cut")]
pub mod armed {
    use core::sync::atomic::{AtomicU32, Ordering::Relaxed};

    /// Points until the cut, the cut's included; 0: none armed.
    static LEFT: AtomicU32 = AtomicU32::new(0);

    /// The power cut after `done` more points: those done, the next not.
    pub fn arm(done: u32) {
        LEFT.store(done.saturating_add(1), Relaxed);
    }

    pub fn disarm() {
        LEFT.store(0, Relaxed);
    }

    /// One point passed: whether it is the armed cut (the flash driver then resets
    /// the core, after what a cut there leaves: `RamFlash` nothing, `NvmcFlash` the
    /// part of a word or a page done).
    pub fn due() -> bool {
        match LEFT.load(Relaxed) {
            0 => false,
            1 => true,
            n => {
                LEFT.store(n - 1, Relaxed);
                false
            }
        }
    }
}

/// An access out of bounds or unaligned.
#[derive(Debug, PartialEq)]
pub struct Refused(NorFlashErrorKind);

impl NorFlashError for Refused {
    fn kind(&self) -> NorFlashErrorKind {
        self.0
    }
}

impl ErrorType for RamFlash {
    type Error = Refused;
}

impl ReadNorFlash for RamFlash {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Refused> {
        check_read(self, offset, bytes.len()).map_err(Refused)?;
        let at = offset as usize;
        bytes.copy_from_slice(&self.bytes[at..at + bytes.len()]);
        Ok(())
    }

    fn capacity(&self) -> usize {
        self.bytes.len()
    }
}

impl NorFlash for RamFlash {
    const WRITE_SIZE: usize = 4;
    const ERASE_SIZE: usize = SECTOR;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), Refused> {
        check_erase(self, from, to).map_err(Refused)?;
        for word in (from as usize..to as usize).step_by(Self::WRITE_SIZE) {
            self.tick();
            self.bytes[word..word + Self::WRITE_SIZE].fill(0xFF);
        }
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Refused> {
        check_write(self, offset, bytes.len()).map_err(Refused)?;
        for (i, &b) in bytes.iter().enumerate() {
            self.tick();
            self.bytes[offset as usize + i] &= b;
        }
        Ok(())
    }
}
