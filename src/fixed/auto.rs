//! Section 9's model choice per sample in fixed point, as `reference::estimate` and
//! `float::Auto`: the ellipse, or line contact with P / length when 2a > length.

use super::{
    FixedDetails, FixedEllipticScene, FixedEstimate, FixedLineDetails, FixedLineScene, InputRange,
    Log2, constant,
};
use crate::prepared::{
    Kind, PreparedError, Reader, choice_byte, models_present, read_choice, seal,
};
use crate::reference::{ContactModel, MODEL_SWITCH_BAND, ModelChoice, line_may_answer};
use crate::{Error, Scene};

/// A fixed-point scene prepared for both models, choosing one per sample by a
/// [`ModelChoice`] (section 9's rule by default; a forced model for a firmware that must
/// not switch). Loads are counts of the total load (N) when the scene has a length;
/// without one, line contact reads them as N/m.
#[derive(Debug, Clone, Copy)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FixedAuto {
    /// `None` for a plane.
    elliptic: Option<FixedEllipticScene>,
    /// `None` where line contact never answers and its constants do not fit.
    line: Option<FixedLineScene>,
    /// log2(length / 2) in Q8.24; `None` without a length (the ellipse always fits).
    log_half_length: Option<i32>,
    /// log2 of [`MODEL_SWITCH_BAND`] in Q8.24.
    log_band: i32,
    choice: ModelChoice,
    /// log2 of the d/b risk threshold (both models).
    log_risk: i32,
    /// What one count stands for (the estimator contract).
    units: super::Units,
}

/// One sample's answer from a [`FixedAuto`] scene: which model answered and its estimate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FixedAutoEstimate {
    /// The model that answered.
    pub model: ContactModel,
    /// 2a / length within [`MODEL_SWITCH_BAND`] of 1, where the two models differ by a
    /// jump.
    pub near_model_switch: bool,
    /// The estimate.
    pub estimate: FixedEstimate,
}

/// The contact of one sample on request ([`FixedAuto::details`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FixedContactDetails {
    /// The ellipse: theta, m, n, a, b, p0.
    Elliptic(FixedDetails),
    /// The strip: b, p0.
    Line(FixedLineDetails),
}

impl FixedAuto {
    /// Prepares `scene` for section 9's choice per sample, with load counts of
    /// `load_lsb` N and angle counts of `angle_lsb` rad.
    ///
    /// # Errors
    /// As [`FixedEllipticScene::new`] (but a plane is line contact) and
    /// [`FixedLineScene::new`].
    pub fn new(scene: &Scene, load_lsb: f64, angle_lsb: f64) -> Result<Self, Error> {
        Self::with_choice(scene, load_lsb, angle_lsb, ModelChoice::Section9)
    }

    /// Prepares `scene` for the given model choice.
    ///
    /// # Errors
    /// As [`FixedAuto::new`]; [`Error::PlaneHasNoEllipse`] for a plane forced to the
    /// ellipse.
    pub fn with_choice(
        scene: &Scene,
        load_lsb: f64,
        angle_lsb: f64,
        choice: ModelChoice,
    ) -> Result<Self, Error> {
        let elliptic = match FixedEllipticScene::new(scene, load_lsb, angle_lsb) {
            Ok(e) => Some(e),
            Err(Error::PlaneHasNoEllipse) if choice != ModelChoice::Elliptic => None,
            // Forced line contact needs the ellipse only for the flag near the switch.
            Err(_) if choice == ModelChoice::Line => None,
            Err(e) => return Err(e),
        };
        let log_half_length = match scene.length() {
            Some(l) => Some(constant(l / 2.0)?),
            None => None,
        };
        // The line scene, refused only where line contact may answer.
        let line = match FixedLineScene::new(scene, load_lsb, angle_lsb) {
            Ok(l) => Some(l),
            Err(_) if !line_may_answer(scene, choice) => None,
            Err(e) => return Err(e),
        };
        Ok(FixedAuto {
            elliptic,
            line,
            log_half_length,
            log_band: constant(MODEL_SWITCH_BAND)?,
            choice,
            log_risk: super::log_risk(crate::estimator::DEFAULT_RISK_SLIP_RATIO)?,
            units: super::Units::new(load_lsb, angle_lsb)?,
        })
    }

    /// The same scene with another d/b threshold for the risk flag (both models).
    ///
    /// # Errors
    /// [`Error::OutOfRange`] for a threshold that is not positive and finite.
    pub fn with_risk_slip_ratio(mut self, slip_ratio: f32) -> Result<Self, Error> {
        self.log_risk = super::log_risk(slip_ratio)?;
        self.elliptic = match self.elliptic {
            Some(e) => Some(e.with_risk_slip_ratio(slip_ratio)?),
            None => None,
        };
        self.line = match self.line {
            Some(l) => Some(l.with_risk_slip_ratio(slip_ratio)?),
            None => None,
        };
        Ok(self)
    }

    /// The d/b threshold of the risk flag.
    pub fn risk_slip_ratio(&self) -> f32 {
        Log2(self.log_risk).to_f32()
    }

    /// The inputs this scene accepts: the line scene's range, and the ellipse's where
    /// it may answer (its smallest load).
    pub fn input_range(&self) -> InputRange {
        match (&self.elliptic, &self.line, self.choice) {
            (Some(e), _, ModelChoice::Elliptic) | (Some(e), None, _) => e.input_range(),
            (_, Some(l), ModelChoice::Line) | (None, Some(l), _) => l.input_range(),
            (Some(e), Some(l), _) => InputRange {
                load_min: e.input_range().load_min,
                angle_max: l.input_range().angle_max.min(e.input_range().angle_max),
            },
            (None, None, _) => InputRange {
                load_min: u32::MAX,
                angle_max: 0,
            },
        }
    }

    /// The model for `load`, `angle` counts, and whether it is near the switch.
    #[inline]
    fn choose(&self, load: u32, angle: i32) -> Result<(ContactModel, bool), Error> {
        let Some(e) = &self.elliptic else {
            return Ok((ContactModel::Line, false));
        };
        let a = angle.unsigned_abs();
        if a > e.input_range().angle_max {
            return Err(Error::Angle);
        }
        let (longer, near) = match self.log_half_length {
            None => (false, false),
            Some(half) => {
                // log2(2a / length), saturating at the ends (a = 0 or infinity).
                let excess = e.log_semi_axis(load, a)?.0 as i64 - half as i64;
                (excess > 0, excess.abs() <= self.log_band as i64)
            }
        };
        Ok((self.choice.model(longer), near))
    }

    /// The estimate for `load` counts and `angle` counts (signed), by the scene's model
    /// choice.
    ///
    /// # Errors
    /// As [`FixedEllipticScene::estimate`] and [`FixedLineScene::estimate`].
    #[inline]
    pub fn estimate(&self, load: u32, angle: i32) -> Result<FixedAutoEstimate, Error> {
        let (model, near_model_switch) = self.choose(load, angle)?;
        let estimate = match (model, &self.elliptic, &self.line) {
            (ContactModel::Elliptic, Some(e), _) => e.estimate(load, angle)?,
            (_, _, Some(l)) => l.estimate(load, angle)?,
            _ => return Err(Error::OutOfRange), // not reached: see `line_may_answer`
        };
        Ok(FixedAutoEstimate {
            model,
            near_model_switch,
            estimate,
        })
    }

    /// The contact of the model [`FixedAuto::estimate`] chooses for this sample.
    ///
    /// # Errors
    /// As [`FixedAuto::estimate`].
    pub fn details(&self, load: u32, angle: i32) -> Result<FixedContactDetails, Error> {
        match (self.choose(load, angle)?.0, &self.elliptic, &self.line) {
            (ContactModel::Elliptic, Some(e), _) => {
                e.details(load, angle).map(FixedContactDetails::Elliptic)
            }
            (_, _, Some(l)) => l.details(load, angle).map(FixedContactDetails::Line),
            _ => Err(Error::OutOfRange), // not reached: see `line_may_answer`
        }
    }
}

impl crate::Estimator for FixedAuto {
    type Load = u32;
    type Angle = i32;
    type Output = FixedAutoEstimate;
    #[inline(always)]
    fn estimate(&self, load: u32, angle: i32) -> Result<FixedAutoEstimate, Error> {
        FixedAuto::estimate(self, load, angle)
    }
    #[inline(always)]
    fn input(&self, load: f32, phi: f32) -> Result<(u32, i32), Error> {
        self.units.counts(load, phi)
    }
    #[inline(always)]
    fn to_estimate(&self, output: &FixedAutoEstimate) -> crate::Estimate {
        self.units.estimate(&output.estimate)
    }
    /// The same as the default, without building the [`FixedAutoEstimate`] around the
    /// estimate (its copies cost more than the conversion, `cargo xtask bench`).
    #[inline]
    fn estimate_si(&self, load: f32, phi: f32) -> Result<crate::Estimate, Error> {
        let (load, angle) = self.units.counts(load, phi)?;
        let estimate = match (self.choose(load, angle)?.0, &self.elliptic, &self.line) {
            (ContactModel::Elliptic, Some(e), _) => e.estimate(load, angle)?,
            (_, _, Some(l)) => l.estimate(load, angle)?,
            _ => return Err(Error::OutOfRange), // not reached: see `line_may_answer`
        };
        Ok(self.units.estimate(&estimate))
    }
    fn risk_slip_ratio(&self) -> f32 {
        FixedAuto::risk_slip_ratio(self)
    }
    fn with_risk_slip_ratio(self, slip_ratio: f32) -> Result<Self, Error> {
        FixedAuto::with_risk_slip_ratio(self, slip_ratio)
    }
}

impl FixedAuto {
    /// The length of [`FixedAuto::to_bytes`].
    pub const BYTES: usize = crate::prepared::OVERHEAD + Self::PAYLOAD;
    const PAYLOAD: usize = 1 + FixedEllipticScene::PAYLOAD + 1 + FixedLineScene::PAYLOAD + 14 + 8;

    /// The prepared scene as bytes (format in [`crate::prepared`]): both models'
    /// constants (each after a flag byte, zeros when absent), log2(length / 2) after a
    /// flag byte, log2 of the switch band, the model choice, log2 of the risk threshold
    /// and the units.
    pub fn to_bytes(&self) -> [u8; Self::BYTES] {
        seal(Kind::FixedAuto, |w| {
            w.option(
                self.elliptic.as_ref(),
                FixedEllipticScene::PAYLOAD,
                |w, e| e.write(w),
            )?;
            w.option(self.line.as_ref(), FixedLineScene::PAYLOAD, |w, l| {
                l.write(w)
            })?;
            w.option(self.log_half_length.as_ref(), 4, |w, l| w.i32(*l))?;
            w.i32(self.log_band)?;
            w.u8(choice_byte(self.choice))?;
            w.i32(self.log_risk)?;
            self.units.write(w)
        })
    }

    /// The scene [`FixedAuto::to_bytes`] wrote, checked with integer operations only;
    /// it answers bit for bit as the scene that wrote it.
    ///
    /// # Errors
    /// A [`PreparedError`] for a wrong length, magic, kind, version or checksum, or a
    /// constant that [`FixedAuto::new`] does not produce.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, PreparedError> {
        let r = &mut Reader::open(bytes, Kind::FixedAuto, Self::BYTES)?;
        let elliptic = r.option(FixedEllipticScene::PAYLOAD, FixedEllipticScene::read)?;
        let line = r.option(FixedLineScene::PAYLOAD, FixedLineScene::read)?;
        let log_half_length = r.option(4, super::read_constant)?;
        let log_band = super::read_constant(r)?;
        let choice = read_choice(r)?;
        let log_risk = super::read_constant(r)?;
        let units = super::Units::read(r)?;
        // The model a choice forces is there, and some model is.
        models_present(choice, elliptic.is_some(), line.is_some())?;
        Ok(FixedAuto {
            elliptic,
            line,
            log_half_length,
            log_band,
            choice,
            log_risk,
            units,
        })
    }
}
