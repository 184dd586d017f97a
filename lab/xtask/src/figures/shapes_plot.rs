//! The table shapes weighed (`cargo xtask shapes`): docs/shapes.csv and its figure
//! docs/table-shapes.svg, one panel per core and table.

use super::labels::{LabelReport, Labels, text_width};
use super::{
    Area, BLUE_, FONT, GREEN_, GREY, LIGHT, ORANGE, Res, VERMILION, captioned, log_axis,
    power_of_ten, render_sized, text, y_title,
};
use crate::records::ShapeRow;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

/// Errors within this factor of each other count as equal on the Pareto front: each
/// is the maximum over a sample of the domain, and at the f32 floor (about 1e-7) what
/// separates them is rounding.
pub const FRONT_TOLERANCE: f64 = 1.1;

/// The Pareto front of one panel's shapes (not the library's kernel, which is the
/// shipped shape measured apart): by instructions, each shape whose error is below
/// that of every shape with fewer or as many instructions by more than
/// [`FRONT_TOLERANCE`] (on equal instructions, the fewer bytes first).
pub fn pareto_front<'a>(rows: &[&'a ShapeRow]) -> Vec<&'a ShapeRow> {
    let mut shapes: Vec<&ShapeRow> = rows
        .iter()
        .copied()
        .filter(|r| r.kind != "library" && r.error.is_finite())
        .collect();
    shapes.sort_by(|a, b| {
        (a.mean, a.error, a.bytes)
            .partial_cmp(&(b.mean, b.error, b.bytes))
            .expect("no NaN")
    });
    let mut front: Vec<&ShapeRow> = Vec::new();
    for r in shapes {
        if front
            .last()
            .is_none_or(|best| r.error * FRONT_TOLERANCE < best.error)
        {
            front.push(r);
        }
    }
    front
}

/// The two Pareto fronts of one panel's rows.
pub struct Fronts<'a> {
    /// Among the shapes no larger than the library's tables.
    pub within: Vec<&'a ShapeRow>,
    /// Among all.
    pub any: Vec<&'a ShapeRow>,
}

/// The Pareto fronts of one panel's rows (one core, one table): within the library's
/// bytes (the `library` row's; all rows without one) and at any size.
pub fn fronts<'a>(rows: &[&'a ShapeRow]) -> Fronts<'a> {
    let budget = rows
        .iter()
        .find(|r| r.kind == "library")
        .map_or(u64::MAX, |l| l.bytes);
    let within: Vec<&ShapeRow> = rows.iter().copied().filter(|r| r.bytes <= budget).collect();
    Fronts {
        within: pareto_front(&within),
        any: pareto_front(rows),
    }
}

/// The figure's size (px): three rows of two panels and the key below.
pub const SHAPES_SIZE: (u32, u32) = (1400, 1560);
/// Height of the key below the panels (px).
const KEY_HEIGHT: i32 = 170;
/// Font sizes (plotters' sizes) of the panels' titles, axes, point labels and key.
const PANEL_TITLE: u32 = 20;
const AXIS: u32 = 17;
const TICKS: u32 = 16;
const POINT: u32 = 15;
const KEY: u32 = 17;

/// The figure of `rows` as SVG.
///
/// # Errors
/// No row to plot.
pub fn table_shapes_svg(rows: &[ShapeRow]) -> Res<String> {
    Ok(table_shapes_layout(rows)?.0)
}

/// The figure and where its point labels went (for the tests).
pub(super) fn table_shapes_layout(rows: &[ShapeRow]) -> Res<(String, LabelReport)> {
    let mut panels: Vec<(&str, &str)> = Vec::new();
    for r in rows {
        let key = (r.cpu.as_str(), r.table.as_str());
        if !panels.contains(&key) {
            panels.push(key);
        }
    }
    if panels.is_empty() {
        return Err("shapes CSV has no row to plot".into());
    }
    let mut report = LabelReport::default();
    let svg = render_sized(SHAPES_SIZE, |root| {
        let inner = root.titled(
            "Table shapes weighed: instructions per evaluation against error, per core",
            (FONT, 25),
        )?;
        let (w, h) = inner.dim_in_pixel();
        let (grid, key) = inner.split_vertically(h as i32 - KEY_HEIGHT);
        // Two panels a row; a row of f32 tables (a dozen labels each) half again as
        // tall as one of fixed-point tables.
        let weights: Vec<f64> = panels
            .chunks(2)
            .map(|pair| {
                let f32_row = pair.iter().any(|(cpu, table)| {
                    rows.iter()
                        .any(|r| r.cpu == *cpu && r.table == *table && r.core == "f32")
                });
                if f32_row { 1.5 } else { 1.0 }
            })
            .collect();
        let total: f64 = weights.iter().sum();
        let grid_h = f64::from(h) - f64::from(KEY_HEIGHT);
        let mut breaks = Vec::new();
        let mut at = 0.0;
        for w in &weights[..weights.len() - 1] {
            at += w / total * grid_h;
            breaks.push(at.round() as i32);
        }
        let cells = grid.split_by_breakpoints([w as i32 / 2], breaks);
        for (&(cpu, table), cell) in panels.iter().zip(&cells) {
            let panel_rows: Vec<&ShapeRow> = rows
                .iter()
                .filter(|r| r.cpu == cpu && r.table == table)
                .collect();
            report.add(panel(root, cell, &panel_rows)?);
        }
        draw_key(root, &key)?;
        Ok(())
    })?;
    Ok((svg, report))
}

/// `Cortex-M4F` for `cortex-m4f`.
fn cpu_name(cpu: &str) -> String {
    cpu.strip_prefix("cortex-")
        .map_or(cpu.to_string(), |c| format!("Cortex-{}", c.to_uppercase()))
}

/// What a table holds, for a panel's title.
fn table_name(table: &str) -> &str {
    match table {
        "g" => "g(θ)",
        "theta_of_g" => "θ(g)",
        "log_g" => "log₂ g against log₂ θ",
        "log_theta_of_g" => "log₂ θ against log₂ g",
        other => other,
    }
}

/// `1312 B`, `10.4 kB`.
fn bytes(b: u64) -> String {
    if b < 10_000 {
        format!("{b} B")
    } else {
        format!("{:.1} kB", b as f64 / 1000.0)
    }
}

/// The marker shapes of the figure.
#[derive(Clone, Copy)]
enum Mark {
    Circle,
    Triangle,
    Square,
    Diamond,
}

/// Colour and shape of a row: f32 by variable (colour) and segments per octave
/// (shape); fixed point by interpolation (colour) and one table or two (shape).
fn style_of(r: &ShapeRow) -> (RGBColor, Mark) {
    if r.core == "fixed" {
        let color = if r.degree == 1 { VERMILION } else { GREEN_ };
        let mark = if r.segments.contains('+') {
            Mark::Diamond
        } else {
            Mark::Circle
        };
        (color, mark)
    } else {
        let color = if r.variable == "t" { ORANGE } else { BLUE_ };
        let mark = match r.segments.as_str() {
            "1" => Mark::Circle,
            "2" => Mark::Triangle,
            _ => Mark::Square,
        };
        (color, mark)
    }
}

/// Marker half-size (px) for a table of `b` bytes: its area grows with log2 of the
/// bytes, from 3 px at 256 B.
fn radius(b: u64) -> i32 {
    (2.5 + 1.1 * (b.max(256) as f64 / 256.0).log2()).round() as i32
}

/// A marker at pixel `at` on `root`.
fn mark_px(root: &Area, mark: Mark, at: (i32, i32), r: i32, style: ShapeStyle) -> Res<()> {
    match mark {
        Mark::Circle => root.draw(&Circle::new(at, r, style))?,
        Mark::Triangle => root.draw(&TriangleMarker::new(at, r + 1, style))?,
        Mark::Square => {
            let s = r * 7 / 8;
            root.draw(&Rectangle::new(
                [(at.0 - s, at.1 - s), (at.0 + s, at.1 + s)],
                style,
            ))?
        }
        Mark::Diamond => {
            let s = r + 1;
            let (x, y) = at;
            let corners = vec![(x, y - s), (x + s, y), (x, y + s), (x - s, y)];
            if style.filled {
                root.draw(&Polygon::new(corners, style))?
            } else {
                let mut closed = corners.clone();
                closed.push(corners[0]);
                root.draw(&PathElement::new(closed, style))?
            }
        }
    }
    Ok(())
}

/// The staircase of a Pareto front (by instructions): what it attains.
fn staircase(front: &[&ShapeRow], x_hi: f64) -> Vec<(f64, f64)> {
    let mut path = Vec::new();
    for (i, r) in front.iter().enumerate() {
        if i > 0 {
            path.push((r.mean, front[i - 1].error));
        }
        path.push((r.mean, r.error));
    }
    if let Some(last) = front.last() {
        path.push((x_hi, last.error));
    }
    path
}

/// One panel: one table on one core.
fn panel(root: &Area, area: &Area, rows: &[&ShapeRow]) -> Res<Labels> {
    let first = rows[0];
    let library = rows.iter().find(|r| r.kind == "library");
    let title = format!(
        "{} · {} · {}{}",
        table_name(&first.table),
        if first.core == "fixed" {
            "fixed point"
        } else {
            "f32"
        },
        cpu_name(&first.cpu),
        library.map_or(String::new(), |l| format!(" · library {}", bytes(l.bytes)))
    );
    // (An error that is not finite, a shape the evaluator refused somewhere, is in
    // the CSV but off the axis.)
    let shapes: Vec<&ShapeRow> = rows
        .iter()
        .copied()
        .filter(|r| r.kind != "library" && r.error.is_finite())
        .collect();
    let Fronts {
        within: front_budget,
        any: front_any,
    } = fronts(rows);

    let (x_min, x_max) = rows.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), r| {
        (lo.min(r.mean), hi.max(r.mean))
    });
    let (x_lo, x_hi) = (x_min.floor() - 1.5, x_max.ceil() + 1.5);
    let finite = || {
        rows.iter()
            .map(|r| r.error)
            .filter(|e| e.is_finite() && *e > 0.0)
    };
    // Room for a label below the lowest point and above the highest.
    let y_lo = (finite().fold(f64::INFINITY, f64::min) / 2.0)
        .log10()
        .floor() as i32;
    let y_hi = ((finite().fold(0.0, f64::max) * 2.0).log10().ceil() as i32).max(y_lo + 1);

    let body = captioned(area, &title, PANEL_TITLE, 12)?;
    let mut chart = ChartBuilder::on(&body)
        .margin(12)
        .margin_top(0)
        .margin_right(22)
        .x_label_area_size(48)
        .y_label_area_size(78)
        .build_cartesian_2d(x_lo..x_hi, log_axis(y_lo, y_hi))?;
    let ticks = ((x_hi - x_lo) as usize).min(14);
    chart
        .configure_mesh()
        .x_desc("instructions per evaluation (mean)")
        .x_labels(ticks)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&power_of_ten)
        .axis_desc_style((FONT, AXIS))
        .label_style((FONT, TICKS))
        .max_light_lines(0)
        .bold_line_style(LIGHT)
        .draw()?;
    y_title(&chart, "max. relative error", AXIS)?;
    let (xs, ys) = chart.plotting_area().get_pixel_range();
    let mut labels = Labels::new([xs.start, ys.start, xs.end, ys.end]);
    let on = |front: &[&ShapeRow], r: &ShapeRow| front.iter().any(|f| std::ptr::eq(*f, r));

    // The fronts under the points; no label on them either.
    let (any_path, budget_path) = (staircase(&front_any, x_hi), staircase(&front_budget, x_hi));
    for path in [&any_path, &budget_path] {
        for w in path.windows(2) {
            let (a, b) = (chart.backend_coord(&w[0]), chart.backend_coord(&w[1]));
            labels.line(a, b, 2);
        }
    }
    chart.draw_series(DashedLineSeries::new(any_path, 6, 5, GREY.stroke_width(2)))?;
    chart.draw_series(LineSeries::new(budget_path, BLACK.stroke_width(2)))?;
    // Every shape, pale; the fronts' shapes outlined; the library's kernel ringed.
    for r in &shapes {
        let at = chart.backend_coord(&(r.mean, r.error));
        let (color, mark) = style_of(r);
        let rad = radius(r.bytes);
        let front = on(&front_any, r) || on(&front_budget, r);
        let fill = if front {
            color.mix(0.9)
        } else {
            color.mix(0.35)
        };
        mark_px(root, mark, at, rad, fill.filled())?;
        if front {
            mark_px(root, mark, at, rad, BLACK.stroke_width(1))?;
        }
        labels.mark(at, rad + 1);
    }
    if let Some(l) = library.filter(|l| l.error.is_finite()) {
        let at = chart.backend_coord(&(l.mean, l.error));
        let rad = radius(l.bytes) + 5;
        root.draw(&Circle::new(at, rad, BLACK.stroke_width(2)))?;
        labels.mark(at, rad);
    }
    // Labels: the shipped shape, then the fronts'.
    let mut named: Vec<&ShapeRow> = shapes
        .iter()
        .copied()
        .filter(|r| r.kind == "shipped")
        .collect();
    for r in front_budget.iter().chain(&front_any) {
        if !named.iter().any(|n| std::ptr::eq(*n, *r)) {
            named.push(r);
        }
    }
    // A library whose shape is not among those weighed (the f32 tables: half
    // octaves in the centred mantissa) is named at its ring.
    if !named.iter().any(|r| r.kind == "shipped")
        && let Some(l) = library.filter(|l| l.error.is_finite())
    {
        let name = format!("library · {}", bytes(l.bytes));
        let at = chart.backend_coord(&(l.mean, l.error));
        let (h, v, pos) = labels.place(at, &name, POINT);
        root.draw_text(&name, &text(POINT, BLACK, h, v), pos)?;
    }
    for r in named {
        let name = format!("{} · {}", r.shape, bytes(r.bytes));
        let at = chart.backend_coord(&(r.mean, r.error));
        let (h, v, pos) = labels.place(at, &name, POINT);
        root.draw_text(&name, &text(POINT, BLACK, h, v), pos)?;
    }
    Ok(labels)
}

/// One entry of the key: a glyph, then its text.
enum Glyph {
    None,
    Mark(Mark, RGBColor, i32),
    Solid,
    Dashed,
    Ring,
}

/// The key below the panels: colours, shapes, lines and sizes, and how it was measured.
fn draw_key(root: &Area, key: &Area) -> Res<()> {
    let (x0, y0) = key.get_base_pixel();
    let grey = |m| Glyph::Mark(m, GREY, 6);
    let lines: Vec<Vec<(Glyph, String)>> = vec![
        vec![
            (Glyph::None, "f32 (M4F):".into()),
            (
                Glyph::Mark(Mark::Circle, BLUE_, 6),
                "u, the segment's mantissa in [1, 2)".into(),
            ),
            (Glyph::Mark(Mark::Circle, ORANGE, 6), "t = u − 1".into()),
            (grey(Mark::Circle), "1".into()),
            (grey(Mark::Triangle), "2".into()),
            (
                grey(Mark::Square),
                "4 segments per octave; degree 2 to 7 (d2 … d7)".into(),
            ),
        ],
        vec![
            (Glyph::None, "fixed point (M0, M3):".into()),
            (
                Glyph::Mark(Mark::Circle, GREEN_, 6),
                "quadratic (library)".into(),
            ),
            (Glyph::Mark(Mark::Circle, VERMILION, 6), "linear".into()),
            (grey(Mark::Circle), "one table".into()),
            (
                grey(Mark::Diamond),
                "two: coarse, then fine (4+32: nodes per unit of log₂)".into(),
            ),
        ],
        vec![
            (
                Glyph::Solid,
                "Pareto front within the library's bytes".into(),
            ),
            (Glyph::Dashed, "at any size".into()),
            (
                Glyph::Ring,
                "shipped: the library's own kernel, same run".into(),
            ),
            (Glyph::None, "marker area ~ log bytes:".into()),
            (Glyph::Mark(Mark::Circle, GREY, radius(512)), "512 B".into()),
            (Glyph::Mark(Mark::Circle, GREY, radius(4096)), "4 kB".into()),
            (
                Glyph::Mark(Mark::Circle, GREY, radius(32768)),
                "32 kB".into(),
            ),
        ],
        vec![(
            Glyph::None,
            "Instructions: QEMU -icount, mean over inputs spread evenly in log₂ over the domain. \
             Error: the same code on the host, worst over the domain against the f64 reference."
                .into(),
        )],
    ];
    let line_height = 36;
    for (i, line) in lines.iter().enumerate() {
        let y = y0 + 24 + i as i32 * line_height;
        let mut x = x0 + 40;
        for (glyph, words) in line {
            match glyph {
                Glyph::None => {}
                Glyph::Mark(m, color, r) => {
                    mark_px(root, *m, (x + 8, y), *r, color.mix(0.9).filled())?;
                    x += 14 + r;
                }
                Glyph::Solid => {
                    root.draw(&PathElement::new(
                        vec![(x, y), (x + 34, y)],
                        BLACK.stroke_width(2),
                    ))?;
                    x += 42;
                }
                Glyph::Dashed => {
                    root.draw(&plotters::element::DashedPathElement::new(
                        vec![(x, y), (x + 34, y)],
                        6,
                        5,
                        GREY.stroke_width(2),
                    ))?;
                    x += 42;
                }
                Glyph::Ring => {
                    root.draw(&Circle::new((x + 10, y), 10, BLACK.stroke_width(2)))?;
                    x += 26;
                }
            }
            root.draw_text(words, &text(KEY, BLACK, HPos::Left, VPos::Center), (x, y))?;
            x += text_width(words, KEY) + 22;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(shape: &str, mean: f64, error: f64, bytes: u64) -> ShapeRow {
        ShapeRow {
            cpu: "cortex-m4f".into(),
            table: "g".into(),
            core: "f32".into(),
            kind: if shape == "library" {
                "library"
            } else {
                "variant"
            }
            .into(),
            shape: shape.into(),
            variable: "u".into(),
            segments: "1".into(),
            degree: 6,
            bytes,
            mean,
            max: mean + 1.0,
            error,
        }
    }

    #[test]
    fn the_csv_reads_back_what_it_wrote() {
        use crate::records::{parse, to_csv};
        let rows = vec![
            row("library", 23.0, 4.126e-7, 1312),
            row("u-s1-d6", 23.0, 4.126e-7, 1312),
        ];
        let text = to_csv(&rows);
        assert!(text.starts_with("cpu,table,core,kind,shape,"));
        assert_eq!(parse::<ShapeRow>(&text, "t").unwrap(), rows);
        assert!(parse::<ShapeRow>("cpu,table\ncortex-m0,g\n", "t").is_err());
        let bad = text.replace("4.126e-7\n", "x\n");
        assert!(parse::<ShapeRow>(&bad, "t").is_err());
    }

    #[test]
    fn the_front_keeps_what_nothing_beats_by_more_than_the_tolerance() {
        let rows = [
            row("library", 10.0, 1e-9, 1), // the library's kernel: never on the front
            row("a", 15.0, 1e-3, 100),
            row("b", 15.0, 1e-4, 200), // fewer errors, as many instructions
            row("c", 17.0, 2e-4, 100), // dominated by b
            row("d", 19.0, 1e-6, 400),
            row("e", 21.0, 0.95e-6, 100), // within the tolerance of d
            row("f", 23.0, 1e-7, 800),
        ];
        let refs: Vec<&ShapeRow> = rows.iter().collect();
        let names: Vec<&str> = pareto_front(&refs)
            .iter()
            .map(|r| r.shape.as_str())
            .collect();
        assert_eq!(names, ["b", "d", "f"]);
    }

    #[test]
    fn a_panel_per_core_and_table() {
        let mut rows = vec![
            row("library", 23.0, 4e-7, 1312),
            row("u-s1-d6", 23.0, 4e-7, 1312),
            row("u-s4-d4", 19.0, 1.3e-7, 5216),
        ];
        rows[1].kind = "shipped".into();
        let mut fixed = row("library", 48.0, 2e-6, 1196);
        (fixed.cpu, fixed.table, fixed.core) = ("cortex-m0".into(), "log_g".into(), "fixed".into());
        rows.push(fixed);
        let (svg, report) = table_shapes_layout(&rows).unwrap();
        assert!(svg.contains("g(θ) · f32 · Cortex-M4F · library 1312 B"));
        assert!(svg.contains("log₂ g against log₂ θ · fixed point · Cortex-M0"));
        assert!(svg.contains("u-s4-d4 · 5216 B"));
        assert!(report.crowded.is_empty() && report.overlaps().is_empty());
        assert!(table_shapes_layout(&[]).is_err());
    }
}
