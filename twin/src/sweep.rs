//! Design sweeps:
//!
//! - `sweep pressing-force [--out DIR]`: the paper's Figs 23–25, pressing force against load
//!   torque for cone angles 30/45/60°, socket radii 17/20 mm and ball diameters 8.5/9/10 mm,
//!   from the quasi-static law of `noback::mechanism` and, on the 45°/20 mm curve, from the
//!   physical model held at rest under each load (its pack force minus the spring preload).
//! - `sweep PARAM=a..b [--scene S] [--reading R] [--steps N] [--out DIR]`: any `[mechanism]` or
//!   `[open]` key of the scene-file schema over `N` values, charting braking time, angle and
//!   peak braking torque. Runs on two threads and reports progress on stderr.

use crate::cli::default_out_dir;
use crate::metrics::{self, Metrics};
use crate::reading::Reading;
use crate::scene::{Scene, SceneKind};
use crate::sim;
use crate::svg::{self, Panel, Series};
use noback::mechanism::TABLE2;
use std::path::PathBuf;

use crate::args::{self, bad_input};
use clap::Parser;

fn internal(msg: &str) -> i32 {
    eprintln!("xtask sweep: error: {msg}");
    1
}

/// A clap value parser: the number of values, 2..=200.
fn steps_arg(s: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(n) if (2..=200).contains(&n) => Ok(n),
        _ => Err("expected a whole number in 2..=200".into()),
    }
}

/// `cargo xtask sweep`: design sweeps.
#[derive(clap::Args, Debug, Clone)]
pub struct SweepArgs {
    /// `pressing-force` (Figs 23–25) or `PARAM=a..b` (any [mechanism] or [open] key).
    #[arg(value_name = "pressing-force|PARAM=a..b")]
    pub what: String,
    /// Where the CSV and SVG go.
    #[arg(long, value_name = "DIR", default_value_os_t = default_out_dir())]
    pub out: PathBuf,
    /// The built-in scene a parameter sweep runs.
    #[arg(long, value_parser = crate::cli::scene_kind_arg, default_value = "reverse_load")]
    pub scene: SceneKind,
    /// The model reading of a parameter sweep.
    #[arg(long, value_parser = crate::cli::reading_arg, default_value = "physical")]
    pub reading: Reading,
    /// Values in a parameter sweep, 2..=200.
    #[arg(long, allow_hyphen_values = true, value_parser = steps_arg, default_value_t = 5)]
    pub steps: usize,
}

#[derive(Parser)]
#[command(about = "Design sweeps")]
struct SweepCmd {
    #[command(flatten)]
    a: SweepArgs,
}

/// `sweep ...` from raw arguments.
pub fn sweep_main(args: &[String]) -> i32 {
    match args::parse::<SweepCmd>("sweep", args) {
        Ok(c) => sweep_run(&c.a),
        Err(code) => code,
    }
}

/// `sweep` with parsed arguments.
pub fn sweep_run(a: &SweepArgs) -> i32 {
    let (what, out, scene, reading, steps) = (&a.what, &a.out, a.scene, a.reading, a.steps);
    // A bad `PARAM=a..b` or key is bad input, found before any output is written.
    let range = if what == "pressing-force" {
        None
    } else {
        match parse_range(what) {
            Ok((param, lo, hi)) => match scene_with(scene, reading, &param, lo)
                .and_then(|_| scene_with(scene, reading, &param, hi))
            {
                Ok(_) => Some((param, lo, hi)),
                Err(e) => return bad_input("sweep", &e),
            },
            Err(e) => return bad_input("sweep", &e),
        }
    };
    if let Err(e) = std::fs::create_dir_all(out) {
        return internal(&format!("cannot create {}: {e}", out.display()));
    }
    let result = match range {
        None => pressing_force(out),
        Some((param, lo, hi)) => param_sweep(out, &param, lo, hi, steps, scene, reading),
    };
    match result {
        Ok(()) => 0,
        Err(e) => internal(&e),
    }
}

/// Parse `PARAM=a..b`.
pub fn parse_range(s: &str) -> Result<(String, f64, f64), String> {
    let (param, range) = s.split_once('=').ok_or_else(|| {
        format!(
            "`{}`: expected pressing-force or PARAM=a..b",
            args::short(s)
        )
    })?;
    let (a, b) = range
        .split_once("..")
        .ok_or_else(|| format!("`{}`: expected a..b", args::short(range)))?;
    let lo: f64 = a
        .trim()
        .parse()
        .map_err(|_| format!("`{}` is not a number", args::short(a)))?;
    let hi: f64 = b
        .trim()
        .parse()
        .map_err(|_| format!("`{}` is not a number", args::short(b)))?;
    if !(lo.is_finite() && hi.is_finite() && hi > lo) {
        return Err(format!(
            "range {}..{} must be finite and increasing",
            args::num(lo),
            args::num(hi)
        ));
    }
    Ok((param.trim().to_string(), lo, hi))
}

/// The scene with `param = value` applied through the scene-file schema (so names and ranges
/// are checked exactly as in a file).
pub fn scene_with(
    kind: SceneKind,
    reading: Reading,
    param: &str,
    value: f64,
) -> Result<Scene, String> {
    let head = format!(
        "[scene]\nkind = \"{}\"\nreading = \"{}\"\n",
        kind.name(),
        reading.name()
    );
    let mech = format!("{head}[mechanism]\n{param} = {value:?}\n");
    match Scene::from_toml(kind.name(), &mech) {
        Ok(s) => Ok(s),
        Err(e) if e.to_string().contains("unknown field") => {
            let open = format!("{head}[open]\n{param} = {value:?}\n");
            Scene::from_toml(kind.name(), &open).map_err(|e| {
                if e.to_string().contains("unknown field") {
                    format!(
                        "`{}` is neither a [mechanism] nor an [open] key",
                        args::short(param)
                    )
                } else {
                    e.to_string()
                }
            })
        }
        Err(e) => Err(e.to_string()),
    }
}

fn param_sweep(
    out: &std::path::Path,
    param: &str,
    lo: f64,
    hi: f64,
    steps: usize,
    kind: SceneKind,
    reading: Reading,
) -> Result<(), String> {
    let values: Vec<f64> = (0..steps)
        .map(|i| lo + (hi - lo) * i as f64 / (steps - 1) as f64)
        .collect();
    let scenes = values
        .iter()
        .map(|&v| scene_with(kind, reading, param, v))
        .collect::<Result<Vec<Scene>, String>>()?;
    let results = run_parallel(&scenes)?;
    let csv_path = out.join(format!(
        "sweep-{param}-{}-{}.csv",
        kind.name(),
        reading.name()
    ));
    let mut csv = format!(
        "{param},braking_time_s,braking_angle_rad,peak_braking_torque_nm,holding_torque_nm,steps\n"
    );
    for (v, m) in values.iter().zip(&results) {
        let o = |x: Option<f64>| x.map_or(String::new(), |x| format!("{x:.6}"));
        csv.push_str(&format!(
            "{v},{},{},{:.4},{},{}\n",
            o(m.braking_time_s),
            o(m.braking_angle_rad),
            m.peak_braking_torque_nm,
            o(m.holding_torque_nm),
            m.steps
        ));
    }
    std::fs::write(&csv_path, &csv)
        .map_err(|e| format!("cannot write {}: {e}", csv_path.display()))?;
    let col = |f: fn(&Metrics) -> f64| results.iter().map(f).collect::<Vec<f64>>();
    let plot = svg::render_xy(
        &format!(
            "{} ({} reading): sweep of {param}",
            kind.name(),
            reading.name()
        ),
        param,
        &values,
        &[
            Panel {
                title: "braking time (s)",
                series: vec![Series {
                    label: "braking time",
                    color: "#c00",
                    values: col(|m| m.braking_time_s.unwrap_or(f64::NAN)),
                }],
            },
            Panel {
                title: "braking angle (rad)",
                series: vec![Series {
                    label: "braking angle",
                    color: "#06c",
                    values: col(|m| m.braking_angle_rad.unwrap_or(f64::NAN)),
                }],
            },
            Panel {
                title: "peak braking torque (N·m)",
                series: vec![Series {
                    label: "peak torque",
                    color: "#a50",
                    values: col(|m| m.peak_braking_torque_nm),
                }],
            },
        ],
    );
    let svg_path = csv_path.with_extension("svg");
    std::fs::write(&svg_path, plot)
        .map_err(|e| format!("cannot write {}: {e}", svg_path.display()))?;
    print!("{csv}");
    println!("wrote {} and {}", csv_path.display(), svg_path.display());
    Ok(())
}

/// Run scenes on two threads, with progress on stderr.
pub fn run_parallel(scenes: &[Scene]) -> Result<Vec<Metrics>, String> {
    let n = scenes.len();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let threads = 2usize;
    let mut results: Vec<Option<Result<Metrics, String>>> = vec![None; n];
    std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads)
            .map(|k| {
                let done = &done;
                scope.spawn(move || {
                    let mut mine = Vec::new();
                    for (i, s) in scenes.iter().enumerate().filter(|(i, _)| i % threads == k) {
                        let r = sim::run(s)
                            .map(|run| metrics::compute(s, &run.samples, &run.stats, run.wall_s))
                            .map_err(|e| format!("{}: {e}", s.name));
                        let d = done.fetch_add(1, std::sync::atomic::Ordering::SeqCst) + 1;
                        eprintln!("sweep: {d}/{n}");
                        mine.push((i, r));
                    }
                    mine
                })
            })
            .collect();
        for h in handles {
            if let Ok(v) = h.join() {
                for (i, r) in v {
                    if let Some(slot) = results.get_mut(i) {
                        *slot = Some(r);
                    }
                }
            }
        }
    });
    results
        .into_iter()
        .map(|r| r.unwrap_or_else(|| Err("a sweep thread panicked".into())))
        .collect()
}

/// Load torques of the pressing-force sweep (N·m).
pub const SWEEP_TORQUES_NM: [f64; 7] = [0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0];

/// Quasi-static ramp force (N) at cone angle `cone_deg` (from the shaft axis), socket radius
/// `radius_m`, load torque `torque_nm`: `M / (r·tan cone)`.
pub fn ramp_force_n(cone_deg: f64, radius_m: f64, torque_nm: f64) -> f64 {
    let m = noback::mechanism::Mechanism {
        socket_chamfer_rad: (90.0 - cone_deg).to_radians(),
        socket_radius_m: radius_m,
        ..TABLE2
    };
    torque_nm.abs() * m.ramp_factor_per_m()
}

fn pressing_force(out: &std::path::Path) -> Result<(), String> {
    // Physical model check on the design point: hold each load at rest, read the pack force.
    let scenes: Vec<Scene> = SWEEP_TORQUES_NM
        .iter()
        .map(|&t| {
            let mut s = Scene::builtin(SceneKind::Hold, Reading::Physical);
            s.load_torque_nm = t;
            // The held output rings on the contact and spring compliance for ~0.6 s.
            s.duration_s = 1.0;
            s
        })
        .collect();
    let held = run_parallel_samples(&scenes)?;
    let mut csv = String::from("load_torque_nm,cone30_r20_n,cone45_r20_n,cone60_r20_n,cone45_r17_n,ball8_5_r17_n,ball9_r17_n,ball10_r17_n,physical_cone45_r20_n\n");
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); 8];
    for (i, &t) in SWEEP_TORQUES_NM.iter().enumerate() {
        let row = [
            ramp_force_n(30.0, 0.020, t),
            ramp_force_n(45.0, 0.020, t),
            ramp_force_n(60.0, 0.020, t),
            ramp_force_n(45.0, 0.017, t),
            // The ball diameter does not enter the torque–force conversion (paper §5): the three
            // curves coincide with the 45°/17 mm one.
            ramp_force_n(45.0, 0.017, t),
            ramp_force_n(45.0, 0.017, t),
            ramp_force_n(45.0, 0.017, t),
            held.get(i).copied().unwrap_or(f64::NAN) - TABLE2.spring_preload_n(),
        ];
        csv.push_str(&format!("{t}"));
        for (c, v) in row.iter().enumerate() {
            csv.push_str(&format!(",{v:.2}"));
            if let Some(col) = cols.get_mut(c) {
                col.push(*v);
            }
        }
        csv.push('\n');
    }
    let path = out.join("sweep-pressing-force.csv");
    std::fs::write(&path, &csv).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    let c = |i: usize| cols.get(i).cloned().unwrap_or_default();
    let plot = svg::render_xy(
        "Pressing force against load torque (paper Figs 23–25)",
        "N·m",
        &SWEEP_TORQUES_NM,
        &[
            Panel {
                title: "cone angle, r = 20 mm (N)",
                series: vec![
                    Series {
                        label: "30°",
                        color: "#c00",
                        values: c(0),
                    },
                    Series {
                        label: "45°",
                        color: "#080",
                        values: c(1),
                    },
                    Series {
                        label: "60°",
                        color: "#06c",
                        values: c(2),
                    },
                    Series {
                        label: "45°, physical model held",
                        color: "#000",
                        values: c(7),
                    },
                ],
            },
            Panel {
                title: "socket radius, 45° (N)",
                series: vec![
                    Series {
                        label: "17 mm",
                        color: "#c00",
                        values: c(3),
                    },
                    Series {
                        label: "20 mm",
                        color: "#06c",
                        values: c(1),
                    },
                ],
            },
            Panel {
                title: "ball diameter, 45°, 17 mm (N)",
                series: vec![
                    Series {
                        label: "8.5 mm",
                        color: "#c00",
                        values: c(4),
                    },
                    Series {
                        label: "9 mm",
                        color: "#080",
                        values: c(5),
                    },
                    Series {
                        label: "10 mm",
                        color: "#06c",
                        values: c(6),
                    },
                ],
            },
        ],
    );
    let spath = out.join("sweep-pressing-force.svg");
    std::fs::write(&spath, plot).map_err(|e| format!("cannot write {}: {e}", spath.display()))?;
    print!("{csv}");
    let fpath = out.join("sweep-pressing-force-friction.csv");
    let fcsv = crate::ramp_friction::csv();
    std::fs::write(&fpath, &fcsv).map_err(|e| format!("cannot write {}: {e}", fpath.display()))?;
    print!("{fcsv}");
    println!(
        "wrote {}, {} and {}",
        path.display(),
        spath.display(),
        fpath.display()
    );
    Ok(())
}

fn run_parallel_samples(scenes: &[Scene]) -> Result<Vec<f64>, String> {
    let mut out = Vec::new();
    for s in scenes {
        let run = sim::run(s).map_err(|e| format!("{}: {e}", s.name))?;
        out.push(run.samples.last().map_or(f64::NAN, |x| x.pressing_force_n));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pressing_force_trends_follow_the_paper() {
        let t = 20.0;
        assert!(ramp_force_n(30.0, 0.02, t) > ramp_force_n(45.0, 0.02, t));
        assert!(ramp_force_n(45.0, 0.02, t) > ramp_force_n(60.0, 0.02, t));
        assert!(ramp_force_n(45.0, 0.017, t) > ramp_force_n(45.0, 0.02, t));
        // Linear in the load torque.
        let f10 = ramp_force_n(45.0, 0.02, 10.0);
        assert!((ramp_force_n(45.0, 0.02, 20.0) - 2.0 * f10).abs() < 1e-9);
    }

    #[test]
    fn range_and_parameter_errors() {
        assert_eq!(
            parse_range("mu_static=0.2..0.4").unwrap(),
            ("mu_static".into(), 0.2, 0.4)
        );
        assert!(parse_range("mu_static=0.4..0.2").is_err());
        assert!(parse_range("mu_static").is_err());
        assert!(scene_with(SceneKind::Hold, Reading::Paper, "mu_static", 0.25).is_ok());
        assert!(scene_with(
            SceneKind::Hold,
            Reading::Paper,
            "approach_speed_floor_m_s",
            0.1
        )
        .is_ok());
        let e = scene_with(SceneKind::Hold, Reading::Paper, "warp", 1.0).unwrap_err();
        assert!(e.contains("warp"), "{e}");
        let e = scene_with(SceneKind::Hold, Reading::Paper, "restitution", 3.0).unwrap_err();
        assert!(e.contains("mechanism.restitution"), "{e}");
    }
}
