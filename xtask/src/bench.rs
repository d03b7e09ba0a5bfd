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
mod report;
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

/// The braking scenes: the reduced model's references, in both readings.
const BRAKING_SCENES: [(&str, SceneKind, BrakingScene); 2] = [
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
/// The scenes without a braking, as the twin's built-ins run them: at rest under the load with
/// the drive off, and driven against the load (opening) throughout.
const STILL_SCENES: [(&str, SceneKind, BrakingScene); 2] = [
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

/// The shipped monitor's point: M3 instructions per tick (the interrupt's part and its
/// background call) and its braking-torque RMS on reverse_load against each reading (N·m).
struct MonitorPoint {
    insns: f64,
    err_paper: f64,
    err_phys: f64,
}

/// The twin's references: each scene's paper reading with its braking scene, and the
/// braking scenes' physical reading.
struct References {
    paper: Vec<(&'static str, BrakingScene, Vec<Sample>)>,
    physical: Vec<(&'static str, Vec<Sample>)>,
}

impl References {
    fn physical(&self, name: &str) -> Option<&[Sample]> {
        self.physical
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, r)| r.as_slice())
    }
}

/// The chart's two panels (`(M3 insns/s, torque RMS, label)`) and their Pareto fronts.
struct Fronts {
    pts: Vec<(f64, f64, String)>,
    front: Vec<usize>,
    pts_phys: Vec<(f64, f64, String)>,
    front_phys: Vec<usize>,
}

/// Entry.
pub fn main(args: &[String]) -> Result<i32, String> {
    let (quick, json) = options(args)?;
    let t0 = Instant::now();
    crate::bootstrap::ensure_all()?;
    eprintln!("bench: M3 instruction counts under QEMU (noback-bench)");
    let m3 = core_costs(Core::M3, false)?;
    eprintln!("bench: Cortex-M0 instruction counts (noback-bench under QEMU)");
    let m0 = core_costs(Core::M0, false)?;
    let monitor = shipped_monitor()?;
    let mut variants: Vec<Variant> = Vec::new();
    let refs = twin_variants(quick, &mut variants)?;
    quasi_static_variants(&refs, &mut variants);
    reduced_variants(&refs, &m3, &mut variants)?;
    eprintln!("bench: stability of explicit steps on the full physical model");
    let stab = stability_map::run(quick)?;

    // Outputs: the pages under docs/results, or with `--json` a scratch directory under target/.
    let dir = if json {
        workspace_root().join("target").join("bench-json")
    } else {
        workspace_root().join("docs").join("results")
    };
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let write = |name: &str, text: &str| {
        std::fs::write(dir.join(name), text).map_err(|e| format!("{name}: {e}"))
    };
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
    write("host-speed.md", &host_speed::page(&rows, quick))?;
    let csv = pages::speed_accuracy_csv(
        &variants,
        monitor.insns,
        monitor.err_paper,
        monitor.err_phys,
    );
    write("speed-accuracy.csv", &csv)?;
    stability_map::write(&dir, &stab)?;
    let fronts = chart(&dir, &variants, &monitor)?;
    let names: Vec<&str> = BRAKING_SCENES
        .iter()
        .chain(STILL_SCENES.iter())
        .map(|s| s.0)
        .collect();
    let (md, cheapest) = pages::cheapest(&variants, &names, monitor.insns)?;
    write("cheapest-per-scene.md", &md)?;
    write("cost-by-core.md", &pages::cost_by_core(&m3, &m0))?;
    let report = report::Report {
        variants: &variants,
        fronts: &fronts,
        monitor: &monitor,
        cheapest: &cheapest,
        stab: &stab,
        t0,
    };
    if json {
        report.print_json();
    } else {
        report.print_table();
    }
    Ok(0)
}

/// `[--quick] [--json]`.
fn options(args: &[String]) -> Result<(bool, bool), String> {
    let (mut quick, mut json) = (false, false);
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
    Ok((quick, json))
}

/// The shipped monitor: its cost in `cargo xtask run`'s replay on the M3, its estimate on
/// reverse_load against both readings.
fn shipped_monitor() -> Result<MonitorPoint, String> {
    eprintln!("bench: the shipped monitor (cargo xtask run's replay, M3)");
    let (shipped, _) = crate::run::replay_report("reverse_load", Core::M3, None, None, false)?;
    let per_tick = |key: &str| shipped[key].as_f64().unwrap_or(f64::NAN);
    let insns = per_tick("insns_per_step_mean") + per_tick("background_insns_per_call_mean");
    eprintln!("bench: the shipped monitor's estimate on reverse_load against both readings");
    let err = |reading: Reading| -> Result<f64, String> {
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
    Ok(MonitorPoint {
        insns,
        err_paper: err(Reading::Paper)?,
        err_phys: err(Reading::Physical)?,
    })
}

/// The twin at several tolerances, both readings, against its tightest run; returns the
/// references the other variants are measured against.
fn twin_variants(quick: bool, variants: &mut Vec<Variant>) -> Result<References, String> {
    let reps = if quick { 3 } else { 5 };
    let tols: &[f64] = if quick {
        &[1e-3, 1e-5, 1e-7]
    } else {
        &[1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8]
    };
    let mut refs = References {
        paper: Vec::new(),
        physical: Vec::new(),
    };
    for (name, kind, bs) in BRAKING_SCENES {
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
                for _ in 0..reps {
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
                    method: format!("bdf tol={tol:e}"),
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
                refs.paper.push((name, bs, reference));
            } else {
                refs.physical.push((name, reference));
            }
        }
    }
    for (name, kind, bs) in STILL_SCENES {
        eprintln!("bench: twin {name} (paper) reference at tol {REF_TOL}");
        refs.paper
            .push((name, bs, reference(kind, Reading::Paper, REF_TOL)?));
    }
    Ok(refs)
}

/// The quasi-static candidate (no state to advance: no instructions spent on a model step).
fn quasi_static_variants(refs: &References, variants: &mut Vec<Variant>) {
    for (name, bs, reference) in &refs.paper {
        let duration = reference.last().map_or(1.0, |s| s.t_s);
        let rows = run_quasi_static(*bs, 10_000, duration);
        variants.push(Variant {
            family: "quasi-static".into(),
            format: "f64".into(),
            method: "none".into(),
            rate_hz: 10_000.0,
            scene: name,
            e: errors(&rows, reference, bs.release_s),
            e_phys: refs.physical(name).map(|r| errors(&rows, r, bs.release_s)),
            m3_insns_per_step: Some(0.0),
            host_ns_per_step: 0.0,
            rhs_evals: 0.0,
        });
    }
}

/// Every format × integrator × rate of the reduced model on every scene.
fn reduced_variants(
    refs: &References,
    m3: &pages::CoreCosts,
    variants: &mut Vec<Variant>,
) -> Result<(), String> {
    let m3_of = |f: &str, m: &str| m3.iter().find(|(a, b, _, _)| a == f && b == m).map(|x| x.2);
    eprintln!("bench: host ns per step (criterion, study/benches/reduced_step.rs)");
    run_criterion()?;
    let total = FORMATS.len() * Method::ALL.len();
    let mut done = 0;
    for fmt in FORMATS {
        for method in Method::ALL {
            done += 1;
            eprintln!("bench: reduced {fmt} {} ({done}/{total})", method.name());
            let ns = criterion_ns(fmt, method)?;
            for (name, bs, reference) in &refs.paper {
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
                        e_phys: refs.physical(name).map(|r| errors(&rows, r, bs.release_s)),
                        m3_insns_per_step: m3_of(fmt, method.name()),
                        host_ns_per_step: ns,
                        rhs_evals: f64::from(method.rhs_per_step()) * f64::from(rate),
                    });
                }
            }
        }
    }
    Ok(())
}

/// The chart and its Pareto fronts: reduced variants on reverse_load, braking-torque RMS (the
/// quantity the monitor estimates) against each reading, with the shipped monitor's point.
fn chart(
    dir: &std::path::Path,
    variants: &[Variant],
    monitor: &MonitorPoint,
) -> Result<Fronts, String> {
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
                monitor_err: monitor.err_paper,
            },
            charts::Panel {
                title: "against the physical reading (tol 1e-9), the monitor's",
                pts: &pts_phys,
                front: &front_phys,
                monitor_err: monitor.err_phys,
            },
        ],
        monitor.insns * 1e4,
    )?;
    Ok(Fronts {
        pts,
        front,
        pts_phys,
        front_phys,
    })
}
