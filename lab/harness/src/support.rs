//! What the firmware example, the on-target tests and the benchmark image share: exit
//! through semihosting, what their panic and HardFault handlers do
//! ([`log_panics_and_faults!`](crate::log_panics_and_faults) defines them), stack
//! painting and an instruction counter. They log through defmt; the logger is the
//! crate `misalign-logger` (`lab/harness/logger`), which each of them links itself.

use core::sync::atomic::{AtomicBool, Ordering};

// The runtime (vector table, reset) and the critical section of the loggers
// (cortex-m's single-core implementation), linked even where nothing names them.
use cortex_m as _;
use cortex_m_rt as _;

/// Exit status of a panic (as Rust's test harness).
pub const PANIC: i32 = 101;
/// Exit status of a HardFault (a bad memory access, a stack overflow into a fault).
pub const HARD_FAULT: i32 = 102;

/// A decimal count as a compile-time setting gives it (`option_env!`), in a `const`:
/// the images' sample counts. Digits only (anything else is not checked).
pub const fn parse_count(s: &str) -> usize {
    let b = s.as_bytes();
    let mut i = 0;
    let mut n = 0;
    while i < b.len() {
        n = n * 10 + (b[i] - b'0') as usize;
        i += 1;
    }
    n
}

/// Ends the program: semihosting exit with `code` (0 success), after the log is out.
pub fn exit(code: i32) -> ! {
    defmt::flush();
    semihosting::process::exit(code)
}

/// Logs a panic (once: a panic while logging it does not recurse) and exits with
/// [`PANIC`].
pub fn log_panic(info: &core::panic::PanicInfo) -> ! {
    static PANICKING: AtomicBool = AtomicBool::new(false);
    // (Load and store, not swap: the Cortex-M0 has no atomic read-modify-write;
    // single core.)
    if !PANICKING.load(Ordering::Relaxed) {
        PANICKING.store(true, Ordering::Relaxed);
        match info.location() {
            Some(at) => defmt::error!(
                "panicked at {=str}:{=u32}: {}",
                at.file(),
                at.line(),
                defmt::Display2Format(&info.message())
            ),
            None => defmt::error!("panicked: {}", defmt::Display2Format(&info.message())),
        }
    }
    exit(PANIC)
}

/// Logs a HardFault's pc and exits with [`HARD_FAULT`].
pub fn log_hard_fault(frame: &cortex_m_rt::ExceptionFrame) -> ! {
    defmt::error!("HardFault at pc {=u32:#010x}", frame.pc());
    exit(HARD_FAULT)
}

/// Stack painting: fill the free stack with a pattern, run something, and see how deep
/// the pattern was overwritten.
pub mod stack {
    /// The pattern (cortex-m-rt's `paint-stack` uses the same value).
    const PAINT: u32 = 0xcccc_cccc;

    unsafe extern "C" {
        /// Lowest address of the stack (end of .bss/.uninit), from cortex-m-rt's link.x.
        static _stack_end: u32;
        /// The stack's top (the RAM's end), from cortex-m-rt's link.x.
        static _stack_start: u32;
    }

    /// The stack's top: [`used`]`(top())` is the deepest stack use since the last
    /// [`paint`], the frames above its caller's included.
    #[inline(always)]
    pub fn top() -> usize {
        (&raw const _stack_start) as usize
    }

    /// The stack pointer of the function this is inlined into.
    #[inline(always)]
    pub fn pointer() -> usize {
        let sp: usize;
        // SAFETY: reads a register, touches no memory.
        unsafe {
            core::arch::asm!("mov {}, sp", out(reg) sp, options(nomem, nostack, preserves_flags))
        };
        sp
    }

    /// Paints the stack below the caller's stack pointer, which it returns.
    ///
    /// Inlined into the caller, whose frame is complete after its prologue, so that
    /// what is painted is exactly what the caller's callees may use. No interrupt
    /// may run until [`used`] (the firmware images enable none).
    #[inline(always)]
    pub fn paint() -> usize {
        let sp = pointer();
        let mut p = (&raw const _stack_end) as usize;
        while p < sp {
            // SAFETY: [_stack_end, sp) is the free part of the stack: no live object
            // is there, and this loop keeps its state in registers.
            unsafe { core::ptr::write_volatile(p as *mut u32, PAINT) };
            p += 4;
        }
        sp
    }

    /// Bytes below `sp` (from [`paint`], in the same caller) written since it
    /// painted: the deepest stack use of the calls in between. Inlined, so that it
    /// scans from the caller's frame without a frame of its own.
    #[inline(always)]
    pub fn used(sp: usize) -> usize {
        let mut p = (&raw const _stack_end) as usize;
        // SAFETY: reads the painted region [_stack_end, sp), which no live object uses.
        while p < sp && unsafe { core::ptr::read_volatile(p as *const u32) } == PAINT {
            p += 4;
        }
        sp - p
    }
}

/// Instructions counted by SysTick. Under QEMU with `-icount shift=6` (as
/// `lab/qemu-run` runs it) every instruction advances virtual time by 64 ns, so
/// SysTick ticks at a fixed ratio per instruction; [`Counter::new`] measures that ratio
/// on a loop of known length. On real hardware SysTick counts clock cycles and the
/// calibration loop takes more than one cycle per instruction, so the counts are only
/// indicative there (use the DWT cycle counter on hardware; it reads 0 in QEMU).
pub mod counter {
    use cortex_m::peripheral::SYST;
    pub use cortex_m::peripheral::syst::SystClkSource;

    const RELOAD: u32 = 0x00ff_ffff;

    /// Instructions of a series of measurements: how many, their sum and maximum.
    #[derive(Clone, Copy, Default)]
    pub struct Stats {
        /// Measurements.
        pub n: u32,
        /// Their instructions in all.
        pub sum: u64,
        /// The most of one.
        pub max: u32,
    }

    impl Stats {
        /// Counts one measurement.
        pub fn add(&mut self, x: u32) {
            self.n += 1;
            self.sum += x as u64;
            self.max = self.max.max(x);
        }

        /// The mean, rounded to the nearest (0 for none).
        pub fn mean(&self) -> u64 {
            (self.sum + self.n as u64 / 2) / (self.n as u64).max(1)
        }
    }

    /// A free-running SysTick and its ticks per instruction.
    pub struct Counter {
        _syst: SYST,
        /// Ticks of the calibration loop and its instruction count.
        ticks: u32,
        instructions: u32,
        /// Instructions of an empty measurement (subtracted).
        overhead: u32,
    }

    impl Counter {
        /// Takes over SysTick (no interrupt), clocked by the core, and calibrates it.
        pub fn new(syst: SYST) -> Self {
            Self::with_clock(syst, SystClkSource::Core, 4096)
        }

        /// The same on SysTick's external reference clock, calibrated on `2 loops`
        /// instructions: coarser, but 24 bits then last far longer (the benchmark's f64
        /// reference on a Cortex-M0 takes ~10 million instructions, the core clock's
        /// 24 bits about 10 million). `ticks_per_1000() == 0` when the board has no
        /// reference clock.
        pub fn with_clock(mut syst: SYST, source: SystClkSource, loops: u32) -> Self {
            syst.disable_interrupt();
            syst.disable_counter();
            syst.set_clock_source(source);
            syst.set_reload(RELOAD);
            syst.clear_current();
            syst.enable_counter();
            // Two loop lengths: the difference cancels the cost of reading the timer.
            let short = elapsed(|| spin(64));
            let long = elapsed(|| spin(64 + loops));
            let mut counter = Counter {
                _syst: syst,
                ticks: long.wrapping_sub(short) & RELOAD,
                instructions: 2 * loops,
                overhead: 0,
            };
            counter.overhead = counter.measure(|| ()).1;
            counter
        }

        /// Gives SysTick back.
        pub fn release(self) -> SYST {
            self._syst
        }

        /// Runs `f` and returns its result and the instructions it took (at most
        /// about 10 million: SysTick has 24 bits).
        #[inline(always)]
        pub fn measure<R>(&self, f: impl FnOnce() -> R) -> (R, u32) {
            let start = SYST::get_current();
            let r = f();
            let end = SYST::get_current();
            let ticks = start.wrapping_sub(end) & RELOAD;
            let n = div(
                ticks as u64 * self.instructions as u64 + self.ticks as u64 / 2,
                self.ticks,
            );
            // Computed here, before the caller's next reading of the timer: arithmetic
            // may otherwise move past it, into the next measurement (the volatile
            // readings order only each other).
            let n = core::hint::black_box(n);
            (r, (n as u32).saturating_sub(self.overhead))
        }

        /// SysTick ticks per 1000 instructions (1600 on the mps2 boards under QEMU).
        pub fn ticks_per_1000(&self) -> u32 {
            div(self.ticks as u64 * 1000, self.instructions) as u32
        }
    }

    /// `n / d` rounded down (`n` for `d == 0`), by shifts and subtractions: a 64-bit
    /// division would link the 64-bit division routine (about 1 KiB on a Cortex-M0)
    /// into every image that counts, and into its measured size. Never inlined: called
    /// after the window's end, it would otherwise be unrolled into every call site.
    #[inline(never)]
    fn div(n: u64, d: u32) -> u64 {
        let d = u64::from(d.max(1));
        let mut q = 0u64;
        let mut rest = 0u64;
        for bit in (0..64).rev() {
            rest = rest << 1 | (n >> bit & 1);
            if rest >= d {
                rest -= d;
                q |= 1 << bit;
            }
        }
        q
    }

    #[inline(always)]
    fn elapsed(f: impl FnOnce()) -> u32 {
        let start = SYST::get_current();
        f();
        start.wrapping_sub(SYST::get_current())
    }

    /// `n` iterations of two instructions (`subs`, `bne`).
    #[inline(always)]
    fn spin(n: u32) {
        // SAFETY: a register-only loop.
        unsafe {
            core::arch::asm!(
                "2:",
                "subs {0}, #1",
                "bne 2b",
                inout(reg) n => _,
                options(nomem, nostack),
            )
        };
    }
}
