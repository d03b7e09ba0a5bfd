//! Speed benchmark (issue 3 §9): times each paper scene of the `physical` reading and, in the
//! same run, the independent scipy `solve_ivp(method="Radau")` solve of the same equations
//! (`bench/radau.py`) at the same tolerance, and prints the ratio.
//!
//! `cargo run --release -p noback-twin --example bench -- [--tolerance TOL] [--no-scipy]`
use noback_twin::metrics;
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::sim;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let tol = args
        .iter()
        .position(|a| a == "--tolerance")
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse::<f64>().ok())
        .unwrap_or(1e-5);
    let scipy = !args.iter().any(|a| a == "--no-scipy");
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/../bench/radau.py");
    println!("| scene | twin wall (s) | twin RHS evals | twin braking time / angle | scipy Radau wall (s) | scipy RHS evals | scipy braking time / angle | ratio |");
    println!("|---|---|---|---|---|---|---|---|");
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
        let o = |v: Option<f64>| v.map_or("—".to_string(), |v| format!("{v:.4}"));
        let (py_wall, py_rhs, py_bt) = if scipy {
            let out = std::process::Command::new("timeout")
                .arg("600")
                .arg("python3")
                .arg(script)
                .arg(kind.name())
                .arg("--tolerance")
                .arg(format!("{tol:e}"))
                .output();
            match out {
                Ok(o2) if o2.status.success() => {
                    let v: serde_json::Value =
                        serde_json::from_slice(&o2.stdout).unwrap_or(serde_json::Value::Null);
                    let w = v["wall_s"].as_f64().unwrap_or(f64::NAN);
                    let n = v["rhs_evals"].as_u64().unwrap_or(0);
                    let bt = format!(
                        "{} / {}",
                        o(v["braking_time_s"].as_f64()),
                        o(v["braking_angle_rad"].as_f64())
                    );
                    (w, n.to_string(), bt)
                }
                Ok(o2) => (
                    f64::NAN,
                    "failed".into(),
                    String::from_utf8_lossy(&o2.stderr)
                        .lines()
                        .last()
                        .unwrap_or("")
                        .to_string(),
                ),
                Err(e) => (f64::NAN, "not run".into(), e.to_string()),
            }
        } else {
            (f64::NAN, "—".into(), "—".into())
        };
        println!(
            "| {} | {:.4} | {} | {} / {} | {:.2} | {} | {} | {:.0}× |",
            kind.name(),
            best,
            m.rhs_evals,
            o(m.braking_time_s),
            o(m.braking_angle_rad),
            py_wall,
            py_rhs,
            py_bt,
            py_wall / best
        );
    }
}
