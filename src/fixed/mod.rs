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
//! The `fixed` crate was weighed and not used: its types fix the binary point at compile
//! time, while these quantities span ten decades per scene and need a per-value
//! exponent; a Q8.24 logarithm is one.

pub mod logexp;
pub mod uniform;

mod elliptic;
mod line;

pub use elliptic::{FixedDetails, FixedEllipticScene};
pub use line::FixedLineScene;

use crate::Error;
use crate::reference::Regime;
use logexp::exp2_fixed;
use uniform::ONE;

/// A positive quantity as its base-2 logarithm in Q8.24: `x = 2^(self.0 / 2^24)`.
/// `i32::MIN` stands for 0 and `i32::MAX` for +infinity.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
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
pub struct InputRange {
    /// Smallest non-zero load in counts (0 is accepted too); below it the critical
    /// angle would fall under the tables (theta0 < 2^-40).
    pub load_min: u32,
    /// Largest |angle| in counts: theta <= pi/2 (eq 4).
    pub angle_max: u32,
}

/// The per-sample answer of the fixed-point core. Units: N (N/m for line contact
/// without a length), rad, angle counts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
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
    /// reaches d/b = 1.
    pub critical_angle: Option<Log2>,
    /// `phi0 - |phi|` in angle counts, saturating at the i32 range.
    pub margin: Option<i32>,
    /// d/b at or above the scene's risk threshold.
    pub microslip_risk: bool,
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

/// log2(pi/2) in Q8.24: g and theta above it have no table (eq 18 has no solution).
const LOG2_HALF_PI: i32 = 10_930_291;

/// `counts - a`, saturating to i32, from the critical angle in counts' log2.
#[inline(always)]
fn margin_counts(log_phi0_counts: i32, a: u32) -> i32 {
    let phi0 = exp2_fixed(log_phi0_counts, 0) as i64;
    (phi0 - a as i64).clamp(i32::MIN as i64, i32::MAX as i64) as i32
}

/// Q8.24 log2 of a positive f64 scene constant, within +-100. The per-sample sums
/// that add such constants to logarithms of counts are bounded when the scene is
/// prepared ([`output_range`]), so that they cannot leave the i32 range.
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

/// [`Error::OutOfRange`] unless the bounds `lo..=hi` of a per-sample log2 (Q8.24, worked
/// out in f64, exact for these integers, when a scene is prepared) lie within
/// [`LOG2_RESULT_LIMIT`]. A scene that passes adds its per-sample logarithms with
/// wrapping (never wrapping) arithmetic, and none of its results stands for 0 or
/// infinity at a load above 0.
fn output_range(lo: f64, hi: f64) -> Result<(), Error> {
    let limit = LOG2_RESULT_LIMIT as f64;
    if -limit <= lo && hi <= limit {
        Ok(())
    } else {
        Err(Error::OutOfRange)
    }
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
