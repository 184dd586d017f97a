//! `cargo xtask tables`: the f32 core's tables, fitted to the project's own f64
//! reference and written as Rust source (`src/tables.rs`).
//!
//! Every table here is an "octave table": the input x > 0 is split by its f32 bits into
//! segments (2^M per octave of x), and on each segment the function is one polynomial of
//! degree D in the local variable `t = u - 3/2`, u the mantissa of x in [1, 2) (so t in
//! [-1/2, 1/2), each segment a part of it). The firmware finds the segment with a shift
//! and evaluates by Horner: no logarithm, no search.

use crate::fit::{horner_f32, minimax_relative_fit, minimax_weighted_fit};
use misalign::float::octave::{CENTER, COMPACT, DEGREE, SEGMENTS_LOG2, WIDE};
use misalign::reference::{normal, tangential};
use std::f64::consts::FRAC_PI_2;
use std::fmt::Write;

/// One octave table to generate.
#[derive(Clone, Copy)]
pub struct OctaveSpec {
    /// Name of the `pub static` in the generated source.
    pub name: &'static str,
    /// What it holds, for the doc comment.
    pub doc: &'static str,
    /// Unbiased f32 exponent of the first octave: x from 2^first.
    pub first_exponent: i32,
    /// Number of octaves: x below 2^(first + octaves).
    pub octaves: i32,
    /// log2 of the segments per octave (M).
    pub segments_log2: u32,
    /// Polynomial degree D.
    pub degree: usize,
    /// Floats per segment in the generated source (the degree's, or padded).
    pub width: usize,
    /// x above this is outside the domain (fit only up to it).
    pub domain_max: f64,
    /// The function, in f64.
    pub f: fn(f64) -> f64,
}

/// g(theta) = m n theta (eqs 5, 6, 16): alone it gives the slip ratio.
pub fn g_of_theta(theta: f64) -> f64 {
    normal::ellipse_shape(theta)
        .expect("theta in the domain")
        .g()
}
/// 1/m(theta) (eqs 5, 6), a = m L: like g a positive power of theta (2/3), which a
/// polynomial per octave fits 20 times better than m's negative power.
pub fn inv_m_of_theta(theta: f64) -> f64 {
    1.0 / normal::ellipse_shape(theta).expect("theta in the domain").m
}
/// theta(g), the inverse of g: gives the critical angle.
pub fn theta_of_g(g: f64) -> f64 {
    normal::theta_for_g(g).expect("g in the domain").theta
}

/// The tables the library ships (their shapes weighed by `cargo xtask shapes`).
pub fn specs() -> [OctaveSpec; 3] {
    [
        OctaveSpec {
            name: "G_OF_THETA",
            doc: "g(theta) = m n theta (eqs 5, 6), theta from 2^-32 to pi/2 (below, the\n\
                  /// small-theta asymptotics), in wide segments.",
            first_exponent: -32,
            octaves: 33,
            segments_log2: SEGMENTS_LOG2,
            degree: DEGREE,
            width: WIDE,
            domain_max: FRAC_PI_2,
            f: g_of_theta,
        },
        OctaveSpec {
            name: "INV_M_OF_THETA",
            doc: "1/m(theta) (eqs 5, 6), theta from 2^-40 to pi/2; n = g / (m theta).",
            first_exponent: -40,
            octaves: 41,
            segments_log2: SEGMENTS_LOG2,
            degree: DEGREE,
            width: COMPACT,
            domain_max: FRAC_PI_2,
            f: inv_m_of_theta,
        },
        OctaveSpec {
            name: "THETA_OF_G",
            doc: "theta(g), the inverse of g(theta), g from 2^-27 to pi/2, in wide segments\n\
                  /// (its top octave, from g = 1, is less accurate than the rest: the estimate\n\
                  /// reads a finer table there).",
            first_exponent: -27,
            octaves: 28,
            segments_log2: SEGMENTS_LOG2,
            degree: DEGREE,
            width: WIDE,
            domain_max: FRAC_PI_2,
            f: theta_of_g,
        },
    ]
}

/// theta(g) on its top octave, g in [1, pi/2], where theta(g) bends the most (theta
/// near pi/2): four segments instead of two.
pub fn theta_top_spec() -> OctaveSpec {
    OctaveSpec {
        name: "THETA_OF_G_TOP",
        doc: "theta(g) for g from 1 to pi/2, four segments (the octave of [`THETA_OF_G`] there\n\
              /// is the least accurate).",
        first_exponent: 0,
        octaves: 1,
        segments_log2: 2,
        degree: DEGREE,
        width: COMPACT,
        domain_max: FRAC_PI_2,
        f: theta_of_g,
    }
}

/// x at local coordinate t of segment `seg` (counted from the table's first segment).
pub fn x_of(spec: &OctaveSpec, seg: usize, t: f64) -> f64 {
    let per = 1usize << spec.segments_log2;
    let e = spec.first_exponent + (seg / per) as i32;
    let j = (seg % per) as f64;
    2f64.powi(e) * (1.0 + (j + t) / per as f64)
}

/// Number of segments.
pub fn segments(spec: &OctaveSpec) -> usize {
    (spec.octaves as usize) << spec.segments_log2
}

/// The fitted f32 coefficients, segment by segment: in t = u - 3/2 on the segment's
/// part of [-1/2, 1/2) (cut at the domain's end), smallest maximum relative error.
pub fn fit(spec: &OctaveSpec) -> Vec<Vec<f32>> {
    (0..segments(spec))
        .map(|seg| {
            let scale = 2f64.powi(spec.first_exponent + (seg >> spec.segments_log2) as i32);
            let (x0, x1) = (x_of(spec, seg, 0.0), x_of(spec, seg, 1.0));
            if x0 >= spec.domain_max {
                // Beyond the domain (the top table's last quarter): never read.
                return vec![0.0; spec.degree + 1];
            }
            let (u0, u1) = (x0 / scale, x1.min(spec.domain_max) / scale);
            minimax_relative_fit(
                |t| (spec.f)(scale * (t + CENTER)),
                u0 - CENTER,
                u1 - CENTER,
                spec.degree,
            )
            .iter()
            .map(|&c| c as f32)
            .collect()
        })
        .collect()
}

/// Evaluates a fitted table at f32 x exactly as the library does; `None` outside.
pub fn eval(spec: &OctaveSpec, coeffs: &[Vec<f32>], x: f32) -> Option<f32> {
    let shift = 23 - spec.segments_log2;
    let base = ((spec.first_exponent + 127) as u32) << spec.segments_log2;
    let index = (x.to_bits() >> shift).checked_sub(base)? as usize;
    let u = f32::from_bits((x.to_bits() & 0x007f_ffff) | 0x3f80_0000);
    coeffs.get(index).map(|c| horner_f32(c, u - CENTER as f32))
}

/// Worst relative error of the f32 table against the f64 function over `samples`
/// f32 points per segment, and where.
pub fn measure(spec: &OctaveSpec, coeffs: &[Vec<f32>], samples: usize) -> (f64, f64) {
    let mut worst = (0.0, 0.0);
    for seg in 0..segments(spec) {
        for k in 0..samples {
            let x = x_of(spec, seg, (k as f64 + 0.5) / samples as f64) as f32;
            if x as f64 >= spec.domain_max {
                continue;
            }
            let got = eval(spec, coeffs, x).expect("inside the table") as f64;
            let want = (spec.f)(x as f64);
            let e = (got / want - 1.0).abs();
            if e > worst.0 {
                worst = (e, x as f64);
            }
        }
    }
    worst
}

/// Degrees of the two pieces of the axial-force kernel.
pub const AXIAL_FORCE_DEGREES: (usize, usize) = (5, 4);

/// `F/(mu P) / s` as a polynomial in s on [0, 1/2] (eq 21 is analytic there), and
/// `(1 - F/(mu P)) / u^5` as a polynomial in `u = sqrt(1 - s)` on [0, sqrt(1/2)]
/// (eq 21's `(1 - s)^(5/2)` branch point factored out; what is left is analytic).
pub fn fit_axial_force(low: usize, high: usize) -> (Vec<f32>, Vec<f32>) {
    let ratio = |s: f64| {
        if s == 0.0 {
            0.75 * std::f64::consts::PI
        } else {
            tangential::axial_force_ratio(s) / s
        }
    };
    // The relative error of F/(mu P) itself, smallest at its largest.
    let lo = minimax_relative_fit(ratio, 0.0, 0.5, low);
    let tail = |u: f64| {
        if u == 0.0 {
            0.8 * std::f64::consts::SQRT_2 // the limit (4 sqrt 2 / 5)
        } else {
            (1.0 - tangential::axial_force_ratio((1.0 - u) * (1.0 + u))) / u.powi(5)
        }
    };
    // An error of the tail counts (1 - F/(mu P)) / (F/(mu P)) times in F/(mu P).
    let weight = |u: f64| {
        let f = tangential::axial_force_ratio((1.0 - u) * (1.0 + u));
        ((1.0 - f) / f).max(1e-12)
    };
    // From u = 1/50: below, 1 - F/(mu P) < 4e-9 is lost to f64's rounding of F/(mu P),
    // and its weight is as small (the polynomial carries on to u = 0).
    let hi = minimax_weighted_fit(tail, weight, 0.02, 0.5f64.sqrt(), high);
    let f32s = |v: Vec<f64>| v.iter().map(|&c| c as f32).collect();
    (f32s(lo), f32s(hi))
}

/// One segment's coefficients as Rust: `[c0, c1, ...]`, padded with zeros to `width`.
fn segment_text(c: &[f32], width: usize) -> String {
    // {:?} prints the shortest text that reads back to the same f32.
    let pad = std::iter::repeat_n(&0.0, width.saturating_sub(c.len()));
    let items: Vec<String> = c.iter().chain(pad).map(|x| format!("{x:?}")).collect();
    format!("[{}]", items.join(", "))
}

/// The generated files: `(path under the repository root, text)`.
pub fn generated() -> [(&'static str, String); 4] {
    [
        ("src/float/tables.rs", source()),
        ("src/reference/fast/seeds.rs", crate::seeds::source()),
        ("src/fixed/tables.rs", crate::fixed_tables::source()),
        ("nodes/firmware/trace.rs", crate::trace::source()),
    ]
}

/// The f32 core's generated tables, `src/float/tables.rs`.
pub fn source() -> String {
    let mut out = String::new();
    out.push_str(
        "//! Tables of the f32 core (octave polynomials; the axial force's two pieces),\n\
         //! generated from the f64 reference by `cargo xtask tables` (lab/xtask/src/tables.rs).\n\
         //! Do not edit: a test regenerates this file and fails on any drift.\n\n\
         use super::octave::{OctaveTable, Row, Segment};\n\n",
    );
    for spec in specs() {
        let coeffs = fit(&spec);
        let per = 1usize << spec.segments_log2;
        // theta(g)'s top octave is THETA_OF_G_TOP's: the check covers the octaves below.
        let checked = if spec.name == "THETA_OF_G" {
            OctaveSpec {
                octaves: spec.octaves - 1,
                ..spec
            }
        } else {
            spec
        };
        let (worst, _) = measure(&checked, &coeffs[..segments(&checked)], 64);
        writeln!(
            out,
            "/// Coefficients of [`{}`], one row per octave: its {per} segments.",
            spec.name
        )
        .unwrap();
        let row = if spec.width == COMPACT {
            "Row".to_string()
        } else {
            format!("Row<{}>", spec.width)
        };
        writeln!(
            out,
            "pub const {}_ROWS: [{row}; {}] = [",
            spec.name, spec.octaves
        )
        .unwrap();
        for octave in coeffs.chunks(per) {
            let segs: Vec<String> = octave.iter().map(|c| segment_text(c, spec.width)).collect();
            writeln!(out, "    [{}],", segs.join(", ")).unwrap();
        }
        out.push_str("];\n\n");
        writeln!(out, "/// {}", spec.doc).unwrap();
        writeln!(
            out,
            "/// Degree {} on each half octave from 2^{}; worst relative error {worst:.1e} at the generator's check{}.",
            spec.degree,
            spec.first_exponent,
            if checked.octaves < spec.octaves {
                " below its top octave"
            } else {
                ""
            }
        )
        .unwrap();
        writeln!(
            out,
            "pub const {0}: OctaveTable<'static{2}> = OctaveTable::new({1}, &{0}_ROWS);\n",
            spec.name,
            spec.first_exponent,
            if spec.width == COMPACT {
                String::new()
            } else {
                format!(", {}", spec.width)
            }
        )
        .unwrap();
    }
    let top = theta_top_spec();
    let coeffs = fit(&top);
    let (worst, _) = measure(&top, &coeffs, 64);
    writeln!(out, "/// {}", top.doc).unwrap();
    writeln!(
        out,
        "/// Degree {}; worst relative error {worst:.1e} at the generator's check.",
        top.degree
    )
    .unwrap();
    writeln!(
        out,
        "pub const {}: [Segment; {}] = [",
        top.name,
        coeffs.len()
    )
    .unwrap();
    for c in &coeffs {
        writeln!(out, "    {},", segment_text(c, top.width)).unwrap();
    }
    out.push_str("];\n\n");
    let (lo, hi) = fit_axial_force(AXIAL_FORCE_DEGREES.0, AXIAL_FORCE_DEGREES.1);
    let pieces = [
        (
            "AXIAL_FORCE_LOW",
            "`F/(mu P) / s` in s for s < 1/2 (eq 21), lowest power first.",
            lo,
        ),
        (
            "AXIAL_FORCE_HIGH",
            "`(1 - F/(mu P)) / u^5` in `u = sqrt(1 - s)` for s >= 1/2 (eq 21), lowest power first.",
            hi,
        ),
    ];
    for (name, doc, c) in pieces {
        writeln!(out, "/// {doc}").unwrap();
        writeln!(out, "pub static {name}: [f32; {}] = [", c.len()).unwrap();
        for x in &c {
            writeln!(out, "    {x:?},").unwrap();
        }
        out.push_str("];\n\n");
    }
    out.pop();
    out
}
