//! `cargo xtask sweep`: every one-argument kernel over every f32 (or u32, or Q8.24
//! fraction) of its domain, against the f64 reference; maximum error in ulps of the
//! result and relative. The table functions need the reference's root finding per
//! point, so they are swept on every 2^k-th f32 of each octave instead (said so).
//! With `--write` it writes docs/sweep.csv and its table in docs/measurements.md.

use crate::records::SweepRow as Row;
use misalign::fixed::logexp::{exp2_fixed, log2_u32};
use misalign::fixed::uniform::ONE;
use misalign::float::kernels::axial_force::axial_force_ratio;
use misalign::float::kernels::cbrt::{cbrt, cbrt_hot};
use misalign::float::kernels::sqrt::inv_sqrt;
use misalign::float::kernels::theta_top::theta_of_g_top;
use misalign::float::tables::{G_OF_THETA, INV_M_OF_THETA, THETA_OF_G};
use misalign::reference::{normal, tangential};

/// Distance in f32 ulps of `got` from the exact `want` (ulp of the f32 nearest want).
fn ulps(got: f32, want: f64) -> f64 {
    let w = want as f32;
    let ulp = (f32::from_bits(w.abs().to_bits() + 1) - w.abs()) as f64;
    (got as f64 - want).abs() / ulp
}

/// Runs `f` over bit patterns `lo..hi` step `step` on two threads; f gives
/// (ulps, relative error) per point.
fn sweep(
    lo: u32,
    hi: u32,
    step: u32,
    f: impl Fn(u32) -> (f64, f64) + Sync,
) -> (u64, f64, f64, f64) {
    let mid = lo + (hi - lo) / 2 / step * step;
    let part = |a: u32, b: u32| {
        let (mut n, mut wu, mut wr, mut at) = (0u64, 0.0f64, 0.0f64, 0u32);
        let mut x = a;
        while x < b {
            let (u, r) = f(x);
            n += 1;
            if u > wu {
                wu = u;
            }
            if r > wr {
                wr = r;
                at = x;
            }
            x = match x.checked_add(step) {
                Some(v) => v,
                None => break,
            };
        }
        (n, wu, wr, at)
    };
    let (a, b) = std::thread::scope(|s| {
        let h = s.spawn(|| part(lo, mid));
        let b = part(mid, hi);
        (h.join().unwrap(), b)
    });
    let at = if a.2 >= b.2 { a.3 } else { b.3 };
    (a.0 + b.0, a.1.max(b.1), a.2.max(b.2), at as f64)
}

fn f32_row(
    kernel: &'static str,
    domain: &str,
    lo: f32,
    hi: f32,
    step: u32,
    f: impl Fn(f32) -> (f32, f64) + Sync,
) -> Row {
    let (n, u, r, at) = sweep(lo.to_bits(), hi.to_bits(), step, |b| {
        let x = f32::from_bits(b);
        let (got, want) = f(x);
        (ulps(got, want), ((got as f64 - want) / want).abs())
    });
    Row {
        kernel: kernel.into(),
        domain: domain.into(),
        points: n,
        max_ulps: u,
        max_rel: r,
        at: f32::from_bits(at as u32) as f64,
    }
}

/// All sweeps; `quick` strides through the f32 kernels too (for CI's short pass).
pub fn run(quick: bool) -> Vec<Row> {
    let s = if quick { 4099 } else { 1 };
    let mut rows = vec![
        f32_row(
            "cbrt",
            "all positive finite f32",
            f32::from_bits(1),
            f32::MAX,
            s,
            |x| (cbrt(x), (x as f64).cbrt()),
        ),
        f32_row(
            "cbrt_hot",
            "all f32 in [2^-81, 1/2)",
            libm::ldexpf(1.0, -81),
            0.5,
            s,
            |x| (cbrt_hot(x), (x as f64).cbrt()),
        ),
        f32_row(
            "inv_sqrt",
            "all positive finite f32",
            f32::from_bits(1),
            f32::MAX,
            s,
            |x| (inv_sqrt(x), 1.0 / (x as f64).sqrt()),
        ),
        f32_row(
            "axial_force_ratio",
            "all f32 in [2^-126, 1)",
            f32::MIN_POSITIVE,
            1.0,
            s,
            |x| {
                (
                    axial_force_ratio(x),
                    tangential::axial_force_ratio(x as f64),
                )
            },
        ),
    ];
    // Tables: every 2^12-th f32 (2048 points per octave), the reference per point.
    let t: u32 = if quick { 1 << 17 } else { 1 << 12 };
    let top = core::f32::consts::FRAC_PI_2;
    rows.push(f32_row(
        "table g(theta)",
        &format!(
            "theta in [2^{}, pi/2], every 2^{}-th f32",
            G_OF_THETA.first_exponent(),
            t.trailing_zeros()
        ),
        G_OF_THETA.lower(),
        top,
        t,
        |x| {
            (
                G_OF_THETA.eval(x).unwrap_or(f32::NAN),
                normal::ellipse_shape(x as f64).unwrap().g(),
            )
        },
    ));
    rows.push(f32_row(
        "table 1/m(theta)",
        &format!(
            "theta in [2^{}, pi/2], every 2^{}-th f32",
            INV_M_OF_THETA.first_exponent(),
            t.trailing_zeros()
        ),
        INV_M_OF_THETA.lower(),
        top,
        t,
        |x| {
            (
                INV_M_OF_THETA.eval(x).unwrap_or(f32::NAN),
                1.0 / normal::ellipse_shape(x as f64).unwrap().m,
            )
        },
    ));
    // From g = 1 the core reads theta(g) from the finer top-octave table, as here.
    rows.push(f32_row(
        "table theta(g)",
        &format!(
            "g in [2^{}, pi/2] (from 1 its top-octave table), every 2^{}-th f32",
            THETA_OF_G.first_exponent(),
            t.trailing_zeros()
        ),
        THETA_OF_G.lower(),
        top,
        t,
        |x| {
            let got = if x >= 1.0 {
                theta_of_g_top(x)
            } else {
                THETA_OF_G.eval(x).unwrap_or(f32::NAN)
            };
            (got, normal::theta_for_g(x as f64).unwrap().theta)
        },
    ));
    // Fixed point: log2 of every u32 (error in log2 units, given as "ulps" of 2^-24).
    let step = if quick { 4099 } else { 1 };
    let (n, _, worst, at) = sweep(1, u32::MAX, step, |x| {
        let e = (log2_u32(x) as f64 / ONE as f64 - (x as f64).log2()).abs();
        (e * ONE as f64, e)
    });
    rows.push(Row {
        kernel: "log2_u32 (log2 units)".into(),
        domain: "every u32 >= 1".into(),
        points: n,
        max_ulps: worst * ONE as f64,
        max_rel: worst,
        at,
    });
    let (n, _, worst, at) = sweep(0, ONE as u32, 1, |f| {
        let l = 5 * ONE + f as i32;
        let got = exp2_fixed(l, 24) as f64 / ONE as f64;
        let want = (l as f64 / ONE as f64).exp2();
        let r = (got / want - 1.0).abs();
        (r * (1u64 << 29) as f64, r)
    });
    rows.push(Row {
        kernel: "exp2_fixed".into(),
        domain: "all 2^24 Q8.24 fractions".into(),
        points: n,
        max_ulps: worst * (1u64 << 29) as f64,
        max_rel: worst,
        at,
    });
    rows
}
