//! Time to critical: the least-squares trend of the margin phi0 - |phi| over a
//! fixed window gives the time until gross slip at the current drift.

use super::condition::{finite, ge};
use super::config::TREND_CAPACITY;
use crate::recip::recip;
use heapless::Deque;

/// One trend point: the mean margin over one interval.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TrendPoint {
    /// Monotonic time at the interval's end (ms, low 32 bits: differences wrap
    /// correctly over any window shorter than 49.7 days).
    pub time_ms: u32,
    /// Mean margin over the interval (rad).
    pub margin: f32,
}

/// The fit's points, oldest first.
pub(crate) type TrendBuffer = Deque<TrendPoint, TREND_CAPACITY>;

/// The accumulator of the current interval.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TrendInterval {
    /// Monotonic time the interval began (ms).
    pub start_ms: u64,
    /// Sum of the margins (rad).
    pub sum: f32,
    /// Number of margins.
    pub count: u32,
}

/// Appends a point, keeping at most `points` (oldest dropped).
pub(crate) fn push(buffer: &mut TrendBuffer, point: TrendPoint, points: usize) {
    while buffer.len() >= points.clamp(1, TREND_CAPACITY) {
        buffer.pop_front();
    }
    let _ = buffer.push_back(point);
}

/// Time (s) until the fitted margin reaches zero: `Some(0)` when the fit at the newest
/// point is already at or below zero, `None` when the margin does not fall (or fewer
/// than 3 points). Least squares of margin on time, times taken relative to the newest
/// point so that f32 keeps them exact. `points` oldest first.
pub fn time_to_critical(points: &[TrendPoint]) -> Option<f32> {
    let newest = points.last()?.time_ms;
    let (mut n, mut sx, mut sy) = (0u32, 0.0f32, 0.0f32);
    for p in points {
        n += 1;
        sx -= newest.wrapping_sub(p.time_ms) as f32 * 1e-3;
        sy += p.margin;
    }
    if n < 3 {
        return None;
    }
    // Divisions as products with a reciprocal (crate::recip: no division routine
    // on a core without an FPU), within 2 ulp.
    let per_n = recip(n as f32);
    let (mx, my) = (sx * per_n, sy * per_n);
    let (mut sxx, mut sxy) = (0.0f32, 0.0f32);
    for p in points {
        let dx = -(newest.wrapping_sub(p.time_ms) as f32 * 1e-3) - mx;
        sxx += dx * dx;
        sxy += dx * (p.margin - my);
    }
    // Comparisons as integers where floats are soft (condition::ge).
    if !finite(sxx) || ge(0.0, sxx) {
        return None;
    }
    let slope = sxy * recip(sxx); // rad/s
    let now = my - slope * mx; // the fit at the newest point (x = 0)
    if !finite(now) || !finite(slope) {
        return None;
    }
    if ge(0.0, now) {
        Some(0.0)
    } else if !ge(slope, 0.0) {
        let t = now * recip(-slope);
        finite(t).then_some(t)
    } else {
        None
    }
}
