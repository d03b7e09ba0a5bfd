//! `cargo xtask monitor SCENE|FILE [--json] [--out DIR]` — the monitor against the twin on one
//! scene: accuracy figures, flags, detection latency per injected fault, false alarms, and a
//! plot with the twin's raw and compared signals beside the monitor's estimate.
//! The comparison itself lives in `host_tests::accuracy` (this file only runs and reports).

use crate::replay::twin_trace;
use crate::shell::workspace_root;
use host_tests::accuracy::{
    compare, detection_latency_s, false_alarms, manifest_time, run_monitor, COMPARE_WINDOW_S,
};
use noback::monitor::Config;
use noback_twin::svg::{render, Panel, Series};
use serde_json::json;
use std::path::PathBuf;

/// Entry.
pub fn main(args: &[String]) -> Result<i32, String> {
    let mut target = None;
    let mut json_out = false;
    let mut out = workspace_root().join("target").join("monitor");
    let mut it = args.iter();
    while let Some(arg) = it.next() {
        match arg.as_str() {
            "--json" => json_out = true,
            "--out" => out = PathBuf::from(it.next().ok_or("--out needs a directory")?),
            s if s.starts_with("--") => return Err(format!("unknown option `{s}`")),
            s => target = Some(s.to_string()),
        }
    }
    let target = target.ok_or("usage: cargo xtask monitor SCENE|FILE [--json] [--out DIR]")?;
    let scene = noback_twin::cli::load_scene(&target, None)?;
    let trace = twin_trace(&target)?;
    let estimates = run_monitor(&trace, Config::default())?;
    let acc = compare(&trace, &estimates);

    let detections: Vec<_> = scene
        .faults
        .iter()
        .map(|f| {
            json!({
                "kind": format!("{:?}", f.kind),
                "at_s": f.at_s,
                "manifests_at_s": manifest_time(f, &trace),
                "detection_latency_s": detection_latency_s(f, &trace, &acc),
            })
        })
        .collect();
    let flags: Vec<_> = acc
        .flags
        .iter()
        .map(|f| json!({"flag": f.flag, "t_s": f.t_s}))
        .collect();
    let report = json!({
        "scene": target,
        "samples": trace.rows.len(),
        "compare_window_s": COMPARE_WINDOW_S,
        "pressing_force_rmse_n": acc.pressing_force_rmse_n,
        "pressing_force_rmse_pct": acc.pressing_force_rmse_pct,
        "braking_torque_rmse_nm": acc.braking_torque_rmse_nm,
        "holding_torque_twin_nm": acc.holding_torque_nm.map(|h| h.0),
        "holding_torque_monitor_nm": acc.holding_torque_nm.map(|h| h.1),
        "holding_torque_err_pct": acc.holding_torque_err_pct(),
        "lock_time_twin_s": acc.lock_time_s.map(|l| l.0),
        "lock_time_monitor_s": acc.lock_time_s.and_then(|l| l.1),
        "lock_time_err_s": acc.lock_time_err_s().filter(|e| e.is_finite()),
        "flags": flags,
        "detection_latency_s": detections,
        "false_alarms": false_alarms(&scene.faults, &acc),
    });

    std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
    let stem = std::path::Path::new(&target)
        .file_stem()
        .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
    let svg_path = out.join(format!("monitor-{stem}.svg"));
    let svg = render(
        &format!("monitor vs twin: {target}"),
        &acc.t_s,
        &[
            Panel {
                title: "pressing force (N)",
                series: vec![
                    Series {
                        label: "twin raw",
                        color: "#bbbbbb",
                        values: acc.twin_force_raw_n.clone(),
                    },
                    Series {
                        label: "twin compared",
                        color: "#1f77b4",
                        values: acc.twin_force_n.clone(),
                    },
                    Series {
                        label: "monitor",
                        color: "#d62728",
                        values: acc.monitor_force_n.clone(),
                    },
                ],
            },
            Panel {
                title: "braking torque (N·m)",
                series: vec![
                    Series {
                        label: "twin raw",
                        color: "#bbbbbb",
                        values: acc.twin_torque_raw_nm.clone(),
                    },
                    Series {
                        label: "twin compared",
                        color: "#1f77b4",
                        values: acc.twin_torque_nm.clone(),
                    },
                    Series {
                        label: "monitor",
                        color: "#d62728",
                        values: acc.monitor_torque_nm.clone(),
                    },
                ],
            },
        ],
    );
    std::fs::write(&svg_path, svg).map_err(|e| format!("{}: {e}", svg_path.display()))?;

    if json_out {
        println!("{report}");
    } else {
        println!(
            "{}",
            serde_json::to_string_pretty(&report).map_err(|e| e.to_string())?
        );
        eprintln!("plot: {}", svg_path.display());
    }
    Ok(0)
}
