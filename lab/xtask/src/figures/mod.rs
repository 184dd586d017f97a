//! `cargo xtask figures`: the paper's Figs 1-4 redrawn from the f64 reference
//! ([`paper`]), the benchmark's speed against error ([`bench_plot`], from
//! docs/bench.csv) and the table shapes weighed ([`shapes_plot`], from
//! docs/shapes.csv), label placement in [`labels`], as SVG files under `docs/`. This
//! module holds what they share: size, fonts, colours, axes.
//!
//! The output is deterministic (no dates, no randomness, fixed orders), so
//! `cargo xtask figures --check` can hold the committed files to what the reference
//! gives today. Text stays SVG `<text>`: no fonts are read or rasterised.

mod bench_plot;
mod labels;
mod paper;
pub mod render;
mod shapes_plot;

pub use bench_plot::speed_vs_error;
pub use shapes_plot::fronts;

use crate::records::{self, BenchRow, Record, ShapeRow};
use std::error::Error;
use std::fmt::Write as _;
use std::path::Path;
use std::process::ExitCode;

use plotters::coord::Shift;
use plotters::coord::combinators::WithKeyPoints;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

type Res<T> = Result<T, Box<dyn Error>>;
type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

/// Every figure is drawn at this size (px).
pub const SIZE: (u32, u32) = (800, 600);
/// The one font every renderer here has ([`misalign_cli::svg`]).
const FONT: &str = misalign_cli::svg::FONT;
/// Font sizes as plotters takes them (it writes `size / 1.24` px into the SVG).
const TITLE: u32 = 25;
const DESC: u32 = 21;
const LABEL: u32 = 18;
const NOTE: u32 = 17;

// Okabe-Ito colours: distinguishable with the common colour-vision deficiencies.
const BLUE_: RGBColor = RGBColor(0, 114, 178);
const ORANGE: RGBColor = RGBColor(230, 159, 0);
const GREEN_: RGBColor = RGBColor(0, 158, 115);
const VERMILION: RGBColor = RGBColor(213, 94, 0);
const PURPLE: RGBColor = RGBColor(204, 121, 167);
const SKY: RGBColor = RGBColor(86, 180, 233);
const GREY: RGBColor = RGBColor(110, 110, 110);
const LIGHT: RGBColor = RGBColor(225, 225, 225);
/// Fills of the slip and stick zones (orange and sky blue, lightened).
const SLIP_FILL: RGBColor = RGBColor(248, 222, 170);
const STICK_FILL: RGBColor = RGBColor(170, 217, 244);
/// `10⁻⁶` for a power of ten, else the value in short scientific form.
fn power_of_ten(v: &f64) -> String {
    let e = v.log10().round();
    if (v / 10f64.powf(e) - 1.0).abs() < 1e-6 {
        let digits: String = format!("{}", e as i32)
            .chars()
            .map(|c| match c {
                '-' => '⁻',
                '0' => '⁰',
                '1' => '¹',
                '2' => '²',
                '3' => '³',
                '4' => '⁴',
                '5' => '⁵',
                '6' => '⁶',
                '7' => '⁷',
                '8' => '⁸',
                _ => '⁹',
            })
            .collect();
        format!("10{digits}")
    } else {
        format!("{v:.0e}")
    }
}

/// Three significant digits, fixed point: `0.0166`, `779`, `1.41e-4` below 1e-3.
fn sig3(v: f64) -> String {
    let e = v.abs().log10().floor();
    if e < -3.0 {
        format!("{v:.2e}")
    } else {
        format!("{v:.*}", (2.0 - e).max(0.0) as usize)
    }
}

fn one_decimal(v: &f64) -> String {
    // No "-0.0" for a tick that lands a rounding error below zero.
    format!("{:.1}", if v.abs() < 1e-9 { 0.0 } else { *v })
}

/// 10^e exactly (as the decimal literal `1e{e}` parses).
fn ten_to(e: i32) -> f64 {
    format!("1e{e}").parse().expect("a power of ten")
}

/// A log axis from 10^lo to 10^hi with a tick and label at every decade.
fn log_axis(lo: i32, hi: i32) -> WithKeyPoints<LogCoord<f64>> {
    (ten_to(lo)..ten_to(hi))
        .log_scale()
        .with_key_points((lo..=hi).map(ten_to).collect())
}

/// A text style in the figure font, anchored at `(h, v)`.
fn text(size: u32, color: RGBColor, h: HPos, v: VPos) -> TextStyle<'static> {
    TextStyle {
        font: (FONT, size).into_font(),
        color: color.to_backend_color(),
        pos: Pos::new(h, v),
    }
}

/// Draws into an 800x600 SVG held in memory and returns it.
fn render(draw: impl FnOnce(&Area) -> Res<()>) -> Res<String> {
    render_sized(SIZE, draw)
}

/// Draws into an SVG of `size` px held in memory and returns it, as a browser, librsvg
/// and ImageMagick draw alike ([`misalign_cli::svg::portable`]).
fn render_sized(size: (u32, u32), draw: impl FnOnce(&Area) -> Res<()>) -> Res<String> {
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, size).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root)?;
        root.present()?;
    }
    Ok(misalign_cli::svg::portable(&buf)?)
}

/// Room between a caption and its plot for the y axis's title (px).
const Y_TITLE_ROOM: i32 = 24;

/// Draws `caption` centred at the top of `area`, `margin` px down, and returns the area
/// under it, with room above the plot for the y axis's title ([`y_title`]).
fn captioned<'a>(area: &Area<'a>, caption: &str, size: u32, margin: i32) -> Res<Area<'a>> {
    let (w, _) = area.dim_in_pixel();
    area.draw_text(
        caption,
        &text(size, BLACK, HPos::Center, VPos::Top),
        (w as i32 / 2, margin),
    )?;
    // plotters writes a font size of `size / 1.24` px; a line is about 1.2 of it.
    let caption_px = (f64::from(size) / 1.24 * 1.2).ceil() as i32;
    Ok(area.margin(margin + caption_px + Y_TITLE_ROOM, 0, 0, 0))
}

/// The y axis's title, horizontal, above the plot's top left corner: ImageMagick draws
/// rotated text the other way round.
fn y_title<CT: CoordTranslate>(
    chart: &ChartContext<'_, SVGBackend<'_>, CT>,
    title: &str,
    size: u32,
) -> Res<()> {
    chart.plotting_area().strip_coord_spec().draw_text(
        title,
        &text(size, BLACK, HPos::Left, VPos::Bottom),
        (0, -8),
    )?;
    Ok(())
}

/// Legend entry: a short line in `style`.
fn legend_line(style: ShapeStyle) -> impl Fn((i32, i32)) -> PathElement<(i32, i32)> {
    move |(x, y)| PathElement::new(vec![(x, y), (x + 28, y)], style)
}

/// Legend entry: a short dashed line in `style`.
fn legend_dashed(
    style: ShapeStyle,
) -> impl Fn((i32, i32)) -> DashedPathElement<std::vec::IntoIter<(i32, i32)>, i32> {
    move |(x, y)| DashedPathElement::new(vec![(x, y), (x + 28, y)], 9, 5, style)
}

/// Names of the benchmark's figure and of the table shapes' under `docs/`.
pub const SPEED_SVG: &str = "speed-vs-error.svg";
pub const SHAPES_SVG: &str = "table-shapes.svg";

/// Writes the table shapes' figure of `rows` to `svg_path`.
///
/// # Errors
/// No row to plot, or an unwritable SVG.
pub fn table_shapes(rows: &[ShapeRow], svg_path: &Path) -> Res<()> {
    let svg = shapes_plot::table_shapes_svg(rows)?;
    std::fs::write(svg_path, svg).map_err(|e| format!("write {}: {e}", svg_path.display()))?;
    Ok(())
}

/// `cargo xtask figures [--check]` with `docs` the output folder.
pub fn run(docs: &Path, check: bool) -> ExitCode {
    match run_inner(docs, check) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(e) => {
            eprintln!("figures: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Says which labels of `name` found no free place or overlap (the tests forbid both
/// for the committed CSVs).
fn warn_labels(name: &str, report: &labels::LabelReport) {
    if !report.crowded.is_empty() {
        eprintln!("{name}: labels with no free place: {:?}", report.crowded);
    }
    let overlaps = report.overlaps();
    if !overlaps.is_empty() {
        eprintln!("{name}: {} pairs of labels overlap", overlaps.len());
    }
}

/// The figures drawn from measurements, each from its CSV under `docs` when that
/// exists: the speed against error (docs/bench.csv) and the table shapes
/// (docs/shapes.csv), with where their labels went.
fn measured_figures(docs: &Path) -> Res<Vec<(&'static str, String, labels::LabelReport)>> {
    let mut out = Vec::new();
    let csv = docs.join(BenchRow::FILE);
    if csv.exists() {
        let rows = bench_plot::parse_bench_csv(&std::fs::read_to_string(&csv)?)?;
        let (svg, report) = bench_plot::speed_vs_error_layout(&rows)?;
        out.push((SPEED_SVG, svg, report));
    } else {
        println!(
            "skipped {SPEED_SVG}: no {} (run cargo xtask bench)",
            csv.display()
        );
    }
    let csv = docs.join(ShapeRow::FILE);
    if csv.exists() {
        let rows = records::parse::<ShapeRow>(&std::fs::read_to_string(&csv)?, "shapes CSV")?;
        let (svg, report) = shapes_plot::table_shapes_layout(&rows)?;
        out.push((SHAPES_SVG, svg, report));
    } else {
        println!(
            "skipped {SHAPES_SVG}: no {} (run cargo xtask shapes)",
            csv.display()
        );
    }
    Ok(out)
}

fn run_inner(docs: &Path, check: bool) -> Res<bool> {
    // `lab/xtask/../docs` reads better as the absolute folder.
    let docs = &docs
        .parent()
        .and_then(|p| p.canonicalize().ok())
        .zip(docs.file_name())
        .map_or_else(|| docs.to_path_buf(), |(p, name)| p.join(name));
    let mut figures = paper::paper_figures()?;
    for (name, svg, report) in measured_figures(docs)? {
        warn_labels(name, &report);
        figures.push((name, svg));
    }
    if check {
        let mut stale = String::new();
        for (name, svg) in &figures {
            let path = docs.join(name);
            if std::fs::read_to_string(&path).ok().as_deref() != Some(svg.as_str()) {
                writeln!(stale, "    {}", path.display())?;
            }
        }
        if stale.is_empty() {
            println!("{} figures match the reference", figures.len());
            return Ok(true);
        }
        eprint!("figures differ from what `cargo xtask figures` writes:\n{stale}");
        return Ok(false);
    }
    std::fs::create_dir_all(docs)?;
    for (name, svg) in &figures {
        let path = docs.join(name);
        std::fs::write(&path, svg)?;
        println!("wrote {}", path.display());
    }
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The committed speed-against-error and table-shapes figures are what their
    /// committed CSVs draw, and every label in them found a place of its own: none
    /// overlaps another, none was forced onto a marker.
    #[test]
    fn measured_figures_match_their_csvs_and_no_label_overlaps() {
        let docs = crate::root().join("docs");
        let figures = measured_figures(&docs).unwrap();
        assert_eq!(
            figures.len(),
            2,
            "docs/bench.csv and docs/shapes.csv are committed"
        );
        for (name, svg, report) in figures {
            let committed = std::fs::read_to_string(docs.join(name)).unwrap_or_default();
            assert!(
                committed == svg,
                "docs/{name} differs from its CSV's figure: run `cargo xtask figures`"
            );
            assert!(!report.boxes.is_empty(), "{name}: no label placed");
            assert_eq!(
                report.crowded,
                Vec::<String>::new(),
                "{name}: crowded labels"
            );
            assert_eq!(report.overlaps(), vec![], "{name}: overlapping labels");
        }
    }

    #[test]
    fn power_of_ten_labels() {
        assert_eq!(power_of_ten(&1e-6), "10⁻⁶");
        assert_eq!(power_of_ten(&1e5), "10⁵");
        assert_eq!(power_of_ten(&1.0), "10⁰");
        assert_eq!(power_of_ten(&2e-3), "2e-3");
    }
}
