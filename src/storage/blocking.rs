//! Running the store on bare metal without an async executor.
//!
//! `sequential-storage`'s API is async; most flash HALs are blocking
//! (`embedded-storage`'s `NorFlash`). Two pieces bridge that:
//!
//! - [`BlockingFlash`] wraps a blocking flash driver into the async
//!   `embedded-storage-async` traits the store needs (each operation completes in
//!   its first poll);
//! - [`block_on`] (`embassy-futures`' busy-polling executor, `no_std`, no heap, no
//!   critical section, builds for thumbv6m and thumbv7em) runs one store call to its
//!   end from ordinary blocking firmware code:
//!
//! ```ignore
//! use misalign::storage::{block_on, endurance, BlockingFlash, Store};
//! let region = 0x3_0000..0x3_8000; // eight 4 KiB sectors
//! let flash = BlockingFlash(hal_flash);
//! let mut store = Store::<_, 1024>::new(flash, region, endurance::DEFAULT_INTERVAL_S)?;
//! let restored = block_on(store.restore::<MonitorState>())?;
//! // ... in the sampling loop:
//! block_on(store.checkpoint_if_due(now_s, &state))?;
//! ```
//!
//! With a blocking flash underneath, `block_on` polls each future once: no busy wait.
//! A firmware with an executor (embassy) awaits the store's futures instead and uses
//! its HAL's async flash directly.

pub use embassy_futures::block_on;

use embedded_storage::nor_flash as blocking;
use embedded_storage_async::nor_flash as nb;

/// A blocking `embedded-storage` flash driver seen through the async
/// `embedded-storage-async` traits, for [`Store`](super::Store).
#[derive(Debug, Clone, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BlockingFlash<F>(pub F);

impl<F: blocking::ErrorType> nb::ErrorType for BlockingFlash<F> {
    type Error = F::Error;
}

impl<F: blocking::ReadNorFlash> nb::ReadNorFlash for BlockingFlash<F> {
    const READ_SIZE: usize = F::READ_SIZE;

    async fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        self.0.read(offset, bytes)
    }

    fn capacity(&self) -> usize {
        self.0.capacity()
    }
}

impl<F: blocking::NorFlash> nb::NorFlash for BlockingFlash<F> {
    const WRITE_SIZE: usize = F::WRITE_SIZE;
    const ERASE_SIZE: usize = F::ERASE_SIZE;

    async fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        self.0.erase(from, to)
    }

    async fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        self.0.write(offset, bytes)
    }
}
