//! Convergence of every metric of every built-in scene in both readings (issue 18): its value at
//! tolerances 1e-4 … 1e-10, the reference (the value at 1e-10) and the loosest tolerance from
//! which every tighter one stays within 1 % of it. A metric that does not settle is reported
//! with its spread and never used as a headline. `examples/converge.rs` writes the committed
//! reference (`twin/tests/reference/converged.json`) and docs/results/convergence.md.

use crate::metrics::{self, Metrics};
use crate::reading::Reading;
use crate::scene::{Scene, SceneKind};
use crate::sim;
use crate::solver::SolverError;
use serde::{Deserialize, Serialize};

/// Tolerances of the study, loosest first; the last is the reference.
pub const TOLERANCES: [f64; 7] = [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10];
/// A metric has settled when it stays within this of the reference.
pub const SETTLE: f64 = 0.01;
/// Absolute slack below which two values are equal whatever their ratio (metrics near 0).
pub const ABS_SLACK: f64 = 1e-6;

type Get = fn(&Metrics) -> Option<f64>;

/// The metrics studied, by name.
pub const METRICS: [(&str, Get); 9] = [
    ("braking_time_s", |m| m.braking_time_s),
    ("braking_angle_rad", |m| m.braking_angle_rad),
    ("contact_lag_s", |m| m.contact_lag_s),
    ("holding_torque_nm", |m| m.holding_torque_nm),
    ("peak_braking_torque_nm", |m| Some(m.peak_braking_torque_nm)),
    ("trough_braking_torque_nm", |m| {
        Some(m.trough_braking_torque_nm)
    }),
    ("period_s", |m| m.period_s),
    ("max_output_speed_rad_s", |m| Some(m.max_output_speed_rad_s)),
    ("axial_travel_mm", |m| m.axial_travel_mm),
];

/// One metric of one scene and reading across the tolerances.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Entry {
    /// Scene.
    pub scene: String,
    /// Reading.
    pub reading: String,
    /// Metric name (a field of [`Metrics`]).
    pub metric: String,
    /// Value at each of [`TOLERANCES`] (`None` where the metric does not exist in that run).
    pub values: Vec<Option<f64>>,
    /// The reference: the value at the tightest tolerance.
    pub reference: Option<f64>,
    /// Tolerance of the reference.
    pub reference_tolerance: f64,
    /// Loosest tolerance from which every tighter one is within 1 % of the reference; `None`
    /// if the metric does not settle (then `spread` says how far it wanders).
    pub settles_at: Option<f64>,
    /// (min, max) over the tolerances.
    pub spread: Option<(f64, f64)>,
}

/// Whether `v` is within [`SETTLE`] of `reference`.
pub fn close(v: Option<f64>, reference: Option<f64>) -> bool {
    match (v, reference) {
        (None, None) => true,
        (Some(v), Some(r)) => (v - r).abs() <= SETTLE * r.abs() || (v - r).abs() <= ABS_SLACK,
        _ => false,
    }
}

/// Settling tolerance and spread of one row of values.
pub fn settle(values: &[Option<f64>]) -> (Option<f64>, Option<(f64, f64)>) {
    let reference = values.last().copied().flatten();
    let mut settles = None;
    for (i, tol) in TOLERANCES.iter().enumerate().rev() {
        let tail = values.get(i..).unwrap_or(&[]);
        if tail.iter().all(|v| close(*v, reference)) {
            settles = Some(*tol);
        } else {
            break;
        }
    }
    // The reference alone "settles" trivially: demand agreement with the next looser one.
    if settles == TOLERANCES.last().copied() {
        settles = None;
    }
    let present: Vec<f64> = values.iter().flatten().copied().collect();
    let spread = if present.is_empty() {
        None
    } else {
        Some((
            present.iter().copied().fold(f64::INFINITY, f64::min),
            present.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        ))
    };
    (settles, spread)
}

/// Run one scene at every tolerance and tabulate its metrics.
pub fn study(kind: SceneKind, reading: Reading) -> Result<Vec<Entry>, SolverError> {
    let mut runs = Vec::new();
    for tol in TOLERANCES {
        let mut s = Scene::builtin(kind, reading);
        s.tolerance = tol;
        let r = sim::run(&s)?;
        runs.push(metrics::compute(&s, &r.samples, &r.stats, 0.0));
    }
    Ok(METRICS
        .iter()
        .filter_map(|(name, get)| {
            let values: Vec<Option<f64>> = runs.iter().map(get).collect();
            if values.iter().all(Option::is_none) {
                return None;
            }
            let (settles_at, spread) = settle(&values);
            Some(Entry {
                scene: kind.name().into(),
                reading: reading.name().into(),
                metric: (*name).into(),
                reference: values.last().copied().flatten(),
                reference_tolerance: TOLERANCES[TOLERANCES.len() - 1],
                values,
                settles_at,
                spread,
            })
        })
        .collect())
}

/// The metric `name` of `m`.
pub fn metric(m: &Metrics, name: &str) -> Option<f64> {
    METRICS
        .iter()
        .find(|(n, _)| *n == name)
        .and_then(|(_, get)| get(m))
}

fn sig(v: Option<f64>) -> String {
    v.map_or("—".into(), |v| format!("{v:.5}"))
}

/// docs/results/convergence.md (no wall times: the same bytes on an unchanged tree).
pub fn markdown(entries: &[Entry]) -> String {
    let mut s = String::from(
        "# Convergence of the twin's metrics\n\nWritten by `cargo run --release -p noback-twin \
         --example converge`; do not edit. Every metric of every built-in scene in both \
         readings at tolerances 1e-4 … 1e-10. *Settles at*: the loosest tolerance from which \
         every tighter one is within 1 % of the 1e-10 reference (or 1e-6 absolute); *no* = it \
         does not settle: its spread is reported and it is never a headline. The references \
         are committed in `twin/tests/reference/converged.json`; `twin/tests/converged.rs` \
         checks the default tolerance (1e-5) against them.\n\n",
    );
    s.push_str("| scene | reading | metric |");
    for t in TOLERANCES {
        s.push_str(&format!(" {t:e} |"));
    }
    s.push_str(" settles at |\n|---|---|---|");
    for _ in TOLERANCES {
        s.push_str("---|");
    }
    s.push_str("---|\n");
    for e in entries {
        s.push_str(&format!("| {} | {} | {} |", e.scene, e.reading, e.metric));
        for v in &e.values {
            s.push_str(&format!(" {} |", sig(*v)));
        }
        let settles = match (e.settles_at, e.spread) {
            (Some(t), _) => format!("{t:e}"),
            (None, Some((lo, hi))) => format!("no ({lo:.4}–{hi:.4})"),
            (None, None) => "no".into(),
        };
        s.push_str(&format!(" {settles} |\n"));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settling_rules() {
        let v = |x: f64| Some(x);
        let row = [v(1.2), v(1.05), v(1.001), v(1.0), v(1.0), v(1.0), v(1.0)];
        assert_eq!(settle(&row).0, Some(1e-6));
        // Wanders at the end: never settles.
        let row = [v(1.0), v(1.0), v(1.0), v(1.0), v(1.0), v(1.2), v(1.0)];
        assert_eq!(settle(&row).0, None);
        assert_eq!(settle(&row).1, Some((1.0, 1.2)));
        // Appears only at the tight end: settles where it appears and stays.
        let row = [None, None, None, None, v(2.0), v(2.0), v(2.0)];
        assert_eq!(settle(&row).0, Some(1e-8));
    }
}
