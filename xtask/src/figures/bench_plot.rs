//! The benchmark's figure: speed against error of every model, per CPU
//! (`docs/speed-vs-error.svg`), from the benchmark's rows.

use super::labels::{Labels, text_width};
use super::{
    BLUE_, DESC, FONT, GREEN_, GREY, LABEL, LIGHT, NOTE, ORANGE, PURPLE, Res, SKY, VERMILION,
    log_axis, power_of_ten, render, ten_to, text,
};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};
use std::path::Path;

/// One row of the benchmark's CSV that the speed-against-error figure uses.
#[derive(Debug, Clone, PartialEq)]
pub struct BenchRow {
    /// `cortex-m0`, ...
    pub cpu: String,
    /// `reference`, `f32`, `fixed`, `hamrock-brewe`, ...
    pub model: String,
    /// `estimate`, or `table:...` / `kernel:...` for the variants weighed.
    pub operation: String,
    /// Mean instructions per call.
    pub instructions: f64,
    /// Maximum relative error against the f64 reference.
    pub error: f64,
}

/// The rows of `cpu,model,operation,instructions_mean,instructions_max,max_rel_error`
/// (columns by name, in any order) that the figure plots ([`plotted`]). Rows with an
/// empty instruction count or error are left out.
///
/// # Errors
/// A missing column, a malformed record or a number that does not parse.
pub fn parse_bench_csv(text: &str) -> Res<Vec<BenchRow>> {
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let headers = reader.headers()?.clone();
    let column = |name: &str| {
        headers
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| format!("bench CSV has no column `{name}`"))
    };
    let cols = [
        column("cpu")?,
        column("model")?,
        column("operation")?,
        column("instructions_mean")?,
        column("max_rel_error")?,
    ];
    let mut rows = Vec::new();
    for (index, record) in reader.records().enumerate() {
        let record = record?;
        let line = index + 2;
        let field = |c: usize| {
            record
                .get(c)
                .ok_or_else(|| format!("bench CSV line {line}: too few fields"))
        };
        let (instr, err) = (field(cols[3])?, field(cols[4])?);
        if instr.is_empty() || err.is_empty() {
            continue;
        }
        let number = |s: &str| {
            s.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && *v >= 0.0)
                .ok_or_else(|| format!("bench CSV line {line}: bad number `{s}`"))
        };
        rows.push(BenchRow {
            cpu: field(cols[0])?.to_string(),
            model: field(cols[1])?.to_string(),
            operation: field(cols[2])?.to_string(),
            instructions: number(instr)?,
            error: number(err)?,
        });
    }
    Ok(rows.into_iter().filter(plotted).collect())
}

/// Whether the figure plots `row`: every elliptic estimate, and the `table:` and
/// `kernel:` variants where they run (f32 on the Cortex-M4F, fixed point on the
/// Cortex-M0), so that the labels stay legible.
pub fn plotted(row: &BenchRow) -> bool {
    let variant = row.operation.starts_with("table:") || row.operation.starts_with("kernel:");
    let where_it_runs = (row.model == "f32" && row.cpu == "cortex-m4f")
        || (row.model == "fixed" && row.cpu == "cortex-m0");
    row.operation == "estimate" || (variant && where_it_runs)
}

/// `cortex-m4f` -> `m4f`.
fn short_cpu(cpu: &str) -> &str {
    cpu.strip_prefix("cortex-").unwrap_or(cpu)
}

/// The figure's log axes, in whole decades.
struct Axes {
    /// Where an error of exactly 0 (the reference against itself) is drawn: on a
    /// dashed line one decade below the smallest non-zero error, which says so.
    floor: f64,
    x_lo: i32,
    x_hi: i32,
    y_lo: i32,
    y_hi: i32,
    /// Some row has an error of exactly 0.
    has_zero: bool,
}

impl Axes {
    fn of(rows: &[BenchRow]) -> Self {
        let min_err = rows
            .iter()
            .map(|r| r.error)
            .filter(|e| *e > 0.0)
            .fold(f64::INFINITY, f64::min);
        let floor = if min_err.is_finite() {
            ten_to(min_err.log10().floor() as i32 - 1)
        } else {
            1e-16
        };
        // Three times the largest count leaves room for the labels right of the points.
        let (x_lo, _) = decades(rows.iter().map(|r| r.instructions));
        let (_, x_hi) = decades(rows.iter().map(|r| r.instructions * 3.0));
        let (y_lo, y_hi) = decades(rows.iter().map(|r| r.error.max(floor)));
        let has_zero = rows.iter().any(|r| r.error == 0.0);
        Axes {
            floor,
            x_lo,
            x_hi,
            y_lo: y_lo - i32::from(has_zero),
            y_hi,
            has_zero,
        }
    }
}

/// Whole decades around `values`: (floor(log10 min), ceil(log10 max)), at least one.
fn decades(values: impl Iterator<Item = f64>) -> (i32, i32) {
    let (lo, hi) = values.fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    let (lo, hi) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    (lo, hi.max(lo + 1))
}

/// The models of the estimate rows: the four known ones in a fixed order, then any
/// other in sorted order.
fn models_in_order(rows: &[BenchRow]) -> Vec<&str> {
    let mut models: Vec<&str> = vec!["reference", "f32", "fixed", "hamrock-brewe"];
    let mut others: Vec<&str> = rows
        .iter()
        .filter(|r| r.operation == "estimate" && !models.contains(&r.model.as_str()))
        .map(|r| r.model.as_str())
        .collect();
    others.sort_unstable();
    others.dedup();
    models.extend(others);
    models
}

/// The speed-against-error figure of the benchmark's `rows` (those it [`plotted`]) as
/// SVG.
///
/// # Errors
/// When no plotted row has instructions > 0.
pub fn speed_vs_error_svg(rows: &[BenchRow]) -> Res<String> {
    let rows: Vec<BenchRow> = rows
        .iter()
        .filter(|r| plotted(r) && r.instructions > 0.0)
        .cloned()
        .collect();
    if rows.is_empty() {
        return Err("bench CSV has no estimate, table: or kernel: row to plot".into());
    }
    // The Cortex-M7 runs the M4F's code: its rows are drawn only where they differ.
    let as_m4f = |r: &BenchRow| {
        r.cpu == "cortex-m7"
            && rows.iter().any(|o| {
                o.cpu == "cortex-m4f"
                    && (&o.model, &o.operation, o.instructions, o.error)
                        == (&r.model, &r.operation, r.instructions, r.error)
            })
    };
    let m7_as_m4f = rows.iter().any(as_m4f);
    let rows: Vec<BenchRow> = rows.iter().filter(|r| !as_m4f(r)).cloned().collect();
    let caption = if m7_as_m4f {
        "Speed against error per CPU and model (M7: only where it differs from the M4F)"
    } else {
        "Speed against error: one estimate (d/b, regime, F, φ₀) per CPU and model"
    };
    let Axes {
        floor,
        x_lo,
        x_hi,
        y_lo,
        y_hi,
        has_zero,
    } = Axes::of(&rows);
    let y_of = |r: &BenchRow| r.error.max(floor);
    let models = models_in_order(&rows);
    let palette = [BLUE_, GREEN_, VERMILION, ORANGE, PURPLE, SKY, BLACK];

    render(|root| {
        let mut chart = ChartBuilder::on(root)
            .caption(caption, (FONT, 23))
            .margin(18)
            .x_label_area_size(62)
            .y_label_area_size(90)
            .build_cartesian_2d(log_axis(x_lo, x_hi), log_axis(y_lo, y_hi))?;
        chart
            .configure_mesh()
            .x_desc("instructions per estimate (mean; QEMU -icount)")
            .y_desc("max. relative error vs f64 reference")
            .x_label_formatter(&power_of_ten)
            .y_label_formatter(&power_of_ten)
            .axis_desc_style((FONT, DESC))
            .label_style((FONT, LABEL))
            .light_line_style(WHITE)
            .bold_line_style(LIGHT)
            .draw()?;
        if has_zero {
            chart.draw_series(DashedLineSeries::new(
                [(ten_to(x_lo), floor), (ten_to(x_hi), floor)],
                4,
                4,
                GREY.stroke_width(1),
            ))?;
        }
        // Markers first; their boxes keep the labels off them.
        let (xs, ys) = chart.plotting_area().get_pixel_range();
        let mut labels = Labels::new([xs.start, ys.start, xs.end, ys.end]);
        let mut pending: Vec<(String, (i32, i32), RGBColor, u32)> = Vec::new();
        for (i, model) in models.iter().enumerate() {
            let color = palette[i % palette.len()];
            let points: Vec<&BenchRow> = rows
                .iter()
                .filter(|r| r.operation == "estimate" && r.model == *model)
                .collect();
            if points.is_empty() {
                continue;
            }
            chart
                .draw_series(
                    points
                        .iter()
                        .map(|r| Circle::new((r.instructions, y_of(r)), 6, color.filled())),
                )?
                .label(format!("{model} (estimate)"))
                .legend(move |(x, y)| Circle::new((x + 10, y), 6, color.filled()));
            for r in points {
                let at = chart.backend_coord(&(r.instructions, y_of(r)));
                labels.mark(at, 7);
                pending.push((short_cpu(&r.cpu).to_string(), at, color, NOTE));
            }
        }
        let variants: Vec<&BenchRow> = rows.iter().filter(|r| r.operation != "estimate").collect();
        if !variants.is_empty() {
            chart
                .draw_series(
                    variants
                        .iter()
                        .map(|r| TriangleMarker::new((r.instructions, y_of(r)), 7, GREY.filled())),
                )?
                .label("tables and kernels weighed")
                .legend(|(x, y)| TriangleMarker::new((x + 10, y), 7, GREY.filled()));
            for r in variants {
                let at = chart.backend_coord(&(r.instructions, y_of(r)));
                labels.mark(at, 8);
                let name = format!("{} ({} {})", r.operation, short_cpu(&r.cpu), r.model);
                pending.push((name, at, GREY, 15));
            }
        }
        if has_zero {
            // Just above the dashed line, at its left end.
            let (x, y) = chart.backend_coord(&(ten_to(x_lo), floor));
            let name = "error = 0 (exact): drawn on this line";
            let (w, h) = (text_width(name, 15), 15 * 100 / 124);
            labels.taken.push([x + 6, y - 4 - h, x + 6 + w, y - 4]);
            root.draw_text(
                name,
                &text(15, GREY, HPos::Left, VPos::Bottom),
                (x + 6, y - 4),
            )?;
        }
        for (name, at, color, size) in pending {
            let (h, v, pos) = labels.place(at, &name, size);
            root.draw_text(&name, &text(size, color, h, v), pos)?;
        }
        let corner = labels.emptiest_corner(legend_box(&models, &rows));
        chart
            .configure_series_labels()
            .position(corner)
            .margin(12)
            .legend_area_size(30)
            .background_style(WHITE)
            .border_style(GREY)
            .label_font((FONT, NOTE))
            .draw()?;
        Ok(())
    })
}

/// Estimated size (px) of the legend of the speed-against-error figure.
fn legend_box(models: &[&str], rows: &[BenchRow]) -> (i32, i32) {
    let mut names: Vec<String> = models
        .iter()
        .filter(|m| {
            rows.iter()
                .any(|r| r.operation == "estimate" && r.model == **m)
        })
        .map(|m| format!("{m} (estimate)"))
        .collect();
    if rows.iter().any(|r| r.operation != "estimate") {
        names.push("tables and kernels weighed".to_string());
    }
    let widest = names.iter().map(|n| text_width(n, NOTE)).max().unwrap_or(0);
    (widest + 60, 22 * names.len() as i32 + 16)
}

/// Writes the speed-against-error figure of `rows` to `svg_path`.
///
/// # Errors
/// As [`speed_vs_error_svg`], or an unwritable SVG.
pub fn speed_vs_error(rows: &[BenchRow], svg_path: &Path) -> Res<()> {
    let svg = speed_vs_error_svg(rows)?;
    std::fs::write(svg_path, svg).map_err(|e| format!("write {}: {e}", svg_path.display()))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const SAMPLE: &str = "\
cpu,model,operation,instructions_mean,instructions_max,max_rel_error
cortex-m4f,reference,estimate,250000,310000,0
cortex-m4f,f32,estimate,120,131,5.6e-7
cortex-m4f,fixed,estimate,450,470,1.5e-6
cortex-m4f,hamrock-brewe,estimate,90,95,1.7
cortex-m0,fixed,estimate,560,590,1.5e-6
cortex-m0,f32,estimate,2100,2300,5.6e-7
cortex-m4f,f32,kernel:cbrt,18,18,1.0e-7
cortex-m4f,f32,table:degree4,100,104,3.0e-6
cortex-m4f,f32,cbrt,18,18,1.0e-7
";

    #[test]
    fn bench_csv_rows_are_read_by_name() {
        let rows = parse_bench_csv(SAMPLE).unwrap();
        assert_eq!(rows.len(), 8, "the plain `cbrt` row is not plotted");
        assert_eq!(rows[1].model, "f32");
        assert_eq!((rows[1].instructions, rows[1].error), (120.0, 5.6e-7));
        assert!(parse_bench_csv("cpu,model,operation\n").is_err());
        let bad = "cpu,model,operation,instructions_mean,instructions_max,max_rel_error\n\
                   m0,f32,estimate,abc,1,1e-7\n";
        assert!(parse_bench_csv(bad).is_err());
        let reordered = "max_rel_error,operation,model,cpu,instructions_mean\n\
                         1e-7,estimate,f32,cortex-m7,100\n\
                         ,estimate,f32,cortex-m7,100\n";
        let rows = parse_bench_csv(reordered).unwrap();
        assert_eq!(rows.len(), 1);
        assert_eq!(
            (rows[0].cpu.as_str(), rows[0].instructions),
            ("cortex-m7", 100.0)
        );
    }

    #[test]
    fn speed_vs_error_writes_a_labelled_svg() {
        let dir = std::env::temp_dir().join(format!("xtask-figures-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let svg = dir.join("speed.svg");
        let rows = parse_bench_csv(SAMPLE).unwrap();
        speed_vs_error(&rows, &svg).unwrap();
        let out = std::fs::read_to_string(&svg).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(out.starts_with("<svg width=\"800\" height=\"600\""));
        for label in [
            "reference (estimate)",
            "hamrock-brewe (estimate)",
            "error = 0",
            "m0",
            "kernel:cbrt (m4f f32)",
            "table:degree4 (m4f f32)",
            "tables and kernels weighed",
            "instructions per estimate",
        ] {
            assert!(out.contains(label), "missing label {label}");
        }
        assert!(
            !out.contains(">\ncbrt"),
            "plain kernel rows are not plotted"
        );
        assert_eq!(out, speed_vs_error_svg(&rows).unwrap(), "deterministic");
        assert!(speed_vs_error(&[], &svg).is_err(), "no rows, no figure");
    }
}
