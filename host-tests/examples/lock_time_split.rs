//! Where the commissioned braking runs' lock-time and pressing-force misses lie
//! (docs/monitor-limits.md, "Lock time"). The nominal reverse_load and forward_load draws of
//! `monitor-mc --family plant` whose unit acceptance commissions, where twin and monitor both end
//! locked, as on docs/monitor-family.md. Per form and scene:
//! - the monitor's lock after the twin's pack sticks (the page's lock time), and after the twin's
//!   output stops (turns, or falls inside the stick band): the encoders see only the second;
//! - the pressing-force RMS error (% of the compared peak) split by phase: driving, braking (cut
//!   to the monitor's lock), the rattle (150 ms after it), the hold.
//!
//! `cargo run --release -p host-tests --example lock_time_split -- [RUNS] [SEED]`
//! (defaults 2000, 1616).

use host_tests::accuracy::{compare, run_monitor, Accuracy};
use host_tests::family::{form, runs_and_seed};
use host_tests::mc::{braking_draws, commission_draw};
use noback_twin::trace::Trace;
use std::collections::BTreeMap;

/// Error within which a lock counts (issue 16's target, s).
const LOCK_TARGET_S: f64 = 0.010;
/// Force RMS within which a run counts (% of the compared peak).
const FORCE_TARGET_PCT: f64 = 10.0;
/// The rattle after the monitor's lock that the split counts apart (s).
const RATTLE_S: f64 = 0.150;

#[derive(Default)]
struct Tally {
    runs: usize,
    after_stick: Vec<f64>,
    after_stop: Vec<f64>,
    force_over: usize,
    /// Per phase: the squared error's sum over the runs whose force RMS is over the target.
    force_phase: [f64; 4],
    force_total: f64,
}

/// The twin's output stop after the cut: the first sample whose speed has turned against the
/// cut's, or lies inside the monitor's stick band.
fn output_stop(trace: &Trace, cut: f64, band: f64) -> Option<f64> {
    let w0 = trace.rows.iter().find(|r| r.t_s >= cut)?.output_speed_rad_s;
    trace
        .rows
        .iter()
        .find(|r| {
            r.t_s >= cut && (r.output_speed_rad_s * w0 <= 0.0 || r.output_speed_rad_s.abs() < band)
        })
        .map(|r| r.t_s)
}

/// The force error's squares summed by phase (driving, braking, rattle, hold), in (% of peak)².
fn force_phases(acc: &Accuracy, cut: f64, lock: f64) -> [f64; 4] {
    let peak = acc
        .twin_force_n
        .iter()
        .cloned()
        .fold(0.0, f64::max)
        .max(1e-9);
    let n = acc.t_s.len() as f64;
    let mut phase = [0.0; 4];
    for ((t, m), w) in acc
        .t_s
        .iter()
        .zip(&acc.monitor_force_n)
        .zip(&acc.twin_force_n)
    {
        let j = match *t {
            t if t < cut => 0,
            t if t < lock => 1,
            t if t < lock + RATTLE_S => 2,
            _ => 3,
        };
        phase[j] += (100.0 * (m - w) / peak).powi(2) / n;
    }
    phase
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

fn main() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let (runs, seed) = runs_and_seed(&mut args, 2000, 1616);
    let mut by: BTreeMap<String, Tally> = BTreeMap::new();
    for draw in braking_draws(seed, runs) {
        let (_, d, trace) = draw?;
        let Ok(unit) = commission_draw(&d) else {
            continue;
        };
        let band = unit.config.thresholds.stick_speed_rad_s;
        let acc = compare(&trace, &run_monitor(&trace, unit.config)?);
        let (Some(b), Some((stick, Some(lock)))) = (acc.braking(), acc.lock_time_s) else {
            continue;
        };
        let cut = trace
            .rows
            .windows(2)
            .find(|w| w[0].drive_on && !w[1].drive_on)
            .map_or(0.0, |w| w[1].t_s);
        let t = by
            .entry(format!("{} {}", form(&d.scene), d.scene.kind.name()))
            .or_default();
        t.runs += 1;
        t.after_stick.push(lock - stick);
        t.after_stop
            .push(output_stop(&trace, cut, band).map_or(f64::INFINITY, |s| lock - s));
        if b.force_rms_pct > FORCE_TARGET_PCT {
            t.force_over += 1;
            let p = force_phases(&acc, cut, lock);
            for (a, x) in t.force_phase.iter_mut().zip(p) {
                *a += x;
            }
            t.force_total += b.force_rms_pct.powi(2);
        }
    }
    println!("commissioned nominal braking runs of seed {seed} (first {runs} draws), both ending locked:\n");
    println!("| form, scene | runs | lock within 10 ms of the pack's stick | of the output's stop | median lock after the stick (ms) | after the output's stop (ms) | latest after the output's stop (ms) |");
    println!("|---|---|---|---|---|---|---|");
    for (k, t) in &mut by {
        let within = |v: &[f64]| v.iter().filter(|e| e.abs() <= LOCK_TARGET_S).count();
        let latest = t
            .after_stop
            .iter()
            .cloned()
            .fold(f64::NEG_INFINITY, f64::max);
        println!(
            "| {k} | {} | {} | {} | {:.1} | {:.1} | {:.1} |",
            t.runs,
            within(&t.after_stick),
            within(&t.after_stop),
            1e3 * median(&mut t.after_stick),
            1e3 * median(&mut t.after_stop),
            1e3 * latest
        );
    }
    println!("\nruns whose force RMS is over 10 % of the peak: the squared error's share by phase");
    println!("| form, scene | runs over | driving | braking | rattle (150 ms) | hold |");
    println!("|---|---|---|---|---|---|");
    for (k, t) in &by {
        let total: f64 = t.force_phase.iter().sum::<f64>().max(1e-12);
        let [a, b, c, e] = t.force_phase.map(|x| format!("{:.0} %", 100.0 * x / total));
        println!("| {k} | {} | {a} | {b} | {c} | {e} |", t.force_over);
    }
    Ok(())
}
