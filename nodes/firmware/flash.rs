//! The Modbus node's two flash regions (feature `modbus-flash`, `persist.rs`) on the
//! board the image is built for. On the Cortex-M0 (thumbv6m, told apart as the one
//! target without compare-and-swap) the micro:bit's flash through the nRF51's NVMC
//! (`nodes/common/nvmc_flash.rs`), in the regions its memory layout reserves at the
//! end of the flash (`lab/harness/boards/microbit.x`, whose symbols give their bounds);
//! another Cortex-M0 board needs its own driver here and its layout's regions. On the
//! MPS2 boards (Cortex-M3, M4F, M7) RAM in cortex-m-rt's `.uninit`, kept across a
//! system reset (`nodes/common/ram_flash.rs`, shared with the storage node).

#[cfg(not(target_has_atomic = "ptr"))]
pub use crate::nvmc_flash::{NvmcFlash as Board, PAGE as SECTOR};
#[cfg(target_has_atomic = "ptr")]
pub use crate::ram_flash::{RamFlash as Board, SECTOR};

/// The store's region (the state's and the configuration's records).
pub const STORE_SIZE: usize = 4 * SECTOR;
/// The event queue's region.
pub const EVENTS_SIZE: usize = 2 * SECTOR;

/// The store's region and the event queue's, erased on the first power-on; taken once
/// per boot (`Persist::open`). `None` if the memory layout does not reserve them as
/// these sizes.
#[cfg(not(target_has_atomic = "ptr"))]
pub fn regions() -> Option<(Board, Board)> {
    unsafe extern "C" {
        // The regions' bounds, from lab/harness/boards/microbit.x (only their addresses
        // are taken).
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
    // SAFETY: the micro:bit's memory layout reserves both ranges in its flash, outside
    // the FLASH region the program is linked into, and this runs once per boot.
    let (mut store, mut events) = unsafe {
        (
            Board::new(store, STORE_SIZE)?,
            Board::new(events, EVENTS_SIZE)?,
        )
    };
    for region in [&mut store, &mut events] {
        if region.reads_all_zeros() {
            region.erase_all();
        }
    }
    Some((store, events))
}

/// The store's region and the event queue's, erased on the first power-on; taken once
/// per boot (`Persist::open`).
#[cfg(target_has_atomic = "ptr")]
pub fn regions() -> Option<(Board, Board)> {
    use core::mem::MaybeUninit;
    use core::ptr::addr_of_mut;

    #[unsafe(link_section = ".uninit.misalign_node_store")]
    static mut STORE: MaybeUninit<[u8; STORE_SIZE]> = MaybeUninit::uninit();
    #[unsafe(link_section = ".uninit.misalign_node_events")]
    static mut EVENTS: MaybeUninit<[u8; EVENTS_SIZE]> = MaybeUninit::uninit();
    /// [`ERASED`] once the two regions were erased at the first power-on: QEMU starts
    /// with RAM of zeros, where a new part's flash comes erased.
    #[unsafe(link_section = ".uninit.misalign_node_erased")]
    static mut FIRST_POWER_ON: MaybeUninit<u32> = MaybeUninit::uninit();
    const ERASED: u32 = 0x4552_4153;

    // SAFETY: the only references to the two statics, taken once per boot (`node`
    // calls `Persist::open` once, before its loop); u8 holds any bit pattern, and the
    // RAM is initialised memory on the target (what the previous boot left, or the
    // power-on contents).
    let (store, events) = unsafe {
        (
            &mut *addr_of_mut!(STORE).cast::<[u8; STORE_SIZE]>(),
            &mut *addr_of_mut!(EVENTS).cast::<[u8; EVENTS_SIZE]>(),
        )
    };
    // SAFETY: a u32 of RAM, kept across a reset, any bit pattern valid; read and
    // written volatile, as memory the compiler cannot know (what the last boot left).
    let marker = addr_of_mut!(FIRST_POWER_ON).cast::<u32>();
    if unsafe { marker.read_volatile() } != ERASED {
        store.fill(0xFF);
        events.fill(0xFF);
        // SAFETY: as above.
        unsafe { marker.write_volatile(ERASED) };
    }
    Some((Board::new(store, None), Board::new(events, None)))
}
