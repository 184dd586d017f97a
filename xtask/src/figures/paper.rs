//! `cargo xtask figures`: the paper's Figs 1-4 redrawn from the f64 reference
//! (`misalign::reference`), and the benchmark's speed against error, as SVG files
//! under `docs/`.
//!
//! The output is deterministic (no dates, no randomness, fixed orders), so
//! `cargo xtask figures --check` can hold the committed files to what the reference
//! gives today. Text stays SVG `<text>`: no fonts are read or rasterised.

use std::error::Error;
use std::fmt::Write as _;
use std::path::Path;
use std::process::ExitCode;

use misalign::Scene;
use misalign::reference::{self, Elliptic, line, normal, tangential};
use plotters::coord::Shift;
use plotters::coord::combinators::WithKeyPoints;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

type Res<T> = Result<T, Box<dyn Error>>;
type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

/// Every figure is drawn at this size (px).
pub const SIZE: (u32, u32) = (800, 600);
const FONT: &str = "sans-serif";
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

/// Range of theta (rad) of Figs 1 and 3: the small angles the paper plots.
pub const THETA_RANGE: (f64, f64) = (1e-6, 1e-1);
/// Points per drawn curve on the theta axis (12 per decade: the curves are nearly
/// straight in log-log, and SVG coordinates are whole pixels, so more points only
/// add pixel-rounding wiggle).
pub const THETA_POINTS: usize = 61;

/// The slip ratio d/b of the partial-slip case of Fig. 2.
pub const FIG2_SLIP_RATIO: f64 = 0.5;

/// File name and content of one figure.
pub type Figure = (&'static str, String);

/// `n` points from `lo` to `hi` (both included), evenly spaced in log.
fn log_grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let decades = (hi / lo).log10();
    (0..n)
        .map(|i| match i {
            0 => lo,
            _ if i == n - 1 => hi,
            _ => lo * 10f64.powf(decades * i as f64 / (n - 1) as f64),
        })
        .collect()
}

/// `n` values of theta log-spaced over [`THETA_RANGE`].
pub fn theta_grid(n: usize) -> Vec<f64> {
    log_grid(THETA_RANGE.0, THETA_RANGE.1, n)
}

/// Fig. 1: `(theta, m, n)` from eqs (5)-(6) at each theta of `thetas`.
pub fn fig1_data(thetas: &[f64]) -> Vec<(f64, f64, f64)> {
    thetas
        .iter()
        .copied()
        .map(|theta| {
            let s = normal::ellipse_shape(theta).expect("theta in [0, pi/2]");
            (theta, s.m, s.n)
        })
        .collect()
}

/// Fig. 3: `(theta, mu^3 P0*)` from eq (18), `mu^3 P0* = (pi m n theta)^3 / 48`, at
/// each theta of `thetas`.
pub fn fig3_data(thetas: &[f64]) -> Vec<(f64, f64)> {
    thetas
        .iter()
        .copied()
        .map(|theta| {
            let g = normal::ellipse_shape(theta)
                .expect("theta in [0, pi/2]")
                .g();
            let x = std::f64::consts::PI * g;
            (theta, x * x * x / 48.0)
        })
        .collect()
}

/// Fig. 4: `(d/b, F/(mu P) of the ellipse (eq 21), F/(mu P) of line contact (eq 27))`
/// for d/b from 0 to 1.2 in steps of `1/per_unit` (d/b = 1 is a grid point).
pub fn fig4_data(per_unit: u32) -> Vec<(f64, f64, f64)> {
    (0..=per_unit * 6 / 5)
        .map(|i| {
            let s = f64::from(i) / f64::from(per_unit);
            (
                s,
                tangential::axial_force_ratio(s),
                line::axial_force_ratio(s),
            )
        })
        .collect()
}

/// The partial-slip case of Fig. 2: steel rollers (R1 = R2 = 50 mm, G = 79.3 GPa,
/// nu = 0.3, mu = 0.3) under P = 1 kN at the misalignment that gives d/b = 1/2.
pub struct Fig2Case {
    /// The installation.
    pub scene: Scene,
    /// The reference solution at the chosen phi.
    pub contact: Elliptic,
    /// The critical angle phi0 (rad) at this load.
    pub phi0: f64,
}

/// Finds the phi of [`Fig2Case`] by bisection: d/b grows with phi from 0 to 1 at phi0.
pub fn fig2_case() -> Fig2Case {
    let scene = Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3).expect("a valid scene");
    let load = 1000.0;
    let slip = |phi: f64| {
        reference::elliptic(&scene, load, phi)
            .expect("valid sample")
            .slip_ratio
    };
    let (phi0, _) = reference::critical_angle(&scene, load).expect("a critical angle");
    let (mut lo, mut hi) = (0.0, phi0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if slip(mid) < FIG2_SLIP_RATIO {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let contact = reference::elliptic(&scene, load, hi).expect("valid sample");
    Fig2Case {
        scene,
        contact,
        phi0,
    }
}

/// Fig. 2(a): the stick zone as `(x/a, y_min/b, y_max/b)` from `Elliptic::stick_zone`
/// (y from 2d - c to c, eqs 10, 14), x over the sections where c(x) > d, spaced
/// densely near the ends where the zone closes at y = d.
pub fn fig2_stick_zone(case: &Fig2Case) -> Vec<(f64, f64, f64)> {
    let e = &case.contact;
    let s = e.d / e.b;
    let edge = (1.0 - s * s).sqrt();
    let n = 200;
    (0..=n)
        .map(|i| {
            let xa = -edge * (std::f64::consts::PI * f64::from(i) / f64::from(n)).cos();
            let (lo, hi) = e.stick_zone(xa * e.a).unwrap_or((e.d, e.d));
            (xa, lo / e.b, hi / e.b)
        })
        .collect()
}

/// Fig. 2(b): `(y/b, X/(mu p0), p/p0)` across the ellipse at x = 0 (eqs 7, 11).
pub fn fig2_traction(case: &Fig2Case) -> Vec<(f64, f64, f64)> {
    let e = &case.contact;
    let mu_p0 = case.scene.friction() * e.p0;
    (0..=400)
        .map(|i| {
            let yb = f64::from(i) / 200.0 - 1.0;
            let y = yb * e.b;
            (
                yb,
                e.traction(&case.scene, 0.0, y) / mu_p0,
                e.pressure(0.0, y) / e.p0,
            )
        })
        .collect()
}

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
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, SIZE).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root)?;
        root.present()?;
    }
    Ok(buf)
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

/// Fig. 1: m and n versus theta, log-log.
pub fn fig1() -> Res<String> {
    let data = fig1_data(&theta_grid(THETA_POINTS));
    render(|root| {
        let mut chart = ChartBuilder::on(root)
            .caption(
                "Fig. 1 (paper, eqs 5-6): ellipse coefficients m, n at small θ",
                (FONT, TITLE),
            )
            .margin(18)
            .x_label_area_size(62)
            .y_label_area_size(90)
            .build_cartesian_2d(log_axis(-6, -1), log_axis(-3, 5))?;
        chart
            .configure_mesh()
            .x_desc("auxiliary angle θ (rad), eq (4); θ = φ for equal radii")
            .y_desc("m, n (dimensionless): a = m L, b = n L")
            .x_label_formatter(&power_of_ten)
            .y_label_formatter(&power_of_ten)
            .axis_desc_style((FONT, DESC))
            .label_style((FONT, LABEL))
            .light_line_style(WHITE)
            .bold_line_style(LIGHT)
            .draw()?;
        let m_style = BLUE_.stroke_width(3);
        chart
            .draw_series(LineSeries::new(
                data.iter().map(|&(t, m, _)| (t, m)),
                m_style,
            ))?
            .label("m: semi-axis a along the rollers")
            .legend(legend_line(m_style));
        let n_style = VERMILION.stroke_width(3);
        chart
            .draw_series(DashedLineSeries::new(
                data.iter().map(|&(t, _, n)| (t, n)),
                12,
                6,
                n_style,
            ))?
            .label("n: semi-axis b across (rolling direction)")
            .legend(legend_dashed(n_style));
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .margin(12)
            .legend_area_size(40)
            .background_style(WHITE)
            .border_style(GREY)
            .label_font((FONT, LABEL))
            .draw()?;
        root.draw_text(
            "L³ = 3P(1 − ν)R1R2 / (2G(R1 + R2)); a/b = m/n = 1/k′",
            &text(NOTE, GREY, HPos::Right, VPos::Bottom),
            (760, 500),
        )?;
        Ok(())
    })
}

/// Fig. 2: (a) stick and slip zones in x/a, y/b; (b) traction across at x = 0.
pub fn fig2() -> Res<String> {
    let case = fig2_case();
    let e = &case.contact;
    let s = e.d / e.b;
    let zone = fig2_stick_zone(&case);
    let traction = fig2_traction(&case);
    render(|root| {
        root.draw_text(
            &format!(
                "Fig. 2 (paper, eqs 10-14): partial slip at d/b = {:.2}",
                e.slip_ratio
            ),
            &text(TITLE, BLACK, HPos::Center, VPos::Top),
            (400, 8),
        )?;
        root.draw_text(
            "steel rollers R1 = R2 = 50 mm, G = 79.3 GPa, ν = 0.3, μ = 0.3, load P = 1 kN",
            &text(NOTE, GREY, HPos::Center, VPos::Top),
            (400, 40),
        )?;
        root.draw_text(
            &format!(
                "φ = {} rad (φ₀ = {} rad at this load); a = {} mm, b = {} mm",
                sig3(e.phi),
                sig3(case.phi0),
                sig3(e.a * 1e3),
                sig3(e.b * 1e3)
            ),
            &text(NOTE, GREY, HPos::Center, VPos::Top),
            (400, 62),
        )?;
        let body = root.margin(86, 0, 0, 0);
        let (left, right) = body.split_horizontally(400);
        stick_slip_panel(&left, s, &zone)?;
        traction_panel(&right, s, &traction)?;
        Ok(())
    })
}

fn stick_slip_panel(area: &Area, s: f64, zone: &[(f64, f64, f64)]) -> Res<()> {
    let mut chart = ChartBuilder::on(area)
        .caption("(a) stick and slip zones", (FONT, DESC))
        .margin(10)
        .x_label_area_size(56)
        .y_label_area_size(62)
        .build_cartesian_2d(-1.3..1.3, -1.3..1.3)?;
    chart
        .configure_mesh()
        .x_desc("x/a (along the rollers; dimensionless)")
        .y_desc("y/b (rolling direction; dimensionless)")
        .x_label_formatter(&one_decimal)
        .y_label_formatter(&one_decimal)
        .x_labels(6)
        .axis_desc_style((FONT, LABEL))
        .label_style((FONT, NOTE))
        .disable_mesh()
        .draw()?;
    // The ellipse x^2/a^2 + y^2/b^2 = 1, all slipping but for the stick zone.
    let outline: Vec<(f64, f64)> = (0..=360)
        .map(|i| {
            let t = f64::from(i).to_radians();
            (t.cos(), t.sin())
        })
        .collect();
    chart.draw_series(std::iter::once(Polygon::new(
        outline.clone(),
        SLIP_FILL.filled(),
    )))?;
    let mut stick: Vec<(f64, f64)> = zone.iter().map(|&(x, _, hi)| (x, hi)).collect();
    stick.extend(zone.iter().rev().map(|&(x, lo, _)| (x, lo)));
    chart.draw_series(std::iter::once(Polygon::new(
        stick.clone(),
        STICK_FILL.filled(),
    )))?;
    chart.draw_series(LineSeries::new(
        zone.iter().map(|&(x, lo, _)| (x, lo)),
        BLUE_.stroke_width(3),
    ))?;
    chart.draw_series(LineSeries::new(outline, BLACK.stroke_width(2)))?;
    let edge = (1.0 - s * s).sqrt();
    chart.draw_series(DashedLineSeries::new(
        [(-edge, s), (edge, s)],
        8,
        5,
        GREY.stroke_width(2),
    ))?;
    let centre = |size| text(size, BLACK, HPos::Center, VPos::Center);
    chart.draw_series([
        Text::new("stick", (0.0, 0.75), centre(LABEL)),
        Text::new("slip", (0.0, -0.45), centre(LABEL)),
        Text::new("leading edge", (0.0, 1.15), centre(NOTE)),
        Text::new("trailing edge", (0.0, -1.15), centre(NOTE)),
        Text::new(
            "y = d",
            (edge + 0.07, s),
            text(NOTE, GREY, HPos::Left, VPos::Center),
        ),
    ])?;
    chart.draw_series(std::iter::once(Text::new(
        "y = 2d − c(x)",
        (-0.25, 2.0 * s - (1.0 - 0.25f64 * 0.25).sqrt() - 0.1),
        text(NOTE, BLUE_, HPos::Center, VPos::Top),
    )))?;
    Ok(())
}

fn traction_panel(area: &Area, s: f64, traction: &[(f64, f64, f64)]) -> Res<()> {
    let mut chart = ChartBuilder::on(area)
        .caption("(b) axial traction X at x = 0", (FONT, DESC))
        .margin(10)
        .x_label_area_size(56)
        .y_label_area_size(62)
        .build_cartesian_2d(-1.05..1.05, 0.0..1.15)?;
    chart
        .configure_mesh()
        .x_desc("y/b (rolling direction; dimensionless)")
        .y_desc("X / (μ p₀) (dimensionless)")
        .x_label_formatter(&one_decimal)
        .y_label_formatter(&one_decimal)
        .x_labels(6)
        .axis_desc_style((FONT, LABEL))
        .label_style((FONT, NOTE))
        .light_line_style(WHITE)
        .bold_line_style(LIGHT)
        .draw()?;
    // Stick zone at x = 0: y from 2d - b to b.
    chart.draw_series(std::iter::once(Rectangle::new(
        [(2.0 * s - 1.0, 0.0), (1.0, 1.15)],
        STICK_FILL.mix(0.5).filled(),
    )))?;
    chart.draw_series(std::iter::once(Text::new(
        "stick",
        (s, 1.08),
        text(NOTE, BLUE_, HPos::Center, VPos::Center),
    )))?;
    chart.draw_series(std::iter::once(Text::new(
        "slip",
        (s - 1.0, 1.08),
        text(NOTE, VERMILION, HPos::Center, VPos::Center),
    )))?;
    let full = GREY.stroke_width(2);
    chart
        .draw_series(DashedLineSeries::new(
            traction.iter().map(|&(y, _, p)| (y, p)),
            10,
            6,
            full,
        ))?
        .label("full slip: μ p (eq 7)")
        .legend(legend_dashed(full));
    let x_style = BLUE_.stroke_width(3);
    chart
        .draw_series(LineSeries::new(
            traction.iter().map(|&(y, x, _)| (y, x)),
            x_style,
        ))?
        .label("X (eq 11)")
        .legend(legend_line(x_style));
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerMiddle)
        .margin(8)
        .legend_area_size(36)
        .background_style(WHITE)
        .border_style(GREY)
        .label_font((FONT, NOTE))
        .draw()?;
    Ok(())
}

/// Fig. 3: mu^3 P0* versus theta, log-log.
pub fn fig3() -> Res<String> {
    let data = fig3_data(&theta_grid(THETA_POINTS));
    render(|root| {
        let mut chart = ChartBuilder::on(root)
            .caption(
                "Fig. 3 (paper, eq 18): critical load μ³P₀* = (π m n θ)³/48",
                (FONT, TITLE),
            )
            .margin(18)
            .x_label_area_size(62)
            .y_label_area_size(90)
            .build_cartesian_2d(log_axis(-6, -1), log_axis(-13, -1))?;
        chart
            .configure_mesh()
            .x_desc("auxiliary angle θ (rad), eq (4); θ = φ for equal radii")
            .y_desc("μ³ P₀* (dimensionless; P* of eq 17)")
            .x_label_formatter(&power_of_ten)
            .y_label_formatter(&power_of_ten)
            .axis_desc_style((FONT, DESC))
            .label_style((FONT, LABEL))
            .light_line_style(WHITE)
            .bold_line_style(LIGHT)
            .draw()?;
        let style = BLUE_.stroke_width(3);
        chart
            .draw_series(LineSeries::new(data.iter().copied(), style))?
            .label("μ³P₀*: load at which d/b = 1 (complete microslip)")
            .legend(legend_line(style));
        chart.draw_series([
            Text::new(
                "μ³P* above the curve: a stick zone, d/b = (P₀*/P*)^(1/3) < 1 (eq 19)",
                (1.5e-6, 1e-3),
                text(NOTE, BLACK, HPos::Left, VPos::Center),
            ),
            Text::new(
                "μ³P* below: slip everywhere (d/b ≥ 1)",
                (2e-3, 1e-10),
                text(NOTE, BLACK, HPos::Center, VPos::Center),
            ),
        ])?;
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .margin(12)
            .legend_area_size(40)
            .background_style(WHITE)
            .border_style(GREY)
            .label_font((FONT, LABEL))
            .draw()?;
        Ok(())
    })
}

/// Fig. 4: F/(mu P) versus d/b, ellipse (eq 21) and line contact (eq 27).
pub fn fig4() -> Res<String> {
    let data = fig4_data(50);
    render(|root| {
        let mut chart = ChartBuilder::on(root)
            .caption(
                "Fig. 4 (paper, eq 21): axial force F/(μP) versus slip ratio d/b",
                (FONT, TITLE),
            )
            .margin(18)
            .x_label_area_size(62)
            .y_label_area_size(80)
            .build_cartesian_2d(0.0..1.2, 0.0..1.1)?;
        chart
            .configure_mesh()
            .x_desc("slip ratio d/b (dimensionless), eqs (15)-(16)")
            .y_desc("F/(μP) (dimensionless)")
            .x_label_formatter(&one_decimal)
            .y_label_formatter(&one_decimal)
            .axis_desc_style((FONT, DESC))
            .label_style((FONT, LABEL))
            .light_line_style(WHITE)
            .bold_line_style(LIGHT)
            .draw()?;
        chart.draw_series(DashedLineSeries::new(
            [(1.0, 0.0), (1.0, 1.1)],
            4,
            5,
            GREY.stroke_width(2),
        ))?;
        chart.draw_series([
            Text::new(
                "d/b ≥ 1:",
                (1.1, 0.93),
                text(NOTE, GREY, HPos::Center, VPos::Center),
            ),
            Text::new(
                "F = μP",
                (1.1, 0.88),
                text(NOTE, GREY, HPos::Center, VPos::Center),
            ),
        ])?;
        let ell = BLUE_.stroke_width(3);
        chart
            .draw_series(LineSeries::new(data.iter().map(|&(s, f, _)| (s, f)), ell))?
            .label("contact ellipse, eq (21)")
            .legend(legend_line(ell));
        let strip = VERMILION.stroke_width(3);
        chart
            .draw_series(DashedLineSeries::new(
                data.iter().map(|&(s, _, l)| (s, l)),
                12,
                6,
                strip,
            ))?
            .label("line contact, 2(d/b) − (d/b)², eq (27)")
            .legend(legend_dashed(strip));
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .margin(16)
            .legend_area_size(40)
            .background_style(WHITE)
            .border_style(GREY)
            .label_font((FONT, LABEL))
            .draw()?;
        Ok(())
    })
}

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
/// (columns in any order) whose operation is `estimate` or starts with `table:` or
/// `kernel:`. Rows with an empty instruction count or error are left out.
///
/// # Errors
/// A missing column, a quoted field or a number that does not parse.
pub fn parse_bench_csv(csv: &str) -> Res<Vec<BenchRow>> {
    let mut lines = csv
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let (_, header) = lines.next().ok_or("bench CSV is empty")?;
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let column = |name: &str| {
        names
            .iter()
            .position(|n| *n == name)
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
    for (index, line) in lines {
        if line.contains('"') {
            return Err(format!("bench CSV line {}: quoted fields", index + 1).into());
        }
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        let field = |c: usize| {
            fields
                .get(c)
                .copied()
                .ok_or_else(|| format!("bench CSV line {}: too few fields", index + 1))
        };
        let operation = field(cols[2])?;
        if !(operation == "estimate"
            || operation.starts_with("table:")
            || operation.starts_with("kernel:"))
        {
            continue;
        }
        let (instr, err) = (field(cols[3])?, field(cols[4])?);
        if instr.is_empty() || err.is_empty() {
            continue;
        }
        let number = |s: &str| {
            s.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && *v >= 0.0)
                .ok_or_else(|| format!("bench CSV line {}: bad number `{s}`", index + 1))
        };
        rows.push(BenchRow {
            cpu: field(cols[0])?.to_string(),
            model: field(cols[1])?.to_string(),
            operation: operation.to_string(),
            instructions: number(instr)?,
            error: number(err)?,
        });
    }
    Ok(rows)
}

/// `cortex-m4f` -> `m4f`.
fn short_cpu(cpu: &str) -> &str {
    cpu.strip_prefix("cortex-").unwrap_or(cpu)
}

/// The speed-against-error figure of `csv` (the benchmark's output) as SVG.
///
/// # Errors
/// As [`parse_bench_csv`], or when no row has instructions > 0.
pub fn speed_vs_error_svg(csv: &str) -> Res<String> {
    let rows = parse_bench_csv(csv)?;
    let rows: Vec<BenchRow> = rows.into_iter().filter(|r| r.instructions > 0.0).collect();
    if rows.is_empty() {
        return Err("bench CSV has no estimate, table: or kernel: row to plot".into());
    }
    // An error of exactly 0 (the reference against itself) is drawn on a dashed
    // line one decade below the smallest non-zero error, which says so.
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
    let y_of = |r: &BenchRow| r.error.max(floor);
    // Whole decades around the data: (floor(log10 min), ceil(log10 max)), at least one.
    let decades = |values: &mut dyn Iterator<Item = f64>| {
        let (lo, hi) = values.fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
        let (lo, hi) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
        (lo, hi.max(lo + 1))
    };
    // Three times the largest count leaves room for the labels right of the points.
    let (x_lo, _) = decades(&mut rows.iter().map(|r| r.instructions));
    let (_, x_hi) = decades(&mut rows.iter().map(|r| r.instructions * 3.0));
    let (y_lo, y_hi) = decades(&mut rows.iter().map(y_of));
    let has_zero = rows.iter().any(|r| r.error == 0.0);
    let y_lo = y_lo - i32::from(has_zero);

    // Models in a fixed order, then any other in sorted order.
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

    render(|root| {
        let mut chart = ChartBuilder::on(root)
            .caption(
                "Speed against error: one estimate (d/b, regime, F, φ₀) per CPU and model",
                (FONT, 23),
            )
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

/// Estimated width (px) of `s` in the figure font at plotters size `size`: about
/// 0.56 em per character (SVG text is laid out by the viewer, not here).
fn text_width(s: &str, size: u32) -> i32 {
    (s.chars().count() as f64 * 0.56 * f64::from(size) / 1.24).round() as i32
}

/// Greedy placement of point labels: each label takes the first of a few positions
/// around its point that overlaps no marker and no label placed before it, so that
/// close points (two CPUs at similar counts) stay readable.
struct Labels {
    area: [i32; 4],
    taken: Vec<[i32; 4]>,
}

impl Labels {
    fn new(area: [i32; 4]) -> Self {
        Self {
            area,
            taken: Vec::new(),
        }
    }

    /// A marker of half-size `r` at `at`.
    fn mark(&mut self, at: (i32, i32), r: i32) {
        self.taken.push([at.0 - r, at.1 - r, at.0 + r, at.1 + r]);
    }

    fn free(&self, b: [i32; 4]) -> bool {
        let [x0, y0, x1, y1] = self.area;
        b[0] >= x0
            && b[2] <= x1
            && b[1] >= y0
            && b[3] <= y1
            && self
                .taken
                .iter()
                .all(|t| b[2] <= t[0] || t[2] <= b[0] || b[3] <= t[1] || t[3] <= b[1])
    }

    /// Where to draw `label` for the point at `at`: anchor and position.
    fn place(&mut self, at: (i32, i32), label: &str, size: u32) -> (HPos, VPos, (i32, i32)) {
        let (w, h) = (
            text_width(label, size),
            (f64::from(size) / 1.24).round() as i32,
        );
        let (x, y) = at;
        let d = 10;
        let candidates = [
            (HPos::Left, VPos::Center, (x + d, y)),
            (HPos::Right, VPos::Center, (x - d, y)),
            (HPos::Center, VPos::Bottom, (x, y - d)),
            (HPos::Center, VPos::Top, (x, y + d)),
            (HPos::Left, VPos::Center, (x + d, y - h - 2)),
            (HPos::Left, VPos::Center, (x + d, y + h + 2)),
            (HPos::Right, VPos::Center, (x - d, y - h - 2)),
            (HPos::Right, VPos::Center, (x - d, y + h + 2)),
        ];
        let bbox = |(hp, vp, (px, py)): (HPos, VPos, (i32, i32))| {
            let x0 = match hp {
                HPos::Left => px,
                HPos::Center => px - w / 2,
                HPos::Right => px - w,
            };
            let y0 = match vp {
                VPos::Top => py,
                VPos::Center => py - h / 2,
                VPos::Bottom => py - h,
            };
            [x0, y0, x0 + w, y0 + h]
        };
        let choice = candidates
            .iter()
            .copied()
            .find(|c| self.free(bbox(*c)))
            .unwrap_or(candidates[0]);
        self.taken.push(bbox(choice));
        choice
    }

    /// The corner of the plotting area whose `(w, h)` box covers the fewest markers
    /// and labels (upper right first on ties).
    fn emptiest_corner(&self, (w, h): (i32, i32)) -> SeriesLabelPosition {
        let [x0, y0, x1, y1] = self.area;
        let corners = [
            (SeriesLabelPosition::UpperRight, [x1 - w, y0, x1, y0 + h]),
            (SeriesLabelPosition::UpperLeft, [x0, y0, x0 + w, y0 + h]),
            (SeriesLabelPosition::LowerRight, [x1 - w, y1 - h, x1, y1]),
            (SeriesLabelPosition::LowerLeft, [x0, y1 - h, x0 + w, y1]),
        ];
        let hits = |b: &[i32; 4]| {
            self.taken
                .iter()
                .filter(|t| !(b[2] <= t[0] || t[2] <= b[0] || b[3] <= t[1] || t[3] <= b[1]))
                .count()
        };
        corners
            .into_iter()
            .min_by_key(|(_, b)| hits(b))
            .map_or(SeriesLabelPosition::UpperRight, |(p, _)| p)
    }
}

/// Reads the benchmark's CSV at `csv_path` and writes the speed-against-error figure
/// to `svg_path`.
///
/// # Errors
/// An unreadable CSV, as [`speed_vs_error_svg`], or an unwritable SVG.
pub fn speed_vs_error(csv_path: &Path, svg_path: &Path) -> Res<()> {
    let csv = std::fs::read_to_string(csv_path)
        .map_err(|e| format!("read {}: {e}", csv_path.display()))?;
    let svg = speed_vs_error_svg(&csv)?;
    std::fs::write(svg_path, svg).map_err(|e| format!("write {}: {e}", svg_path.display()))?;
    Ok(())
}

/// The paper's figures, in order: `fig1.svg` ... `fig4.svg`.
///
/// # Errors
/// A drawing error from plotters.
pub fn paper_figures() -> Res<Vec<Figure>> {
    Ok(vec![
        ("fig1.svg", fig1()?),
        ("fig2.svg", fig2()?),
        ("fig3.svg", fig3()?),
        ("fig4.svg", fig4()?),
    ])
}

/// Name of the benchmark's CSV and of its figure under `docs/`.
const BENCH_CSV: &str = "bench.csv";
const SPEED_SVG: &str = "speed-vs-error.svg";

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

fn run_inner(docs: &Path, check: bool) -> Res<bool> {
    // `xtask/../docs` reads better as the absolute folder.
    let docs = &docs
        .parent()
        .and_then(|p| p.canonicalize().ok())
        .zip(docs.file_name())
        .map_or_else(|| docs.to_path_buf(), |(p, name)| p.join(name));
    let mut figures = paper_figures()?;
    let csv = docs.join(BENCH_CSV);
    if csv.exists() {
        if check {
            let text = std::fs::read_to_string(&csv)?;
            figures.push((SPEED_SVG, speed_vs_error_svg(&text)?));
        } else {
            std::fs::create_dir_all(docs)?;
            speed_vs_error(&csv, &docs.join(SPEED_SVG))?;
            println!("wrote {}", docs.join(SPEED_SVG).display());
        }
    } else {
        println!(
            "skipped {SPEED_SVG}: no {} (run the benchmark)",
            csv.display()
        );
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

    fn finite3(v: &[(f64, f64, f64)]) -> bool {
        v.iter()
            .all(|p| p.0.is_finite() && p.1.is_finite() && p.2.is_finite())
    }

    #[test]
    fn fig1_m_falls_and_n_rises_with_theta() {
        // Denser than the drawn curve (THETA_POINTS), to catch a wiggle between points.
        let d = fig1_data(&theta_grid(2001));
        assert_eq!((d[0].0, d[d.len() - 1].0), THETA_RANGE);
        assert!(finite3(&d));
        for w in d.windows(2) {
            assert!(w[1].0 > w[0].0, "theta increasing");
            assert!(w[1].1 < w[0].1, "m decreasing at theta = {}", w[1].0);
            assert!(w[1].2 > w[0].2, "n increasing at theta = {}", w[1].0);
        }
        // Inside the plotted range: m from about 3.5e4 down to 11, n from 4e-3 to 0.25.
        assert!(
            d.iter()
                .all(|&(_, m, n)| (1e-3..1e5).contains(&m) && (1e-3..1e5).contains(&n))
        );
    }

    #[test]
    fn fig1_matches_the_50_digit_reference_row() {
        // vectors_mn.csv, row theta = 9.987598927208069e-7.
        let s = normal::ellipse_shape(9.987598927208069e-7).unwrap();
        assert!((s.m / 3.4646534521276975e4 - 1.0).abs() < 1e-13, "{}", s.m);
        assert!((s.n / 4.28657237516558e-3 - 1.0).abs() < 1e-13, "{}", s.n);
    }

    #[test]
    fn fig2_case_has_half_the_width_slipping() {
        let case = fig2_case();
        let e = &case.contact;
        assert!(
            (e.slip_ratio - FIG2_SLIP_RATIO).abs() < 1e-12,
            "{}",
            e.slip_ratio
        );
        assert!(e.phi > 0.0 && e.phi < case.phi0);
        // Eq (19): d/b = (P0*/P*)^(1/3).
        assert!(((e.p0star / e.pstar).cbrt() - e.slip_ratio).abs() < 1e-12);
        let zone = fig2_stick_zone(&case);
        assert!(finite3(&zone));
        let s = e.d / e.b;
        for &(x, lo, hi) in &zone {
            let c = (1.0 - x * x).max(0.0).sqrt();
            // Inside the ellipse, a reflection of the leading edge about y = d.
            assert!(lo <= hi && hi <= c + 1e-12 && lo >= -c - 1e-12);
            assert!(((lo + hi) / 2.0 - s).abs() < 1e-12);
        }
        // Widest at x = 0: y/b from 2 d/b - 1 = 0 to 1.
        let mid = zone[zone.len() / 2];
        assert!(mid.0.abs() < 1e-12 && mid.1.abs() < 1e-12 && (mid.2 - 1.0).abs() < 1e-12);
    }

    #[test]
    fn fig2_traction_is_full_slip_outside_the_stick_zone_and_below_it_inside() {
        let case = fig2_case();
        let t = fig2_traction(&case);
        assert!(finite3(&t));
        let s = case.contact.slip_ratio;
        for &(y, x, p) in &t {
            assert!(x >= -1e-12 && x <= p + 1e-12, "0 <= X <= mu p at y/b = {y}");
            if y < 2.0 * s - 1.0 - 1e-9 {
                assert!((x - p).abs() < 1e-12, "slip zone: X = mu p at y/b = {y}");
            }
            if (y - s).abs() < 1e-12 {
                // Eq (11b) at the stick zone's centre: sqrt(1 - s^2) - (1 - s).
                assert!((x - ((1.0 - s * s).sqrt() - (1.0 - s))).abs() < 1e-12);
            }
        }
        assert_eq!(
            (t[0].1, t[t.len() - 1].1),
            (0.0, 0.0),
            "no traction at the edges"
        );
    }

    #[test]
    fn fig3_critical_load_rises_with_theta() {
        let d = fig3_data(&theta_grid(2001));
        assert!(
            d.iter()
                .all(|&(t, v)| t.is_finite() && v.is_finite() && v > 0.0)
        );
        assert!(d.windows(2).all(|w| w[1].1 > w[0].1));
        // The same as the reference's P0* with mu = 1, and inside the plotted range.
        for &(t, v) in &d {
            let g = normal::ellipse_shape(t).unwrap().g();
            let r = tangential::critical_nondimensional_load(g, 1.0);
            assert!((v / r - 1.0).abs() < 1e-14);
            assert!((1e-13..1e-1).contains(&v));
        }
    }

    #[test]
    fn fig4_force_rises_to_one_and_stays() {
        let d = fig4_data(1000);
        assert_eq!(d.len(), 1201);
        assert!(finite3(&d));
        assert_eq!(d[0], (0.0, 0.0, 0.0));
        let at_one = d
            .iter()
            .find(|p| p.0 == 1.0)
            .expect("d/b = 1 is on the grid");
        assert_eq!((at_one.1, at_one.2), (1.0, 1.0));
        for w in d.windows(2) {
            if w[1].0 <= 1.0 {
                assert!(w[1].1 > w[0].1 && w[1].2 > w[0].2, "increasing to d/b = 1");
            } else {
                assert_eq!((w[1].1, w[1].2), (1.0, 1.0), "saturated beyond d/b = 1");
            }
            // The ellipse builds its force faster: slope 3 pi/4 against 2 at d/b = 0.
            if w[1].0 < 1.0 {
                assert!(w[1].1 > w[1].2);
            }
        }
    }

    #[test]
    fn power_of_ten_labels() {
        assert_eq!(power_of_ten(&1e-6), "10⁻⁶");
        assert_eq!(power_of_ten(&1e5), "10⁵");
        assert_eq!(power_of_ten(&1.0), "10⁰");
        assert_eq!(power_of_ten(&2e-3), "2e-3");
    }

    #[test]
    fn figures_are_deterministic_svg() {
        let a = paper_figures().unwrap();
        let b = paper_figures().unwrap();
        assert_eq!(a, b);
        for (name, svg) in &a {
            assert!(
                svg.starts_with("<svg width=\"800\" height=\"600\""),
                "{name}"
            );
            assert!(svg.trim_end().ends_with("</svg>"), "{name}");
            assert!(svg.contains("Fig. "), "{name} has a title citing the paper");
        }
    }

    /// The committed SVGs are what the reference draws today (as `--check`).
    #[test]
    fn committed_figures_match_the_reference() {
        let docs = crate::root().join("docs");
        for (name, svg) in paper_figures().unwrap() {
            let committed = std::fs::read_to_string(docs.join(name)).unwrap_or_default();
            assert!(
                committed == svg,
                "docs/{name} drifted from the reference: run `cargo xtask figures`"
            );
        }
    }

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
        let (csv, svg) = (dir.join("bench.csv"), dir.join("speed.svg"));
        std::fs::write(&csv, SAMPLE).unwrap();
        speed_vs_error(&csv, &svg).unwrap();
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
        assert_eq!(out, speed_vs_error_svg(SAMPLE).unwrap(), "deterministic");
        assert!(speed_vs_error(&dir.join("missing.csv"), &svg).is_err());
    }
}
