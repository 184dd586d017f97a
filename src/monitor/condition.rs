//! Conditioning: spike rejection (Hampel), exponential smoothing over irregular time
//! steps, stuck-sensor detection.

use super::config::{SPIKE_WINDOW_CAPACITY, SpikeFilter};

const CAP: usize = SPIKE_WINDOW_CAPACITY;

/// The Hampel window of one channel: the last `size` values in arrival order (a ring
/// of `size` slots) and the same values sorted, so that the median is read, not
/// sorted, per sample. Both hold order keys ([`key`]): every comparison is an integer
/// one, a few instructions on any core (a soft-float comparison on a Cortex-M0 costs
/// ten times more), and a new value takes the oldest one's place in the sorted values
/// by one pass of moves (the window's per-sample cost is in the `cargo xtask bench`
/// profile).
#[derive(Debug, Clone)]
pub(crate) struct Window {
    /// Keys in arrival order: slots `0..len` while filling, then a ring from `head`.
    ring: [i32; CAP],
    /// The same keys ascending.
    sorted: [i32; CAP],
    /// Slot of the oldest value once full (0 before).
    head: u8,
    /// Values held, at most `size`.
    len: u8,
    /// The window's length (1 to `CAP`) the slots are laid out for.
    size: u8,
}

/// A finite value's order key: its bits, negative ones with all but the sign bit
/// flipped, so that keys compare as signed integers exactly as the values do (-0 just
/// below 0). Its own inverse.
#[inline(always)]
fn key(x: f32) -> i32 {
    let i = x.to_bits() as i32;
    i ^ (((i >> 31) as u32) >> 1) as i32
}

/// The value of an order key.
#[inline(always)]
fn value(k: i32) -> f32 {
    f32::from_bits(key(f32::from_bits(k as u32)) as u32)
}

/// `a >= b` for values that are not NaN: the FPU's comparison where there is one
/// (`eabihf`), else integers ([`order`]), some ten times cheaper than a soft-float
/// comparison on a Cortex-M0. The same answer either way, -0 equal to 0 included.
#[inline(always)]
pub(crate) fn ge(a: f32, b: f32) -> bool {
    #[cfg(target_abi = "eabihf")]
    {
        a >= b
    }
    #[cfg(not(target_abi = "eabihf"))]
    {
        order(a) >= order(b)
    }
}

/// `lo <= x <= hi` for `lo`, `hi` not NaN; false for a NaN `x`. As [`ge`]: the FPU's
/// comparisons or integers, the same answer.
#[inline(always)]
pub(crate) fn within(x: f32, lo: f32, hi: f32) -> bool {
    #[cfg(target_abi = "eabihf")]
    {
        x >= lo && x <= hi
    }
    #[cfg(not(target_abi = "eabihf"))]
    {
        let k = order(x);
        k >= order(lo) && k <= order(hi)
    }
}

/// Whether `x` is finite, by its bits: an integer comparison on every core (`f32`'s
/// own test is a soft-float comparison without an FPU).
#[inline(always)]
pub(crate) fn finite(x: f32) -> bool {
    x.to_bits() & 0x7fff_ffff <= f32::MAX.to_bits()
}

/// A value's place in the float order as an i32, -0 equal to 0: the non-negative
/// ones are their bits, a negative one `i32::MIN - bits`. A NaN lands above +inf or
/// below -inf, by its sign.
#[cfg_attr(target_abi = "eabihf", allow(dead_code))]
#[inline(always)]
pub(crate) fn order(x: f32) -> i32 {
    let i = x.to_bits() as i32;
    if i < 0 { i32::MIN.wrapping_sub(i) } else { i }
}

impl Window {
    pub(crate) const fn new() -> Self {
        Window {
            ring: [0; CAP],
            sorted: [0; CAP],
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

    /// The sorted keys.
    fn sorted(&self) -> &[i32] {
        self.sorted.get(..self.len()).unwrap_or(&[])
    }

    /// Appends a finite value, dropping the oldest beyond `n` values (n >= 1).
    pub(crate) fn push_back(&mut self, x: f32, n: usize) {
        if n != usize::from(self.size) {
            self.resize(n.clamp(1, CAP));
        }
        let n = usize::from(self.size).min(CAP);
        let k = key(x);
        let len = usize::from(self.len);
        if len >= n {
            self.replace_oldest(k, n);
            return;
        }
        // Filling: slot `len`, then into the sorted keys after the ones <= k.
        let (Some(slot), Some(sorted)) = (self.ring.get_mut(len), self.sorted.get_mut(..=len))
        else {
            return; // not reached: len < n <= CAP
        };
        *slot = k;
        insert(sorted, len, k);
        self.len = (len + 1) as u8;
    }

    /// A full window of `n` (at most `CAP`): `k` takes the oldest key's slot in the
    /// ring, and its place among the sorted keys, moved from there to where it belongs.
    #[inline(always)]
    fn replace_oldest(&mut self, k: i32, n: usize) {
        // `head < n`: it only ever counts up to `n` and wraps to 0.
        let head = usize::from(self.head);
        let (Some(slot), Some(sorted)) = (self.ring.get_mut(head), self.sorted.get_mut(..n)) else {
            return;
        };
        let old = core::mem::replace(slot, k);
        self.head = if head + 1 >= n { 0 } else { head + 1 } as u8;
        // The oldest key is held (keys are the values, bit for bit).
        let i = sorted.iter().position(|&v| v == old).unwrap_or(0);
        insert(sorted, i, k);
    }

    /// Lays the window out for `n` values, empty: a monitor's window length never
    /// changes (a restore fills a fresh window, which keeps the newest `n`).
    #[cold]
    fn resize(&mut self, n: usize) {
        self.clear();
        self.size = n as u8;
    }

    /// The median of a non-empty window.
    #[inline(always)]
    fn median(&self) -> f32 {
        // n / 2 < n <= CAP.
        let n = usize::from(self.len).min(CAP);
        let upper = value(self.sorted.get(n / 2).copied().unwrap_or(0));
        if n % 2 == 1 {
            upper
        } else {
            let lower = value(
                self.sorted
                    .get((n / 2).saturating_sub(1))
                    .copied()
                    .unwrap_or(0),
            );
            0.5 * (lower + upper)
        }
    }

    /// The median absolute deviation from `med`, the window's median. The deviations
    /// of the sorted values grow outwards from the middle on both sides: the two
    /// sequences are merged up to the middle, `n/2 + 1` steps, no sort.
    #[cold]
    fn mad(&self, med: f32) -> f32 {
        let sorted = self.sorted();
        let n = sorted.len();
        // |value - med| at index i; +inf past either end.
        let deviation = |i: usize| {
            sorted
                .get(i)
                .map_or(f32::INFINITY, |&k| (value(k) - med).abs())
        };
        // The next left index is `left - 1`, the next right one `right`. Absolute
        // values (-0 is 0) and +inf: their bits order them.
        let (mut left, mut right) = (n / 2, n / 2);
        let mut next = || {
            let (a, b) = (deviation(left.wrapping_sub(1)), deviation(right));
            if a.to_bits() <= b.to_bits() {
                left = left.wrapping_sub(1);
                a
            } else {
                right = right.wrapping_add(1);
                b
            }
        };
        for _ in 0..n.saturating_sub(1) / 2 {
            next();
        }
        if n.is_multiple_of(2) {
            let lower = next();
            0.5 * (lower + next())
        } else {
            next()
        }
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
            let med = self.median();
            let deviation = (x - med).abs();
            // Within the floor a value is never a spike: the MAD (a second median) is
            // needed only beyond it, which keeps the usual sample cheap. Both sides
            // are >= 0: their bits order them.
            if deviation.to_bits() > floor.to_bits()
                && deviation.to_bits() > (filter.k * MAD_SCALE * self.mad(med) + floor).to_bits()
            {
                verdict = Some(med);
            }
        }
        self.push_back(x, n);
        verdict
    }
}

/// Puts `k` into the sorted keys in place of the one at `i`: the keys between are
/// moved one place towards `i`, so that all stay sorted.
#[inline(always)]
fn insert(sorted: &mut [i32], mut i: usize, k: i32) {
    // Every index is checked (`get`): no panic path, and as cheap as indexing.
    while let Some(&next) = sorted.get(i.wrapping_add(1)) {
        if next >= k {
            break;
        }
        if let Some(slot) = sorted.get_mut(i) {
            *slot = next;
        }
        i = i.wrapping_add(1);
    }
    while let Some(&prev) = sorted.get(i.wrapping_sub(1)) {
        if prev <= k {
            break;
        }
        if let Some(slot) = sorted.get_mut(i) {
            *slot = prev;
        }
        i = i.wrapping_sub(1);
    }
    if let Some(slot) = sorted.get_mut(i) {
        *slot = k;
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

/// The smoothing weight of the last time step, kept so that a repeated step (a
/// regular sampling period) does not compute `expm1f` and a division per sample (in
/// soft float on a Cortex-M0 that is most of the smoothing's cost). The same value as
/// [`smoothing_weight`] for every step: only its recomputation is skipped.
#[derive(Debug, Clone, Copy)]
pub(crate) struct WeightCache {
    /// The step (ms) `weight` is for; `u32::MAX`, never a forward step, for none.
    dt_ms: u32,
    weight: f32,
}

impl WeightCache {
    pub(crate) const fn new() -> Self {
        WeightCache {
            dt_ms: u32::MAX,
            weight: 0.0,
        }
    }

    /// [`smoothing_weight`] of a step of `dt_ms` for the time constant `tau_s`, which
    /// must be the same at every call (the monitor's configuration).
    pub(crate) fn weight(&mut self, dt_ms: u32, tau_s: f32) -> f32 {
        if dt_ms != self.dt_ms {
            self.weight = smoothing_weight(dt_ms as f32 * 1e-3, tau_s);
            self.dt_ms = dt_ms;
        }
        self.weight
    }
}

/// Stuck-value tracking of one channel: the raw bits and since when they are unchanged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StuckTracker {
    /// Bits of the last raw value.
    pub bits: u32,
    /// Monotonic time (ms) since which the value is unchanged.
    pub since_ms: u64,
}

impl StuckTracker {
    /// Whether the raw value `x` has been unchanged for longer than `limit_ms` at
    /// monotonic time `now_ms`. `reset` restarts the tracking (the machine stands).
    pub(crate) fn stuck(&mut self, x: f32, now_ms: u64, limit_ms: u32, reset: bool) -> bool {
        let bits = x.to_bits();
        if reset || bits != self.bits {
            self.bits = bits;
            self.since_ms = now_ms;
            return false;
        }
        limit_ms > 0 && now_ms.saturating_sub(self.since_ms) > u64::from(limit_ms)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_order_as_the_values_and_invert() {
        let xs = [
            f32::MIN,
            -1e30,
            -2.0,
            -1.0,
            -1e-30,
            -1e-45,
            -0.0,
            0.0,
            1e-45,
            1e-38,
            0.5,
            1.0,
            3.0,
            f32::MAX,
        ];
        for a in xs {
            for b in xs {
                // The float order, with -0 just below 0.
                let below_zero = a == b && a.is_sign_negative() && b.is_sign_positive();
                assert_eq!(key(a) < key(b), a < b || below_zero, "{a} {b}");
                assert_eq!(value(key(a)).to_bits(), a.to_bits(), "{a}");
                assert_eq!(ge(a, b), a >= b, "{a} {b}");
                assert_eq!(order(a) >= order(b), a >= b, "{a} {b}");
                assert!(finite(a));
                assert_eq!(within(a, b, 1.0), b <= a && a <= 1.0, "{a} {b}");
            }
            assert!(!finite(f32::INFINITY) && !finite(f32::NEG_INFINITY));
            // A NaN of either sign is outside every finite range.
            for nan in [f32::NAN, -f32::NAN] {
                assert!(order(nan) > order(f32::INFINITY) || order(nan) < order(f32::NEG_INFINITY));
                assert!(!within(nan, f32::NEG_INFINITY, f32::INFINITY));
                assert!(!finite(nan));
            }
        }
    }

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
                assert_eq!(w.sorted(), &sorted[..], "window {n} after {pushed}");
                // The median and the MAD as a plain sort gives them.
                let med = |v: &[f32]| {
                    let mut v = v.to_vec();
                    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
                    let m = v.len();
                    if m % 2 == 1 {
                        v[m / 2]
                    } else {
                        0.5 * (v[m / 2 - 1] + v[m / 2])
                    }
                };
                let m = med(last);
                assert_eq!(w.median(), m, "window {n} after {pushed}");
                let deviations: std::vec::Vec<f32> = last.iter().map(|x| (x - m).abs()).collect();
                assert_eq!(w.mad(m), med(&deviations), "window {n} after {pushed}");
            }
            // Another length starts the window afresh.
            w.push_back(7.0, 1);
            assert_eq!(w.iter().collect::<std::vec::Vec<_>>(), [7.0]);
            assert_eq!(w.sorted(), [key(7.0)]);
            w.clear();
            assert_eq!(w.iter().count(), 0);
            assert!(w.sorted().is_empty());
        }
    }
}
