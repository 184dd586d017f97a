//! The node's two storage regions on the Pico's own QSPI flash (`persist.rs` keeps its
//! state, committed configuration and events there), through embassy-rp's blocking
//! flash driver (the boot ROM's erase and program routines, run with interrupts
//! masked), in the regions memory.x reserves at the end of the flash, outside the
//! program's.

use embassy_rp::flash::{Blocking, ERASE_SIZE, Flash};
use embassy_rp::peripherals::FLASH;
use embedded_storage::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash, check_erase, check_read,
    check_write,
};

/// The erase unit (bytes): a 4 KiB sector.
pub const SECTOR: usize = ERASE_SIZE;
/// The store's region (the state's and the configuration's records): memory.x's STORE.
pub const STORE_SIZE: usize = 4 * SECTOR;
/// The event queue's region: memory.x's EVENTS.
pub const EVENTS_SIZE: usize = 2 * SECTOR;
/// The Pico's flash (W25Q16JV, 2 MiB).
const FLASH_SIZE: usize = 2 * 1024 * 1024;
/// The flash's address in the memory map (XIP).
const XIP_BASE: usize = 0x1000_0000;

/// One region of the flash, as NOR flash from offset 0.
pub struct Board {
    flash: Flash<'static, FLASH, Blocking, FLASH_SIZE>,
    start: u32,
    len: usize,
}

/// A refused access (out of the region, unaligned) or the driver's error.
#[derive(Debug)]
pub struct Refused(NorFlashErrorKind);

impl NorFlashError for Refused {
    fn kind(&self) -> NorFlashErrorKind {
        self.0
    }
}

impl From<embassy_rp::flash::Error> for Refused {
    fn from(e: embassy_rp::flash::Error) -> Self {
        Refused(e.kind())
    }
}

impl ErrorType for Board {
    type Error = Refused;
}

impl ReadNorFlash for Board {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Refused> {
        check_read(self, offset, bytes.len()).map_err(Refused)?;
        Ok(self.flash.blocking_read(self.start + offset, bytes)?)
    }

    fn capacity(&self) -> usize {
        self.len
    }
}

impl NorFlash for Board {
    const WRITE_SIZE: usize = 4;
    const ERASE_SIZE: usize = SECTOR;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), Refused> {
        check_erase(self, from, to).map_err(Refused)?;
        Ok(self
            .flash
            .blocking_erase(self.start + from, self.start + to)?)
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Refused> {
        check_write(self, offset, bytes.len()).map_err(Refused)?;
        Ok(self.flash.blocking_write(self.start + offset, bytes)?)
    }
}

/// The store's region and the event queue's; taken once per boot
/// (`Persist::open`). `None` if memory.x does not reserve them as these sizes.
pub fn regions() -> Option<(Board, Board)> {
    unsafe extern "C" {
        // The regions' bounds, from memory.x (only their addresses are taken).
        static __misalign_store_start: u8;
        static __misalign_store_end: u8;
        static __misalign_events_start: u8;
        static __misalign_events_end: u8;
    }
    let store = (&raw const __misalign_store_start) as usize;
    let store_end = (&raw const __misalign_store_end) as usize;
    let events = (&raw const __misalign_events_start) as usize;
    let events_end = (&raw const __misalign_events_end) as usize;
    if store_end - store != STORE_SIZE || events_end - events != EVENTS_SIZE {
        defmt::error!("storage: the memory layout's flash regions are not the node's");
        return None;
    }
    let region = |start: usize, len: usize| Board {
        // SAFETY: the blocking driver holds no state of its own (each call goes to
        // the boot ROM with interrupts masked), so the two regions' drivers never
        // disturb each other; this runs once per boot, and nothing else in the node
        // takes the flash.
        flash: Flash::new_blocking(unsafe { FLASH::steal() }),
        start: (start - XIP_BASE) as u32,
        len,
    };
    Some((region(store, STORE_SIZE), region(events, EVENTS_SIZE)))
}
