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
//! `.svg`, `docs/results/cheapest-per-scene.md`, `docs/results/cost-by-core.md`.

pub mod charts;
pub mod explicit;
pub mod work_precision;

use crate::cores::Core;
use crate::qemu::{self, Boot};
use crate::shell::{self, cargo, workspace_root};
use explicit::{Explicit, Verdict};
use fixed::types::{I16F16, I32F32};
use noback::mechanism::TABLE2;
use noback_study::reduced::num::{Real, Widen};
use noback_study::reduced::{BrakingScene, Method, Params, Reduced};
use noback_twin::model::physical::Physical;
use noback_twin::model::Sample;
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::sim::{model_config, run, run_model};
use std::fmt::Write as _;
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
/// Speed below which the output counts as stopped (the twin's metric threshold).
const STOP_RAD_S: f64 = 0.05;
/// The monitor's accuracy targets a variant must meet (docs/monitor-design.md: speed within
/// 0.5 rad/s, holding torque within 5 %; lock seen within ~9 ms there, 10 ms here).
pub const TARGET_SPEED_RMS: f64 = 0.5;
/// Pressing-force RMS target (% of the loaded force).
pub const TARGET_FORCE_PCT: f64 = 5.0;
/// Lock-time target (s).
pub const TARGET_LOCK_S: f64 = 0.01;
/// Holding-torque target (relative).
pub const TARGET_HOLD_REL: f64 = 0.05;

/// The formats measured, by name.
pub const FORMATS: [&str; 5] = ["f64", "f32", "I16F16", "I32F32", "I16F16+I32F32"];

/// Errors of one reduced run against the reference.
#[derive(Clone, Copy, Debug, Default)]
pub struct Errors {
    /// Output-angle RMS (rad).
    pub angle_rms: f64,
    /// Output-speed RMS (rad/s).
    pub speed_rms: f64,
    /// Pressing-force RMS (% of the loaded quasi-static force).
    pub force_rms_pct: f64,
    /// Braking-torque RMS (N·m).
    pub torque_rms: f64,
    /// |lock time − reference lock time| (s); 1.0 if either never locks.
    pub lock_err_s: f64,
    /// Holding torque at the end relative error.
    pub hold_rel: f64,
}

impl Errors {
    /// Meets the monitor's accuracy targets.
    pub fn meets_targets(&self) -> bool {
        self.speed_rms <= TARGET_SPEED_RMS
            && self.force_rms_pct <= TARGET_FORCE_PCT
            && self.lock_err_s <= TARGET_LOCK_S
            && self.hold_rel <= TARGET_HOLD_REL
    }
}

/// One recorded instant: (t, angle, speed, force, torque).
type Row = (f64, f64, f64, f64, f64);

/// Runs a reduced variant on a braking scene for `duration_s`, recording every
/// `max(1/rate, 1e-4)` s.
pub fn run_reduced<N: Real + Widen<A>, A: Real>(
    method: Method,
    scene: BrakingScene,
    rate: u32,
    duration_s: f64,
) -> Vec<Row> {
    let p = Params::from_mechanism(&TABLE2, TABLE2.load_torque_nm, f64::from(rate));
    let mut m = Reduced::<N, A>::new(p, method);
    m.set_drive(true, scene.speed_ref_rad_s);
    let cut = scene.release_tick(rate);
    let steps = (duration_s * f64::from(rate)).round() as u32;
    let every = (rate / 10_000).max(1);
    let mut rows = Vec::with_capacity(steps as usize / every as usize + 1);
    let rec = |m: &Reduced<N, A>, t: f64, rows: &mut Vec<Row>| {
        let o = m.output();
        rows.push((
            t,
            m.state.theta.to_f64(),
            m.state.omega.to_f64(),
            o.pressing_n.to_f64(),
            o.braking_nm.to_f64(),
        ));
    };
    rec(&m, 0.0, &mut rows);
    for k in 0..steps {
        if k == cut {
            m.set_drive(false, 0.0);
        }
        m.step();
        if (k + 1) % every == 0 {
            rec(&m, f64::from(k + 1) / f64::from(rate), &mut rows);
        }
    }
    rows
}

/// The quasi-static candidate: no state to advance. The output runs at the drive's speed
/// reference while the drive is on and is at rest, held by the pack, once it is cut; force and
/// torque are the reduced model's quasi-static outputs at that state (f64: the candidate's
/// error is its physics, not its format). This is what the monitor does in `Holding` and
/// `Driving`.
pub fn run_quasi_static(scene: BrakingScene, rate: u32, duration_s: f64) -> Vec<Row> {
    let p = Params::from_mechanism(&TABLE2, TABLE2.load_torque_nm, f64::from(rate));
    let mut m = Reduced::<f64, f64>::new(p, Method::Euler);
    m.set_drive(true, scene.speed_ref_rad_s);
    let cut = scene.release_tick(rate);
    let steps = (duration_s * f64::from(rate)).round() as u32;
    let dt = 1.0 / f64::from(rate);
    let mut rows = Vec::with_capacity(steps as usize + 1);
    for k in 0..=steps {
        if k == cut {
            m.set_drive(false, 0.0);
            m.state.omega = 0.0;
        }
        if k > 0 && k <= cut {
            m.state.theta += scene.speed_ref_rad_s * dt;
        }
        let o = m.output();
        rows.push((
            f64::from(k) * dt,
            m.state.theta,
            m.state.omega,
            o.pressing_n,
            o.braking_nm,
        ));
    }
    rows
}

fn run_reduced_by_name(
    fmt: &str,
    method: Method,
    scene: BrakingScene,
    rate: u32,
    dur: f64,
) -> Vec<Row> {
    match fmt {
        "f64" => run_reduced::<f64, f64>(method, scene, rate, dur),
        "f32" => run_reduced::<f32, f32>(method, scene, rate, dur),
        "I16F16" => run_reduced::<I16F16, I16F16>(method, scene, rate, dur),
        "I32F32" => run_reduced::<I32F32, I32F32>(method, scene, rate, dur),
        _ => run_reduced::<I16F16, I32F32>(method, scene, rate, dur),
    }
}

/// Runs the criterion benchmark `study/benches/reduced_step.rs` (host nanoseconds per
/// step of every format × integrator).
fn run_criterion() -> Result<(), String> {
    shell::run(cargo().args([
        "bench",
        "-p",
        "noback-study",
        "--bench",
        "reduced_step",
        "--",
        "--noplot",
    ]))
}

/// Criterion's mean estimate of one variant (ns per step), from its `estimates.json`.
fn criterion_ns(fmt: &str, method: Method) -> Result<f64, String> {
    let dir = if fmt == "I16F16+I32F32" { "mixed" } else { fmt };
    let path = workspace_root()
        .join("target")
        .join("criterion")
        .join("reduced_step")
        .join(dir)
        .join(method.name())
        .join("new")
        .join("estimates.json");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let v: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    v["mean"]["point_estimate"]
        .as_f64()
        .ok_or_else(|| format!("{}: no mean.point_estimate", path.display()))
}

/// Lock time after `release` (s): the first recorded instant after the last one at or above
/// the stop threshold; `None` if still moving at the end.
pub fn lock_time(rows: &[(f64, f64)], release: f64) -> Option<f64> {
    let after: Vec<&(f64, f64)> = rows.iter().filter(|r| r.0 >= release - 1e-12).collect();
    match after.iter().rposition(|r| r.1.abs() >= STOP_RAD_S) {
        None => Some(0.0),
        Some(i) => after.get(i + 1).map(|r| r.0 - release),
    }
}

/// The reference samples of a scene (paper reading, tightest tolerance).
pub fn reference(kind: SceneKind, reading: Reading, tol: f64) -> Result<Vec<Sample>, String> {
    let mut scene = Scene::builtin(kind, reading);
    scene.tolerance = tol;
    run(&scene)
        .map(|r| r.samples)
        .map_err(|e| format!("twin {kind:?} at tol {tol}: {e:?}"))
}

/// Errors of reduced rows against reference samples at 10 kHz (t = i·1e-4).
pub fn errors(rows: &[Row], reference: &[Sample], release: f64) -> Errors {
    let f_loaded = TABLE2.quasi_static_pressing_force_n(TABLE2.load_torque_nm);
    let (mut a, mut w, mut f, mut tq, mut n) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let mut ref_rows = Vec::new();
    for r in rows {
        let i = (r.0 * 1e4).round() as usize;
        let Some(s) = reference.get(i) else { continue };
        a += (r.1 - s.output_angle_rad).powi(2);
        w += (r.2 - s.output_speed_rad_s).powi(2);
        f += (r.3 - s.pressing_force_n).powi(2);
        tq += (r.4 - s.braking_torque_nm).powi(2);
        n += 1.0;
        ref_rows.push((s.t_s, s.output_speed_rad_s));
    }
    let n = f64::max(n, 1.0);
    let mine: Vec<(f64, f64)> = rows.iter().map(|r| (r.0, r.2)).collect();
    let lock_err_s = match (lock_time(&mine, release), lock_time(&ref_rows, release)) {
        (Some(x), Some(y)) => (x - y).abs(),
        _ => 1.0,
    };
    // Holding torque: only where the reference ends at rest under the pack (the braking
    // scenes and hold; a driven output has no holding torque).
    let hold = rows.last().map_or(0.0, |r| r.4);
    let held = reference
        .last()
        .filter(|s| s.output_speed_rad_s.abs() < STOP_RAD_S)
        .map(|s| s.braking_torque_nm);
    Errors {
        angle_rms: (a / n).sqrt(),
        speed_rms: (w / n).sqrt(),
        force_rms_pct: 100.0 * (f / n).sqrt() / f_loaded,
        torque_rms: (tq / n).sqrt(),
        lock_err_s,
        hold_rel: held.map_or(0.0, |t| (hold - t).abs() / t.abs().max(1e-9)),
    }
}

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

/// Stability-map row.
#[derive(Clone, Debug)]
struct StabRow {
    method: &'static str,
    /// Which parameter is scaled: `k` (contact stiffness), `Jc` (connecting-shaft inertia,
    /// i.e. the inertia ratio against the output), `mu` (both friction coefficients), or `base`.
    parameter: &'static str,
    scale: f64,
    h_us: f64,
    verdict: &'static str,
    diverged_at_s: Option<f64>,
    speed_rms: Option<f64>,
    rhs_evals: u64,
}

/// Threshold of "inaccurate" for the explicit runs: output-speed RMS against the twin (rad/s).
pub const STAB_INACCURATE_RAD_S: f64 = 0.1;

fn stability(quick: bool) -> Result<Vec<StabRow>, String> {
    let window = if quick { 0.01 } else { 0.03 };
    let steps_us: &[f64] = if quick {
        &[0.125, 0.5, 1.0, 2.0, 2.5, 4.0, 5.0, 10.0]
    } else {
        &[0.125, 0.25, 0.5, 1.0, 2.0, 2.5, 4.0, 5.0, 10.0, 20.0]
    };
    // What makes the full model stiff or soft: contact stiffness, the light connecting shaft
    // against the output (inertia ratio), and friction. One factor at a time around Table 2.
    let variations: &[(&'static str, f64)] = if quick {
        &[("base", 1.0)]
    } else {
        &[
            ("base", 1.0),
            ("k", 0.25),
            ("k", 4.0),
            ("Jc", 0.25),
            ("Jc", 4.0),
            ("mu", 0.5),
            ("mu", 1.5),
        ]
    };
    let mut rows = Vec::new();
    for &(parameter, ks) in variations {
        let mut scene = Scene::builtin(SceneKind::ReverseLoad, Reading::Physical);
        let m = &mut scene.mechanism;
        match parameter {
            "k" => m.contact_stiffness *= ks,
            "Jc" => m.connecting_inertia_kg_m2 *= ks,
            "mu" => {
                m.mu_static *= ks;
                m.mu_dynamic *= ks;
            }
            _ => {}
        }
        scene.duration_s = window;
        scene.tolerance = 1e-8;
        let reference = run_model(&scene, Physical::new(model_config(&scene)))
            .map_err(|e| format!("twin reference: {e:?}"))?
            .samples;
        for method in [Explicit::Euler, Explicit::Rk4] {
            for &h in steps_us {
                let mut model = Physical::new(model_config(&scene));
                let r = explicit::integrate(&mut model, method, h * 1e-6, window, 1e-4);
                let (verdict, at, rms) = match r.verdict {
                    Verdict::Diverged { at_s } => ("diverged", Some(at_s), None),
                    Verdict::Finished => {
                        let (mut s, mut n) = (0.0, 0.0);
                        for (t, _, w) in &r.samples {
                            if let Some(x) = reference.get((t * 1e4).round() as usize) {
                                s += (w - x.output_speed_rad_s).powi(2);
                                n += 1.0;
                            }
                        }
                        let rms = (s / f64::max(n, 1.0)).sqrt();
                        (
                            if rms > STAB_INACCURATE_RAD_S {
                                "inaccurate"
                            } else {
                                "stable"
                            },
                            None,
                            Some(rms),
                        )
                    }
                };
                eprintln!(
                    "bench: stability {} {parameter}×{ks} h={h} µs: {verdict}",
                    method.name()
                );
                // A converging method's verdict cannot improve with a coarser step: a run under
                // the threshold whose finer neighbour is over it is error cancellation near the
                // stability limit, rated inaccurate (its RMS stays in the CSV).
                let finer_inaccurate = rows.iter().any(|r: &StabRow| {
                    r.method == method.name()
                        && r.parameter == parameter
                        && r.scale == ks
                        && r.verdict == "inaccurate"
                });
                let verdict = if verdict == "stable" && finer_inaccurate {
                    "inaccurate"
                } else {
                    verdict
                };
                rows.push(StabRow {
                    method: method.name(),
                    parameter,
                    scale: ks,
                    h_us: h,
                    verdict,
                    diverged_at_s: at,
                    speed_rms: rms,
                    rhs_evals: r.rhs_evals,
                });
            }
        }
    }
    Ok(rows)
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
    let stab = stability(quick)?;

    // Outputs.
    let dir = workspace_root().join("docs").join("results");
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let mut csv = String::from("family,format,method,rate_hz,scene,angle_rms_rad,speed_rms_rad_s,force_rms_pct,torque_rms_nm,lock_err_s,hold_rel,meets_targets,m3_insns_per_step,m3_insns_per_s,host_ns_per_step,rhs_evals_per_s,torque_rms_physical_nm\n");
    for v in &variants {
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{:.6e},{:.6e},{:.4},{:.6e},{:.5},{:.5},{},{},{},{:.1},{},{}",
            v.family,
            v.format,
            v.method,
            v.rate_hz,
            v.scene,
            v.e.angle_rms,
            v.e.speed_rms,
            v.e.force_rms_pct,
            v.e.torque_rms,
            v.e.lock_err_s,
            v.e.hold_rel,
            v.e.meets_targets(),
            opt(v.m3_insns_per_step),
            opt(v.m3_per_s()),
            v.host_ns_per_step,
            v.rhs_evals,
            opt(v.e_phys.map(|e| e.torque_rms))
        );
    }
    let _ = writeln!(
        csv,
        "shipped-monitor,I16F16+Scale+u32 angle,observer,10000,reverse_load,,,,{monitor_paper:.6e},,,,{shipped_insns:.1},{:.6e},,,{monitor_phys:.6e}",
        shipped_insns * 1e4
    );
    std::fs::write(dir.join("speed-accuracy.csv"), &csv).map_err(|e| e.to_string())?;

    let mut scsv = String::from(
        "method,parameter,scale,step_us,verdict,diverged_at_s,speed_rms_rad_s,rhs_evals\n",
    );
    for r in &stab {
        let _ = writeln!(
            scsv,
            "{},{},{},{},{},{},{},{}",
            r.method,
            r.parameter,
            r.scale,
            r.h_us,
            r.verdict,
            opt(r.diverged_at_s),
            opt(r.speed_rms),
            r.rhs_evals
        );
    }
    std::fs::write(dir.join("stability.csv"), &scsv).map_err(|e| e.to_string())?;
    let lanes: Vec<charts::StabCell> = stab
        .iter()
        .map(|r| (r.method, r.parameter, r.scale, r.h_us, r.verdict))
        .collect();
    charts::stability(&dir.join("stability.svg"), &lanes)?;

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
    let mut md = String::from("# The cheapest model per scene\n\nWritten by `cargo xtask bench`. Cheapest = fewest Cortex-M3 instructions per simulated second among the candidates that meet the monitor's accuracy targets against the twin's `paper` reading at tolerance 1e-10: output-speed RMS ≤ 0.5 rad/s, pressing-force RMS ≤ 5 % of the loaded force, lock time within 10 ms, holding torque within 5 % (targets from docs/monitor-design.md). Candidates: every format × integrator × rate of the reduced model, and the quasi-static model with no state to advance (output at the drive's speed while driven, at rest once the drive is cut; 0 instructions of model step). The monitor runs, per scene it recognises, the model named here (`Monitor::scene_model`); `host-tests/tests/monitor_scene_models.rs` fails when they differ.\n\n| scene | cheapest variant | M3 insns/step | M3 insns/s | angle RMS (rad) | speed RMS (rad/s) | force RMS % | lock error (ms) |\n|---|---|---|---|---|---|---|---|\n");
    let mut cheapest_rows = Vec::new();
    for (name, _, _) in scenes.iter().chain(still_scenes.iter()) {
        let name = *name;
        let best = variants
            .iter()
            .filter(|v| {
                v.family != "shipped" && v.rate_hz > 0.0 && v.scene == name && v.e.meets_targets()
            })
            .min_by(|a, b| {
                a.m3_per_s()
                    .unwrap_or(f64::MAX)
                    .total_cmp(&b.m3_per_s().unwrap_or(f64::MAX))
            });
        match best {
            Some(v) => {
                let _ = writeln!(
                    md,
                    "| {name} | {} | {:.0} | {:.3e} | {:.2e} | {:.3} | {:.3} | {:.1} |",
                    v.label(),
                    v.m3_insns_per_step.unwrap_or(f64::NAN),
                    v.m3_per_s().unwrap_or(f64::NAN),
                    v.e.angle_rms,
                    v.e.speed_rms,
                    v.e.force_rms_pct,
                    v.e.lock_err_s * 1e3
                );
                cheapest_rows.push((name, v.label()));
            }
            None => {
                let _ = writeln!(md, "| {name} | none meets the targets | | | | | | |");
            }
        }
    }
    // Continuous closing: the reduced model has no drive-on engagement cycle (the paper
    // reading's 0.444 s limit cycle); the monitor's overrunning equilibrium is the only
    // candidate, measured through the monitor against the physical reading (its ground truth).
    let closing = crate::replay::twin_trace("continuous_closing")?;
    let closing_acc = host_tests::accuracy::compare(
        &closing,
        &host_tests::accuracy::run_monitor(&closing, noback::monitor::Config::default())?,
    );
    let _ = writeln!(
        md,
        "| continuous_closing | {EQUILIBRIUM_LABEL} | 0 | 0 | | | {:.3} | |",
        closing_acc.pressing_force_rmse_pct
    );
    cheapest_rows.push(("continuous_closing", EQUILIBRIUM_LABEL.to_string()));
    md.push_str("\nContinuous closing: the reduced model has no drive-on engagement cycle, so the only candidate is the monitor's overrunning equilibrium (`T = g₁·v − g₀` from the drive torque, no state); its force RMS above is the whole monitor against the twin's `physical` reading (% of the peak, the monitor's 10 % target, `cargo xtask monitor continuous_closing`).\n");
    let _ = writeln!(
        md,
        "\nThe shipped monitor (whole estimator: observer, model, flags) costs {shipped_insns:.1} M3 instructions per 10 kHz tick, its interrupt's part and its background call together ({:.3e} per simulated second).",
        shipped_insns * 1e4
    );
    std::fs::write(dir.join("cheapest-per-scene.md"), &md).map_err(|e| e.to_string())?;

    // Cost by core: the format that is cheap on an M3 (single-cycle 32×32→64 multiply) is not
    // necessarily cheap on an M0 (no long multiply, no FPU).
    let mut cores_md = String::from(
        "# Instructions per step by core\n\nWritten by `cargo xtask bench`; do not edit. \
         `noback-bench` under QEMU `-icount` (reverse-load braking, 3000 steps each).\n\n\
         | format | integrator | M3 mean | M3 max | M0 mean | M0 max | M0 / M3 |\n|---|---|---|---|---|---|---|\n",
    );
    for (f, m, mean3, max3) in &m3 {
        if let Some((_, _, mean0, max0)) = m0.iter().find(|(a, b, _, _)| a == f && b == m) {
            let _ = writeln!(
                cores_md,
                "| {f} | {m} | {mean3:.0} | {max3:.0} | {mean0:.0} | {max0:.0} | {:.1} |",
                mean0 / mean3.max(1.0)
            );
        }
    }
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
            "\nwrote docs/results/speed-accuracy.{{csv,svg}}, stability.{{csv,svg}}, cheapest-per-scene.md, cost-by-core.md in {:.0} s",
            t0.elapsed().as_secs_f64()
        );
    }
    Ok(0)
}
