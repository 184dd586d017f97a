//! `cargo xtask shapes [--short] [--csv]`: the table shapes weighed, each with its
//! instructions, bytes and error, measured in one run beside the library's kernel.
//!
//! The f32 core's tables g(theta) and theta(g) (octave polynomials,
//! src/float/octave.rs) in every variable (the segment's mantissa `u` in [1, 2), as the
//! library, or `t = u - 1`), 1, 2 or 4 segments per octave and degree 2 to 7; the
//! fixed-point core's log2 g against log2 theta and log2 theta(g) against log2 g
//! (uniform Q8.24, src/fixed/uniform.rs) with linear or quadratic interpolation, in one
//! table or two (coarse below the library's split, fine above), at spacings 2^-k.
//!
//! - Tables: fitted here, as `cargo xtask tables` fits the library's (the shape the
//!   library ships comes out bit for bit the library's table: checked), and written as
//!   Rust source for the harness's `shapes` image (`MISALIGN_SHAPES_TABLES`).
//! - Instructions: that image in QEMU (`-icount`), mean and maximum over inputs spread
//!   evenly in log2 over each table's domain; the f32 shapes on the Cortex-M4F (the
//!   Cortex-M7 counts the same instructions), the fixed-point ones on the Cortex-M0 and
//!   M3. The same run measures the library's kernel on the same inputs (`library`).
//! - Error: the same evaluators (`lab/harness/src/shapes.rs`, compiled here too) on the
//!   host, the worst relative error against the f64 reference over every 2^11-th f32 of
//!   the domain and the first and last f32 of every quarter octave (f32), or every
//!   2^12-th Q8.24 argument (fixed point: the error of log2 times ln 2, the relative
//!   error of the value it stands for).
//! - Bytes: the table data in flash (rows padded to a power of two, as the library's).
//!
//! Writes docs/shapes.csv and docs/table-shapes.svg (`--short`: 32 inputs on the
//! target instead of 256, writes nothing); prints, per core and table, the library's
//! kernel and the shapes on its two Pareto fronts (among the shapes no larger than the
//! library's tables, and at any size; errors within 10 % count as equal), or with
//! `--csv` the whole CSV.

use crate::cross::{self, CPUS};
use crate::fit::chebyshev_fit;
use crate::fixed_tables::{self, UniformSpec};
use crate::log::Fields;
use crate::measurements::shapes::table;
use crate::records::{self, ShapeRow};
use crate::tables::{self, OctaveSpec};
use misalign::fixed::tables as fixed_lib;
use misalign::fixed::uniform::{ONE, UniformTable};
use misalign::float::octave::{OctaveTable, Row, WIDE};
use std::collections::HashMap;
use std::f64::consts::{FRAC_PI_2, LN_2};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

/// The evaluators the `shapes` image runs, compiled for the host: the error is
/// measured on the target's arithmetic.
#[path = "../../harness/src/shapes.rs"]
mod eval;
use eval::{Linear, Octaves, Uniform, lookup};

/// An f32 table of the library and the function it holds.
struct F32Table {
    /// `g`, `theta_of_g`: the name in the CSV and in the image's lines.
    name: &'static str,
    /// The library's spec (its domain, function, shape).
    spec: OctaveSpec,
    /// The library's kernel and its rows.
    library: OctaveTable<'static, WIDE>,
    rows: &'static [Row<WIDE>],
}

fn f32_tables() -> [F32Table; 2] {
    let [g, _, theta] = tables::specs();
    [
        F32Table {
            name: "g",
            spec: g,
            library: misalign::float::G_OF_THETA,
            rows: &misalign::float::G_OF_THETA_ROWS,
        },
        F32Table {
            name: "theta_of_g",
            spec: theta,
            library: misalign::float::THETA_OF_G,
            rows: &misalign::float::THETA_OF_G_ROWS,
        },
    ]
}

/// One shape of an octave table.
#[derive(Clone, Copy, PartialEq, Debug)]
struct F32Shape {
    /// Variable `t = u - 1` instead of the mantissa `u`.
    t: bool,
    /// log2 of the segments per octave.
    m: u32,
    /// Degree.
    d: usize,
}

impl F32Shape {
    fn id(&self) -> String {
        format!("{}-s{}-d{}", self.variable(), 1 << self.m, self.d)
    }
    fn variable(&self) -> &'static str {
        if self.t { "t" } else { "u" }
    }
    /// Coefficients per row: `D + 1` padded to a power of two.
    fn width(&self) -> usize {
        (self.d + 1).next_power_of_two()
    }
    fn spec(&self, table: &OctaveSpec) -> OctaveSpec {
        OctaveSpec {
            segments_log2: self.m,
            degree: self.d,
            ..*table
        }
    }
}

fn f32_shapes() -> Vec<F32Shape> {
    let mut out = Vec::new();
    for t in [false, true] {
        for m in 0..=2 {
            for d in 2..=7 {
                out.push(F32Shape { t, m, d });
            }
        }
    }
    out
}

/// The coefficients of `shape` for `table`: `tables::fit` (Chebyshev interpolation
/// per segment, in `u` on [1, 2) or in `t` on [0, 1)), without the segments that lie
/// wholly past the domain (a quarter octave past pi/2).
fn fit_f32(table: &OctaveSpec, shape: F32Shape) -> Vec<Vec<f32>> {
    let spec = shape.spec(table);
    let offset = if shape.t { 0.0 } else { 1.0 };
    (0..tables::segments(&spec))
        .map(|seg| {
            (
                seg,
                tables::x_of(&spec, seg, 0.0),
                tables::x_of(&spec, seg, 1.0),
            )
        })
        .take_while(|&(_, x0, _)| x0 < spec.domain_max)
        .map(|(seg, x0, x1)| {
            let span = if x1 > spec.domain_max {
                (spec.domain_max - x0) / (x1 - x0)
            } else {
                1.0
            };
            chebyshev_fit(
                |v| (spec.f)(tables::x_of(&spec, seg, v - offset)),
                offset,
                offset + span,
                spec.degree,
            )
            .iter()
            .map(|&c| c as f32)
            .collect()
        })
        .collect()
}

/// Rows padded to `W`.
fn padded<const W: usize>(coeffs: &[Vec<f32>]) -> Vec<[f32; W]> {
    coeffs
        .iter()
        .map(|c| {
            let mut row = [0.0; W];
            row[..c.len()].copy_from_slice(c);
            row
        })
        .collect()
}

/// Worst relative error of `f` over `grid` (`(x, exact f(x))`); `None` or NaN is
/// infinite.
fn worst_f32(grid: &[(f32, f64)], f: impl Fn(f32) -> Option<f32>) -> f64 {
    grid.iter()
        .map(|&(x, want)| {
            f(x).map_or(f64::INFINITY, |got| {
                let e = (got as f64 / want - 1.0).abs();
                if e.is_nan() { f64::INFINITY } else { e }
            })
        })
        .fold(0.0, f64::max)
}

/// The error of one shape, through its evaluator `Octaves::<M, D, W, T>`.
fn f32_error<const M: u32, const D: usize, const W: usize, const T: bool>(
    first_exponent: i32,
    coeffs: &[Vec<f32>],
    grid: &[(f32, f64)],
) -> f64 {
    let rows = padded::<W>(coeffs);
    let table = Octaves::<M, D, W, T>::new(first_exponent, &rows);
    worst_f32(grid, |x| table.eval(x))
}

/// Calls `$f::<M, D, W, T>$args` for the runtime shape `$s` (every shape of
/// [`f32_shapes`]).
macro_rules! with_f32_shape {
    ($s:expr, $f:ident $args:tt) => {
        with_f32_shape!(@ $s, $f $args;
            (0, 2, 4) (0, 3, 4) (0, 4, 8) (0, 5, 8) (0, 6, 8) (0, 7, 8)
            (1, 2, 4) (1, 3, 4) (1, 4, 8) (1, 5, 8) (1, 6, 8) (1, 7, 8)
            (2, 2, 4) (2, 3, 4) (2, 4, 8) (2, 5, 8) (2, 6, 8) (2, 7, 8))
    };
    (@ $s:expr, $f:ident $args:tt; $(($m:literal, $d:literal, $w:literal))*) => {
        match ($s.m, $s.d, $s.t) {
            $(
                ($m, $d, false) => $f::<$m, $d, $w, false> $args,
                ($m, $d, true) => $f::<$m, $d, $w, true> $args,
            )*
            _ => unreachable!("no evaluator for {:?}", $s),
        }
    };
}

/// A fixed-point table of the library: two uniform tables split at `split`.
struct FixedTable {
    /// `log_g`, `log_theta_of_g`.
    name: &'static str,
    /// The function, log2 against log2.
    f: fn(f64) -> f64,
    start: f64,
    split: f64,
    end: f64,
    /// The library's two tables.
    library: [UniformTable<'static>; 2],
}

fn fixed_tables() -> [FixedTable; 2] {
    let end = FRAC_PI_2.log2();
    [
        FixedTable {
            name: "log_g",
            f: fixed_tables::g_of_log_theta,
            start: -40.0,
            split: fixed_tables::SPLIT_G,
            end,
            library: [fixed_lib::LOG_G_LOW, fixed_lib::LOG_G_HIGH],
        },
        FixedTable {
            name: "log_theta_of_g",
            f: fixed_tables::log_theta_of_log_g,
            start: -27.0,
            split: fixed_tables::SPLIT_THETA,
            end,
            library: [fixed_lib::LOG_THETA_LOW, fixed_lib::LOG_THETA_HIGH],
        },
    ]
}

/// One shape of a uniform table: interpolation and spacing(s) 2^-k, one table over the
/// whole domain or two split where the library splits.
#[derive(Clone, Copy, PartialEq, Debug)]
struct FixedShape {
    quadratic: bool,
    /// Spacing exponents: `[k]` or `[k_low, k_high]`.
    spacing: Spacing,
}

#[derive(Clone, Copy, PartialEq, Debug)]
enum Spacing {
    One(u32),
    Two(u32, u32),
}

/// The shape the library ships (src/fixed/tables.rs, for both tables).
const FIXED_SHIPPED: FixedShape = FixedShape {
    quadratic: true,
    spacing: Spacing::Two(2, 5),
};

impl FixedShape {
    /// `quad-4+32`: interpolation, segments per octave of the value the argument is the
    /// log2 of (2^k per unit of log2).
    fn id(&self) -> String {
        format!(
            "{}-{}",
            if self.quadratic { "quad" } else { "lin" },
            self.segments()
        )
    }
    fn segments(&self) -> String {
        match self.spacing {
            Spacing::One(k) => format!("{}", 1u32 << k),
            Spacing::Two(a, b) => format!("{}+{}", 1u32 << a, 1u32 << b),
        }
    }
    fn degree(&self) -> u32 {
        if self.quadratic { 2 } else { 1 }
    }
}

/// Quadratic and linear, in one table and in two; spacings from coarse to as fine as
/// the Q16 position allows (2^-8).
fn fixed_shapes() -> Vec<FixedShape> {
    let mut out = Vec::new();
    for quadratic in [true, false] {
        let fine = if quadratic { 2..=6 } else { 4..=8 };
        for k in fine.clone() {
            out.push(FixedShape {
                quadratic,
                spacing: Spacing::One(k),
            });
        }
        let (lows, highs) = if quadratic {
            (0..=3, 3..=7)
        } else {
            (2..=5, 5..=8)
        };
        for a in lows {
            for b in highs.clone() {
                if b > a {
                    out.push(FixedShape {
                        quadratic,
                        spacing: Spacing::Two(a, b),
                    });
                }
            }
        }
    }
    out
}

/// `(start, spacing_log2, Q8.24 values)` of each piece of `shape`: the library's
/// generator's nodes (`fixed_tables::values`), one fewer past the end for linear.
type Piece = (i32, u32, Vec<i32>);

fn fixed_pieces(table: &FixedTable, shape: FixedShape) -> Vec<Piece> {
    let piece = |start: f64, end: f64, k: u32| {
        let spec = UniformSpec {
            name: "",
            doc: "",
            start,
            end,
            spacing_log2: k,
            f: table.f,
        };
        let mut values = fixed_tables::values(&spec);
        if !shape.quadratic {
            values.pop();
        }
        ((start * ONE as f64) as i32, k, values)
    };
    match shape.spacing {
        Spacing::One(k) => vec![piece(table.start, table.end, k)],
        Spacing::Two(a, b) => vec![
            piece(table.start, table.split, a),
            piece(table.split, table.end, b),
        ],
    }
}

/// Whether the library's quadratic kernel holds for these values (second differences
/// below 2^16, as the generator checks).
fn quadratic_fits(pieces: &[Piece]) -> bool {
    pieces.iter().all(|(_, _, v)| {
        v.windows(3)
            .all(|w| (w[2] as i64 - 2 * w[1] as i64 + w[0] as i64).abs() < 1 << 16)
    })
}

/// Worst error of `f` over `grid` (`(y, exact log2)`), as a relative error of the
/// value: |log2 error| ln 2.
fn worst_fixed(grid: &[(i32, f64)], f: impl Fn(i32) -> Option<i32>) -> f64 {
    grid.iter()
        .map(|&(y, want)| {
            f(y).map_or(f64::INFINITY, |got| {
                (got as f64 / ONE as f64 - want).abs() * LN_2
            })
        })
        .fold(0.0, f64::max)
}

fn fixed_error(shape: FixedShape, pieces: &[Piece], grid: &[(i32, f64)]) -> f64 {
    fn quad(p: &Piece) -> UniformTable<'_> {
        UniformTable {
            start: p.0,
            spacing_log2: p.1,
            values: &p.2,
        }
    }
    fn lin(p: &Piece) -> Linear<'_> {
        Linear {
            start: p.0,
            spacing_log2: p.1,
            values: &p.2,
        }
    }
    match (shape.quadratic, pieces) {
        (true, [one]) => worst_fixed(grid, |y| quad(one).eval(y)),
        (false, [one]) => worst_fixed(grid, |y| Uniform::eval(&lin(one), y)),
        (true, [low, high]) => worst_fixed(grid, |y| lookup(&quad(low), &quad(high), y)),
        (false, [low, high]) => worst_fixed(grid, |y| lookup(&lin(low), &lin(high), y)),
        _ => unreachable!("one or two pieces"),
    }
}

/// `f` over `xs` on every core.
fn par_map<X: Sync, Y: Send>(xs: &[X], f: impl Fn(&X) -> Y + Sync) -> Vec<Y> {
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    let chunk = xs.len().div_ceil(threads).max(1);
    std::thread::scope(|s| {
        let handles: Vec<_> = xs
            .chunks(chunk)
            .map(|part| s.spawn(|| part.iter().map(&f).collect::<Vec<Y>>()))
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("worker"))
            .collect()
    })
}

/// Every 2^11-th f32 of each octave of the domain (off the segments' boundaries), and
/// the first and last f32 of every quarter octave, with the f64 reference at each.
fn f32_grid(spec: &OctaveSpec) -> Vec<(f32, f64)> {
    let mut bits = Vec::new();
    for o in 0..spec.octaves {
        let base = ((spec.first_exponent + o + 127) as u32) << 23;
        bits.extend((0..1u32 << 12).map(|j| base + (j << 11) + 0x2a5));
        for q in 0..4u32 {
            bits.push(base + (q << 21));
            bits.push(base + (q << 21) + (1 << 21) - 1);
        }
    }
    let xs: Vec<f32> = bits
        .into_iter()
        .map(f32::from_bits)
        .filter(|&x| x as f64 <= spec.domain_max)
        .collect();
    par_map(&xs, |&x| (x, (spec.f)(x as f64)))
}

/// Every 2^12-th Q8.24 argument of the domain (off the nodes), with the f64 reference.
fn fixed_grid(table: &FixedTable) -> Vec<(i32, f64)> {
    let (lo, hi) = (
        (table.start * ONE as f64) as i32,
        (table.end * ONE as f64) as i32,
    );
    let ys: Vec<i32> = (lo..=hi).step_by(1 << 12).map(|y| y + 0x5a5).collect();
    par_map(&ys, |&y| (y, (table.f)(y as f64 / ONE as f64)))
}

/// One shape of one table, generated and weighed on the host.
struct Weighed {
    table: &'static str,
    core: &'static str,
    shape: String,
    variable: &'static str,
    segments: String,
    degree: u32,
    bytes: usize,
    error: f64,
    shipped: bool,
}

/// Every shape of every table: the image's source (the tables and one measurement per
/// shape) and what the host measured of each; the library's kernels first, as `library`.
fn generate() -> Result<(String, Vec<Weighed>), String> {
    let mut weighed = Vec::new();
    let mut f32_src = String::new();
    for table in f32_tables() {
        let grid = f32_grid(&table.spec);
        // As the core reads it: theta(g) from g = 1 from its top octave's own table.
        let top = table.name == "theta_of_g";
        let library = worst_f32(&grid, |x| {
            if top && x >= 1.0 {
                Some(misalign::float::kernels::theta_top::theta_of_g_top(x))
            } else {
                table.library.eval(x)
            }
        });
        let top_bytes = if top {
            std::mem::size_of_val(&misalign::float::tables::THETA_OF_G_TOP)
        } else {
            0
        };
        // The library's shape lies outside the family weighed here: two segments per
        // octave in the centred variable u - 3/2, fitted for the least relative error
        // (src/float/octave.rs); it is measured beside the family, as itself.
        weighed.push(Weighed {
            table: table.name,
            core: "f32",
            shape: "library".into(),
            variable: "u-3/2",
            segments: format!("{}", 1 << misalign::float::octave::SEGMENTS_LOG2),
            degree: misalign::float::octave::DEGREE as u32,
            bytes: std::mem::size_of_val(table.rows) + top_bytes,
            error: library,
            shipped: true,
        });
        for shape in f32_shapes() {
            let coeffs = fit_f32(&table.spec, shape);
            let error =
                with_f32_shape!(shape, f32_error(table.spec.first_exponent, &coeffs, &grid));
            let w = shape.width();
            weighed.push(Weighed {
                table: table.name,
                core: "f32",
                shape: shape.id(),
                variable: shape.variable(),
                segments: format!("{}", 1 << shape.m),
                degree: shape.d as u32,
                bytes: coeffs.len() * w * 4,
                error,
                shipped: false,
            });
            write_f32_shape(&mut f32_src, table.name, &table.spec, shape, &coeffs);
        }
        eprintln!("shapes: {} weighed on the host", table.name);
    }
    let mut fixed_src = String::new();
    for table in fixed_tables() {
        let grid = fixed_grid(&table);
        let [low, high] = table.library;
        let library = worst_fixed(&grid, |y| lookup(&low, &high, y));
        weighed.push(Weighed {
            table: table.name,
            core: "fixed",
            shape: "library".into(),
            variable: "log2",
            segments: FIXED_SHIPPED.segments(),
            degree: 2,
            bytes: (low.values.len() + high.values.len()) * 4,
            error: library,
            shipped: true,
        });
        for shape in fixed_shapes() {
            let pieces = fixed_pieces(&table, shape);
            if shape.quadratic && !quadratic_fits(&pieces) {
                eprintln!(
                    "shapes: {} {}: second differences too large for the kernel, skipped",
                    table.name,
                    shape.id()
                );
                continue;
            }
            if shape == FIXED_SHIPPED {
                let same = pieces.iter().zip(&table.library).all(|(p, l)| {
                    (p.0, p.1, p.2.as_slice()) == (l.start, l.spacing_log2, l.values)
                });
                if !same {
                    return Err(format!(
                        "{}: the shipped shape's tables are not the library's (cargo xtask tables --check)",
                        table.name
                    ));
                }
            }
            weighed.push(Weighed {
                table: table.name,
                core: "fixed",
                shape: shape.id(),
                variable: "log2",
                segments: shape.segments(),
                degree: shape.degree(),
                bytes: pieces.iter().map(|p| p.2.len() * 4).sum(),
                error: fixed_error(shape, &pieces, &grid),
                shipped: shape == FIXED_SHIPPED,
            });
            write_fixed_shape(&mut fixed_src, table.name, shape, &pieces);
        }
        eprintln!("shapes: {} weighed on the host", table.name);
    }
    let [g, theta] = f32_tables().map(|t| t.name);
    let [log_g, log_theta] = fixed_tables().map(|t| t.name);
    let source = format!(
        "// Written by `cargo xtask shapes` (lab/xtask/src/shapes.rs): every table shape it weighs,\n\
         // measured by lab/harness/src/bin/shapes.rs. Not committed: regenerated by every run.\n\n\
         #[cfg(target_abi = \"eabihf\")]\n\
         pub fn f32_shapes(c: &Counter, {g}: &[f32], {theta}: &[f32]) {{\n{f32_src}}}\n\n\
         #[cfg(not(target_abi = \"eabihf\"))]\n\
         pub fn fixed_shapes(c: &Counter, {log_g}: &[i32], {log_theta}: &[i32]) {{\n{fixed_src}}}\n"
    );
    Ok((source, weighed))
}

/// One f32 shape in the image: its table as a const (as the library's) and its
/// measurement.
fn write_f32_shape(
    out: &mut String,
    table: &str,
    spec: &OctaveSpec,
    shape: F32Shape,
    coeffs: &[Vec<f32>],
) {
    let w = shape.width();
    writeln!(
        out,
        "    {{\n        const T: Octaves<'static, {}, {}, {w}, {}> = Octaves::new({}, &[",
        shape.m, shape.d, shape.t, spec.first_exponent
    )
    .unwrap();
    for row in coeffs {
        let cells: Vec<String> = row
            .iter()
            .copied()
            .chain(std::iter::repeat(0.0))
            .take(w)
            .map(|c| format!("{c:?}"))
            .collect();
        writeln!(out, "            [{}],", cells.join(", ")).unwrap();
    }
    writeln!(
        out,
        "        ]);\n        measure_f32(c, \"{table}\", \"{}\", {table}, |x| T.eval(x));\n    }}",
        shape.id()
    )
    .unwrap();
}

/// One fixed-point shape in the image: its table(s) as consts and its measurement.
fn write_fixed_shape(out: &mut String, table: &str, shape: FixedShape, pieces: &[Piece]) {
    let ty = if shape.quadratic {
        "UniformTable"
    } else {
        "Linear"
    };
    out.push_str("    {\n");
    let names = if pieces.len() == 1 {
        &["T"][..]
    } else {
        &["LOW", "HIGH"][..]
    };
    for (name, (start, k, values)) in names.iter().zip(pieces) {
        writeln!(
            out,
            "        const {name}: {ty}<'static> = {ty} {{\n            start: {start},\n            spacing_log2: {k},\n            values: &["
        )
        .unwrap();
        for chunk in values.chunks(12) {
            let cells: Vec<String> = chunk.iter().map(|v| v.to_string()).collect();
            writeln!(out, "                {},", cells.join(", ")).unwrap();
        }
        out.push_str("            ],\n        };\n");
    }
    let call = if pieces.len() == 1 {
        "T.eval(y)"
    } else {
        "lookup(&LOW, &HIGH, y)"
    };
    writeln!(
        out,
        "        measure_fixed(c, \"{table}\", \"{}\", {table}, |y| {call});\n    }}",
        shape.id()
    )
    .unwrap();
}

/// Where each table family is measured: the f32 core where it runs in hardware, the
/// fixed-point core where there is no FPU.
const RUNS: [(&str, &str); 3] = [
    ("cortex-m4f", "f32"),
    ("cortex-m0", "fixed"),
    ("cortex-m3", "fixed"),
];

/// `(cpu, table, shape) -> (mean, max)` from the `shapes` image on every core of
/// [`RUNS`].
type Counts = HashMap<(String, String, String), (u64, u64)>;

fn measure(source: &str, samples: usize) -> Result<Counts, String> {
    crate::tools::preflight()?;
    let target_dir = std::env::var_os("CARGO_TARGET_DIR")
        .map_or_else(|| crate::root().join("target"), PathBuf::from);
    let dir = target_dir.join("shapes");
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let path = dir.join("tables.rs");
    // Unchanged text, untouched file: cargo rebuilds nothing.
    if std::fs::read_to_string(&path).ok().as_deref() != Some(source) {
        std::fs::write(&path, source).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    let mut counts = Counts::new();
    for (id, _) in RUNS {
        let cpu = CPUS.iter().find(|c| c.id == id).ok_or("no such cpu")?;
        let mut cmd = cross::harness_build(cpu.target);
        cmd.env("MISALIGN_SHAPES_TABLES", &path)
            .env("MISALIGN_SHAPES_SAMPLES", samples.to_string())
            .args(["--bin", "shapes"]);
        let elf = cross::artifact(&cross::build(&mut cmd)?, "shapes")?;
        let (status, log) = cross::qemu(cpu.machine, &elf)?;
        if status != Some(0) {
            return Err(format!("shapes on {id} exited {status:?}:\n{log}"));
        }
        let before = counts.len();
        for (table, shape, mean, max) in log.lines().filter_map(parse_line) {
            counts.insert((id.to_string(), table, shape), (mean, max));
        }
        eprintln!("shapes: {id}: {} measured", counts.len() - before);
    }
    Ok(counts)
}

/// `shape table=<t> shape=<id> n=<calls> mean=<x> max=<y>`.
fn parse_line(line: &str) -> Option<(String, String, u64, u64)> {
    let f = Fields::of(line, "shape table=")?;
    Some((
        f.get("table").ok()?.to_string(),
        f.get("shape").ok()?.to_string(),
        f.num("mean").ok()?,
        f.num("max").ok()?,
    ))
}

/// The CSV's rows: per core of [`RUNS`], per table of its family, the library's kernel
/// and then every shape.
fn rows(weighed: &[Weighed], counts: &Counts) -> Result<Vec<ShapeRow>, String> {
    let mut out = Vec::new();
    for (cpu, core) in RUNS {
        for w in weighed.iter().filter(|w| w.core == core) {
            let key = (cpu.to_string(), w.table.to_string(), w.shape.clone());
            let &(mean, max) = counts
                .get(&key)
                .ok_or_else(|| format!("{cpu}: the image measured no {} {}", w.table, w.shape))?;
            let kind = match (w.shape.as_str(), w.shipped) {
                ("library", _) => "library",
                (_, true) => "shipped",
                _ => "variant",
            };
            out.push(ShapeRow {
                cpu: cpu.to_string(),
                table: w.table.to_string(),
                core: core.to_string(),
                kind: kind.to_string(),
                shape: w.shape.clone(),
                variable: w.variable.to_string(),
                segments: w.segments.clone(),
                degree: w.degree,
                bytes: w.bytes as u64,
                mean: mean as f64,
                max: max as f64,
                // As the CSV holds it, so that the figure and the table redrawn from
                // the CSV are these.
                error: records::rounded(w.error),
            });
        }
    }
    Ok(out)
}

/// The library's kernel against the shape it ships, measured apart in the same run:
/// the same error (the same table, checked above) and, but for code layout, the same
/// instructions.
fn check_baselines(rows: &[ShapeRow]) -> Result<(), String> {
    for lib in rows.iter().filter(|r| r.kind == "library") {
        // The f32 library's shape is not in the family weighed: nothing to hold it to.
        let Some(shipped) = rows
            .iter()
            .find(|r| r.kind == "shipped" && r.cpu == lib.cpu && r.table == lib.table)
        else {
            continue;
        };
        if shipped.error != lib.error || shipped.bytes != lib.bytes {
            return Err(format!(
                "{} {}: the shipped shape ({:e}, {} bytes) is not the library's kernel ({:e}, {} bytes)",
                lib.cpu, lib.table, shipped.error, shipped.bytes, lib.error, lib.bytes
            ));
        }
        if shipped.mean != lib.mean {
            eprintln!(
                "shapes: note: {} {}: the shipped shape takes {} instructions, the library's kernel {}",
                lib.cpu, lib.table, shipped.mean, lib.mean
            );
        }
    }
    Ok(())
}

pub fn run(short: bool, csv: bool) -> ExitCode {
    match run_inner(short, csv) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask shapes: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run_inner(short: bool, csv: bool) -> Result<(), String> {
    let start = std::time::Instant::now();
    let (source, weighed) = generate()?;
    let counts = measure(&source, if short { 32 } else { 256 })?;
    let rows = rows(&weighed, &counts)?;
    check_baselines(&rows)?;
    if csv {
        print!("{}", records::to_csv(&rows));
    } else {
        print!("{}", table(&rows));
    }
    if !short {
        records::write(&rows)?;
        let svg = crate::root().join("docs").join(crate::figures::SHAPES_SVG);
        crate::figures::table_shapes(&rows, &svg).map_err(|e| e.to_string())?;
        eprintln!("wrote {}", svg.display());
        crate::measurements::update()?;
    }
    eprintln!("shapes: {:.0} s", start.elapsed().as_secs_f64());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use misalign::float::THETA_OF_G;

    /// Generating the fixed-point shapes the library ships gives the library's tables
    /// (the f32 library's shape lies outside the family weighed: measured as itself).
    #[test]
    fn the_shipped_shapes_are_the_librarys_tables() {
        for table in fixed_tables() {
            let pieces = fixed_pieces(&table, FIXED_SHIPPED);
            for (p, l) in pieces.iter().zip(&table.library) {
                assert_eq!(
                    (p.0, p.1, p.2.as_slice()),
                    (l.start, l.spacing_log2, l.values)
                );
            }
        }
    }

    /// Finer segments: a quarter octave wholly past pi/2 is not stored, and the table
    /// still answers across the domain.
    #[test]
    fn segments_past_the_domain_are_left_out() {
        let [g, theta] = f32_tables();
        let shape = F32Shape {
            t: true,
            m: 2,
            d: 3,
        };
        let coeffs = fit_f32(&g.spec, shape);
        assert_eq!(coeffs.len(), g.spec.octaves as usize * 4 - 1);
        let rows = padded::<4>(&coeffs);
        let table = Octaves::<2, 3, 4, true>::new(g.spec.first_exponent, &rows);
        for x in [1e-9f32, 1e-3, 0.3, 1.5] {
            let want = (g.spec.f)(x as f64);
            let got = table.eval(x).unwrap() as f64;
            assert!((got / want - 1.0).abs() < 1e-5, "{x}: {got} {want}");
        }
        assert_eq!(table.eval(1.8), None);
        assert_eq!(fit_f32(&theta.spec, shape).len(), 28 * 4 - 1);
        // The library's THETA_OF_G stores the whole last octave.
        assert!(THETA_OF_G.eval(1.8).is_some());
    }

    /// Linear interpolation: the nodes exactly, the midpoint their mean.
    #[test]
    fn linear_interpolation_is_exact_at_the_nodes() {
        let values = [0, ONE, 3 * ONE, 3 * ONE];
        let t = Linear {
            start: -ONE,
            spacing_log2: 2,
            values: &values,
        };
        assert_eq!(t.eval(-ONE), Some(0));
        assert_eq!(t.eval(-ONE + ONE / 4), Some(ONE));
        assert_eq!(t.eval(-ONE + ONE / 8), Some(ONE / 2));
        assert_eq!(t.eval(-ONE + 3 * ONE / 8), Some(2 * ONE));
        assert_eq!(t.eval(-ONE - 1), None);
        assert_eq!(t.eval(-ONE + 3 * ONE / 4), None, "past the last segment");
    }

    #[test]
    fn shapes_are_named_by_their_dimensions() {
        assert_eq!(
            F32Shape {
                t: true,
                m: 2,
                d: 3
            }
            .id(),
            "t-s4-d3"
        );
        assert_eq!(FIXED_SHIPPED.id(), "quad-4+32");
        let lin = FixedShape {
            quadratic: false,
            spacing: Spacing::One(8),
        };
        assert_eq!((lin.id().as_str(), lin.degree()), ("lin-256", 1));
        // Every f32 shape has an evaluator (the dispatch panics otherwise).
        let grid = [(0.5f32, (g_of_half()))];
        for shape in f32_shapes() {
            let coeffs = fit_f32(&f32_tables()[0].spec, shape);
            let first = f32_tables()[0].spec.first_exponent;
            let e = with_f32_shape!(shape, f32_error(first, &coeffs, &grid));
            assert!(e < 2e-2, "{}: {e}", shape.id());
        }
    }

    fn g_of_half() -> f64 {
        tables::g_of_theta(0.5f32 as f64)
    }

    #[test]
    fn image_lines_are_read_back() {
        let line = "shape table=log_g shape=quad-4+32 n=256 mean=48 max=50";
        assert_eq!(
            parse_line(line),
            Some(("log_g".into(), "quad-4+32".into(), 48, 50))
        );
        assert_eq!(parse_line("shape ticks_per_1000=1600"), None);
    }
}
