//! The elliptic contact (paper sections 5-7) in fixed point.

use super::logexp::{div3, exp2_finite, log2_positive, log2_u32};
use super::tables::{
    LOG_FORCE_OVER_S, LOG_G_HIGH, LOG_G_LOW, LOG_M_HIGH, LOG_M_LOW, LOG_THETA_HIGH, LOG_THETA_LOW,
};
use super::uniform::{ONE, UniformTable};
use super::{
    FixedEstimate, InputRange, LOG2_HALF_PI, Log2, Units, angle_max, constant, constant_below,
    log_risk, log2_result, margin_counts, output_range_thirds, read_constant,
};
use crate::estimator::DEFAULT_RISK_SLIP_RATIO;
use crate::prepared::{Kind, PreparedError, Reader, Writer, seal, value};
use crate::reference::{Regime, hertz_scale};
use crate::{Error, Scene, ThetaRelation};
use core::f64::consts::PI;

/// A prepared elliptic-contact scene for the fixed-point core.
#[derive(Debug, Clone, Copy)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FixedEllipticScene {
    /// log2(c x angle LSB): log2 theta = this + log2(counts) (eq 4).
    log_theta_lsb: i32,
    /// log2(A) - log2(load LSB)/3: log2(d/b) = this + log2 g - log2(counts)/3 (eq 16).
    log_slip: i32,
    /// log2(1/A) + log2(load LSB)/3: log2 g0 = this + log2(counts)/3 (eq 18, d/b = 1).
    log_critical: i32,
    /// log2 c: log2 phi0 = log2 theta0 - this.
    log_radius_factor: i32,
    /// log2(mu x load LSB): log2 F = this + log2(counts) + log2(F/(mu P)).
    log_force: i32,
    /// log2 of the d/b risk threshold.
    log_risk: i32,
    /// log2(V^(1/3) x load LSB^(1/3)): log2 L = this + log2(counts)/3 (eqs 2, 3).
    log_hertz: i32,
    /// log2(3 x load LSB / (2 pi)): log2 p0 = this + log2(counts) - log2 a - log2 b (eq 7).
    log_pressure: i32,
    /// The largest log2 g0 (Q8.24) with a critical angle: phi0 = theta0 / c at most
    /// pi/2 (and g0 at most pi/2). Derived from `log_radius_factor` and the theta(g)
    /// table when the scene is prepared or loaded (not in its bytes), so that the
    /// per-sample path tests one bound.
    log_g0_max: i32,
    /// `load_min >= 1`: `estimate` tests zero load only below it.
    range: InputRange,
    /// What one count stands for (the estimator contract).
    pub(super) units: Units,
}

impl FixedEllipticScene {
    /// Prepares `scene` for loads in counts of `load_lsb` newtons and angles in counts of
    /// `angle_lsb` radians.
    ///
    /// # Errors
    /// [`Error::PlaneHasNoEllipse`], [`Error::Unsupported`] (exact theta relation), and
    /// [`Error::OutOfRange`] when the LSBs put the inputs outside the tables (an angle LSB
    /// with c x LSB below 2^-40 rad or above pi/2, which leaves no angle count but 0), a
    /// constant beyond the Q8.24 range, or a sample in the declared range whose d/b or F
    /// would lie outside 2^-126 .. 2^126 (d/b, N), where a Q8.24 log2 cannot hold it.
    pub fn new(scene: &Scene, load_lsb: f64, angle_lsb: f64) -> Result<Self, Error> {
        if scene.is_plane() {
            return Err(Error::PlaneHasNoEllipse);
        }
        if scene.theta_relation() != ThetaRelation::SmallAngle {
            return Err(Error::Unsupported);
        }
        if !(load_lsb.is_finite() && load_lsb > 0.0 && angle_lsb.is_finite() && angle_lsb > 0.0) {
            return Err(Error::OutOfRange);
        }
        let c = scene.radius_factor();
        let v = hertz_scale(scene);
        let slip_gain = PI * scene.shear_modulus() * v * v / (3.0 * scene.friction() * c);
        let cbrt_lsb = libm::cbrt(load_lsb);
        // One count must give a theta on the tables: from 2^-40 up to pi/2 (eq 4), and
        // a |phi| up to pi/2.
        let angle_counts = angle_max(angle_lsb);
        if angle_counts == 0 {
            return Err(Error::OutOfRange);
        }
        let log_theta_lsb = constant(c * angle_lsb)?;
        if log_theta_lsb < LOG_G_LOW.start {
            return Err(Error::OutOfRange);
        }
        let log_critical = constant(cbrt_lsb / slip_gain)?;
        // Smallest load whose g0 = 2^log_critical counts^(1/3) is on the table.
        let deficit = (LOG_THETA_LOW.start as f64 - log_critical as f64) / ONE as f64;
        let load_min = if deficit <= 0.0 {
            1.0
        } else {
            libm::ceil(libm::exp2(3.0 * deficit))
        };
        let load_min = if load_min > u32::MAX as f64 {
            u32::MAX
        } else {
            load_min as u32
        };
        let scene = FixedEllipticScene {
            log_theta_lsb,
            log_slip: constant(slip_gain / cbrt_lsb)?,
            log_critical,
            log_radius_factor: constant(c)?,
            log_force: constant_below(scene.friction() * load_lsb)?,
            log_risk: constant(DEFAULT_RISK_SLIP_RATIO as f64)?,
            log_hertz: constant(v * cbrt_lsb)?,
            log_pressure: constant(3.0 * load_lsb / (2.0 * PI))?,
            log_g0_max: log_g0_max(constant(c)?),
            units: Units::new(load_lsb, angle_lsb)?,
            range: InputRange {
                load_min,
                // |phi| <= pi/2; then theta = c |phi| <= pi/2 too (c <= 1).
                angle_max: angle_counts,
            },
        };
        scene.check_sums()?;
        Ok(scene)
    }

    /// Bounds every per-sample sum of [`FixedEllipticScene::estimate`] over the declared
    /// range, in i64: d/b (eq 16) and F (eqs 21, 29) must lie within
    /// [`super::LOG2_RESULT_LIMIT`]; the other sums (z, y, theta0 - theta LSB, phi0) add
    /// table values (|log2| < 42) to constants (|log2| < 100) and counts (< 32) and stay
    /// inside i32 by construction.
    // Inlined into `from_bytes`, so that a node loading a scene never builds it in
    // memory for this check and the reciprocals of its units, which a counts-only
    // node does not use, are not computed (soft-float on a Cortex-M0: 1.4 KiB).
    #[inline(always)]
    fn check_sums(&self) -> Result<(), Error> {
        // In i64 and times 3 (the thirds of log2 P exact): integers only, so that
        // scenes loaded from bytes are checked without floating point.
        let one = ONE as i64;
        let lp_min = log2_u32(self.range.load_min) as i64; // load_min >= 1
        let lp_max = 32 * one;
        // g from one angle count up to g(pi/2) = pi/2; one octave for the tables' error.
        let g_min = lookup(LOG_G_LOW, LOG_G_HIGH, self.log_theta_lsb)? as i64 - one;
        let g_max = LOG2_HALF_PI as i64 + one;
        let slip = self.log_slip as i64;
        let slip_min = 3 * (slip + g_min) - lp_max;
        let slip_max = 3 * (slip + g_max) - lp_min;
        output_range_thirds(slip_min, slip_max)?;
        // F / (mu P) = s r(s), log2 r in [0, 1.25] (eq 21), one octave for the table:
        // F grows like P^(2/3) in partial slip and like P in gross slip.
        let force = self.log_force as i64;
        let partial_min = 3 * (force + slip + g_min + lp_min - one) - lp_min;
        output_range_thirds(
            i64::min(partial_min, 3 * (force + lp_min)),
            3 * (force + lp_max),
        )
    }

    /// The finest angle LSB (rad) this scene accepts: one count must give theta >= 2^-40,
    /// where the tables start.
    pub fn min_angle_lsb(scene: &Scene) -> f64 {
        libm::exp2(LOG_G_LOW.start as f64 / ONE as f64) / scene.radius_factor() * (1.0 + 1e-12)
    }

    /// The same scene with another d/b threshold for the risk flag.
    ///
    /// # Errors
    /// [`Error::OutOfRange`] for a threshold that is not positive and finite.
    pub fn with_risk_slip_ratio(mut self, slip_ratio: f32) -> Result<Self, Error> {
        self.log_risk = log_risk(slip_ratio)?;
        Ok(self)
    }

    /// The d/b threshold of the risk flag.
    pub fn risk_slip_ratio(&self) -> f32 {
        Log2(self.log_risk).to_f32()
    }

    /// The inputs this scene accepts.
    pub fn input_range(&self) -> InputRange {
        self.range
    }

    /// The estimate for `load` counts and `angle` counts (signed).
    /// Zero angle: d/b = 0, F = 0. Zero load: d/b = inf (gross slip), F = 0, phi0 = 0.
    ///
    /// # Errors
    /// [`Error::Angle`] above the scene's angle range, [`Error::OutOfRange`] for a
    /// non-zero load below its load range.
    #[inline(always)]
    pub fn estimate(&self, load: u32, angle: i32) -> Result<FixedEstimate, Error> {
        let a = angle.unsigned_abs();
        // The angle's range is tested once, below, at both ends; where a sample is
        // refused before that, its angle is tested first.
        let refusal = |load_error| {
            if a > self.range.angle_max {
                Error::Angle
            } else {
                load_error
            }
        };
        // load_min >= 1: one compare on the common path, zero load inside it.
        if load < self.range.load_min {
            return if load == 0 && a <= self.range.angle_max {
                Ok(zero_load(a, self.log_risk))
            } else {
                Err(refusal(Error::OutOfRange))
            };
        }
        // load >= 1: log2 without its test for 0. Wrapping adds below never wrap: `new`
        // bounded the constants (|log2| < 100) and every sum over the declared range
        // (`check_sums`); counts add < 32, tables < 42.
        let lp = log2_positive(load);
        let lp3 = div3(lp);
        // Critical angle: g(theta0) = g0 (eq 18 at d/b = 1), phi0 = theta0 / c.
        let z = self.log_critical.wrapping_add(lp3);
        // No critical angle above g0 = pi/2 (eq 18), nor where phi0 = theta0 / c would
        // pass pi/2 (unequal radii): `log_g0_max` bounds both.
        let (critical, margin) = if z > self.log_g0_max {
            (None, None)
        } else {
            let log_theta0 = lookup(LOG_THETA_LOW, LOG_THETA_HIGH, z).map_err(refusal)?;
            // Both within the tables' theta range, 2^-42 .. pi/2.
            let counts = margin_counts(log_theta0.wrapping_sub(self.log_theta_lsb), a);
            (
                Some(Log2(log_theta0.wrapping_sub(self.log_radius_factor))),
                Some(counts),
            )
        };
        // Both ends of the angle's range in one unsigned compare (0 wraps above it):
        // zero angle answers with the critical angle, above the range is refused.
        if a.wrapping_sub(1) >= self.range.angle_max {
            return if a == 0 {
                Ok(zero_angle(critical, margin))
            } else {
                Err(Error::Angle)
            };
        }
        self.misaligned(a, angle < 0, (lp, lp3), critical, margin)
    }

    /// The estimate of a misaligned (`a` >= 1 counts), loaded (`load` >= load_min)
    /// sample, with log2 of its load counts and their third, and its critical angle;
    /// its wrapping adds are bounded as in `estimate`.
    #[inline(always)]
    fn misaligned(
        &self,
        a: u32,
        negative: bool,
        (lp, lp3): (i32, i32),
        critical_angle: Option<Log2>,
        margin: Option<i32>,
    ) -> Result<FixedEstimate, Error> {
        // d/b = A g(theta) P^(-1/3) (eq 16).
        let log_g = lookup(
            LOG_G_LOW,
            LOG_G_HIGH,
            self.log_theta_lsb.wrapping_add(log2_positive(a)),
        )?;
        let ls = self.log_slip.wrapping_add(log_g).wrapping_sub(lp3);
        // F / (mu P) = s r(s) for s < 1 (eq 21), 1 beyond (eq 29); never above 1.
        let (regime, log_ratio) = if ls < 0 {
            // Against s in Q0.24 (s < 1 here): one table of 524 bytes.
            let s = exp2_finite(ls, 24) as i32; // ls: a sum of finite logarithms
            let log_r = LOG_FORCE_OVER_S.eval(s).ok_or(Error::OutOfRange)?;
            (Regime::Partial, ls.wrapping_add(log_r).min(0))
        } else {
            (Regime::Gross, 0)
        };
        Ok(FixedEstimate {
            slip_ratio: Log2(ls),
            regime,
            axial_force: Log2(self.log_force.wrapping_add(lp).wrapping_add(log_ratio)),
            axial_force_negative: negative,
            critical_angle,
            margin,
            microslip_risk: ls >= self.log_risk,
        })
    }
}

impl FixedEllipticScene {
    /// log2 of the semi-axis a = m L in m (eqs 2, 5-6) for `load` counts and |angle|
    /// `abs_angle` counts within the input range: section 9's measure. [`Log2::ZERO`]
    /// at zero load, [`Log2::INFINITY`] at zero angle.
    ///
    /// # Errors
    /// [`Error::OutOfRange`] off the m table (not reached within the input range).
    #[inline]
    pub(super) fn log_semi_axis(&self, load: u32, abs_angle: u32) -> Result<Log2, Error> {
        if load == 0 {
            return Ok(Log2::ZERO);
        }
        if abs_angle == 0 {
            return Ok(Log2::INFINITY);
        }
        let y = self.log_theta_lsb.saturating_add(log2_u32(abs_angle));
        let log_m = lookup(LOG_M_LOW, LOG_M_HIGH, y)?;
        Ok(Log2(
            log_m
                .saturating_add(self.log_hertz)
                .saturating_add(div3(log2_u32(load))),
        ))
    }

    /// The contact ellipse on request: theta, m, n (eqs 4-6), a, b (eqs 2-3), p0 (eq 7),
    /// all as [`Log2`]. At zero angle m = a = infinity, n = b = p0 = 0; at zero load
    /// a = b = p0 = 0.
    ///
    /// # Errors
    /// As [`FixedEllipticScene::estimate`]; [`Error::OutOfRange`] also where a, b or p0
    /// lies outside 2^-126 .. 2^126 (m, Pa).
    pub fn details(&self, load: u32, angle: i32) -> Result<FixedDetails, Error> {
        let a = angle.unsigned_abs();
        if a > self.range.angle_max {
            return Err(Error::Angle);
        }
        if load != 0 && load < self.range.load_min {
            return Err(Error::OutOfRange);
        }
        if a == 0 {
            let (inf, zero) = (Log2::INFINITY, Log2::ZERO);
            return Ok(FixedDetails {
                theta: zero,
                m: inf,
                n: zero,
                a: inf,
                b: zero,
                p0: zero,
            });
        }
        // Within the tables, as in `estimate`.
        let y = self.log_theta_lsb.wrapping_add(log2_u32(a));
        let log_g = lookup(LOG_G_LOW, LOG_G_HIGH, y)?;
        let log_m = lookup(LOG_M_LOW, LOG_M_HIGH, y)?;
        let log_n = log_g.wrapping_sub(log_m).wrapping_sub(y); // n = g / (m theta)
        let (log_a, log_b, log_p0) = if load == 0 {
            (Log2::ZERO, Log2::ZERO, Log2::ZERO)
        } else {
            // a, b and p0 may leave the Q8.24 range where d/b and F do not: in i64
            // (sums of five i32 at most: no wrap), then a typed error for a result
            // that does not fit.
            let lp = log2_u32(load);
            let wide = |x: i32| x as i64;
            let log_l = wide(self.log_hertz).wrapping_add(wide(div3(lp)));
            let la = wide(log_m).wrapping_add(log_l);
            let lb = wide(log_n).wrapping_add(log_l);
            let lp0 = wide(self.log_pressure)
                .wrapping_add(wide(lp))
                .wrapping_sub(la)
                .wrapping_sub(lb);
            (log2_result(la)?, log2_result(lb)?, log2_result(lp0)?)
        };
        Ok(FixedDetails {
            theta: Log2(y),
            m: Log2(log_m),
            n: Log2(log_n),
            a: log_a,
            b: log_b,
            p0: log_p0,
        })
    }
}

/// The contact ellipse of one sample in the fixed-point core, as base-2 logarithms:
/// theta (rad), m, n, a and b (m), p0 (Pa).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FixedDetails {
    /// Auxiliary angle theta (rad), eq (4).
    pub theta: Log2,
    /// m (eqs 5-6).
    pub m: Log2,
    /// n (eqs 5-6).
    pub n: Log2,
    /// Semi-axis along the rollers a (m).
    pub a: Log2,
    /// Semi-axis in the rolling direction b (m).
    pub b: Log2,
    /// Peak pressure p0 (Pa).
    pub p0: Log2,
}

/// The largest log2 g0 (Q8.24, at most log2(pi/2)) whose theta0 from the table gives
/// phi0 = theta0 / c at most pi/2, for `log_c` = log2 c: a bisection on the table
/// (theta(g) increases), integers only, so that a scene loaded from bytes derives it
/// alike. Below the table's start: the start less one (no critical angle at all).
fn log_g0_max(log_c: i32) -> i32 {
    let within = |z: i32| {
        lookup(LOG_THETA_LOW, LOG_THETA_HIGH, z)
            .is_ok_and(|t| t as i64 - log_c as i64 <= LOG2_HALF_PI as i64)
    };
    let (mut lo, mut hi) = (LOG_THETA_LOW.start, LOG2_HALF_PI);
    if within(hi) {
        return hi;
    }
    if !within(lo) {
        return lo.saturating_sub(1);
    }
    // within(lo) and not within(hi), lo < hi, both within +-2^31 / 2 (table and
    // log2(pi/2)): the differences cannot wrap; 32 halvings at most.
    while hi.wrapping_sub(lo) > 1 {
        let mid = lo.wrapping_add(hi.wrapping_sub(lo) / 2);
        if within(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// A log-log table in two pieces, coarse below the high piece's start.
#[inline(always)]
fn lookup(low: UniformTable<'static>, high: UniformTable<'static>, x: i32) -> Result<i32, Error> {
    // Each branch evaluates its own table: with the spacing a constant in each, the
    // shifts and masks are immediates (selecting the table first and evaluating once
    // made them registers, about 15 instructions more on the Cortex-M0).
    let value = if x < high.start {
        low.eval(x)
    } else {
        high.eval(x)
    };
    value.ok_or(Error::OutOfRange)
}

/// Zero angle: no slip and no force; the critical angle and margin still stand.
pub(super) fn zero_angle(critical: Option<Log2>, margin: Option<i32>) -> FixedEstimate {
    FixedEstimate {
        slip_ratio: Log2::ZERO,
        regime: Regime::Partial,
        axial_force: Log2::ZERO,
        axial_force_negative: false,
        critical_angle: critical,
        margin,
        microslip_risk: false,
    }
}

/// Zero load: an unloaded contact slips wherever it is misaligned (eq 16 with P = 0).
pub(super) fn zero_load(a: u32, log_risk: i32) -> FixedEstimate {
    let slip = if a == 0 { Log2::ZERO } else { Log2::INFINITY };
    FixedEstimate {
        slip_ratio: slip,
        regime: if a == 0 {
            Regime::Partial
        } else {
            Regime::Gross
        },
        axial_force: Log2::ZERO,
        axial_force_negative: false,
        critical_angle: Some(Log2::ZERO),
        margin: Some(0i32.saturating_sub_unsigned(a)),
        microslip_risk: slip.0 >= log_risk,
    }
}

impl FixedEllipticScene {
    /// The length of [`FixedEllipticScene::to_bytes`].
    pub const BYTES: usize = crate::prepared::OVERHEAD + Self::PAYLOAD;
    pub(super) const PAYLOAD: usize = 48;

    /// The prepared scene as bytes (format in [`crate::prepared`]): for a scene
    /// prepared on a host and loaded on the node with [`FixedEllipticScene::from_bytes`].
    pub fn to_bytes(&self) -> [u8; Self::BYTES] {
        seal(Kind::FixedElliptic, |w| self.write(w))
    }

    /// The scene [`FixedEllipticScene::to_bytes`] wrote, checked with integer
    /// operations only; it answers bit for bit as the scene that wrote it.
    ///
    /// # Errors
    /// A [`PreparedError`] for a wrong length, magic, kind, version or checksum, or a
    /// constant that [`FixedEllipticScene::new`] does not produce.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, PreparedError> {
        Self::read(&mut Reader::open(bytes, Kind::FixedElliptic, Self::BYTES)?)
    }

    pub(super) fn write(&self, w: &mut Writer<'_>) -> Result<(), PreparedError> {
        let constants = [
            self.log_theta_lsb,
            self.log_slip,
            self.log_critical,
            self.log_radius_factor,
            self.log_force,
            self.log_risk,
            self.log_hertz,
            self.log_pressure,
        ];
        w.each(&constants, |w, x| w.i32(*x))?;
        w.u32(self.range.load_min)?;
        w.u32(self.range.angle_max)?;
        self.units.write(w)
    }

    pub(super) fn read(r: &mut Reader<'_>) -> Result<Self, PreparedError> {
        let mut c = [0i32; 8];
        for x in &mut c {
            *x = read_constant(r)?;
        }
        let scene = FixedEllipticScene {
            log_theta_lsb: c[0],
            log_slip: c[1],
            log_critical: c[2],
            log_radius_factor: c[3],
            log_force: c[4],
            log_risk: c[5],
            log_hertz: c[6],
            log_pressure: c[7],
            log_g0_max: log_g0_max(c[3]),
            range: InputRange {
                load_min: r.u32()?,
                angle_max: r.u32()?,
            },
            units: Units::read(r)?,
        };
        value(
            scene.log_theta_lsb >= LOG_G_LOW.start
                && scene.range.load_min >= 1
                && (1..=1 << 31).contains(&scene.range.angle_max),
        )?;
        scene.check_sums().map_err(|_| PreparedError::Value)?;
        Ok(scene)
    }
}

#[cfg(test)]
mod order_tests {
    use super::*;
    use std::vec;

    impl FixedEllipticScene {
        /// The estimate with its tests in their plain order (the angle's range, the
        /// load's, the critical angle's bound, zero angle), as it was written before the
        /// per-sample path merged them.
        fn estimate_plain(&self, load: u32, angle: i32) -> Result<FixedEstimate, Error> {
            let a = angle.unsigned_abs();
            if a > self.range.angle_max {
                return Err(Error::Angle);
            }
            if load < self.range.load_min {
                return if load == 0 {
                    Ok(zero_load(a, self.log_risk))
                } else {
                    Err(Error::OutOfRange)
                };
            }
            let lp = log2_u32(load);
            let lp3 = div3(lp);
            let z = self.log_critical.wrapping_add(lp3);
            let (critical, margin) = if z > self.log_g0_max {
                (None, None)
            } else {
                let log_theta0 = lookup(LOG_THETA_LOW, LOG_THETA_HIGH, z)?;
                let counts = margin_counts(log_theta0.wrapping_sub(self.log_theta_lsb), a);
                (
                    Some(Log2(log_theta0.wrapping_sub(self.log_radius_factor))),
                    Some(counts),
                )
            };
            if a == 0 {
                return Ok(zero_angle(critical, margin));
            }
            self.misaligned(a, angle < 0, (lp, lp3), critical, margin)
        }
    }

    /// `estimate` answers as the plain order of tests, answers and refusals alike: over
    /// scenes of equal and very unequal radii (phi0 beyond pi/2 at heavy loads), soft
    /// and stiff, frictions and LSBs over many decades (light loads whose critical
    /// angle falls off the table among them), at every edge of the angle and the load.
    #[test]
    fn merged_tests_answer_as_the_plain_order() {
        let (mut answers, mut refusals) = (0, 0);
        for (r1, r2) in [(0.05, 0.05), (0.02, 0.5), (1e-3, 1.0), (1e-6, 1e3)] {
            for (g, mu) in [(79.3e9, 0.3), (1e6, 1e-6), (1e15, 30.0)] {
                let scene = Scene::new(r1, r2, g, 0.3, mu).unwrap();
                for lp in (-60..=40).step_by(10) {
                    for la in [-40, -20, -1] {
                        let angle_lsb = f64::max(
                            libm::exp2(la as f64),
                            FixedEllipticScene::min_angle_lsb(&scene),
                        );
                        let Ok(core) =
                            FixedEllipticScene::new(&scene, libm::exp2(lp as f64), angle_lsb)
                        else {
                            continue;
                        };
                        let (min, max) = (core.range.load_min, core.range.angle_max);
                        let mut loads = vec![0, 1, 2, u32::MAX, min.saturating_sub(1)];
                        loads.extend((0..64).map(|k| min.saturating_add(k * k * k)));
                        loads.extend((0..32).map(|k| 1u32 << k));
                        let mut angles = vec![0, 1, 2, i32::MAX, i32::MIN, i32::MIN + 1];
                        angles.extend([max, max.wrapping_add(1), max / 2].map(|x| x as i32));
                        angles.extend((0..31).map(|k| 1i32 << k));
                        for &load in &loads {
                            for &angle in &angles {
                                for angle in [angle, angle.wrapping_neg()] {
                                    let want = core.estimate_plain(load, angle);
                                    assert_eq!(core.estimate(load, angle), want, "{load} {angle}");
                                    if want.is_ok() {
                                        answers += 1;
                                    } else {
                                        refusals += 1;
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
        assert!(answers > 10_000 && refusals > 1_000, "{answers} {refusals}");
    }
}
