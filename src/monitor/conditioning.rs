//! The conditioning stage: spike rejection (Hampel) and exponential smoothing over
//! irregular time steps, of load and angle, for a sample that passed the checks and
//! runs; the load clamped at zero. Its state: the two windows, the smoothed values and
//! the last time step's values.
//!
//! **Settling.** After a start afresh (a new monitor, a fault, a stop, a new
//! configuration or scene) the windows are empty and a value has nothing to be tested
//! against: the first `window` valid running samples only fill the windows and
//! condition nothing. The next one is the first the spike test can test, against all
//! of them, and the first conditioned; the smoothing starts from it. So no single
//! sample, whatever its value, decides what follows a restart: an outlier among the
//! filling samples is one of three or more values, which moves neither the window's
//! median nor its MAD far, and an outlier first tested is a spike. Without spike
//! rejection there is no window and nothing settles.

use super::config::{Config, SPIKE_WINDOW_CAPACITY, SpikeFilter};
use super::order::{ge, key, positive, value};
use super::statistics::Statistics;

const CAP: usize = SPIKE_WINDOW_CAPACITY;

/// The Hampel window of one channel: the last `size` values in arrival order (a ring
/// of `size` slots) as order keys ([`key`]: integer comparisons, a few instructions on
/// any core where a soft-float one costs ten times more), and keys bounding them.
///
/// The usual sample is decided without the median: the median lies between the
/// window's least and greatest values, so a value within `floor` of both bounds is
/// within `floor` of the median and never a spike. Only a value outside that interval
/// sorts a copy of the window for the median and the MAD (and tightens the bounds to
/// its ends): the verdict is always the exact test's (a test checks it against a sort
/// on random streams). A pushed value widens the bounds, an evicted one leaves them
/// loose but still bounds; the interval's keys are formed again only after the bounds
/// moved (two float operations: soft float on a Cortex-M0). The window's per-sample
/// cost is in the `cargo xtask bench` profile.
#[derive(Debug, Clone)]
pub(crate) struct Window {
    /// Keys in arrival order: slots `0..len` while filling, then a ring from `head`.
    ring: [i32; CAP],
    /// Keys at or below and at or above every key held (loose after an eviction).
    lo: i32,
    hi: i32,
    /// The keys between which a value is within the floor of every value between
    /// `lo` and `hi` (one key inside the rounded bounds), when `fresh`.
    accept_lo: i32,
    accept_hi: i32,
    /// Whether `accept_lo`, `accept_hi` are those of the current `lo`, `hi`.
    fresh: bool,
    /// Slot of the oldest value once full (0 before).
    head: u8,
    /// Values held, at most `size`.
    len: u8,
    /// The window's length (1 to `CAP`) the slots are laid out for.
    size: u8,
}

impl Window {
    pub(crate) const fn new() -> Self {
        Window {
            ring: [0; CAP],
            lo: 0,
            hi: 0,
            accept_lo: 0,
            accept_hi: -1,
            fresh: false,
            head: 0,
            len: 0,
            size: CAP as u8,
        }
    }

    fn len(&self) -> usize {
        usize::from(self.len).min(CAP)
    }

    pub(crate) fn clear(&mut self) {
        self.head = 0;
        self.len = 0;
    }

    /// The values, oldest first.
    pub(crate) fn iter(&self) -> impl Iterator<Item = f32> + '_ {
        (0..self.len()).map(|k| self.nth_oldest(k))
    }

    /// The `k`-th value from the oldest (`k` below the length).
    fn nth_oldest(&self, k: usize) -> f32 {
        // head < size: slots from the oldest, wrapping once.
        let (head, size) = (usize::from(self.head), usize::from(self.size));
        let i = head.wrapping_add(k);
        let i = if i >= size { i.wrapping_sub(size) } else { i };
        self.ring.get(i).map_or(0.0, |&k| value(k))
    }

    /// The keys held, in slot order.
    fn keys(&self) -> &[i32] {
        self.ring.get(..self.len()).unwrap_or(&[])
    }

    /// The keys held, ascending, and how many.
    fn sorted(&self) -> ([i32; CAP], usize) {
        let keys = self.keys();
        let mut sorted = self.ring;
        let n = keys.len();
        sort(&mut sorted, n);
        (sorted, n)
    }

    /// Appends a finite value, dropping the oldest beyond `n` values (n >= 1).
    #[inline(always)]
    pub(crate) fn push_back(&mut self, x: f32, n: usize) {
        if n != usize::from(self.size) {
            self.resize(n.clamp(1, CAP));
        }
        let n = usize::from(self.size).min(CAP);
        let k = key(x);
        let len = usize::from(self.len);
        let slot = if len < n {
            self.len = (len + 1) as u8;
            len
        } else {
            // Full: the oldest slot. `head < n`: it only ever counts up to `n` and
            // wraps to 0.
            let head = usize::from(self.head);
            self.head = if head + 1 >= n { 0 } else { head + 1 } as u8;
            head
        };
        if let Some(s) = self.ring.get_mut(slot) {
            *s = k;
        }
        // An evicted value leaves the bounds loose, still bounds.
        if len == 0 {
            (self.lo, self.hi, self.fresh) = (k, k, false);
        } else if k < self.lo {
            (self.lo, self.fresh) = (k, false);
        } else if k > self.hi {
            (self.hi, self.fresh) = (k, false);
        }
    }

    /// Lays the window out for `n` values, empty: a monitor's window length never
    /// changes (a restore fills a fresh window, which keeps the newest `n`).
    #[cold]
    fn resize(&mut self, n: usize) {
        self.clear();
        self.size = n as u8;
    }

    /// The keys of values within `floor` of every value from `lo` to `hi`:
    /// `[hi - floor, lo + floor]`, one key inside each rounded end, so that a value
    /// between them is within the floor of the exact median (empty when the window
    /// spreads over more than twice the floor).
    fn refresh(&mut self, floor: f32) {
        self.accept_lo = key(value(self.hi) - floor).wrapping_add(1);
        self.accept_hi = key(value(self.lo) + floor).wrapping_sub(1);
        self.fresh = true;
    }

    /// The Hampel test of a finite value `x`: `Some(median)` when `x` is a spike
    /// (further than `k` scaled MADs plus `floor` from the window's median), to be used
    /// in its place. The raw value enters the window either way, so that a real step
    /// passes once it fills half the window. No test until `window` values are in.
    #[inline(always)]
    pub(crate) fn hampel(&mut self, x: f32, filter: &SpikeFilter, floor: f32) -> Option<f32> {
        let n = usize::from(filter.window);
        let mut verdict = None;
        if usize::from(self.len) >= n && n > 0 {
            if !self.fresh {
                self.refresh(floor);
            }
            let k = key(x);
            if k < self.accept_lo || k > self.accept_hi {
                verdict = self.exact(x, filter, floor);
            }
        }
        self.push_back(x, n);
        verdict
    }

    /// The exact test, for a value outside the bounds' interval: the median and the
    /// MAD of a sorted copy of the window, whose ends tighten the bounds.
    #[cold]
    #[inline(never)]
    fn exact(&mut self, x: f32, filter: &SpikeFilter, floor: f32) -> Option<f32> {
        let (sorted, n) = self.sorted();
        let sorted = sorted.get(..n).unwrap_or(&[]);
        if let (Some(&lo), Some(&hi)) = (sorted.first(), sorted.last())
            && (lo, hi) != (self.lo, self.hi)
        {
            (self.lo, self.hi, self.fresh) = (lo, hi, false);
        }
        let med = median(sorted);
        let deviation = (x - med).abs();
        // Within the floor a value is never a spike. Both sides are >= 0: their bits
        // order them.
        let spike = deviation.to_bits() > floor.to_bits()
            && deviation.to_bits() > (filter.k * MAD_SCALE * mad(sorted, med) + floor).to_bits();
        spike.then_some(med)
    }
}

/// The median of sorted keys' values (0 for none).
fn median(sorted: &[i32]) -> f32 {
    let n = sorted.len();
    let upper = value(sorted.get(n / 2).copied().unwrap_or(0));
    if n % 2 == 1 {
        upper
    } else {
        let lower = value(sorted.get((n / 2).wrapping_sub(1)).copied().unwrap_or(0));
        0.5 * (lower + upper)
    }
}

/// The median absolute deviation from `med`, the median of the sorted keys' values:
/// the deviations' keys (their bits, >= 0) sorted, and their median.
fn mad(sorted: &[i32], med: f32) -> f32 {
    let mut deviations = [0; CAP];
    for (d, &k) in deviations.iter_mut().zip(sorted) {
        *d = key((value(k) - med).abs());
    }
    let n = sorted.len();
    sort(&mut deviations, n);
    median(deviations.get(..n).unwrap_or(&[]))
}

/// Sorts the first `n` keys ascending (insertion: a window holds at most seven).
fn sort(keys: &mut [i32; CAP], n: usize) {
    let n = n.min(CAP);
    for j in 1..n {
        // j < n <= CAP: every index below is in bounds, as the compiler sees.
        let k = keys[j];
        let mut i = j;
        while i > 0 && keys[i - 1] > k {
            keys[i] = keys[i - 1];
            i -= 1;
        }
        keys[i] = k;
    }
}

/// Scale of the median absolute deviation to a standard deviation for Gaussian noise.
const MAD_SCALE: f32 = 1.4826;

/// The weight of a new sample in the exponential smoothing after a time step `dt_s`
/// (s): `1 - exp(-dt / tau)`, the exact discrete form of a first-order lag with time
/// constant `tau_s`, so that irregular sampling weighs each sample by the time it
/// stands for. `y += weight (x - y)`.
pub(crate) fn smoothing_weight(dt_s: f32, tau_s: f32) -> f32 {
    one_minus_exp_neg(dt_s * crate::recip::recip(tau_s))
}

/// `1 - exp(-x)` for `x >= 0` (1 for NaN), within 2.5e-7 of it relative (a test
/// measures it against f64 over x from 1e-9 to 100). A few dozen bytes of code where
/// libm's `expm1f` takes 800 on a Cortex-M0 (a monitoring node has 16 KiB of flash):
/// `x` is halved `m` times to below 1/8, where `expm1(-y)` is its Taylor series to
/// y^6, and doubled back `m` times by `expm1(2z) = expm1(z) (expm1(z) + 2)`, which
/// has no cancellation.
fn one_minus_exp_neg(x: f32) -> f32 {
    // On the bits, x >= 0: no soft-float comparison (NaN lands above 88 too).
    if x.to_bits() >= 88f32.to_bits() {
        return 1.0; // exp(-x) is below the smallest f32, or x is NaN
    }
    let (mut y, mut m) = (x, 0u32);
    while y.to_bits() >= 0.125f32.to_bits() {
        y *= 0.5;
        m = m.wrapping_add(1); // at most 10: x < 88
    }
    // expm1(-y), Horner.
    let mut e = -y
        * (1.0
            - y * (0.5
                - y * (1.0 / 6.0 - y * (1.0 / 24.0 - y * (1.0 / 120.0 - y * (1.0 / 720.0))))));
    for _ in 0..m {
        e *= e + 2.0;
    }
    -e
}

/// The time step in s and the smoothing weight of the last step, kept so that a
/// repeated step (a regular sampling period) converts nothing and computes no
/// exponential per sample (in soft float on a Cortex-M0 that is most of the
/// smoothing's cost). The same values as computed afresh for every step.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StepCache {
    /// The step (ms) the values are for; `u32::MAX`, never a forward step, for none.
    dt_ms: u32,
    step: StepValues,
}

/// A time step's values.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StepValues {
    /// The step (s).
    pub(crate) dt_s: f32,
    /// [`smoothing_weight`] of the step.
    pub(crate) weight: f32,
}

impl StepCache {
    pub(crate) const fn new() -> Self {
        StepCache {
            dt_ms: u32::MAX,
            step: StepValues {
                dt_s: 0.0,
                weight: 0.0,
            },
        }
    }

    /// The values of a step of `dt_ms` for the time constant `tau_s`, which must be
    /// the same at every call (the monitor's configuration).
    #[inline(always)]
    pub(crate) fn get(&mut self, dt_ms: u32, tau_s: f32) -> StepValues {
        if dt_ms != self.dt_ms {
            self.refresh(dt_ms, tau_s);
        }
        self.step
    }

    #[cold]
    fn refresh(&mut self, dt_ms: u32, tau_s: f32) {
        let dt_s = dt_ms as f32 * 1e-3;
        self.step = StepValues {
            dt_s,
            weight: smoothing_weight(dt_s, tau_s),
        };
        self.dt_ms = dt_ms;
    }
}

/// A conditioned sample: load (N, at least 0) and angle (rad), and its time step (s).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Conditioned {
    pub(crate) load: f32,
    pub(crate) phi: f32,
    pub(crate) dt_s: f32,
}

/// The stage's state: the spike windows of load and angle, the smoothed values, the
/// last time step's values, whether the last sample only filled the windows; and
/// whether the configuration smooths at all.
#[derive(Debug, Clone)]
pub(crate) struct Conditioning {
    /// The spike windows of load (N) and angle (rad).
    pub(crate) windows: [Window; 2],
    /// Smoothed load (N) and angle (rad), `None` after a restart.
    pub(crate) smoothed: Option<[f32; 2]>,
    /// Whether the last sample conditioned was settling (it only filled the windows).
    /// Not part of the monitor's state: it follows from the windows but for the one
    /// sample that fills them (see [`Conditioning::resumed`]).
    pub(crate) settling: bool,
    step_cache: StepCache,
    /// Whether the smoothing is on (its time constant above zero).
    smoothing: bool,
}

impl Conditioning {
    pub(crate) fn new(config: &Config) -> Self {
        Conditioning {
            windows: [Window::new(), Window::new()],
            smoothed: None,
            settling: false,
            step_cache: StepCache::new(),
            // Above zero, by the bits (validated finite and not negative).
            smoothing: positive(config.smoothing_tau_s),
        }
    }

    /// Conditions a running sample's load `load` (N) and angle `phi` (rad) after a
    /// step of `dt_ms`: spikes replaced by their window's median (counted in `stats`),
    /// then smoothed with the weight of the step, the load clamped at zero. `None`
    /// while the conditioning settles (see the module's documentation).
    #[inline(always)]
    pub(crate) fn condition(
        &mut self,
        config: &Config,
        load: f32,
        phi: f32,
        dt_ms: u32,
        stats: &mut Statistics,
    ) -> Option<Conditioned> {
        let (mut load, mut phi) = (load, phi);
        if let Some(filter) = &config.spikes {
            // Settling: a window is not yet full, and takes the value untested.
            let settling = self.filling(usize::from(filter.window));
            self.settling = settling;
            // One loop over both channels: one copy of the window's code in the image.
            let mut values = [load, phi];
            let floors = [filter.load_floor, filter.angle_floor];
            for ((w, x), floor) in self.windows.iter_mut().zip(&mut values).zip(floors) {
                if let Some(m) = w.hampel(*x, filter, floor) {
                    *x = m;
                    stats.count_spike();
                }
            }
            if settling {
                // Nothing decided; the smoothing starts from the first tested value.
                self.smoothed = None;
                return None;
            }
            [load, phi] = values;
        }
        let step = self.step_cache.get(dt_ms, config.smoothing_tau_s);
        if self.smoothing {
            if let Some([l, p]) = self.smoothed {
                load = l + step.weight * (load - l);
                phi = p + step.weight * (phi - p);
            }
            self.smoothed = Some([load, phi]);
        }
        // A load cell reads a little below zero at rest; the contact has none.
        let load = if ge(load, 0.0) { load } else { 0.0 };
        Some(Conditioned {
            load,
            phi,
            dt_s: step.dt_s,
        })
    }

    /// Whether a window holds fewer than `n` values (the spike window's length): the
    /// next sample settles.
    #[inline(always)]
    fn filling(&self, n: usize) -> bool {
        let [load, angle] = &self.windows;
        usize::from(load.len.min(angle.len)) < n
    }

    /// After the windows were restored, with a spike window of `window` values (none:
    /// spike rejection off): whether the last sample was settling, as far as the
    /// windows tell (partly filled; a state taken just after the sample that filled
    /// them reads as settled, and the next sample decides either way).
    pub(crate) fn resumed(&mut self, window: Option<usize>) {
        let started = self.windows.iter().any(|w| w.len() > 0);
        self.settling = started && window.is_some_and(|n| self.filling(n));
    }

    /// Starts afresh after a sample that was not conditioned (a fault, a stop): the
    /// values before it say nothing about the ones after. The next valid running
    /// samples settle it again.
    pub(crate) fn restart(&mut self) {
        for w in &mut self.windows {
            w.clear();
        }
        self.smoothed = None;
        self.settling = false;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_minus_exp_neg_is_within_its_bound() {
        let mut worst = 0.0f64;
        let mut x = 1e-9f32;
        while x < 100.0 {
            let exact = -f64::from(-x).exp_m1();
            let got = f64::from(one_minus_exp_neg(x));
            worst = worst.max((got - exact).abs() / exact);
            x *= 1.0001;
        }
        std::println!("1 - exp(-x): worst relative error {worst:.2e}");
        assert!(worst < 2.5e-7, "{worst:e}");
        assert_eq!(one_minus_exp_neg(0.0), 0.0);
        assert_eq!(one_minus_exp_neg(1e3), 1.0);
        assert_eq!(one_minus_exp_neg(f32::NAN), 1.0);
    }

    /// The window against a plain model: the last `n` values in order, and the same
    /// sorted (values with ties and both zeros, windows of 1 to the capacity).
    #[test]
    fn window_holds_the_last_values_sorted() {
        let mut rng = 0x2545_f491u32;
        let values = [0.0f32, -0.0, 1.0, -1.0, 2.5, 2.5, 1e-6, -3.0];
        for n in 1..=CAP {
            let mut w = Window::new();
            let mut model: [f32; 64] = [0.0; 64];
            let mut pushed = 0usize;
            for _ in 0..64 {
                rng ^= rng << 13;
                rng ^= rng >> 17;
                rng ^= rng << 5;
                let x = values[(rng % values.len() as u32) as usize];
                w.push_back(x, n);
                model[pushed] = x;
                pushed += 1;
                let last = &model[pushed.saturating_sub(n)..pushed];
                let held: [u32; CAP] =
                    core::array::from_fn(|i| w.iter().nth(i).map_or(u32::MAX, |v| v.to_bits()));
                let want: [u32; CAP] =
                    core::array::from_fn(|i| last.get(i).map_or(u32::MAX, |v| v.to_bits()));
                assert_eq!(held, want, "window {n} after {pushed}");
                let mut sorted: std::vec::Vec<i32> = last.iter().map(|&x| key(x)).collect();
                sorted.sort();
                let (held_sorted, len) = w.sorted();
                assert_eq!(
                    &held_sorted[..len],
                    &sorted[..],
                    "window {n} after {pushed}"
                );
                // The bounds hold every value.
                assert!(sorted.iter().all(|&k| w.lo <= k && k <= w.hi));
                // The median and the MAD as a plain sort gives them.
                let m = plain_median(last);
                assert_eq!(median(&sorted), m, "window {n} after {pushed}");
                let deviations: std::vec::Vec<f32> = last.iter().map(|x| (x - m).abs()).collect();
                assert_eq!(
                    mad(&sorted, m),
                    plain_median(&deviations),
                    "window {n} after {pushed}"
                );
            }
            // Another length starts the window afresh.
            w.push_back(7.0, 1);
            assert_eq!(w.iter().collect::<std::vec::Vec<_>>(), [7.0]);
            assert_eq!(w.sorted().1, 1);
            w.clear();
            assert_eq!(w.iter().count(), 0);
            assert_eq!(w.sorted().1, 0);
        }
    }

    fn plain_median(v: &[f32]) -> f32 {
        let mut v = v.to_vec();
        v.sort_by(|a, b| a.partial_cmp(b).unwrap());
        let m = v.len();
        if m % 2 == 1 {
            v[m / 2]
        } else {
            0.5 * (v[m / 2 - 1] + v[m / 2])
        }
    }

    /// The Hampel verdict, decided by the bounds where it can be, against the plain
    /// test (median and MAD of a sort of the window) on random streams: noise near the
    /// floor, drifts, steps and spikes, both signs, every window length.
    #[test]
    fn hampel_is_the_exact_test() {
        let mut rng = 0x1234_5678u32;
        let mut uniform = || {
            rng ^= rng << 13;
            rng ^= rng >> 17;
            rng ^= rng << 5;
            (rng >> 8) as f32 / 16_777_216.0
        };
        for n in 3..=CAP {
            for (floor, noise) in [(1.0f32, 0.3f32), (1.0, 0.6), (1.0, 2.0), (2e-5, 3e-6)] {
                let filter = SpikeFilter {
                    window: n as u8,
                    k: 4.0,
                    load_floor: floor,
                    angle_floor: floor,
                };
                let mut w = Window::new();
                let mut last: std::vec::Vec<f32> = std::vec::Vec::new();
                for i in 0..4000 {
                    let mut x = (i as f32 * 1e-3 - 1.0) * floor + noise * (uniform() - 0.5);
                    if i % 97 == 0 {
                        x += 10.0 * floor * (uniform() - 0.5);
                    }
                    if i % 500 == 250 {
                        x = -x;
                    }
                    let want = (last.len() >= n).then(|| {
                        let window = &last[last.len() - n..];
                        let m = plain_median(window);
                        let devs: std::vec::Vec<f32> =
                            window.iter().map(|v| (v - m).abs()).collect();
                        let d = (x - m).abs();
                        (d > floor && d > filter.k * MAD_SCALE * plain_median(&devs) + floor)
                            .then_some(m)
                    });
                    let got = w.hampel(x, &filter, floor);
                    assert_eq!(got, want.flatten(), "n {n} floor {floor} sample {i}");
                    last.push(x);
                }
            }
        }
    }
}
