//! Durable state on the node (issue 13, item 4): a checkpoint, a reset, a restore, in
//! QEMU, through `misalign::storage` exactly as a firmware uses it (a blocking flash
//! driver, `BlockingFlash`, `block_on`, no executor).
//!
//! The "flash" is 4 KiB of RAM in cortex-m-rt's `.uninit` section: not zeroed at start,
//! not reloaded by QEMU's reset, so it survives the reset as flash would. A second
//! `.uninit` word counts the boots. The image runs three times in one QEMU session:
//!
//! 1. cold boot: the region holds whatever RAM held (zeros in QEMU): the restore
//!    must give nothing and, the region not being blank, a reported event; then two
//!    checkpoints (at the interval, and one on demand) and a reset (SYSRESETREQ);
//! 2. after the reset: the restore must give exactly the second checkpoint; one more
//!    checkpoint, a reset;
//! 3. the restore must give the third; exit 0.
//!
//! Exit status (semihosting): 0 when every step holds, 10 + boot on a wrong restore,
//! 20 + boot on a storage error, 101 on a panic.
//!
//! ```sh
//! cargo run --release --target thumbv7em-none-eabihf \
//!     --features firmware,sequential-storage --example storage_node
//! cargo run --release --target thumbv6m-none-eabi \
//!     --features firmware,sequential-storage --example storage_node
//! ```
//!
//! On the host it builds as a stub, so that `cargo build --all-features` keeps working.
#![cfg_attr(target_os = "none", no_std)]
#![cfg_attr(target_os = "none", no_main)]

#[cfg(target_os = "none")]
mod node {
    use core::mem::MaybeUninit;
    use core::ptr::addr_of_mut;

    use embedded_storage::nor_flash::{
        ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash, check_erase,
        check_read, check_write,
    };
    use misalign::storage::{
        BlockingFlash, Checkpoint, CodecError, Reader, RestoreOutcome, Store, Writer, block_on,
    };

    const SECTOR: usize = 1024;
    const SIZE: usize = 4 * SECTOR;
    /// What the boot counter holds beside its count, so that cold RAM is told apart.
    const BOOT_MAGIC: u32 = 0x4D53_4C42;

    #[unsafe(link_section = ".uninit.misalign_flash")]
    static mut FLASH: MaybeUninit<[u8; SIZE]> = MaybeUninit::uninit();
    #[unsafe(link_section = ".uninit.misalign_boots")]
    static mut BOOTS: MaybeUninit<[u32; 2]> = MaybeUninit::uninit();

    /// NOR flash over the `.uninit` RAM: erase to 0xFF, writes only clear bits.
    struct RamFlash(&'static mut [u8; SIZE]);

    #[derive(Debug, PartialEq)]
    struct Refused(NorFlashErrorKind);

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
            bytes.copy_from_slice(&self.0[at..at + bytes.len()]);
            Ok(())
        }

        fn capacity(&self) -> usize {
            SIZE
        }
    }

    impl NorFlash for RamFlash {
        const WRITE_SIZE: usize = 4;
        const ERASE_SIZE: usize = SECTOR;

        fn erase(&mut self, from: u32, to: u32) -> Result<(), Refused> {
            check_erase(self, from, to).map_err(Refused)?;
            self.0[from as usize..to as usize].fill(0xFF);
            Ok(())
        }

        fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Refused> {
            check_write(self, offset, bytes.len()).map_err(Refused)?;
            let at = offset as usize;
            for (cell, &b) in self.0[at..at + bytes.len()].iter_mut().zip(bytes) {
                *cell &= b;
            }
            Ok(())
        }
    }

    /// A monitor-like state: energies per state, counters.
    #[derive(Debug, PartialEq)]
    struct Wear {
        energy_j: [f64; 3],
        samples: u32,
    }

    impl Checkpoint for Wear {
        const KIND: u8 = misalign::storage::kind::MONITOR_STATE;
        const VERSION: u16 = 1;
        const SIZE: usize = 3 * 8 + 4;

        fn encode(&self, w: &mut Writer<'_>) -> Result<(), CodecError> {
            w.each(&self.energy_j, |w, e| w.f64(*e))?;
            w.u32(self.samples)
        }

        fn decode(r: &mut Reader<'_>) -> Result<Self, CodecError> {
            Ok(Wear {
                energy_j: r.array_of(|r| r.f64())?,
                samples: r.u32()?,
            })
        }
    }

    fn wear(n: u32) -> Wear {
        let k = f64::from(n);
        Wear {
            energy_j: [k * 1.25, k * k, 1e3 / (k + 1.0)],
            samples: n * 1000,
        }
    }

    fn exit(code: i32) -> ! {
        semihosting::process::exit(code)
    }

    fn reset() -> ! {
        cortex_m::peripheral::SCB::sys_reset()
    }

    #[cortex_m_rt::entry]
    fn main() -> ! {
        // SAFETY: the only references to the two statics, taken once at start-up;
        // u8 and u32 hold any bit pattern, and the RAM is initialised memory on the
        // target (what the previous boot left, or the power-on contents).
        let (flash, boots) = unsafe {
            (
                &mut *addr_of_mut!(FLASH).cast::<[u8; SIZE]>(),
                &mut *addr_of_mut!(BOOTS).cast::<[u32; 2]>(),
            )
        };
        let boot = if boots[0] == BOOT_MAGIC { boots[1] } else { 0 };
        *boots = [BOOT_MAGIC, boot + 1];
        let code = boot as i32;

        let Ok(mut store) = Store::<_, 64>::new(BlockingFlash(RamFlash(flash)), 0..SIZE as u32, 60)
        else {
            exit(20 + code)
        };
        let Ok(restored) = block_on(store.restore::<Wear>()) else {
            exit(20 + code)
        };
        match boot {
            0 => {
                // Cold RAM is not a blank flash: nothing restored, an event reported.
                if restored.value.is_some()
                    || !matches!(restored.outcome, RestoreOutcome::Rejected(_))
                    || store.stats().rejected != 1
                {
                    exit(10 + code);
                }
                // At the interval (the first call starts it), then on demand.
                let due = block_on(store.checkpoint_if_due(0, &wear(1)))
                    .and_then(|_| block_on(store.checkpoint_if_due(60, &wear(1))));
                if due != Ok(Some(1)) || block_on(store.checkpoint(&wear(2))) != Ok(2) {
                    exit(20 + code);
                }
                reset()
            }
            1 => {
                if restored.value != Some(wear(2))
                    || restored.outcome != (RestoreOutcome::Restored { sequence: 2 })
                {
                    exit(10 + code);
                }
                if block_on(store.checkpoint(&wear(3))) != Ok(3) {
                    exit(20 + code);
                }
                reset()
            }
            _ => {
                if restored.value != Some(wear(3))
                    || restored.outcome != (RestoreOutcome::Restored { sequence: 3 })
                {
                    exit(10 + code);
                }
                // Cold start next time QEMU runs this image.
                *boots = [0, 0];
                exit(0)
            }
        }
    }

    #[panic_handler]
    fn panic(_: &core::panic::PanicInfo) -> ! {
        exit(101)
    }
}

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!(
        "the storage node runs on a Cortex-M: cargo run --release --target \
         thumbv7em-none-eabihf --features firmware,sequential-storage --example storage_node"
    );
    std::process::exit(2);
}
