//! Wear: the power F phi V dissipated in the microslip region (paper section 7)
//! integrated into energy, with a compensated sum that keeps its precision over years.

/// A compensated sum in f32: the running sum and what its rounding has lost so far.
/// Each term is added together with the lost part, by an error-free transformation
/// (Fast2Sum with the larger operand first), so the lost part stays below half an ulp
/// of the sum and the total's error at about one f32 ulp of it however many small
/// terms are added (a plain f32 sum of 1 mJ steps stops growing at about 16 kJ).
/// Cheap on an FPU: five additions and a compare per term, no f64.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct EnergySum {
    /// The running sum (J).
    pub sum: f32,
    /// What the rounding of `sum` lost (J), below half its ulp.
    pub compensation: f32,
}

impl EnergySum {
    /// Adds a finite term (J); a non-finite one, or one that would overflow the sum,
    /// is ignored (the monitor never passes one).
    #[inline]
    pub fn add(&mut self, term: f32) {
        let y = term + self.compensation;
        let t = self.sum + y;
        if !super::condition::finite(t) {
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
    pub fn total(&self) -> f64 {
        f64::from(self.sum) + f64::from(self.compensation)
    }
}

/// Dissipated power (W) = |F| |phi| V, section 7: the torque's power input F phi V is
/// dissipated by friction in the microslip region.
#[inline]
pub fn dissipated_power(axial_force: f32, phi: f32, speed: f32) -> f32 {
    axial_force.abs() * phi.abs() * speed
}
