//! The fixed-point core, for microcontrollers without an FPU (Cortex-M0, M3).
//!
//! Inputs are integers in units the scene declares: load counts (`u32`, N per count,
//! or N/m for line contact without a length) and angle counts (`i32`, rad per count).
//! Inside, it is a logarithmic number system: every quantity is its base-2 logarithm
//! in Q8.24 ([`Log2`]), so the products and powers of eqs (16), (18), (21) and (23)-(28)
//! become additions, a shift and a division by 3; only the per-scene constants are
//! computed in floating point, once. Outputs keep their relative precision over the
//! whole range (d/b from 1e-6 to 1e4 alike), which no fixed binary point could.
//!
//! Each prepared scene states the input range it accepts ([`InputRange`]); outside it
//! the answer is a typed error, never a wrapped value.
//!
//! Inverse estimates (mu or phi from a measured axial force) exist in the reference and
//! the f32 core only; [`crate::float::inverse`] says why not here.
//!
//! The `fixed` crate was weighed and not used: its types fix the binary point at compile
//! time, while these quantities span ten decades per scene and need a per-value
//! exponent; a Q8.24 logarithm is one.

mod auto;
mod elliptic;
mod line;
internal! {
    /// Q8.24 log2, exp2 and division by 3.
    mod logexp;
}
internal! {
    /// The generated tables of the fixed-point core.
    #[rustfmt::skip]
    mod tables;
}
internal! {
    /// Uniform Q8.24 tables with quadratic interpolation.
    mod uniform;
}

pub use auto::{FixedAuto, FixedAutoEstimate, FixedContactDetails};
pub use elliptic::{FixedDetails, FixedEllipticScene};
pub use line::{FixedLineDetails, FixedLineScene};
pub use logexp::EXP2_MAX_REL_ERROR;

use crate::Error;
use crate::prepared::{PreparedError, Reader, Writer};
use crate::reference::Regime;
use logexp::exp2_fixed;
use uniform::ONE;

/// A positive quantity as its base-2 logarithm in Q8.24: `x = 2^(self.0 / 2^24)`.
/// `i32::MIN` stands for 0 and `i32::MAX` for +infinity.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Log2(pub i32);

impl Log2 {
    /// Stands for 0.
    pub const ZERO: Log2 = Log2(i32::MIN);
    /// Stands for +infinity.
    pub const INFINITY: Log2 = Log2(i32::MAX);

    /// The logarithm of a positive finite f64 (scene preparation, hosts, tests).
    ///
    /// # Errors
    /// [`Error::OutOfRange`] unless `|log2 x| < 127`.
    pub fn from_f64(x: f64) -> Result<Self, Error> {
        let l = libm::log2(x) * ONE as f64;
        if l.is_finite() && libm::fabs(l) < 127.0 * ONE as f64 {
            Ok(Log2(libm::round(l) as i32))
        } else {
            Err(Error::OutOfRange)
        }
    }

    /// The value as f64 (hosts, tests; links libm's exp2).
    pub fn to_f64(self) -> f64 {
        match self.0 {
            i32::MIN => 0.0,
            i32::MAX => f64::INFINITY,
            l => libm::exp2(l as f64 / ONE as f64),
        }
    }

    /// The value as f32, by integer operations only (no libm, no soft-float exp2):
    /// relative error at most [`EXP2_MAX_REL_ERROR`] plus half an f32 ulp;
    /// below f32's normal range it is 0, above it +infinity.
    pub fn to_f32(self) -> f32 {
        let l = self.0;
        if l == i32::MIN {
            return 0.0;
        }
        let biased = (l >> 24) + 127;
        if l == i32::MAX || biased >= 255 {
            return f32::INFINITY;
        }
        if biased <= 0 {
            return 0.0;
        }
        // 2^fraction with 23 fraction bits, in [2^23, 2^24).
        let mantissa = exp2_fixed(l & (ONE - 1), 23);
        // mantissa >= 2^23: wrapping only where the proof cannot see it (no overflow).
        f32::from_bits(((biased as u32) << 23).wrapping_add(mantissa.wrapping_sub(1 << 23)))
    }

    /// The value as an unsigned fixed-point number with `frac_bits` fraction bits,
    /// truncated, saturating at `u32::MAX`.
    pub fn to_fixed(self, frac_bits: u32) -> u32 {
        match self.0 {
            i32::MIN => 0,
            i32::MAX => u32::MAX,
            l => exp2_fixed(l, frac_bits),
        }
    }
}

/// What a prepared fixed-point scene accepts per sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct InputRange {
    /// Smallest non-zero load in counts (0 is accepted too); below it the critical
    /// angle would fall under the tables (theta0 < 2^-40).
    pub load_min: u32,
    /// Largest |angle| in counts: |phi| <= pi/2 (so theta <= pi/2, eq 4).
    pub angle_max: u32,
}

/// The per-sample answer of the fixed-point core. Units: N (N/m for line contact
/// without a length), rad, angle counts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FixedEstimate {
    /// log2 of the slip ratio d/b; [`Log2::ZERO`] at zero angle, [`Log2::INFINITY`] at
    /// zero load.
    pub slip_ratio: Log2,
    /// Partial slip (d/b < 1) or gross slip.
    pub regime: Regime,
    /// log2 of |F| in N (eqs 21, 27, 29).
    pub axial_force: Log2,
    /// True when F is negative (it has the sign of phi).
    pub axial_force_negative: bool,
    /// log2 of the critical angle phi0 in rad at this load; `None` when no theta <= pi/2
    /// reaches d/b = 1 or phi0 would pass pi/2 (log2 above log2(pi/2) in Q8.24): no
    /// angle between two axes reaches gross slip.
    pub critical_angle: Option<Log2>,
    /// `phi0 - |phi|` in angle counts, saturating at the i32 range.
    pub margin: Option<i32>,
    /// d/b at or above the scene's risk threshold.
    pub microslip_risk: bool,
}

/// The units of a fixed-point scene's inputs: what one count of load and of angle
/// stands for, kept in f32 to convert SI samples and answers (the estimator contract).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Units {
    /// N (or N/m) per load count.
    load_lsb: f32,
    /// rad per angle count.
    angle_lsb: f32,
    /// Load counts per N and angle counts per rad as [`split`] gives them: the
    /// per-sample conversion multiplies their significands in integers.
    per_load: (u32, i32),
    per_angle: (u32, i32),
}

/// A finite non-negative f32's significand (below 2^24, the leading one of a normal
/// number included) and the power of two it is scaled by: `x = significand
/// 2^exponent`.
#[inline(always)]
fn split(bits: u32) -> (u32, i32) {
    let field = (bits >> 23) as i32;
    if field == 0 {
        (bits, -149) // zero or subnormal
    } else {
        (bits & 0x007f_ffff | 0x0080_0000, field - 150)
    }
}

/// `a b` for `a`, `b` below 2^24, exact: four 12-bit products, so that a core
/// without a long multiply (a Cortex-M0) calls no 64-bit multiplication routine.
#[inline(always)]
fn mul24(a: u32, b: u32) -> u64 {
    let (a1, a0, b1, b0) = (a >> 12, a & 0xfff, b >> 12, b & 0xfff);
    // Each product is below 2^24 and `mid` below 2^25: no overflow in u32 (wrapping:
    // the compiler cannot see the operands' range through a stored scale).
    let mid = a1.wrapping_mul(b0).wrapping_add(a0.wrapping_mul(b1));
    (u64::from(a1.wrapping_mul(b1)) << 24)
        .wrapping_add(u64::from(mid) << 12)
        .wrapping_add(u64::from(a0.wrapping_mul(b0)))
}

/// `|x| scale` rounded to the nearest integer (halves up), for a finite `x` and a
/// positive normal `scale` given as [`split`] gives it; `None` above `max`. Exact in
/// integers: one rounding, where `x * scale + 0.5` in f32 rounds twice, and no
/// soft-float call on a core without an FPU (a Cortex-M0 pays some 160 instructions
/// for that multiply and add, this some 40; the benchmark's `monitor` row). Out of
/// line: one copy for load and angle in a node's 16 KiB of flash.
#[inline(never)]
fn counts_of(x: f32, (significand, exponent): (u32, i32), max: u32) -> Option<u32> {
    let (m, e) = split(x.to_bits() & 0x7fff_ffff);
    // |x| scale = p 2^-shift, p below 2^48.
    let p = mul24(m, significand);
    // Both exponents lie in -149..=104 (`split`): no overflow.
    let shift = e.wrapping_add(exponent).wrapping_neg();
    if shift <= 0 {
        // At least 2^46 counts: beyond every count range.
        return None;
    }
    // The shift on the two 32-bit halves: a 64-bit shift by a variable amount is a
    // routine call on a Cortex-M0.
    let (hi, lo, shift) = ((p >> 32) as u32, p as u32, shift as u32);
    let (counts, half) = if shift < 32 {
        if hi >> shift != 0 {
            return None; // 2^32 counts or more
        }
        // 1 <= shift < 32.
        let up = 32u32.wrapping_sub(shift);
        (
            (hi << up) | (lo >> shift),
            (lo >> shift.wrapping_sub(1)) & 1,
        )
    } else if shift < 64 {
        let s = shift.wrapping_sub(32);
        let half = if s == 0 {
            lo >> 31
        } else {
            (hi >> s.wrapping_sub(1)) & 1
        };
        (hi >> s, half)
    } else {
        (0, 0) // below 2^-16 counts
    };
    counts.checked_add(half).filter(|&c| c <= max)
}

impl Units {
    /// The units of LSBs already checked positive and finite.
    pub(crate) fn new(load_lsb: f64, angle_lsb: f64) -> Result<Self, Error> {
        let (load_lsb, angle_lsb) = (load_lsb as f32, angle_lsb as f32);
        if load_lsb.is_normal() && angle_lsb.is_normal() {
            Ok(Units::of(load_lsb, angle_lsb))
        } else {
            Err(Error::OutOfRange)
        }
    }

    /// The units of two positive normal f32 LSBs, their reciprocals formed once here
    /// (the same way whether prepared on the node or loaded from bytes).
    fn of(load_lsb: f32, angle_lsb: f32) -> Self {
        Units {
            load_lsb,
            angle_lsb,
            // Reciprocals without a division (crate::recip, within 1 ulp): no
            // division routine in a node's flash.
            per_load: split(crate::recip::recip(load_lsb).to_bits()),
            per_angle: split(crate::recip::recip(angle_lsb).to_bits()),
        }
    }

    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Result<(), PreparedError> {
        w.f32(self.load_lsb)?;
        w.f32(self.angle_lsb)
    }

    /// Units from prepared bytes: both positive normal f32, as [`Units::new`] makes them.
    pub(crate) fn read(r: &mut Reader<'_>) -> Result<Self, PreparedError> {
        let load_lsb = crate::prepared::positive_normal(r.f32()?)?;
        let angle_lsb = crate::prepared::positive_normal(r.f32()?)?;
        Ok(Units::of(load_lsb, angle_lsb))
    }

    /// A sample in N and rad as counts, rounded to the nearest.
    #[inline]
    pub(crate) fn counts(&self, load: f32, phi: f32) -> Result<(u32, i32), Error> {
        // The checks on the bits: integer comparisons, where soft float would call a
        // comparison routine for each (a Cortex-M0).
        let load_bits = load.to_bits();
        // Finite and not below 0 (-0 is 0): not NaN, negative or infinite.
        if load_bits > f32::MAX.to_bits() && load_bits != (-0.0f32).to_bits() {
            return Err(Error::Load);
        }
        if phi.to_bits() & 0x7fff_ffff > f32::MAX.to_bits() {
            return Err(Error::Angle);
        }
        let (Some(load), Some(angle)) = (
            counts_of(load, self.per_load, u32::MAX),
            counts_of(phi, self.per_angle, i32::MAX as u32),
        ) else {
            return Err(Error::OutOfRange);
        };
        // angle <= i32::MAX: fits, and so does its negation.
        let angle = angle as i32;
        Ok((
            load,
            if phi.is_sign_negative() {
                angle.wrapping_neg()
            } else {
                angle
            },
        ))
    }

    /// A fixed-point answer in SI f32 (a margin saturated at the i32 range of counts
    /// stays saturated: choose the angle LSB so that the margins of interest fit).
    #[inline]
    pub(crate) fn estimate(&self, e: &FixedEstimate) -> crate::Estimate {
        let force = e.axial_force.to_f32();
        crate::Estimate {
            slip_ratio: e.slip_ratio.to_f32(),
            regime: e.regime,
            axial_force: if e.axial_force_negative {
                -force
            } else {
                force
            },
            critical_angle: e.critical_angle.map(Log2::to_f32),
            margin: e.margin.map(|m| m as f32 * self.angle_lsb),
            microslip_risk: e.microslip_risk,
        }
    }
}

/// The estimator contract for the fixed-point scenes: counts in, [`FixedEstimate`]
/// out; [`Estimator::estimate_si`] converts through the scene's [`Units`].
macro_rules! fixed_estimator {
    ($($scene:ty),*) => {$(
        impl crate::Estimator for $scene {
            type Load = u32;
            type Angle = i32;
            type Output = FixedEstimate;
            #[inline(always)]
            fn estimate(&self, load: u32, angle: i32) -> Result<FixedEstimate, Error> {
                <$scene>::estimate(self, load, angle)
            }
            #[inline(always)]
            fn input(&self, load: f32, phi: f32) -> Result<(u32, i32), Error> {
                self.units.counts(load, phi)
            }
            #[inline(always)]
            fn to_estimate(&self, output: &FixedEstimate) -> crate::Estimate {
                self.units.estimate(output)
            }
            fn risk_slip_ratio(&self) -> f32 {
                <$scene>::risk_slip_ratio(self)
            }
            fn with_risk_slip_ratio(self, slip_ratio: f32) -> Result<Self, Error> {
                <$scene>::with_risk_slip_ratio(self, slip_ratio)
            }
        }
    )*};
}

fixed_estimator!(FixedEllipticScene, FixedLineScene);

/// The Q8.24 log2 of a risk threshold (positive and finite).
fn log_risk(slip_ratio: f32) -> Result<i32, Error> {
    constant(crate::estimator::check_risk(slip_ratio)? as f64)
}

/// An LSB for which `x = counts x LSB` holds exactly (to f64 rounding) with an integer
/// `counts <= max_counts`, and `LSB >= min_lsb`: for hosts that feed recorded values to
/// the fixed-point core (the CSV estimator, tests). Returns `(LSB, counts)`; x = 0 gives
/// counts 0 and the LSB `max(min_lsb, 1e-9)`.
pub fn exact_lsb(x: f64, max_counts: u32, min_lsb: f64) -> (f64, u32) {
    let x = libm::fabs(x);
    if x == 0.0 || !x.is_finite() {
        return (libm::fmax(min_lsb, 1e-9), 0);
    }
    let counts = libm::fmin(libm::fmax(libm::floor(x / min_lsb), 1.0), max_counts as f64);
    (x / counts, counts as u32)
}

/// Largest angle count with counts x `angle_lsb` <= pi/2 as f64 has it (the angle
/// between two axes is at most a right angle; `FRAC_PI_2` lies below the true pi/2,
/// and the reference accepts it), at most 2^31.
fn angle_max(angle_lsb: f64) -> u32 {
    let half_pi = core::f64::consts::FRAC_PI_2;
    let mut n = libm::floor(half_pi / angle_lsb);
    // The quotient's rounding may put n one count off, either way.
    if n * angle_lsb > half_pi {
        n -= 1.0;
    } else if (n + 1.0) * angle_lsb <= half_pi {
        n += 1.0;
    }
    libm::fmin(libm::fmax(n, 0.0), 2_147_483_648.0) as u32
}

/// log2(pi/2) in Q8.24: g and theta above it have no table (eq 18 has no solution).
const LOG2_HALF_PI: i32 = 10_930_291;

/// `counts - a`, saturating to i32, from the critical angle in counts' log2.
#[inline(always)]
fn margin_counts(log_phi0_counts: i32, a: u32) -> i32 {
    // A difference of two finite logarithms (the critical angle's and one count's).
    let phi0 = logexp::exp2_finite(log_phi0_counts, 0);
    if (phi0 | a) < 1 << 31 {
        // Both fit i32 and are non-negative: the difference cannot wrap.
        (phi0 as i32).wrapping_sub(a as i32)
    } else {
        (phi0 as i64 - a as i64).clamp(i32::MIN as i64, i32::MAX as i64) as i32
    }
}

/// Q8.24 log2 of a positive f64 scene constant, within +-100. The per-sample sums
/// that add such constants to logarithms of counts are bounded when the scene is
/// prepared ([`output_range_thirds`]), so that they cannot leave the i32 range.
fn constant(x: f64) -> Result<i32, Error> {
    let l = Log2::from_f64(x)?.0;
    if l.unsigned_abs() < 100 << 24 {
        Ok(l)
    } else {
        Err(Error::OutOfRange)
    }
}

/// [`constant`] rounded down, less one unit: with it, `this + log2_u32(P)` stays
/// below `log2(x P)`, since [`logexp::log2_u32`] exceeds log2 by less than one unit
/// ([`logexp::LOG2_MAX_EXCESS`]). For F = mu P in gross slip (eq 29): |F| <= mu P.
fn constant_below(x: f64) -> Result<i32, Error> {
    constant(x)?;
    let l = libm::floor(libm::log2(x) * ONE as f64) as i32;
    Ok(l.saturating_sub(1))
}

/// The largest |log2| (Q8.24) of a per-sample result: one octave inside what
/// [`Log2::from_f64`] accepts, and far from the values that stand for 0 and infinity.
const LOG2_RESULT_LIMIT: i64 = 126 << 24;

/// [`Error::OutOfRange`] unless the bounds `lo..=hi` of a per-sample log2 (Q8.24),
/// both given times 3 (exact integers, when a scene is prepared or loaded), lie within
/// [`LOG2_RESULT_LIMIT`]. A scene that passes adds its per-sample logarithms with
/// wrapping (never wrapping) arithmetic, and none of its results stands for 0 or
/// infinity at a load above 0.
fn output_range_thirds(lo: i64, hi: i64) -> Result<(), Error> {
    let limit = 3 * LOG2_RESULT_LIMIT;
    if -limit <= lo && hi <= limit {
        Ok(())
    } else {
        Err(Error::OutOfRange)
    }
}

/// A Q8.24 scene constant from prepared bytes: within +-100, as [`constant`] makes it.
fn read_constant(r: &mut Reader<'_>) -> Result<i32, PreparedError> {
    let l = r.i32()?;
    crate::prepared::value(l.unsigned_abs() < 100 << 24)?;
    Ok(l)
}

/// A log2 in i64 (the `details` sums of a few i32, which cannot wrap i64) as [`Log2`],
/// within [`LOG2_RESULT_LIMIT`].
fn log2_result(x: i64) -> Result<Log2, Error> {
    if x.unsigned_abs() <= LOG2_RESULT_LIMIT as u64 {
        Ok(Log2(x as i32))
    } else {
        Err(Error::OutOfRange)
    }
}

#[cfg(test)]
mod tests {
    /// The integer conversion against the exact product in f64 (exact for two f32
    /// significands) rounded half up, over the exponents that matter and a spread of
    /// significands, at three scales.
    #[test]
    fn counts_are_the_rounded_product() {
        for scale in [1e2f32, 1.0 / 3e-9, 7.3e9, 3e38] {
            let split_scale = super::split(scale.to_bits());
            for bits in (0..0x5f00_0000u32).step_by(4099) {
                let x = f32::from_bits(bits);
                let exact = f64::from(x) * f64::from(scale);
                let want = (exact + 0.5).floor();
                let got = super::counts_of(x, split_scale, u32::MAX);
                if want > f64::from(u32::MAX) {
                    assert_eq!(got, None, "{x:e} {scale:e}");
                } else {
                    assert_eq!(got, Some(want as u32), "{x:e} {scale:e}");
                    assert_eq!(super::counts_of(-x, split_scale, u32::MAX), got);
                }
            }
            assert_eq!(super::counts_of(0.0, split_scale, 7), Some(0));
        }
        assert_eq!(super::mul24(0xff_ffff, 0xff_ffff), 0xff_ffffu64 * 0xff_ffff);
    }
}
