//! The elliptic contact (paper sections 5-7) in fixed point.

use super::logexp::{div3, exp2_fixed, log2_u32};
use super::tables::{
    LOG_FORCE_OVER_S, LOG_G_HIGH, LOG_G_LOW, LOG_M_HIGH, LOG_M_LOW, LOG_THETA_HIGH, LOG_THETA_LOW,
};
use super::uniform::{ONE, UniformTable};
use super::{
    FixedEstimate, InputRange, LOG2_HALF_PI, Log2, Units, constant, log_risk, margin_counts,
};
use crate::estimator::DEFAULT_RISK_SLIP_RATIO;
use crate::reference::{Regime, hertz_scale};
use crate::{Error, Scene, ThetaRelation};
use core::f64::consts::{FRAC_PI_2, PI};

/// A prepared elliptic-contact scene for the fixed-point core.
#[derive(Debug, Clone, Copy)]
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
    /// with c x LSB below 2^-40 rad, or a constant beyond the Q8.24 range).
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
        Ok(FixedEllipticScene {
            log_theta_lsb,
            log_slip: constant(slip_gain / cbrt_lsb)?,
            log_critical,
            log_radius_factor: constant(c)?,
            log_force: constant(scene.friction() * load_lsb)?,
            log_risk: constant(DEFAULT_RISK_SLIP_RATIO as f64)?,
            log_hertz: constant(v * cbrt_lsb)?,
            log_pressure: constant(3.0 * load_lsb / (2.0 * PI))?,
            units: Units::new(load_lsb, angle_lsb)?,
            range: InputRange {
                load_min: if load_min > u32::MAX as f64 {
                    u32::MAX
                } else {
                    load_min as u32
                },
                angle_max: libm::fmin(libm::floor(FRAC_PI_2 / (c * angle_lsb)), 2_147_483_648.0)
                    as u32,
            },
        })
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
    #[inline]
    pub fn estimate(&self, load: u32, angle: i32) -> Result<FixedEstimate, Error> {
        let a = angle.unsigned_abs();
        if a > self.range.angle_max {
            return Err(Error::Angle);
        }
        if load == 0 {
            return Ok(zero_load(a, self.log_risk));
        }
        if load < self.range.load_min {
            return Err(Error::OutOfRange);
        }
        let lp = log2_u32(load);
        let lp3 = div3(lp);
        // Critical angle: g(theta0) = g0 (eq 18 at d/b = 1), phi0 = theta0 / c.
        let z = self.log_critical + lp3;
        let (critical, margin) = if z > LOG2_HALF_PI {
            (None, None)
        } else {
            let log_theta0 = lookup(LOG_THETA_LOW, LOG_THETA_HIGH, z)?;
            let counts = margin_counts(log_theta0 - self.log_theta_lsb, a);
            (
                Some(Log2(log_theta0 - self.log_radius_factor)),
                Some(counts),
            )
        };
        if a == 0 {
            return Ok(zero_angle(critical, margin));
        }
        // d/b = A g(theta) P^(-1/3) (eq 16).
        let log_g = lookup(LOG_G_LOW, LOG_G_HIGH, self.log_theta_lsb + log2_u32(a))?;
        let ls = self.log_slip.saturating_add(log_g).saturating_sub(lp3);
        // F / (mu P) = s r(s) for s < 1 (eq 21), 1 beyond (eq 29).
        let (regime, log_ratio) = if ls < 0 {
            let s = exp2_fixed(ls, 24) as i32; // d/b in Q0.24
            let log_r = LOG_FORCE_OVER_S.eval(s).ok_or(Error::OutOfRange)?;
            (Regime::Partial, ls + log_r)
        } else {
            (Regime::Gross, 0)
        };
        Ok(FixedEstimate {
            slip_ratio: Log2(ls),
            regime,
            axial_force: Log2(self.log_force.saturating_add(lp).saturating_add(log_ratio)),
            axial_force_negative: angle < 0,
            critical_angle: critical,
            margin,
            microslip_risk: ls >= self.log_risk,
        })
    }
}

impl FixedEllipticScene {
    /// The contact ellipse on request: theta, m, n (eqs 4-6), a, b (eqs 2-3), p0 (eq 7),
    /// all as [`Log2`]. At zero angle m = a = infinity, n = b = p0 = 0; at zero load
    /// a = b = p0 = 0.
    ///
    /// # Errors
    /// As [`FixedEllipticScene::estimate`].
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
        let y = self.log_theta_lsb + log2_u32(a);
        let log_g = lookup(LOG_G_LOW, LOG_G_HIGH, y)?;
        let log_m = lookup(LOG_M_LOW, LOG_M_HIGH, y)?;
        let log_n = log_g - log_m - y; // n = g / (m theta)
        let (log_a, log_b, log_p0) = if load == 0 {
            (i32::MIN, i32::MIN, i32::MIN)
        } else {
            let lp = log2_u32(load);
            let log_l = self.log_hertz.saturating_add(div3(lp));
            let (la, lb) = (log_m.saturating_add(log_l), log_n.saturating_add(log_l));
            (
                la,
                lb,
                self.log_pressure
                    .saturating_add(lp)
                    .saturating_sub(la)
                    .saturating_sub(lb),
            )
        };
        Ok(FixedDetails {
            theta: Log2(y),
            m: Log2(log_m),
            n: Log2(log_n),
            a: Log2(log_a),
            b: Log2(log_b),
            p0: Log2(log_p0),
        })
    }
}

/// The contact ellipse of one sample in the fixed-point core, as base-2 logarithms:
/// theta (rad), m, n, a and b (m), p0 (Pa).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
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

/// A log-log table in two pieces, coarse below the high piece's start.
#[inline(always)]
fn lookup(low: UniformTable<'static>, high: UniformTable<'static>, x: i32) -> Result<i32, Error> {
    let table = if x < high.start { low } else { high };
    table.eval(x).ok_or(Error::OutOfRange)
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
