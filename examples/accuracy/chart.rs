//! The chart: one log–log panel per problem (relative error against time per step), one
//! marker series per integrator (or strain model), substeps labelled, the Pareto front drawn.

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::problems::Problem;

const SERIES: [(&str, RGBColor); 15] = [
    ("explicit_euler", RGBColor(214, 39, 40)),
    ("symplectic_euler", RGBColor(31, 119, 180)),
    ("velocity_verlet", RGBColor(44, 160, 44)),
    ("rk4", RGBColor(148, 103, 189)),
    ("implicit_euler", RGBColor(255, 127, 14)),
    ("symplectic_euler+automatic", RGBColor(184, 134, 11)),
    ("symplectic_euler+bdf2", RGBColor(0, 0, 139)),
    ("symplectic_euler+backward_euler", RGBColor(255, 187, 120)),
    ("Green", RGBColor(23, 190, 207)),
    ("Cauchy", RGBColor(188, 189, 34)),
    ("Corotated", RGBColor(140, 86, 75)),
    ("StableNeoHookean", RGBColor(227, 119, 194)),
    ("Splitting", RGBColor(0, 128, 128)),
    ("ExpMap", RGBColor(127, 127, 127)),
    ("FirstOrder", RGBColor(0, 0, 0)),
];

/// The 1 %, 0.1 % and 0.01 % lines.
const TOLERANCE: RGBColor = RGBColor(230, 150, 150);

fn colour(series: &str) -> RGBColor {
    SERIES
        .iter()
        .find(|(n, _)| *n == series)
        .map_or(BLACK, |(_, c)| *c)
}

type DrawResult = Result<(), String>;

fn err<E: std::fmt::Debug>(e: E) -> String {
    format!("{e:?}")
}

/// Draws every panel and the legend on `root`.
pub fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, problems: &[Problem]) -> DrawResult {
    root.fill(&WHITE).map_err(err)?;
    let (title, body) = root.split_vertically(56);
    title
        .draw(&Text::new(
            "hooke: what accuracy costs in time (relative error vs wall-clock time per 1/60 s step, 2-core machine, release)",
            (20, 16),
            ("sans-serif", 24).into_font().color(&BLACK),
        ))
        .map_err(err)?;
    let cols = 4;
    let rows = (problems.len() + 1).div_ceil(cols);
    let panels = body.split_evenly((rows, cols));
    for (p, area) in problems.iter().zip(&panels) {
        panel(area, p)?;
    }
    if let Some(area) = panels.get(problems.len()) {
        legend(area)?;
    }
    root.present().map_err(err)
}

fn panel<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, p: &Problem) -> DrawResult {
    let points: Vec<(f64, f64, String, String)> = (0..p.report.measurements.len())
        .filter_map(|i| {
            let m = &p.report.measurements[i];
            let (series, label) = p.naming(i);
            let rel = p.relative(m);
            // An error below f32 rounding (or exactly zero) is drawn at the floor.
            (rel.is_finite()).then(|| (m.seconds_per_step * 1e6, rel.max(1e-7), series, label))
        })
        .collect();
    let diverged = p.report.measurements.len() - points.len();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (x, y, _, _) in &points {
        (x0, x1, y0, y1) = (x0.min(*x), x1.max(*x), y0.min(*y), y1.max(*y));
    }
    if points.is_empty() {
        (x0, x1, y0, y1) = (1.0, 10.0, 1e-3, 1.0);
    }
    let caption = if diverged > 0 {
        format!("{} ({diverged} settings diverged, not drawn)", p.name)
    } else {
        p.name.to_string()
    };
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 15))
        .margin(8)
        .x_label_area_size(34)
        .y_label_area_size(58)
        .build_cartesian_2d(
            (x0 / 1.6..x1 * 1.6).log_scale(),
            (y0 / 4.0..(y1 * 4.0).min(1e3)).log_scale(),
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("time per step (µs)")
        .y_desc("relative error")
        .x_labels(8)
        .y_labels(8)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .label_style(("sans-serif", 11))
        .axis_desc_style(("sans-serif", 12))
        .disable_mesh()
        .draw()
        .map_err(err)?;
    // The 1 %, 0.1 % and 0.01 % lines.
    for tol in [1e-2, 1e-3, 1e-4] {
        if tol > y0 / 4.0 && tol < y1 * 4.0 {
            chart
                .draw_series(LineSeries::new(
                    [(x0 / 1.6, tol), (x1 * 1.6, tol)],
                    TOLERANCE.stroke_width(1),
                ))
                .map_err(err)?;
        }
    }
    // The Pareto front: no other point is both faster and more accurate.
    let mut sorted = points.clone();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut front: Vec<(f64, f64)> = Vec::new();
    for (x, y, _, _) in &sorted {
        if front.last().is_none_or(|last| *y < last.1) {
            front.push((*x, *y));
        }
    }
    chart
        .draw_series(LineSeries::new(front, BLACK.stroke_width(2)))
        .map_err(err)?;
    for (x, y, series, label) in &points {
        let c = colour(series);
        chart
            .draw_series(std::iter::once(
                EmptyElement::at((*x, *y))
                    + Circle::new((0, 0), 4, c.filled())
                    + Text::new(
                        label.clone(),
                        (5, -12),
                        ("sans-serif", 10).into_font().color(&c),
                    ),
            ))
            .map_err(err)?;
    }
    Ok(())
}

fn legend<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>) -> DrawResult {
    let font = ("sans-serif", 14).into_font();
    area.draw(&Text::new(
        "Legend",
        (20, 16),
        ("sans-serif", 16).into_font(),
    ))
    .map_err(err)?;
    // Left column: the marker series.
    let mut y = 42;
    for (name, c) in SERIES {
        area.draw(&Circle::new((28, y + 7), 5, c.filled()))
            .map_err(err)?;
        // The policy's series by what they are (their keys name the dial's integrator too).
        let shown = match name {
            "symplectic_euler+automatic" => "rescue: automatic (default)",
            "symplectic_euler+bdf2" => "rescue: BDF2",
            "symplectic_euler+backward_euler" => "rescue: backward Euler",
            other => other,
        };
        area.draw(&Text::new(shown, (42, y), font.clone()))
            .map_err(err)?;
        y += 20;
    }
    // Right column: the lines and how to read the labels.
    let (x, mut y) = (215, 42);
    area.draw(&PathElement::new(
        vec![(x, y + 7), (x + 18, y + 7)],
        BLACK.stroke_width(2),
    ))
    .map_err(err)?;
    area.draw(&Text::new("Pareto front", (x + 24, y), font.clone()))
        .map_err(err)?;
    y += 20;
    area.draw(&PathElement::new(
        vec![(x, y + 7), (x + 18, y + 7)],
        TOLERANCE.stroke_width(1),
    ))
    .map_err(err)?;
    area.draw(&Text::new("1 %, 0.1 %, 0.01 %", (x + 24, y), font.clone()))
        .map_err(err)?;
    y += 30;
    for line in [
        "Pareto front: the cheapest",
        "setting for its error.",
        "Labels: substeps per step",
        "(×1 … ×8).",
        "FEM panel: mesh cells;",
        "time of one static solve.",
        "Orientation panel:",
        "SE symplectic Euler,",
        "VV velocity Verlet;",
        "Splitting is the default.",
        "rescue: symplectic Euler,",
        "what is past its limit",
        "rescued by the policy;",
        "automatic: local substeps",
        "or BDF2, the cheaper.",
        "Diverged settings are",
        "counted in the panel title.",
    ] {
        area.draw(&Text::new(line, (x, y), ("sans-serif", 12).into_font()))
            .map_err(err)?;
        y += 17;
    }
    Ok(())
}
