//! One healthy plant-family run read closely: its draw, every flag with its time, which check
//! raised the first (the first flag gone with that check's threshold out of reach), and the
//! monitor's estimate over the 20 ms before it (`DETAIL_MS` for longer) (docs/decisions.md, "The plant family's false
//! alarms at tuning seed 4242").
//!
//! `cargo run --release -p host-tests --example false_alarm_detail -- SEED RUN [RUN …]`

use host_tests::accuracy::{compare, run_monitor};
use host_tests::family::{form, Family};
use host_tests::mc::{draw_in, draw_trace, not_driven};
use noback::monitor::{Config, Thresholds};

/// Puts one check's thresholds out of reach.
type SwitchOff = fn(&mut Thresholds);

/// Each check family with its switch.
const CHECKS: [(&str, SwitchOff); 7] = [
    ("drive step", |t| t.step_allowance_nm = 1e3),
    ("drag (the reference or a lagging output)", |t| {
        t.drag_allowance_nm = 1e3
    }),
    ("braking envelope", |t| {
        t.braking_angle_factor = 16.0;
        t.undecelerated_allowance_rad = 1.0;
        t.braking_grace_s = 10.0;
    }),
    ("capacity margin", |t| t.min_capacity_margin = 0.1),
    ("creep", |t| t.creep_limit_rad = 100.0),
    ("stuck counter", |t| {
        t.max_lost_motion_rad = 100.0;
        t.free_input_travel_rad = 100.0;
    }),
    ("dead current", |t| t.dead_current_nm = 1e-3),
];

/// Samples shown before the first flag and the stride: 20 ms every 1 ms, or `DETAIL_MS`
/// milliseconds in about 40 lines.
fn window() -> (usize, usize) {
    let ms: usize = match std::env::var("DETAIL_MS") {
        Err(_) => 20,
        Ok(v) => v.parse().unwrap_or_else(|e| {
            eprintln!("error: DETAIL_MS '{v}' is not a whole number of milliseconds ({e})");
            std::process::exit(2)
        }),
    };
    (ms.saturating_mul(10), (ms.saturating_mul(10) / 40).max(10))
}

fn main() -> Result<(), String> {
    let args: Vec<u64> = std::env::args()
        .skip(1)
        .map(|s| {
            s.parse().unwrap_or_else(|e| {
                eprintln!("error: '{s}' is not a whole number ({e})");
                std::process::exit(2)
            })
        })
        .collect();
    let Some((&seed, runs)) = args.split_first() else {
        eprintln!("error: usage: false_alarm_detail SEED RUN [RUN …]");
        std::process::exit(2)
    };
    let (span, every) = window();
    for &i in runs {
        let d = draw_in(Family::Plant, seed, i, None);
        let s = &d.scene;
        let trace = draw_trace(&d)?;
        let est = run_monitor(&trace, Family::Plant.config())?;
        let acc = compare(&trace, &est);
        println!(
            "run {i}: {} {:?}, load {:.2} N·m, speed {:.2} rad/s, cut {:?} s, mirrored {}, apart {}",
            form(s),
            s.kind,
            s.load_torque_nm,
            s.initial_speed_rad_s,
            s.release_at_s,
            d.mirrored,
            not_driven(&trace, &s.sensors)
        );
        println!("  open {:?}", s.open);
        println!("  noise {:?}", s.noise);
        for f in &acc.flags {
            println!("  flag {} at {:.4} s", f.flag, f.t_s);
        }
        let Some(first) = acc.flags.first() else {
            continue;
        };
        for (name, off) in CHECKS {
            let mut c: Config = Family::Plant.config();
            off(&mut c.thresholds);
            let Ok(e) = run_monitor(&trace, c) else {
                println!("  {name}: out of the format's reach");
                continue;
            };
            let without = compare(&trace, &e);
            if without.flags.first().is_none_or(|f| f.t_s > first.t_s) {
                println!("  raised by: {name}");
            }
        }
        let at = (first.t_s * trace.sample_rate_hz).round() as usize;
        for k in (at.saturating_sub(span)..=at.min(est.len().saturating_sub(1))).step_by(every) {
            let (e, r) = (&est[k], &trace.rows[k]);
            println!(
                "  {:.4} {:?} {:?} load {:7.3} brake {:7.3} meas {:7.3} drive {:7.3} w {:7.3} win {:7.3} | twin w_out {:7.3} brake {:7.3} state {}",
                r.t_s,
                e.scene,
                e.brake,
                e.load_torque_nm.to_num::<f64>(),
                e.braking_torque_nm.to_num::<f64>(),
                e.measured_braking_torque_nm.to_num::<f64>(),
                e.drive_torque_nm.to_num::<f64>(),
                e.output_speed_rad_s.to_num::<f64>(),
                e.input_speed_rad_s.to_num::<f64>(),
                r.output_speed_rad_s,
                r.braking_torque_nm,
                r.brake_state,
            );
        }
    }
    Ok(())
}
