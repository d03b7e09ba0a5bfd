//! What the drive does while one encoder stands still and the other turns: for each draw that
//! raises `sensor_fault`, the span before it with the drive on and the output counter
//! unchanged, its input travel and the mean |drive torque| over it. A stuck output encoder on
//! a driven door shows the drive's torque; an input turning free of its output shows none.
//!
//! `cargo run --release -p host-tests --example stuck_span_torque -- RUNS SEED [plant]
//! [healthy] [no-free-span] [RUN…]` (defaults: the physical-default family, encoder_stuck draws, runs
//! 0..RUNS).

use host_tests::accuracy::{compare, detection_latency_s, manifest_time, run_monitor};
use host_tests::family::{form, ExampleArgs};
use host_tests::mc::{draw_in, draw_trace, not_driven};
use noback::fx::counter_delta;
use noback_twin::fault::FaultKind;

fn main() -> Result<(), String> {
    let a = ExampleArgs::parse(100, 11);
    let (runs, seed, family) = (a.runs, a.seed, a.family);
    let fault = (!a.has("healthy")).then_some(FaultKind::EncoderStuck);
    let mut c = family.config();
    if a.has("no-free-span") {
        c.thresholds.driven_torque_nm = 0.0;
    }
    println!(
        "family {}, seed {seed}, {runs} draws, {}",
        family.name(),
        fault.map_or("healthy".into(), |k| format!("{k:?}"))
    );
    let listed: Vec<u64> = a.rest.iter().filter_map(|a| a.parse().ok()).collect();
    let indices: Vec<u64> = if listed.is_empty() {
        (0..runs).collect()
    } else {
        listed
    };
    for i in indices {
        let d = draw_in(family, seed, i, fault);
        let trace = draw_trace(&d)?;
        let est = run_monitor(&trace, c)?;
        if let (true, Some(f)) = (a.has("latency"), d.scene.faults.first()) {
            let latency = detection_latency_s(f, &trace, &compare(&trace, &est));
            println!("run {i} {} latency {latency:?}", form(&d.scene));
            continue;
        }
        let Some(at) = est.iter().position(|e| e.flags.sensor_fault) else {
            continue;
        };
        let out = trace.rows[at].output_count;
        let mut start = at;
        while start > 0
            && trace.rows[start - 1].output_count == out
            && trace.rows[start - 1].drive_on
        {
            start -= 1;
        }
        let span = &est[start..=at];
        let mean = span
            .iter()
            .map(|e| e.drive_torque_nm.to_num::<f64>().abs())
            .sum::<f64>()
            / span.len() as f64;
        let sensors = &d.scene.sensors;
        let travel = f64::from(
            counter_delta(
                trace.rows[start].motor_count,
                trace.rows[at].motor_count,
                sensors.motor_counter_bits,
            )
            .unsigned_abs(),
        ) * sensors.input_rad_per_motor_count();
        let manifest = d
            .scene
            .faults
            .first()
            .and_then(|f| manifest_time(f, &trace));
        let after = manifest.map_or(String::new(), |m| {
            format!(
                ", {:.1} ms after manifesting",
                (at as f64 / c.tick_hz - m) * 1e3
            )
        });
        println!(
            "run {i:6} {:8} {:?} load {:5.1} at {:.4} s{after}: still span {:5.1} ms, input {travel:.3} rad, mean |drive| {mean:.2} N·m, apart {}",
            form(&d.scene),
            d.scene.kind,
            d.scene.load_torque_nm,
            at as f64 / c.tick_hz,
            span.len() as f64 * 1e3 / c.tick_hz,
            not_driven(&trace, &d.scene.sensors)
        );
    }
    Ok(())
}
