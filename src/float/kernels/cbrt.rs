//! Cube root `x^(1/3)` for f32: a bit-level first guess, a Halley step and a Newton step
//! (each in correction form); no library call (`libm::cbrtf` costs about 1580
//! instructions on the Cortex-M4F because it works in soft f64). The elliptic core's
//! `g0 = (B^3 P)^(1/3)` (eqs 16, 18) takes [`cbrt_hot`] on its per-sample path; the line
//! core, the inverses and the rare paths [`cbrt`].

/// Maximum relative error of [`cbrt`] over all positive finite f32 (measured by the
/// exhaustive test below over [1, 8), which covers every input: the kernel is exact
/// under scaling by 8 down to 2^-120, and scales smaller inputs up by 2^24 first;
/// `cargo xtask sweep` checks every f32).
pub const CBRT_MAX_REL_ERROR: f32 = 1.0e-7;

/// First guess: the bits of x^(1/3) are about `bits(x)/3 + K` (3.2 % off at most).
const MAGIC: u32 = 0x2a51_0700;

/// Inputs below this are scaled up by 2^24 first and inputs above [`SCALE_ABOVE`]
/// down by 2^-24, so that every intermediate stays normal and finite and the kernel
/// stays exact under scaling by 8.
pub(crate) const SCALE_BELOW: f32 = 7.523_164e-37; // 2^-120
/// See [`SCALE_BELOW`].
pub(crate) const SCALE_ABOVE: f32 = 1.329_228e36; // 2^120

/// `x^(1/3)` for non-negative finite `x`, subnormals included; 0 for 0. Other inputs
/// (negative, NaN, inf) give an unspecified value: callers check.
#[inline(always)]
pub fn cbrt(x: f32) -> f32 {
    if x < SCALE_BELOW {
        if x == 0.0 {
            return 0.0;
        }
        // Scale by 2^24 (exact), then x^(1/3) gains a factor 2^8.
        return cbrt_normal(x * 16_777_216.0) * (1.0 / 256.0);
    }
    if x > SCALE_ABOVE {
        return cbrt_normal(x * (1.0 / 16_777_216.0)) * 256.0;
    }
    cbrt_normal(x)
}

/// [`cbrt`] out of line: one copy for the rare paths (extreme loads, the small-theta
/// asymptotics), whose flash counts in the estimator's budget.
#[inline(never)]
pub(crate) fn cbrt_cold(x: f32) -> f32 {
    cbrt(x)
}

/// `x^(1/3)` for `2^-120 <= x <= 2^120`: the per-sample path, whose caller checks.
#[inline(always)]
pub(crate) fn cbrt_normal(x: f32) -> f32 {
    refine(x, f32::from_bits(x.to_bits() / 3 + MAGIC))
}

/// `x^(1/3)` for `2^-81 <= x < 1/2` (the f32 elliptic core's g0^3), as [`cbrt`] but
/// with the first guess `bits(x) / 3 + K` formed in f32 (rounded there, which the
/// steps absorb: not exact under scaling by 8, so measured over its whole domain:
/// [`CBRT_HOT_MAX_REL_ERROR`]). Two instructions fewer on a Cortex-M4F than the
/// integer division by 3 and its constants.
#[inline(always)]
pub fn cbrt_hot(x: f32) -> f32 {
    let guess = x.to_bits() as f32 * (1.0 / 3.0) + MAGIC as f32;
    refine(x, f32::from_bits(guess as u32))
}

/// Maximum relative error of [`cbrt_hot`] over every f32 in [2^-81, 1/2): 7.92e-8
/// measured (`MISALIGN_SWEEP_STEP=1 cargo test --lib cbrt`; `cargo test` every 13th).
pub const CBRT_HOT_MAX_REL_ERROR: f32 = 8.0e-8;

/// The cube root of x from a guess y within 3.5 %.
#[inline(always)]
fn refine(x: f32, mut y: f32) -> f32 {
    // Halley for y^3 = x, as a correction y <- y + y (x - y^3) / (2 y^3 + x): the
    // error e -> about 0.62 e^3 (3.2 % -> 2.1e-5).
    let y3 = y * y * y;
    y += y * ((x - y3) / (y3 + y3 + x));
    // Newton, y <- y + (x / y^2 - y) / 3: 2.1e-5 -> 4e-10, and the last rounding is
    // that of a small term.
    y + (x / (y * y) - y) * (1.0 / 3.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel_err(x: f32) -> f64 {
        (cbrt(x) as f64 / libm::cbrt(x as f64) - 1.0).abs()
    }

    /// Every f32 in [1, 8): three octaves, one full period of the scale symmetry.
    #[test]
    fn exhaustive_over_one_period() {
        let (lo, hi) = (1.0f32.to_bits(), 8.0f32.to_bits());
        let worst = (lo..hi)
            .map(|b| rel_err(f32::from_bits(b)))
            .fold(0.0, f64::max);
        println!("cbrt worst relative error {worst:.3e}");
        assert!(worst <= CBRT_MAX_REL_ERROR as f64, "{worst:e}");
    }

    /// Every 13th f32 of the hot path's domain by default; `MISALIGN_SWEEP_STEP=1` for
    /// all of them.
    #[test]
    fn hot_cube_root_over_its_domain() {
        let step = std::env::var("MISALIGN_SWEEP_STEP")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(13);
        let (lo, hi) = (libm::ldexpf(1.0, -81).to_bits(), 0.5f32.to_bits());
        let worst = (lo..hi)
            .step_by(step)
            .map(|b| {
                let x = f32::from_bits(b);
                (cbrt_hot(x) as f64 / libm::cbrt(x as f64) - 1.0).abs()
            })
            .fold(0.0, f64::max);
        println!("cbrt_hot worst relative error {worst:.3e}");
        assert!(worst <= CBRT_HOT_MAX_REL_ERROR as f64, "{worst:e}");
    }

    #[test]
    fn scale_symmetry_and_extremes() {
        for x in [1.7f32, 3.3, 7.9] {
            for k in -40..=40 {
                let s = libm::powf(8.0, k as f32);
                if (SCALE_BELOW..=SCALE_ABOVE).contains(&(x * s)) {
                    assert_eq!(cbrt(x * s), cbrt(x) * libm::powf(2.0, k as f32), "{x} {k}");
                }
            }
        }
        for x in [
            f32::from_bits(1),
            1e-40,
            f32::MIN_POSITIVE,
            1e-37,
            f32::MAX,
            1e38,
        ] {
            assert!(
                rel_err(x) <= CBRT_MAX_REL_ERROR as f64,
                "{x:e}: {:e}",
                rel_err(x)
            );
        }
        assert_eq!(cbrt(0.0), 0.0);
        assert!((cbrt(27.0) - 3.0).abs() <= 3.0 * 2.0 * f32::EPSILON);
    }
}
