//! `cargo xtask bench [--quick] [--json]` — speed against accuracy (issue 6).
//!
//! 1. The twin's `paper` reading at its tightest tolerance is the reference of the reduced model
//!    (`noback_study::reduced`): the reduced model is that reading's quasi-static physics at a
//!    fixed step, so this isolates the error of format, integrator and rate.
//! 2. Every format × integrator × rate of the reduced model on `reverse_load` and
//!    `forward_load`: output-angle and speed RMS, pressing-force RMS (% of the loaded force),
//!    braking-torque RMS, lock-time error; host ns per step (criterion,
//!    `study/benches/reduced_step.rs`); Cortex-M3 instructions per step under QEMU
//!    (`noback-study`'s `noback-bench`, `-icount shift=10`), and per simulated second.
//! 3. The twin itself at several tolerances, both readings, against its tightest run.
//! 4. The full physical model (`TwinModel::rhs`) with explicit Euler and RK4 at fixed steps from
//!    0.5 µs up past their stability limit, varying contact stiffness, the connecting-shaft
//!    inertia (inertia ratio) and μ one at a time: stable, diverged or
//!    inaccurate (`bench/explicit.rs`).
//! 5. The shipped monitor's cost (`cargo xtask run`'s replay on the M3).
//!
//! Writes `docs/results/speed-accuracy.csv` and `.svg`, `docs/results/stability.csv` and
//! `.svg`, `docs/results/cheapest-per-scene.md`, `docs/results/cost-by-core.md` (instruction
//! counts and errors: the same bytes on every run) and the benchmark page
//! `docs/results/host-speed.md` (host wall times, with the machine); with `--json`, only prints.

pub mod charts;
pub mod explicit;
mod host_speed;
mod pages;
mod stability_map;
mod variants;
pub mod work_precision;

use variants::{
    criterion_ns, errors, reference, run_criterion, run_quasi_static, run_reduced_by_name, Errors,
    Row, FORMATS,
};

use crate::cores::Core;
use crate::qemu::{self, Boot};
use crate::shell::workspace_root;
use noback_study::reduced::{BrakingScene, Method};
use noback_twin::model::Sample;
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::sim::run;
use std::time::Instant;

/// The label of the quasi-static candidate in the tables (the monitor's
/// `SceneModel::QuasiStatic` has the same).
pub const QUASI_STATIC_LABEL: &str = "quasi-static (no state)";
/// The label of the monitor's model while overrunning (continuous closing).
pub const EQUILIBRIUM_LABEL: &str = "quasi-static equilibrium";

/// Rates of the reduced model (Hz).
pub const RATES: [u32; 6] = [1_000, 2_000, 5_000, 10_000, 20_000, 50_000];
/// Tightest tolerance of the twin: the reference.
pub const REF_TOL: f64 = 1e-10;
/// One row of the speed-accuracy table.
#[derive(Clone, Debug)]
struct Variant {
    family: String,
    format: String,
    method: String,
    rate_hz: f64,
    scene: &'static str,
    e: Errors,
    /// Errors against the physical reading (the one the monitor follows), braking scenes only.
    e_phys: Option<Errors>,
    m3_insns_per_step: Option<f64>,
    host_ns_per_step: f64,
    rhs_evals: f64,
}

impl Variant {
    fn m3_per_s(&self) -> Option<f64> {
        self.m3_insns_per_step.map(|i| i * self.rate_hz)
    }
    fn label(&self) -> String {
        if self.family == "quasi-static" {
            return QUASI_STATIC_LABEL.to_string();
        }
        format!(
            "{} {} {} {}",
            self.family,
            self.format,
            self.method,
            if self.rate_hz > 0.0 {
                format!("{} kHz", self.rate_hz / 1e3)
            } else {
                String::new()
            }
        )
    }
}

/// Instructions per step (mean, max) of every format × integrator on `core`, from
/// `noback-bench` under QEMU.
fn core_costs(core: Core, echo: bool) -> Result<Vec<(String, String, f64, f64)>, String> {
    let elf = crate::run::build_package_bin("noback-study", "noback-bench", core, None, &[])?;
    let shift = crate::run::BENCH_SHIFT;
    let out = qemu::boot(&Boot {
        elf: &elf,
        core,
        timeout: qemu::BOOT_TIMEOUT,
        extra: qemu::icount(shift),
        echo,
        args: Vec::new(),
    })?;
    if out.code != 0 {
        return Err(format!("noback-bench exited with code {}", out.code));
    }
    let mut v = Vec::new();
    for line in out
        .lines
        .iter()
        .filter(|l| l.split_whitespace().nth(1) == Some("variant"))
    {
        let f = crate::run::fields(line);
        let get = |k: &str| f.get(k).copied().unwrap_or("");
        let (mean, max) = crate::run::step_insns(&f, core)?;
        v.push((get("fmt").to_string(), get("method").to_string(), mean, max));
    }
    if !out.lines.iter().any(|l| l.contains("bench-done")) {
        return Err("noback-bench did not finish".into());
    }
    Ok(v)
}

fn opt(v: Option<f64>) -> String {
    v.map_or(String::new(), |x| format!("{x:.6e}"))
}

/// Entry.
pub fn main(args: &[String]) -> Result<i32, String> {
    let mut quick = false;
    let mut json = false;
    for a in args {
        match a.as_str() {
            "--quick" => quick = true,
            "--json" => json = true,
            other => {
                return Err(format!(
                    "unknown argument `{other}` (bench [--quick] [--json])"
                ))
            }
        }
    }
    let t0 = Instant::now();
    crate::bootstrap::ensure_all()?;
    let reps = if quick { 3 } else { 11 };
    let scenes = [
        (
            "reverse_load",
            SceneKind::ReverseLoad,
            BrakingScene::REVERSE,
        ),
        (
            "forward_load",
            SceneKind::ForwardLoad,
            BrakingScene::FORWARD,
        ),
    ];
    // The scenes without braking, as the twin's built-ins run them: at rest under the load with
    // the drive off, and driven against the load (opening) throughout.
    let still_scenes = [
        (
            "hold",
            SceneKind::Hold,
            BrakingScene {
                speed_ref_rad_s: 0.0,
                release_s: 0.0,
            },
        ),
        (
            "drive",
            SceneKind::Drive,
            BrakingScene {
                speed_ref_rad_s: -13.78,
                release_s: f64::INFINITY,
            },
        ),
    ];

    eprintln!("bench: M3 instruction counts under QEMU (noback-bench)");
    let m3 = core_costs(Core::M3, false)?;
    eprintln!("bench: Cortex-M0 instruction counts (noback-bench under QEMU)");
    let m0 = core_costs(Core::M0, false)?;
    let m3_of = |f: &str, m: &str| m3.iter().find(|(a, b, _, _)| a == f && b == m).map(|x| x.2);
    eprintln!("bench: the shipped monitor (cargo xtask run's replay, M3)");
    let (shipped, _) = crate::run::replay_report("reverse_load", Core::M3, None, None, false)?;
    // All the monitor's work per tick: the interrupt's part and its background (PendSV) call.
    let shipped_insns = shipped["insns_per_step_mean"].as_f64().unwrap_or(f64::NAN)
        + shipped["background_insns_per_call_mean"]
            .as_f64()
            .unwrap_or(f64::NAN);
    eprintln!("bench: the shipped monitor's estimate on reverse_load against both readings");
    let monitor_err = |reading: Reading| -> Result<f64, String> {
        let (_, acc) = host_tests::accuracy::monitor_on_scene(&Scene::builtin(
            SceneKind::ReverseLoad,
            reading,
        ))?;
        let (mut s, mut n) = (0.0, 0.0);
        for (m, t) in acc.monitor_torque_nm.iter().zip(&acc.twin_torque_raw_nm) {
            s += (m - t).powi(2);
            n += 1.0;
        }
        Ok((s / f64::max(n, 1.0)).sqrt())
    };
    let monitor_paper = monitor_err(Reading::Paper)?;
    let monitor_phys = monitor_err(Reading::Physical)?;

    let mut variants: Vec<Variant> = Vec::new();
    // Twin at several tolerances, both readings, against its tightest run.
    let tols: &[f64] = if quick {
        &[1e-3, 1e-5, 1e-7]
    } else {
        &[1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8]
    };
    let mut refs = Vec::new();
    let mut phys_refs: Vec<(&str, Vec<Sample>)> = Vec::new();
    for (name, kind, bs) in scenes {
        for reading in [Reading::Paper, Reading::Physical] {
            let ref_tol = if reading == Reading::Paper {
                REF_TOL
            } else {
                1e-9
            };
            eprintln!(
                "bench: twin {name} ({}) reference at tol {ref_tol}",
                reading.name()
            );
            let reference = reference(kind, reading, ref_tol)?;
            for &tol in tols {
                let mut scene = Scene::builtin(kind, reading);
                scene.tolerance = tol;
                let mut walls = Vec::new();
                let mut last = None;
                for _ in 0..reps.min(5) {
                    let r = run(&scene).map_err(|e| format!("twin at {tol}: {e:?}"))?;
                    walls.push(r.wall_s);
                    last = Some(r);
                }
                walls.sort_by(f64::total_cmp);
                let Some(r) = last else { continue };
                let rows: Vec<Row> = r
                    .samples
                    .iter()
                    .map(|s| {
                        (
                            s.t_s,
                            s.output_angle_rad,
                            s.output_speed_rad_s,
                            s.pressing_force_n,
                            s.braking_torque_nm,
                        )
                    })
                    .collect();
                let mut e = errors(&rows, &reference, bs.release_s);
                e.hold_rel = 0.0;
                variants.push(Variant {
                    family: format!("twin-{}", reading.name()),
                    format: "f64".into(),
                    method: format!("rosenbrock tol={tol:e}"),
                    rate_hz: 0.0,
                    scene: name,
                    e,
                    e_phys: None,
                    m3_insns_per_step: None,
                    host_ns_per_step: walls.get(walls.len() / 2).copied().unwrap_or(0.0) * 1e9
                        / r.stats.steps.max(1) as f64,
                    rhs_evals: r.stats.rhs_evals as f64,
                });
            }
            if reading == Reading::Paper {
                refs.push((name, bs, reference));
            } else {
                phys_refs.push((name, reference));
            }
        }
    }
    for (name, kind, bs) in still_scenes {
        eprintln!("bench: twin {name} (paper) reference at tol {REF_TOL}");
        refs.push((name, bs, reference(kind, Reading::Paper, REF_TOL)?));
    }
    let phys_of = |name: &str| {
        phys_refs
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, r)| r.as_slice())
    };
    // The quasi-static candidate (no state to advance: no instructions spent on a model step).
    for (name, bs, reference) in &refs {
        let duration = reference.last().map_or(1.0, |s| s.t_s);
        let rows = run_quasi_static(*bs, 10_000, duration);
        variants.push(Variant {
            family: "quasi-static".into(),
            format: "f64".into(),
            method: "none".into(),
            rate_hz: 10_000.0,
            scene: name,
            e: errors(&rows, reference, bs.release_s),
            e_phys: phys_of(name).map(|r| errors(&rows, r, bs.release_s)),
            m3_insns_per_step: Some(0.0),
            host_ns_per_step: 0.0,
            rhs_evals: 0.0,
        });
    }
    // The reduced model.
    eprintln!("bench: host ns per step (criterion, study/benches/reduced_step.rs)");
    run_criterion()?;
    let total = FORMATS.len() * Method::ALL.len();
    let mut done = 0;
    for fmt in FORMATS {
        for method in Method::ALL {
            done += 1;
            eprintln!("bench: reduced {fmt} {} ({done}/{total})", method.name());
            let ns = criterion_ns(fmt, method)?;
            for (name, bs, reference) in &refs {
                for rate in RATES {
                    let duration = reference.last().map_or(1.0, |s| s.t_s);
                    let rows = run_reduced_by_name(fmt, method, *bs, rate, duration);
                    variants.push(Variant {
                        family: "reduced".into(),
                        format: fmt.into(),
                        method: method.name().into(),
                        rate_hz: f64::from(rate),
                        scene: name,
                        e: errors(&rows, reference, bs.release_s),
                        e_phys: phys_of(name).map(|r| errors(&rows, r, bs.release_s)),
                        m3_insns_per_step: m3_of(fmt, method.name()),
                        host_ns_per_step: ns,
                        rhs_evals: f64::from(method.rhs_per_step()) * f64::from(rate),
                    });
                }
            }
        }
    }
    eprintln!("bench: stability of explicit steps on the full physical model");
    let stab = stability_map::run(quick)?;

    // Outputs: the pages under docs/results, or with `--json` a scratch directory under target/.
    let dir = if json {
        workspace_root().join("target").join("bench-json")
    } else {
        workspace_root().join("docs").join("results")
    };
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let rows: Vec<_> = variants
        .iter()
        .map(|v| host_speed::Row {
            family: &v.family,
            format: &v.format,
            method: &v.method,
            scene: v.scene,
            ns_per_step: v.host_ns_per_step,
        })
        .collect();
    std::fs::write(dir.join("host-speed.md"), host_speed::page(&rows, quick))
        .map_err(|e| e.to_string())?;
    let csv = pages::speed_accuracy_csv(&variants, shipped_insns, monitor_paper, monitor_phys);
    std::fs::write(dir.join("speed-accuracy.csv"), &csv).map_err(|e| e.to_string())?;

    stability_map::write(&dir, &stab)?;

    // Chart and Pareto fronts: reduced variants on reverse_load, braking-torque RMS (the
    // quantity the monitor estimates) against each reading, with the shipped monitor's point.
    let rev: Vec<&Variant> = variants
        .iter()
        .filter(|v| v.family == "reduced" && v.scene == "reverse_load")
        .collect();
    let panel = |phys: bool| -> Vec<(f64, f64, String)> {
        rev.iter()
            .filter_map(|v| {
                let e = if phys { v.e_phys? } else { v.e };
                v.m3_per_s().map(|c| (c, e.torque_rms.max(1e-9), v.label()))
            })
            .collect()
    };
    let (pts, pts_phys) = (panel(false), panel(true));
    let front = charts::pareto(&pts.iter().map(|p| (p.0, p.1)).collect::<Vec<_>>());
    let front_phys = charts::pareto(&pts_phys.iter().map(|p| (p.0, p.1)).collect::<Vec<_>>());
    charts::speed_accuracy(
        &dir.join("speed-accuracy.svg"),
        [
            charts::Panel {
                title: "against the paper reading (tol 1e-10)",
                pts: &pts,
                front: &front,
                monitor_err: monitor_paper,
            },
            charts::Panel {
                title: "against the physical reading (tol 1e-9), the monitor's",
                pts: &pts_phys,
                front: &front_phys,
                monitor_err: monitor_phys,
            },
        ],
        shipped_insns * 1e4,
    )?;

    // Cheapest per scene.
    let names: Vec<&str> = scenes
        .iter()
        .chain(still_scenes.iter())
        .map(|s| s.0)
        .collect();
    let (md, cheapest_rows) = pages::cheapest(&variants, &names, shipped_insns)?;
    std::fs::write(dir.join("cheapest-per-scene.md"), &md).map_err(|e| e.to_string())?;

    let cores_md = pages::cost_by_core(&m3, &m0);
    std::fs::write(dir.join("cost-by-core.md"), &cores_md).map_err(|e| e.to_string())?;

    if json {
        let vs: Vec<_> = variants
            .iter()
            .map(|v| {
                serde_json::json!({
                    "family": v.family, "format": v.format, "method": v.method,
                    "rate_hz": v.rate_hz, "scene": v.scene,
                    "angle_rms_rad": v.e.angle_rms, "speed_rms_rad_s": v.e.speed_rms,
                    "force_rms_pct": v.e.force_rms_pct, "torque_rms_nm": v.e.torque_rms,
                    "lock_err_s": v.e.lock_err_s, "meets_targets": v.e.meets_targets(),
                    "m3_insns_per_step": v.m3_insns_per_step, "host_ns_per_step": v.host_ns_per_step,
                })
            })
            .collect();
        let front_labels: Vec<&String> = front
            .iter()
            .filter_map(|&i| pts.get(i).map(|p| &p.2))
            .collect();
        println!(
            "{}",
            serde_json::json!({
                "variants": vs, "pareto_reverse_load": front_labels,
                "pareto_reverse_load_physical": front_phys.iter().filter_map(|&i| pts_phys.get(i).map(|p| &p.2)).collect::<Vec<_>>(),
                "monitor": {"m3_insns_per_s": shipped_insns * 1e4, "torque_rms_paper_nm": monitor_paper, "torque_rms_physical_nm": monitor_phys},
                "cheapest": cheapest_rows, "shipped_insns_per_step": shipped_insns,
                "stability": stab.iter().map(|r| serde_json::json!({"method": r.method, "parameter": r.parameter, "scale": r.scale, "h_us": r.h_us, "verdict": r.verdict})).collect::<Vec<_>>(),
                "seconds": t0.elapsed().as_secs_f64(),
            })
        );
    } else {
        println!("format         method      rate   scene         angle RMS  speed RMS  force%  lock ms  M3 insn/step  host ns  targets");
        for v in variants.iter().filter(|v| v.family == "reduced") {
            println!(
                "{:<14} {:<11} {:>3}k  {:<12} {:>9.2e}  {:>9.2e}  {:>6.3}  {:>7.2}  {:>12.0}  {:>7.1}  {}",
                v.format,
                v.method,
                v.rate_hz / 1e3,
                v.scene,
                v.e.angle_rms,
                v.e.speed_rms,
                v.e.force_rms_pct,
                v.e.lock_err_s * 1e3,
                v.m3_insns_per_step.unwrap_or(f64::NAN),
                v.host_ns_per_step,
                if v.e.meets_targets() { "yes" } else { "no" }
            );
        }
        println!("\ntwin against its tightest run (paper 1e-10, physical 1e-9):");
        for v in variants.iter().filter(|v| v.family != "reduced") {
            println!(
                "{:<15} {:<24} {:<12} angle RMS {:.2e}  speed RMS {:.2e}  lock err {:.2} ms  rhs evals {:.0}  host ns/step {:.0}",
                v.family, v.method, v.scene, v.e.angle_rms, v.e.speed_rms, v.e.lock_err_s * 1e3, v.rhs_evals, v.host_ns_per_step
            );
        }
        println!("\nPareto front (reverse_load, braking-torque RMS vs M3 insns/s, paper reading):");
        for &i in &front {
            if let Some(p) = pts.get(i) {
                println!("  {:<40} {:.3e} insns/s  {:.2e} N·m", p.2, p.0, p.1);
            }
        }
        println!("\nstability (full physical model, explicit fixed steps):");
        for r in &stab {
            println!(
                "  {:<5} {:>4}×{:<5} h={:>5} µs  {}",
                r.method, r.parameter, r.scale, r.h_us, r.verdict
            );
        }
        println!("\ncheapest per scene:");
        for (s, l) in &cheapest_rows {
            println!("  {s}: {l}");
        }
        println!("shipped monitor: {shipped_insns:.1} M3 insns/step");
        println!(
            "\nwrote docs/results/speed-accuracy.{{csv,svg}}, stability.{{csv,svg}}, cheapest-per-scene.md, cost-by-core.md, host-speed.md in {:.0} s",
            t0.elapsed().as_secs_f64()
        );
    }
    Ok(0)
}
