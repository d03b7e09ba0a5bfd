//! The variants `cargo xtask bench` measures: the reduced model in each format × integrator ×
//! rate, the quasi-static candidate, and their errors against the twin's reference.

use crate::shell::{self, cargo, workspace_root};
use fixed::types::{I16F16, I32F32};
use noback::mechanism::TABLE2;
use noback_study::reduced::num::{Real, Widen};
use noback_study::reduced::{BrakingScene, Method, Params, Reduced};
use noback_twin::model::Sample;
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::sim::run;

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
pub type Row = (f64, f64, f64, f64, f64);

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

pub fn run_reduced_by_name(
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
pub fn run_criterion() -> Result<(), String> {
    // Criterion's report goes to stderr: with `--json` stdout carries the JSON line alone.
    shell::run(
        cargo()
            .args([
                "bench",
                "-p",
                "noback-study",
                "--bench",
                "reduced_step",
                "--",
                "--noplot",
            ])
            .stdout(std::io::stderr()),
    )
}

/// Criterion's mean estimate of one variant (ns per step), from its `estimates.json`.
pub fn criterion_ns(fmt: &str, method: Method) -> Result<f64, String> {
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
