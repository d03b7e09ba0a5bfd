//! Speed benchmark (issue 18): each paper scene of the `physical` reading against its converged
//! reference (`tests/reference/converged.json`, tolerance 1e-10), timed (best of three) with its
//! worst relative error, beside the independent scipy `solve_ivp(method="Radau")` solve of the
//! same equations (`bench/radau.py`) and diffsol's TR-BDF2 (another method on the same
//! `OdeSystem`, same event rule) at the same tolerance. A speed ratio is printed only where both
//! sides hold every compared metric within 1 % of the reference (matched accuracy).
//!
//! `cargo run --release -p noback-twin --example bench -- [--tolerance TOL] [--no-scipy] [--json | --json-out PATH]`
use noback_twin::convergence::{self, Entry};
use noback_twin::metrics;
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::sim;
use noback_twin::solver::{Integrator, Method};
use serde_json::{json, Value};

/// The metrics both sides report (scipy's script reports only these).
const COMPARED: [&str; 2] = ["braking_time_s", "braking_angle_rad"];

fn worst(refs: &[Entry], scene: &str, get: &dyn Fn(&str) -> Option<f64>) -> Option<f64> {
    let mut w: Option<f64> = None;
    for name in COMPARED {
        let Some(e) = refs
            .iter()
            .find(|e| e.scene == scene && e.reading == "physical" && e.metric == name)
        else {
            continue;
        };
        let (Some(r), Some(v)) = (e.reference, get(name)) else {
            // A metric the reference has and the run lacks: unbounded error.
            return Some(f64::INFINITY);
        };
        let err = if r == 0.0 {
            v.abs()
        } else {
            ((v - r) / r).abs()
        };
        w = Some(w.map_or(err, |x: f64| x.max(err)));
    }
    w
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let tol = args
        .iter()
        .position(|a| a == "--tolerance")
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse::<f64>().ok())
        .unwrap_or(1e-5);
    let scipy = !args.iter().any(|a| a == "--no-scipy");
    let as_json = args.iter().any(|a| a == "--json");
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let refs: Vec<Entry> =
        std::fs::read_to_string(format!("{root}/twin/tests/reference/converged.json"))
            .ok()
            .and_then(|t| serde_json::from_str(&t).ok())
            .unwrap_or_default();
    let script = format!("{root}/bench/radau.py");
    let mut rows: Vec<Value> = Vec::new();
    if !as_json {
        println!("| scene | reference braking time / angle (1e-10) | twin (BDF) wall (s) | twin RHS evals | twin worst error | TR-BDF2 wall (s) | TR-BDF2 worst error | TR-BDF2 / twin wall | scipy Radau wall (s) | scipy RHS evals | scipy braking time / angle | scipy worst error | scipy / twin wall at matched accuracy |");
        println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    }
    for kind in [
        SceneKind::ReverseLoad,
        SceneKind::ForwardLoad,
        SceneKind::ContinuousClosing,
        SceneKind::Hold,
    ] {
        let mut s = Scene::builtin(kind, Reading::Physical);
        s.tolerance = tol;
        let mut best = f64::INFINITY;
        let mut last = None;
        for _ in 0..3 {
            match sim::run(&s) {
                Ok(r) => {
                    best = best.min(r.wall_s);
                    last = Some(metrics::compute(&s, &r.samples, &r.stats, r.wall_s));
                }
                Err(e) => {
                    eprintln!("{}: {e}", kind.name());
                    std::process::exit(2);
                }
            }
        }
        let Some(m) = last else { continue };
        let mut ds_best = f64::INFINITY;
        let mut ds_last = None;
        for _ in 0..3 {
            match sim::run_with(
                &s,
                Integrator::with_method(Method::TrBdf2, sim::solver_options(&s)),
            ) {
                Ok(r) => {
                    ds_best = ds_best.min(r.wall_s);
                    ds_last = Some(metrics::compute(&s, &r.samples, &r.stats, r.wall_s));
                }
                Err(e) => eprintln!("{} (TR-BDF2): {e}", kind.name()),
            }
        }
        let ds_err = ds_last
            .as_ref()
            .and_then(|d| worst(&refs, kind.name(), &|n| convergence::metric(d, n)));
        let twin_err = worst(&refs, kind.name(), &|n| convergence::metric(&m, n));
        let reference = |n: &str| {
            refs.iter()
                .find(|e| e.scene == kind.name() && e.reading == "physical" && e.metric == n)
                .and_then(|e| e.reference)
        };
        let py: Value = if scipy {
            eprintln!("bench: scipy Radau on {} (minutes)", kind.name());
            match std::process::Command::new("timeout")
                .args(["1800", "python3", &script, kind.name(), "--tolerance"])
                .arg(format!("{tol:e}"))
                .output()
            {
                Ok(o) if o.status.success() => {
                    serde_json::from_slice(&o.stdout).unwrap_or(Value::Null)
                }
                Ok(o) => {
                    json!({"error": String::from_utf8_lossy(&o.stderr).lines().last().unwrap_or("").to_string()})
                }
                Err(e) => json!({"error": e.to_string()}),
            }
        } else {
            Value::Null
        };
        let py_err = if py.get("wall_s").is_some() {
            worst(&refs, kind.name(), &|n| py.get(n).and_then(Value::as_f64))
        } else {
            None
        };
        let py_wall = py.get("wall_s").and_then(Value::as_f64);
        // Matched: a compared metric exists and both sides hold it within 1 % of the reference.
        let matched = |e: Option<f64>| e.is_some_and(|e| e <= convergence::SETTLE);
        let ratio = match py_wall {
            Some(w) if matched(twin_err) && matched(py_err) => Some(w / best),
            _ => None,
        };
        rows.push(json!({
            "scene": kind.name(),
            "tolerance": tol,
            "reference": {"tolerance": 1e-10, "braking_time_s": reference("braking_time_s"), "braking_angle_rad": reference("braking_angle_rad")},
            "twin": {"wall_s": best, "rhs_evals": m.rhs_evals, "braking_time_s": m.braking_time_s, "braking_angle_rad": m.braking_angle_rad, "worst_rel_error": twin_err},
            "tr_bdf2": ds_last.as_ref().map(|d| json!({"wall_s": ds_best, "rhs_evals": d.rhs_evals, "braking_time_s": d.braking_time_s, "braking_angle_rad": d.braking_angle_rad, "worst_rel_error": ds_err})),
            "tr_bdf2_ratio_at_matched_accuracy": (matched(twin_err) && matched(ds_err)).then(|| ds_best / best),
            "scipy_radau": {"run": py, "worst_rel_error": py_err},
            "ratio_at_matched_accuracy": ratio,
        }));
        if !as_json {
            let o = |v: Option<f64>| v.map_or("—".to_string(), |v| format!("{v:.4}"));
            let pct =
                |v: Option<f64>| v.map_or("—".to_string(), |v| format!("{:.2} %", 100.0 * v));
            let pf = |n: &str| py.get(n).and_then(Value::as_f64);
            println!(
                "| {} | {} / {} | {:.4} | {} | {} | {} | {} | {} | {} | {} | {} / {} | {} | {} |",
                kind.name(),
                o(reference("braking_time_s")),
                o(reference("braking_angle_rad")),
                best,
                m.rhs_evals,
                pct(twin_err),
                if ds_best.is_finite() {
                    format!("{ds_best:.4}")
                } else {
                    "failed".into()
                },
                pct(ds_err),
                if matched(twin_err) && matched(ds_err) {
                    format!("{:.2}", ds_best / best)
                } else if twin_err.is_none() {
                    "— (no compared metric)".into()
                } else {
                    "— (not matched)".into()
                },
                py_wall.map_or("—".into(), |w| format!("{w:.2}")),
                py.get("rhs_evals")
                    .and_then(Value::as_u64)
                    .map_or("—".into(), |n| n.to_string()),
                o(pf("braking_time_s")),
                o(pf("braking_angle_rad")),
                pct(py_err),
                match (ratio, py_wall) {
                    (Some(r), _) => format!("{r:.0}×"),
                    (None, Some(_)) if twin_err.is_none() => "— (no compared metric)".into(),
                    (None, Some(_)) => "— (not matched)".into(),
                    (None, None) => "—".into(),
                },
            );
        }
    }
    if as_json {
        println!("{}", json!({ "scenes": rows }));
    } else if let Some(p) = args
        .iter()
        .position(|a| a == "--json-out")
        .and_then(|i| args.get(i + 1))
    {
        if let Err(e) = std::fs::write(p, json!({ "scenes": rows }).to_string()) {
            eprintln!("{p}: {e}");
            std::process::exit(2);
        }
    }
}
