//! A lower bound on the monitor's per-sample cost, against which issue 10's targets
//! (300 instructions a sample on the Cortex-M4F, 1200 on the Cortex-M0) are weighed.
//!
//! The stages of `Monitor::process` with the default configuration, written flat: the
//! clock and the time per state, the gap, the range checks, the stop, the two stuck
//! trackers, the Hampel spike test of both channels (decided by the window's bounds
//! where it can be, the exact median and MAD otherwise, as the monitor does), the
//! smoothing, the estimate, the readings, the extremes, the wear integral, the start-up
//! inhibit, the slip level with its deadband, the on- and off-delays and the trend's
//! interval. Left out, so that this is a floor and not a monitor: the `Option`s, the
//! fault causes and counts, the event queue, the trend's fit (once per interval),
//! the `Approaching` test and the friction.
//!
//! Where there is an FPU it runs the f32 core (`EllipticScene`) in f32. Without one it
//! runs the fixed-point core (`FixedEllipticScene`) in its own units: the sample
//! converted once to counts in integers, the checks on the floats' bits, the spike
//! test, the smoothing, the extremes and the trend in counts and Q8.24 log2, the wear
//! as 2^(log2 F + log2 phi + log2 V + log2 dt) summed in a u64: no soft-float call per
//! sample. Both over the first 4096 samples of the built-in scenario, as
//! `cargo xtask bench` measures the monitor. One line:
//! `lean core=<f32|fixed> n=<samples> mean=<x> max=<y> spikes=<k> state=<s>`.
//!
//! ```sh
//! cargo run --release --manifest-path harness/Cargo.toml --profile firmware \
//!     --target thumbv7em-none-eabihf --bin lean_monitor
//! cargo run --release --manifest-path harness/Cargo.toml --profile firmware \
//!     --target thumbv6m-none-eabi --bin lean_monitor
//! ```
#![no_std]
#![no_main]

use misalign_harness::support;
use misalign_logger as _;

misalign_harness::log_panics_and_faults!();

mod run {
    use core::hint::black_box;
    use misalign::monitor::scenario;
    use misalign_harness::prepared;
    use misalign_harness::support::counter::{Counter, Stats};

    /// Samples of the scenario, as the benchmark's monitor rows.
    const SAMPLES: usize = 4096;
    /// The spike window (the default configuration's).
    const N: usize = 7;

    /// A float's place in the float order (-0 below +0: no matter here).
    #[inline(always)]
    fn key(x: f32) -> i32 {
        let i = x.to_bits() as i32;
        i ^ (((i >> 31) as u32) >> 1) as i32
    }

    #[cfg(target_abi = "eabihf")]
    #[inline(always)]
    fn value(k: i32) -> f32 {
        f32::from_bits((k ^ (((k >> 31) as u32) >> 1) as i32) as u32)
    }

    /// How a window's keys are compared: the f32 order keys, or counts.
    trait Domain {
        type Floor: Copy;
        /// The key of |a - b|.
        fn dev(a: i32, b: i32) -> i32;
        /// Whether deviation `dev` is a spike for a MAD of `mad`.
        fn exceeds(dev: i32, mad: i32, floor: Self::Floor) -> bool;
        /// The keys within the floor of every key from `lo` to `hi`.
        fn accept(lo: i32, hi: i32, floor: Self::Floor) -> (i32, i32);
    }

    #[cfg(target_abi = "eabihf")]
    struct Floats;
    #[cfg(target_abi = "eabihf")]
    impl Domain for Floats {
        type Floor = f32;
        fn dev(a: i32, b: i32) -> i32 {
            key((value(a) - value(b)).abs())
        }
        fn exceeds(dev: i32, mad: i32, floor: f32) -> bool {
            let d = value(dev);
            d > floor && d > 4.0 * 1.4826 * value(mad) + floor
        }
        fn accept(lo: i32, hi: i32, floor: f32) -> (i32, i32) {
            (key(value(hi) - floor) + 1, key(value(lo) + floor) - 1)
        }
    }

    #[cfg(not(target_abi = "eabihf"))]
    struct Counts;
    #[cfg(not(target_abi = "eabihf"))]
    impl Domain for Counts {
        type Floor = i32;
        fn dev(a: i32, b: i32) -> i32 {
            a.wrapping_sub(b).wrapping_abs()
        }
        fn exceeds(dev: i32, mad: i32, floor: i32) -> bool {
            // 4 x 1.4826 in Q8.
            dev > floor && i64::from(dev) > ((i64::from(mad) * 1518) >> 8) + i64::from(floor)
        }
        fn accept(lo: i32, hi: i32, floor: i32) -> (i32, i32) {
            (hi.saturating_sub(floor), lo.saturating_add(floor))
        }
    }

    /// The Hampel window: a ring of keys and loose bounds on them.
    struct Window {
        ring: [i32; N],
        head: usize,
        len: usize,
        lo: i32,
        hi: i32,
        accept: (i32, i32),
        fresh: bool,
    }

    impl Window {
        const fn new() -> Self {
            Window {
                ring: [0; N],
                head: 0,
                len: 0,
                lo: 0,
                hi: 0,
                accept: (0, -1),
                fresh: false,
            }
        }

        /// `Some(median)` if `k` is a spike; `k` enters the window either way.
        #[inline(always)]
        fn hampel<D: Domain>(&mut self, k: i32, floor: D::Floor) -> Option<i32> {
            let mut verdict = None;
            if self.len == N {
                if !self.fresh {
                    self.accept = D::accept(self.lo, self.hi, floor);
                    self.fresh = true;
                }
                if k < self.accept.0 || k > self.accept.1 {
                    verdict = self.exact::<D>(k, floor);
                }
            }
            if let Some(slot) = self.ring.get_mut(self.head) {
                *slot = k;
            }
            self.head = if self.head + 1 >= N { 0 } else { self.head + 1 };
            if self.len == 0 {
                (self.lo, self.hi, self.fresh) = (k, k, false);
            } else if k < self.lo {
                (self.lo, self.fresh) = (k, false);
            } else if k > self.hi {
                (self.hi, self.fresh) = (k, false);
            }
            self.len = (self.len + 1).min(N);
            verdict
        }

        /// The exact test: the median and the MAD of a sorted copy, whose ends tighten
        /// the bounds.
        #[cold]
        #[inline(never)]
        fn exact<D: Domain>(&mut self, k: i32, floor: D::Floor) -> Option<i32> {
            let mut s = self.ring;
            s.sort_unstable();
            (self.lo, self.hi, self.fresh) = (s[0], s[N - 1], false);
            let med = s[N / 2];
            let mut d = [0; N];
            for (d, &x) in d.iter_mut().zip(&s) {
                *d = D::dev(x, med);
            }
            d.sort_unstable();
            D::exceeds(D::dev(k, med), d[N / 2], floor).then_some(med)
        }
    }

    /// What both variants keep besides their numbers: the clock, the state machine,
    /// the stuck trackers and the counts.
    struct Common {
        last: u32,
        started_clock: bool,
        elapsed: u64,
        state: u8,
        time_in: [u64; 5],
        samples: u64,
        stuck_bits: [u32; 2],
        stuck_since: [u64; 2],
        windows: [Window; 2],
        smoothing: bool,
        dt_ms: u32,
        started: u64,
        pending: u8,
        pending_since: u64,
        since: u64,
        spikes: u32,
        trend_count: u32,
        trend_start: u64,
    }

    impl Common {
        fn new() -> Self {
            Common {
                last: 0,
                started_clock: false,
                elapsed: 0,
                state: 0,
                time_in: [0; 5],
                samples: 0,
                stuck_bits: [0; 2],
                stuck_since: [0; 2],
                windows: [Window::new(), Window::new()],
                smoothing: false,
                dt_ms: u32::MAX,
                started: u64::MAX,
                pending: 255,
                pending_since: 0,
                since: 0,
                spikes: 0,
                trend_count: 0,
                trend_start: 0,
            }
        }

        /// The clock, the checks and the stop: `(step ms, now ms, candidate)`, the
        /// candidate `Some` unless the sample is to be estimated.
        #[inline(always)]
        fn check(&mut self, t: u32, load: f32, phi: f32, speed: f32) -> (u32, u64, Option<u8>) {
            self.samples = self.samples.wrapping_add(1);
            let d = t.wrapping_sub(self.last);
            let backwards = d >= 1 << 31;
            let d = if self.started_clock && !backwards {
                d
            } else {
                0
            };
            (self.last, self.started_clock) = (t, true);
            self.elapsed = self.elapsed.wrapping_add(u64::from(d));
            let now = self.elapsed;
            if let Some(x) = self.time_in.get_mut(usize::from(self.state)) {
                *x = x.wrapping_add(u64::from(d));
            }
            let (kl, kp, kv) = (key(load), key(phi), key(speed));
            let mut fault = backwards
                || d > 10_000
                || !(kl >= key(-200.0)
                    && kl <= key(50_000.0)
                    && kp >= key(-0.05)
                    && kp <= key(0.05)
                    && kv >= 0
                    && kv <= key(50.0));
            let running = kl >= key(100.0) && kv >= key(0.1);
            if !fault {
                for (i, x) in [load, phi].into_iter().enumerate() {
                    let b = x.to_bits();
                    if !running || b != self.stuck_bits[i] {
                        (self.stuck_bits[i], self.stuck_since[i]) = (b, now);
                    } else if now - self.stuck_since[i] > 120_000 {
                        fault = true;
                    }
                }
            }
            let candidate = if fault {
                Some(4)
            } else if !running {
                Some(0)
            } else {
                if self.started == u64::MAX {
                    self.started = now;
                }
                None
            };
            if candidate.is_some() {
                for w in &mut self.windows {
                    w.len = 0;
                }
                self.smoothing = false;
            }
            (d, now, candidate)
        }

        /// The trend's interval: whether it closes at `now`.
        #[inline(always)]
        fn trend(&mut self, now: u64) -> bool {
            if self.trend_count == 0 {
                self.trend_start = now;
            }
            self.trend_count += 1;
            let closes = now - self.trend_start >= 300_000;
            if closes {
                self.trend_count = 0;
            }
            closes
        }

        /// The slip level from d/b above the warning and alarm levels (each a pair: to
        /// enter, and to stay, the deadband below), inhibited at start-up.
        #[inline(always)]
        fn level<T: PartialOrd + Copy>(&self, now: u64, s: T, warn: [T; 2], alarm: [T; 2]) -> u8 {
            if now - self.started < 60_000 {
                return 1;
            }
            let stay = [self.state == 2 || self.state == 3, self.state == 3];
            let (w, a) = (warn[usize::from(stay[0])], alarm[usize::from(stay[1])]);
            if s >= a {
                3
            } else if s >= w {
                2
            } else {
                1
            }
        }

        /// The on- and off-delays.
        #[inline(always)]
        fn offer(&mut self, candidate: u8, now: u64) -> u8 {
            if candidate == self.state {
                self.pending = 255;
            } else {
                if self.pending != candidate {
                    (self.pending, self.pending_since) = (candidate, now);
                }
                let delay = if candidate > self.state {
                    5_000
                } else {
                    30_000
                };
                if now - self.pending_since >= delay {
                    (self.state, self.since, self.pending) = (candidate, now, 255);
                }
            }
            self.state
        }
    }

    /// A core's numbers: the stages from the spike test on, in its units.
    trait Stages {
        fn common(&mut self) -> &mut Common;
        /// The slip level of a running sample after step `d` ms at `now`.
        fn estimate(&mut self, d: u32, now: u64, load: f32, phi: f32, speed: f32) -> u8;
    }

    /// One sample through every stage: the state after it.
    #[inline(never)]
    fn process<S: Stages>(s: &mut S, t: u32, load: f32, phi: f32, speed: Option<f32>) -> u8 {
        let v = speed.unwrap_or(2.0);
        let (d, now, candidate) = s.common().check(t, load, phi, v);
        let candidate = match candidate {
            Some(c) => c,
            None => s.estimate(d, now, load, phi, v),
        };
        s.common().offer(candidate, now)
    }

    #[cfg(target_abi = "eabihf")]
    mod lean {
        use super::*;
        use misalign::float::EllipticScene;

        pub const CORE: &str = "f32";

        pub struct Lean {
            c: Common,
            core: EllipticScene<'static>,
            smoothed: [f32; 2],
            weight: f32,
            dt_s: f32,
            reading: [f32; 6],
            max_slip_ratio: f32,
            max_force: f32,
            min_margin: f32,
            energy: [(f32, f32); 5],
            trend_sum: f32,
        }

        impl Lean {
            pub fn new() -> Option<Self> {
                Some(Lean {
                    c: Common::new(),
                    core: EllipticScene::from_bytes(&prepared::ELLIPTIC).ok()?,
                    smoothed: [0.0; 2],
                    weight: 0.0,
                    dt_s: 0.0,
                    reading: [0.0; 6],
                    max_slip_ratio: 0.0,
                    max_force: 0.0,
                    min_margin: f32::INFINITY,
                    energy: [(0.0, 0.0); 5],
                    trend_sum: 0.0,
                })
            }
        }

        impl Stages for Lean {
            fn common(&mut self) -> &mut Common {
                &mut self.c
            }

            #[inline(always)]
            fn estimate(&mut self, d: u32, now: u64, load: f32, phi: f32, v: f32) -> u8 {
                let mut x = [load, phi];
                for (i, floor) in [100.0, 2e-5].into_iter().enumerate() {
                    if let Some(m) = self.c.windows[i].hampel::<Floats>(key(x[i]), floor) {
                        x[i] = value(m);
                        self.c.spikes += 1;
                    }
                }
                if d != self.c.dt_ms {
                    self.c.dt_ms = d;
                    self.dt_s = d as f32 * 1e-3;
                    self.weight = 1.0 - libm::expf(-self.dt_s / 3.0);
                }
                if self.c.smoothing {
                    for (x, y) in x.iter_mut().zip(&self.smoothed) {
                        *x = y + self.weight * (*x - y);
                    }
                }
                (self.smoothed, self.c.smoothing) = (x, true);
                let [l, p] = x;
                let Ok(e) = self.core.estimate(l.max(0.0), p) else {
                    return 4;
                };
                let margin = e.margin.unwrap_or(f32::INFINITY);
                let force = e.axial_force.abs();
                self.reading = [
                    l,
                    p,
                    e.slip_ratio,
                    e.axial_force,
                    e.critical_angle.unwrap_or(0.0),
                    margin,
                ];
                if e.slip_ratio > self.max_slip_ratio {
                    self.max_slip_ratio = e.slip_ratio;
                }
                if force > self.max_force {
                    self.max_force = force;
                }
                if margin < self.min_margin {
                    self.min_margin = margin;
                }
                // Kahan's compensated sum of F phi V dt.
                if let Some((sum, c)) = self.energy.get_mut(usize::from(self.c.state)) {
                    let y = force * p.abs() * v * self.dt_s - *c;
                    let t = *sum + y;
                    *c = (t - *sum) - y;
                    *sum = t;
                }
                self.trend_sum += margin;
                if self.c.trend(now) {
                    self.trend_sum = 0.0;
                }
                self.c.level(now, e.slip_ratio, [0.8, 0.75], [1.0, 0.95])
            }
        }
    }

    #[cfg(not(target_abi = "eabihf"))]
    mod lean {
        use super::*;
        use misalign::fixed::FixedEllipticScene;
        use misalign::fixed::logexp::{exp2_fixed, log2_u32};

        pub const CORE: &str = "fixed";

        /// `x * per * 2^shift` to the count below, in integers (`per` 24 bits).
        #[inline(always)]
        fn counts(x: f32, (per, shift): (u32, i32)) -> i32 {
            let b = x.to_bits();
            let mantissa = (b & 0x7f_ffff) | 0x80_0000;
            let e = ((b >> 23) & 0xff) as i32 - 150 + shift;
            let p = u64::from(mantissa) * u64::from(per);
            let v = if e >= 0 {
                p << e.min(63) as u32
            } else if e > -64 {
                p >> (-e) as u32
            } else {
                0
            };
            let v = v.min(i32::MAX as u64) as i32;
            if b >> 31 != 0 { -v } else { v }
        }

        /// `x` as a 24-bit significand and a power of two.
        fn split(x: f64) -> (u32, i32) {
            let (mut m, mut e) = (x, 0);
            while m >= 16_777_216.0 {
                (m, e) = (m / 2.0, e + 1);
            }
            while m < 8_388_608.0 {
                (m, e) = (m * 2.0, e - 1);
            }
            (m as u32, e)
        }

        /// log2 in Q8.24.
        fn log2q(x: f64) -> i32 {
            (libm::log2(x) * 16_777_216.0) as i32
        }

        pub struct Lean {
            c: Common,
            core: FixedEllipticScene,
            per_load: (u32, i32),
            per_angle: (u32, i32),
            floors: [i32; 2],
            smoothed: [i32; 2],
            /// The smoothing weight in Q16, log2 of dt (s) in Q8.24.
            weight: i32,
            log2_dt: i32,
            log2_angle_lsb: i32,
            warn: [i32; 2],
            alarm: [i32; 2],
            reading: [i32; 6],
            max_slip_ratio: i32,
            max_force: i32,
            min_margin: i32,
            /// J in 2^-16.
            energy: [u64; 5],
            trend_sum: i64,
        }

        impl Lean {
            pub fn new() -> Option<Self> {
                Some(Lean {
                    c: Common::new(),
                    core: FixedEllipticScene::from_bytes(&prepared::FIXED_ELLIPTIC).ok()?,
                    per_load: split(1.0 / prepared::LOAD_LSB),
                    per_angle: split(1.0 / prepared::ANGLE_LSB),
                    floors: [
                        (100.0 / prepared::LOAD_LSB) as i32,
                        (2e-5 / prepared::ANGLE_LSB) as i32,
                    ],
                    smoothed: [0; 2],
                    weight: 0,
                    log2_dt: 0,
                    log2_angle_lsb: log2q(prepared::ANGLE_LSB),
                    warn: [log2q(0.8), log2q(0.75)],
                    alarm: [0, log2q(0.95)],
                    reading: [0; 6],
                    max_slip_ratio: i32::MIN,
                    max_force: i32::MIN,
                    min_margin: i32::MAX,
                    energy: [0; 5],
                    trend_sum: 0,
                })
            }
        }

        impl Stages for Lean {
            fn common(&mut self) -> &mut Common {
                &mut self.c
            }

            #[inline(always)]
            fn estimate(&mut self, d: u32, now: u64, load: f32, phi: f32, v: f32) -> u8 {
                let mut x = [
                    counts(load, self.per_load).max(0),
                    counts(phi, self.per_angle),
                ];
                for (i, floor) in self.floors.into_iter().enumerate() {
                    if let Some(m) = self.c.windows[i].hampel::<Counts>(x[i], floor) {
                        x[i] = m;
                        self.c.spikes += 1;
                    }
                }
                if d != self.c.dt_ms {
                    self.c.dt_ms = d;
                    let dt_s = f64::from(d) * 1e-3;
                    self.log2_dt = log2q(dt_s);
                    self.weight = ((1.0 - libm::exp(-dt_s / 3.0)) * 65_536.0) as i32;
                }
                if self.c.smoothing {
                    for (x, y) in x.iter_mut().zip(&self.smoothed) {
                        *x = y + ((i64::from(self.weight) * i64::from(*x - y)) >> 16) as i32;
                    }
                }
                (self.smoothed, self.c.smoothing) = (x, true);
                let [l, p] = x;
                let Ok(e) = self.core.estimate(l as u32, p) else {
                    return 4;
                };
                let margin = e.margin.unwrap_or(i32::MAX);
                let phi0 = e.critical_angle.map_or(i32::MIN, |c| c.0);
                self.reading = [l, p, e.slip_ratio.0, e.axial_force.0, phi0, margin];
                if e.slip_ratio.0 > self.max_slip_ratio {
                    self.max_slip_ratio = e.slip_ratio.0;
                }
                if e.axial_force.0 > self.max_force {
                    self.max_force = e.axial_force.0;
                }
                if margin < self.min_margin {
                    self.min_margin = margin;
                }
                // F phi V dt as 2 to its log2, in 2^-16 J, summed exactly; V in
                // 2^-16 m/s.
                let log2_speed = log2_u32(counts(v, (1 << 23, -7)) as u32).wrapping_sub(16 << 24);
                let log2_phi = log2_u32(p.unsigned_abs()).wrapping_add(self.log2_angle_lsb);
                let log2_energy = e
                    .axial_force
                    .0
                    .wrapping_add(log2_phi)
                    .wrapping_add(log2_speed)
                    .wrapping_add(self.log2_dt);
                if let Some(sum) = self.energy.get_mut(usize::from(self.c.state)) {
                    *sum = sum.wrapping_add(u64::from(exp2_fixed(log2_energy, 16)));
                }
                self.trend_sum += i64::from(margin);
                if self.c.trend(now) {
                    self.trend_sum = 0;
                }
                self.c.level(now, e.slip_ratio.0, self.warn, self.alarm)
            }
        }
    }

    pub fn main(counter: Counter) -> i32 {
        let Some(lean) = lean::Lean::new() else {
            defmt::error!("the build-time scene was refused");
            return 2;
        };
        let mut lean = black_box(lean);
        let mut stats = Stats::default();
        let mut state = 0;
        for sample in scenario::Scenario::new().take(SAMPLES) {
            let s = black_box(sample);
            let (st, k) = counter.measure(|| process(&mut lean, s.time_ms, s.load, s.phi, s.speed));
            state = black_box(st);
            stats.add(k);
        }
        defmt::println!(
            "lean core={=str} n={=u32} mean={=u64} max={=u32} spikes={=u32} state={=u8}",
            lean::CORE,
            stats.n,
            stats.mean(),
            stats.max,
            lean.common().spikes,
            state
        );
        0
    }
}

#[cortex_m_rt::entry]
fn main() -> ! {
    let Some(p) = cortex_m::Peripherals::take() else {
        support::exit(3)
    };
    let counter = support::counter::Counter::new(p.SYST);
    support::exit(run::main(counter))
}
