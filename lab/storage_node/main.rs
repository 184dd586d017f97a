//! Durable state on the node: the condition monitor's whole state checkpointed to
//! flash while it monitors, through resets and power cuts, in QEMU, through
//! `misalign::storage` exactly as a firmware uses it (a blocking flash driver,
//! `BlockingFlash`, `block_on`, no executor).
//!
//! The node monitors the built-in scenario (`misalign::monitor::scenario`, one sample a
//! second) over the demo scene prepared at build time, with the core the monitoring
//! node uses on that target (f32 with an FPU, fixed point without), and checkpoints
//! the monitor's whole state (`MonitorState`, an 812-byte record) once a minute of
//! samples and at each event it raises; each event goes first to the flash event queue
//! (`EventQueue`, 2 KiB of its own), which every boot reads back: exactly the events
//! stored and not acknowledged (a master acknowledges every one after the first reset;
//! none may come back). The "flash" is 4 KiB of RAM in cortex-m-rt's `.uninit`
//! section: not zeroed at start, not reloaded by QEMU's reset, so it survives the
//! reset as flash would. A
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
//! 20 + step on a storage error (step: 0 to 3 as above), 40 + step on a wrong event
//! queue (or none stored before the first reset), 30 if the power-cut phase
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
#[path = "../../nodes/common/ram_flash.rs"]
mod ram_flash;

#[cfg(target_os = "none")]
mod node {
    use core::mem::MaybeUninit;
    use core::ptr::addr_of_mut;

    use super::ram_flash::{RamFlash, SECTOR};
    use misalign::Estimator;
    #[cfg(not(target_abi = "eabihf"))]
    use misalign::fixed::FixedEllipticScene;
    #[cfg(target_abi = "eabihf")]
    use misalign::float::EllipticScene;
    use misalign::monitor::scenario::Scenario;
    use misalign::monitor::{Config, Event, Monitor, MonitorState};
    use misalign::storage::{
        BlockingFlash, Checkpoint, EventQueue, RestoreOutcome, Store, block_on, codec,
    };
    use misalign_harness::prepared;
    use misalign_harness::support::{exit, stack};

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
    /// The event queue's region: two sectors.
    const EVENTS_SIZE: usize = 2 * SECTOR;
    /// The event queue's buffer.
    const EVENT_BUF: usize = EventQueue::<BlockingFlash<RamFlash>, Event, 0>::buffer_len();
    type Events = EventQueue<BlockingFlash<RamFlash>, Event, EVENT_BUF>;

    #[unsafe(link_section = ".uninit.misalign_flash")]
    static mut FLASH: MaybeUninit<[u8; SIZE]> = MaybeUninit::uninit();
    #[unsafe(link_section = ".uninit.misalign_events")]
    static mut EVENTS: MaybeUninit<[u8; EVENTS_SIZE]> = MaybeUninit::uninit();
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
        /// Events stored on flash (the next one's number), and the acknowledgement on
        /// flash plus one (0: none).
        events: u32,
        acked: u32,
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
        match Store::new(
            BlockingFlash(RamFlash::new(bytes, cut)),
            0..SIZE as u32,
            INTERVAL_S,
        ) {
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
        events: &mut Events,
        control: &mut Control,
    ) {
        let code = control.step as i32;
        for sample in samples_from(done(m)) {
            if done(m) >= until {
                break;
            }
            m.process(sample);
            if store_events(m, events, control) || (done(m) == ON_DEMAND_AT && control.step == 0) {
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

    /// The monitor's new events onto the flash queue (a sample replayed after a reset
    /// raises again the events already stored: skipped). True if the sample raised an
    /// event: the state is checkpointed at each.
    fn store_events<E: Estimator>(
        m: &mut Monitor<E>,
        events: &mut Events,
        control: &mut Control,
    ) -> bool {
        let mut raised = false;
        while let Some(e) = m.pop_event() {
            raised = true;
            if e.seq < control.events {
                continue;
            }
            match block_on(events.push(e.seq, &e)) {
                Ok(pushed) if pushed.dropped == 0 && e.seq == control.events => {}
                _ => exit(40 + control.step as i32),
            }
            control.events = e.seq + 1;
        }
        raised
    }

    /// Exits unless the event queue holds exactly the events stored and not
    /// acknowledged, in order: none lost, none acknowledged back.
    fn check_events(events: &mut Events, control: &Control) {
        let code = 40 + control.step as i32;
        let Ok(found) = block_on(events.open()) else {
            exit(code)
        };
        let acked = control.acked.checked_sub(1);
        let newest = control.events.checked_sub(1);
        let first = newest
            .map(|_| control.acked)
            .filter(|&f| f < control.events);
        let unacked = control.events - control.acked;
        let expected = (acked, newest, first, unacked);
        if (
            found.acknowledged,
            found.newest,
            found.first,
            found.unacknowledged,
        ) != expected
        {
            exit(code);
        }
        let mut next = control.acked;
        let read = block_on(events.read(0, |seq, e| {
            let ok = seq == next && e.seq == seq;
            next += 1;
            ok
        }));
        if read != Ok(unacked) || next != control.events {
            exit(code);
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
            // Delivered, as the node delivers each to its event queue.
            while m.pop_event().is_some() {}
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
        events: &mut Events,
        control: &mut Control,
    ) -> ! {
        control.reference_crc = reference(monitor(core));
        run_to(m, FIRST_RESET_AT, store, events, control);
        control.step = 1;
        reset(control)
    }

    /// After the first reset: on from the restored state, with checkpoints, and one on
    /// demand before the (planned) reset to the power-cut phase.
    #[inline(never)]
    fn after_reset<E: Estimator>(
        m: &mut Monitor<E>,
        store: &mut Store<BlockingFlash<RamFlash>, BUF>,
        events: &mut Events,
        control: &mut Control,
    ) -> ! {
        run_to(m, SECOND_RESET_AT, store, events, control);
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
        events: &mut Events,
        control: &mut Control,
    ) -> ! {
        let Some(sample) = samples_from(done(m)).next() else {
            exit(31)
        };
        m.process(sample);
        store_events(m, events, control);
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
        events: &mut Events,
        control: &mut Control,
    ) -> ! {
        run_to(m, FINAL, store, events, control);
        if crc_of(&m.snapshot()) != control.reference_crc {
            exit(32);
        }
        note_stack(control);
        defmt::println!(
            "storage node: {=usize} samples monitored through 3 resets and {=u32} power cuts (one at every point of a checkpoint of the {=usize}-byte record), {=u32} checkpoints (once a minute and at each event); the state is the uninterrupted run's; events kept on flash, read back at every boot, none back once acknowledged: {=u32}; deepest stack {=u32} bytes",
            FINAL,
            control.boots - 1,
            RECORD,
            control.committed,
            control.events,
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
        events_flash: &'static mut [u8; EVENTS_SIZE],
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
        let events_flash = RamFlash::new(events_flash, None);
        let Ok(mut events) = Events::new(BlockingFlash(events_flash), 0..EVENTS_SIZE as u32) else {
            exit(40 + code)
        };
        // As a node restores: one monitor and one state, decoded in place.
        let mut m = monitor(&core);
        let mut state = MonitorState::default();
        let Ok(outcome) = block_on(store.restore_into(&mut state)) else {
            exit(20 + code)
        };
        if step == 0 {
            // Cold RAM is not a blank flash: nothing restored, an event reported; the
            // event queue's region erased and reported.
            if !matches!(outcome, RestoreOutcome::Rejected(_)) || store.stats().rejected != 1 {
                exit(10 + code);
            }
            if !block_on(events.open()).is_ok_and(|found| found.erased) {
                exit(40 + code);
            }
            cold(&core, &mut m, &mut store, &mut events, control)
        }
        check_restore(outcome, &state, control);
        check_events(&mut events, control);
        if step == 1 {
            // A master acknowledges every event stored before the first reset (there
            // is one: the start): from here on each boot must find it acknowledged.
            let Some(newest) = control.events.checked_sub(1) else {
                exit(40 + code)
            };
            if block_on(events.acknowledge(newest)) != Ok(true) {
                exit(40 + code);
            }
            control.acked = newest + 1;
        }
        m.resume(&state);
        match step {
            1 => after_reset(&mut m, &mut store, &mut events, control),
            2 => power_cut(&mut m, &mut store, &mut events, control),
            _ => finish(&mut m, &mut store, &mut events, control),
        }
    }

    #[cortex_m_rt::entry]
    fn main() -> ! {
        // SAFETY: the only references to the three statics, taken once at start-up;
        // u8 and u32 hold any bit pattern, and the RAM is initialised memory on the
        // target (what the previous boot left, or the power-on contents).
        let (flash, events, control) = unsafe {
            (
                &mut *addr_of_mut!(FLASH).cast::<[u8; SIZE]>(),
                &mut *addr_of_mut!(EVENTS).cast::<[u8; EVENTS_SIZE]>(),
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
                events: 0,
                acked: 0,
            };
        }
        control.sp = sp as u32;
        // The demo scene prepared at build time (the monitor's model for the
        // scenario's range, the ellipse), loaded as the monitoring node loads it.
        #[cfg(target_abi = "eabihf")]
        let core = || EllipticScene::from_bytes(&prepared::ELLIPTIC).ok();
        #[cfg(not(target_abi = "eabihf"))]
        let core = || FixedEllipticScene::from_bytes(&prepared::FIXED_ELLIPTIC).ok();
        node(core, flash, events, control)
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
