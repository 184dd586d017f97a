//! Line contact (paper section 8) in fixed point: no table beyond log2 and exp2.

use super::elliptic::{zero_angle, zero_load};
use super::logexp::{exp2_fixed, log2_u32};
use super::uniform::ONE;
use super::{
    FixedEstimate, InputRange, LOG2_HALF_PI, Log2, Units, angle_max, constant, constant_below,
    log_risk, margin_counts, output_range_thirds, read_constant,
};
use crate::estimator::DEFAULT_RISK_SLIP_RATIO;
use crate::prepared::{Kind, PreparedError, Reader, Writer, seal, value};
use crate::reference::Regime;
use crate::{Error, Scene};
use core::f64::consts::PI;

/// A prepared line-contact scene for the fixed-point core. Loads are per unit length
/// (N/m) without a scene length, total (N) with one, as for [`crate::float::LineScene`].
#[derive(Debug, Clone, Copy)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FixedLineScene {
    /// log2 of `sqrt(pi (1 - nu) G R l) / (2 mu)` x angle LSB / sqrt(load LSB) (eq 23).
    log_slip: i32,
    /// log2 of `2 mu / sqrt(pi G (1 - nu) R l)` x sqrt(load LSB) (eq 28).
    log_critical: i32,
    /// log2(angle LSB).
    log_angle_lsb: i32,
    /// log2(mu x load LSB).
    log_force: i32,
    /// log2 of the d/b risk threshold.
    log_risk: i32,
    /// log2 of `2 sqrt((1 - nu) R / (pi G l))` x sqrt(load LSB): log2 b = this +
    /// log2(counts)/2 (eq 22).
    log_width: i32,
    /// log2 of `sqrt(G / (pi (1 - nu) R l))` x sqrt(load LSB): log2 p0 = this +
    /// log2(counts)/2 (p0 = 2 P / (pi b l)).
    log_pressure: i32,
    range: InputRange,
    /// What one count stands for (the estimator contract).
    pub(super) units: Units,
}

impl FixedLineScene {
    /// Prepares `scene` for load counts of `load_lsb` (N/m, or N with a length) and angle
    /// counts of `angle_lsb` rad.
    ///
    /// # Errors
    /// [`Error::OutOfRange`] for LSBs that are not positive and finite, an angle LSB
    /// above pi/2 (which leaves no angle count but 0), constants beyond the Q8.24
    /// range, or a sample in the declared range whose d/b, F or phi0 in counts would lie
    /// outside 2^-126 .. 2^126, where a Q8.24 log2 cannot hold it.
    pub fn new(scene: &Scene, load_lsb: f64, angle_lsb: f64) -> Result<Self, Error> {
        if !(load_lsb.is_finite() && load_lsb > 0.0 && angle_lsb.is_finite() && angle_lsb > 0.0) {
            return Err(Error::OutOfRange);
        }
        let mu = scene.friction();
        let stiffness = PI
            * (1.0 - scene.poisson_ratio())
            * scene.shear_modulus()
            * scene.effective_radius()
            * scene.length().unwrap_or(1.0);
        let root = libm::sqrt(stiffness);
        let root_lsb = libm::sqrt(load_lsb);
        let angle_counts = angle_max(angle_lsb);
        if angle_counts == 0 {
            return Err(Error::OutOfRange); // no angle count but 0 up to pi/2
        }
        // sqrt((1 - nu) R / (pi G l)), as a product of roots (no overflow).
        let sq = libm::sqrt;
        let length = scene.length().unwrap_or(1.0);
        let compliance = sq((1.0 - scene.poisson_ratio()) / PI)
            * (sq(scene.effective_radius()) / sq(scene.shear_modulus()))
            / sq(length);
        let scene = FixedLineScene {
            log_slip: constant(root / (2.0 * mu) * angle_lsb / root_lsb)?,
            log_critical: constant(2.0 * mu / root * root_lsb)?,
            log_angle_lsb: constant(angle_lsb)?,
            log_force: constant_below(mu * load_lsb)?,
            log_risk: constant(DEFAULT_RISK_SLIP_RATIO as f64)?,
            units: Units::new(load_lsb, angle_lsb)?,
            log_width: constant(2.0 * compliance * root_lsb)?,
            log_pressure: constant(root_lsb / (PI * compliance * length))?,
            range: InputRange {
                load_min: 1,
                angle_max: angle_counts, // |phi| <= pi/2
            },
        };
        scene.check_sums()?;
        Ok(scene)
    }

    /// Bounds every per-sample sum of [`FixedLineScene::estimate`] over the declared
    /// range (loads of 1 to 2^32 counts, angles of 1 to `angle_max` counts), in i64.
    // Inlined into `from_bytes`, so that a node loading a scene never builds it in
    // memory for this check and the reciprocals of its units, which a counts-only
    // node does not use, are not computed (soft-float on a Cortex-M0: 1.4 KiB).
    #[inline(always)]
    fn check_sums(&self) -> Result<(), Error> {
        // In i64 (exact, integers only: scenes loaded from bytes are checked alike),
        // times 3 for `output_range_thirds`.
        let one = ONE as i64;
        let half_lp_max = 16 * one;
        let la_max = log2_u32(self.range.angle_max) as i64 + one;
        // phi0 in counts (eq 28), what the margin is formed from.
        let critical = self.log_critical as i64 - self.log_angle_lsb as i64;
        output_range_thirds(3 * critical, 3 * (critical + half_lp_max))?;
        // d/b (eq 23): |phi| / sqrt(P).
        let slip = self.log_slip as i64;
        output_range_thirds(3 * (slip - half_lp_max), 3 * (slip + la_max))?;
        // F = mu P s (2 - s) grows like sqrt(P) in partial slip (eq 27), like P beyond.
        let force = self.log_force as i64;
        output_range_thirds(3 * i64::min(force + slip, force), 3 * (force + 32 * one))
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
    ///
    /// # Errors
    /// [`Error::Angle`] above the scene's angle range.
    #[inline]
    pub fn estimate(&self, load: u32, angle: i32) -> Result<FixedEstimate, Error> {
        let a = angle.unsigned_abs();
        if a > self.range.angle_max {
            return Err(Error::Angle);
        }
        if load == 0 {
            return Ok(zero_load(a, self.log_risk));
        }
        // Wrapping adds below never wrap: `new` bounded the constants (|log2| < 100)
        // and every sum over the declared range (`check_sums`); counts add < 32.
        let lp = log2_u32(load);
        let half_lp = lp >> 1;
        let log_phi0 = self.log_critical.wrapping_add(half_lp); // eq (28)
        // phi0 beyond pi/2 (an extreme load per length): no angle between two axes
        // reaches gross slip.
        let (critical, margin) = if log_phi0 > LOG2_HALF_PI {
            (None, None)
        } else {
            (
                Some(Log2(log_phi0)),
                Some(margin_counts(log_phi0.wrapping_sub(self.log_angle_lsb), a)),
            )
        };
        if a == 0 {
            return Ok(zero_angle(critical, margin));
        }
        let ls = self
            .log_slip
            .wrapping_add(log2_u32(a))
            .wrapping_sub(half_lp); // eq (23)
        // F / (mu P) = s (2 - s) below s = 1 (eq 27), 1 above (eq 29); never above 1.
        let (regime, log_ratio) = if ls < 0 {
            let s = exp2_fixed(ls, 24); // Q0.24, below 2^24 (ls < 0)
            // log2(2 - s) in [0, 1]: (2 - s) in Q0.24 is 2^24 .. 2^25, no wrap.
            let two_minus_s = (2u32 << 24).wrapping_sub(s);
            let log_two_minus_s = log2_u32(two_minus_s).wrapping_sub(24 << 24);
            (Regime::Partial, ls.wrapping_add(log_two_minus_s).min(0))
        } else {
            (Regime::Gross, 0)
        };
        Ok(FixedEstimate {
            slip_ratio: Log2(ls),
            regime,
            axial_force: Log2(self.log_force.wrapping_add(lp).wrapping_add(log_ratio)),
            axial_force_negative: angle < 0,
            critical_angle: critical,
            margin,
            microslip_risk: ls >= self.log_risk,
        })
    }

    /// The contact strip on request, as base-2 logarithms: half-width b (m, eq 22) and
    /// peak pressure p0 (Pa), from the load per unit length (counts / l). Zero load
    /// gives b = p0 = 0.
    ///
    /// # Errors
    /// [`Error::Angle`] above the scene's angle range.
    pub fn details(&self, load: u32, angle: i32) -> Result<FixedLineDetails, Error> {
        if angle.unsigned_abs() > self.range.angle_max {
            return Err(Error::Angle);
        }
        if load == 0 {
            return Ok(FixedLineDetails {
                b: Log2::ZERO,
                p0: Log2::ZERO,
            });
        }
        let half_lp = log2_u32(load) >> 1;
        Ok(FixedLineDetails {
            b: Log2(self.log_width.saturating_add(half_lp)),
            p0: Log2(self.log_pressure.saturating_add(half_lp)),
        })
    }
}

/// The contact strip of one sample in the fixed-point core, as base-2 logarithms.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FixedLineDetails {
    /// Half-width of the strip b (m), eq (22).
    pub b: Log2,
    /// Peak pressure p0 (Pa).
    pub p0: Log2,
}

impl FixedLineScene {
    /// The length of [`FixedLineScene::to_bytes`].
    pub const BYTES: usize = crate::prepared::OVERHEAD + Self::PAYLOAD;
    pub(super) const PAYLOAD: usize = 44;

    /// The prepared scene as bytes (format in [`crate::prepared`]).
    pub fn to_bytes(&self) -> [u8; Self::BYTES] {
        seal(Kind::FixedLine, |w| self.write(w))
    }

    /// The scene [`FixedLineScene::to_bytes`] wrote, checked with integer operations
    /// only; it answers bit for bit as the scene that wrote it.
    ///
    /// # Errors
    /// A [`PreparedError`] for a wrong length, magic, kind, version or checksum, or a
    /// constant that [`FixedLineScene::new`] does not produce.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, PreparedError> {
        Self::read(&mut Reader::open(bytes, Kind::FixedLine, Self::BYTES)?)
    }

    pub(super) fn write(&self, w: &mut Writer<'_>) -> Result<(), PreparedError> {
        let constants = [
            self.log_slip,
            self.log_critical,
            self.log_angle_lsb,
            self.log_force,
            self.log_risk,
            self.log_width,
            self.log_pressure,
        ];
        w.each(&constants, |w, x| w.i32(*x))?;
        w.u32(self.range.load_min)?;
        w.u32(self.range.angle_max)?;
        self.units.write(w)
    }

    pub(super) fn read(r: &mut Reader<'_>) -> Result<Self, PreparedError> {
        let mut c = [0i32; 7];
        for x in &mut c {
            *x = read_constant(r)?;
        }
        let scene = FixedLineScene {
            log_slip: c[0],
            log_critical: c[1],
            log_angle_lsb: c[2],
            log_force: c[3],
            log_risk: c[4],
            log_width: c[5],
            log_pressure: c[6],
            range: InputRange {
                load_min: r.u32()?,
                angle_max: r.u32()?,
            },
            units: Units::read(r)?,
        };
        value(scene.range.load_min == 1 && (1..=1 << 31).contains(&scene.range.angle_max))?;
        scene.check_sums().map_err(|_| PreparedError::Value)?;
        Ok(scene)
    }
}
