//! Simulated sensors that replay a trace of raw codes through the same traits as the
//! real chips (feature `_sim`; semver-exempt, for tests and for firmware in QEMU, which
//! has no load cell). `no_std`, no heap, no `unsafe`.
//!
//! - [`SimClock`] and [`SimDelay`]: simulated time; a delay advances the clock.
//! - [`SimHx711`]: an HX711 behind an embedded-hal `InputPin` (DOUT, [`SimDout`]) and
//!   `OutputPin` (PD_SCK, [`SimSck`]): a conversion is ready a conversion period after
//!   the previous one was read, its 24 bits shift out MSB first on PD_SCK's rising
//!   edges, the 25th to 27th pulse set the next gain, PD_SCK high for more than 60 µs
//!   powers it down. Faults can be injected: DOUT forced high (unplugged, never ready)
//!   or low (shorted, all zeros), pin errors.
//! - [`SimAdc`]: an [`Adc`] of `N` channels, each replaying its own trace, with the
//!   same faults (timeout, bus error).
//!
//! A trace is a slice of raw codes, replayed in a loop; [`SimHx711::feed`] and
//! [`SimAdc::feed`] put a one-off code ahead of it. [`TraceEncoder`] turns a scenario's
//! samples (load P in N, angle phi in rad) into the codes that the calibrated sensors
//! read back as those values, with a small dither so that a steady value is not taken
//! for a stuck sensor.

use core::cell::{Cell, RefCell};
use core::fmt;

use embedded_hal::delay::DelayNs;
use embedded_hal::digital::{self, ErrorType, InputPin, OutputPin};

use super::{Adc, AdcError, Hx711Channel, LoadCalibration, MisalignmentCalibration, Rails};

/// Simulated time, ns, shared by the delays and the simulated chips.
#[derive(Debug, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SimClock {
    now_ns: Cell<u64>,
}

impl SimClock {
    /// A clock at 0.
    pub const fn new() -> Self {
        SimClock {
            now_ns: Cell::new(0),
        }
    }

    /// The time, ns.
    pub fn now_ns(&self) -> u64 {
        self.now_ns.get()
    }

    /// Moves the time on by `ns` (saturating).
    pub fn advance(&self, ns: u64) {
        self.now_ns.set(self.now_ns.get().saturating_add(ns));
    }

    /// A delay on this clock.
    pub fn delay(&self) -> SimDelay<'_> {
        SimDelay { clock: self }
    }
}

/// An embedded-hal delay that advances a [`SimClock`] instead of waiting.
#[derive(Debug, Clone, Copy)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SimDelay<'a> {
    clock: &'a SimClock,
}

impl DelayNs for SimDelay<'_> {
    fn delay_ns(&mut self, ns: u32) {
        self.clock.advance(ns.into());
    }
}

/// An injected pin or bus error.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SimError;

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("injected pin or bus error")
    }
}

impl core::error::Error for SimError {}

impl digital::Error for SimError {
    fn kind(&self) -> digital::ErrorKind {
        digital::ErrorKind::Other
    }
}

/// Where the HX711's serial interface is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    /// Converting; ready at `ready_ns`.
    Converting { ready_ns: u64 },
    /// Shifting `word` out: `pulses` rising edges so far.
    Shifting { word: u32, pulses: u8 },
}

#[derive(Debug)]
struct Hx711State<'a> {
    trace: &'a [i32],
    next: usize,
    fed: Option<i32>,
    period_ns: u64,
    phase: Phase,
    /// The gain of the conversion under way.
    gain: Hx711Channel,
    sck_high_since: Option<u64>,
    dout_forced: Option<bool>,
    pin_error: bool,
    conversions: u32,
    last_gain: Option<Hx711Channel>,
}

/// A simulated HX711 replaying a trace of raw 24-bit codes (clamped to the rails),
/// through its two pins ([`dout`](Self::dout), [`sck`](Self::sck)).
#[derive(Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SimHx711<'a> {
    clock: &'a SimClock,
    state: RefCell<Hx711State<'a>>,
}

impl<'a> SimHx711<'a> {
    /// A chip on `clock` that converts every `period_ns` ns (100 ms at 10 samples/s)
    /// and replays `trace` in a loop (all zeros if empty). It has just been powered
    /// up: channel A, gain 128, the first conversion ready after one period.
    pub fn new(clock: &'a SimClock, period_ns: u64, trace: &'a [i32]) -> Self {
        SimHx711 {
            clock,
            state: RefCell::new(Hx711State {
                trace,
                next: 0,
                fed: None,
                period_ns,
                phase: Phase::Converting {
                    ready_ns: clock.now_ns().saturating_add(period_ns),
                },
                gain: Hx711Channel::A128,
                sck_high_since: None,
                dout_forced: None,
                pin_error: false,
                conversions: 0,
                last_gain: None,
            }),
        }
    }

    /// The DOUT pin (an input for the driver).
    pub fn dout(&self) -> SimDout<'_, 'a> {
        SimDout { chip: self }
    }

    /// The PD_SCK pin (an output for the driver).
    pub fn sck(&self) -> SimSck<'_, 'a> {
        SimSck { chip: self }
    }

    /// Replaces the trace and restarts it.
    pub fn set_trace(&self, trace: &'a [i32]) {
        let mut s = self.state.borrow_mut();
        s.trace = trace;
        s.next = 0;
    }

    /// The next conversion gives `raw` instead of the trace's next code (once).
    pub fn feed(&self, raw: i32) {
        self.state.borrow_mut().fed = Some(raw);
    }

    /// Forces DOUT: `Some(true)` high (unplugged with a pull-up: never ready),
    /// `Some(false)` low (shorted: always ready, all zeros), `None` the chip drives it.
    pub fn force_dout(&self, level: Option<bool>) {
        self.state.borrow_mut().dout_forced = level;
    }

    /// Makes both pins return [`SimError`] (or stop doing so).
    pub fn set_pin_error(&self, on: bool) {
        self.state.borrow_mut().pin_error = on;
    }

    /// How many conversions have been shifted out so far.
    pub fn conversions(&self) -> u32 {
        self.state.borrow().conversions
    }

    /// The gain of the conversion last shifted out, if any.
    pub fn last_gain(&self) -> Option<Hx711Channel> {
        self.state.borrow().last_gain
    }

    /// The channel and gain of the conversion under way.
    pub fn gain(&self) -> Hx711Channel {
        self.state.borrow().gain
    }

    fn dout_level(&self) -> Result<bool, SimError> {
        let now = self.clock.now_ns();
        let mut s = self.state.borrow_mut();
        if s.pin_error {
            return Err(SimError);
        }
        if let Some(level) = s.dout_forced {
            return Ok(level);
        }
        let sck_low = s.sck_high_since.is_none();
        Ok(match s.phase {
            Phase::Converting { ready_ns } => now < ready_ns,
            // After the 25th pulse DOUT goes high until the next conversion.
            Phase::Shifting { pulses, .. } if pulses >= 25 => {
                if sck_low {
                    // The read is over: the next conversion with the gain just set.
                    let ready_ns = now.saturating_add(s.period_ns);
                    s.phase = Phase::Converting { ready_ns };
                    now < ready_ns
                } else {
                    true
                }
            }
            Phase::Shifting { word, pulses } => {
                let bit = 24u8.saturating_sub(pulses.max(1));
                word >> bit & 1 == 1
            }
        })
    }

    fn set_sck(&self, high: bool) -> Result<(), SimError> {
        let now = self.clock.now_ns();
        let mut s = self.state.borrow_mut();
        if s.pin_error {
            return Err(SimError);
        }
        match (high, s.sck_high_since) {
            (true, None) => {
                s.sck_high_since = Some(now);
                self.rising_edge(&mut s, now);
            }
            (false, Some(since)) => {
                s.sck_high_since = None;
                if now.saturating_sub(since) > 60_000 {
                    // Powered down; on waking it resets to channel A, gain 128.
                    s.gain = Hx711Channel::A128;
                    s.phase = Phase::Converting {
                        ready_ns: now.saturating_add(s.period_ns),
                    };
                }
            }
            _ => {}
        }
        Ok(())
    }

    fn rising_edge(&self, s: &mut Hx711State<'a>, now: u64) {
        if s.dout_forced.is_some() {
            // A shorted or open DOUT: the chip's own state does not matter.
            return;
        }
        match s.phase {
            Phase::Converting { ready_ns } if now >= ready_ns => {
                let raw =
                    next_code(s.trace, &mut s.next, &mut s.fed).clamp(-(1 << 23), (1 << 23) - 1);
                s.phase = Phase::Shifting {
                    word: (raw as u32) & 0xFF_FFFF,
                    pulses: 1,
                };
                s.conversions = s.conversions.saturating_add(1);
                s.last_gain = Some(s.gain);
            }
            Phase::Converting { .. } => {}
            Phase::Shifting { word, pulses } => {
                let pulses = pulses.saturating_add(1);
                s.phase = Phase::Shifting { word, pulses };
                s.gain = match pulses {
                    ..=24 => s.gain,
                    25 => Hx711Channel::A128,
                    26 => Hx711Channel::B32,
                    _ => Hx711Channel::A64,
                };
            }
        }
    }
}

/// The simulated HX711's DOUT pin.
#[derive(Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SimDout<'c, 'a> {
    chip: &'c SimHx711<'a>,
}

/// The simulated HX711's PD_SCK pin.
#[derive(Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SimSck<'c, 'a> {
    chip: &'c SimHx711<'a>,
}

impl ErrorType for SimDout<'_, '_> {
    type Error = SimError;
}

impl ErrorType for SimSck<'_, '_> {
    type Error = SimError;
}

impl InputPin for SimDout<'_, '_> {
    fn is_high(&mut self) -> Result<bool, SimError> {
        self.chip.dout_level()
    }

    fn is_low(&mut self) -> Result<bool, SimError> {
        self.chip.dout_level().map(|high| !high)
    }
}

impl OutputPin for SimSck<'_, '_> {
    fn set_low(&mut self) -> Result<(), SimError> {
        self.chip.set_sck(false)
    }

    fn set_high(&mut self) -> Result<(), SimError> {
        self.chip.set_sck(true)
    }
}

/// A simulated ADC of `N` channels (channel `i` replays `traces[i]` in a loop), with
/// injectable timeouts and bus errors.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SimAdc<'a, const N: usize> {
    traces: [&'a [i32]; N],
    next: [usize; N],
    fed: [Option<i32>; N],
    rails: Rails,
    timeout: bool,
    bus_error: bool,
    reads: u32,
}

impl<'a, const N: usize> SimAdc<'a, N> {
    /// An ADC with these rails replaying these traces (codes clamped to the rails; an
    /// empty trace reads 0).
    pub fn new(rails: Rails, traces: [&'a [i32]; N]) -> Self {
        SimAdc {
            traces,
            next: [0; N],
            fed: [None; N],
            rails,
            timeout: false,
            bus_error: false,
            reads: 0,
        }
    }

    /// Replaces channel `channel`'s trace and restarts it (ignored for a channel
    /// beyond `N`).
    pub fn set_trace(&mut self, channel: usize, trace: &'a [i32]) {
        if let (Some(t), Some(n)) = (self.traces.get_mut(channel), self.next.get_mut(channel)) {
            *t = trace;
            *n = 0;
        }
    }

    /// The next read of `channel` gives `raw` (once), ahead of its trace.
    pub fn feed(&mut self, channel: usize, raw: i32) {
        if let Some(f) = self.fed.get_mut(channel) {
            *f = Some(raw);
        }
    }

    /// Every read times out (the chip never has data ready), or stops doing so.
    pub fn set_timeout(&mut self, on: bool) {
        self.timeout = on;
    }

    /// Every read is a bus error, or stops being one.
    pub fn set_bus_error(&mut self, on: bool) {
        self.bus_error = on;
    }

    /// How many codes were read so far.
    pub fn reads(&self) -> u32 {
        self.reads
    }
}

impl<const N: usize> Adc for SimAdc<'_, N> {
    type Channel = usize;
    type Error = SimError;

    fn rails(&self) -> Rails {
        self.rails
    }

    /// A code of channel `channel` (a channel beyond `N` is a bus error).
    fn read(&mut self, channel: usize) -> Result<i32, AdcError<SimError>> {
        if self.bus_error {
            return Err(AdcError::Bus(SimError));
        }
        if self.timeout {
            return Err(AdcError::Timeout);
        }
        let (Some(trace), Some(next), Some(fed)) = (
            self.traces.get(channel),
            self.next.get_mut(channel),
            self.fed.get_mut(channel),
        ) else {
            return Err(AdcError::Bus(SimError));
        };
        let raw = next_code(trace, next, fed);
        self.reads = self.reads.saturating_add(1);
        Ok(raw.clamp(self.rails.min, self.rails.max))
    }
}

/// The fed code if there is one, else the trace's next (in a loop; 0 if empty).
fn next_code(trace: &[i32], next: &mut usize, fed: &mut Option<i32>) -> i32 {
    if let Some(raw) = fed.take() {
        return raw;
    }
    let raw = trace.get(*next % trace.len().max(1)).copied();
    *next = next.wrapping_add(1);
    raw.unwrap_or(0)
}

/// The raw codes of one sample: the load cell's and the two probes'.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SampleCodes {
    /// The load cell's code.
    pub load: i32,
    /// Probe 1's code.
    pub probe1: i32,
    /// Probe 2's code.
    pub probe2: i32,
}

/// Turns a scenario's samples into raw codes for the simulated chips: the codes the
/// given calibrations read back as load P and angle phi (probe 2 held at `d2_m`,
/// probe 1 at `d2_m + zero_offset_m + span_m * tan(phi)`), each with a deterministic
/// dither of up to `dither` counts (xorshift32), as real noise would have.
#[derive(Debug, Clone, Copy)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TraceEncoder<C> {
    load: LoadCalibration<C>,
    probes: MisalignmentCalibration,
    d2_m: f32,
    dither: u32,
    state: u32,
}

impl<C: Copy> TraceEncoder<C> {
    /// An encoder for these calibrations; `dither` counts of noise (0: exact codes).
    pub fn new(
        load: LoadCalibration<C>,
        probes: MisalignmentCalibration,
        d2_m: f32,
        dither: u32,
    ) -> Self {
        TraceEncoder {
            load,
            probes,
            d2_m,
            dither,
            state: 0x9E37_79B9,
        }
    }

    /// A dither in `-dither ..= dither`.
    fn noise(&mut self) -> i32 {
        let mut x = self.state;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.state = x;
        let width = u64::from(self.dither) * 2 + 1;
        // In -dither ..= dither; `as` truncates (no panic) for a dither beyond i32.
        ((u64::from(x) % width) as i64 - i64::from(self.dither)) as i32
    }

    /// The codes of a sample with load `p_n` N and angle `phi_rad` rad.
    pub fn codes(&mut self, p_n: f32, phi_rad: f32) -> SampleCodes {
        let pr = &self.probes;
        let d1 = self.d2_m + pr.zero_offset_m + pr.span_m * libm::tanf(phi_rad);
        let (load, probe1, probe2) = (
            self.load.counts_for(p_n),
            pr.probe1.counts_for(d1),
            pr.probe2.counts_for(self.d2_m),
        );
        SampleCodes {
            load: load.saturating_add(self.noise()),
            probe1: probe1.saturating_add(self.noise()),
            probe2: probe2.saturating_add(self.noise()),
        }
    }
}
