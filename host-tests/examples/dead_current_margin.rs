//! The healthy margin of the dead-current-reading check (`src/monitor/dead_current.rs`): over
//! the Monte Carlo's nominal draws, the lowest block mean of the drive torque's magnitude that
//! the check would judge (drive on, the output turning faster than
//! `thresholds.dead_current_speed_rad_s` over the block, the pack seen holding the output
//! within the hold memory), computed in f64 from the sensor traces with the check's sampling:
//! one sample per 16 ticks, blocks of 8, the first block after a drive edge not judged, none in
//! the monitor's first 0.06 s.
//!
//! `cargo run --release -p host-tests --example dead_current_margin -- [RUNS] [SEED]`
//! (defaults 2000 and 2026). docs/decisions.md, "Dead current reading check", quotes it.

use host_tests::family::runs_and_seed;
use host_tests::mc::{draw_legacy as draw, draw_trace};
use noback::monitor::Config;
use noback::sensors::SensorConfig;

/// Ticks per window and windows per block (the check's constants).
const WINDOW: usize = 16;
const BLOCK: usize = 8;
/// Hold memory (windows).
const MEMORY: u32 = 32;

fn main() {
    let mut args = std::env::args().skip(1);
    let (runs, seed) = runs_and_seed(&mut args, 2000, 2026);
    let config = Config::physical_reading();
    let s: SensorConfig = config.sensors;
    let nm_per_code = s.input_torque_nm(s.amps_per_count());
    let mid = f64::from(1_u32 << (s.current_adc_bits - 1));
    let out_counts = 1_i64 << s.output_encoder_bits;
    let min_travel = config.thresholds.dead_current_speed_rad_s * (WINDOW * BLOCK) as f64
        / config.tick_hz
        / s.output_rad_per_count();
    let mut lowest: Vec<(f64, u64, String)> = Vec::new();
    let mut judged = 0_usize;
    for index in 0..runs {
        let d = draw(seed, index, None);
        let trace = match draw_trace(&d) {
            Ok(t) => t,
            Err(e) => {
                eprintln!("draw {index}: {e}");
                continue;
            }
        };
        let rows = &trace.rows;
        let mut best: Option<(f64, f64)> = None;
        let (mut sum_u, mut sum_travel, mut windows, mut armed) = (0.0, 0_i64, 0, false);
        let (mut dir, mut since_hold) = (0_i64, u32::MAX);
        let mut prev_out = rows.first().map_or(0, |r| i64::from(r.output_count));
        for (k, r) in rows.iter().enumerate().skip(WINDOW - 1).step_by(WINDOW) {
            let out = i64::from(r.output_count);
            if !r.drive_on {
                (sum_u, sum_travel, windows, armed) = (0.0, 0, 0, false);
                (dir, since_hold) = (0, u32::MAX);
                prev_out = out;
                continue;
            }
            let mut travel = (out - prev_out).rem_euclid(out_counts);
            if travel >= out_counts / 2 {
                travel -= out_counts;
            }
            prev_out = out;
            let thrown_back = travel * dir < 0;
            since_hold = if travel.abs() <= 1 || thrown_back {
                0
            } else {
                since_hold.saturating_add(1)
            };
            if travel != 0 {
                dir = travel.signum();
            }
            sum_u += (f64::from(r.current_code) - mid).abs() * nm_per_code;
            sum_travel += travel.abs();
            windows += 1;
            if windows < BLOCK {
                continue;
            }
            let mean = sum_u / BLOCK as f64;
            if armed
                && since_hold < MEMORY
                && sum_travel as f64 > min_travel
                && rows.get(k).is_some_and(|r| r.t_s > 0.06)
            {
                judged += 1;
                if best.is_none_or(|(m, _)| mean < m) {
                    best = Some((mean, r.t_s));
                }
            }
            (sum_u, sum_travel, windows, armed) = (0.0, 0, 0, true);
        }
        if let Some((mean, t)) = best {
            lowest.push((
                mean,
                index,
                format!(
                    "{:?}, load {:.1} N·m, speed {:.1} rad/s, at {t:.3} s",
                    d.scene.kind, d.scene.load_torque_nm, d.scene.initial_speed_rad_s
                ),
            ));
        }
    }
    lowest.sort_by(|a, b| a.0.total_cmp(&b.0));
    println!(
        "{runs} nominal draws (seed {seed}): {judged} blocks judged in {} draws; threshold {} N·m",
        lowest.len(),
        config.thresholds.dead_current_nm
    );
    println!("lowest block means of |drive torque| (N·m):");
    for (mean, index, what) in lowest.iter().take(5) {
        println!("  {mean:.3}  draw {index}: {what}");
    }
}
