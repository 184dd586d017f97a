//! Section 9's model choice per sample in f32: the ellipse, or line contact with
//! P / length when the ellipse is longer than the rollers, as `reference::estimate`.

use super::{Details, EllipticScene, Estimate, LineDetails, LineScene, check};
use crate::prepared::{
    Kind, PreparedError, Reader, choice_byte, models_present, positive_finite, positive_normal,
    read_choice, seal,
};
use crate::reference::{ContactModel, MODEL_SWITCH_BAND, ModelChoice, line_may_answer};
use crate::{Error, Scene};
use core::f32::consts::FRAC_PI_2;

/// A scene prepared for both models, choosing one per sample by a [`ModelChoice`]:
/// section 9's rule (the default, as [`crate::reference::estimate`]), or one model
/// forced, which a firmware that must not switch states explicitly. P is the total load
/// (N) when the scene has a length; without one, line contact reads it as N/m (and
/// section 9 then takes the ellipse, or line contact for a plane).
///
/// Per sample the choice costs one table read (1/m at theta) and a comparison of
/// 2a = 2 m L (eqs 2, 5-6) with the length.
#[derive(Debug, Clone, Copy)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Auto {
    /// `None` for a plane (or radii whose c underflows f32's tables).
    pub(super) elliptic: Option<EllipticScene<'static>>,
    /// `None` where line contact never answers and its constants do not fit f32.
    pub(super) line: Option<LineScene>,
    /// 2 / length (1/m); 0 without a length (the ellipse always fits).
    pub(super) two_over_length: f32,
    pub(super) choice: ModelChoice,
    /// d/b at and above which the risk flag is raised (both models).
    risk_slip_ratio: f32,
}

/// One sample's answer from an [`Auto`] scene: which model answered and its estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AutoEstimate {
    /// The model that answered.
    pub model: ContactModel,
    /// 2a / length within [`MODEL_SWITCH_BAND`] of 1: the two models differ here by a
    /// jump (d/b by up to 1.22 times, see the constant), so either answer is uncertain.
    pub near_model_switch: bool,
    /// The estimate (F in N with a length, N/m in line contact without one).
    pub estimate: Estimate,
}

/// The contact of one sample on request ([`Auto::details`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ContactDetails {
    /// The ellipse: theta, m, n, a, b, p0.
    Elliptic(Details),
    /// The strip: b, p0.
    Line(LineDetails),
}

impl Auto {
    /// Prepares `scene` for section 9's choice per sample.
    ///
    /// # Errors
    /// As [`EllipticScene::new`] (but a plane is line contact) and [`LineScene::new`].
    pub fn new(scene: &Scene) -> Result<Self, Error> {
        Self::with_choice(scene, ModelChoice::Section9)
    }

    /// Prepares `scene` for the given model choice.
    ///
    /// # Errors
    /// As [`Auto::new`]; [`Error::PlaneHasNoEllipse`] for a plane forced to the ellipse.
    pub fn with_choice(scene: &Scene, choice: ModelChoice) -> Result<Self, Error> {
        let elliptic = match EllipticScene::new(scene) {
            Ok(e) => Some(e),
            Err(Error::PlaneHasNoEllipse) if choice != ModelChoice::Elliptic => None,
            // Forced line contact needs the ellipse only for the flag near the switch.
            Err(_) if choice == ModelChoice::Line => None,
            Err(e) => return Err(e),
        };
        let two_over_length = match scene.length() {
            Some(l) => {
                let x = (2.0 / l) as f32;
                if !(x.is_normal() || x == 0.0) {
                    return Err(Error::OutOfRange);
                }
                x
            }
            None => 0.0,
        };
        // The line scene, refused only where line contact may answer.
        let line = match LineScene::new(scene) {
            Ok(l) => Some(l),
            Err(_) if !line_may_answer(scene, choice) => None,
            Err(e) => return Err(e),
        };
        Ok(Auto {
            elliptic,
            line,
            two_over_length,
            choice,
            risk_slip_ratio: crate::estimator::DEFAULT_RISK_SLIP_RATIO,
        })
    }

    /// The same scene with another d/b threshold for the risk flag (both models).
    ///
    /// # Errors
    /// [`Error::OutOfRange`] for a threshold that is not positive and finite.
    pub fn with_risk_slip_ratio(mut self, slip_ratio: f32) -> Result<Self, Error> {
        let risk = crate::estimator::check_risk(slip_ratio)?;
        self.risk_slip_ratio = risk;
        self.elliptic = match self.elliptic {
            Some(e) => Some(e.with_risk_slip_ratio(risk)?),
            None => None,
        };
        self.line = match self.line {
            Some(l) => Some(l.with_risk_slip_ratio(risk)?),
            None => None,
        };
        Ok(self)
    }

    /// The d/b threshold of the risk flag.
    pub fn risk_slip_ratio(&self) -> f32 {
        self.risk_slip_ratio
    }

    /// The model for a checked sample, and whether it is near the switch; the ellipse
    /// only when the scene has one.
    #[inline]
    pub(super) fn choose(&self, load: f32, phi: f32) -> (ContactModel, bool) {
        let Some(e) = &self.elliptic else {
            return (ContactModel::Line, false);
        };
        let ratio = if self.two_over_length == 0.0 {
            0.0
        } else {
            e.length_ratio(load, phi, self.two_over_length)
        };
        let near = (1.0 / MODEL_SWITCH_BAND as f32..=MODEL_SWITCH_BAND as f32).contains(&ratio);
        (self.choice.model(ratio > 1.0), near)
    }

    #[inline(always)]
    pub(super) fn checked(load: f32, phi: f32) -> Result<(), Error> {
        check(load, phi)?;
        if phi.abs() > FRAC_PI_2 {
            return Err(Error::Angle);
        }
        Ok(())
    }

    /// The estimate for load `load` (N; N/m in line contact without a length) and
    /// misalignment `phi` (rad, signed), by the scene's model choice.
    ///
    /// # Errors
    /// As [`EllipticScene::estimate`] and [`LineScene::estimate`].
    #[inline]
    pub fn estimate(&self, load: f32, phi: f32) -> Result<AutoEstimate, Error> {
        Self::checked(load, phi)?;
        let (model, near_model_switch) = self.choose(load, phi);
        let estimate = match (model, &self.elliptic, &self.line) {
            (ContactModel::Elliptic, Some(e), _) => e.estimate(load, phi)?,
            (_, _, Some(l)) => l.estimate(load, phi)?,
            _ => return Err(Error::OutOfRange), // not reached: see `line_may_answer`
        };
        Ok(AutoEstimate {
            model,
            near_model_switch,
            estimate,
        })
    }

    /// The contact of the model [`Auto::estimate`] chooses for this sample.
    ///
    /// # Errors
    /// As [`Auto::estimate`].
    pub fn details(&self, load: f32, phi: f32) -> Result<ContactDetails, Error> {
        Self::checked(load, phi)?;
        match (self.choose(load, phi).0, &self.elliptic, &self.line) {
            (ContactModel::Elliptic, Some(e), _) => {
                e.details(load, phi).map(ContactDetails::Elliptic)
            }
            (_, _, Some(l)) => l.details(load, phi).map(ContactDetails::Line),
            _ => Err(Error::OutOfRange), // not reached: see `line_may_answer`
        }
    }
}

impl crate::Estimator for Auto {
    type Load = f32;
    type Angle = f32;
    type Output = AutoEstimate;
    #[inline(always)]
    fn estimate(&self, load: f32, phi: f32) -> Result<AutoEstimate, Error> {
        Auto::estimate(self, load, phi)
    }
    #[inline(always)]
    fn input(&self, load: f32, phi: f32) -> Result<(f32, f32), Error> {
        Ok((load, phi))
    }
    #[inline(always)]
    fn to_estimate(&self, output: &AutoEstimate) -> Estimate {
        output.estimate
    }
    /// [`Auto::estimate`]'s `estimate` field, without building the [`AutoEstimate`]
    /// around it: its copies cost a Cortex-M4F about 400 instructions a sample
    /// (`cargo xtask bench`, the monitor's pipeline), more than the estimate itself.
    #[inline]
    fn estimate_si(&self, load: f32, phi: f32) -> Result<Estimate, Error> {
        Self::checked(load, phi)?;
        match (self.choose(load, phi).0, &self.elliptic, &self.line) {
            (ContactModel::Elliptic, Some(e), _) => e.estimate(load, phi),
            (_, _, Some(l)) => l.estimate(load, phi),
            _ => Err(Error::OutOfRange), // not reached: see `line_may_answer`
        }
    }
    fn risk_slip_ratio(&self) -> f32 {
        Auto::risk_slip_ratio(self)
    }
    fn with_risk_slip_ratio(self, slip_ratio: f32) -> Result<Self, Error> {
        Auto::with_risk_slip_ratio(self, slip_ratio)
    }
}

impl Auto {
    /// The length of [`Auto::to_bytes`].
    pub const BYTES: usize =
        crate::prepared::OVERHEAD + 1 + EllipticScene::PAYLOAD + 1 + LineScene::PAYLOAD + 9;

    /// The prepared scene as bytes (format in [`crate::prepared`]): both models'
    /// constants (each after a flag byte, zeros when absent), 2 / length, the model
    /// choice and the risk threshold. The ellipse loads with the full tables.
    pub fn to_bytes(&self) -> [u8; Self::BYTES] {
        seal(Kind::Auto, |w| {
            w.option(self.elliptic.as_ref(), EllipticScene::PAYLOAD, |w, e| {
                e.write(w)
            })?;
            w.option(self.line.as_ref(), LineScene::PAYLOAD, |w, l| l.write(w))?;
            w.f32(self.two_over_length)?;
            w.u8(choice_byte(self.choice))?;
            w.f32(self.risk_slip_ratio)
        })
    }

    /// The scene [`Auto::to_bytes`] wrote, checked on the bits of its constants (no
    /// floating-point operation); it answers bit for bit as the scene that wrote it.
    ///
    /// # Errors
    /// A [`PreparedError`] for a wrong length, magic, kind, version or checksum, or a
    /// constant that [`Auto::new`] does not produce.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, PreparedError> {
        let r = &mut Reader::open(bytes, Kind::Auto, Self::BYTES)?;
        let elliptic = r.option(EllipticScene::PAYLOAD, |r| {
            EllipticScene::read(r, super::Tables::FULL)
        })?;
        let line = r.option(LineScene::PAYLOAD, LineScene::read)?;
        let two_over_length = r.f32()?;
        if two_over_length.to_bits() != 0 {
            positive_normal(two_over_length)?;
        }
        let choice = read_choice(r)?;
        let risk_slip_ratio = positive_finite(r.f32()?)?;
        models_present(choice, elliptic.is_some(), line.is_some())?;
        Ok(Auto {
            elliptic,
            line,
            two_over_length,
            choice,
            risk_slip_ratio,
        })
    }
}
