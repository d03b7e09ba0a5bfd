//! Metrics of a run (definitions in docs/model.md, "Metrics"; all in the twin's sign
//! convention, positive = load direction).

use crate::model::Sample;
use crate::scene::{Scene, SceneKind};
use crate::solver::SolverStats;
use serde::Serialize;

/// Start of the settled window of continuous closing (s): the paper reads its period and peaks
/// after 1.2 s.
pub const SETTLED_FROM_S: f64 = 1.2;

/// The metrics of one run. `None` where a metric does not apply (no release, no oscillation).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Metrics {
    /// Scene name.
    pub scene: String,
    /// Reading.
    pub reading: String,
    /// From release until the output speed stays below the stop threshold (s).
    pub braking_time_s: Option<f64>,
    /// |output angle at stop − output angle at release| (rad).
    pub braking_angle_rad: Option<f64>,
    /// From release until the pressing force first exceeds the spring preload plus half the
    /// load's ramp force (s).
    pub contact_lag_s: Option<f64>,
    /// Mean braking torque over the last 10 % of the run, if the brake is locked there (N·m).
    pub holding_torque_nm: Option<f64>,
    /// Largest braking torque (after release, or in the settled window) (N·m).
    pub peak_braking_torque_nm: f64,
    /// Mean of the per-cycle minima of the braking torque in the settled window of a periodic
    /// run; otherwise the smallest braking torque after release (N·m).
    pub trough_braking_torque_nm: f64,
    /// Mean period of the braking-torque cycle in the settled window (s).
    pub period_s: Option<f64>,
    /// Largest |output speed| (after release, or in the settled window) (rad/s).
    pub max_output_speed_rad_s: f64,
    /// Sign changes of the output speed after release, each beyond the stop threshold.
    pub output_reversals: u32,
    /// Largest axial excursion (max − min) of the output balls or the big connecting shaft
    /// before the settled window of continuous closing (mm); `None` if the reading has no
    /// axial motion.
    pub axial_travel_mm: Option<f64>,
    /// Accepted integrator steps.
    pub steps: u64,
    /// Rejected steps.
    pub rejected_steps: u64,
    /// Right-hand-side evaluations.
    pub rhs_evals: u64,
    /// Located events.
    pub events: u64,
    /// Wall-clock time of the integration (s).
    pub wall_s: f64,
}

/// Compute the metrics of a run.
pub fn compute(scene: &Scene, samples: &[Sample], stats: &SolverStats, wall_s: f64) -> Metrics {
    compute_settled_from(scene, samples, stats, wall_s, SETTLED_FROM_S)
}

/// [`compute`] with the start of continuous closing's settled window moved to `settled_from_s`
/// (the paper protocol's cut-time robustness check).
pub fn compute_settled_from(
    scene: &Scene,
    samples: &[Sample],
    stats: &SolverStats,
    wall_s: f64,
    settled_from_s: f64,
) -> Metrics {
    let thr = scene.open.stop_threshold_rad_s;
    let release = scene.release_at_s.or(if scene.kind == SceneKind::Hold {
        Some(0.0)
    } else {
        None
    });
    let periodic = scene.kind == SceneKind::ContinuousClosing;
    let window_start = if periodic {
        settled_from_s.min(scene.duration_s * 0.5)
    } else {
        release.unwrap_or(0.0)
    };
    let window: Vec<&Sample> = samples.iter().filter(|s| s.t_s >= window_start).collect();
    let mut m = Metrics {
        scene: scene.name.clone(),
        reading: scene.reading.name().to_string(),
        steps: stats.steps,
        rejected_steps: stats.rejected,
        rhs_evals: stats.rhs_evals,
        events: stats.events,
        wall_s,
        ..Metrics::default()
    };
    m.peak_braking_torque_nm = window
        .iter()
        .map(|s| s.braking_torque_nm)
        .fold(0.0, f64::max);
    m.trough_braking_torque_nm = window
        .iter()
        .map(|s| s.braking_torque_nm)
        .fold(f64::INFINITY, f64::min);
    if !m.trough_braking_torque_nm.is_finite() {
        m.trough_braking_torque_nm = 0.0;
    }
    m.max_output_speed_rad_s = window
        .iter()
        .map(|s| s.output_speed_rad_s.abs())
        .fold(0.0, f64::max);
    if let Some(r) = release {
        let after: Vec<&Sample> = samples.iter().filter(|s| s.t_s >= r).collect();
        let at_release = after.first().map(|s| s.output_angle_rad).unwrap_or(0.0);
        // Braking time: last sample at or above the threshold.
        let last_moving = after
            .iter()
            .rposition(|s| s.output_speed_rad_s.abs() >= thr);
        let end_t = samples.last().map(|s| s.t_s).unwrap_or(0.0);
        match last_moving {
            Some(i) if i + 1 < after.len() => {
                let stop = after.get(i + 1).map(|s| (s.t_s, s.output_angle_rad));
                if let Some((ts, angle)) = stop {
                    if ts < end_t {
                        m.braking_time_s = Some(ts - r);
                        m.braking_angle_rad = Some((angle - at_release).abs());
                    }
                }
            }
            None => {
                m.braking_time_s = Some(0.0);
                m.braking_angle_rad = Some(0.0);
            }
            _ => {}
        }
        let spring = scene.mechanism.spring_preload_n();
        let ramp = scene.load_torque_nm.abs() * scene.mechanism.ramp_factor_per_m();
        let level = spring + 0.5 * ramp;
        m.contact_lag_s = after
            .iter()
            .find(|s| s.pressing_force_n > level)
            .map(|s| s.t_s - r);
        // Reversals with hysteresis.
        let mut sign = 0i8;
        for s in &after {
            let w = s.output_speed_rad_s;
            let now = if w > thr {
                1
            } else if w < -thr {
                -1
            } else {
                0
            };
            if now != 0 {
                if sign != 0 && now != sign {
                    m.output_reversals += 1;
                }
                sign = now;
            }
        }
    }
    // Holding torque: last 10 % locked.
    let n = samples.len();
    let tail = samples.get(n - n / 10..).unwrap_or(&[]);
    if !tail.is_empty() && tail.iter().all(|s| s.brake_state == 2) {
        m.holding_torque_nm =
            Some(tail.iter().map(|s| s.braking_torque_nm).sum::<f64>() / tail.len() as f64);
    }
    if periodic {
        let early: Vec<&Sample> = samples.iter().filter(|s| s.t_s < window_start).collect();
        let span = |f: fn(&Sample) -> f64| {
            let hi = early.iter().map(|s| f(s)).fold(f64::MIN, f64::max);
            let lo = early.iter().map(|s| f(s)).fold(f64::MAX, f64::min);
            if hi >= lo {
                hi - lo
            } else {
                0.0
            }
        };
        let travel = span(|s| s.ball_axial_m).max(span(|s| s.shaft_axial_m));
        if travel > 0.0 {
            m.axial_travel_mm = Some(travel * 1e3);
        }
        let (p, trough) = period_and_trough(&window);
        m.period_s = p;
        if let Some(t) = trough {
            m.trough_braking_torque_nm = t;
        }
    }
    m
}

/// Period from upward crossings of the mid level, and the mean per-cycle minimum.
fn period_and_trough(window: &[&Sample]) -> (Option<f64>, Option<f64>) {
    let hi = window
        .iter()
        .map(|s| s.braking_torque_nm)
        .fold(f64::MIN, f64::max);
    let lo = window
        .iter()
        .map(|s| s.braking_torque_nm)
        .fold(f64::MAX, f64::min);
    if hi.partial_cmp(&(lo + 1.0)) != Some(std::cmp::Ordering::Greater) {
        return (None, None);
    }
    let mid = 0.5 * (hi + lo);
    let mut ups = Vec::new();
    for pair in window.windows(2) {
        if let [a, b] = pair {
            if a.braking_torque_nm < mid && b.braking_torque_nm >= mid {
                ups.push(b.t_s);
            }
        }
    }
    if ups.len() < 2 {
        return (None, None);
    }
    let (first, last) = match (ups.first(), ups.last()) {
        (Some(f), Some(l)) => (*f, *l),
        _ => return (None, None),
    };
    let period = (last - first) / (ups.len() - 1) as f64;
    let mut minima = Vec::new();
    for pair in ups.windows(2) {
        if let [a, b] = pair {
            let min = window
                .iter()
                .filter(|s| s.t_s >= *a && s.t_s < *b)
                .map(|s| s.braking_torque_nm)
                .fold(f64::MAX, f64::min);
            minima.push(min);
        }
    }
    let trough = if minima.is_empty() {
        None
    } else {
        Some(minima.iter().sum::<f64>() / minima.len() as f64)
    };
    (Some(period), trough)
}
