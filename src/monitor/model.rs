//! Section 9's model choice, made once for the scene's operating range, so that the
//! states cannot chatter where the ellipse reaches the rollers' ends.

use crate::reference::{self, ModelChoice};
use crate::{Error, Scene};

/// The model a monitor should hold for loads up to `load_max` (N) and misalignments
/// down to `angle_min` (rad, > 0): line contact for a plane, or when the ellipse is
/// longer than the rollers anywhere in that range (at the heaviest load and smallest
/// misalignment, where it is longest); the ellipse otherwise. Pass it to
/// [`float::Auto::with_choice`](crate::float::Auto::with_choice) or
/// [`fixed::FixedAuto::with_choice`](crate::fixed::FixedAuto::with_choice).
///
/// Section 9's choice per sample ([`ModelChoice::Section9`]) switches between the
/// models where 2a crosses the length, and d/b jumps there by up to 22 %: a monitor
/// given such a scene could chatter between states; one given this choice cannot.
///
/// # Errors
/// [`Error::Load`] or [`Error::Angle`] for an operating range that is not positive and
/// finite; the reference's errors for the scene at that range.
pub fn model_for_range(scene: &Scene, load_max: f64, angle_min: f64) -> Result<ModelChoice, Error> {
    if !(load_max.is_finite() && load_max > 0.0) {
        return Err(Error::Load);
    }
    if !(angle_min.is_finite() && angle_min > 0.0) {
        return Err(Error::Angle);
    }
    let line = match scene.length() {
        _ if scene.is_plane() => true,
        None => false,
        Some(_) => {
            reference::elliptic(scene, load_max, angle_min)?
                .validity
                .longer_than_rollers
        }
    };
    Ok(if line {
        ModelChoice::Line
    } else {
        ModelChoice::Elliptic
    })
}
