//! Polynomial fits for the generated tables: the smallest maximum relative error (by
//! Lawson's iteration), as monomial coefficients for Horner evaluation, in f64; the
//! tables store them in f32.

/// Coefficients `c[0] + c[1] t + ... + c[d] t^d` of the polynomial of degree `d` with
/// the smallest maximum *relative* error to `f` on `[lo, hi]` (f without a zero there),
/// near enough: Lawson's iteration of weighted least squares on 200 Chebyshev points,
/// from the interpolant's weights, the best of 100 rounds kept. Deterministic (plain
/// f64 arithmetic), so that `cargo xtask tables` writes the same file every time.
pub fn minimax_relative_fit(f: impl Fn(f64) -> f64, lo: f64, hi: f64, d: usize) -> Vec<f64> {
    minimax_weighted_fit(f, |_| 1.0, lo, hi, d)
}

/// As [`minimax_relative_fit`], the relative error at t counted `weight(t)` times (the
/// weight positive): where the error of this polynomial matters less, it may be larger.
pub fn minimax_weighted_fit(
    f: impl Fn(f64) -> f64,
    weight: impl Fn(f64) -> f64,
    lo: f64,
    hi: f64,
    d: usize,
) -> Vec<f64> {
    const POINTS: usize = 200;
    let ts: Vec<f64> = (0..POINTS)
        .map(|i| {
            let x = (std::f64::consts::PI * (i as f64 + 0.5) / POINTS as f64).cos();
            lo + 0.5 * (hi - lo) * (1.0 - x)
        })
        .collect();
    let fs: Vec<f64> = ts.iter().map(|&t| f(t)).collect();
    // Scaled so that p(t) / fs - 1 is the weighted relative error.
    let scale: Vec<f64> = ts.iter().map(|&t| weight(t)).collect();
    let n = d + 1;
    let mut weights = vec![1.0; POINTS];
    let mut best = (f64::INFINITY, vec![0.0; n]);
    for _ in 0..100 {
        // Normal equations of sum w (p(t)/f(t) - 1)^2 over the points.
        let mut a = vec![vec![0.0; n]; n];
        let mut b = vec![0.0; n];
        for (((&t, &fx), &w), &sc) in ts.iter().zip(&fs).zip(&weights).zip(&scale) {
            let row: Vec<f64> = (0..n).map(|j| sc * t.powi(j as i32) / fx).collect();
            for r in 0..n {
                for c in 0..n {
                    a[r][c] += w * row[r] * row[c];
                }
                b[r] += w * row[r] * sc;
            }
        }
        let coeffs = solve(a, b);
        let errors: Vec<f64> = ts
            .iter()
            .zip(&fs)
            .zip(&scale)
            .map(|((&t, &fx), &sc)| sc * (horner_f64(&coeffs, t) / fx - 1.0).abs())
            .collect();
        if coeffs.iter().any(|c| !c.is_finite()) {
            break; // the weights have collapsed onto too few points
        }
        let worst = errors.iter().copied().fold(0.0, f64::max);
        if worst < best.0 {
            best = (worst, coeffs);
        }
        // Lawson: weight each point by its error, so that the largest errors shrink.
        let total: f64 = weights.iter().zip(&errors).map(|(w, e)| w * e).sum();
        if total.is_nan() || total <= 0.0 {
            break; // exact (or nothing left to weigh)
        }
        for (w, e) in weights.iter_mut().zip(&errors) {
            *w = (*w * e / total * POINTS as f64).max(1e-300);
        }
    }
    best.1
}

fn horner_f64(c: &[f64], t: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &ck| acc * t + ck)
}

/// Gaussian elimination with partial pivoting (small, well-scaled systems).
fn solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
    let n = b.len();
    for i in 0..n {
        let p = (i..n)
            .max_by(|&x, &y| a[x][i].abs().total_cmp(&a[y][i].abs()))
            .unwrap_or(i);
        a.swap(i, p);
        b.swap(i, p);
        let (upper, lower) = a.split_at_mut(i + 1);
        let pivot = &upper[i];
        for (k, row) in lower.iter_mut().enumerate() {
            let f = row[i] / pivot[i];
            for (x, p) in row[i..].iter_mut().zip(&pivot[i..]) {
                *x -= f * p;
            }
            b[i + 1 + k] -= f * b[i];
        }
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        let s: f64 = (i + 1..n).map(|c| a[i][c] * x[c]).sum();
        x[i] = (b[i] - s) / a[i][i];
    }
    x
}

/// Coefficients `c[0] + c[1] u + ... + c[d] u^d` of the polynomial of degree `d` that
/// interpolates `f` at the `d + 1` Chebyshev nodes of `[lo, hi]` (the family of shapes
/// `cargo xtask shapes` weighs).
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
    fn minimax_fits_a_cubic_exactly() {
        let c = minimax_relative_fit(|t| 2.0 - t + 0.5 * t * t * t, -0.5, 0.5, 3);
        for (got, want) in c.iter().zip([2.0, -1.0, 0.0, 0.5]) {
            assert!((got - want).abs() < 1e-12, "{c:?}");
        }
    }
}
