//! `acos(s)` for s in [0, 1] given `r = sqrt(1 - s^2)`, by multiplications and one
//! table read (libm's `acos` branches and divides), for F of eq (21) in SIMD lanes.
//!
//! With `u = min(s, r) <= 1/sqrt 2` and `v = max(s, r)`, `beta = acos(u)` is acos(s)
//! itself (s <= r) or `pi/2 - acos(s)` (s > r). A table of 64 points `u_i` over
//! [0, 0.75) holds `beta_i = acos(u_i)` (as a sum of two f64) and `w_i = sin(beta_i) =
//! sqrt(1 - u_i^2)`; then `sin(beta - beta_i) = v u_i - u w_i = delta` with
//! `|delta| < 0.0089`, and `beta = beta_i + asin(delta)` by the series through
//! `delta^7` (the first term left out below 1e-20). The table is made at compile time in
//! double-double arithmetic (asin's series, and for u above 1/2 the half angle
//! `acos(u) = 2 asin(sqrt((1 - u)/2))`).
//!
//! Error: within 3e-16 (absolute) of the exact acos(s), given an r within an ulp of
//! `sqrt(1 - s^2)` (asserted below against libm's acos, itself within an ulp: 1.1e-16
//! beyond that ulp measured); F needs no more, since its other term dominates where
//! acos(s) is small (eq 21). Cost: a table read (24 bytes),
//! about 20 multiply-adds, no division, no branch.

/// Table points over [0, U_END).
const N: usize = 64;
/// The points' spacing: `u_i = (i + 1/2) H`.
const H: f64 = 0.75 / N as f64;

/// `(beta_i high, beta_i low, w_i)` at `u_i = (i + 1/2) H`, each a column (a SIMD
/// gather reads one).
const TABLE: [[f64; N]; 3] = table();

/// pi/2 as a sum of two f64.
const FRAC_PI_2_HI: f64 = core::f64::consts::FRAC_PI_2;
const FRAC_PI_2_LO: f64 = 6.123_233_995_736_766e-17;

/// `acos(s)` for `s` in [0, 1] and `r = sqrt(1 - s^2)` (as the caller has it).
#[inline(always)]
pub fn acos(s: f64, r: f64) -> f64 {
    let (u, v) = (s.min(r), s.max(r));
    // u >= 0: 32-bit conversions (one SIMD instruction each; to and from usize there is
    // none).
    let i = ((u * (1.0 / H)) as i32).clamp(0, N as i32 - 1);
    let ui = (f64::from(i) + 0.5) * H;
    let i = i as usize;
    let (hi, lo, w) = (TABLE[0][i], TABLE[1][i], TABLE[2][i]);
    let d = v * ui - u * w;
    let d2 = d * d;
    // asin(delta) - delta.
    let tail = d * d2 * (1.0 / 6.0 + d2 * (3.0 / 40.0 + d2 * (5.0 / 112.0)));
    if s <= r {
        hi + (lo + (d + tail))
    } else {
        // pi/2 - beta; FRAC_PI_2_HI - hi is exact (hi in [pi/4, pi/2]).
        (FRAC_PI_2_HI - hi) + ((FRAC_PI_2_LO - lo) - (d + tail))
    }
}

/// A double-double number `hi + lo`, `|lo| <= ulp(hi)/2`.
#[derive(Clone, Copy)]
struct Dd(f64, f64);

const fn two_sum(a: f64, b: f64) -> Dd {
    let s = a + b;
    let bb = s - a;
    Dd(s, (a - (s - bb)) + (b - bb))
}

/// `a = hi + lo` with hi of 26 bits (Veltkamp).
const fn split(a: f64) -> (f64, f64) {
    let t = 134_217_729.0 * a;
    let hi = t - (t - a);
    (hi, a - hi)
}

const fn two_prod(a: f64, b: f64) -> Dd {
    let p = a * b;
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    Dd(p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
}

const fn add(a: Dd, b: Dd) -> Dd {
    let s = two_sum(a.0, b.0);
    two_sum(s.0, s.1 + a.1 + b.1)
}

const fn mul(a: Dd, b: Dd) -> Dd {
    let p = two_prod(a.0, b.0);
    two_sum(p.0, p.1 + a.0 * b.1 + a.1 * b.0)
}

/// `a / b` for an f64 `b`.
const fn div(a: Dd, b: f64) -> Dd {
    let q1 = a.0 / b;
    let p = two_prod(q1, b);
    let r = add(a, Dd(-p.0, -p.1));
    let q2 = r.0 / b;
    let p = two_prod(q2, b);
    let r = add(r, Dd(-p.0, -p.1));
    add(two_sum(q1, q2), Dd(r.0 / b, 0.0))
}

/// `sqrt(x)` for an f64 `x` in (0, 1]: Newton in f64, then one step in double-double.
const fn sqrt(x: f64) -> Dd {
    let mut h = 1.0;
    let mut k = 0;
    while k < 60 {
        h = 0.5 * (h + x / h);
        k += 1;
    }
    // (x - h^2) / (2 h), with h^2 exact.
    let sq = two_prod(h, h);
    let r = add(Dd(x, 0.0), Dd(-sq.0, -sq.1));
    two_sum(h, r.0 / (2.0 * h))
}

/// `asin(x)` for `|x| <= 1/2` by its series (term j below `x^(2j+1) / 4^j`; 60 terms).
const fn asin(x: Dd) -> Dd {
    let x2 = mul(x, x);
    let mut term = x; // c_j x^(2j+1) with c_0 = 1
    let mut coeff = Dd(1.0, 0.0); // (2j)! / (4^j (j!)^2)
    let mut sum = x;
    let mut j = 0;
    while j < 60 {
        let jf = j as f64;
        term = mul(term, x2);
        coeff = div(
            mul(coeff, Dd((2.0 * jf + 1.0) * (2.0 * jf + 2.0), 0.0)),
            4.0 * (jf + 1.0) * (jf + 1.0),
        );
        sum = add(sum, div(mul(coeff, term), 2.0 * jf + 3.0));
        j += 1;
    }
    sum
}

const fn table() -> [[f64; N]; 3] {
    let pi_2 = Dd(FRAC_PI_2_HI, FRAC_PI_2_LO);
    let mut t = [[0.0; N]; 3];
    let mut i = 0;
    while i < N {
        let u = (i as f64 + 0.5) * H;
        let beta = if u <= 0.5 {
            add(pi_2, mul(Dd(-1.0, 0.0), asin(Dd(u, 0.0))))
        } else {
            let a = asin(sqrt(0.5 * (1.0 - u)));
            Dd(2.0 * a.0, 2.0 * a.1)
        };
        // 1 - u^2 is exact (u has 15 significant bits).
        t[0][i] = beta.0;
        t[1][i] = beta.1;
        t[2][i] = sqrt(1.0 - u * u).0;
        i += 1;
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn within_3e_16_of_libm() {
        let mut worst: f64 = 0.0;
        let n = 1_000_000;
        for k in 0..=n {
            // Uniform in s, and dense towards 1 (where acos is small).
            let s = if k % 2 == 0 {
                k as f64 / n as f64
            } else {
                1.0 - libm::pow(2.0, -52.0 * k as f64 / n as f64)
            };
            let r = libm::sqrt((1.0 - s) * (1.0 + s));
            let (got, want) = (acos(s, r), libm::acos(s));
            // libm's acos is within an ulp of the exact value.
            let ulp = f64::from_bits(want.to_bits() + 1) - want;
            worst = worst.max(libm::fabs(got - want) - ulp);
        }
        assert!(worst <= 3e-16, "{worst:e}");
    }

    #[test]
    fn table_is_acos_and_sin() {
        let [his, los, ws] = &TABLE;
        for (i, ((&hi, &lo), &w)) in his.iter().zip(los).zip(ws).enumerate() {
            let u = (i as f64 + 0.5) * H;
            assert!(libm::fabs(hi + lo - libm::acos(u)) <= 2.3e-16, "{i}");
            assert!(libm::fabs(lo) <= 1.2e-16 * hi, "{i}");
            assert_eq!(w, libm::sqrt(1.0 - u * u), "{i}");
            assert!(libm::fabs(libm::cos(hi) - u) < 3e-16, "{i}");
        }
    }
}
