//! `cargo xtask twin-bench [--tolerance TOL] [--no-scipy] [--scipy-tolerances A,B] [--json]` — the twin's speed and
//! worst error against its converged reference on each paper scene (release build), beside
//! diffsol's TR-BDF2 (same `OdeSystem`) and an independent solve of the
//! same equations with scipy's `solve_ivp(method="Radau")` (`bench/radau.py`; installed with pip
//! when missing); then the work–precision sweep (`examples/work_precision.rs`). Writes
//! `docs/results/twin-speed.md` and `work-precision.svg` (benchmark pages); `--json` only prints.

use crate::bench::work_precision::{self as wp, Point};
use crate::shell::{self, cargo, workspace_root};
use std::process::Command;

/// Entry.
pub fn main(args: &[String]) -> Result<i32, String> {
    let scipy = !args.iter().any(|a| a == "--no-scipy");
    if scipy {
        let have = Command::new("python3")
            .args(["-c", "import scipy"])
            .status()
            .is_ok_and(|s| s.success());
        if !have {
            eprintln!("twin-bench: scipy is missing; installing it with pip");
            shell::run(Command::new("python3").args(["-m", "pip", "install", "--quiet", "scipy"]))?;
        }
    }
    let json = args.iter().any(|a| a == "--json");
    let side = workspace_root()
        .join("target")
        .join("twin")
        .join("twin-bench.json");
    let mut cmd = cargo();
    cmd.args([
        "run",
        "--quiet",
        "--release",
        "-p",
        "noback-twin",
        "--example",
        "bench",
        "--",
    ])
    .args(args);
    if !json {
        if let Some(d) = side.parent() {
            std::fs::create_dir_all(d).map_err(|e| format!("{}: {e}", d.display()))?;
        }
        cmd.arg("--json-out").arg(&side);
    }
    eprintln!("$ {}", shell::describe(&cmd));
    let out = cmd
        .output()
        .map_err(|e| format!("starting the twin bench: {e}"))?;
    let table = String::from_utf8_lossy(&out.stdout).to_string();
    if !out.status.success() {
        eprintln!("{}", String::from_utf8_lossy(&out.stderr));
        return Err("the twin bench failed".into());
    }
    let bench_json = if json {
        table.clone()
    } else {
        print!("{table}");
        std::fs::read_to_string(&side).unwrap_or_default()
    };
    let mut wcmd = cargo();
    wcmd.args([
        "run",
        "--quiet",
        "--release",
        "-p",
        "noback-twin",
        "--example",
        "work_precision",
    ]);
    eprintln!("$ {}", shell::describe(&wcmd));
    let wout = wcmd
        .output()
        .map_err(|e| format!("starting the work-precision sweep: {e}"))?;
    if !wout.status.success() {
        eprintln!("{}", String::from_utf8_lossy(&wout.stderr));
        return Err("the work-precision sweep failed".into());
    }
    let mut pts = wp::parse(&String::from_utf8_lossy(&wout.stdout));
    let bench: serde_json::Value = serde_json::from_str(&bench_json).unwrap_or_default();
    pts.extend(scipy_points(&bench));
    if scipy {
        let list = args
            .iter()
            .position(|a| a == "--scipy-tolerances")
            .and_then(|i| args.get(i + 1))
            .map_or("1e-3,1e-4", String::as_str);
        let mut tols = Vec::new();
        for t in list.split(',') {
            tols.push(
                t.trim()
                    .parse::<f64>()
                    .map_err(|_| format!("--scipy-tolerances: `{t}` is not a number"))?,
            );
        }
        pts.extend(scipy_sweep(&bench, &tols)?);
    }
    if json {
        let mut v = bench;
        let list: Vec<serde_json::Value> = pts
            .iter()
            .map(|p| serde_json::json!({"scene": p.scene, "solver": p.solver, "tolerance": p.tolerance, "wall_s": p.wall_s, "worst_rel_error": p.error, "worst_metric": p.metric}))
            .collect();
        if let Some(o) = v.as_object_mut() {
            o.insert("work_precision".into(), list.into());
        }
        println!("{v}");
        return Ok(0);
    }
    let wp_md = wp::markdown(&pts);
    print!("{wp_md}");
    let machine = crate::machine::this();
    let doc = format!(
        "# Twin speed against diffsol's SDIRK methods and scipy Radau (benchmark page)\n\nWritten by `cargo xtask twin-bench{}`; do not edit. \
         Release build, physical reading, same equations and tolerance on both sides. Wall times \
         from one run on {machine} (shared): a benchmark, not a test, and they change \
         from run to run. Errors are against the converged references \
         (`twin/tests/reference/converged.json`, tolerance 1e-10; braking time and angle, the \
         metrics both sides report); a speed ratio is given only where both sides hold them within 1 % (continuous closing has \
         neither, so no ratio). The twin integrates with diffsol's BDF (`twin/src/solver/integrator.rs`); \
         TR-BDF2 is another of diffsol's methods on the same `OdeSystem`, its error over the same \
         two metrics here; the work–precision section below takes every metric.\n\n{table}\n## Work–precision\n\n\
         `examples/work_precision.rs`: tolerances 1e-3 … 1e-7, best of three runs each; error = \
         worst relative error over every metric of the scene that has a converged reference \
         (scipy Radau: braking time and angle only, at 1e-3, 1e-4 and the bench's tolerance). A solver meets an accuracy level at \
         its cheapest tolerance whose worst error is at or below it at that and every tighter tolerance; the ratio compares those \
         cheapest walls. Chart: `work-precision.svg`.\n\n![work-precision](work-precision.svg)\n\n{wp_md}",
        args.iter().map(|a| format!(" {a}")).collect::<String>()
    );
    let path = workspace_root()
        .join("docs")
        .join("results")
        .join("twin-speed.md");
    std::fs::write(&path, doc).map_err(|e| format!("{}: {e}", path.display()))?;
    wp::chart(&path.with_file_name("work-precision.svg"), &pts)?;
    eprintln!("wrote {} and work-precision.svg", path.display());
    Ok(0)
}

/// scipy Radau at further tolerances (`bench/radau.py`, minutes each), its worst relative error
/// over braking time and angle against the references the bench printed.
fn scipy_sweep(bench: &serde_json::Value, tols: &[f64]) -> Result<Vec<Point>, String> {
    let script = workspace_root().join("bench").join("radau.py");
    let mut out = Vec::new();
    for r in bench
        .get("scenes")
        .and_then(|s| s.as_array())
        .into_iter()
        .flatten()
    {
        let (Some(scene), Some(main_tol)) = (
            r.get("scene").and_then(|v| v.as_str()),
            r.get("tolerance").and_then(|v| v.as_f64()),
        ) else {
            continue;
        };
        for &tol in tols.iter().filter(|&&t| t != main_tol) {
            eprintln!("twin-bench: scipy Radau on {scene} at {tol:e}");
            let o = Command::new("timeout")
                .arg("1800")
                .arg("python3")
                .arg(&script)
                .args([scene, "--tolerance", &format!("{tol:e}")])
                .output()
                .map_err(|e| format!("starting {}: {e}", script.display()))?;
            let run: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap_or_default();
            let Some(wall_s) = run.get("wall_s").and_then(|v| v.as_f64()) else {
                continue;
            };
            let mut worst: Option<f64> = None;
            for m in ["braking_time_s", "braking_angle_rad"] {
                let Some(re) = r["reference"].get(m).and_then(|v| v.as_f64()) else {
                    continue;
                };
                let e = run
                    .get(m)
                    .and_then(|v| v.as_f64())
                    .map_or(f64::INFINITY, |v| ((v - re) / re).abs());
                worst = Some(worst.map_or(e, |w: f64| w.max(e)));
            }
            out.push(Point {
                scene: scene.to_string(),
                solver: "scipy-radau".into(),
                tolerance: tol,
                wall_s,
                error: worst.filter(|e| e.is_finite()),
                metric: "braking time / angle".into(),
            });
        }
    }
    Ok(out)
}

/// scipy Radau's points from the bench's JSON (one tolerance; error over time and angle).
fn scipy_points(bench: &serde_json::Value) -> Vec<Point> {
    let Some(rows) = bench.get("scenes").and_then(|s| s.as_array()) else {
        return Vec::new();
    };
    rows.iter()
        .filter_map(|r| {
            let run = r.get("scipy_radau")?;
            Some(Point {
                scene: r.get("scene")?.as_str()?.to_string(),
                solver: "scipy-radau".into(),
                tolerance: r.get("tolerance")?.as_f64()?,
                wall_s: run.get("run")?.get("wall_s")?.as_f64()?,
                error: run.get("worst_rel_error").and_then(|e| e.as_f64()),
                metric: "braking time / angle".into(),
            })
        })
        .collect()
}
