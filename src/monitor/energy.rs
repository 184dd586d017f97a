//! The energy stage: the power F phi V dissipated in the microslip region (paper
//! section 7) over each estimated sample's time step, added to the energy of the state
//! reported after it, in a compensated sum that keeps its precision over years. Its
//! state: the step's energy until that state is known.

use super::order::{finite, positive};

/// A compensated sum in f32: the running sum and what its rounding has lost so far.
/// Each term is added together with the lost part, by an error-free transformation
/// (Fast2Sum with the larger operand first), so the lost part stays below half an ulp
/// of the sum and the total's error at about one f32 ulp of it however many small
/// terms are added (a plain f32 sum of 1 mJ steps stops growing at about 16 kJ).
/// Cheap on an FPU: five additions and a compare per term, no f64.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct EnergySum {
    /// The running sum (J).
    pub(crate) sum: f32,
    /// What the rounding of `sum` lost (J), below half its ulp.
    pub(crate) compensation: f32,
}

impl EnergySum {
    /// Adds a finite term (J); a non-finite one, or one that would overflow the sum,
    /// is ignored (the monitor never passes one).
    #[inline]
    pub(crate) fn add(&mut self, term: f32) {
        let y = term + self.compensation;
        let t = self.sum + y;
        if !finite(t) {
            return;
        }
        // Fast2Sum: t + (lost) == sum + y exactly.
        // |sum| >= |y| by the bits of the absolute values (finite here): the same
        // order, and an integer comparison where floats are soft.
        self.compensation = if self.sum.abs().to_bits() >= y.abs().to_bits() {
            (self.sum - t) + y
        } else {
            (y - t) + self.sum
        };
        self.sum = t;
    }

    /// The total (J), sum and compensation added in f64.
    pub(crate) fn total(&self) -> f64 {
        f64::from(self.sum) + f64::from(self.compensation)
    }
}

/// Dissipated power (W) = |F| |phi| V, section 7: the torque's power input F phi V is
/// dissipated by friction in the microslip region.
#[inline]
pub fn dissipated_power(axial_force: f32, phi: f32, speed: f32) -> f32 {
    axial_force.abs() * phi.abs() * speed
}

/// The stage's state: the energy (J) of the current sample's step, added once the
/// state reported after the sample is known (a value of its own in the checkpoint).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Energy {
    pub(crate) step_j: f32,
}

impl Energy {
    /// The energy of an estimated sample's step: axial force `force` (N), angle `phi`
    /// (rad), speed `speed` (m/s) over `dt_s` (s).
    #[inline(always)]
    pub(crate) fn note(&mut self, force: f32, phi: f32, speed: f32, dt_s: f32) {
        self.step_j = dissipated_power(force, phi, speed) * dt_s;
    }

    /// The step's energy (J) to add to the state reported after the sample (never
    /// `Stopped`: a running sample leaves it), if above zero; then none is left.
    #[inline(always)]
    pub(crate) fn take(&mut self) -> Option<f32> {
        // Above zero (by its bits: a soft-float comparison costs more).
        if positive(self.step_j) {
            let j = self.step_j;
            self.step_j = 0.0;
            Some(j)
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn energy_keeps_its_precision_over_1e9_increments() {
        const N: u64 = 1_000_000_000;
        let unit = 1.0f32 / 1024.0; // ~1 mJ, exact in binary
        let mut compensated = EnergySum::default();
        let mut plain = 0.0f32;
        let mut counts = 0u64;
        for i in 0..N {
            let k = (i % 7 + 1) as u32;
            let term = k as f32 * unit;
            compensated.add(core::hint::black_box(term));
            plain += term;
            counts += u64::from(k);
        }
        let exact = counts as f64 / 1024.0;
        let relative = (compensated.total() - exact).abs() / exact;
        assert!(relative < 1e-6, "compensated sum off by {relative:e}");
        // The same increments in a plain f32 sum lose most of the total.
        assert!(((f64::from(plain) - exact) / exact).abs() > 0.5);
    }
}
