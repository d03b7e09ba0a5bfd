//! What a pack drag changes in continuous closing's chatter, where the monitor misses it
//! (docs/decisions.md, "Where the misses fall"): for each drag draw of the Monte Carlo
//! that the shipped monitor misses in continuous closing, the same draw without the fault is
//! run too, and the twin's truths are compared over the 50 ms after the onset — the mean drive
//! torque, the mean pack torque, the share of the time the pack is locked, the output's mean
//! speed. It also asks whether any check of the chatter's free-run phases (the drive on, the
//! pack released and slipping at its drag, the shafts together: the only phase where the
//! load, the drive and a drag meet in one quasi-static balance) could have answered in time:
//! a free-run phase of at least 4 ms must start after the onset and end within 50 ms of it.
//!
//! `cargo run --release -p host-tests --example drag_in_chatter -- [RUNS] [SEED]` (defaults
//! 500 and 2026).

use host_tests::accuracy::{compare, detection_latency_s, manifest_time, run_monitor};
use host_tests::family::runs_and_seed;
use host_tests::mc::{draw_legacy as draw, draw_trace, scene_after, Context, Draw, PRE_ROLL_S};
use noback::monitor::Config;
use noback_twin::fault::FaultKind;
use noback_twin::model::Sample;

/// The draw's scene as the Monte Carlo runs it (the twin started `PRE_ROLL_S` earlier),
/// with or without its fault.
fn twin_samples(d: &Draw, with_fault: bool) -> Result<Vec<Sample>, String> {
    let mut scene = scene_after(d, PRE_ROLL_S);
    if !with_fault {
        scene.faults.clear();
    }
    noback_twin::sim::run(&scene)
        .map(|r| r.samples)
        .map_err(|e| e.to_string())
}

/// Means over the drive-on samples in [a, b) (twin time): drive torque, pack torque, locked
/// share, output speed.
fn means(samples: &[Sample], a: f64, b: f64) -> [f64; 4] {
    let w: Vec<&Sample> = samples
        .iter()
        .filter(|s| s.t_s >= a && s.t_s < b && s.drive_on)
        .collect();
    let n = w.len().max(1) as f64;
    let sum = |f: &dyn Fn(&Sample) -> f64| w.iter().map(|s| f(s)).sum::<f64>() / n;
    [
        sum(&|s| s.drive_torque_nm),
        sum(&|s| s.braking_torque_nm),
        sum(&|s| f64::from(u8::from(s.brake_state == 2))),
        sum(&|s| s.output_speed_rad_s),
    ]
}

/// The first free-run phase (≥ 4 ms) starting at or after `from` (twin time): its end.
fn first_free_run_end(samples: &[Sample], from: f64) -> Option<f64> {
    let free = |s: &Sample| {
        s.drive_on
            && s.brake_state == 1
            && s.braking_torque_nm < 40.0
            && (s.output_speed_rad_s - s.input_speed_rad_s).abs() < 0.5
            && s.output_speed_rad_s.abs() > 1.0
    };
    let mut k = samples.iter().position(|s| s.t_s >= from)?;
    while k < samples.len() {
        if samples.get(k).is_some_and(free) {
            let start = k;
            while samples.get(k).is_some_and(free) {
                k += 1;
            }
            let (t0, t1) = (samples.get(start)?.t_s, samples.get(k - 1)?.t_s);
            if t1 - t0 >= 0.004 {
                return Some(t1);
            }
        }
        k += 1;
    }
    None
}

fn main() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let (runs, seed) = runs_and_seed(&mut args, 500, 2026);
    let config = Config::physical_reading();
    let (mut manifested, mut detected, mut cc_missed, mut in_time) = (0, 0, 0, 0);
    println!(
        "drag misses in continuous closing (seed {seed}): means over the 50 ms after the \
         onset, healthy → with the drag"
    );
    for index in 0..runs {
        let d = draw(seed, index, Some(FaultKind::Drag));
        let Some(fault) = d.scene.faults.first().copied() else {
            continue;
        };
        let trace = draw_trace(&d)?;
        let Some(manifest) = manifest_time(&fault, &trace) else {
            continue;
        };
        manifested += 1;
        let acc = compare(&trace, &run_monitor(&trace, config)?);
        if detection_latency_s(&fault, &trace, &acc).is_some_and(|l| l <= 0.05) {
            detected += 1;
            continue;
        }
        if Context::of(fault.at_s, &trace, d.scene.kind, &config) != Context::ContinuousClosing {
            continue;
        }
        cc_missed += 1;
        let (a, b) = (fault.at_s + PRE_ROLL_S, fault.at_s + PRE_ROLL_S + 0.05);
        let faulty = twin_samples(&d, true)?;
        let healthy = twin_samples(&d, false)?;
        let [uh, th, lh, vh] = means(&healthy, a, b);
        let [uf, tf, lf, vf] = means(&faulty, a, b);
        let end = first_free_run_end(&faulty, a);
        let answerable = end.is_some_and(|e| e <= manifest + PRE_ROLL_S + 0.05);
        if answerable {
            in_time += 1;
        }
        println!(
            "  draw {index:3}: load {:4.1} N·m, severity {:.2}: drive {uh:5.1} → {uf:5.1} N·m, \
             pack {th:6.1} → {tf:6.1} N·m, locked {lh:.2} → {lf:.2}, output {vh:4.1} → {vf:4.1} \
             rad/s; a free-run phase ends {}",
            d.scene.load_torque_nm,
            fault.severity,
            end.map_or("never after the onset".to_string(), |e| format!(
                "{:.1} ms after the onset",
                (e - a) * 1e3
            )),
        );
    }
    let pct = |n: usize| 100.0 * n as f64 / manifested.max(1) as f64;
    println!(
        "manifested {manifested}, detected within 50 ms {detected} ({:.1} %); missed in \
         continuous closing {cc_missed}, of which a free-run phase ends within 50 ms in \
         {in_time}: a perfect free-run check would reach {:.1} %",
        pct(detected),
        pct(detected + in_time)
    );
    Ok(())
}
