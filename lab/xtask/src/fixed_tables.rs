//! The fixed-point core's tables (Q8.24, uniform spacing, quadratic interpolation),
//! generated from the f64 reference into src/fixed/tables.rs, beside that core.

use misalign::fixed::uniform::{ONE, UniformTable};
use misalign::reference::{normal, tangential};
use std::f64::consts::FRAC_PI_2;
use std::fmt::Write;

/// One uniform table: values `f(start + i h)`, `h = 2^-spacing_log2`, for the domain
/// `[start, end]` plus the two nodes past it that interpolation reads.
#[derive(Clone, Copy)]
pub struct UniformSpec {
    pub name: &'static str,
    pub doc: &'static str,
    pub start: f64,
    pub end: f64,
    pub spacing_log2: u32,
    /// Function value in its natural units (stored as round(value * 2^24)).
    pub f: fn(f64) -> f64,
}

/// The ellipse at any k' > 0: k' > 1 continues m, n, g past theta = pi/2 (the
/// Carlson forms hold for any positive arguments), so that interpolation nodes just
/// past the domain's end are the function itself, not an extrapolation.
fn shape_at_theta(theta: f64) -> normal::EllipseShape {
    if theta <= FRAC_PI_2 {
        return normal::ellipse_shape(theta).expect("theta in [0, pi/2]");
    }
    let (mut lo, mut hi) = (1.0f64, 16.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if normal::shape_from_kprime(mid).theta < theta {
            lo = mid
        } else {
            hi = mid
        }
    }
    normal::shape_from_kprime(0.5 * (lo + hi))
}

pub fn g_of_log_theta(y: f64) -> f64 {
    shape_at_theta(y.exp2()).g().log2()
}

fn m_of_log_theta(y: f64) -> f64 {
    shape_at_theta(y.exp2()).m.log2()
}

pub fn log_theta_of_log_g(z: f64) -> f64 {
    let g = z.exp2();
    if g <= FRAC_PI_2 {
        return normal::theta_for_g(g).expect("g in range").theta.log2();
    }
    let (mut lo, mut hi) = (1.0f64, 16.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if normal::shape_from_kprime(mid).g() < g {
            lo = mid
        } else {
            hi = mid
        }
    }
    normal::shape_from_kprime(0.5 * (lo + hi)).theta.log2()
}

fn log_force_over_s(s: f64) -> f64 {
    if s <= 0.0 {
        (0.75 * std::f64::consts::PI).log2()
    } else if s >= 1.0 {
        (1.0 / s).log2() // F = mu P above s = 1: eq (21) meets it with two derivatives
    } else {
        (tangential::axial_force_ratio(s) / s).log2()
    }
}

/// Where the log-log table of g switches from coarse to fine spacing: below
/// log2 theta = -4 its third derivative stays under 2e-3, above it reaches 1.1.
pub const SPLIT_G: f64 = -4.0;
/// The same for theta(g): its third derivative stays under 1.3e-3 below log2 g = -6.
pub const SPLIT_THETA: f64 = -6.0;

/// Spacing exponents (the shapes weighed by `cargo xtask shapes`).
pub fn specs() -> [UniformSpec; 9] {
    let top = FRAC_PI_2.log2();
    [
        UniformSpec {
            name: "LOG2_MANTISSA",
            doc: "log2(1 + x), x in [0, 1): the fraction part of an integer's log2.",
            start: 0.0,
            end: 1.0,
            spacing_log2: 7,
            f: |x| (1.0 + x).log2(),
        },
        UniformSpec {
            name: "EXP2_FRACTION",
            doc: "2^x, x in [0, 1): the mantissa of an exponential.",
            start: 0.0,
            end: 1.0,
            spacing_log2: 6,
            f: |x| x.exp2(),
        },
        UniformSpec {
            name: "LOG_G_LOW",
            doc: "log2 g(theta) against y = log2 theta, y from -40 to -4 (eqs 5, 6, 16).",
            start: -40.0,
            end: SPLIT_G,
            spacing_log2: 2,
            f: g_of_log_theta,
        },
        UniformSpec {
            name: "LOG_G_HIGH",
            doc: "log2 g(theta) against y = log2 theta, y from -4 to log2(pi/2) (eqs 5, 6, 16).",
            start: SPLIT_G,
            end: top,
            spacing_log2: 5,
            f: g_of_log_theta,
        },
        UniformSpec {
            name: "LOG_THETA_LOW",
            doc: "log2 theta(g) against log2 g from -27 to -6: the critical angle (eq 18).",
            start: -27.0,
            end: SPLIT_THETA,
            spacing_log2: 2,
            f: log_theta_of_log_g,
        },
        UniformSpec {
            name: "LOG_THETA_HIGH",
            doc: "log2 theta(g) against log2 g from -6 to log2(pi/2): the critical angle (eq 18).",
            start: SPLIT_THETA,
            end: top,
            spacing_log2: 5,
            f: log_theta_of_log_g,
        },
        UniformSpec {
            name: "LOG_M_LOW",
            doc: "log2 m(theta) against y = log2 theta, y from -40 to -4 (eqs 5, 6): details only.",
            start: -40.0,
            end: SPLIT_G,
            spacing_log2: 2,
            f: m_of_log_theta,
        },
        UniformSpec {
            name: "LOG_M_HIGH",
            doc: "log2 m(theta) against y = log2 theta, y from -4 to log2(pi/2) (eqs 5, 6): details only.",
            start: SPLIT_G,
            end: top,
            spacing_log2: 5,
            f: m_of_log_theta,
        },
        // Against s, one exp2 per partial-slip sample: 524 bytes, where tables against
        // log2 s (some 6 instructions fewer on a Cortex-M0) took 1476, more than a
        // monitoring node in 16 KiB of flash can spare.
        UniformSpec {
            name: "LOG_FORCE_OVER_S",
            doc: "log2(F/(mu P) / s) against s = d/b in [0, 1) (eq 21), s in Q0.24.",
            start: 0.0,
            end: 1.0,
            spacing_log2: 7,
            f: log_force_over_s,
        },
    ]
}

/// Number of nodes: the domain plus two past it.
pub fn nodes(spec: &UniformSpec) -> usize {
    let h = (-(spec.spacing_log2 as f64)).exp2();
    ((spec.end - spec.start) / h).ceil() as usize + 3
}

/// The Q8.24 values.
pub fn values(spec: &UniformSpec) -> Vec<i32> {
    let h = (-(spec.spacing_log2 as f64)).exp2();
    (0..nodes(spec))
        .map(|i| ((spec.f)(spec.start + i as f64 * h) * ONE as f64).round() as i32)
        .collect()
}

/// Worst absolute error (in the value's units) of the library's interpolation over
/// `samples` points per segment inside the domain, and the largest |second difference|.
pub fn measure(spec: &UniformSpec, values: &[i32], samples: usize) -> (f64, i32) {
    let table = UniformTable {
        start: (spec.start * ONE as f64) as i32,
        spacing_log2: spec.spacing_log2,
        values,
    };
    let h = (-(spec.spacing_log2 as f64)).exp2();
    let mut worst: f64 = 0.0;
    for i in 0..nodes(spec) - 3 {
        for k in 0..samples {
            // Off the grid of t (Q16 of a segment): the rounding of t counts too.
            let x = spec.start + (i as f64 + (k as f64 + 0.382) / samples as f64) * h;
            if x > spec.end {
                continue;
            }
            let xq = (x * ONE as f64).round() as i32;
            let got = table.eval(xq).expect("inside") as f64 / ONE as f64;
            worst = worst.max((got - (spec.f)(xq as f64 / ONE as f64)).abs());
        }
    }
    let d2 = values
        .windows(3)
        .map(|w| (w[2] - 2 * w[1] + w[0]).abs())
        .max()
        .unwrap_or(0);
    (worst, d2)
}

/// The fixed-point core's generated tables, `src/fixed/tables.rs`.
pub fn source() -> String {
    let mut out = String::from(
        "//! Tables of the fixed-point core (Q8.24, uniform spacing, quadratic interpolation),\n\
         //! generated from the f64 reference by `cargo xtask tables` (lab/xtask/src/fixed_tables.rs).\n\
         //! Do not edit: a test regenerates this file and fails on any drift.\n\n\
         use super::uniform::UniformTable;\n\n",
    );
    for spec in specs() {
        let v = values(&spec);
        let (worst, d2) = measure(&spec, &v, 16);
        assert!(
            d2 < 1 << 16,
            "{}: second differences too large for the kernel",
            spec.name
        );
        writeln!(out, "/// {}", spec.doc).unwrap();
        writeln!(
            out,
            "/// Q8.24, spacing 2^-{}, quadratic interpolation; worst error {worst:.1e} at the generator's check.",
            spec.spacing_log2
        )
        .unwrap();
        writeln!(
            out,
            "pub const {}: UniformTable<'static> = UniformTable {{",
            spec.name
        )
        .unwrap();
        writeln!(out, "    start: {},", (spec.start * ONE as f64) as i32).unwrap();
        writeln!(out, "    spacing_log2: {},", spec.spacing_log2).unwrap();
        out.push_str("    values: &[\n");
        for chunk in v.chunks(8) {
            let line: Vec<String> = chunk.iter().map(|x| x.to_string()).collect();
            writeln!(out, "        {},", line.join(", ")).unwrap();
        }
        out.push_str("    ],\n};\n\n");
    }
    out.pop();
    out
}
