//! Command-line entry points, wired into `cargo xtask twin|paper|sweep` by the lead:
//!
//! - `twin SCENE|FILE [--reading paper|physical] [--out DIR] [--json] [--tolerance TOL]`
//! - `paper [--json] [--out FILE] [--tolerance TOL]`
//! - `sweep pressing-force [--out DIR]` and `sweep PARAM=a..b [--scene S] [--steps N] [--reading R] [--out DIR]`
//!
//! Parsing is clap's, by the convention of `crate::args`: a bad argument or input prints one
//! line naming it and returns exit code 2; a file that cannot be written returns 1.

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

pub use crate::args::EXIT_USAGE;
use crate::args::{self, bad_input};
use clap::Parser;

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

/// An internal failure (a file that cannot be written): exit 1.
fn internal(prog: &str, msg: &str) -> i32 {
    eprintln!("xtask {prog}: error: {msg}");
    1
}

/// Default output directory for runs.
pub fn default_out_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/twin")
}

/// A clap value parser: `paper` or `physical`.
pub fn reading_arg(s: &str) -> Result<Reading, String> {
    Reading::parse(s).ok_or_else(|| "expected paper or physical".into())
}

/// A clap value parser: a built-in scene name.
pub fn scene_kind_arg(s: &str) -> Result<SceneKind, String> {
    SceneKind::parse(s).ok_or_else(|| format!("not a built-in scene ({BUILTINS})"))
}

/// The built-in scenes, as messages list them.
pub const BUILTINS: &str =
    "reverse_load, forward_load, continuous_closing, hold, drive, functional_test";

/// `cargo xtask twin`: run the digital twin on one scene.
#[derive(clap::Args, Debug, Clone)]
pub struct TwinArgs {
    /// A built-in scene (reverse_load, forward_load, continuous_closing, hold, drive) or a TOML
    /// scene file.
    #[arg(value_name = "SCENE|FILE")]
    pub target: String,
    /// The model reading (default: the scene's, physical for built-ins).
    #[arg(long, value_parser = reading_arg, value_name = "paper|physical")]
    pub reading: Option<Reading>,
    /// Where the CSV, the trace and the SVG go.
    #[arg(long, value_name = "DIR", default_value_os_t = default_out_dir())]
    pub out: PathBuf,
    /// Print the metrics as one JSON object.
    #[arg(long)]
    pub json: bool,
    /// The integrator's tolerance, in (1e-10, 1e-2).
    #[arg(long, allow_hyphen_values = true, value_parser = args::tolerance, value_name = "TOL")]
    pub tolerance: Option<f64>,
}

#[derive(Parser)]
#[command(about = "Run the digital twin on one scene")]
struct TwinCmd {
    #[command(flatten)]
    a: TwinArgs,
}

/// Load a scene by built-in name or TOML file path.
pub fn load_scene(target: &str, reading: Option<Reading>) -> Result<Scene, String> {
    let mut scene = if let Some(kind) = SceneKind::parse(target) {
        Scene::builtin(kind, reading.unwrap_or_default())
    } else {
        let path = Path::new(target);
        if !path.is_file() {
            return Err(format!(
                "`{}` is neither a built-in scene ({BUILTINS}) nor a file",
                args::short(target)
            ));
        }
        Scene::from_file(path).map_err(|e| format!("{}: {e}", args::short(target)))?
    };
    if let Some(r) = reading {
        scene.reading = r;
    }
    Ok(scene)
}

/// `twin SCENE|FILE [--reading paper|physical] [--out DIR] [--json]` from raw arguments.
pub fn twin_main(args: &[String]) -> i32 {
    match args::parse::<TwinCmd>("twin", args) {
        Ok(c) => twin_run(&c.a),
        Err(code) => code,
    }
}

/// `twin` with parsed arguments.
pub fn twin_run(a: &TwinArgs) -> i32 {
    let mut scene = match load_scene(&a.target, a.reading) {
        Ok(s) => s,
        Err(e) => return bad_input("twin", &e),
    };
    if let Some(t) = a.tolerance {
        scene.tolerance = t;
    }
    let run = match sim::run(&scene) {
        Ok(r) => r,
        Err(e) => return bad_input("twin", &format!("scene {}: {e}", scene.name)),
    };
    let m = metrics::compute(&scene, &run.samples, &run.stats, run.wall_s);
    let stem = format!("{}-{}", scene.name, scene.reading.name());
    if let Err(e) = write_outputs(&a.out, &stem, &scene, &run.samples) {
        return internal("twin", &e);
    }
    if a.json {
        match serde_json::to_string(&m) {
            Ok(s) => println!("{s}"),
            Err(e) => return internal("twin", &format!("json: {e}")),
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

/// `cargo xtask paper`: the paper's scenes under both readings.
#[derive(clap::Args, Debug, Clone)]
pub struct PaperArgs {
    /// Print the table as one JSON object (and write nothing).
    #[arg(long)]
    pub json: bool,
    /// Where the page goes.
    #[arg(long, value_name = "FILE", default_value_os_t = default_paper_doc())]
    pub out: PathBuf,
    /// The integrator's tolerance, in (1e-10, 1e-2).
    #[arg(long, allow_hyphen_values = true, value_parser = args::tolerance, value_name = "TOL", default_value_t = 1e-5)]
    pub tolerance: f64,
}

#[derive(Parser)]
#[command(about = "The paper's scenes under both readings")]
struct PaperCmd {
    #[command(flatten)]
    a: PaperArgs,
}

/// `paper [--json] [--out FILE] [--tolerance TOL]` from raw arguments.
pub fn paper_main(args: &[String]) -> i32 {
    match args::parse::<PaperCmd>("paper", args) {
        Ok(c) => paper_run(&c.a),
        Err(code) => code,
    }
}

/// `paper` with parsed arguments: the paper protocol (fixed tolerances) and every figure of both
/// readings (at TOL); writes docs/paper-comparison.md, or with `--json` prints JSON and writes
/// nothing.
pub fn paper_run(a: &PaperArgs) -> i32 {
    let (json, out, tolerance) = (a.json, &a.out, a.tolerance);
    let page = match paper_page::build(tolerance) {
        Ok(t) => t,
        Err(e) => return internal("paper", &format!("paper scenes: {e}")),
    };
    if json {
        match serde_json::to_string(&page) {
            Ok(s) => println!("{s}"),
            Err(e) => return internal("paper", &format!("json: {e}")),
        }
        return 0;
    }
    if let Err(e) = std::fs::write(out, page.markdown()) {
        return internal("paper", &format!("cannot write {}: {e}", out.display()));
    }
    print!("{}", page.markdown());
    println!("\nwrote {}", out.display());
    0
}
