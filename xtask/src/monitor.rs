//! `cargo xtask monitor SCENE|SCENE.toml|TRACE.csv [--config FILE] [--json] [--out DIR]` — the monitor against
//! the twin on one scene (or on a recorded trace): accuracy figures, flags, detection latency per injected fault, false alarms
//! (none counted where the input comes apart from the output: an unhealthy plant), and a
//! plot with the twin's raw and compared signals beside the monitor's estimate.
//! The comparison itself lives in `host_tests::accuracy` (this file only runs and reports).

use crate::replay::trace_of;
use crate::shell::workspace_root;
use host_tests::accuracy::run_functional_test;
use host_tests::accuracy::{
    compare, false_alarms, latency_after, manifest_time, manifest_time_beside, run_monitor,
    scene_trace, Accuracy, COMPARE_WINDOW_S,
};
use host_tests::mc::not_driven;
use noback::monitor::Config;
use noback::sensors::SensorConfig;
use noback_twin::fault::Fault;
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::svg::{render, Panel, Series};
use noback_twin::trace::Trace;

use noback_twin::args::bad_input;
#[cfg(test)]
use noback_twin::args::EXIT_USAGE as EXIT_INPUT;
use serde_json::json;
use std::path::PathBuf;

/// `cargo xtask monitor`'s options.
#[derive(clap::Args, Debug)]
pub struct MonitorArgs {
    /// A built-in scene, a TOML scene file, or a recorded trace (`.csv`, the twin's format).
    #[arg(value_name = "SCENE|FILE|TRACE.csv")]
    pub target: String,
    /// Print the report as one JSON object.
    #[arg(long)]
    pub json: bool,
    /// The monitor's configuration file (docs/commissioning.md);
    /// default: uncommissioned.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Where the plot goes.
    #[arg(long, value_name = "DIR", default_value_os_t = workspace_root().join("target").join("monitor"))]
    pub out: PathBuf,
}

/// Reads a configuration file; the error names the file and the key.
pub fn config_from_file(path: &std::path::Path) -> Result<Config, String> {
    std::fs::read_to_string(path)
        .map_err(|e| e.to_string())
        .and_then(|t| host_tests::config_file::parse(&t))
        .map_err(|e| format!("{}: {e}", path.display()))
}

/// Entry.
/// The functional test of a `functional_test` scene, requested when its opening starts: a
/// configuration file's procedure (a commissioned unit's acceptance readings), or the scene's.
fn functional_test_json(
    trace: &noback_twin::trace::Trace,
    config: Option<Config>,
    scene: &Scene,
) -> Result<serde_json::Value, String> {
    let (kind, test) = host_tests::dormant::procedure_of(scene);
    let config = crate::run::test_configuration(config, kind, test)?;
    let test = kind
        .test(&config)
        .ok_or("the configuration has no uncoupled push")?;
    let r = run_functional_test(trace, config, (kind, &test), scene.test.start_s)?;
    Ok(json!({
        "procedure": r.procedure.name(),
        "result": format!("{:?}", r.result).to_lowercase(),
        "opening_torque_nm": r.opening_torque_nm.to_num::<f64>(),
        "breakaway_torque_nm": r.breakaway_torque_nm.to_num::<f64>(),
        "capacity_nm": r.capacity_nm.to_num::<f64>(),
        "margin": r.margin.to_num::<f64>(),
    }))
}

/// Whether the plant's input came apart from its output on `plant` (the run without its faults),
/// and the run's false alarms where it did not: such a plant is not healthy (the Monte Carlo
/// counts it apart), so its flags are not false.
fn counted_alarms(
    plant: &Trace,
    sensors: &SensorConfig,
    faults: &[Fault],
    acc: &Accuracy,
) -> (bool, Option<usize>) {
    let apart = not_driven(plant, sensors);
    (apart, (!apart).then(|| false_alarms(faults, acc)))
}

pub fn main(a: &MonitorArgs) -> Result<i32, String> {
    let (target, json_out, out) = (a.target.clone(), a.json, a.out.clone());
    // A trace file (the twin's CSV format) is replayed as it is; anything else is a scene (the
    // twin failing on a scene that passed the schema is still the scene's fault).
    let (scene, trace) = match trace_of(&target) {
        Ok((trace, scene)) => (scene, trace),
        Err(e) => return Ok(bad_input("monitor", &e)),
    };
    let faults = scene.as_ref().map(|s| s.faults.clone()).unwrap_or_default();
    let config = match &a.config {
        None => Config::default(),
        Some(path) => match config_from_file(path) {
            Ok(c) => c,
            Err(e) => return Ok(bad_input("monitor", &e)),
        },
    };
    let estimates = run_monitor(&trace, config)?;
    let acc = compare(&trace, &estimates);
    let sensors = scene.as_ref().map_or(config.sensors, |s| s.sensors);
    let functional_test = match scene
        .as_ref()
        .filter(|s| s.kind == SceneKind::FunctionalTest)
    {
        Some(s) => {
            let file = a.config.is_some().then_some(config);
            match functional_test_json(&trace, file, s) {
                Ok(v) => Some(v),
                Err(e) => return Ok(bad_input("monitor", &e)),
            }
        }
        None => None,
    };

    // The same scene without its faults: where a holding fault manifests, and whether the plant
    // itself came apart (judged there, as the Monte Carlo judges a fault draw).
    let healthy = match scene.as_ref() {
        Some(s) if !faults.is_empty() => {
            let mut s = s.clone();
            s.faults.clear();
            Some(scene_trace(&s)?)
        }
        _ => None,
    };
    let (apart, counted) =
        counted_alarms(healthy.as_ref().unwrap_or(&trace), &sensors, &faults, &acc);
    let detections: Vec<_> = faults
        .iter()
        .map(|f| {
            let at = match &healthy {
                Some(h) => manifest_time_beside(f, &trace, h),
                None => manifest_time(f, &trace),
            };
            json!({
                "kind": format!("{:?}", f.kind),
                "at_s": f.at_s,
                "manifests_at_s": at,
                "detection_latency_s": at.and_then(|at| latency_after(at, f, &acc)),
            })
        })
        .collect();
    let flags: Vec<_> = acc
        .flags
        .iter()
        .map(|f| json!({"flag": f.flag, "t_s": (f.t_s * trace.sample_rate_hz).round() / trace.sample_rate_hz}))
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
        "input_apart_from_output": apart,
        "false_alarms": counted,
        "functional_test": functional_test,
        "config": a.config.as_ref().map_or("uncommissioned".into(), |p| p.display().to_string()),
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

#[cfg(test)]
mod tests {
    use super::*;

    fn write(name: &str, text: &str) -> String {
        let dir = std::env::temp_dir().join(format!("noback-xtask-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path.to_string_lossy().into_owned()
    }

    #[test]
    fn a_plant_whose_input_comes_apart_counts_no_false_alarm_and_a_stall_counts_its_flags() {
        use noback_twin::reading::Reading;
        // The paper reading's closing at 2 N·m: the input runs on while the output stands
        // (flagged, not counted); the physical drive stalled at 60 N·m: counted, none.
        for (kind, reading, load, want) in [
            (SceneKind::ForwardLoad, Reading::Paper, 2.0, (true, None)),
            (SceneKind::Drive, Reading::Physical, 60.0, (false, Some(0))),
        ] {
            let mut scene = Scene::builtin(kind, reading);
            scene.load_torque_nm = load;
            let trace = scene_trace(&scene).unwrap();
            let acc = compare(&trace, &run_monitor(&trace, Config::default()).unwrap());
            assert_eq!(
                acc.flags.is_empty(),
                !want.0,
                "{kind:?} {:?}",
                acc.flag_times()
            );
            let got = counted_alarms(&trace, &scene.sensors, &scene.faults, &acc);
            assert_eq!(got, want, "{kind:?} {load}");
        }
    }

    #[test]
    fn bad_inputs_exit_with_code_2() {
        let run = |target: &str| {
            main(&MonitorArgs {
                target: target.into(),
                json: false,
                config: None,
                out: std::env::temp_dir(),
            })
        };
        // Unknown scene name, truncated trace, trace from another version.
        assert_eq!(run("no_such_scene"), Ok(EXIT_INPUT));
        let header = noback_twin::trace::HEADER;
        let cols = noback_twin::trace::COLUMNS.join(",");
        let truncated = write(
            "truncated.trace.csv",
            &format!("{header}\n# sample_rate_hz=10000\n{cols}\n0.0000,2048,0,0,1,169.2"),
        );
        assert_eq!(run(&truncated), Ok(EXIT_INPUT));
        let other = write("other.trace.csv", &format!("# noback-trace v9\n{cols}\n"));
        assert_eq!(run(&other), Ok(EXIT_INPUT));
        // A configuration file with an unknown key.
        let config = write("bad.config.toml", "[monitor.thresholds]\nbogus = 1\n");
        let with = MonitorArgs {
            target: "reverse_load".into(),
            json: false,
            config: Some(config.into()),
            out: std::env::temp_dir(),
        };
        assert_eq!(main(&with), Ok(EXIT_INPUT));
    }
}
