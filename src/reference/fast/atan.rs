//! `atan(t) / t` for small t, by its Taylor series `sum (-1)^j t^2j / (2j + 1)`
//! through `t^14`.
//!
//! Error: for `t^2 <= T2_MAX` the series alternates with decreasing terms, so the
//! first left out, `t^16 / 17 < 1e-20`, bounds the truncation; Horner in `t^2` from the
//! small end rounds to within 1 ulp (each step adds a term below 1/200 of the running
//! sum). Cost: 8 multiply-adds, no division, no branch.

/// Largest `t^2` the truncated series is exact for (`tan(1/16)^2` is 3.9e-3).
#[cfg(test)]
pub const T2_MAX: f64 = 0.0045;

/// `(-1)^j / (2j + 1)`, j = 0..8.
const COEFFICIENTS: [f64; 8] = [
    1.0,
    -1.0 / 3.0,
    1.0 / 5.0,
    -1.0 / 7.0,
    1.0 / 9.0,
    -1.0 / 11.0,
    1.0 / 13.0,
    -1.0 / 15.0,
];

/// `atan(t) / t` at `t2 = t^2 <= T2_MAX`, the series through `t^14`.
#[inline(always)]
pub fn atan_ratio(t2: f64) -> f64 {
    let mut acc = 0.0;
    let mut j = COEFFICIENTS.len();
    while j > 0 {
        j -= 1;
        acc = acc * t2 + COEFFICIENTS[j];
    }
    acc
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn meets_libm() {
        let mut worst: f64 = 0.0;
        for i in 0..=2000 {
            let t = libm::sqrt(T2_MAX) * libm::pow(2.0, -30.0 * i as f64 / 2000.0);
            let got = t * atan_ratio(t * t);
            worst = worst.max((got / libm::atan(t) - 1.0).abs());
        }
        // libm's atan is within 1 ulp; the series within 1 ulp of atan(t)/t.
        assert!(worst < 3.0 * f64::EPSILON, "{worst:e}");
    }

    #[test]
    fn truncation_is_below_1e_20() {
        assert!(libm::pow(T2_MAX, 8.0) / 17.0 < 1e-20 * (1.0 - T2_MAX / 3.0));
    }
}
