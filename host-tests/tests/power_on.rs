//! Power-on with the brake already failing: the door is held by a pack that has lost most of
//! its friction when the monitor starts, so the output slips from the first tick with the drive
//! off. The monitor must flag it (brake_slip or brake_weak), and must not when the pack is
//! healthy. Traces come from the twin (physical reading).

use host_tests::accuracy::monitor_on_scene;
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
