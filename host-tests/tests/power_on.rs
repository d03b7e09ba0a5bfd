//! Power-on with the brake already failing: the door is held by a pack that has lost most of
//! its friction when the monitor starts, so the output slips from the first tick with the drive
//! off. The monitor must flag it (brake_slip or brake_weak), and must not when the pack is
//! healthy. Traces come from the twin (physical reading). And power-on into a running drive: a
//! drive fault soon after is flagged.

use host_tests::accuracy::{compare, monitor_on_scene, run_monitor};
use host_tests::mc::{draw_trace, Draw};
use noback::monitor::Config;
use noback_twin::fault::{Fault, FaultKind};
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};

fn flags_after_power_on(fault: Option<Fault>) -> Vec<(&'static str, f64)> {
    let mut scene = Scene::builtin(SceneKind::Hold, Reading::Physical);
    scene.faults.extend(fault);
    let (_, acc) = monitor_on_scene(&scene).expect("twin and monitor");
    acc.flag_times()
}

#[test]
fn a_pack_failing_at_power_on_is_flagged_and_a_healthy_one_is_not() {
    let healthy = flags_after_power_on(None);
    assert!(healthy.is_empty(), "healthy hold raised {healthy:?}");
    let failing = flags_after_power_on(Some(Fault {
        kind: FaultKind::FrictionLoss,
        at_s: 0.0,
        severity: 0.9,
    }));
    let brake = failing
        .iter()
        .find(|(f, _)| *f == "brake_slip" || *f == "brake_weak");
    assert!(
        brake.is_some(),
        "failing pack at power-on not flagged: {failing:?}"
    );
}

/// Powered on into a running drive (the twin run for `mc::PRE_ROLL_S` first, past its own
/// start-up transient), a drag or a lost current gain that appears 60 ms later is flagged
/// within 50 ms: the observer starts from the measured motion and the drive checks are armed
/// ≈ 50 ms after power-on. With the full 0.1 s settling they are armed only at ≈ 0.12 s and the
/// fault is read as part of the load (docs/monitor-design.md, "Power-on into a running drive").
#[test]
fn a_drive_fault_60_ms_after_power_on_into_a_running_drive_is_flagged() {
    for (kind, flag) in [
        (FaultKind::Drag, "brake_drag"),
        (FaultKind::CurrentOpen, "sensor_fault"),
    ] {
        let mut scene = Scene::builtin(SceneKind::Drive, Reading::Physical);
        scene.load_torque_nm = 20.0;
        scene.initial_speed_rad_s = 10.0;
        let fault = Fault {
            kind,
            at_s: 0.06,
            severity: 0.7,
        };
        scene.faults.push(fault);
        let trace = draw_trace(&Draw {
            scene,
            mirrored: false,
        })
        .expect("twin");
        let flag_within = |config: Config| {
            let acc = compare(&trace, &run_monitor(&trace, config).expect("monitor"));
            assert!(
                acc.flags.iter().all(|f| f.t_s >= fault.at_s),
                "{kind:?}: flagged before the onset: {:?}",
                acc.flag_times()
            );
            acc.flags
                .iter()
                .find(|f| f.flag == flag)
                .map(|f| f.t_s - fault.at_s)
                .filter(|l| *l <= 0.05)
        };
        let seeded = flag_within(Config::default());
        println!("{kind:?} 60 ms after power-on: {flag} after {seeded:?} s");
        assert!(seeded.is_some(), "{kind:?}: {flag} not raised within 50 ms");
        let mut unseeded = Config::default();
        unseeded.thresholds.power_on_settle_s = unseeded.thresholds.settle_time_s;
        assert_eq!(
            flag_within(unseeded),
            None,
            "{kind:?}: with the full settling the fault should be read as load"
        );
    }
}
