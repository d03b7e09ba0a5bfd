//! Faults change what they say: a pack that loses its friction lets the load run away; sensor
//! faults change only the raw readings.

use noback_twin::fault::{Fault, FaultKind};
use noback_twin::metrics;
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::sensing;
use noback_twin::sim::{self, SAMPLE_RATE_HZ};

#[test]
fn friction_loss_lets_the_load_run_away() {
    for reading in [Reading::Paper, Reading::Physical] {
        let mut s = Scene::builtin(SceneKind::Hold, reading);
        s.duration_s = 0.3;
        s.faults.push(Fault {
            kind: FaultKind::FrictionLoss,
            at_s: 0.1,
            severity: 0.8,
        });
        let r = sim::run(&s).unwrap();
        let m = metrics::compute(&s, &r.samples, &r.stats, r.wall_s);
        // Before the fault the brake holds; after it the output accelerates in the load direction.
        let before = r.samples.iter().find(|x| x.t_s >= 0.09).unwrap();
        assert!(
            before.output_speed_rad_s.abs() < 0.1,
            "{reading:?}: {}",
            before.output_speed_rad_s
        );
        let last = r.samples.last().unwrap();
        assert!(
            last.output_speed_rad_s > 5.0,
            "{reading:?}: {}",
            last.output_speed_rad_s
        );
        assert!(m.holding_torque_nm.is_none());
    }
}

#[test]
fn sensor_faults_touch_only_the_readings() {
    let mut s = Scene::builtin(SceneKind::Drive, Reading::Paper);
    s.duration_s = 0.1;
    let r = sim::run(&s).unwrap();
    let healthy = sensing::trace(&r.samples, &s.sensors, &s.noise, &[], SAMPLE_RATE_HZ);
    let faults = [
        Fault {
            kind: FaultKind::EncoderStuck,
            at_s: 0.05,
            severity: 1.0,
        },
        Fault {
            kind: FaultKind::CurrentOpen,
            at_s: 0.05,
            severity: 1.0,
        },
    ];
    let faulty = sensing::trace(&r.samples, &s.sensors, &s.noise, &faults, SAMPLE_RATE_HZ);
    let at = |t: f64| healthy.rows.iter().position(|x| x.t_s >= t).unwrap();
    let (i0, i1) = (at(0.06), at(0.09));
    // Healthy: the output encoder moves and the drive draws current.
    assert_ne!(healthy.rows[i0].output_count, healthy.rows[i1].output_count);
    assert_ne!(healthy.rows[i1].current_code, 2048);
    // Faulty: frozen encoder, mid-scale (0 A) current, same truth.
    assert_eq!(faulty.rows[i0].output_count, faulty.rows[i1].output_count);
    assert_eq!(faulty.rows[i1].current_code, 2048);
    assert_eq!(
        faulty.rows[i1].output_speed_rad_s,
        healthy.rows[i1].output_speed_rad_s
    );
    // Before the fault the traces agree.
    let early = at(0.04);
    assert_eq!(faulty.rows[early], healthy.rows[early]);
}

/// A ramp jam (the balls cannot climb): at full severity the pack is clamped by the spring
/// alone (≈ 8.4 N·m, below the 20.3 N·m load) and the held door back-drives, in both readings;
/// at 0.3 the load still holds (a partial jam lowers the capacity, it does not show).
#[test]
fn a_full_ramp_jam_lets_the_held_load_back_drive_and_a_partial_one_holds() {
    for reading in [Reading::Paper, Reading::Physical] {
        for (severity, runs_away) in [(1.0, true), (0.3, false)] {
            let mut s = Scene::builtin(SceneKind::Hold, reading);
            s.duration_s = 0.3;
            s.faults.push(Fault {
                kind: FaultKind::RampJam,
                at_s: 0.1,
                severity,
            });
            let r = sim::run(&s).unwrap();
            let last = r.samples.last().unwrap();
            assert_eq!(
                last.output_speed_rad_s > 1.0,
                runs_away,
                "{reading:?} jam {severity}: speed {}",
                last.output_speed_rad_s
            );
        }
    }
}

/// The functional test's drive: at rest until the test starts, then it opens the door against
/// the load (the drive carries the load), slows it to rest and lets go, pushes along the load
/// until the output breaks away, and from the abort angle (from the opening's end) it holds
/// the door at rest.
#[test]
fn the_functional_test_opens_then_pushes_until_breakaway_and_stops_at_the_abort_angle() {
    let s = Scene::builtin(SceneKind::FunctionalTest, Reading::Physical);
    let p = s.test;
    let r = sim::run(&s).unwrap();
    let at = |t: f64| r.samples.iter().find(|x| x.t_s >= t).unwrap();
    let start = at(p.start_s).output_angle_rad;
    assert!((at(0.15).output_angle_rad - start).abs() < 1e-3);
    // Opening: against the load (negative) below the creep speed (the proportional servo's
    // droop under the load), the drive carrying the load.
    let opening = at(p.start_s + 0.8 * p.open_s);
    let w = -opening.output_speed_rad_s / p.creep_speed_rad_s;
    assert!((0.3..=1.0).contains(&w), "{opening:?}");
    assert!(opening.drive_torque_nm < -s.load_torque_nm, "{opening:?}");
    // At rest on the brake when the push starts.
    let rest = at(p.push_s() - 1e-3);
    assert!(rest.output_speed_rad_s.abs() < 0.05, "{rest:?}");
    let peak = r
        .samples
        .iter()
        .filter(|x| x.t_s >= p.push_s())
        .map(|x| x.drive_torque_nm)
        .fold(0.0, f64::max);
    assert!((5.0..20.0).contains(&peak), "breakaway push {peak} N·m");
    let end = r.samples.last().unwrap();
    assert!(
        end.drive_on && end.output_speed_rad_s.abs() < 0.05,
        "{end:?}"
    );
    let travel = end.output_angle_rad - at(p.start_s + p.open_s).output_angle_rad;
    assert!(
        travel >= p.abort_angle_rad && travel < 2.0 * p.abort_angle_rad,
        "travel {travel} rad"
    );
}
