//! Polynomial fits for the generated tables: Chebyshev-node interpolation, turned into
//! monomial coefficients for Horner evaluation, in f64; the tables store them in f32.

/// Coefficients `c[0] + c[1] u + ... + c[d] u^d` of the polynomial of degree `d` that
/// interpolates `f` at the `d + 1` Chebyshev nodes of `[lo, hi]`.
pub fn chebyshev_fit(f: impl Fn(f64) -> f64, lo: f64, hi: f64, d: usize) -> Vec<f64> {
    let n = d + 1;
    let nodes: Vec<f64> = (0..n)
        .map(|k| {
            lo + 0.5
                * (hi - lo)
                * (1.0 - (std::f64::consts::PI * (k as f64 + 0.5) / n as f64).cos())
        })
        .collect();
    let values: Vec<f64> = nodes.iter().map(|&t| f(t)).collect();
    // Newton's divided differences, then expand to monomials: stable for d <= 10.
    let mut dd = values.clone();
    for j in 1..n {
        for i in (j..n).rev() {
            dd[i] = (dd[i] - dd[i - 1]) / (nodes[i] - nodes[i - j]);
        }
    }
    let mut coeffs = vec![0.0; n];
    for i in (0..n).rev() {
        // coeffs = coeffs * (t - nodes[i]) + dd[i]
        let mut next = vec![0.0; n];
        for k in 0..n {
            if k + 1 < n {
                next[k + 1] += coeffs[k];
            }
            next[k] -= coeffs[k] * nodes[i];
        }
        next[0] += dd[i];
        coeffs = next;
    }
    coeffs
}

/// Horner evaluation in f32 with a rounding after each multiply and each add, as
/// the library does it (Rust does not fuse `a * b + c`).
pub fn horner_f32(c: &[f32], t: f32) -> f32 {
    let mut acc = c[c.len() - 1];
    for &ck in c[..c.len() - 1].iter().rev() {
        acc = acc * t + ck;
    }
    acc
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn fits_a_cubic_exactly() {
        let c = chebyshev_fit(|t| 1.0 - 2.0 * t + 0.5 * t * t * t, -0.5, 1.0, 3);
        for (got, want) in c.iter().zip([1.0, -2.0, 0.0, 0.5]) {
            assert!((got - want).abs() < 1e-12, "{c:?}");
        }
    }
}
