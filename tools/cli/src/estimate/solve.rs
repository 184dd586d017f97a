//! `--solve mu|phi`: the inverse estimates, one row in, one row out, over
//! `misalign::reference::inverse` and the f32 cores' `*_from_axial_force`. The header,
//! the columns, the numbers and the scene are read by the forward mode's code in
//! `cli.rs`; only the unknown's inputs, the answer and its row are here.

use super::{Contact, Model, Num, f32_error, to_f32};
use clap::ValueEnum;
use misalign::Scene;
use misalign::float::Auto;
use misalign::reference::inverse::{self, Inverse};
use serde::ser::{Serialize, SerializeStruct, Serializer};

/// `--solve`: the unknown the inverse gives from a measured axial force F.
#[derive(Clone, Copy, PartialEq, Debug, ValueEnum)]
pub enum Unknown {
    /// The friction coefficient, from R1,R2,G,nu,P,phi,F.
    Mu,
    /// The misalignment (rad, signed like F), from R1,R2,G,nu,mu,P,F.
    Phi,
}

/// The friction of the scenes of `--solve mu`: `Scene::new` needs one, and neither the
/// reference nor the f32 mu-inverse reads it (their docs say so).
pub const PLACEHOLDER_FRICTION: f64 = 1.0;

/// What `--model fixed` says on every row.
pub const NO_FIXED_INVERSE: &str = "the fixed-point core has no inverse (it would need \
    new log-domain tables: misalign::float::inverse says why); use --model f32 or \
    --model reference";

impl Unknown {
    /// The input columns, in the order [`answer`] reads them.
    pub fn inputs(self) -> &'static [&'static str; 7] {
        match self {
            Unknown::Mu => &["R1", "R2", "G", "nu", "P", "phi", "F"],
            Unknown::Phi => &["R1", "R2", "G", "nu", "mu", "P", "F"],
        }
    }

    /// The scene's constants (R1, R2, G, nu, mu) among the inputs `x`.
    pub fn scene_constants(self, x: &[f64; 7]) -> [f64; 5] {
        let mu = match self {
            Unknown::Mu => PLACEHOLDER_FRICTION,
            Unknown::Phi => x[4],
        };
        [x[0], x[1], x[2], x[3], mu]
    }

    fn column(self) -> &'static str {
        match self {
            Unknown::Mu => "mu",
            Unknown::Phi => "phi",
        }
    }
}

/// One output row of `--solve`: `mu|phi,bound,sensitivity,error`. Serialized by hand
/// because the first column's name is the unknown's.
#[derive(Debug)]
pub struct SolveRow<'a> {
    unknown: Unknown,
    answer: Option<Inverse<Num>>,
    error: &'a str,
}

impl<'a> SolveRow<'a> {
    /// The row of an answer, or of an error (`answer` `None`, message in `error`).
    pub fn new(unknown: Unknown, answer: Option<Inverse<Num>>, error: &'a str) -> Self {
        SolveRow {
            unknown,
            answer,
            error,
        }
    }
}

impl Serialize for SolveRow<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let a = self.answer.as_ref();
        let error = match a {
            Some(Inverse::Inconsistent(why)) => why.as_str(),
            _ => self.error,
        };
        let mut row = serializer.serialize_struct("SolveRow", 4)?;
        row.serialize_field(self.unknown.column(), &a.and_then(Inverse::value))?;
        row.serialize_field("bound", a.map_or("", Inverse::bound_str))?;
        row.serialize_field("sensitivity", &a.and_then(Inverse::sensitivity))?;
        row.serialize_field("error", error)?;
        row.end()
    }
}

/// The answer for one row: `x` in the order of [`Unknown::inputs`], `scene` built from
/// its constants (and the row's length). P and F as the forward mode reads P: totals
/// with a length, per unit length in line contact without one.
pub fn answer(
    unknown: Unknown,
    model: Model,
    contact: Contact,
    scene: &Scene,
    x: &[f64; 7],
) -> Result<Inverse<Num>, String> {
    let text = |e: misalign::Error| e.to_string();
    // (P, phi, F); phi is not an input of the phi-inverse.
    let (load, phi, force) = match unknown {
        Unknown::Mu => (x[4], x[5], x[6]),
        Unknown::Phi => (x[5], 0.0, x[6]),
    };
    match model {
        Model::Reference => {
            let per_length = |v: f64| v / scene.length().unwrap_or(1.0);
            let answer = match (unknown, contact) {
                (Unknown::Mu, Contact::Auto) => inverse::friction_estimate(scene, load, phi, force),
                (Unknown::Mu, Contact::Elliptic) => {
                    inverse::friction_elliptic(scene, load, phi, force)
                }
                (Unknown::Mu, Contact::Line) => {
                    inverse::friction_line(scene, per_length(load), phi, per_length(force))
                }
                (Unknown::Phi, Contact::Auto) => inverse::angle_estimate(scene, load, force),
                (Unknown::Phi, Contact::Elliptic) => inverse::angle_elliptic(scene, load, force),
                (Unknown::Phi, Contact::Line) => {
                    inverse::angle_line(scene, per_length(load), per_length(force))
                }
            };
            Ok(answer.map_err(text)?.map(Num::F64))
        }
        Model::F32 => {
            // NaN or infinite values go to the core, whose typed errors name them.
            let narrow = |name: &str, unit: &str, v: f64| {
                if v.is_finite() {
                    to_f32(name, unit, v)
                } else {
                    Ok(v as f32)
                }
            };
            let (p, f) = (narrow("P", "N", load)?, narrow("F", "N", force)?);
            let core = Auto::with_choice(scene, contact.choice()).map_err(f32_error)?;
            let answer = match unknown {
                // |phi| above f64's FRAC_PI_2 refused before f32's rounding carries
                // it onto f32's FRAC_PI_2, as in the reference.
                Unknown::Mu if phi.abs() > core::f64::consts::FRAC_PI_2 => {
                    Err(misalign::Error::Angle)
                }
                Unknown::Mu => core.friction_from_axial_force(p, narrow("phi", "rad", phi)?, f),
                Unknown::Phi => core.angle_from_axial_force(p, f),
            };
            Ok(answer.map_err(f32_error)?.map(Num::F32))
        }
        Model::Fixed => Err(NO_FIXED_INVERSE.into()),
    }
}
