//! `cargo xtask commission RUN [RUN…] [--load-nm L]… [--as-built FILE] [--out FILE] [--json]` — the unit's
//! settings from its recorded acceptance runs (`host_tests::commission`), written as the
//! monitor's configuration file (`host_tests::config_file`).

use crate::replay::trace_of;
use host_tests::as_built::AsBuilt;
use host_tests::dormant::{accept, procedure_of};
use noback::monitor::functional_test::Procedure;
use noback::monitor::{Config, DrivingPack};
use noback_twin::args::bad_input;
use noback_twin::scene::SceneKind;
use noback_twin::trace::Trace;
use serde_json::json;
use std::path::PathBuf;

/// `cargo xtask commission`'s options.
#[derive(clap::Args, Debug)]
pub struct CommissionArgs {
    /// The acceptance runs, each a built-in scene, a TOML scene file or a recorded trace
    /// (`.csv`): the drive opens against (or closes with) a known load, is cut, and the brake
    /// holds; two openings at loads 5 N·m or more apart also give the current's gain, two
    /// closings so the overrunning line (docs/commissioning.md). A `functional_test` scene
    /// sets the test's expected breakaway (at 1 N·m or less, a spring-only pack's uncoupled push).
    #[arg(value_name = "SCENE|FILE|TRACE.csv", required = true)]
    pub targets: Vec<String>,
    /// The load the crew applied in each run, in order (N·m); a scene's own load when not given,
    /// required for a trace.
    #[arg(long, value_name = "NM", allow_hyphen_values = true)]
    pub load_nm: Vec<f64>,
    /// The unit's build record (`[as_built]`: spring_preload_n, socket_radius_m,
    /// socket_chamfer_rad, pack_inner_radius_m, pack_outer_radius_m): the pack's model is set from
    /// it in place of Table 2's (docs/commissioning.md, "The build record").
    #[arg(long, value_name = "FILE")]
    pub as_built: Option<PathBuf>,
    /// Where the configuration file goes (default: printed).
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Print what was identified as one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// Entry.
pub fn main(a: &CommissionArgs) -> Result<i32, String> {
    if !a.load_nm.is_empty() && a.load_nm.len() != a.targets.len() {
        return Ok(bad_input(
            "commission",
            &format!(
                "--load-nm: {} given for {} runs (one per run, in order)",
                a.load_nm.len(),
                a.targets.len()
            ),
        ));
    }
    // The record first: a bad one is refused before any acceptance run is read.
    let base = match &a.as_built {
        None => Config::default(),
        Some(path) => match std::fs::read_to_string(path)
            .map_err(|e| e.to_string())
            .and_then(|text| AsBuilt::parse(&text))
        {
            Ok(r) => r.config(),
            Err(e) => return Ok(bad_input("commission", &format!("{}: {e}", path.display()))),
        },
    };
    let mut runs = Vec::new();
    // The unit's functional tests at acceptance: (trace, its scene), set after the rest.
    let mut test_runs = Vec::new();
    for (i, target) in a.targets.iter().enumerate() {
        let (trace, scene_load) = match trace_of(target) {
            Ok((trace, Some(scene))) if scene.kind == SceneKind::FunctionalTest => {
                test_runs.push((trace, scene));
                continue;
            }
            Ok((trace, scene)) => (trace, scene.map(|s| s.load_torque_nm)),
            Err(e) => return Ok(bad_input("commission", &e)),
        };
        let Some(load) = a.load_nm.get(i).copied().or(scene_load) else {
            return Ok(bad_input(
                "commission",
                &format!(
                    "{}: a trace needs --load-nm, the load the crew applied",
                    noback_twin::args::short(target)
                ),
            ));
        };
        runs.push((trace, load));
    }
    let pairs: Vec<(&Trace, f64)> = runs.iter().map(|(t, l)| (t, *l)).collect();
    let mut c = match host_tests::commission::commission_with(&pairs, base) {
        Ok(c) => c,
        Err(e) => return Ok(bad_input("commission", &e)),
    };
    let mut test_note = String::new();
    let mut tests: Vec<_> = test_runs
        .iter()
        .map(|(trace, scene)| (procedure_of(scene), trace, scene))
        .collect();
    // The loaded push first: the uncoupled one runs on its drive and timing.
    tests.sort_by_key(|((kind, _), _, _)| *kind == Procedure::Uncoupled);
    if tests
        .first()
        .is_some_and(|t| t.0 .0 == Procedure::Uncoupled)
    {
        // Its acceptance has a floor only: the loaded push judges a dragging pack.
        return Ok(bad_input(
            "commission",
            "the uncoupled push needs the loaded functional_test run beside it",
        ));
    }
    if tests.windows(2).any(|w| w[0].0 .0 == w[1].0 .0) {
        return Ok(bad_input(
            "commission",
            "two functional tests of one procedure given: one loaded and one uncoupled at most",
        ));
    }
    for ((kind, procedure), trace, scene) in tests {
        let name = kind.name();
        if kind == Procedure::Uncoupled && c.config.driving_pack != DrivingPack::SpringOnly {
            return Ok(bad_input(
                "commission",
                "the uncoupled push is for a spring-only pack; these runs identified a relieved one",
            ));
        }
        let Some(mut t) = (match accept(trace, c.config, (kind, &procedure), scene.test.start_s) {
            Ok(t) => t,
            Err(e) => return Ok(bad_input("commission", &format!("the {name} push: {e}"))),
        }) else {
            return Ok(bad_input(
                "commission",
                &format!("the {name} acceptance push failed: the unit is not healthy"),
            ));
        };
        // The file carries the acceptance readings to the millinewton-metre.
        let mn = |x: Option<f64>| x.map(|v| (v * 1e3).round() / 1e3);
        t.expected_breakaway_nm = mn(t.expected_breakaway_nm);
        t.expected_opening_nm = mn(t.expected_opening_nm);
        let b = t.expected_breakaway_nm.unwrap_or(0.0);
        let opening = t
            .expected_opening_nm
            .map_or(String::new(), |o| format!(", opening {o} N·m"));
        kind.set_test(&mut c.config, t);
        test_note += &format!(
            ", {name} functional test breakaway {b} N·m{opening} at {} N·m",
            procedure.load_nm
        );
    }
    let loads: Vec<String> = runs.iter().map(|(_, l)| format!("{l}")).collect();
    let comment = format!(
        "cargo xtask commission {} (loads {} N·m): current offset {:.3} A, gain {:.4}, drag while driving {:.3} N·m, braking against the load {:.3} of capacity",
        a.targets.iter().map(|t| noback_twin::args::short(t)).collect::<Vec<_>>().join(" "),
        loads.join(", "),
        c.current_offset_a,
        c.gain,
        c.drive_drag_nm,
        c.braking_share
    ) + &test_note
        + &a.as_built.as_ref().map_or(String::new(), |p| {
            format!(", build record {}", noback_twin::args::short(&p.to_string_lossy()))
        });
    let text = host_tests::config_file::write(&c.config, &comment)?;
    if let Some(path) = &a.out {
        std::fs::write(path, &text).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    if a.json {
        let runs: Vec<_> = c
            .runs
            .iter()
            .map(|f| {
                json!({
                    "run": a.targets.get(f.run),
                    "load_nm": f.load_nm,
                    "cut_s": f.cut_s,
                    "drive_speed_rad_s": f.drive_speed_rad_s,
                    "drive_torque_nm": f.drive_torque_nm,
                    "hold_current_a": f.hold_current_a,
                    "braking_time_s": f.braking_time_s,
                    "braking_nm": f.braking_nm,
                    "braking_share": f.braking_share,
                    "decel_rad_s2": f.decel_rad_s2,
                    "closing": f.closing,
                })
            })
            .collect();
        println!(
            "{}",
            json!({
                "runs": runs,
                "current_offset_a": c.current_offset_a,
                "gain": c.gain,
                "drive_drag_nm": c.drive_drag_nm,
                "braking_share": c.braking_share,
                "sliding_mu": c.config.sliding_mu,
                "driving_pack": format!("{:?}", c.config.driving_pack),
                "aiding_braking": c.aiding.map(|b| json!({
                    "inertia_kg_m2": b.inertia_kg_m2,
                    "drag_nm": b.drag_nm,
                    "load_gain": b.load_gain,
                })),
                "overrun_line": c.config.overrun_line.map(|l| json!({
                    "gain": l.gain,
                    "offset_nm": l.offset_nm,
                })),
                "lock_times": c.config.lock_times.map(|l| json!({
                    "along_s": l.along_s,
                    "against_s": l.against_s,
                })),
                "config_file": text,
            })
        );
    } else if a.out.is_none() {
        print!("{text}");
    } else {
        eprintln!("{comment}");
    }
    Ok(0)
}
