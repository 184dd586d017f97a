//! Conditioning: spike rejection (Hampel), exponential smoothing over irregular time
//! steps, stuck-sensor detection.

use super::config::{SPIKE_WINDOW_CAPACITY, SpikeFilter};
use heapless::{Deque, Vec};

/// The Hampel window of one channel: the last raw values in arrival order, and the
/// same values kept sorted, so that the median is read, not sorted, per sample.
#[derive(Debug, Clone)]
pub(crate) struct Window {
    fifo: Deque<f32, SPIKE_WINDOW_CAPACITY>,
    // A u8 length: the window holds at most 7 (RAM budget of the live monitor).
    sorted: Vec<f32, SPIKE_WINDOW_CAPACITY, u8>,
}

impl Window {
    pub(crate) const fn new() -> Self {
        Window {
            fifo: Deque::new(),
            sorted: Vec::new(),
        }
    }

    pub(crate) fn clear(&mut self) {
        self.fifo.clear();
        self.sorted.clear();
    }

    /// The values, oldest first.
    pub(crate) fn iter(&self) -> impl Iterator<Item = &f32> {
        self.fifo.iter()
    }

    /// Appends a finite value, dropping the oldest beyond `n` values (n >= 1).
    pub(crate) fn push_back(&mut self, x: f32, n: usize) {
        while self.fifo.len() >= n.clamp(1, SPIKE_WINDOW_CAPACITY) {
            let Some(old) = self.fifo.pop_front() else {
                break;
            };
            // The same value (bit for bit) was inserted into `sorted` with it.
            if let Some(i) = self
                .sorted
                .iter()
                .position(|v| v.to_bits() == old.to_bits())
            {
                // Moved to the end by swaps and dropped (not `remove`, whose memmove
                // costs 1.3 KB of flash on a Cortex-M0 for at most 7 values).
                for j in i + 1..self.sorted.len() {
                    self.sorted.swap(j - 1, j);
                }
                self.sorted.pop();
            }
        }
        let at = self
            .sorted
            .iter()
            .position(|&v| v > x)
            .unwrap_or(self.sorted.len());
        // Neither is full after the pops above. Inserted at `at` by swaps (as above).
        if self.fifo.push_back(x).is_ok() {
            if self.sorted.push(x).is_ok() {
                let mut j = self.sorted.len().saturating_sub(1);
                while j > at {
                    self.sorted.swap(j - 1, j);
                    j -= 1;
                }
            } else {
                self.fifo.pop_back();
            }
        }
    }

    /// The Hampel test of a finite value `x`: `Some(median)` when `x` is a spike
    /// (further than `k` scaled MADs plus `floor` from the window's median), to be used
    /// in its place. The raw value enters the window either way, so that a real step
    /// passes once it fills half the window. No test until `window` values are in.
    pub(crate) fn hampel(&mut self, x: f32, filter: &SpikeFilter, floor: f32) -> Option<f32> {
        let n = usize::from(filter.window).clamp(1, SPIKE_WINDOW_CAPACITY);
        let mut verdict = None;
        if self.sorted.len() >= n {
            let med = median_of_sorted(&self.sorted);
            let deviation = (x - med).abs();
            // Within the floor a value is never a spike: the MAD (a second median) is
            // needed only beyond it, which keeps the usual sample cheap.
            if deviation > floor {
                let mut values = [0.0f32; SPIKE_WINDOW_CAPACITY];
                let m = self.sorted.len().min(SPIKE_WINDOW_CAPACITY);
                for (v, w) in values.iter_mut().zip(self.sorted.iter()) {
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

/// Scale of the median absolute deviation to a standard deviation for Gaussian noise.
const MAD_SCALE: f32 = 1.4826;

/// Median of sorted values (0 for none).
fn median_of_sorted(values: &[f32]) -> f32 {
    let n = values.len();
    match n {
        0 => 0.0,
        _ if n % 2 == 1 => values[n / 2],
        _ => 0.5 * (values[n / 2 - 1] + values[n / 2]),
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
