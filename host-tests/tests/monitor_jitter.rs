//! The shipped monitor with ±20 % tick jitter: the MCU samples its sensors at instants that
//! wander by up to a fifth of a period around the nominal 100 µs grid while the monitor still
//! integrates with the nominal step. Emulated on the twin's paper braking scenes by
//! interpolating the twin's state at the jittered instants before quantising it. The monitor
//! must stay stable (bounded, no flag) and keep its accuracy targets on the holding torque and
//! the lock time.

use host_tests::accuracy::{compare, run_monitor};
use noback::monitor::Config;
use noback_twin::model::Sample;
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::sensing::Rng;

/// Largest sampling-instant error, in periods.
const JITTER: f64 = 0.2;

/// The twin's samples re-taken at jittered instants (linear interpolation of the continuous
/// quantities, the discrete ones from the nearer sample); the time stamps stay nominal.
fn jittered(samples: &[Sample], seed: u64) -> Vec<Sample> {
    let mut rng = Rng::new(seed);
    let n = samples.len();
    (0..n)
        .map(|k| {
            let nominal = samples[k];
            let shift = JITTER * (2.0 * rng.uniform() - 1.0); // in periods
            let (i, frac) = if shift >= 0.0 {
                (k, shift)
            } else {
                (k.saturating_sub(1), 1.0 + shift)
            };
            let (a, b) = (samples[i], samples[(i + 1).min(n - 1)]);
            let lerp = |x: f64, y: f64| x + frac * (y - x);
            let near = if frac < 0.5 { a } else { b };
            Sample {
                t_s: nominal.t_s,
                output_angle_rad: lerp(a.output_angle_rad, b.output_angle_rad),
                output_speed_rad_s: lerp(a.output_speed_rad_s, b.output_speed_rad_s),
                input_angle_rad: lerp(a.input_angle_rad, b.input_angle_rad),
                input_speed_rad_s: lerp(a.input_speed_rad_s, b.input_speed_rad_s),
                drive_torque_nm: lerp(a.drive_torque_nm, b.drive_torque_nm),
                pressing_force_n: nominal.pressing_force_n,
                braking_torque_nm: nominal.braking_torque_nm,
                brake_state: nominal.brake_state,
                drive_on: near.drive_on,
                ..nominal
            }
        })
        .collect()
}

#[test]
fn jittered_sampling_keeps_the_monitor_stable_and_accurate() {
    for (kind, seed) in [(SceneKind::ReverseLoad, 11), (SceneKind::ForwardLoad, 12)] {
        let scene = Scene::builtin(kind, Reading::Physical);
        let run = noback_twin::sim::run(&scene).expect("twin");
        let samples = jittered(&run.samples, seed);
        let trace = noback_twin::sensing::trace(
            &samples,
            &scene.sensors,
            &scene.noise,
            &scene.faults,
            noback_twin::sim::SAMPLE_RATE_HZ,
        );
        let estimates = run_monitor(&trace, Config::default()).expect("monitor");
        let acc = compare(&trace, &estimates);
        assert!(
            acc.flags.is_empty(),
            "{kind:?}: flags under jitter {:?}",
            acc.flags
        );
        let hold = acc.holding_torque_err_pct().expect("both lock");
        assert!(hold <= 5.0, "{kind:?}: holding torque error {hold} %");
        let lock = acc.lock_time_err_s().expect("the twin locks");
        assert!(lock <= 0.010, "{kind:?}: lock time error {lock} s");
        assert!(estimates
            .iter()
            .all(|e| e.pressing_force_n.to_num::<f64>().is_finite()
                && e.pressing_force_n.to_num::<f64>() < 30_000.0));
    }
}
