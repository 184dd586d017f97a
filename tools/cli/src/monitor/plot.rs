//! The monitor example's figures (SVG via plotters; text stays SVG text, no fonts read).

use super::Res;
use super::series::{CURVES, Timeline};
use crate::monitor_output::ThresholdRow;
use misalign::monitor::RiskState;
use plotters::prelude::*;
use std::path::Path;

const BLUE_: RGBColor = RGBColor(0, 114, 178);
const ORANGE: RGBColor = RGBColor(230, 159, 0);
const GREEN_: RGBColor = RGBColor(0, 158, 115);
const VERMILION: RGBColor = RGBColor(213, 94, 0);
const GREY: RGBColor = RGBColor(150, 150, 150);

/// A step longer than this (s) between plotted values is drawn as a gap.
const GAP_S: f64 = 60.0;

/// d/b, margin, F and the state over time (h), events as vertical lines (one per bin of
/// the timeline and kind).
pub fn timeline(path: &Path, timeline: &Timeline) -> Res<()> {
    let root = SVGBackend::new(path, (1000, 900)).into_drawing_area();
    root.fill(&WHITE)?;
    let panels = root.split_evenly((4, 1));
    let t_end = (timeline.end_s() / 3600.0).max(1e-3);
    let colours = [BLUE_, GREEN_, ORANGE, VERMILION];
    for (k, (area, (name, colour))) in panels.iter().zip(CURVES.iter().zip(colours)).enumerate() {
        let name = *name;
        let runs = timeline.runs(k, GAP_S);
        let (mut lo, mut hi) = runs
            .iter()
            .flatten()
            .fold((f32::MAX, f32::MIN), |(l, h), v| (l.min(v.1), h.max(v.1)));
        if name == "state" {
            (lo, hi) = (0.0, 4.0);
        }
        if lo > hi {
            (lo, hi) = (0.0, 1.0);
        }
        let pad = ((hi - lo) * 0.05).max(1e-6);
        let mut chart = ChartBuilder::on(area)
            .margin(8)
            .x_label_area_size(28)
            .y_label_area_size(70)
            .build_cartesian_2d(0.0..t_end, (lo - pad)..(hi + pad))?;
        let mut mesh = chart.configure_mesh();
        mesh.x_desc("t (h)").y_desc(name).light_line_style(WHITE);
        let states = |y: &f32| {
            RiskState::ALL
                .get(y.round() as usize)
                .filter(|_| (y - y.round()).abs() < 1e-3)
                .map_or(String::new(), |s| s.as_str().to_string())
        };
        if name == "state" {
            mesh.y_labels(5).y_label_formatter(&states);
        }
        mesh.draw()?;
        for bin in timeline.bins() {
            let marks = [
                (bin.state_change, GREY.stroke_width(1)),
                (bin.alert, VERMILION.stroke_width(2)),
            ];
            for (t, style) in marks {
                if let Some(t) = t {
                    let t = t / 3600.0;
                    chart.draw_series(std::iter::once(PathElement::new(
                        vec![(t, lo - pad), (t, hi + pad)],
                        style,
                    )))?;
                }
            }
        }
        // One line per run of samples: a stop, a fault or a dropout leaves a gap.
        for run in runs {
            let run = run.into_iter().map(|(t, v)| (t / 3600.0, v));
            chart.draw_series(LineSeries::new(run, colour.stroke_width(1)))?;
        }
        if name == "d/b" {
            for (y, label) in [(0.8f32, "warning"), (1.0, "alarm")] {
                if y > lo - pad && y < hi + pad {
                    chart
                        .draw_series(std::iter::once(PathElement::new(
                            vec![(0.0, y), (t_end, y)],
                            BLACK.stroke_width(1),
                        )))?
                        .label(label);
                }
            }
        }
    }
    root.present()?;
    Ok(())
}

/// phi0(P) and the trigger angles over the load range, with the replay's operating
/// points (P in N, |phi| in rad).
pub fn thresholds(path: &Path, table: &[ThresholdRow], points: &[(f32, f32)]) -> Res<()> {
    let root = SVGBackend::new(path, (800, 600)).into_drawing_area();
    root.fill(&WHITE)?;
    let p_max = table.iter().map(|r| r[0]).fold(1.0, f64::max);
    let phi_max = table
        .iter()
        .flat_map(|r| r[1..].iter())
        .filter(|x| x.is_finite())
        .fold(1e-6f64, |a, &b| a.max(b))
        * 1e3
        * 1.1;
    let mut chart = ChartBuilder::on(&root)
        .margin(12)
        .caption("Where each state triggers", ("sans-serif", 22))
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..p_max, 0.0..phi_max)?;
    chart
        .configure_mesh()
        .x_desc("load P (N)")
        .y_desc("misalignment (mrad)")
        .draw()?;
    let samples: Vec<(f64, f64)> = points
        .iter()
        .map(|&(load, phi)| (f64::from(load), f64::from(phi) * 1e3))
        .filter(|&(load, phi)| load <= p_max && phi <= phi_max)
        .collect();
    chart
        .draw_series(samples.iter().map(|&c| Circle::new(c, 1, GREY.filled())))?
        .label("samples")
        .legend(|(x, y)| Circle::new((x + 10, y), 3, GREY.filled()));
    let curves: [(usize, &str, RGBColor); 5] = [
        (1, "phi0 (gross slip, d/b = 1)", BLACK),
        (2, "warning raised", ORANGE),
        (3, "warning cleared", GREEN_),
        (4, "alarm raised", VERMILION),
        (5, "alarm cleared", BLUE_),
    ];
    for (i, label, colour) in curves {
        let line: Vec<(f64, f64)> = table
            .iter()
            .filter(|r| r[i].is_finite())
            .map(|r| (r[0], r[i] * 1e3))
            .collect();
        chart
            .draw_series(LineSeries::new(line, colour.stroke_width(2)))?
            .label(label)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperLeft)
        .draw()?;
    root.present()?;
    Ok(())
}
