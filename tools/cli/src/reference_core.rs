//! The f64 reference as an estimator the condition monitor runs on the PC
//! (`cargo run --example monitor -- --model reference`): every sample through the
//! whole paper (`misalign::reference::estimate_with`), its answer rounded to the
//! [`Estimate`] the monitor reads, so that a replay on the reference shows which events
//! are the physics' and which a core's rounding. No firmware runs it (its cost per
//! sample is in docs/measurements.md's estimate table).

use misalign::estimator::DEFAULT_RISK_SLIP_RATIO;
use misalign::reference::inverse::{self, Inverse};
use misalign::reference::{self, ContactModel, ModelChoice};
use misalign::{Error, Estimate, Estimator, FrictionInverse, Scene};

/// The reference over one scene with one contact model choice (section 9's for an
/// operating range, as the cores are built: `monitor::model_for_range`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReferenceCore {
    scene: Scene,
    choice: ModelChoice,
    risk_slip_ratio: f32,
}

impl ReferenceCore {
    /// The reference over `scene`, the contact model chosen by `choice`.
    ///
    /// # Errors
    /// [`Error::PlaneHasNoEllipse`] for a plane forced to the ellipse.
    pub fn with_choice(scene: &Scene, choice: ModelChoice) -> Result<Self, Error> {
        if choice == ModelChoice::Elliptic && scene.is_plane() {
            return Err(Error::PlaneHasNoEllipse);
        }
        Ok(ReferenceCore {
            scene: *scene,
            choice,
            risk_slip_ratio: DEFAULT_RISK_SLIP_RATIO,
        })
    }

    /// The contact model of a sample at `load` (N) and `phi` (rad).
    fn solution(&self, load: f32, phi: f32) -> Result<reference::Solution, Error> {
        reference::estimate_with(&self.scene, f64::from(load), f64::from(phi), self.choice)
    }
}

impl Estimator for ReferenceCore {
    type Load = f32;
    type Angle = f32;
    type Output = Estimate;

    /// The reference's answer in f64, each value rounded once to f32; the margin
    /// `phi0 - |phi|` is formed in f64 before its rounding.
    fn estimate(&self, load: f32, phi: f32) -> Result<Estimate, Error> {
        let solution = self.solution(load, phi)?;
        let slip_ratio = solution.slip_ratio();
        let critical_angle = solution
            .critical_angle()
            .filter(|c| *c <= core::f64::consts::FRAC_PI_2);
        Ok(Estimate {
            slip_ratio: slip_ratio as f32,
            regime: solution.regime(),
            axial_force: solution.axial_force(&self.scene) as f32,
            critical_angle: critical_angle.map(|c| c as f32),
            margin: critical_angle.map(|c| (c - f64::from(phi).abs()) as f32),
            microslip_risk: slip_ratio as f32 >= self.risk_slip_ratio,
        })
    }

    fn input(&self, load: f32, phi: f32) -> Result<(f32, f32), Error> {
        Ok((load, phi))
    }

    fn to_estimate(&self, output: &Estimate) -> Estimate {
        *output
    }

    fn risk_slip_ratio(&self) -> f32 {
        self.risk_slip_ratio
    }

    fn with_risk_slip_ratio(self, slip_ratio: f32) -> Result<Self, Error> {
        if slip_ratio.is_finite() && slip_ratio > 0.0 {
            Ok(ReferenceCore {
                risk_slip_ratio: slip_ratio,
                ..self
            })
        } else {
            Err(Error::OutOfRange)
        }
    }
}

impl FrictionInverse for ReferenceCore {
    /// The reference's inverse (`reference::inverse`) of the model this sample takes,
    /// rounded to f32.
    fn friction_from_axial_force(
        &self,
        load: f32,
        phi: f32,
        force: f32,
    ) -> Result<Inverse<f32>, Error> {
        let (p, a, f) = (f64::from(load), f64::from(phi), f64::from(force));
        if !f.is_finite() {
            return Err(Error::Force);
        }
        let answer = match self.solution(load, phi)?.model() {
            ContactModel::Elliptic => inverse::friction_elliptic(&self.scene, p, a, f)?,
            ContactModel::Line => {
                let length = self.scene.length().unwrap_or(1.0);
                inverse::friction_line(&self.scene, p / length, a, f / length)?
            }
        };
        Ok(answer.map(|x| x as f32))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each field is the reference's, rounded once; the inverse gives back the mu of
    /// the forward answer.
    #[test]
    fn the_reference_rounded_once() {
        let scene = Scene::DEMO;
        let core = ReferenceCore::with_choice(&scene, ModelChoice::Section9).unwrap();
        let (load, phi) = (2500.0f32, 2.5e-4f32);
        let e = core.estimate_si(load, phi).unwrap();
        let r = reference::estimate(&scene, 2500.0, f64::from(phi)).unwrap();
        assert_eq!(e.slip_ratio, r.slip_ratio() as f32);
        assert_eq!(e.axial_force, r.axial_force(&scene) as f32);
        let phi0 = r.critical_angle().unwrap();
        assert_eq!(e.critical_angle, Some(phi0 as f32));
        assert_eq!(e.margin, Some((phi0 - f64::from(phi)) as f32));
        assert!(!e.microslip_risk);
        let mu = core
            .friction_from_axial_force(load, phi, e.axial_force)
            .unwrap()
            .value()
            .unwrap();
        assert!((mu / scene.friction() as f32 - 1.0).abs() < 1e-5, "{mu}");
        assert_eq!(core.estimate_si(f32::NAN, phi), Err(Error::Load));
        assert_eq!(
            core.friction_from_axial_force(load, phi, f32::INFINITY),
            Err(Error::Force)
        );
    }
}
