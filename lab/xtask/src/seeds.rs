//! `cargo xtask tables`: the f64 seed tables of the reference's fast path
//! (src/reference/fast/seeds.rs): k' as a function of theta and of `g^3`, fitted to the
//! f64 reference, one polynomial per segment interpolating it at Chebyshev nodes. They
//! start one Newton step, so 1e-9 is what they need.

use crate::fit::chebyshev_fit;
use misalign::reference::fast::table::{DEGREE, WIDTH, x_of};
use misalign::reference::normal;
use std::fmt::Write;

/// Segments per octave (log2) of the theta table and of the `g^3` table (an octave of
/// `g^3` is about half one of theta).
const THETA_SEGMENTS_LOG2: u32 = 2;
const G_CUBED_SEGMENTS_LOG2: u32 = 1;

/// The theta domain: [2^-40, 2^-3).
const THETA_EXPONENTS: (i32, i32) = (-40, -3);

fn kprime_of_theta(theta: f64) -> f64 {
    normal::ellipse_shape(theta)
        .expect("theta in the domain")
        .kprime
}

fn g_cubed_of_theta(theta: f64) -> f64 {
    let g = normal::ellipse_shape(theta)
        .expect("theta in the domain")
        .g();
    g * g * g
}

/// `k'^2` (nearly proportional to `g^3`, so that a polynomial fits it far better than k').
fn kprime_squared_of_g_cubed(y: f64) -> f64 {
    let k = normal::theta_for_g(libm::cbrt(y))
        .expect("g in the domain")
        .kprime;
    k * k
}

/// The exponents of the `g^3` table: every octave whose `g^3` lies within the theta
/// domain's.
fn g_cubed_exponents() -> (i32, i32) {
    let lo = g_cubed_of_theta(libm::ldexp(1.0, THETA_EXPONENTS.0));
    let hi = g_cubed_of_theta(libm::ldexp(1.0, THETA_EXPONENTS.1));
    (libm::log2(lo).ceil() as i32, libm::log2(hi).floor() as i32)
}

/// The segments of one table, and its worst relative error at 64 points a segment.
fn fit(
    first_exponent: i32,
    octaves: i32,
    segments_log2: u32,
    f: fn(f64) -> f64,
) -> (Vec<Vec<f64>>, f64) {
    let n = (octaves as usize) << segments_log2;
    let mut worst: f64 = 0.0;
    let segments = (0..n)
        .map(|i| {
            let at = |tau: f64| x_of(first_exponent, segments_log2, i, tau);
            let c = chebyshev_fit(|tau| f(at(tau)), -1.0, 1.0, DEGREE);
            for k in 0..64 {
                let tau = -1.0 + (k as f64 + 0.5) / 32.0;
                let got = c.iter().rev().fold(0.0, |acc, &ck| acc * tau + ck);
                worst = worst.max((got / f(at(tau)) - 1.0).abs());
            }
            c
        })
        .collect();
    (segments, worst)
}

fn table(
    out: &mut String,
    name: &str,
    doc: &str,
    (first, end): (i32, i32),
    segments_log2: u32,
    f: fn(f64) -> f64,
) {
    let (segments, worst) = fit(first, end - first, segments_log2, f);
    writeln!(
        out,
        "/// Coefficients of [`{name}`], {} segments an octave.",
        1 << segments_log2
    )
    .unwrap();
    writeln!(
        out,
        "pub const {name}_SEGMENTS: [Segment; {}] = [",
        segments.len()
    )
    .unwrap();
    for c in &segments {
        let pad = std::iter::repeat_n(&0.0, WIDTH - c.len());
        let items: Vec<String> = c.iter().chain(pad).map(|x| format!("{x:?}")).collect();
        writeln!(out, "    [{}],", items.join(", ")).unwrap();
    }
    out.push_str("];\n\n");
    writeln!(out, "/// {doc}").unwrap();
    writeln!(
        out,
        "/// From 2^{first} to 2^{end}, degree {DEGREE}; worst relative error {worst:.1e} at the generator's check."
    )
    .unwrap();
    writeln!(
        out,
        "pub const {name}: Table<'static, {segments_log2}> = Table::new({first}, &{name}_SEGMENTS);\n"
    )
    .unwrap();
}

/// The generated file.
pub fn source() -> String {
    let mut out = String::new();
    out.push_str(
        "//! Seed tables of the reference's fast path (src/reference/fast/table.rs), generated\n\
         //! from the f64 reference by `cargo xtask tables` (lab/xtask/src/seeds.rs).\n\
         //! Do not edit: a test regenerates this file and fails on any drift.\n\n\
         use super::table::{Segment, Table};\n\n",
    );
    table(
        &mut out,
        "KPRIME_OF_THETA",
        "k'(theta) (eqs 5, 6).",
        THETA_EXPONENTS,
        THETA_SEGMENTS_LOG2,
        kprime_of_theta,
    );
    table(
        &mut out,
        "KPRIME_SQUARED_OF_G_CUBED",
        "`k'^2` at `g^3`, `g = m n theta` (eqs 5, 6, 18).",
        g_cubed_exponents(),
        G_CUBED_SEGMENTS_LOG2,
        kprime_squared_of_g_cubed,
    );
    out.pop();
    out
}
