//! The monitor example's figures (SVG via plotters; text stays SVG text, no fonts read),
//! written through [`crate::svg::portable`] so that a browser, librsvg and ImageMagick
//! draw them alike. Axis titles are horizontal, above each axis; tick labels carry the
//! decimals their step needs and never read `-0`.

use super::Res;
use super::series::{CURVES, Timeline};
use crate::monitor_output::ThresholdRow;
use misalign::monitor::{RiskState, Thresholds};
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

const BLUE_: RGBColor = RGBColor(0, 114, 178);
const ORANGE: RGBColor = RGBColor(230, 159, 0);
const GREEN_: RGBColor = RGBColor(0, 158, 115);
const VERMILION: RGBColor = RGBColor(213, 94, 0);
const GREY: RGBColor = RGBColor(150, 150, 150);
const LIGHT: RGBColor = RGBColor(225, 225, 225);
/// The state's line: apart from the event lines' colours.
const DARK: RGBColor = RGBColor(60, 60, 60);

const FONT: &str = crate::svg::FONT;

/// A step longer than this (s) between plotted values is drawn as a gap.
const GAP_S: f64 = 60.0;

type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

/// Ticks at a round step (1, 2 or 5 times a power of ten) over `lo..hi`, at most about
/// `most` of them, with the decimals that step needs.
fn ticks(lo: f64, hi: f64, most: usize) -> (Vec<f64>, usize) {
    let raw = ((hi - lo) / most.max(1) as f64).max(f64::MIN_POSITIVE);
    let power = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * power)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * power);
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    ((first..=last).map(|i| i as f64 * step).collect(), decimals)
}

/// A linear axis with its ticks where [`ticks`] puts them (plotters' own `WithKeyPoints`
/// over `f64` takes no label formatter).
#[derive(Clone)]
struct Axis {
    range: std::ops::Range<f64>,
    ticks: Vec<f64>,
}

impl Ranged for Axis {
    type FormatOption = plotters::coord::ranged1d::DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let f = (value - self.range.start) / (self.range.end - self.range.start);
        limit.0 + (f * f64::from(limit.1 - limit.0)).round() as i32
    }

    fn key_points<Hint: plotters::coord::ranged1d::KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            Vec::new()
        } else {
            self.ticks.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.range.clone()
    }
}

/// A tick label with `decimals` decimals; never `-0`.
fn tick_label(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    if s.trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        s.trim_start_matches('-').to_string()
    } else {
        s
    }
}

fn style(size: u32, colour: RGBColor, h: HPos, v: VPos) -> TextStyle<'static> {
    TextStyle {
        font: (FONT, size).into_font(),
        color: colour.to_backend_color(),
        pos: Pos::new(h, v),
    }
}

/// The axis title above a chart's plotting area, at its left edge, horizontal.
fn axis_title<C>(chart: &ChartContext<SVGBackend<'_>, C>, title: &str) -> Res<()>
where
    C: CoordTranslate,
{
    let area = chart.plotting_area().strip_coord_spec();
    area.draw_text(title, &style(13, BLACK, HPos::Left, VPos::Bottom), (0, -6))?;
    Ok(())
}

/// Writes what `draw` draws on a `size` canvas to `path`, portable.
fn write(path: &Path, size: (u32, u32), draw: impl FnOnce(&Area) -> Res<()>) -> Res<()> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root)?;
        root.present()?;
    }
    std::fs::write(path, crate::svg::portable(&svg)?)?;
    Ok(())
}

/// The figure's legend in one row from `(x, y)`: per entry a short vertical line in its
/// style (an event line), or dashed and horizontal (a threshold), then its label.
fn legend_row(
    area: &Area,
    (mut x, y): (i32, i32),
    entries: &[(ShapeStyle, bool, &str)],
) -> Res<()> {
    for &(line, dashed, label) in entries {
        if dashed {
            area.draw(&DashedPathElement::new(
                vec![(x, y), (x + 22, y)],
                5,
                3,
                line,
            ))?;
        } else {
            area.draw(&PathElement::new(
                vec![(x + 11, y - 8), (x + 11, y + 8)],
                line,
            ))?;
        }
        area.draw_text(
            label,
            &style(13, BLACK, HPos::Left, VPos::Center),
            (x + 30, y),
        )?;
        // About 7 px a character at 13 px.
        x += 30 + 7 * label.chars().count() as i32 + 16;
    }
    Ok(())
}

/// d/b, margin, F and the state over time (h), events as vertical lines (one per bin of
/// the timeline and kind), the warning and alarm thresholds of `thresholds` on the
/// curve they are set on; `source` names the replay in the title.
pub fn timeline(
    path: &Path,
    timeline: &Timeline,
    thresholds: &Thresholds,
    source: &str,
) -> Res<()> {
    write(path, (1000, 1000), |root| {
        root.draw_text(
            &format!("Condition monitor over {source}"),
            &style(20, BLACK, HPos::Center, VPos::Top),
            (500, 10),
        )?;
        // The legend of the event lines and thresholds, one row under the title.
        legend_row(
            root,
            (80, 50),
            &[
                (GREY.stroke_width(1), false, "a state change"),
                (
                    VERMILION.stroke_width(2),
                    false,
                    "approaching (time to critical) or a friction event",
                ),
                (BLACK.stroke_width(1), true, "warning and alarm thresholds"),
            ],
        )?;
        let body = root.margin(70, 0, 0, 0);
        let panels = body.split_evenly((4, 1));
        let t_end = (timeline.end_s() / 3600.0).max(1e-3);
        let (t_ticks, t_decimals) = ticks(0.0, t_end, 10);
        let colours = [BLUE_, GREEN_, ORANGE, DARK];
        let titles = [
            "slip ratio d/b",
            "margin to the critical angle, phi0 - |phi| (mrad)",
            "axial force F (N)",
            "risk state",
        ];
        // The thresholds and the curve they are drawn on (d/b, or the margin in mrad).
        let lines: [(usize, f64, &str); 2] = match *thresholds {
            Thresholds::SlipRatio { warning, alarm, .. } => [
                (0, f64::from(warning), "warning"),
                (0, f64::from(alarm), "alarm"),
            ],
            Thresholds::Margin { warning, alarm, .. } => [
                (1, f64::from(warning) * 1e3, "warning"),
                (1, f64::from(alarm) * 1e3, "alarm"),
            ],
        };
        for (k, (area, (name, colour))) in panels.iter().zip(CURVES.iter().zip(colours)).enumerate()
        {
            let runs: Vec<Vec<(f64, f64)>> = timeline
                .runs(k, GAP_S)
                .into_iter()
                .map(|run| {
                    run.into_iter()
                        .map(|(t, v)| (t / 3600.0, f64::from(v)))
                        .collect()
                })
                .collect();
            let state = *name == "state";
            let (mut lo, mut hi) = runs
                .iter()
                .flatten()
                .fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(v.1), h.max(v.1)));
            for &(curve, y, _) in &lines {
                if curve == k && lo <= hi {
                    (lo, hi) = (lo.min(y), hi.max(y));
                }
            }
            if state {
                (lo, hi) = (0.0, 4.0);
            }
            if lo > hi {
                (lo, hi) = (0.0, 1.0);
            }
            let pad = ((hi - lo) * 0.05).max(1e-6);
            let (y_lo, y_hi) = (lo - pad, hi + pad);
            let (y_ticks, y_decimals) = if state {
                ((0..RiskState::ALL.len()).map(|i| i as f64).collect(), 0)
            } else {
                ticks(y_lo, y_hi, 6)
            };
            let last = k == panels.len() - 1;
            let mut chart = ChartBuilder::on(area)
                .margin_left(8)
                .margin_right(16)
                .margin_top(26)
                .margin_bottom(4)
                .x_label_area_size(if last { 48 } else { 24 })
                .y_label_area_size(92)
                .build_cartesian_2d(
                    Axis {
                        range: 0.0..t_end,
                        ticks: t_ticks.clone(),
                    },
                    Axis {
                        range: y_lo..y_hi,
                        ticks: y_ticks,
                    },
                )?;
            let t_label = |t: &f64| tick_label(*t, t_decimals);
            let y_label = |y: &f64| {
                if state {
                    RiskState::ALL
                        .get(y.round() as usize)
                        .filter(|_| (y - y.round()).abs() < 1e-6)
                        .map_or(String::new(), |s| s.as_str().to_string())
                } else {
                    tick_label(*y, y_decimals)
                }
            };
            let mut mesh = chart.configure_mesh();
            mesh.max_light_lines(0)
                .bold_line_style(LIGHT)
                .label_style((FONT, 13))
                .axis_desc_style((FONT, 14))
                .x_label_formatter(&t_label)
                .y_label_formatter(&y_label);
            if last {
                mesh.x_desc("time since the start (h)");
            }
            mesh.draw()?;
            axis_title(&chart, titles[k])?;
            for bin in timeline.bins() {
                let marks = [
                    (bin.state_change, GREY.stroke_width(1)),
                    (bin.alert, VERMILION.stroke_width(2)),
                ];
                for (t, style) in marks {
                    if let Some(t) = t {
                        let t = t / 3600.0;
                        chart.draw_series(std::iter::once(PathElement::new(
                            vec![(t, y_lo), (t, y_hi)],
                            style,
                        )))?;
                    }
                }
            }
            // One line per run of samples: a stop, a fault or a dropout leaves a gap.
            for run in runs {
                chart.draw_series(LineSeries::new(run, colour.stroke_width(1)))?;
            }
            for &(curve, y, label) in &lines {
                if curve != k {
                    continue;
                }
                chart.draw_series(std::iter::once(DashedPathElement::new(
                    vec![(0.0, y), (t_end, y)],
                    5,
                    3,
                    BLACK.stroke_width(1),
                )))?;
                chart.draw_series(std::iter::once(Text::new(
                    format!("{label} {}", tick_label(y, 2)),
                    (t_end * 0.005, y),
                    style(12, BLACK, HPos::Left, VPos::Bottom),
                )))?;
            }
        }
        Ok(())
    })
}

/// phi0(P) and the trigger angles over the load range, with the replay's operating
/// points (P in N, |phi| in rad).
pub fn thresholds(path: &Path, table: &[ThresholdRow], points: &[(f32, f32)]) -> Res<()> {
    write(path, (800, 600), |root| {
        let p_max = table.iter().map(|r| r[0]).fold(1.0, f64::max);
        let phi_max = table
            .iter()
            .flat_map(|r| r[1..].iter())
            .filter(|x| x.is_finite())
            .fold(1e-6f64, |a, &b| a.max(b))
            * 1e3
            * 1.1;
        let (p_ticks, p_decimals) = ticks(0.0, p_max, 8);
        let (phi_ticks, phi_decimals) = ticks(0.0, phi_max, 8);
        root.draw_text(
            "Where each state is raised and cleared, over the load range",
            &style(20, BLACK, HPos::Center, VPos::Top),
            (400, 10),
        )?;
        // Room under the title for the horizontal axis title above the plot.
        let body = root.margin(64, 0, 0, 0);
        let mut chart = ChartBuilder::on(&body)
            .margin(12)
            .margin_right(24)
            .x_label_area_size(48)
            .y_label_area_size(56)
            .build_cartesian_2d(
                Axis {
                    range: 0.0..p_max,
                    ticks: p_ticks,
                },
                Axis {
                    range: 0.0..phi_max,
                    ticks: phi_ticks,
                },
            )?;
        let p_label = |p: &f64| tick_label(*p, p_decimals);
        let phi_label = |phi: &f64| tick_label(*phi, phi_decimals);
        chart
            .configure_mesh()
            .max_light_lines(0)
            .bold_line_style(LIGHT)
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 14))
            .x_desc("load P (N)")
            .x_label_formatter(&p_label)
            .y_label_formatter(&phi_label)
            .draw()?;
        axis_title(&chart, "misalignment |phi| (mrad)")?;
        let samples: Vec<(f64, f64)> = points
            .iter()
            .map(|&(load, phi)| (f64::from(load), f64::from(phi) * 1e3))
            .filter(|&(load, phi)| load <= p_max && phi <= phi_max)
            .collect();
        chart
            .draw_series(samples.iter().map(|&c| Circle::new(c, 1, GREY.filled())))?
            .label("the replay's samples")
            .legend(|(x, y)| Circle::new((x + 10, y), 3, GREY.filled()));
        let curve = |i: usize| -> Vec<(f64, f64)> {
            table
                .iter()
                .filter(|r| r[i].is_finite())
                .map(|r| (r[0], r[i] * 1e3))
                .collect()
        };
        let raised_cleared: [(usize, &str, RGBColor); 4] = [
            (2, "warning raised", ORANGE),
            (3, "warning cleared", GREEN_),
            (4, "alarm raised", VERMILION),
            (5, "alarm cleared", BLUE_),
        ];
        for (i, label, colour) in raised_cleared {
            chart
                .draw_series(LineSeries::new(curve(i), colour.stroke_width(2)))?
                .label(label)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
                });
        }
        // phi0 last and dashed: where the alarm is gross slip (d/b = 1) it lies on the
        // "alarm raised" curve, which shows through its gaps.
        chart
            .draw_series(std::iter::once(DashedPathElement::new(
                curve(1),
                8,
                5,
                BLACK.stroke_width(2),
            )))?
            .label("phi0: gross slip (d/b = 1)")
            .legend(|(x, y)| {
                DashedPathElement::new(vec![(x, y), (x + 20, y)], 8, 5, BLACK.stroke_width(2))
            });
        chart
            .configure_series_labels()
            .label_font((FONT, 13))
            .background_style(WHITE)
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperLeft)
            .draw()?;
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_carry_the_decimals_of_their_step() {
        let (t, d) = ticks(300.0, 1100.0, 8);
        assert_eq!(
            t.iter().map(|v| tick_label(*v, d)).collect::<Vec<_>>()[..3],
            ["300", "400", "500"]
        );
        let (t, d) = ticks(-0.31, 0.7, 6);
        let labels: Vec<String> = t.iter().map(|v| tick_label(*v, d)).collect();
        assert_eq!(labels, ["-0.2", "0.0", "0.2", "0.4", "0.6"]);
        assert_eq!(tick_label(-1e-17, 1), "0.0");
        assert_eq!(tick_label(-0.04, 1), "0.0");
        assert_eq!(tick_label(-0.06, 1), "-0.1");
    }
}
