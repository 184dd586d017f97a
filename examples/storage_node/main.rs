//! Durable state on the node: the condition monitor's whole state checkpointed to
//! flash while it monitors, through resets and power cuts, in QEMU, through
//! `misalign::storage` exactly as a firmware uses it (a blocking flash driver,
//! `BlockingFlash`, `block_on`, no executor).
//!
//! The node monitors the built-in scenario (`misalign::monitor::scenario`, one sample a
//! second) over the demo scene prepared at build time, with the core the monitoring
//! node uses on that target (f32 with an FPU, fixed point without), and checkpoints
//! the monitor's whole state (`MonitorState`, an 812-byte record) once a minute of
//! samples. The "flash" is 4 KiB of RAM in cortex-m-rt's `.uninit` section: not zeroed
//! at start, not reloaded by QEMU's reset, so it survives the reset as flash would. A
//! control block in `.uninit` carries the test's progress across resets. The image
//! runs many times in one QEMU session:
//!
//! 0. cold boot: the region holds whatever RAM held (zeros in QEMU): the restore must
//!    give nothing and, the region not being blank, a reported event. The node runs
//!    the first 1800 samples (30 min) without a break for the reference; then it
//!    starts afresh with checkpoints (one on demand, one at the interval) and resets
//!    between two checkpoints;
//! 1. after the reset: the restore must give exactly the last checkpoint; the node
//!    goes on from it (the samples after it are replayed, as the scenario stands for
//!    the sensors), checkpoints on demand before a planned reset, and resets;
//! 2. the power-cut phase: on boot `k` the node goes on from the restored state for
//!    one sample and checkpoints, and the flash driver resets the core at the `k`-th
//!    byte written (or word erased) of that checkpoint; after each such reset the
//!    restore must give exactly the last complete checkpoint or the cut one, whole.
//!    The phase ends when a checkpoint completes before its cut point, i.e. when every
//!    point of one has been cut; it must have swept at least a whole record;
//! 3. the node goes on from the last checkpoint to the 1800th sample: its state must
//!    be the reference's, bit for bit, as if the power had never failed.
//!
//! The states are compared by the CRC-32 their records carry. On a real node the samples
//! after the last checkpoint are lost with the power (the monitor then sees a gap);
//! here they are replayed, so that the run can be compared with the reference. The
//! node reports the deepest stack use of its boots.
//!
//! Exit status (semihosting): 0 when every step holds; 10 + step on a wrong restore,
//! 20 + step on a storage error (step: 0 to 3 as above), 30 if the power-cut phase
//! swept less than a record, 31 if the monitor refused its configuration or the scene
//! or the scenario ended, 32 if the final state is not the reference's; 101 on a panic.
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
use misalign_logger as _;
#[cfg(target_os = "none")]
misalign_harness::log_panics_and_faults!();

#[cfg(target_os = "none")]
mod node {
    use core::mem::MaybeUninit;
    use core::ptr::addr_of_mut;

    use embedded_storage::nor_flash::{
        ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash, check_erase,
        check_read, check_write,
    };
    use misalign::Estimator;
    #[cfg(not(target_abi = "eabihf"))]
    use misalign::fixed::FixedEllipticScene;
    #[cfg(target_abi = "eabihf")]
    use misalign::float::EllipticScene;
    use misalign::monitor::scenario::Scenario;
    use misalign::monitor::{Config, Monitor, MonitorState};
    use misalign::storage::{BlockingFlash, Checkpoint, RestoreOutcome, Store, block_on, codec};
    use misalign_harness::prepared;
    use misalign_harness::support::{exit, stack};

    const SECTOR: usize = 1024;
    const SIZE: usize = 4 * SECTOR;
    /// What the control block holds first, so that cold RAM is told apart.
    const MAGIC: u32 = 0x4D53_4C43;
    /// Samples of the whole run (30 min: the start-up inhibit, six trend intervals,
    /// the first spike).
    const FINAL: usize = 1800;
    /// The checkpoint interval (s).
    const INTERVAL_S: u32 = 60;
    /// The cold boot's on-demand checkpoint, after this many samples.
    const ON_DEMAND_AT: usize = 30;
    /// The first reset, after this many samples (14 s after the last checkpoint: an
    /// unplanned one).
    const FIRST_RESET_AT: usize = 75;
    /// The second reset, after this many samples (planned: a checkpoint on demand
    /// first).
    const SECOND_RESET_AT: usize = 90;
    /// Bytes of a monitor state's record.
    const RECORD: usize = codec::record_len(MonitorState::SIZE);
    /// The store's buffer for it.
    const BUF: usize = Store::<BlockingFlash<RamFlash>, 0>::buffer_len::<MonitorState>();

    #[unsafe(link_section = ".uninit.misalign_flash")]
    static mut FLASH: MaybeUninit<[u8; SIZE]> = MaybeUninit::uninit();
    #[unsafe(link_section = ".uninit.misalign_control")]
    static mut CONTROL: MaybeUninit<Control> = MaybeUninit::uninit();

    /// The test's progress, kept across resets.
    #[derive(Clone, Copy)]
    #[repr(C)]
    struct Control {
        magic: u32,
        /// 0: cold boot, 1: after the first reset, 2: the power-cut phase, 3: after it.
        step: u32,
        /// The power-cut phase: where this boot's checkpoint is cut.
        cut: u32,
        /// The newest checkpoint known complete, and its state's CRC.
        committed: u32,
        committed_crc: u32,
        /// The CRC of the state of the checkpoint being written (committed + 1).
        pending_crc: u32,
        /// The CRC of the reference's state after [`FINAL`] samples.
        reference_crc: u32,
        /// Boots of the power-cut phase.
        boots: u32,
        /// The stack pointer where this boot painted the free stack, and the deepest
        /// stack use of any boot (bytes).
        sp: u32,
        stack_max: u32,
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
                // The power fails: no stack use noted (the deepest is the completed
                // checkpoint's, noted at the phase's end).
                cortex_m::peripheral::SCB::sys_reset();
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

    /// Notes this boot's deepest stack use.
    fn note_stack(control: &mut Control) {
        let used = stack::used(control.sp as usize) as u32;
        control.stack_max = control.stack_max.max(used);
    }

    /// A reset (SYSRESETREQ), after noting this boot's stack use.
    fn reset(control: &mut Control) -> ! {
        note_stack(control);
        cortex_m::peripheral::SCB::sys_reset()
    }

    /// A store on the `.uninit` flash, with a cut armed or not.
    fn open(
        bytes: &'static mut [u8; SIZE],
        cut: Option<u32>,
    ) -> Store<BlockingFlash<RamFlash>, BUF> {
        let flash = RamFlash {
            bytes,
            points: 0,
            cut,
        };
        match Store::new(BlockingFlash(flash), 0..SIZE as u32, INTERVAL_S) {
            Ok(store) => store,
            Err(_) => exit(20),
        }
    }

    /// The CRC-32 that a state's record carries (the record numbered 0, so that equal
    /// states have equal CRCs).
    #[inline(never)]
    fn crc_of(state: &MonitorState) -> u32 {
        let mut record = [0u8; RECORD];
        let Ok(n) = codec::encode(state, 0, &mut record) else {
            exit(20)
        };
        let crc = record
            .get(n.wrapping_sub(4)..n)
            .and_then(|b| b.try_into().ok());
        crc.map_or(0, u32::from_le_bytes)
    }

    /// The scenario's samples from the `done`-th on.
    fn samples_from(done: usize) -> impl Iterator<Item = misalign::monitor::Sample> {
        Scenario::new().skip(done)
    }

    /// Samples a monitor has processed (each of the scenario's is processed once).
    fn done<E: Estimator>(m: &Monitor<E>) -> usize {
        m.statistics().samples() as usize
    }

    /// Feeds samples to `m` until it has processed `until`, checkpointing at the
    /// interval of scenario time (and on demand after [`ON_DEMAND_AT`] samples); each
    /// checkpoint written is recorded as committed.
    fn run_to<E: Estimator>(
        m: &mut Monitor<E>,
        until: usize,
        store: &mut Store<BlockingFlash<RamFlash>, BUF>,
        control: &mut Control,
    ) {
        let code = control.step as i32;
        for sample in samples_from(done(m)) {
            if done(m) >= until {
                break;
            }
            m.process(sample);
            if done(m) == ON_DEMAND_AT && control.step == 0 {
                checkpoint_now(m, store, control);
                continue;
            }
            let state = m.snapshot();
            match block_on(store.checkpoint_if_due(m.elapsed_ms() / 1000, &state)) {
                Ok(Some(sequence)) => {
                    (control.committed, control.committed_crc) = (sequence, crc_of(&state));
                }
                Ok(None) => {}
                Err(_) => exit(20 + code),
            }
        }
        if done(m) != until {
            exit(31)
        }
    }

    /// Exits unless the restore of a boot after the cold one gave the committed
    /// checkpoint or, in the power-cut phase, the cut one whole, into `state`.
    fn check_restore(outcome: RestoreOutcome, state: &MonitorState, control: &mut Control) {
        let code = control.step as i32;
        let RestoreOutcome::Restored { sequence } = outcome else {
            exit(10 + code)
        };
        let crc = crc_of(state);
        let committed = sequence == control.committed && crc == control.committed_crc;
        let pending = control.step == 2
            && sequence == control.committed.wrapping_add(1)
            && crc == control.pending_crc;
        if !(committed || pending) {
            exit(10 + code);
        }
        (control.committed, control.committed_crc) = (sequence, crc);
    }

    /// The CRC of the state of `m` after the first [`FINAL`] samples without a break.
    #[inline(never)]
    fn reference<E: Estimator>(mut m: Monitor<E>) -> u32 {
        for sample in samples_from(0).take(FINAL) {
            m.process(sample);
        }
        crc_of(&m.snapshot())
    }

    /// A fresh monitor over the core `core` builds.
    fn monitor<E: Estimator>(core: &impl Fn() -> Option<E>) -> Monitor<E> {
        let Some(core) = core() else { exit(31) };
        Monitor::new(core, Config::default()).unwrap_or_else(|_| exit(31))
    }

    /// A checkpoint of the state of `m` now, on demand; its CRC is noted as pending
    /// while it is written, and as committed once it is complete.
    fn checkpoint_now<E: Estimator>(
        m: &Monitor<E>,
        store: &mut Store<BlockingFlash<RamFlash>, BUF>,
        control: &mut Control,
    ) {
        let state = m.snapshot();
        control.pending_crc = crc_of(&state);
        let Ok(sequence) = block_on(store.checkpoint(&state)) else {
            exit(20 + control.step as i32)
        };
        (control.committed, control.committed_crc) = (sequence, control.pending_crc);
    }

    /// The cold boot: the reference, then the monitor from scratch with checkpoints
    /// until the first reset.
    #[inline(never)]
    fn cold<E: Estimator>(
        core: &impl Fn() -> Option<E>,
        m: &mut Monitor<E>,
        store: &mut Store<BlockingFlash<RamFlash>, BUF>,
        control: &mut Control,
    ) -> ! {
        control.reference_crc = reference(monitor(core));
        run_to(m, FIRST_RESET_AT, store, control);
        control.step = 1;
        reset(control)
    }

    /// After the first reset: on from the restored state, with checkpoints, and one on
    /// demand before the (planned) reset to the power-cut phase.
    #[inline(never)]
    fn after_reset<E: Estimator>(
        m: &mut Monitor<E>,
        store: &mut Store<BlockingFlash<RamFlash>, BUF>,
        control: &mut Control,
    ) -> ! {
        run_to(m, SECOND_RESET_AT, store, control);
        checkpoint_now(m, store, control);
        (control.step, control.cut, control.boots) = (2, 0, 0);
        reset(control)
    }

    /// A boot of the power-cut phase: on from the restored state for one sample and a
    /// checkpoint, cut at this boot's point (a reset). A checkpoint that completes
    /// before its cut point ends the phase: every point of one has been cut.
    #[inline(never)]
    fn power_cut<E: Estimator>(
        m: &mut Monitor<E>,
        store: &mut Store<BlockingFlash<RamFlash>, BUF>,
        control: &mut Control,
    ) -> ! {
        let Some(sample) = samples_from(done(m)).next() else {
            exit(31)
        };
        m.process(sample);
        checkpoint_now(m, store, control);
        // This boot's cut point was `control.cut - 1`.
        if (control.cut as usize) <= RECORD {
            exit(30);
        }
        control.step = 3;
        reset(control)
    }

    /// After the power cuts: on from the last checkpoint to the end, which must be the
    /// reference's state.
    #[inline(never)]
    fn finish<E: Estimator>(
        m: &mut Monitor<E>,
        store: &mut Store<BlockingFlash<RamFlash>, BUF>,
        control: &mut Control,
    ) -> ! {
        run_to(m, FINAL, store, control);
        if crc_of(&m.snapshot()) != control.reference_crc {
            exit(32);
        }
        note_stack(control);
        defmt::println!(
            "storage node: {=usize} samples monitored through 3 resets and {=u32} power cuts (one at every point of a checkpoint of the {=usize}-byte record), {=u32} checkpoints; the state is the uninterrupted run's; deepest stack {=u32} bytes",
            FINAL,
            control.boots - 1,
            RECORD,
            control.committed,
            control.stack_max
        );
        // Cold start next time QEMU runs this image.
        control.magic = 0;
        exit(0)
    }

    /// The node's whole test with the core `core` builds: one step per boot.
    fn node<E: Estimator>(
        core: impl Fn() -> Option<E>,
        flash: &'static mut [u8; SIZE],
        control: &mut Control,
    ) -> ! {
        let step = control.step;
        let code = step as i32;
        // In the power-cut phase this boot's checkpoint is cut at the next point (the
        // restore before it only reads).
        let cut = control.cut;
        if step == 2 {
            control.cut = cut + 1;
            control.boots += 1;
        }
        let mut store = open(flash, (step == 2).then_some(cut));
        // As a node restores: one monitor and one state, decoded in place.
        let mut m = monitor(&core);
        let mut state = MonitorState::default();
        let Ok(outcome) = block_on(store.restore_into(&mut state)) else {
            exit(20 + code)
        };
        if step == 0 {
            // Cold RAM is not a blank flash: nothing restored, an event reported.
            if !matches!(outcome, RestoreOutcome::Rejected(_)) || store.stats().rejected != 1 {
                exit(10 + code);
            }
            cold(&core, &mut m, &mut store, control)
        }
        check_restore(outcome, &state, control);
        m.resume(&state);
        match step {
            1 => after_reset(&mut m, &mut store, control),
            2 => power_cut(&mut m, &mut store, control),
            _ => finish(&mut m, &mut store, control),
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
        let sp = stack::paint();
        if control.magic != MAGIC {
            *control = Control {
                magic: MAGIC,
                step: 0,
                cut: 0,
                committed: 0,
                committed_crc: 0,
                pending_crc: 0,
                reference_crc: 0,
                boots: 0,
                sp: 0,
                stack_max: 0,
            };
        }
        control.sp = sp as u32;
        // The demo scene prepared at build time (the monitor's model for the
        // scenario's range, the ellipse), loaded as the monitoring node loads it.
        #[cfg(target_abi = "eabihf")]
        let core = || EllipticScene::from_bytes(&prepared::ELLIPTIC).ok();
        #[cfg(not(target_abi = "eabihf"))]
        let core = || FixedEllipticScene::from_bytes(&prepared::FIXED_ELLIPTIC).ok();
        node(core, flash, control)
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
