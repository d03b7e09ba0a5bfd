//! The margin of the `brake_degraded` check (`checks/overrunning.rs`): for each draw of a
//! family, the most negative 20 ms mean of the drive torque along the output's motion, as the
//! monitor reports it, over windows where the drive is on and both shafts turn the same way
//! throughout (the check's conditions, sampled every tick instead of its 2.5 kHz). Healthy draws
//! against draws with each holding fault (onset and severity as the Monte Carlo draws them);
//! also the healthy draws in which the monitor raised `brake_degraded`.
//!
//! `cargo run --release -p host-tests --example held_back_margin -- [RUNS] [SEED] [plant]
//! [healthy]` (defaults 300, 2026, the physical-default family, every row; `healthy`: the
//! healthy row alone, for a large false-warning campaign).

use host_tests::accuracy::run_monitor;
use host_tests::family::{form, ExampleArgs};
use host_tests::mc::{draw_in, draw_trace};
use noback::monitor::{Estimate, Scene};
use noback_twin::fault::FaultKind;

/// Ticks per window: 20 ms at 10 kHz (`thresholds.held_back_time_s`).
const WINDOW: usize = 200;
/// The stick band (rad/s, `thresholds.stick_speed_rad_s`).
const STICK: f64 = 0.3;

/// The most negative window mean of the drive torque along the motion from `from_s` on.
fn most_held_back(e: &[Estimate], from_s: f64) -> Option<f64> {
    let dir = |x: f64| {
        if x > STICK {
            1
        } else if x < -STICK {
            -1
        } else {
            0
        }
    };
    let along: Vec<Option<(i32, f64)>> = e
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let w = s.output_speed_rad_s.to_num::<f64>();
            let d = dir(w);
            let driving = matches!(s.scene, Scene::Driving | Scene::Overrunning);
            (k as f64 * 1e-4 >= from_s
                && driving
                && d != 0
                && dir(s.input_speed_rad_s.to_num::<f64>()) == d)
                .then(|| (d, s.drive_torque_nm.to_num::<f64>() * f64::from(d)))
        })
        .collect();
    along
        .windows(WINDOW)
        .filter_map(|w| {
            let first = w.first().copied().flatten()?.0;
            let all: Option<Vec<f64>> = w
                .iter()
                .map(|x| x.filter(|(d, _)| *d == first).map(|(_, a)| a))
                .collect();
            all.map(|a| a.iter().sum::<f64>() / WINDOW as f64)
        })
        .min_by(f64::total_cmp)
}

fn main() -> Result<(), String> {
    let a = ExampleArgs::parse(300, 2026);
    let (runs, seed, family) = (a.runs, a.seed, a.family);
    let healthy_only = a.has("healthy");
    println!(
        "family {}, seed {seed}, {runs} draws per row; N·m along the motion",
        family.name()
    );
    let kinds = [
        None,
        Some(FaultKind::FrictionLoss),
        Some(FaultKind::SpringBroken),
        Some(FaultKind::PackWear),
        Some(FaultKind::RampJam),
    ];
    for fault in kinds
        .into_iter()
        .take(if healthy_only { 1 } else { kinds.len() })
    {
        let mut seen: Vec<(f64, u64, &str, f64)> = Vec::new();
        let mut warned: Vec<u64> = Vec::new();
        for i in 0..runs {
            let d = draw_in(family, seed, i, fault);
            let trace = draw_trace(&d)?;
            let estimates = run_monitor(&trace, family.config())?;
            if estimates.iter().any(|e| e.flags.brake_degraded) {
                warned.push(i);
            }
            // From the observer's settling (power-on) or the fault's onset.
            let from = 0.06_f64.max(d.scene.faults.first().map_or(0.0, |f| f.at_s));
            if let Some(m) = most_held_back(&estimates, from) {
                seen.push((m, i, form(&d.scene), d.scene.load_torque_nm));
            }
        }
        seen.sort_by(|a, b| a.0.total_cmp(&b.0));
        let below = |t: f64| seen.iter().filter(|s| s.0 < t).count();
        let name = fault.map_or("healthy".to_string(), |k| format!("{k:?}"));
        println!(
            "{name:13} draws with a window {:4}; below −1: {:3}, −3: {:3}, −5: {:3}; most held back: {}",
            seen.len(),
            below(-1.0),
            below(-3.0),
            below(-5.0),
            seen.iter()
                .take(3)
                .map(|(m, i, f, l)| format!("{m:.2} (run {i}, {f}, load {l:.1})"))
                .collect::<Vec<_>>()
                .join(", ")
        );
        if fault.is_none() {
            println!(
                "healthy draws that raised brake_degraded: {} {warned:?}",
                warned.len()
            );
        }
    }
    Ok(())
}
