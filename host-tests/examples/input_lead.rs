//! How far the input ran ahead of the output when the drive was cut. For each paper-form draw
//! with a cut: the input's lead over the output along the motion from power-on to the cut, its
//! rate over the last 50 ms, the mean |drive torque| and the flags (with the detection latency
//! for a fault draw). After a drive whose input ran ahead, the pack engages only once the output
//! has caught it up; docs/decisions.md, "An input that ran ahead of its output".
//!
//! `cargo run --release -p host-tests --example input_lead -- RUNS SEED [plant] [KIND] [list]`
//! (defaults: healthy draws of the physical-default family; KIND a fault kind as scene files
//! name it, e.g. `friction_loss`; `list` prints every draw, else only those that ran ahead).

use host_tests::accuracy::{compare, detection_latency_s, run_monitor};
use host_tests::family::{form, ExampleArgs};
use host_tests::mc::{draw_in, draw_trace};
use host_tests::stats::quantile_line;
use noback::fx::counter_delta;
use noback_twin::fault::FaultKind;
use noback_twin::trace::Trace;

/// The span the lead's rate is read over before the cut (s).
const RATE_SPAN_S: f64 = 0.05;
/// A rate above this (rad/s) counts as running ahead in the summary: the monitor's stick speed.
const AHEAD_RAD_S: f64 = 0.3;

/// The input's travel less the output's along the output's net motion, summed step by step
/// from the first sample to each (rad; output side).
fn lead(trace: &Trace, s: &noback::sensors::SensorConfig) -> Vec<f64> {
    let (ri, ro) = (s.input_rad_per_motor_count(), s.output_rad_per_count());
    let (mut input, mut out) = (0.0, 0.0);
    let mut lead = vec![0.0];
    for w in trace.rows.windows(2) {
        input += f64::from(counter_delta(
            w[0].motor_count,
            w[1].motor_count,
            s.motor_counter_bits,
        )) * ri;
        out += f64::from(counter_delta(
            w[0].output_count,
            w[1].output_count,
            s.output_encoder_bits,
        )) * ro;
        lead.push((input - out) * out.signum());
    }
    lead
}

fn main() -> Result<(), String> {
    let a = ExampleArgs::parse(2000, 4242);
    let kind = a.rest.iter().find_map(|w| FaultKind::parse(w));
    let (mut ahead, mut together) = (Vec::new(), Vec::new());
    println!(
        "family {}, seed {}, {} draws, {}",
        a.family.name(),
        a.seed,
        a.runs,
        kind.map_or("healthy".into(), |k| format!("{k:?}"))
    );
    for i in 0..a.runs {
        let d = draw_in(a.family, a.seed, i, kind);
        let Some(cut_s) = d.scene.release_at_s else {
            continue;
        };
        if form(&d.scene) != "paper" {
            continue;
        }
        let trace = draw_trace(&d)?;
        let cut = (cut_s * trace.sample_rate_hz) as usize;
        let back = (RATE_SPAN_S * trace.sample_rate_hz) as usize;
        if cut < back || cut >= trace.rows.len() {
            continue;
        }
        let l = lead(&trace, &d.scene.sensors);
        let rate = (l[cut] - l[cut - back]) / RATE_SPAN_S;
        let est = run_monitor(&trace, a.family.config())?;
        let drive = est[..cut]
            .iter()
            .map(|e| e.drive_torque_nm.to_num::<f64>().abs())
            .sum::<f64>()
            / cut as f64;
        let acc = compare(&trace, &est);
        let outcome = match d.scene.faults.first() {
            Some(f) => match detection_latency_s(f, &trace, &acc) {
                Some(l) => format!("detected {:.1} ms after manifesting", l * 1e3),
                None => "not manifested or not detected".into(),
            },
            None => format!("flags {:?}", acc.flag_times()),
        };
        if rate > AHEAD_RAD_S || a.has("list") {
            println!(
                "run {i} {:?} load {:.2} N·m: lead {:.3} rad, rate {:.3} rad/s, drive {:.2} N·m, {outcome}",
                d.scene.kind, d.scene.load_torque_nm, l[cut], rate, drive
            );
        }
        if rate > AHEAD_RAD_S {
            &mut ahead
        } else {
            &mut together
        }
        .push(rate);
    }
    let at = [0.01, 0.5, 0.99];
    println!(
        "ran ahead (rate > {AHEAD_RAD_S} rad/s): {} draws, rate {}",
        ahead.len(),
        quantile_line(ahead, &at)
    );
    println!(
        "the rest: {} draws, rate {}",
        together.len(),
        quantile_line(together, &at)
    );
    Ok(())
}
