//! The paper's Figs 1-4, redrawn from the f64 reference (`misalign::reference`).

use super::{
    Area, BLUE_, DESC, FONT, GREY, LABEL, LIGHT, NOTE, Res, SLIP_FILL, STICK_FILL, TITLE,
    VERMILION, captioned, legend_dashed, legend_line, log_axis, one_decimal, power_of_ten, render,
    sig3, text, y_title,
};
use misalign::Scene;
use misalign::reference::{self, Elliptic, line, normal, tangential};
use plotters::coord::ranged1d::ValueFormatter;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

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
    let scene = Scene::DEMO;
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

/// A chart of the paper's figures: f64 on both axes.
type Chart<'a, 'b, X, Y> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>;

/// Two curves of `data` `(x, y1, y2)`: y1 solid blue, y2 dashed vermilion, each with
/// its legend entry.
fn solid_and_dashed<X, Y>(
    chart: &mut Chart<'_, '_, X, Y>,
    data: &[(f64, f64, f64)],
    solid: &str,
    dashed: &str,
) -> Res<()>
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let style = BLUE_.stroke_width(3);
    chart
        .draw_series(LineSeries::new(data.iter().map(|&(x, y, _)| (x, y)), style))?
        .label(solid)
        .legend(legend_line(style));
    let style = VERMILION.stroke_width(3);
    chart
        .draw_series(DashedLineSeries::new(
            data.iter().map(|&(x, _, y)| (x, y)),
            12,
            6,
            style,
        ))?
        .label(dashed)
        .legend(legend_dashed(style));
    Ok(())
}

/// An axis: its description and its labels' format.
type Axis<'a> = (&'a str, &'a dyn Fn(&f64) -> String);

/// The grid, the axes' descriptions and labels, in the figure font.
fn mesh<X, Y>(chart: &mut Chart<'_, '_, X, Y>, x: Axis, y: Axis) -> Res<()>
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    chart
        .configure_mesh()
        .x_desc(x.0)
        .x_label_formatter(x.1)
        .y_label_formatter(y.1)
        .axis_desc_style((FONT, DESC))
        .label_style((FONT, LABEL))
        .max_light_lines(0)
        .bold_line_style(LIGHT)
        .draw()?;
    y_title(chart, y.0, DESC)
}

/// The legend box at `at`, `margin` px from the plot's edge.
fn legend<'a, 'b: 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, SVGBackend<'b>, CT>,
    at: SeriesLabelPosition,
    margin: u32,
) -> Res<()> {
    chart
        .configure_series_labels()
        .position(at)
        .margin(margin)
        .legend_area_size(40)
        .background_style(WHITE)
        .border_style(GREY)
        .label_font((FONT, LABEL))
        .draw()?;
    Ok(())
}

/// Fig. 1: m and n versus theta, log-log.
pub fn fig1() -> Res<String> {
    let data = fig1_data(&theta_grid(THETA_POINTS));
    render(|root| {
        let body = captioned(
            root,
            "Fig. 1 (paper, eqs 5-6): ellipse coefficients m, n at small θ",
            TITLE,
            18,
        )?;
        let mut chart = ChartBuilder::on(&body)
            .margin(18)
            .margin_top(0)
            .x_label_area_size(62)
            .y_label_area_size(90)
            .build_cartesian_2d(log_axis(-6, -1), log_axis(-3, 5))?;
        mesh(
            &mut chart,
            (
                "auxiliary angle θ (rad), eq (4); θ = φ for equal radii",
                &power_of_ten,
            ),
            ("m, n (dimensionless): a = m L, b = n L", &power_of_ten),
        )?;
        solid_and_dashed(
            &mut chart,
            &data,
            "m: semi-axis a along the rollers",
            "n: semi-axis b across (rolling direction)",
        )?;
        legend(&mut chart, SeriesLabelPosition::UpperRight, 12)?;
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
    let body = captioned(area, "(a) stick and slip zones", DESC, 10)?;
    let mut chart = ChartBuilder::on(&body)
        .margin(10)
        .margin_top(0)
        .x_label_area_size(56)
        .y_label_area_size(62)
        .build_cartesian_2d(-1.3..1.3, -1.3..1.3)?;
    chart
        .configure_mesh()
        .x_desc("x/a (along the rollers; dimensionless)")
        .x_label_formatter(&one_decimal)
        .y_label_formatter(&one_decimal)
        .x_labels(6)
        .axis_desc_style((FONT, LABEL))
        .label_style((FONT, NOTE))
        .disable_mesh()
        .draw()?;
    y_title(&chart, "y/b (rolling direction; dimensionless)", LABEL)?;
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
    let body = captioned(area, "(b) axial traction X at x = 0", DESC, 10)?;
    let mut chart = ChartBuilder::on(&body)
        .margin(10)
        .margin_top(0)
        .x_label_area_size(56)
        .y_label_area_size(62)
        .build_cartesian_2d(-1.05..1.05, 0.0..1.15)?;
    chart
        .configure_mesh()
        .x_desc("y/b (rolling direction; dimensionless)")
        .x_label_formatter(&one_decimal)
        .y_label_formatter(&one_decimal)
        .x_labels(6)
        .axis_desc_style((FONT, LABEL))
        .label_style((FONT, NOTE))
        .max_light_lines(0)
        .bold_line_style(LIGHT)
        .draw()?;
    y_title(&chart, "X / (μ p₀) (dimensionless)", LABEL)?;
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
        let body = captioned(
            root,
            "Fig. 3 (paper, eq 18): critical load μ³P₀* = (π m n θ)³/48",
            TITLE,
            18,
        )?;
        let mut chart = ChartBuilder::on(&body)
            .margin(18)
            .margin_top(0)
            .x_label_area_size(62)
            .y_label_area_size(90)
            .build_cartesian_2d(log_axis(-6, -1), log_axis(-13, -1))?;
        mesh(
            &mut chart,
            (
                "auxiliary angle θ (rad), eq (4); θ = φ for equal radii",
                &power_of_ten,
            ),
            ("μ³ P₀* (dimensionless; P* of eq 17)", &power_of_ten),
        )?;
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
        legend(&mut chart, SeriesLabelPosition::UpperLeft, 12)?;
        Ok(())
    })
}

/// Fig. 4: F/(mu P) versus d/b, ellipse (eq 21) and line contact (eq 27).
pub fn fig4() -> Res<String> {
    let data = fig4_data(50);
    render(|root| {
        let body = captioned(
            root,
            "Fig. 4 (paper, eq 21): axial force F/(μP) versus slip ratio d/b",
            TITLE,
            18,
        )?;
        let mut chart = ChartBuilder::on(&body)
            .margin(18)
            .margin_top(0)
            .x_label_area_size(62)
            .y_label_area_size(80)
            .build_cartesian_2d(0.0..1.2, 0.0..1.1)?;
        mesh(
            &mut chart,
            (
                "slip ratio d/b (dimensionless), eqs (15)-(16)",
                &one_decimal,
            ),
            ("F/(μP) (dimensionless)", &one_decimal),
        )?;
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
        solid_and_dashed(
            &mut chart,
            &data,
            "contact ellipse, eq (21)",
            "line contact, 2(d/b) − (d/b)², eq (27)",
        )?;
        legend(&mut chart, SeriesLabelPosition::LowerRight, 16)?;
        Ok(())
    })
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
}
