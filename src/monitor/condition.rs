//! Conditioning: spike rejection (Hampel), exponential smoothing over irregular time
//! steps, stuck-sensor detection.

use super::config::{SPIKE_WINDOW_CAPACITY, SpikeFilter};
use heapless::Deque;

/// The Hampel window of one channel: the last `window` raw values, oldest first.
pub(crate) type Window = Deque<f32, SPIKE_WINDOW_CAPACITY>;

/// Scale of the median absolute deviation to a standard deviation for Gaussian noise.
const MAD_SCALE: f32 = 1.4826;

/// Median of `values[..len]` (finite values), sorting them in place.
fn median(values: &mut [f32]) -> f32 {
    // Insertion sort: at most 9 values.
    for i in 1..values.len() {
        let mut j = i;
        while j > 0 && values[j - 1] > values[j] {
            values.swap(j - 1, j);
            j -= 1;
        }
    }
    let n = values.len();
    match n {
        0 => 0.0,
        _ if n % 2 == 1 => values[n / 2],
        _ => 0.5 * (values[n / 2 - 1] + values[n / 2]),
    }
}

/// The Hampel test of a finite value `x` against the window: `Some(median)` when `x`
/// is a spike (further than `k` scaled MADs plus `floor` from the median), to be used
/// in its place. The raw value enters the window either way, so that a real step
/// passes once it fills half the window. No test until the window is full.
pub(crate) fn hampel(window: &mut Window, x: f32, filter: &SpikeFilter, floor: f32) -> Option<f32> {
    let n = usize::from(filter.window).clamp(1, SPIKE_WINDOW_CAPACITY);
    let mut verdict = None;
    if window.len() >= n {
        let mut values = [0.0f32; SPIKE_WINDOW_CAPACITY];
        for (v, w) in values.iter_mut().zip(window.iter()) {
            *v = *w;
        }
        let med = median(&mut values[..n]);
        for v in &mut values[..n] {
            *v = (*v - med).abs();
        }
        let mad = median(&mut values[..n]);
        if (x - med).abs() > filter.k * MAD_SCALE * mad + floor {
            verdict = Some(med);
        }
    }
    while window.len() >= n {
        window.pop_front();
    }
    // Cannot be full after the pops above (n <= capacity).
    let _ = window.push_back(x);
    verdict
}

/// Exponential smoothing whose weight follows the real time step `dt_s` (s):
/// `y += (1 - exp(-dt / tau)) (x - y)`, the exact discrete form of a first-order lag
/// with time constant `tau_s`, so that irregular sampling weighs each sample by the
/// time it stands for.
pub(crate) fn smooth(previous: f32, x: f32, dt_s: f32, tau_s: f32) -> f32 {
    let weight = -libm::expm1f(-dt_s / tau_s);
    previous + weight * (x - previous)
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
