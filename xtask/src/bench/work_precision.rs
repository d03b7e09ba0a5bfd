//! Work–precision of the twin's integrator (diffsol BDF) against diffsol's SDIRK methods and scipy
//! Radau (issue 18):
//! the table (per scene, solver and tolerance: wall time, worst relative error against the
//! converged reference), the speed ratio at matched accuracy, and the chart (one panel per
//! scene, error against wall time, log–log, engineering notation).

use serde_json::Value;
use std::fmt::Write as _;
use std::path::Path;

/// Accuracy levels at which solvers are compared (worst relative error over every metric).
pub const LEVELS: [f64; 2] = [1e-2, 1e-3];
/// Errors below this are drawn at it (log axes).
const FLOOR: f64 = 1e-9;

pub use noback_twin::svg::{eng, eng_unit};

/// The log-axis range spanning whole decades around `[lo, hi]`, at least one decade wide.
pub fn decades(lo: f64, hi: f64) -> (f64, f64) {
    let a = 10f64.powf(lo.max(1e-300).log10().floor());
    let mut b = 10f64.powf(hi.max(1e-300).log10().ceil());
    if b <= a {
        b = a * 10.0;
    }
    (a, b)
}

/// One measured point.
#[derive(Clone, Debug)]
pub struct Point {
    /// Scene.
    pub scene: String,
    /// Solver name.
    pub solver: String,
    /// Tolerance.
    pub tolerance: f64,
    /// Wall time (s), best of the repeats.
    pub wall_s: f64,
    /// Worst relative error over the reference's metrics (`None`: no metric or failed).
    pub error: Option<f64>,
    /// The metric that set it.
    pub metric: String,
}

/// Points from the work-precision example's JSON lines.
pub fn parse(lines: &str) -> Vec<Point> {
    lines
        .lines()
        .filter_map(|l| serde_json::from_str::<Value>(l).ok())
        .filter_map(|v| {
            Some(Point {
                scene: v.get("scene")?.as_str()?.to_string(),
                solver: v.get("solver")?.as_str()?.to_string(),
                tolerance: v.get("tolerance")?.as_f64()?,
                wall_s: v.get("wall_s")?.as_f64()?,
                error: v.get("worst_rel_error").and_then(Value::as_f64),
                metric: v
                    .get("worst_metric")
                    .and_then(Value::as_str)
                    .unwrap_or("")
                    .to_string(),
            })
        })
        .collect()
}

/// The cheapest point of `solver` on `scene` whose worst error is at most `level` and stays
/// so at every tighter tolerance measured (a lucky loose tolerance does not count).
pub fn cheapest<'a>(pts: &'a [Point], scene: &str, solver: &str, level: f64) -> Option<&'a Point> {
    let mine: Vec<&Point> = pts
        .iter()
        .filter(|p| p.scene == scene && p.solver == solver)
        .collect();
    let ok = |p: &Point| p.error.is_some_and(|e| e <= level);
    mine.iter()
        .copied()
        .filter(|p| {
            mine.iter()
                .filter(|q| q.tolerance <= p.tolerance)
                .all(|q| ok(q))
        })
        .min_by(|a, b| a.wall_s.total_cmp(&b.wall_s))
}

fn scenes(pts: &[Point]) -> Vec<String> {
    let mut v: Vec<String> = Vec::new();
    for p in pts {
        if !v.contains(&p.scene) {
            v.push(p.scene.clone());
        }
    }
    v
}

fn solvers(pts: &[Point]) -> Vec<String> {
    let mut v: Vec<String> = Vec::new();
    for p in pts {
        if !v.contains(&p.solver) {
            v.push(p.solver.clone());
        }
    }
    v
}

/// The markdown: the matched-accuracy summary, then every point.
pub fn markdown(pts: &[Point]) -> String {
    let mut md = String::from(
        "| scene | accuracy level | twin (diffsol BDF): tol, wall | diffsol TR-BDF2: tol, wall | diffsol ESDIRK34: tol, wall | twin wall / best peer wall |\n|---|---|---|---|---|---|\n",
    );
    for scene in scenes(pts) {
        for level in LEVELS {
            let cell = |solver: &str| {
                cheapest(pts, &scene, solver, level).map_or("not reached".to_string(), |p| {
                    format!("{:e}, {}s", p.tolerance, eng(p.wall_s))
                })
            };
            let twin = cheapest(pts, &scene, "diffsol-bdf", level);
            let peer = ["diffsol-trbdf2", "diffsol-esdirk34", "scipy-radau"]
                .iter()
                .filter_map(|s| cheapest(pts, &scene, s, level))
                .min_by(|a, b| a.wall_s.total_cmp(&b.wall_s));
            let ratio = match (twin, peer) {
                (Some(t), Some(p)) => format!("{:.2} ({})", t.wall_s / p.wall_s, p.solver),
                _ => "—".into(),
            };
            let _ = writeln!(
                md,
                "| {scene} | ≤ {} % | {} | {} | {} | {ratio} |",
                level * 100.0,
                cell("diffsol-bdf"),
                cell("diffsol-trbdf2"),
                cell("diffsol-esdirk34"),
            );
        }
    }
    md.push_str("\nEvery point (worst relative error over every metric that has a converged reference; the metric that sets it):\n\n| scene | solver | tolerance | wall | worst error | set by |\n|---|---|---|---|---|---|\n");
    for p in pts {
        let _ = writeln!(
            md,
            "| {} | {} | {:e} | {}s | {} | {} |",
            p.scene,
            p.solver,
            p.tolerance,
            eng(p.wall_s),
            p.error
                .map_or("— (no compared metric)".into(), |e| format!("{:.2e}", e)),
            p.metric
        );
    }
    md
}

/// The chart: one log–log panel per scene, worst error against wall time, a line per solver.
pub fn chart(path: &Path, pts: &[Point]) -> Result<(), String> {
    use plotters::prelude::*;
    let e = |x: DrawingAreaErrorKind<_>| format!("work-precision chart: {x:?}");
    let names = scenes(pts);
    let root = SVGBackend::new(path, (1100, 820)).into_drawing_area();
    root.fill(&WHITE).map_err(e)?;
    let root = root
        .titled(
            "Work–precision, physical reading: worst relative error vs wall time (one run)",
            ("sans-serif", 18),
        )
        .map_err(e)?;
    let panels = root.split_evenly((2, 2));
    let colours = [BLUE, RED, GREEN, MAGENTA, BLACK];
    for (scene, area) in names.iter().zip(panels.iter()) {
        let sp: Vec<&Point> = pts.iter().filter(|p| &p.scene == scene).collect();
        let (mut x0, mut x1) = (f64::MAX, 0.0_f64);
        let (mut y0, mut y1) = (f64::MAX, 0.0_f64);
        for p in &sp {
            x0 = x0.min(p.wall_s);
            x1 = x1.max(p.wall_s);
            if let Some(err) = p.error {
                y0 = y0.min(err.max(FLOOR));
                y1 = y1.max(err.max(FLOOR));
            }
        }
        if x1 <= 0.0 || y1 <= 0.0 {
            continue;
        }
        let mut c = ChartBuilder::on(area)
            .caption(scene, ("sans-serif", 15))
            .margin(10)
            .x_label_area_size(36)
            .y_label_area_size(60)
            .build_cartesian_2d(
                {
                    let (a, b) = decades(x0, x1);
                    (a..b).log_scale()
                },
                {
                    let (a, b) = decades(y0, y1);
                    (a..b).log_scale()
                },
            )
            .map_err(e)?;
        c.configure_mesh()
            .x_desc("wall time (s)")
            .y_desc("worst relative error")
            .x_label_formatter(&|v| eng(*v))
            .y_label_formatter(&|v| eng(*v))
            .draw()
            .map_err(e)?;
        for (k, solver) in solvers(pts).iter().enumerate() {
            let col = colours.get(k).copied().unwrap_or(BLACK);
            let mut line: Vec<(f64, f64)> = sp
                .iter()
                .filter(|p| &p.solver == solver)
                .filter_map(|p| p.error.map(|err| (p.wall_s, err.max(FLOOR))))
                .collect();
            if line.is_empty() {
                continue;
            }
            line.sort_by(|a, b| a.0.total_cmp(&b.0));
            c.draw_series(LineSeries::new(line.clone(), col.stroke_width(1)))
                .map_err(e)?;
            c.draw_series(
                line.iter()
                    .map(|&(x, y)| Circle::new((x, y), 4, col.filled())),
            )
            .map_err(e)?
            .label(solver.as_str())
            .legend(move |(x, y)| Circle::new((x + 8, y), 4, col.filled()));
        }
        c.configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(e)?;
    }
    root.present().map_err(e)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn engineering_notation() {
        assert_eq!(decades(16.9, 91.0), (10.0, 100.0));
        assert_eq!(decades(20.0, 30.0), (10.0, 100.0));
    }

    #[test]
    fn cheapest_respects_the_level() {
        let p = |solver: &str, wall_s: f64, e: f64| Point {
            scene: "s".into(),
            solver: solver.into(),
            tolerance: 1e-5,
            wall_s,
            error: Some(e),
            metric: String::new(),
        };
        let mut pts = vec![p("a", 1.0, 0.02), p("a", 2.0, 0.005), p("a", 3.0, 1e-4)];
        for (k, q) in pts.iter_mut().enumerate() {
            q.tolerance = 10f64.powi(-3 - k as i32);
        }
        assert_eq!(cheapest(&pts, "s", "a", 1e-2).map(|p| p.wall_s), Some(2.0));
        assert_eq!(cheapest(&pts, "s", "a", 1e-3).map(|p| p.wall_s), Some(3.0));
        assert!(cheapest(&pts, "s", "a", 1e-5).is_none());
        // A loose tolerance that is lucky (a tighter one misses) does not count.
        pts[1].error = Some(0.05);
        assert_eq!(cheapest(&pts, "s", "a", 1e-2).map(|p| p.wall_s), Some(3.0));
    }
}
