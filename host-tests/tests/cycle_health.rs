//! The drive's own cycle as a health check (`brake_degraded`, a warning; issue 17, item 1):
//! while the door closes along its load with the drive on, a healthy no-back brakes the load
//! and the drive pushes to unlock it; a pack that lets the load through leaves the drive
//! holding the door back. The twin's worn, jammed or friction-lost pack does that in the
//! physical reading (`cargo run --release -p host-tests --example held_back_margin`;
//! docs/decisions.md, "A pack that lets an overrunning load through").

use host_tests::accuracy::{compare, run_monitor, scene_trace};
use host_tests::family::Family;
use host_tests::mc::{draw_in, draw_trace};
use noback::monitor::Config;
use noback_twin::fault::{Fault, FaultKind};
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};

const ONSET_S: f64 = 0.6;

/// A closing at 20 N·m with `fault` from [`ONSET_S`]: the warning's time and whether the
/// estimate at the end is trusted and reports a capacity margin.
fn closing_with(kind: FaultKind, severity: f64) -> (Option<f64>, bool, bool) {
    let mut scene = Scene::builtin(SceneKind::ContinuousClosing, Reading::Physical);
    scene.load_torque_nm = 20.0;
    scene.duration_s = 1.0;
    scene.faults.push(Fault {
        kind,
        at_s: ONSET_S,
        severity,
    });
    let trace = scene_trace(&scene).expect("twin");
    let estimates = run_monitor(&trace, Config::default()).expect("monitor");
    let acc = compare(&trace, &estimates);
    let warned = acc
        .flags
        .iter()
        .find(|f| f.flag == "brake_degraded")
        .map(|f| f.t_s);
    let last = estimates.last();
    (
        warned,
        last.is_some_and(|e| e.trusted),
        last.is_some_and(|e| e.capacity_margin > 0),
    )
}

#[test]
fn a_pack_that_lets_the_closing_load_through_is_warned_within_the_closing() {
    for kind in [
        FaultKind::PackWear,
        FaultKind::RampJam,
        FaultKind::FrictionLoss,
    ] {
        let (warned, trusted, margin) = closing_with(kind, 0.6);
        println!("{kind:?}: brake_degraded at {warned:?}");
        // The pack lets go within ~10 ms of the onset; a 20 ms block, once the shafts turn
        // together again, then at most one more.
        let at = warned.unwrap_or_else(|| panic!("{kind:?}: no brake_degraded"));
        assert!((ONSET_S..ONSET_S + 0.1).contains(&at), "{kind:?} at {at}");
        assert!(
            !trusted,
            "{kind:?}: the estimate after the warning must be untrusted"
        );
        assert!(
            !margin,
            "{kind:?}: a pack that let the load through has no margin"
        );
    }
}

#[test]
fn a_broken_spring_still_brakes_the_closing_and_is_left_to_the_functional_test() {
    // The ramps still clamp the pack under the load: the drive pushes along the motion.
    assert_eq!(closing_with(FaultKind::SpringBroken, 1.0).0, None);
}

#[test]
fn healthy_closings_whose_output_chatters_against_the_drive_raise_nothing() {
    // Tuning seed 2026's closings whose output is thrown back against a pushing drive for up
    // to 20 ms at a time (a block of one direction without the input would have warned).
    for run in [29, 57, 156, 261, 407, 458, 589, 609, 648, 680, 836] {
        let d = draw_in(Family::PhysicalDefault, 2026, run, None);
        assert_eq!(d.scene.kind, SceneKind::ContinuousClosing);
        let trace = draw_trace(&d).expect("twin");
        let acc = compare(
            &trace,
            &run_monitor(&trace, Family::PhysicalDefault.config()).expect("monitor"),
        );
        assert!(acc.flags.is_empty(), "run {run}: {:?}", acc.flag_times());
    }
}
