//! The trend stage: the least-squares trend of the margin phi0 - |phi| over a fixed
//! window gives the time until gross slip at the current drift, when the fit is above
//! zero now and falls credibly ([`time_to_critical`]); the events stage warns when it
//! falls below the horizon. Its state: the current interval, the points, the latest
//! time to critical.

use super::config::{TREND_CAPACITY, TREND_SLOPE_STANDARD_ERRORS, TrendConfig};
use super::order::{finite, ge};
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
pub(crate) struct TrendInterval {
    /// Monotonic time the interval began (ms).
    pub(crate) start_ms: u64,
    /// Sum of the margins (rad).
    pub(crate) sum: f32,
    /// Number of margins.
    pub(crate) count: u32,
}

/// The stage's state.
#[derive(Debug, Clone)]
pub(crate) struct Trend {
    /// The current interval.
    pub(crate) interval: TrendInterval,
    /// The fit's points, oldest first.
    pub(crate) points: TrendBuffer,
    /// The latest time to critical (s).
    pub(crate) time_to_critical_s: Option<f32>,
}

impl Trend {
    pub(crate) const fn new() -> Self {
        Trend {
            interval: TrendInterval {
                start_ms: 0,
                sum: 0.0,
                count: 0,
            },
            points: TrendBuffer::new(),
            time_to_critical_s: None,
        }
    }

    /// Adds an estimated sample's margin `margin` (rad) at monotonic time `now` (ms)
    /// to the current interval, which becomes a point once it spans the configured
    /// interval.
    #[inline(always)]
    pub(crate) fn add(&mut self, tc: TrendConfig, margin: f32, now: u64) {
        let iv = &mut self.interval;
        if iv.count == 0 {
            iv.start_ms = now;
        }
        iv.sum += margin;
        iv.count = iv.count.saturating_add(1);
        if now.wrapping_sub(iv.start_ms) >= u64::from(tc.interval_ms) {
            self.point(tc, now);
        }
    }

    /// Seconds from the newest point (the fit's time) to monotonic time `now` (ms).
    #[cold]
    pub(crate) fn fit_age_s(&self, now: u64) -> f32 {
        self.points
            .back()
            .map_or(0.0, |p| (now as u32).wrapping_sub(p.time_ms) as f32 * 1e-3)
    }

    /// Closes the interval at `now`: its mean margin becomes a point, and with a full
    /// window the time to critical is fitted anew.
    #[cold]
    fn point(&mut self, tc: TrendConfig, now: u64) {
        let iv = &mut self.interval;
        let point = TrendPoint {
            time_ms: now as u32,
            margin: iv.sum * recip(iv.count as f32),
        };
        *iv = TrendInterval::default();
        // Points older than the window leave (after a stop, say).
        let window = u64::from(tc.interval_ms) * u64::from(tc.points);
        while let Some(old) = self.points.front() {
            if u64::from((now as u32).wrapping_sub(old.time_ms)) > window {
                self.points.pop_front();
            } else {
                break;
            }
        }
        push(&mut self.points, point, usize::from(tc.points));
        // The fit waits for a full window: a shorter one mistakes the load's
        // cycles for a drift.
        if self.points.len() < usize::from(tc.points) {
            self.time_to_critical_s = None;
            return;
        }
        let mut points = [TrendPoint::default(); TREND_CAPACITY];
        for (slot, p) in points.iter_mut().zip(self.points.iter()) {
            *slot = *p;
        }
        let n = self.points.len().min(TREND_CAPACITY);
        self.time_to_critical_s = time_to_critical(&points[..n]);
    }
}

/// Appends a point, keeping at most `points` (oldest dropped).
pub(crate) fn push(buffer: &mut TrendBuffer, point: TrendPoint, points: usize) {
    while buffer.len() >= points.clamp(1, TREND_CAPACITY) {
        buffer.pop_front();
    }
    let _ = buffer.push_back(point);
}

/// Time (s) until the fitted margin reaches zero, ahead of the newest point: `Some`
/// only when the least-squares line of margin on time is above zero at the newest
/// point, falls, and falls credibly (its slope at least
/// [`TREND_SLOPE_STANDARD_ERRORS`] of its standard errors below zero); `None`
/// otherwise (fewer than 3 points, a margin that does not fall or whose fall the
/// scatter hides, or a fit already at or below zero: a crossing in the past predicts
/// nothing). Times are taken relative to the newest point so that f32 keeps them
/// exact. `points` oldest first.
pub fn time_to_critical(points: &[TrendPoint]) -> Option<f32> {
    let newest = points.last()?.time_ms;
    let x = |p: &TrendPoint| -(newest.wrapping_sub(p.time_ms) as f32 * 1e-3);
    let (mut n, mut sx, mut sy) = (0u32, 0.0f32, 0.0f32);
    for p in points {
        n += 1;
        sx += x(p);
        sy += p.margin;
    }
    if n < 3 {
        return None;
    }
    // Divisions as products with a reciprocal (crate::recip: no division routine
    // on a core without an FPU), within 2 ulp.
    let per_n = recip(n as f32);
    let (mx, my) = (sx * per_n, sy * per_n);
    let (mut sxx, mut sxy, mut syy) = (0.0f32, 0.0f32, 0.0f32);
    for p in points {
        let (dx, dy) = (x(p) - mx, p.margin - my);
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
    }
    // Comparisons as integers where floats are soft (condition::ge).
    if !finite(sxx) || ge(0.0, sxx) {
        return None;
    }
    let slope = sxy * recip(sxx); // rad/s
    let now = my - slope * mx; // the fit at the newest point (x = 0)
    if !finite(now) || !finite(slope) || ge(0.0, now) || ge(slope, 0.0) {
        return None;
    }
    // Credible: -slope / se >= k, se^2 = (syy - slope sxy) / ((n - 2) sxx), which
    // squared is R^2 = sxy^2 / (sxx syy) >= k^2 / (n - 2 + k^2): no pass over the
    // residuals.
    let k2 = TREND_SLOPE_STANDARD_ERRORS * TREND_SLOPE_STANDARD_ERRORS;
    if !ge(sxy * sxy * ((n - 2) as f32 + k2), k2 * sxx * syy) {
        return None;
    }
    let t = now * recip(-slope);
    finite(t).then_some(t)
}
