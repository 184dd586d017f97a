//! Friction tracking: with a measured axial force F, the friction
//! coefficient mu per sample from the inverse of eqs (16, 21) (ellipse) or (23, 27)
//! (line contact), used only where it is well-posed, filtered over time, compared with
//! a baseline captured at commissioning. A falling or rising mu is a lubrication or
//! contamination warning. The stage's state: [`FrictionStatus`].

use super::conditioning::smoothing_weight;
use super::config::FrictionConfig;
use crate::reference::inverse::Inverse;

/// What the tracker holds: the filtered mu, the baseline, the change state
/// ([`Monitor::friction_status`](super::Monitor::friction_status)).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrictionStatus {
    /// The filtered mu; meaningful once `accepted > 0`.
    pub(crate) mu: f32,
    /// The baseline mu; meaningful once `baseline_captured` (a flag rather than an
    /// `Option`: the live monitor's RAM budget).
    pub(crate) baseline: f32,
    /// Whether the baseline has been captured.
    pub(crate) baseline_captured: bool,
    /// Estimates accepted (well-posed) so far (saturating).
    pub(crate) accepted: u32,
    /// Samples with a measured F whose mu was not used (saturating).
    pub(crate) rejected: u32,
    /// Time (ms) the filtered mu has been on the other side of the band than `changed`
    /// says, over accepted samples.
    pub(crate) pending_ms: u32,
    /// Whether a friction change is raised.
    pub(crate) changed: bool,
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

    /// Estimates of mu accepted (well-posed) so far (saturating).
    pub fn accepted(&self) -> u32 {
        self.accepted
    }

    /// Samples with a measured F whose mu was not used: ill-posed (a lower bound,
    /// inconsistent, too sensitive) or refused (saturating).
    pub fn rejected(&self) -> u32 {
        self.rejected
    }

    /// Whether a friction change is raised: the filtered mu left the band around the
    /// baseline for the delay and has not come back within the band less the deadband.
    pub fn changed(&self) -> bool {
        self.changed
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
