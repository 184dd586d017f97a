//! The benchmark's figure: speed against error of every model, a panel per CPU
//! (`docs/speed-vs-error.svg`), from the benchmark's rows. The estimates are labelled
//! by model; the tables and kernels by a number, which the key names.

use super::labels::{LabelReport, Labels};
use super::{
    Area, BLUE_, FONT, GREEN_, GREY, LIGHT, NOTE, ORANGE, PURPLE, Res, SKY, VERMILION, captioned,
    log_axis, power_of_ten, render_sized, ten_to, text, y_title,
};
use crate::records::{self, BenchRow};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};
use std::path::Path;

/// The rows of docs/bench.csv that the figure plots ([`plotted`]).
///
/// # Errors
/// A missing column, a malformed record or a number that does not parse.
pub fn parse_bench_csv(text: &str) -> Res<Vec<BenchRow>> {
    let rows = records::parse::<BenchRow>(text, "bench CSV")?;
    Ok(rows.into_iter().filter(plotted).collect())
}

/// A row's instructions per call (mean): the x axis.
fn x(r: &BenchRow) -> f64 {
    r.mean as f64
}

/// A row's error: the y axis (NaN where none was measured; such rows are not plotted).
fn err(r: &BenchRow) -> f64 {
    r.error.unwrap_or(f64::NAN)
}

/// Whether the figure plots `row`: every elliptic estimate, and the `table:` and
/// `kernel:` variants where their core runs: f32 where there is an FPU (Cortex-M4F,
/// M7), fixed point where there is none (Cortex-M0, M3); each with an error measured
/// and instructions counted.
pub fn plotted(row: &BenchRow) -> bool {
    if row.error.is_none_or(|e| !e.is_finite() || e < 0.0) || row.mean == 0 {
        return false;
    }
    let variant = row.operation.starts_with("table:") || row.operation.starts_with("kernel:");
    let fpu = matches!(row.cpu.as_str(), "cortex-m4f" | "cortex-m7");
    let where_it_runs = (row.model == "f32" && fpu) || (row.model == "fixed" && !fpu);
    row.operation == "estimate" || (variant && where_it_runs)
}

/// `Cortex-M4F` for `cortex-m4f`.
fn cpu_name(cpu: &str) -> String {
    cpu.strip_prefix("cortex-")
        .map_or(cpu.to_string(), |c| format!("Cortex-{}", c.to_uppercase()))
}

/// The figure's log axes, in whole decades, shared by every panel.
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
            .map(err)
            .filter(|e| *e > 0.0)
            .fold(f64::INFINITY, f64::min);
        let floor = if min_err.is_finite() {
            ten_to(min_err.log10().floor() as i32 - 1)
        } else {
            1e-16
        };
        // Three times the largest count leaves room for the labels right of the points.
        let (x_lo, _) = decades(rows.iter().map(x));
        let (_, x_hi) = decades(rows.iter().map(|r| x(r) * 3.0));
        let (y_lo, y_hi) = decades(rows.iter().map(|r| err(r).max(floor)));
        let has_zero = rows.iter().any(|r| err(r) == 0.0);
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
/// other in sorted order; with their colours.
fn models_in_order(rows: &[BenchRow]) -> Vec<(&str, RGBColor)> {
    let mut models: Vec<&str> = vec!["reference", "f32", "fixed", "hamrock-brewe"];
    let mut others: Vec<&str> = rows
        .iter()
        .filter(|r| r.operation == "estimate" && !models.contains(&r.model.as_str()))
        .map(|r| r.model.as_str())
        .collect();
    others.sort_unstable();
    others.dedup();
    models.extend(others);
    let palette = [BLUE_, GREEN_, VERMILION, ORANGE, PURPLE, SKY, BLACK];
    models
        .into_iter()
        .filter(|m| {
            rows.iter()
                .any(|r| r.operation == "estimate" && r.model == *m)
        })
        .enumerate()
        .map(|(i, m)| (m, palette[i % palette.len()]))
        .collect()
}

/// The figure's size (px): two panels a row, the key in the cell after the last.
pub const SPEED_SIZE: (u32, u32) = (1200, 1060);
/// Font sizes (plotters' sizes) of the panels' titles, axes and point labels.
const PANEL_TITLE: u32 = 21;
const AXIS: u32 = 18;
const TICKS: u32 = 16;
const POINT: u32 = 16;

/// One panel: a CPU's rows (and the title that says which CPUs it stands for).
struct Panel {
    title: String,
    rows: Vec<BenchRow>,
}

/// The panels: one per CPU, in the rows' order; the Cortex-M7's merged into the M4F's
/// when every one of its rows is the M4F's (QEMU counts instructions, and the M7 runs
/// the M4F's image: the same counts).
fn panels(rows: &[BenchRow]) -> Vec<Panel> {
    let mut cpus: Vec<&str> = Vec::new();
    for r in rows {
        if !cpus.contains(&r.cpu.as_str()) {
            cpus.push(&r.cpu);
        }
    }
    let of =
        |cpu: &str| -> Vec<BenchRow> { rows.iter().filter(|r| r.cpu == cpu).cloned().collect() };
    let key = |r: &BenchRow| (r.model.clone(), r.operation.clone(), x(r), err(r));
    let m4f: Vec<_> = of("cortex-m4f").iter().map(key).collect();
    let m7 = of("cortex-m7");
    let merged = !m4f.is_empty() && !m7.is_empty() && m7.iter().all(|r| m4f.contains(&key(r)));
    cpus.into_iter()
        .filter(|cpu| !(merged && *cpu == "cortex-m7"))
        .map(|cpu| Panel {
            title: if merged && cpu == "cortex-m4f" {
                "Cortex-M4F and M7 (the same image: the same counts)".to_string()
            } else {
                cpu_name(cpu)
            },
            rows: of(cpu),
        })
        .collect()
}

/// The tables and kernels drawn, numbered for the key: `(model, operation)` in the
/// rows' order.
fn variants(rows: &[BenchRow]) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = Vec::new();
    for r in rows.iter().filter(|r| r.operation != "estimate") {
        let k = (r.model.clone(), r.operation.clone());
        if !out.contains(&k) {
            out.push(k);
        }
    }
    out
}

/// The speed-against-error figure of the benchmark's `rows` (those it [`plotted`]) as
/// SVG.
///
/// # Errors
/// When no plotted row has instructions > 0.
pub fn speed_vs_error_svg(rows: &[BenchRow]) -> Res<String> {
    Ok(speed_vs_error_layout(rows)?.0)
}

/// The figure and where its point labels went (for the tests).
pub(super) fn speed_vs_error_layout(rows: &[BenchRow]) -> Res<(String, LabelReport)> {
    let rows: Vec<BenchRow> = rows.iter().filter(|r| plotted(r)).cloned().collect();
    if rows.is_empty() {
        return Err("bench CSV has no estimate, table: or kernel: row to plot".into());
    }
    let axes = Axes::of(&rows);
    let models = models_in_order(&rows);
    let numbered = variants(&rows);
    let panels = panels(&rows);
    let mut report = LabelReport::default();
    let svg = render_sized(SPEED_SIZE, |root| {
        let inner = root.titled(
            "Speed against error: every model's estimate and the kernels weighed, per core",
            (FONT, 25),
        )?;
        let cells = inner.split_evenly(((panels.len() + 1).div_ceil(2), 2));
        for (panel, cell) in panels.iter().zip(&cells) {
            report.add(draw_panel(root, cell, panel, &axes, &models, &numbered)?);
        }
        draw_key(root, &cells[panels.len()], &axes, &models, &numbered)?;
        Ok(())
    })?;
    Ok((svg, report))
}

/// One CPU's panel: the estimates (colour by model, labelled by name) and the tables
/// and kernels (grey triangles, labelled by their number in the key).
fn draw_panel(
    root: &Area,
    cell: &Area,
    panel: &Panel,
    axes: &Axes,
    models: &[(&str, RGBColor)],
    numbered: &[(String, String)],
) -> Res<Labels> {
    let y_of = |r: &BenchRow| err(r).max(axes.floor);
    let body = captioned(cell, &panel.title, PANEL_TITLE, 12)?;
    let mut chart = ChartBuilder::on(&body)
        .margin(12)
        .margin_top(0)
        .margin_right(20)
        .x_label_area_size(52)
        .y_label_area_size(82)
        .build_cartesian_2d(
            log_axis(axes.x_lo, axes.x_hi),
            log_axis(axes.y_lo, axes.y_hi),
        )?;
    chart
        .configure_mesh()
        .x_desc("instructions per call (mean; QEMU -icount)")
        .x_label_formatter(&power_of_ten)
        .y_label_formatter(&|v| {
            // Every other decade: the axis is long.
            let e = v.log10().round() as i32;
            if e % 2 == 0 {
                power_of_ten(v)
            } else {
                String::new()
            }
        })
        .axis_desc_style((FONT, AXIS))
        .label_style((FONT, TICKS))
        .max_light_lines(0)
        .bold_line_style(LIGHT)
        .draw()?;
    y_title(&chart, "max. relative error", AXIS)?;
    if axes.has_zero {
        chart.draw_series(DashedLineSeries::new(
            [
                (ten_to(axes.x_lo), axes.floor),
                (ten_to(axes.x_hi), axes.floor),
            ],
            4,
            4,
            GREY.stroke_width(1),
        ))?;
    }
    let (xs, ys) = chart.plotting_area().get_pixel_range();
    let mut labels = Labels::new([xs.start, ys.start, xs.end, ys.end]);
    // Markers first; their boxes keep the labels off them.
    let mut pending: Vec<(String, (i32, i32), RGBColor)> = Vec::new();
    for r in panel.rows.iter().filter(|r| r.operation != "estimate") {
        let at = chart.backend_coord(&(x(r), y_of(r)));
        root.draw(&TriangleMarker::new(at, 6, GREY.filled()))?;
        labels.mark(at, 6);
        let k = (r.model.clone(), r.operation.clone());
        let n = numbered.iter().position(|v| *v == k).map_or(0, |i| i + 1);
        pending.push((n.to_string(), at, GREY));
    }
    for &(model, color) in models {
        for r in panel
            .rows
            .iter()
            .filter(|r| r.operation == "estimate" && r.model == model)
        {
            let at = chart.backend_coord(&(x(r), y_of(r)));
            root.draw(&Circle::new(at, 7, color.filled()))?;
            labels.mark(at, 7);
            // The estimates' names first: the fewer labels, the larger.
            pending.insert(0, (model.to_string(), at, color));
        }
    }
    for (name, at, color) in pending {
        let (h, v, pos) = labels.place(at, &name, POINT);
        root.draw_text(&name, &text(POINT, color, h, v), pos)?;
    }
    Ok(labels)
}

/// The key, in the cell after the last panel: the models' colours, the numbered
/// tables and kernels, and what the axes measure.
fn draw_key(
    root: &Area,
    cell: &Area,
    axes: &Axes,
    models: &[(&str, RGBColor)],
    numbered: &[(String, String)],
) -> Res<()> {
    let (x0, y0) = cell.get_base_pixel();
    let (x, mut y) = (x0 + 110, y0 + 40);
    let line = 25;
    let style = |c| text(NOTE, c, HPos::Left, VPos::Center);
    root.draw_text(
        "Key",
        &text(PANEL_TITLE, BLACK, HPos::Left, VPos::Center),
        (x, y),
    )?;
    y += line + 6;
    for &(model, color) in models {
        root.draw(&Circle::new((x + 8, y), 7, color.filled()))?;
        root.draw_text(
            &format!("{model}: one estimate (d/b, regime, F, φ₀)"),
            &style(BLACK),
            (x + 26, y),
        )?;
        y += line;
    }
    y += 6;
    root.draw(&TriangleMarker::new((x + 8, y), 6, GREY.filled()))?;
    root.draw_text(
        "n: a table or kernel, where its core runs",
        &style(BLACK),
        (x + 26, y),
    )?;
    y += line;
    for (i, (model, op)) in numbered.iter().enumerate() {
        root.draw_text(&format!("{}", i + 1), &style(GREY), (x + 4, y))?;
        root.draw_text(&format!("{op} ({model})"), &style(BLACK), (x + 26, y))?;
        y += line;
    }
    y += 6;
    let notes = [
        "f32 with an FPU (M4F, M7), fixed point without (M0, M3)".to_string(),
        "error: worst relative error against the f64 reference".to_string(),
        if axes.has_zero {
            format!(
                "error = 0 (exact): on the dashed line at {}",
                power_of_ten(&axes.floor)
            )
        } else {
            String::new()
        },
    ];
    for note in notes.iter().filter(|n| !n.is_empty()) {
        root.draw_text(note, &style(GREY), (x, y))?;
        y += line;
    }
    Ok(())
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
    fn bench_csv_rows_plotted() {
        let rows = parse_bench_csv(SAMPLE).unwrap();
        assert_eq!(rows.len(), 8, "the plain `cbrt` row is not plotted");
        assert_eq!(rows[1].model, "f32");
        assert_eq!((x(&rows[1]), err(&rows[1])), (120.0, 5.6e-7));
        let profile = "cpu,model,operation,instructions_mean,instructions_max,max_rel_error
                       cortex-m7,f32,estimate,100,120,1e-7
                       cortex-m7,f32,estimate,100,120,
";
        assert_eq!(parse_bench_csv(profile).unwrap().len(), 1);
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
        assert!(out.starts_with("<svg width=\"1200\" height=\"1060\""));
        for label in [
            "reference: one estimate",
            "hamrock-brewe: one estimate",
            "error = 0 (exact)",
            "Cortex-M0",
            "Cortex-M4F",
            "kernel:cbrt (f32)",
            "table:degree4 (f32)",
            "n: a table or kernel",
            "instructions per call",
        ] {
            assert!(out.contains(label), "missing label {label}");
        }
        assert!(
            !out.contains(">cbrt ("),
            "plain kernel rows are not plotted"
        );
        assert_eq!(out, speed_vs_error_svg(&rows).unwrap(), "deterministic");
        assert!(speed_vs_error(&[], &svg).is_err(), "no rows, no figure");
    }

    #[test]
    fn a_panel_per_cpu_and_the_m7_with_the_m4f_when_it_counts_the_same() {
        let mut rows = parse_bench_csv(SAMPLE).unwrap();
        let titles = |rows: &[BenchRow]| -> Vec<String> {
            panels(rows).into_iter().map(|p| p.title).collect()
        };
        assert_eq!(titles(&rows), ["Cortex-M4F", "Cortex-M0"]);
        let m7: Vec<BenchRow> = rows
            .iter()
            .filter(|r| r.cpu == "cortex-m4f")
            .map(|r| BenchRow {
                cpu: "cortex-m7".into(),
                ..r.clone()
            })
            .collect();
        rows.extend(m7.clone());
        assert_eq!(
            titles(&rows),
            [
                "Cortex-M4F and M7 (the same image: the same counts)",
                "Cortex-M0"
            ]
        );
        // One count differs: the M7 has a panel of its own.
        rows.retain(|r| r.cpu != "cortex-m7");
        rows.extend(m7.into_iter().map(|r| BenchRow {
            mean: r.mean + 1,
            ..r
        }));
        assert_eq!(titles(&rows), ["Cortex-M4F", "Cortex-M0", "Cortex-M7"]);
        let (_, report) = speed_vs_error_layout(&rows).unwrap();
        assert!(report.crowded.is_empty(), "{:?}", report.crowded);
        assert!(report.overlaps().is_empty());
    }
}
