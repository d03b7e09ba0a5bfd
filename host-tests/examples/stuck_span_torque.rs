//! What the drive does while one encoder stands still and the other turns: for each draw that
//! raises `sensor_fault`, the span before it with the drive on and the output counter
//! unchanged, its input travel and the mean |drive torque| over it. A stuck output encoder on
//! a driven door shows the drive's torque; an input turning free of its output shows none.
//!
//! `cargo run --release -p host-tests --example stuck_span_torque -- RUNS SEED [plant]
//! [healthy] [no-free-span] [RUN…]` (defaults: the physical-default family, encoder_stuck draws, runs
//! 0..RUNS).

use host_tests::accuracy::{compare, detection_latency_s, manifest_time, run_monitor};
use host_tests::family::{form, runs_and_seed, Family};
use host_tests::mc::{draw_in, draw_trace, not_driven};
use noback_twin::fault::FaultKind;

fn main() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let (runs, seed) = runs_and_seed(&mut args, 100, 11);
    let rest: Vec<String> = args.collect();
    let family = Family::from_args(&rest);
    let fault = (!rest.iter().any(|a| a == "healthy")).then_some(FaultKind::EncoderStuck);
    let mut c = family.config();
    if rest.iter().any(|a| a == "no-free-span") {
        c.thresholds.driven_torque_nm = 0.0;
    }
    println!(
        "family {}, seed {seed}, {runs} draws, {}",
        family.name(),
        fault.map_or("healthy".into(), |k| format!("{k:?}"))
    );
    let listed: Vec<u64> = rest.iter().filter_map(|a| a.parse().ok()).collect();
    let indices: Vec<u64> = if listed.is_empty() {
        (0..runs).collect()
    } else {
        listed
    };
    for i in indices {
        let d = draw_in(family, seed, i, fault);
        let trace = draw_trace(&d)?;
        let est = run_monitor(&trace, c)?;
        if let (true, Some(f)) = (rest.iter().any(|a| a == "latency"), d.scene.faults.first()) {
            let latency = detection_latency_s(f, &trace, &compare(&trace, &est));
            println!("run {i} {} latency {latency:?}", form(&d.scene));
            continue;
        }
        let Some(at) = est.iter().position(|e| e.flags.sensor_fault) else {
            continue;
        };
        let e = &est[at];
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
        let travel = (e.input_speed_rad_s.to_num::<f64>()).abs() * span.len() as f64 / c.tick_hz;
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
            "run {i:6} {:8} {:?} load {:5.1} at {:.4} s{after}: still span {:5.1} ms, input ≈ {travel:.3} rad, mean |drive| {mean:.2} N·m, apart {}",
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
