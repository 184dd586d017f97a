//! The monitor tests' angles: the misalignment at which an estimator gives a slip
//! ratio.

use misalign::Estimator;

/// The misalignment (rad, 0 to 10 mrad) at which `core` gives d/b = `target` at `load`
/// (N), by bisection to f32's resolution.
pub fn angle_for<E: Estimator>(core: &E, target: f32, load: f32) -> f32 {
    let (mut lo, mut hi) = (0.0f32, 0.01f32);
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if core.estimate_si(load, mid).unwrap().slip_ratio < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}
