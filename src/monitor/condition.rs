//! Conditioning: spike rejection (Hampel), exponential smoothing over irregular time
//! steps, stuck-sensor detection.

use super::config::{SPIKE_WINDOW_CAPACITY, SpikeFilter};

const CAP: usize = SPIKE_WINDOW_CAPACITY;

/// The Hampel window of one channel: the last raw values in arrival order (a ring),
/// and the same values kept sorted, so that the median is read, not sorted, per
/// sample. Plain arrays moved by swaps: a few instructions per value, no `memmove`
/// call (the window costs per sample what the `cargo xtask bench` profile shows).
#[derive(Debug, Clone)]
pub(crate) struct Window {
    ring: [f32; CAP],
    sorted: [f32; CAP],
    /// Index of the oldest value in `ring`.
    head: u8,
    /// Values held (at most `CAP`).
    len: u8,
}

impl Window {
    pub(crate) const fn new() -> Self {
        Window {
            ring: [0.0; CAP],
            sorted: [0.0; CAP],
            head: 0,
            len: 0,
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
    pub(crate) fn iter(&self) -> impl Iterator<Item = &f32> {
        let head = usize::from(self.head);
        (0..self.len()).filter_map(move |k| self.ring.get(head.wrapping_add(k) % CAP))
    }

    /// The values in order.
    fn sorted(&self) -> &[f32] {
        self.sorted.get(..self.len()).unwrap_or(&[])
    }

    /// Drops the oldest value from the ring and its copy (the first one equal bit for
    /// bit) from the sorted values.
    fn pop_oldest(&mut self) {
        let n = self.len();
        let Some(&old) = self.ring.get(usize::from(self.head) % CAP) else {
            return;
        };
        if n == 0 {
            return;
        }
        self.head = (usize::from(self.head).wrapping_add(1) % CAP) as u8;
        self.len = (n - 1) as u8;
        // The same value (bit for bit) was inserted into `sorted` with it: move it to
        // the end, past the values that remain.
        if let Some(i) = self.sorted[..n]
            .iter()
            .position(|v| v.to_bits() == old.to_bits())
        {
            for k in i + 1..n {
                self.sorted.swap(k - 1, k);
            }
        }
    }

    /// Appends a finite value, dropping the oldest beyond `n` values (n >= 1).
    pub(crate) fn push_back(&mut self, x: f32, n: usize) {
        let n = n.clamp(1, CAP);
        while self.len() > n {
            self.pop_oldest(); // only after a restore into a shorter window
        }
        let len = self.len();
        if len == n && self.replace_oldest(x) {
            return;
        }
        while self.len() >= n {
            self.pop_oldest();
        }
        let len = self.len();
        if len >= CAP {
            return; // not reached: the pops above leave room
        }
        self.ring[usize::from(self.head).wrapping_add(len) % CAP] = x;
        // After the values <= x, before the first greater one.
        self.sorted[len] = x;
        let mut k = len;
        while k > 0 && greater(self.sorted[k - 1], x) {
            self.sorted.swap(k - 1, k);
            k -= 1;
        }
        self.len = (len + 1) as u8;
    }

    /// In a full window: `x` takes the oldest value's place in the ring and in the
    /// sorted values, moved from there to after the values <= x and before the first
    /// greater one (the same order as dropping the oldest and inserting x, in one
    /// pass). `false`, nothing changed, if the oldest is not found (not reached).
    fn replace_oldest(&mut self, x: f32) -> bool {
        let n = self.len();
        let head = usize::from(self.head) % CAP;
        let Some(&old) = self.ring.get(head) else {
            return false;
        };
        let Some(i) = self.sorted[..n]
            .iter()
            .position(|v| v.to_bits() == old.to_bits())
        else {
            return false;
        };
        // The newest slot: `head + n`, the oldest's own when the window is the ring.
        self.ring[head.wrapping_add(n) % CAP] = x;
        self.head = (head.wrapping_add(1) % CAP) as u8;
        self.sorted[i] = x;
        let mut k = i;
        while k > 0 && greater(self.sorted[k - 1], x) {
            self.sorted.swap(k - 1, k);
            k -= 1;
        }
        while k + 1 < n && !greater(self.sorted[k + 1], x) {
            self.sorted.swap(k, k + 1);
            k += 1;
        }
        true
    }

    /// The Hampel test of a finite value `x`: `Some(median)` when `x` is a spike
    /// (further than `k` scaled MADs plus `floor` from the window's median), to be used
    /// in its place. The raw value enters the window either way, so that a real step
    /// passes once it fills half the window. No test until `window` values are in.
    pub(crate) fn hampel(&mut self, x: f32, filter: &SpikeFilter, floor: f32) -> Option<f32> {
        let n = usize::from(filter.window).clamp(1, SPIKE_WINDOW_CAPACITY);
        let mut verdict = None;
        let sorted = self.sorted();
        if sorted.len() >= n {
            let med = median_of_sorted(sorted);
            let deviation = (x - med).abs();
            // Within the floor a value is never a spike: the MAD (a second median) is
            // needed only beyond it, which keeps the usual sample cheap.
            if deviation > floor {
                let mut values = [0.0f32; SPIKE_WINDOW_CAPACITY];
                let m = sorted.len().min(SPIKE_WINDOW_CAPACITY);
                for (v, w) in values.iter_mut().zip(sorted.iter()) {
                    *v = (*w - med).abs();
                }
                let mad = median(&mut values[..m]);
                if deviation > filter.k * MAD_SCALE * mad + floor {
                    verdict = Some(med);
                }
            }
        }
        self.push_back(x, n);
        verdict
    }
}

/// `a > b` for finite values. Without an FPU (the soft-float targets, the host's tests)
/// by integers: the bits mapped to an order of signed integers with 0 and -0 equal,
/// exactly the float order, some ten times cheaper than a soft-float comparison on a
/// Cortex-M0; with one (`eabihf`), the FPU's comparison.
#[inline(always)]
fn greater(a: f32, b: f32) -> bool {
    #[cfg(target_abi = "eabihf")]
    {
        a > b
    }
    #[cfg(not(target_abi = "eabihf"))]
    {
        order_key(a) > order_key(b)
    }
}

/// A finite value's place in the float order as an i32: the non-negative ones are
/// their bits, a negative one `i32::MIN - bits` (so -0 is 0, like 0).
#[cfg_attr(target_abi = "eabihf", allow(dead_code))]
#[inline(always)]
fn order_key(x: f32) -> i32 {
    let i = x.to_bits() as i32;
    if i < 0 { i32::MIN.wrapping_sub(i) } else { i }
}

/// Scale of the median absolute deviation to a standard deviation for Gaussian noise.
const MAD_SCALE: f32 = 1.4826;

/// Median of sorted values (0 for none).
fn median_of_sorted(values: &[f32]) -> f32 {
    let n = values.len();
    match n {
        0 => 0.0,
        _ if n % 2 == 1 => values.get(n / 2).copied().unwrap_or(0.0),
        // n even and >= 2: the two middle values, (n - 1) / 2 = n / 2 - 1 and n / 2.
        _ => match (values.get((n - 1) / 2), values.get(n / 2)) {
            (Some(a), Some(b)) => 0.5 * (a + b),
            _ => 0.0,
        },
    }
}

/// Median of finite values, sorting them in place.
fn median(values: &mut [f32]) -> f32 {
    // Insertion sort: at most 7 values, and only for the MAD, beyond the floor.
    for i in 1..values.len() {
        let mut j = i;
        while j > 0 && values[j - 1] > values[j] {
            values.swap(j - 1, j);
            j -= 1;
        }
    }
    median_of_sorted(values)
}

/// The weight of a new sample in the exponential smoothing after a time step `dt_s`
/// (s): `1 - exp(-dt / tau)`, the exact discrete form of a first-order lag with time
/// constant `tau_s`, so that irregular sampling weighs each sample by the time it
/// stands for. `y += weight (x - y)`.
pub(crate) fn smoothing_weight(dt_s: f32, tau_s: f32) -> f32 {
    -libm::expm1f(-dt_s / tau_s)
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
    fn integer_order_is_the_float_order() {
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
                assert_eq!(order_key(a) > order_key(b), a > b, "{a} {b}");
                assert_eq!(greater(a, b), a > b, "{a} {b}");
            }
        }
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
                let mut sorted = [0.0f32; CAP];
                sorted[..last.len()].copy_from_slice(last);
                let m = last.len();
                // Stable: equal values (0 and -0 too) in arrival order, bit for bit.
                sorted[..m].sort_by(|a, b| a.partial_cmp(b).unwrap());
                let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<std::vec::Vec<_>>();
                assert_eq!(
                    bits(w.sorted()),
                    bits(&sorted[..m]),
                    "window {n} after {pushed}"
                );
            }
            // Into a shorter window (a restore with another configuration).
            w.push_back(7.0, 1);
            assert_eq!(w.iter().copied().collect::<std::vec::Vec<_>>(), [7.0]);
            assert_eq!(w.sorted(), [7.0]);
            w.clear();
            assert_eq!(w.iter().count(), 0);
            assert!(w.sorted().is_empty());
        }
    }
}
