//! `K - E` and `E - k'^2 K` at small `k'`, by the series of K and E about `k' = 0`
//! (DLMF 19.12.1-2) truncated after `k'^12`:
//!
//! ```text
//! K = sum a_j k'^2j (ln(1/k') + d_j),   a_j = ((1/2)_j / j!)^2,
//! E = 1 + sum b_j k'^(2j+2) (ln(1/k') + d_j - 1/((2j+1)(2j+2))),
//!     b_j = (1/2)_j (3/2)_j / (2 (2)_j j!),   d_j = psi(1+j) - psi(1/2+j).
//! ```
//!
//! Each of `A = K - E` and `B = E - k'^2 K` is `X_L(p) ln(1/k') + X_0(p)` with `p = k'^2`
//! and polynomials whose coefficients follow from the recurrences (computed at compile
//! time, below), so neither cancels: `A ~ ln(4/k') - 1`, `B ~ 1`.
//!
//! Error: for `k' <= KPRIME_MAX` (p <= 1.03e-3) the first term left out is below 2e-21 of
//! either sum; the evaluation rounds each to within 6 ulps of Carlson's R_D given
//! `ln(1/k')` (asserted below; R_D's own error is a few ulps). Cost: four Horner chains
//! of degree 6 run side by side, no division and no branch (rows in SIMD lanes take
//! the same terms).

/// Largest `k'` the truncated series is exact for (to below 2e-21 relative).
#[cfg(test)]
pub const KPRIME_MAX: f64 = 0.032;

/// Coefficients per polynomial (degree 6 in p).
const TERMS: usize = 7;

/// `[A_L, A_0, B_L, B_0]`, lowest power first.
const COEFFICIENTS: [[f64; TERMS]; 4] = coefficients();

const fn coefficients() -> [[f64; TERMS]; 4] {
    // K = KL ln(1/k') + K0, E = EL ln(1/k') + E0, as polynomials in p.
    let mut kl = [0.0; TERMS + 1];
    let mut k0 = [0.0; TERMS + 1];
    let mut el = [0.0; TERMS + 1];
    let mut e0 = [0.0; TERMS + 1];
    e0[0] = 1.0;
    let mut a = 1.0; // a_j
    let mut b = 0.5; // b_j
    let mut d = 2.0 * core::f64::consts::LN_2; // d_j = psi(1+j) - psi(1/2+j)
    let mut j = 0;
    while j < TERMS {
        let jf = j as f64;
        kl[j] = a;
        k0[j] = a * d;
        el[j + 1] = b;
        e0[j + 1] = b * (d - 1.0 / ((2.0 * jf + 1.0) * (2.0 * jf + 2.0)));
        let r = (jf + 0.5) / (jf + 1.0);
        a *= r * r;
        b *= (jf + 0.5) * (jf + 1.5) / ((jf + 2.0) * (jf + 1.0));
        d -= 1.0 / ((jf + 1.0) * (2.0 * jf + 1.0));
        j += 1;
    }
    let mut out = [[0.0; TERMS]; 4];
    let mut j = 0;
    while j < TERMS {
        out[0][j] = kl[j] - el[j];
        out[1][j] = k0[j] - e0[j];
        let (kl_prev, k0_prev) = if j == 0 {
            (0.0, 0.0)
        } else {
            (kl[j - 1], k0[j - 1])
        };
        out[2][j] = el[j] - kl_prev;
        out[3][j] = e0[j] - k0_prev;
        j += 1;
    }
    out
}

/// `(K - E, E - k'^2 K)` at `p = k'^2` with `log_inv = ln(1/k')`, for `k' <= KPRIME_MAX`.
#[inline(always)]
pub fn differences(p: f64, log_inv: f64) -> (f64, f64) {
    let [al, a0, bl, b0] = &COEFFICIENTS;
    let (mut xal, mut xa0, mut xbl, mut xb0) = (0.0, 0.0, 0.0, 0.0);
    let mut j = TERMS;
    while j > 0 {
        j -= 1;
        xal = xal * p + al[j];
        xa0 = xa0 * p + a0[j];
        xbl = xbl * p + bl[j];
        xb0 = xb0 * p + b0[j];
    }
    (xal * log_inv + xa0, xbl * log_inv + xb0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::carlson::carlson_rd_pair;

    /// Against Carlson's R_D (DLMF 19.25.1): `K - E = k^2 R_D(0, k'^2, 1) / 3`,
    /// `E - k'^2 K = k^2 k'^2 R_D(0, 1, k'^2) / 3`.
    #[test]
    fn meets_carlson() {
        let mut worst: f64 = 0.0;
        for i in 0..=400 {
            let kp = KPRIME_MAX * libm::pow(2.0, -40.0 * i as f64 / 400.0);
            let p = kp * kp;
            let k2 = (1.0 - kp) * (1.0 + kp);
            let (rd1, rd2) = carlson_rd_pair(p);
            let (a, b) = differences(p, -libm::log(kp));
            let ea = (a / (k2 * rd1 / 3.0) - 1.0).abs();
            let eb = (b / (k2 * p * rd2 / 3.0) - 1.0).abs();
            worst = worst.max(ea).max(eb);
        }
        // Both sides round: a few ulps each.
        assert!(worst < 6.0 * f64::EPSILON, "{worst:e}");
    }

    /// The first coefficient left out, times `p^7 ln(1/k')`, is below 2e-21 of the sums
    /// at `KPRIME_MAX` (where it is largest relative to them).
    #[test]
    fn truncation_is_below_2e_21() {
        // a_6 and b_6 bound every coefficient of p^7 left out (A's is a_7 - b_6, B's
        // b_6 - a_6), each later one is smaller by p; |d_j| <= 2 ln 2.
        let (mut a, mut b) = (1.0f64, 0.5f64);
        for j in 0..TERMS - 1 {
            let jf = j as f64;
            a *= ((jf + 0.5) / (jf + 1.0)) * ((jf + 0.5) / (jf + 1.0));
            b *= (jf + 0.5) * (jf + 1.5) / ((jf + 2.0) * (jf + 1.0));
        }
        let p = KPRIME_MAX * KPRIME_MAX;
        let l = -libm::log(KPRIME_MAX);
        let left = 2.0 * (a + b) * libm::pow(p, TERMS as f64) * (l + 2.5);
        let (aa, bb) = differences(p, l);
        assert!(left < 2e-21 * aa.min(bb), "{left:e}");
    }
}
