//! Brake-failure detection on the twin's traces (physical reading), with faults severe enough
//! that the brake really fails: it no longer holds the load, or it really drags. These replace
//! the synthetic-plant tests that encoded the paper reading (a worn pack at μ × 0.5 braking
//! slower, a pack dragging at spring pressure): in the physical reading a pack at half its
//! friction still self-locks and holds, so the failure must be a real one.
//!
//! - `friction_loss` 0.9: μ_s·c·k = 2.49 × 0.1 < 1, the pack cannot self-lock; after the cut
//!   the output runs away under the load.
//! - `drag` 1.0: 1000 N extra pressing force, ≈ 12 N·m more pack torque while driving (the
//!   input ramps unload it by 1/(1 + μ_d·c·k)).
//!
//! Latencies are measured from the fault's manifesting (`host_tests::accuracy::manifest_time`:
//! the next drive cut for holding faults, the running drive for drag), against issue 4's
//! 50 ms.

use host_tests::accuracy::{
    compare, detection_latency_s, manifest_time, monitor_on_scene, run_monitor, run_monitor_with,
    scene_trace, Accuracy,
};
use noback::monitor::Config;
use noback_twin::fault::{Fault, FaultKind};
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::trace::{Trace, TraceRow};

const TARGET_S: f64 = 0.050;

fn run(kind: SceneKind, fault: Option<Fault>) -> (Trace, Accuracy) {
    run_with(kind, fault, Config::default())
}

fn run_with(kind: SceneKind, fault: Option<Fault>, config: Config) -> (Trace, Accuracy) {
    let mut scene = Scene::builtin(kind, Reading::Physical);
    scene.faults.extend(fault);
    let trace = scene_trace(&scene).expect("twin");
    let acc = compare(&trace, &run_monitor(&trace, config).expect("monitor"));
    (trace, acc)
}

/// Runs `scene` with `fault` and returns the fault's detection latency (printed with `label`
/// and the flags) and the flags' names.
fn detect(mut scene: Scene, fault: Fault, label: &str) -> (Option<f64>, Vec<&'static str>) {
    scene.faults.push(fault);
    let (trace, acc) = monitor_on_scene(&scene).expect("twin and monitor");
    let latency = detection_latency_s(&fault, &trace, &acc);
    println!("{label}: latency {latency:?}, flags {:?}", acc.flag_times());
    (latency, acc.flags.iter().map(|f| f.flag).collect())
}

/// The trace's first sample at or after `t` (s).
fn row_at(trace: &Trace, t: f64) -> Option<&TraceRow> {
    trace.rows.iter().find(|r| r.t_s >= t)
}

fn flag_time(acc: &Accuracy, flag: &str) -> Option<f64> {
    acc.flags.iter().find(|f| f.flag == flag).map(|f| f.t_s)
}

/// First time the twin's output is faster than the monitor's plausibility limit (the output
/// running away: a sensor fault from then on is the encoder step check doing its job).
fn runaway_time(trace: &Trace) -> f64 {
    let limit = Config::default().thresholds.max_output_speed_rad_s;
    trace
        .rows
        .iter()
        .find(|r| r.output_speed_rad_s.abs() > limit)
        .map_or(f64::INFINITY, |r| r.t_s)
}

/// A pack that cannot hold: `brake_weak` within `within` seconds of the drive's cut.
fn check_pack_that_cannot_hold(kind: SceneKind, config: Config, within: f64) {
    let fault = Fault {
        kind: FaultKind::FrictionLoss,
        at_s: 0.1,
        severity: 0.9,
    };
    let (trace, acc) = run_with(kind, Some(fault), config);
    let cut = trace
        .rows
        .iter()
        .find(|r| !r.drive_on)
        .map(|r| r.t_s)
        .expect("the scene cuts the drive");
    let weak = flag_time(&acc, "brake_weak");
    let latency = detection_latency_s(&fault, &trace, &acc);
    println!(
        "{kind:?} friction_loss 0.9: cut {cut:.4} s, brake_weak {weak:?}, latency {latency:?}, flags {:?}",
        acc.flag_times()
    );
    // The output really runs away (the fault is real) …
    assert!(
        trace
            .rows
            .last()
            .is_some_and(|r| r.output_speed_rad_s.abs() > 20.0),
        "the pack still holds: not a failing brake"
    );
    // … and the braking envelope calls it within `within` of the cut.
    let weak = weak.expect("brake_weak");
    assert!(
        weak > cut && weak - cut <= within,
        "brake_weak {weak} vs cut {cut}"
    );
    assert!(latency.is_some_and(|l| l <= within), "{latency:?}");
    // Nothing else before the output leaves the plausible speed range but the warning of a
    // closing with the drive on that already let the load through (`cycle_health.rs`).
    let runaway = runaway_time(&trace);
    for f in &acc.flags {
        assert!(
            ["brake_weak", "brake_slip", "brake_degraded"].contains(&f.flag) || f.t_s >= runaway,
            "{} at {} (runaway at {runaway})",
            f.flag,
            f.t_s
        );
    }
}

#[test]
fn reverse_load_with_a_pack_that_cannot_hold_raises_brake_weak_within_50_ms_of_the_cut() {
    check_pack_that_cannot_hold(SceneKind::ReverseLoad, Config::physical_reading(), TARGET_S);
}

/// Uncommissioned, the envelope does not count on the pack against the opposing load (the
/// paper reading's ramps clamp only once the output turns back): the same failure is called
/// once the load has turned the output back: 0.177 s after the cut (`brake_slip` at 0.128 s),
/// not the commissioned 50 ms.
#[test]
fn reverse_load_with_a_pack_that_cannot_hold_raises_brake_weak_uncommissioned() {
    check_pack_that_cannot_hold(SceneKind::ReverseLoad, Config::default(), 0.2);
}

#[test]
fn forward_load_with_a_pack_that_cannot_hold_raises_brake_weak_within_50_ms_of_the_cut() {
    check_pack_that_cannot_hold(SceneKind::ForwardLoad, Config::default(), TARGET_S);
}

#[test]
fn pack_losing_grip_while_holding_raises_brake_slip() {
    // Held (drive off from power-on), locked by 0.1 s; at 0.3 s the pack loses 90 % of its
    // friction and the output starts to move under the load.
    let fault = Fault {
        kind: FaultKind::FrictionLoss,
        at_s: 0.3,
        severity: 0.9,
    };
    let (healthy_trace, healthy) = run(SceneKind::Hold, None);
    assert!(
        healthy.flags.is_empty(),
        "healthy hold: {:?}",
        healthy.flags
    );
    let held = healthy_trace
        .rows
        .last()
        .map_or(0.0, |r| r.output_speed_rad_s);
    assert!(held.abs() < 0.05, "healthy hold moves at {held} rad/s");
    let (trace, acc) = run(SceneKind::Hold, Some(fault));
    let stop = 0.05; // the twin's stop threshold (rad/s)
    let moved = trace
        .rows
        .iter()
        .find(|r| r.t_s >= fault.at_s && r.output_speed_rad_s.abs() > stop)
        .map(|r| r.t_s)
        .expect("the output moves");
    let slip = flag_time(&acc, "brake_slip").expect("brake_slip");
    println!(
        "hold, friction_loss 0.9 at 0.3 s: moving at {moved:.4} s, brake_slip at {slip:.4} s, flags {:?}",
        acc.flag_times()
    );
    assert!(
        slip > moved && slip - moved <= TARGET_S,
        "{slip} vs {moved}"
    );
    // No flag before the fault.
    assert!(
        acc.flags.iter().all(|f| f.t_s >= fault.at_s),
        "{:?}",
        acc.flags
    );
}

#[test]
fn dragging_pack_while_driving_raises_brake_drag() {
    // The drive scene (drive carrying 20.3 N·m): the load is learned by 0.15 s and becomes the
    // drag reference; at 0.3 s the pack starts to drag (1000 N extra pressing force).
    let fault = Fault {
        kind: FaultKind::Drag,
        at_s: 0.3,
        severity: 1.0,
    };
    let (_, healthy) = run(SceneKind::Drive, None);
    assert!(
        healthy.flags.is_empty(),
        "healthy drive: {:?}",
        healthy.flags
    );
    let (trace, acc) = run(SceneKind::Drive, Some(fault));
    let drag = flag_time(&acc, "brake_drag").expect("brake_drag");
    let latency = detection_latency_s(&fault, &trace, &acc);
    println!(
        "drive, drag 1.0 at 0.3 s: brake_drag at {drag:.4} s, latency {latency:?}, flags {:?}",
        acc.flag_times()
    );
    assert!(latency.is_some_and(|l| l <= TARGET_S), "{latency:?}");
    assert!(
        acc.flags.iter().all(|f| f.flag == "brake_drag"),
        "{:?}",
        acc.flags
    );
}

#[test]
fn a_slow_slip_while_holding_is_seen_on_both_encoders_before_the_output_span_could_show_it() {
    // A light held load (8.4 N·m) and a pack at 10 % of its friction: the output creeps away,
    // and the input shaft is carried along with it (the connecting shaft turns). The output's
    // span alone must exceed the rattle (`creep_limit_rad`, 0.15 rad); the common-slip check
    // answers while the output has travelled less than that.
    let fault = Fault {
        kind: FaultKind::FrictionLoss,
        at_s: 0.2,
        severity: 0.9,
    };
    let mut scene = Scene::builtin(SceneKind::Hold, Reading::Physical);
    scene.load_torque_nm = 8.4;
    scene.faults.push(fault);
    let (trace, acc) = monitor_on_scene(&scene).expect("twin and monitor");
    let manifest = manifest_time(&fault, &trace).expect("the pack slips");
    let slip = flag_time(&acc, "brake_slip").expect("brake_slip");
    let angle = |t: f64| row_at(&trace, t).map_or(f64::NAN, |r| r.output_angle_rad);
    let travel = (angle(slip) - angle(fault.at_s)).abs();
    println!(
        "hold 8.4 N·m, friction_loss 0.9: slipping from {manifest:.4} s, brake_slip at {slip:.4} s after {travel:.3} rad, flags {:?}",
        acc.flag_times()
    );
    assert!(slip - manifest <= TARGET_S, "{slip} vs {manifest}");
    let creep_limit = Config::default().thresholds.creep_limit_rad;
    assert!(
        travel < creep_limit,
        "{travel} rad: the span check could have fired"
    );
    assert!(
        acc.flags.iter().all(|f| f.t_s >= fault.at_s),
        "{:?}",
        acc.flags
    );
}

#[test]
fn a_pack_that_lets_the_output_speed_up_after_the_cut_is_flagged_within_30_ms() {
    // Forward load (20.3 N·m along the motion) on a pack at 30 % of its friction from 0.1 s:
    // after the cut the pack's 18 N·m cannot stop the load, and the output speeds up. A working
    // pack decelerates it from the first millisecond, so travel beyond the cut speed's is a
    // brake that does not brake (the braking envelope's undecelerated check).
    let fault = Fault {
        kind: FaultKind::FrictionLoss,
        at_s: 0.1,
        severity: 0.7,
    };
    let (trace, acc) = run(SceneKind::ForwardLoad, Some(fault));
    let cut = trace
        .rows
        .iter()
        .find(|r| !r.drive_on)
        .expect("the scene cuts the drive");
    let weak = flag_time(&acc, "brake_weak").expect("brake_weak");
    let speed_at = |t: f64| row_at(&trace, t).map_or(f64::NAN, |r| r.output_speed_rad_s.abs());
    println!(
        "forward_load, friction_loss 0.7: cut {:.4} s at {:.2} rad/s, brake_weak {weak:.4} s at {:.2} rad/s, flags {:?}",
        cut.t_s,
        cut.output_speed_rad_s.abs(),
        speed_at(weak),
        acc.flag_times()
    );
    assert!(
        speed_at(weak) > cut.output_speed_rad_s.abs(),
        "the output did not speed up: not this test's case"
    );
    assert!(
        weak > cut.t_s && weak - cut.t_s <= 0.030,
        "{weak} vs {}",
        cut.t_s
    );
    // Before the cut only the warning that the drive held the door back (`cycle_health.rs`).
    assert!(
        acc.flags
            .iter()
            .all(|f| f.t_s >= cut.t_s || f.flag == "brake_degraded"),
        "{:?}",
        acc.flags
    );
}

/// A current reading that loses gain while the door closes under its load (overrunning, the
/// pack slipping at the drive's equilibrium) is a `sensor_fault` within 50 ms, and never a
/// `brake_drag`: the lower reading makes the overrunning reading impossible (the pack model
/// drops to zero) and the monitor would switch to "the drive carries the load", where the
/// learned load no longer fits and the drag check answered — the wrong flag — 50 ms later.
/// The change of reading now waits for the step check's verdict, and with the pack model at
/// its floor the implied load moves by the drive torque's step alone (the plain limit).
#[test]
fn current_reading_losing_gain_in_continuous_closing_is_a_sensor_fault_not_a_drag() {
    for severity in [0.5, 0.7, 0.9] {
        let fault = Fault {
            kind: FaultKind::CurrentOpen,
            at_s: 1.0,
            severity,
        };
        let scene = Scene::builtin(SceneKind::ContinuousClosing, Reading::Physical);
        let label = format!("continuous closing, current_open {severity} at 1.0 s");
        let (latency, flags) = detect(scene, fault, &label);
        assert!(
            latency.is_some_and(|l| l <= TARGET_S),
            "{label}: {latency:?}"
        );
        assert!(
            flags.iter().all(|f| *f == "sensor_fault"),
            "{label}: {flags:?}"
        );
    }
}

/// A pack that starts to drag while the monitor reads the drive as overrunning (a light load
/// against the motion draws the current of a heavy one along it: at power-on the monitor cannot
/// tell them apart and takes the overrunning reading) makes the drive push harder, past any
/// overrunning load of the envelope: the reading must change to "the drive carries the load",
/// and the switch re-seeded the step check's history past the step — the drag went
/// unflagged. The change of reading now waits for the step check's verdict (its harder half
/// counts during a pending change away from overrunning; towards it, the light-load chatter
/// of continuous closing would be read as drag).
#[test]
fn pack_starting_to_drag_under_the_overrunning_reading_raises_brake_drag() {
    for (load_nm, speed_rad_s, severity) in [(6.6, 12.8, 0.7), (8.0, 10.0, 0.6), (5.0, 16.0, 0.9)] {
        let mut scene = Scene::builtin(SceneKind::Drive, Reading::Physical);
        scene.load_torque_nm = load_nm;
        scene.initial_speed_rad_s = speed_rad_s;
        let (_, healthy) = monitor_on_scene(&scene).expect("twin and monitor");
        assert!(
            healthy.flags.is_empty(),
            "healthy: {:?}",
            healthy.flag_times()
        );
        let fault = Fault {
            kind: FaultKind::Drag,
            at_s: 0.11,
            severity,
        };
        let label = format!(
            "drive against {load_nm} N·m at {speed_rad_s} rad/s, drag {severity} at 0.11 s"
        );
        let (latency, _) = detect(scene, fault, &label);
        assert!(
            latency.is_some_and(|l| l <= TARGET_S),
            "{label}: {latency:?}"
        );
    }
}

/// A worn pack (1 mm more clearance) that opens while the door is held lets the output go with
/// the pack *open*, not slipping: the twin's brake state stays 0 and the output runs away under
/// the load. That is the brake failing to hold (it counted as never manifesting while only a
/// slipping pack did) and the monitor answers within 50 ms.
#[test]
fn worn_pack_that_opens_while_holding_manifests_and_raises_brake_slip() {
    let fault = Fault {
        kind: FaultKind::PackWear,
        at_s: 0.2,
        severity: 0.8,
    };
    let (trace, acc) = run(SceneKind::Hold, Some(fault));
    let manifest = manifest_time(&fault, &trace).expect("the brake lets go");
    let open = trace
        .rows
        .iter()
        .filter(|r| r.t_s >= manifest && r.t_s < manifest + 0.02)
        .all(|r| r.brake_state == 0);
    assert!(open, "the pack is open, not slipping, when it lets go");
    let latency = detection_latency_s(&fault, &trace, &acc);
    println!(
        "hold, pack_wear 0.8 at 0.2 s: lets go at {manifest:.4} s, latency {latency:?}, flags {:?}",
        acc.flag_times()
    );
    assert!(latency.is_some_and(|l| l <= TARGET_S), "{latency:?}");
    assert!(flag_time(&acc, "brake_slip").is_some());
}

/// A current reading that loses most of its gain 5 ms before the drive is cut leaves the drive
/// checks no time; with the drive's current command the reading is called within the drive
/// (blocks of 1.6 ms). Tuning seed 2026's current_open runs 27 and 69 are this case.
#[test]
fn a_gain_lost_just_before_the_cut_is_called_within_the_drive_with_the_command() {
    let mut scene = Scene::builtin(SceneKind::ReverseLoad, Reading::Physical);
    let cut = scene.release_at_s.expect("reverse_load cuts its drive");
    let fault = Fault {
        kind: FaultKind::CurrentOpen,
        at_s: cut - 0.005,
        severity: 0.8,
    };
    scene.faults.push(fault);
    let trace = scene_trace(&scene).expect("twin");
    let estimates = run_monitor_with(&trace, Config::default(), true).expect("monitor");
    let acc = compare(&trace, &estimates);
    let latency = detection_latency_s(&fault, &trace, &acc);
    println!(
        "reverse_load, current_open 0.8 5 ms before the cut, with the command: latency \
         {latency:?}, flags {:?}",
        acc.flag_times()
    );
    assert!(latency.is_some_and(|l| l <= 0.005), "{latency:?}");
    assert_eq!(
        flag_time(&acc, "brake_drag"),
        None,
        "a sensor fault, not a drag"
    );
}
