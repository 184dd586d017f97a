//! Friction tracking: with a measured axial force F, the friction
//! coefficient mu per sample from the inverse of eqs (16, 21) (ellipse) or (23, 27)
//! (line contact), used only where it is well-posed, filtered over time, compared with
//! a baseline captured at commissioning. A falling or rising mu is a lubrication or
//! contamination warning.

use super::condition::smoothing_weight;
use crate::reference::inverse::Inverse;

/// How mu is tracked: which answers count, the filter, the baseline and the band.
/// Times in ms or s as named; mu is dimensionless.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrictionConfig {
    /// An exact mu counts only when its sensitivity `d ln mu / d ln F` is at most this
    /// (> 0): near the no-slip limit a small error in F is a large one in mu. (Lower
    /// bounds, where F saturates in gross slip, and inconsistent answers never count.)
    pub sensitivity_max: f32,
    /// Time constant (s, > 0) of the exponential filter of mu, whose weight
    /// `1 - exp(-dt / tau)` follows the time step of the sample, like the smoothing of
    /// load and angle.
    pub tau_s: f32,
    /// The baseline is captured once the machine has run this long (ms, from its start,
    /// as the start-up inhibit) ...
    pub baseline_after_ms: u32,
    /// ... and at least this many estimates were accepted (>= 1).
    pub baseline_after_estimates: u32,
    /// The relative band around the baseline (> 0): a change is raised when
    /// `|mu / baseline - 1| > band`.
    pub band: f32,
    /// The change clears when `|mu / baseline - 1| < band - deadband` (0 <= deadband <
    /// band).
    pub deadband: f32,
    /// Raising and clearing wait until the filtered mu has stayed on the other side for
    /// this long (ms), counted over the accepted samples' time steps.
    pub delay_ms: u32,
}

impl Default for FrictionConfig {
    /// For the demo scene sampled about once a second: exact answers with a
    /// sensitivity up to 10, a 60 s filter, the baseline after 10 minutes of running
    /// and 100 accepted estimates, a band of 20 % with 5 % deadband, 60 s delay.
    fn default() -> Self {
        FrictionConfig {
            sensitivity_max: 10.0,
            tau_s: 60.0,
            baseline_after_ms: 600_000,
            baseline_after_estimates: 100,
            band: 0.2,
            deadband: 0.05,
            delay_ms: 60_000,
        }
    }
}

impl FrictionConfig {
    /// Whether the values are consistent (see the fields).
    pub(crate) fn is_valid(&self) -> bool {
        let positive = |x: f32| x.is_finite() && x > 0.0;
        positive(self.sensitivity_max)
            && positive(self.tau_s)
            && self.baseline_after_estimates >= 1
            && positive(self.band)
            && self.deadband.is_finite()
            && self.deadband >= 0.0
            && self.deadband < self.band
    }
}

/// What the tracker holds: the filtered mu, the baseline, the change state.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrictionStatus {
    /// The filtered mu; meaningful once `accepted > 0`.
    pub mu: f32,
    /// The baseline mu; meaningful once `baseline_captured` (a flag rather than an
    /// `Option`: the live monitor's RAM budget).
    pub baseline: f32,
    /// Whether the baseline has been captured.
    pub baseline_captured: bool,
    /// Estimates accepted (well-posed) so far (saturating).
    pub accepted: u32,
    /// Samples with a measured F whose mu was not used: ill-posed (a lower bound,
    /// inconsistent, too sensitive) or refused (saturating).
    pub rejected: u32,
    /// Time (ms) the filtered mu has been on the other side of the band than `changed`
    /// says, over accepted samples.
    pub pending_ms: u32,
    /// Whether a friction change is raised.
    pub changed: bool,
}

impl FrictionStatus {
    pub(crate) const fn new() -> Self {
        FrictionStatus {
            mu: 0.0,
            baseline: 0.0,
            baseline_captured: false,
            accepted: 0,
            rejected: 0,
            pending_ms: 0,
            changed: false,
        }
    }

    /// The filtered mu, `None` before the first accepted estimate.
    pub fn filtered(&self) -> Option<f32> {
        (self.accepted > 0).then_some(self.mu)
    }

    /// The baseline, `None` before it is captured.
    pub fn baseline(&self) -> Option<f32> {
        self.baseline_captured.then_some(self.baseline)
    }

    /// Offers one sample's inverse over a step of `dt_ms`; `running_ms` is how long the
    /// machine has run. Returns `Some(changed)` when the change state flips.
    pub(crate) fn offer(
        &mut self,
        config: &FrictionConfig,
        answer: Option<Inverse<f32>>,
        dt_ms: u32,
        running_ms: u64,
    ) -> Option<bool> {
        let value = match answer {
            Some(Inverse::Exact { value, sensitivity })
                if value.is_finite()
                    && value > 0.0
                    && sensitivity.is_finite()
                    && sensitivity <= config.sensitivity_max =>
            {
                value
            }
            _ => {
                self.rejected = self.rejected.saturating_add(1);
                return None;
            }
        };
        if self.accepted == 0 {
            self.mu = value;
        } else {
            let w = smoothing_weight(dt_ms as f32 * 1e-3, config.tau_s);
            self.mu += w * (value - self.mu);
        }
        self.accepted = self.accepted.saturating_add(1);
        let Some(baseline) = self.baseline() else {
            if self.accepted >= config.baseline_after_estimates
                && running_ms >= u64::from(config.baseline_after_ms)
            {
                self.baseline = self.mu;
                self.baseline_captured = true;
            }
            return None;
        };
        let deviation = (self.mu / baseline - 1.0).abs();
        let other_side = if self.changed {
            deviation < config.band - config.deadband
        } else {
            deviation > config.band
        };
        if !other_side {
            self.pending_ms = 0;
            return None;
        }
        self.pending_ms = self.pending_ms.saturating_add(dt_ms);
        if self.pending_ms < config.delay_ms {
            return None;
        }
        self.pending_ms = 0;
        self.changed = !self.changed;
        Some(self.changed)
    }

    /// Takes the filtered mu as the baseline now (commissioning on demand); `None`
    /// before the first accepted estimate. Returns the baseline and whether a raised
    /// change was cleared by it.
    pub(crate) fn capture(&mut self) -> Option<(f32, bool)> {
        let mu = self.filtered()?;
        self.baseline = mu;
        self.baseline_captured = true;
        self.pending_ms = 0;
        let cleared = self.changed;
        self.changed = false;
        Some((mu, cleared))
    }
}
