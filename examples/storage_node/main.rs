//! Durable state on the node: a checkpoint, a reset, a restore, in
//! QEMU, through `misalign::storage` exactly as a firmware uses it (a blocking flash
//! driver, `BlockingFlash`, `block_on`, no executor).
//!
//! The "flash" is 4 KiB of RAM in cortex-m-rt's `.uninit` section: not zeroed at start,
//! not reloaded by QEMU's reset, so it survives the reset as flash would. A control
//! block in `.uninit` carries the test's progress across resets. The image runs many
//! times in one QEMU session:
//!
//! 1. cold boot: the region holds whatever RAM held (zeros in QEMU): the restore
//!    must give nothing and, the region not being blank, a reported event; then two
//!    checkpoints (at the interval, and one on demand) and a reset (SYSRESETREQ);
//! 2. after the reset: the restore must give exactly the second checkpoint; one more
//!    checkpoint, a reset;
//! 3. then the power cut on the target: on boot `k` of this phase the flash driver
//!    resets the core at the `k`-th byte written (or word erased) of a checkpoint, so
//!    that the checkpoint is cut there; after each such reset the restore must give
//!    exactly the last complete checkpoint or the cut one, whole. The phase ends when a
//!    checkpoint completes before its cut point, i.e. when every byte of one has been
//!    cut; it must have swept at least a whole record.
//!
//! Exit status (semihosting): 0 when every step holds; 10 + step on a wrong restore
//! (step: 0 cold, 1 after the first reset, 2 in the power-cut phase), 20 + step on a
//! storage error, 30 if the power-cut phase swept less than a record; 101 on a panic.
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
    /// What the control block holds first, so that cold RAM is told apart.
    const MAGIC: u32 = 0x4D53_4C42;

    #[unsafe(link_section = ".uninit.misalign_flash")]
    static mut FLASH: MaybeUninit<[u8; SIZE]> = MaybeUninit::uninit();
    #[unsafe(link_section = ".uninit.misalign_control")]
    static mut CONTROL: MaybeUninit<Control> = MaybeUninit::uninit();

    /// The test's progress, kept across resets.
    #[derive(Clone, Copy)]
    #[repr(C)]
    struct Control {
        magic: u32,
        /// 0: cold boot, 1: after the first reset, 2: the power-cut phase.
        step: u32,
        /// The power-cut phase: where this boot's checkpoint is cut.
        cut: u32,
        /// The newest checkpoint known complete.
        committed: u32,
    }

    /// NOR flash over the `.uninit` RAM: erase to 0xFF, writes only clear bits. With a
    /// cut armed, it resets the core at the `cut`-th point: a byte written or a word
    /// erased (the bytes and words before it done, that one and the rest not).
    struct RamFlash {
        bytes: &'static mut [u8; SIZE],
        points: u32,
        cut: Option<u32>,
    }

    impl RamFlash {
        fn tick(&mut self) {
            if self.cut == Some(self.points) {
                reset();
            }
            self.points += 1;
        }
    }

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
            bytes.copy_from_slice(&self.bytes[at..at + bytes.len()]);
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

    /// A store on the `.uninit` flash, with a cut armed or not.
    fn open(
        bytes: &'static mut [u8; SIZE],
        cut: Option<u32>,
    ) -> Store<BlockingFlash<RamFlash>, 64> {
        let flash = RamFlash {
            bytes,
            points: 0,
            cut,
        };
        match Store::new(BlockingFlash(flash), 0..SIZE as u32, 60) {
            Ok(store) => store,
            Err(_) => exit(20),
        }
    }

    #[cortex_m_rt::entry]
    fn main() -> ! {
        // SAFETY: the only references to the two statics, taken once at start-up;
        // u8 and u32 hold any bit pattern, and the RAM is initialised memory on the
        // target (what the previous boot left, or the power-on contents).
        let (flash, control) = unsafe {
            (
                &mut *addr_of_mut!(FLASH).cast::<[u8; SIZE]>(),
                &mut *addr_of_mut!(CONTROL).cast::<Control>(),
            )
        };
        if control.magic != MAGIC {
            *control = Control {
                magic: MAGIC,
                step: 0,
                cut: 0,
                committed: 0,
            };
        }
        let step = control.step;
        let code = step as i32;
        // In the power-cut phase this boot's checkpoint is cut at the next point (the
        // restore before it only reads).
        let cut = control.cut;
        if step == 2 {
            control.cut = cut + 1;
        }
        let mut store = open(flash, (step == 2).then_some(cut));
        let Ok(restored) = block_on(store.restore::<Wear>()) else {
            exit(20 + code)
        };
        match step {
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
                control.step = 1;
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
                *control = Control {
                    step: 2,
                    cut: 0,
                    committed: 3,
                    ..*control
                };
                reset()
            }
            _ => {
                // After a cut: the last complete checkpoint or the cut one, whole.
                let RestoreOutcome::Restored { sequence } = restored.outcome else {
                    exit(10 + code)
                };
                let committed = control.committed;
                if !(sequence == committed || sequence == committed + 1)
                    || restored.value != Some(wear(sequence))
                {
                    exit(10 + code);
                }
                control.committed = sequence;
                if block_on(store.checkpoint(&wear(sequence + 1))) != Ok(sequence + 1) {
                    exit(20 + code);
                }
                // It completed before its cut point: every byte has been cut.
                let mut store = open(store.into_flash().0.bytes, None);
                let Ok(last) = block_on(store.restore::<Wear>()) else {
                    exit(20 + code)
                };
                if last.value != Some(wear(sequence + 1)) {
                    exit(10 + code);
                }
                if (cut as usize) < misalign::storage::codec::record_len(Wear::SIZE) {
                    exit(30);
                }
                // Cold start next time QEMU runs this image.
                control.magic = 0;
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
