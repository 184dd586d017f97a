//! A scene prepared on the PC as bytes for a node (`misalign::prepared`: versioned,
//! with a CRC-32), written once for `cargo run --example prepare` (which
//! tools/commission.py runs) and the web page's commissioning (tools/web): the same
//! scene gives the same bytes in both.

use misalign::fixed::{FixedAuto, FixedEllipticScene, FixedLineScene};
use misalign::float::{Auto, EllipticScene, LineScene};
use misalign::reference::ModelChoice;
use misalign::{Error, Scene};

/// The prepared scene type the node loads.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SceneType {
    /// `fixed::FixedEllipticScene` (Cortex-M0/M3)
    FixedElliptic,
    /// `fixed::FixedLineScene`
    FixedLine,
    /// `fixed::FixedAuto` (section 9's choice, or `--choice`)
    FixedAuto,
    /// `float::EllipticScene` (FPU; the node names its tables)
    Elliptic,
    /// `float::LineScene`
    Line,
    /// `float::Auto`
    Auto,
}

/// The auto types' contact model choice.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Choice {
    /// Section 9's rule, per sample.
    Section9,
    /// Always the ellipse.
    Elliptic,
    /// Always line contact.
    Line,
}

/// How a scene is prepared.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// The type the node loads.
    pub scene_type: SceneType,
    /// The auto types' model choice.
    pub choice: Choice,
    /// The fixed-point core's load LSB (N per count).
    pub load_lsb: f64,
    /// The fixed-point core's angle LSB (rad per count).
    pub angle_lsb: f64,
    /// The d/b threshold of the risk flag (`None`: the library's default, 0.8).
    pub risk: Option<f32>,
}

impl Default for Options {
    /// The example's defaults: the fixed-point ellipse at 1 mN and 10 prad a count.
    fn default() -> Self {
        Options {
            scene_type: SceneType::FixedElliptic,
            choice: Choice::Section9,
            load_lsb: 1e-3,
            angle_lsb: 1e-11,
            risk: None,
        }
    }
}

impl Options {
    /// What tools/commission.py prepares for a node's core: `float::Auto` (`fpu`) or
    /// `fixed::FixedAuto` at the default LSBs, section 9's choice.
    pub fn for_core(fpu: bool) -> Self {
        Options {
            scene_type: if fpu {
                SceneType::Auto
            } else {
                SceneType::FixedAuto
            },
            ..Options::default()
        }
    }
}

/// `scene` prepared as `options` say, as bytes.
///
/// # Errors
/// The scene type's errors for the scene, the LSBs or the risk threshold.
pub fn prepared(scene: &Scene, options: &Options) -> Result<Vec<u8>, Error> {
    let choice = match options.choice {
        Choice::Section9 => ModelChoice::Section9,
        Choice::Elliptic => ModelChoice::Elliptic,
        Choice::Line => ModelChoice::Line,
    };
    let risk = options
        .risk
        .unwrap_or(misalign::estimator::DEFAULT_RISK_SLIP_RATIO);
    let (p, a) = (options.load_lsb, options.angle_lsb);
    Ok(match options.scene_type {
        SceneType::FixedElliptic => FixedEllipticScene::new(scene, p, a)?
            .with_risk_slip_ratio(risk)?
            .to_bytes()
            .to_vec(),
        SceneType::FixedLine => FixedLineScene::new(scene, p, a)?
            .with_risk_slip_ratio(risk)?
            .to_bytes()
            .to_vec(),
        SceneType::FixedAuto => FixedAuto::with_choice(scene, p, a, choice)?
            .with_risk_slip_ratio(risk)?
            .to_bytes()
            .to_vec(),
        SceneType::Elliptic => EllipticScene::new(scene)?
            .with_risk_slip_ratio(risk)?
            .to_bytes()
            .to_vec(),
        SceneType::Line => LineScene::new(scene)?
            .with_risk_slip_ratio(risk)?
            .to_bytes()
            .to_vec(),
        SceneType::Auto => Auto::with_choice(scene, choice)?
            .with_risk_slip_ratio(risk)?
            .to_bytes()
            .to_vec(),
    })
}
