//! Work–precision (issue 18): each paper scene of the `physical` reading under the twin's
//! integrator (diffsol BDF) and diffsol's SDIRK methods (TR-BDF2, ESDIRK34) at tolerances
//! 1e-3 … 1e-7; per run the worst
//! relative error over every metric the converged reference has (1 % / 1e-6 absolute rule of
//! `convergence::close`) and the wall time (best of `--repeat`, default 3). Prints JSON lines.
//!
//! `cargo run --release -p noback-twin --example work_precision -- [--repeat N]`
use noback_twin::convergence::{self, Entry, ABS_SLACK};
use noback_twin::metrics;
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::sim;
use noback_twin::solver::{Integrator, Method};
use serde_json::json;

/// Tolerances of the sweep, loosest first.
const TOLS: [f64; 5] = [1e-3, 1e-4, 1e-5, 1e-6, 1e-7];

/// Worst relative error over the scene's reference metrics (absolute below `ABS_SLACK`·100).
fn worst(refs: &[Entry], scene: &str, m: &metrics::Metrics) -> Option<(f64, String)> {
    let mut w: Option<(f64, String)> = None;
    for e in refs
        .iter()
        .filter(|e| e.scene == scene && e.reading == "physical" && e.settles_at.is_some())
    {
        let Some(r) = e.reference else { continue };
        let err = match convergence::metric(m, &e.metric) {
            None => f64::INFINITY,
            Some(v) if r.abs() < 100.0 * ABS_SLACK => (v - r).abs(),
            Some(v) => ((v - r) / r).abs(),
        };
        if w.as_ref().is_none_or(|(x, _)| err > *x) {
            w = Some((err, e.metric.clone()));
        }
    }
    w
}

/// Best wall time and the last run, or the solver's error.
type Timed = Result<(f64, sim::Run), String>;

fn time(s: &Scene, make: &dyn Fn() -> Integrator, repeat: usize) -> Timed {
    let mut best = f64::INFINITY;
    let mut last = None;
    for _ in 0..repeat {
        let r = sim::run_with(s, make()).map_err(|e| e.to_string())?;
        best = best.min(r.wall_s);
        last = Some(r);
    }
    last.map(|r| (best, r)).ok_or_else(|| "no run".into())
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let repeat = args
        .iter()
        .position(|a| a == "--repeat")
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse::<usize>().ok())
        .unwrap_or(3)
        .max(1);
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let refs: Vec<Entry> =
        std::fs::read_to_string(format!("{root}/twin/tests/reference/converged.json"))
            .ok()
            .and_then(|t| serde_json::from_str(&t).ok())
            .unwrap_or_default();
    for kind in [
        SceneKind::ReverseLoad,
        SceneKind::ForwardLoad,
        SceneKind::ContinuousClosing,
        SceneKind::Hold,
    ] {
        for tol in TOLS {
            let mut s = Scene::builtin(kind, Reading::Physical);
            s.tolerance = tol;
            let opts = sim::solver_options(&s);
            let runs = [Method::Bdf, Method::TrBdf2, Method::Esdirk34].map(|m| {
                (
                    m.name(),
                    time(&s, &|| Integrator::with_method(m, opts), repeat),
                )
            });
            for (solver, r) in runs {
                let line = match r {
                    Ok((wall, run)) => {
                        let m = metrics::compute(&s, &run.samples, &run.stats, run.wall_s);
                        let w = worst(&refs, kind.name(), &m);
                        json!({"scene": kind.name(), "solver": solver, "tolerance": tol,
                            "wall_s": wall, "rhs_evals": run.stats.rhs_evals,
                            "steps": run.stats.steps, "events": run.stats.events,
                            "worst_rel_error": w.as_ref().map(|x| x.0).filter(|e| e.is_finite()),
                            "worst_metric": w.map(|x| x.1)})
                    }
                    Err(e) => json!({"scene": kind.name(), "solver": solver,
                        "tolerance": tol, "error": e}),
                };
                println!("{line}");
            }
        }
    }
}
