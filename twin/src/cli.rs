//! Command-line entry points, wired into `cargo xtask twin|paper|sweep` by the lead:
//!
//! - `twin SCENE|FILE [--reading paper|physical] [--out DIR] [--json] [--tolerance TOL]`
//! - `paper [--json] [--out FILE] [--tolerance TOL]`
//! - `sweep pressing-force [--out DIR]` and `sweep PARAM=a..b [--scene S] [--steps N] [--reading R] [--out DIR]`
//!
//! Every error prints one clear line on stderr and returns exit code 2.

use crate::metrics::{self, Metrics};
use crate::model::Sample;
use crate::paper_page;
use crate::reading::Reading;
use crate::scene::{Scene, SceneKind};
use crate::sensing;
use crate::sim::{self, SAMPLE_RATE_HZ};
use crate::svg::{self, Panel, Series};
use std::io::Write;
use std::path::{Path, PathBuf};

pub use crate::sweep::sweep_main;

/// Exit code of a usage or input error.
pub const EXIT_USAGE: i32 = 2;

/// Dispatch `twin ...`, `paper ...` or `sweep ...` by the first argument (for the example
/// binary); anything else is taken as `twin` arguments.
pub fn dispatch(args: &[String]) -> i32 {
    match args.first().map(String::as_str) {
        Some("paper") => paper_main(args.get(1..).unwrap_or(&[])),
        Some("sweep") => crate::sweep::sweep_main(args.get(1..).unwrap_or(&[])),
        Some("twin") => twin_main(args.get(1..).unwrap_or(&[])),
        _ => twin_main(args),
    }
}

fn fail(msg: &str) -> i32 {
    eprintln!("error: {msg}");
    EXIT_USAGE
}

/// Default output directory for runs.
pub fn default_out_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/twin")
}

struct TwinArgs {
    target: String,
    reading: Option<Reading>,
    out: PathBuf,
    json: bool,
    tolerance: Option<f64>,
}

fn parse_twin_args(args: &[String]) -> Result<TwinArgs, String> {
    let mut it = args.iter();
    let mut a = TwinArgs {
        target: String::new(),
        reading: None,
        out: default_out_dir(),
        json: false,
        tolerance: None,
    };
    while let Some(arg) = it.next() {
        match arg.as_str() {
            "--reading" => {
                let v = it.next().ok_or("--reading needs paper or physical")?;
                a.reading = Some(
                    Reading::parse(v)
                        .ok_or_else(|| format!("--reading `{v}`: expected paper or physical"))?,
                );
            }
            "--out" => a.out = PathBuf::from(it.next().ok_or("--out needs a directory")?),
            "--json" => a.json = true,
            "--tolerance" => {
                let v = it.next().ok_or("--tolerance needs a number")?;
                let t: f64 = v
                    .parse()
                    .map_err(|_| format!("--tolerance `{v}` is not a number"))?;
                if !(t > 1e-10 && t < 1e-2) {
                    return Err(format!("--tolerance {t} is out of range (1e-10, 1e-2)"));
                }
                a.tolerance = Some(t);
            }
            s if s.starts_with("--") => return Err(format!("unknown option `{s}`")),
            s => {
                if !a.target.is_empty() {
                    return Err(format!("unexpected argument `{s}` (one scene per run)"));
                }
                a.target = s.to_string();
            }
        }
    }
    if a.target.is_empty() {
        return Err("usage: twin SCENE|FILE [--reading paper|physical] [--out DIR] [--json] [--tolerance TOL]; scenes: reverse_load forward_load continuous_closing hold drive".into());
    }
    Ok(a)
}

/// Load a scene by built-in name or TOML file path.
pub fn load_scene(target: &str, reading: Option<Reading>) -> Result<Scene, String> {
    let mut scene = if let Some(kind) = SceneKind::parse(target) {
        Scene::builtin(kind, reading.unwrap_or_default())
    } else {
        let path = Path::new(target);
        if !path.exists() {
            return Err(format!("`{target}` is neither a built-in scene (reverse_load, forward_load, continuous_closing, hold, drive) nor a file"));
        }
        Scene::from_file(path).map_err(|e| format!("{}: {e}", path.display()))?
    };
    if let Some(r) = reading {
        scene.reading = r;
    }
    Ok(scene)
}

/// `twin SCENE|FILE [--reading paper|physical] [--out DIR] [--json]`.
pub fn twin_main(args: &[String]) -> i32 {
    let a = match parse_twin_args(args) {
        Ok(a) => a,
        Err(e) => return fail(&e),
    };
    let mut scene = match load_scene(&a.target, a.reading) {
        Ok(s) => s,
        Err(e) => return fail(&e),
    };
    if let Some(t) = a.tolerance {
        scene.tolerance = t;
    }
    let run = match sim::run(&scene) {
        Ok(r) => r,
        Err(e) => return fail(&format!("scene {}: {e}", scene.name)),
    };
    let m = metrics::compute(&scene, &run.samples, &run.stats, run.wall_s);
    let stem = format!("{}-{}", scene.name, scene.reading.name());
    if let Err(e) = write_outputs(&a.out, &stem, &scene, &run.samples) {
        return fail(&e);
    }
    if a.json {
        match serde_json::to_string(&m) {
            Ok(s) => println!("{s}"),
            Err(e) => return fail(&format!("json: {e}")),
        }
    } else {
        print_summary(&m, &a.out, &stem);
    }
    0
}

fn print_summary(m: &Metrics, out: &Path, stem: &str) {
    let o = |v: Option<f64>| v.map_or("—".to_string(), |v| format!("{v:.4}"));
    println!("scene {} ({} reading)", m.scene, m.reading);
    println!(
        "  braking time {} s, angle {} rad, contact lag {} s",
        o(m.braking_time_s),
        o(m.braking_angle_rad),
        o(m.contact_lag_s)
    );
    println!(
        "  holding {} N·m, peak {:.2} / trough {:.2} N·m, period {} s",
        o(m.holding_torque_nm),
        m.peak_braking_torque_nm,
        m.trough_braking_torque_nm,
        o(m.period_s)
    );
    println!(
        "  max output speed {:.3} rad/s, {} reversals",
        m.max_output_speed_rad_s, m.output_reversals
    );
    println!(
        "  solver: {} steps, {} rejected, {} RHS evaluations, {} events, {:.3} s",
        m.steps, m.rejected_steps, m.rhs_evals, m.events, m.wall_s
    );
    println!(
        "  wrote {}/{stem}.csv, {stem}.trace.csv, {stem}.svg",
        out.display()
    );
}

/// Write the time history (CSV), the sensor trace (v1) and the SVG plot.
pub fn write_outputs(
    out: &Path,
    stem: &str,
    scene: &Scene,
    samples: &[Sample],
) -> Result<(), String> {
    std::fs::create_dir_all(out).map_err(|e| format!("cannot create {}: {e}", out.display()))?;
    let hist = out.join(format!("{stem}.csv"));
    write_history(&hist, samples).map_err(|e| format!("cannot write {}: {e}", hist.display()))?;
    let trace = sensing::trace(
        samples,
        &scene.sensors,
        &scene.noise,
        &scene.faults,
        SAMPLE_RATE_HZ,
    );
    let tpath = out.join(format!("{stem}.trace.csv"));
    trace
        .write(&tpath)
        .map_err(|e| format!("cannot write {}: {e}", tpath.display()))?;
    let svg = plot(
        &format!("{} — {} reading", scene.name, scene.reading.name()),
        samples,
    );
    let spath = out.join(format!("{stem}.svg"));
    std::fs::write(&spath, svg).map_err(|e| format!("cannot write {}: {e}", spath.display()))?;
    Ok(())
}

/// Time-history CSV header (the full truth; the sensor trace is the separate v1 format).
pub const HISTORY_HEADER: &str = "# noback-twin history v1";

fn write_history(path: &Path, samples: &[Sample]) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(w, "{HISTORY_HEADER}")?;
    writeln!(w, "t_s,output_angle_rad,output_speed_rad_s,input_angle_rad,input_speed_rad_s,drive_torque_nm,drive_on,pressing_force_n,braking_torque_nm,brake_state,contact_force_n,input_contact_force_n,ball_axial_m,shaft_axial_m")?;
    for s in samples {
        writeln!(
            w,
            "{:.4},{:.7},{:.6},{:.7},{:.6},{:.4},{},{:.3},{:.4},{},{:.3},{:.3},{:.4e},{:.4e}",
            s.t_s,
            s.output_angle_rad,
            s.output_speed_rad_s,
            s.input_angle_rad,
            s.input_speed_rad_s,
            s.drive_torque_nm,
            u8::from(s.drive_on),
            s.pressing_force_n,
            s.braking_torque_nm,
            s.brake_state,
            s.contact_force_n,
            s.input_contact_force_n,
            s.ball_axial_m,
            s.shaft_axial_m
        )?;
    }
    w.flush()
}

fn plot(title: &str, samples: &[Sample]) -> String {
    let t: Vec<f64> = samples.iter().map(|s| s.t_s).collect();
    let col = |f: fn(&Sample) -> f64| samples.iter().map(f).collect::<Vec<f64>>();
    svg::render(
        title,
        &t,
        &[
            Panel {
                title: "force (N)",
                series: vec![
                    Series {
                        label: "pressing force",
                        color: "#c00",
                        values: col(|s| s.pressing_force_n),
                    },
                    Series {
                        label: "contact force (one output ball)",
                        color: "#06c",
                        values: col(|s| s.contact_force_n),
                    },
                ],
            },
            Panel {
                title: "braking torque (N·m)",
                series: vec![Series {
                    label: "braking torque",
                    color: "#a50",
                    values: col(|s| s.braking_torque_nm),
                }],
            },
            Panel {
                title: "speed (rad/s)",
                series: vec![
                    Series {
                        label: "output",
                        color: "#080",
                        values: col(|s| s.output_speed_rad_s),
                    },
                    Series {
                        label: "input",
                        color: "#888",
                        values: col(|s| s.input_speed_rad_s),
                    },
                ],
            },
            Panel {
                title: "output angle (rad)",
                series: vec![Series {
                    label: "output angle",
                    color: "#608",
                    values: col(|s| s.output_angle_rad),
                }],
            },
            Panel {
                title: "axial position (mm)",
                series: vec![
                    Series {
                        label: "output balls",
                        color: "#06c",
                        values: col(|s| s.ball_axial_m * 1e3),
                    },
                    Series {
                        label: "big connecting shaft",
                        color: "#c00",
                        values: col(|s| s.shaft_axial_m * 1e3),
                    },
                ],
            },
        ],
    )
}

/// Where `paper` writes its table by default.
pub fn default_paper_doc() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../docs/paper-comparison.md")
}

/// `paper [--json] [--out FILE] [--tolerance TOL]`: the paper protocol (fixed tolerances) and
/// every figure of both readings (at TOL); writes docs/paper-comparison.md, or with `--json`
/// prints JSON and writes nothing.
pub fn paper_main(args: &[String]) -> i32 {
    let mut json = false;
    let mut out = default_paper_doc();
    let mut tolerance = 1e-5;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--json" => json = true,
            "--out" => match it.next() {
                Some(p) => out = PathBuf::from(p),
                None => return fail("--out needs a file"),
            },
            "--tolerance" => match it.next().and_then(|v| v.parse::<f64>().ok()) {
                Some(t) if t > 1e-10 && t < 1e-2 => tolerance = t,
                _ => return fail("--tolerance needs a number in (1e-10, 1e-2)"),
            },
            s => {
                return fail(&format!(
                    "unknown argument `{s}`; usage: paper [--json] [--out FILE] [--tolerance TOL]"
                ))
            }
        }
    }
    let page = match paper_page::build(tolerance) {
        Ok(t) => t,
        Err(e) => return fail(&format!("paper scenes: {e}")),
    };
    if json {
        // JSON goes to stdout only; the page is written only without --json.
        match serde_json::to_string(&page) {
            Ok(s) => println!("{s}"),
            Err(e) => return fail(&format!("json: {e}")),
        }
        return 0;
    }
    if let Err(e) = std::fs::write(&out, page.markdown()) {
        return fail(&format!("cannot write {}: {e}", out.display()));
    }
    print!("{}", page.markdown());
    println!("\nwrote {}", out.display());
    0
}
