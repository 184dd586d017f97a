//! NOR flash over the nRF51's non-volatile memory controller (NVMC), for the Cortex-M0
//! examples on the micro:bit (the nRF51822, and QEMU's `microbit`, which models the
//! NVMC: hw/nvram/nrf51_nvm.c). The flash is read where it is mapped; a word is
//! written by an ordinary word store while CONFIG enables writes, and a 1 KiB page is
//! erased by writing its address to ERASEPAGE while CONFIG enables erases. A write
//! only clears bits (QEMU 7.2 ANDs the stored word into the flash word, as the part
//! does); the driver stores whole words only, as the part requires.
//! The regions this driver owns are reserved in the board's memory layout
//! (`lab/harness/boards/microbit.x`), so that no program can be linked over them; they
//! survive a system reset (`SCB::sys_reset` and QEMU's monitor `system_reset` both
//! keep the flash outside the loaded image).
//!
//! With the feature `_power-cut` a cut armed at run time (`ram_flash::armed`, shared
//! with the RAM flash) resets the core at its point, a byte written or a word erased,
//! as `RamFlash` does: the bytes (words) before it done, that one and the rest not.
//! Included by `#[path]`; the accesses to the NVMC's registers and to the flash are
//! the only `unsafe` here.

use embedded_storage::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash, check_erase, check_read,
    check_write,
};

/// The erase unit: one page of the nRF51 (bytes).
pub const PAGE: usize = 1024;

/// The NVMC's registers (nRF51 Series Reference Manual, NVMC).
const NVMC: usize = 0x4001_E000;
/// Bit 0: 1 when the controller is ready for the next write or erase.
const READY: usize = NVMC + 0x400;
/// 0: read only, 1: writes enabled, 2: erases enabled.
const CONFIG: usize = NVMC + 0x504;
/// A page's address written here erases it (while CONFIG is 2).
const ERASEPAGE: usize = NVMC + 0x508;
const CONFIG_READ: u32 = 0;
const CONFIG_WRITE: u32 = 1;
const CONFIG_ERASE: u32 = 2;

/// NOR flash over the pages `base..base + len` of the nRF51's flash.
pub struct NvmcFlash {
    base: usize,
    len: usize,
}

impl NvmcFlash {
    /// The driver over `base..base + len`, or `None` unless both are whole pages.
    ///
    /// # Safety
    /// The range is flash of this nRF51 that nothing else uses: no code or data of the
    /// program (the memory layout reserves it) and no other `NvmcFlash`.
    pub unsafe fn new(base: usize, len: usize) -> Option<Self> {
        (base.is_multiple_of(PAGE) && len.is_multiple_of(PAGE)).then_some(NvmcFlash { base, len })
    }

    /// Whether every word reads 0. QEMU starts its flash with zeros outside the image,
    /// where a new part's flash comes erased; a region sequential-storage wrote never
    /// reads all zeros (a header of zeros fails its length's checksum).
    pub fn reads_all_zeros(&self) -> bool {
        (0..self.len).step_by(4).all(|at| self.word(at) == 0)
    }

    /// Every page erased, without power-cut points: the region made ready on a first
    /// power-on.
    pub fn erase_all(&mut self) {
        for page in (0..self.len).step_by(PAGE) {
            self.erase_page(page);
        }
    }

    fn word(&self, at: usize) -> u32 {
        // SAFETY: `at` is a word inside the region (`new`'s contract).
        unsafe { read_word(self.base + at) }
    }

    fn program(&mut self, at: usize, value: u32) {
        // SAFETY: `at` is a word inside the region (`new`'s contract).
        unsafe { program(self.base + at, value) }
    }

    fn erase_page(&mut self, page: usize) {
        // SAFETY: `page` is the offset of a page inside the region (`new`'s contract).
        unsafe { erase_page(self.base + page) }
    }

    /// A power cut at the `word`-th word of erasing `page` (feature `_power-cut`): the
    /// words before it erased, the rest as they were, then the reset. The NVMC erases a
    /// whole page at once, so the page's words from `word` on are kept meanwhile in a
    /// scratch page of flash that the memory layout reserves for test builds
    /// (`__misalign_scratch_start`; the node's RAM has no free KiB for them).
    #[cfg(feature = "_power-cut")]
    #[cold]
    #[inline(never)]
    fn cut_erase(&mut self, page: usize, word: usize) -> ! {
        unsafe extern "C" {
            // From lab/harness/boards/microbit.x; only its address is taken.
            static __misalign_scratch_start: u8;
        }
        let scratch = (&raw const __misalign_scratch_start) as usize;
        if word > 0 {
            // SAFETY: the scratch page is flash of this part that the layout reserves
            // for this use alone; `page` is a page of the region.
            unsafe {
                erase_page(scratch);
                for at in (4 * word..PAGE).step_by(4) {
                    program(scratch + at, self.word(page + at));
                }
                erase_page(self.base + page);
                for at in (4 * word..PAGE).step_by(4) {
                    program(self.base + page + at, read_word(scratch + at));
                }
            }
        }
        cortex_m::peripheral::SCB::sys_reset()
    }
}

/// The flash word at `addr`, read where the flash is mapped; volatile, since the NVMC
/// changes it behind the compiler's back.
///
/// # Safety
/// `addr` is a word of this nRF51's flash.
unsafe fn read_word(addr: usize) -> u32 {
    // SAFETY: the caller's.
    unsafe { core::ptr::read_volatile(addr as *const u32) }
}

/// `value` ANDed into the flash word at `addr` (the NVMC clears bits only): writes
/// enabled, the word stored, read-only restored, each step once READY.
///
/// # Safety
/// `addr` is a word of this nRF51's flash that no code or data of the program uses.
unsafe fn program(addr: usize, value: u32) {
    // SAFETY: the caller's; the NVMC's registers are at their documented addresses on
    // every nRF51.
    unsafe {
        configure(CONFIG_WRITE);
        core::ptr::write_volatile(addr as *mut u32, value);
        wait_ready();
        configure(CONFIG_READ);
    }
}

/// The flash page at `addr` erased (every byte 0xFF).
///
/// # Safety
/// As [`program`], `addr` the first byte of a page.
unsafe fn erase_page(addr: usize) {
    // SAFETY: as `program`.
    unsafe {
        configure(CONFIG_ERASE);
        core::ptr::write_volatile(ERASEPAGE as *mut u32, addr as u32);
        wait_ready();
        configure(CONFIG_READ);
    }
}

/// CONFIG set, once the controller is ready.
///
/// # Safety
/// Only on an nRF51 (the NVMC's addresses).
unsafe fn configure(mode: u32) {
    // SAFETY: the caller's; CONFIG is a plain read-write register.
    unsafe {
        wait_ready();
        core::ptr::write_volatile(CONFIG as *mut u32, mode);
    }
}

/// # Safety
/// Only on an nRF51 (the NVMC's addresses).
unsafe fn wait_ready() {
    // SAFETY: the caller's; READY is a read-only register.
    while unsafe { core::ptr::read_volatile(READY as *const u32) } & 1 == 0 {}
}

/// An access out of bounds or unaligned.
#[derive(Debug, PartialEq)]
pub struct Refused(NorFlashErrorKind);

impl NorFlashError for Refused {
    fn kind(&self) -> NorFlashErrorKind {
        self.0
    }
}

impl ErrorType for NvmcFlash {
    type Error = Refused;
}

impl ReadNorFlash for NvmcFlash {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Refused> {
        check_read(self, offset, bytes.len()).map_err(Refused)?;
        for (i, b) in bytes.iter_mut().enumerate() {
            // SAFETY: a byte inside the region (checked above), mapped flash; volatile,
            // as `read_word`.
            *b =
                unsafe { core::ptr::read_volatile((self.base + offset as usize + i) as *const u8) };
        }
        Ok(())
    }

    fn capacity(&self) -> usize {
        self.len
    }
}

impl NorFlash for NvmcFlash {
    const WRITE_SIZE: usize = 4;
    const ERASE_SIZE: usize = PAGE;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), Refused> {
        check_erase(self, from, to).map_err(Refused)?;
        for page in (from as usize..to as usize).step_by(PAGE) {
            #[cfg(feature = "_power-cut")]
            if let Some(word) = (0..PAGE / 4).find(|_| crate::ram_flash::armed::due()) {
                self.cut_erase(page, word);
            }
            self.erase_page(page);
        }
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Refused> {
        check_write(self, offset, bytes.len()).map_err(Refused)?;
        for (k, chunk) in bytes.chunks_exact(Self::WRITE_SIZE).enumerate() {
            let at = offset as usize + k * Self::WRITE_SIZE;
            // Bytes not yet written stay 0xFF: ANDed, they leave the flash as it is.
            let mut word = [0xFF; 4];
            for (i, &b) in chunk.iter().enumerate() {
                #[cfg(feature = "_power-cut")]
                if crate::ram_flash::armed::due() {
                    // The power cut at this byte: the ones before it written.
                    self.program(at, u32::from_le_bytes(word));
                    cortex_m::peripheral::SCB::sys_reset();
                }
                word[i] = b;
            }
            self.program(at, u32::from_le_bytes(word));
        }
        Ok(())
    }
}
