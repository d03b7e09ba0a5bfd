//! The charts of `cargo xtask bench` (plotters, SVG): speed against accuracy in two panels (the
//! reduced variants against the paper and the physical reading, with the shipped monitor's
//! point) and the stability map. Axes in engineering notation; point labels only as numbers
//! that are drawn where they do not collide, with the full names in a key beside the panels.

use super::work_precision::{decades, eng, eng_unit};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// One cell of the stability map: method, parameter, scale, step (µs), verdict.
pub type StabCell = (&'static str, &'static str, f64, f64, &'static str);

/// One panel of the speed–accuracy chart.
pub struct Panel<'a> {
    /// Panel title (the reference).
    pub title: &'a str,
    /// `(M3 instructions per simulated second, braking-torque RMS (N·m), label)`.
    pub pts: &'a [(f64, f64, String)],
    /// Indices of the Pareto front in `pts`.
    pub front: &'a [usize],
    /// The shipped monitor's braking-torque RMS against this reading (N·m).
    pub monitor_err: f64,
}

/// Indices of the Pareto-optimal points (lower cost and lower error both better).
pub fn pareto(points: &[(f64, f64)]) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..points.len()).collect();
    idx.sort_by(|&a, &b| {
        let (pa, pb) = (points.get(a), points.get(b));
        pa.map(|p| p.0)
            .unwrap_or(f64::MAX)
            .total_cmp(&pb.map(|p| p.0).unwrap_or(f64::MAX))
    });
    let mut best = f64::INFINITY;
    let mut front = Vec::new();
    for i in idx {
        if let Some(&(_, e)) = points.get(i) {
            if e < best {
                best = e;
                front.push(i);
            }
        }
    }
    front
}

fn err<E: std::fmt::Debug>(x: E) -> String {
    format!("chart: {x:?}")
}

/// Speed against accuracy, two panels side by side and a key of the Pareto points.
pub fn speed_accuracy(
    path: &Path,
    panels: [Panel<'_>; 2],
    monitor_per_s: f64,
) -> Result<(), String> {
    let root = SVGBackend::new(path, (1400, 660)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let root = root
        .titled(
            "reverse_load: braking-torque RMS error vs Cortex-M3 instructions per simulated second",
            ("sans-serif", 18),
        )
        .map_err(err)?;
    let (plots, key) = root.split_horizontally(1040);
    let areas = plots.split_evenly((1, 2));
    let mut key_lines: Vec<String> = Vec::new();
    for (k, (panel, area)) in panels.iter().zip(areas.iter()).enumerate() {
        key_lines.push(format!(
            "{} — {}",
            if k == 0 { "left" } else { "right" },
            panel.title
        ));
        draw_panel(area, panel, monitor_per_s, &mut key_lines)?;
        key_lines.push(String::new());
    }
    key.draw(&Text::new(
        "Pareto front (number: variant)",
        (4, 14),
        ("sans-serif", 13),
    ))
    .map_err(err)?;
    for (i, line) in key_lines.iter().enumerate() {
        let y = 34 + 14 * i as i32;
        key.draw(&Text::new(line.clone(), (4, y), ("sans-serif", 11)))
            .map_err(err)?;
    }
    root.present().map_err(err)?;
    Ok(())
}

fn draw_panel(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    panel: &Panel<'_>,
    monitor_per_s: f64,
    key: &mut Vec<String>,
) -> Result<(), String> {
    let (mut x0, mut x1, mut y0, mut y1) = (monitor_per_s, monitor_per_s, f64::MAX, 0.0_f64);
    for (x, y, _) in panel.pts {
        x0 = x0.min(*x);
        x1 = x1.max(*x);
        y0 = y0.min(*y);
        y1 = y1.max(*y);
    }
    let (y0, y1) = decades(
        y0.min(panel.monitor_err).max(1e-9),
        y1.max(panel.monitor_err),
    );
    let (x0, x1) = decades(x0, x1);
    let mut c = ChartBuilder::on(area)
        .caption(panel.title, ("sans-serif", 14))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(64)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(err)?;
    c.configure_mesh()
        .x_desc("M3 instructions per simulated second (QEMU -icount)")
        .y_desc("braking-torque RMS error (N·m)")
        .x_label_formatter(&|v| eng(*v))
        .y_label_formatter(&|v| eng(*v))
        .draw()
        .map_err(err)?;
    c.draw_series(
        panel
            .pts
            .iter()
            .map(|(x, y, _)| Circle::new((*x, *y), 3, BLUE.mix(0.4).filled())),
    )
    .map_err(err)?
    .label("reduced variant (format × integrator × rate)")
    .legend(|(x, y)| Circle::new((x + 8, y), 3, BLUE.mix(0.4).filled()));
    let line: Vec<(f64, f64, &str)> = panel
        .front
        .iter()
        .filter_map(|&i| panel.pts.get(i).map(|p| (p.0, p.1, p.2.as_str())))
        .collect();
    c.draw_series(LineSeries::new(
        line.iter().map(|p| (p.0, p.1)),
        RED.stroke_width(2),
    ))
    .map_err(err)?
    .label("Pareto front")
    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], RED.stroke_width(2)));
    c.draw_series(std::iter::once(TriangleMarker::new(
        (monitor_per_s, panel.monitor_err),
        8,
        GREEN.filled(),
    )))
    .map_err(err)?
    .label("shipped monitor (whole estimator, through the sensors)")
    .legend(|(x, y)| TriangleMarker::new((x + 8, y), 6, GREEN.filled()));
    // Numbers beside the front's points, skipped where they would collide with one drawn.
    let mut placed: Vec<(i32, i32)> = vec![c.backend_coord(&(monitor_per_s, panel.monitor_err))];
    for (n, (x, y, label)) in line.iter().enumerate() {
        key.push(format!(
            "{:>2}  {label}: {}, {}",
            n + 1,
            eng_unit(*x, "/s"),
            eng_unit(*y, "N·m")
        ));
        let (px, py) = c.backend_coord(&(*x, *y));
        if placed
            .iter()
            .all(|&(qx, qy)| (qx - px).abs() > 16 || (qy - py).abs() > 12)
        {
            placed.push((px, py));
            c.draw_series(std::iter::once(Text::new(
                format!("{}", n + 1),
                (*x, *y),
                ("sans-serif", 11).into_font().color(&RED),
            )))
            .map_err(err)?;
        }
    }
    c.configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(err)?;
    Ok(())
}

/// The stability map: a row per method × parameter × scale, a dot per step.
pub fn stability(path: &Path, rows: &[StabCell]) -> Result<(), String> {
    let mut lanes: Vec<(&str, &str, f64)> = Vec::new();
    for r in rows {
        if !lanes.contains(&(r.0, r.1, r.2)) {
            lanes.push((r.0, r.1, r.2));
        }
    }
    let height = 120 + 28 * lanes.len() as u32;
    let root = SVGBackend::new(path, (860, height)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let mut c = ChartBuilder::on(&root)
        .caption(
            "full physical model, fixed explicit steps: green stable, orange inaccurate, red diverged",
            ("sans-serif", 16),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(110)
        .build_cartesian_2d(
            (0.08_f64..40.0).log_scale(),
            -0.5_f64..lanes.len() as f64 - 0.5,
        )
        .map_err(err)?;
    let names: Vec<String> = lanes
        .iter()
        .map(|l| format!("{} {}×{}", l.0, l.1, l.2))
        .collect();
    c.configure_mesh()
        .x_desc("step (s)")
        .x_label_formatter(&|v| eng(*v * 1e-6))
        .y_labels(lanes.len().max(1))
        .y_label_formatter(&|v| {
            if (v - v.round()).abs() > 1e-6 || *v < 0.0 {
                return String::new();
            }
            names.get(v.round() as usize).cloned().unwrap_or_default()
        })
        .disable_y_mesh()
        .draw()
        .map_err(err)?;
    for (li, lane) in lanes.iter().enumerate() {
        let y = li as f64;
        for r in rows.iter().filter(|r| (r.0, r.1, r.2) == *lane) {
            let col = match r.4 {
                "stable" => GREEN,
                "inaccurate" => RGBColor(255, 140, 0),
                _ => RED,
            };
            c.draw_series(std::iter::once(Circle::new((r.3, y), 7, col.filled())))
                .map_err(err)?;
        }
    }
    root.present().map_err(err)?;
    Ok(())
}
