//! A change of driving reading is bumpless (docs/monitor-design.md, "Bumpless change of
//! reading"): the Monte Carlo's nominal draw 348 (seed 2026: reverse_load, 10.5 N·m, 9.8 rad/s,
//! mirrored, in the power-on ambiguity's band) changes its driving reading while driving.
//! Without the bumpless transfer the observer rang after the change and the step check raised
//! a false `brake_drag` at 0.158 s; with it the run is clean.

use host_tests::accuracy::{compare, run_monitor};
use host_tests::mc::{draw_among, draw_trace_after, SCENE_KINDS};
use noback::monitor::{Config, Scene};

#[test]
fn a_change_of_reading_while_driving_raises_nothing() {
    // Drawn as the campaign drew it then, among the first four scene kinds, and powered on at
    // the scene's start as then (in the twin's start-up transient).
    let trace =
        draw_trace_after(&draw_among(&SCENE_KINDS[..4], 2026, 348, None), 0.0).expect("twin");
    let estimates = run_monitor(&trace, Config::default()).expect("monitor");
    // The run does change its driving reading (else it would not test the transfer).
    let mut changes = 0;
    for w in estimates.windows(2) {
        let driving = |s: Scene| matches!(s, Scene::Driving | Scene::Overrunning);
        if driving(w[0].scene) && driving(w[1].scene) && w[0].scene != w[1].scene {
            changes += 1;
        }
    }
    assert!(changes >= 1, "no change of reading in this draw");
    let acc = compare(&trace, &estimates);
    assert!(acc.flags.is_empty(), "{:?}", acc.flags);
}
