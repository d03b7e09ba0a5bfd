//! Synthetic scenarios for the monitor: a small f64 plant (output shaft under a constant load,
//! ideal speed-servo drive, quasi-static pack with Table 1 stick/slip) produces quantised
//! encoder counts and ADC codes; the monitor's estimates are checked against the plant's truth.
//!
//! The plant follows the twin's physical reading (docs/monitor-design.md, "physical reading"),
//! quasi-statically: while driving the pack slips at μ_d — at the drive drag
//! `μ_d·c·F_s/(1 + μ_d·c·k)` when the drive carries the load, at `μ_d·c·(F_s + 2k·M)/(1 + μ_d·c·k)`
//! when the load runs along the motion — and with the drive off both faces of the V sockets
//! clamp the pack, capacity `μ_s·c·(F_s + k·|M|)` whichever way the output turns. What the
//! plant leaves out (the contact impacts, the rattle in the lost motion, the lost motion
//! itself) is exercised on twin traces in `monitor_twin_faults.rs` and
//! `monitor_paper_scenes.rs`.
//!
//! The plant (`monitor_scenario/plant.rs`) is written independently of the monitor's code, from
//! the same `noback::mechanism` and `noback::sensors` numbers (one source of truth for
//! parameters); the property tests over the operating envelope are in
//! `monitor_scenario/envelope.rs`.

use noback::mechanism::TABLE2;
use noback::monitor::{BrakeState, Config, Estimate, Flags, Monitor, Scene};

#[path = "monitor_scenario/envelope.rs"]
mod envelope;
#[path = "monitor_scenario/plant.rs"]
mod plant;

use plant::*;

fn check_paper_case(load: f64, speed: f64, name: &str) {
    let mut plant = Plant::new(load, speed);
    let mut monitor = Monitor::new(Config::physical_reading()).unwrap();
    let trace = run(&mut plant, &mut monitor, speed, 0.2, 0.7);
    let last = trace.last().unwrap().2;
    dump(&trace, name);
    let spring = TABLE2.spring_preload_n();
    let want_force = TABLE2.quasi_static_pressing_force_n(load);
    let hold = last.braking_torque_nm.to_num::<f64>();
    let force = last.pressing_force_n.to_num::<f64>();
    let lock_true = true_lock_time(&trace, 0.2).unwrap();
    let lock_seen = first_time(&trace, |x| x.0 > 0.2 && x.2.brake == BrakeState::Locked).unwrap();
    let load_at_cut = trace
        .iter()
        .find(|x| x.0 >= 0.2)
        .unwrap()
        .2
        .load_torque_nm
        .to_num::<f64>();
    println!(
        "{name}: holding {hold:.3} N·m (load {load}), force {force:.1} N (want {want_force:.1} = {spring:.1} + {:.1}), \
         load at cut {load_at_cut:.3}, lock true {lock_true:.4} s seen {lock_seen:.4} s, margin {:.3}, energy {:.3} J, health {:.4}",
        want_force - spring,
        last.capacity_margin.to_num::<f64>(),
        last.friction_energy_j.to_num::<f64>(),
        last.pack_health.to_num::<f64>(),
    );
    // Heat: the monitor integrates |T·ω| of its own Table 1 torque and observed speed; the plant
    // integrates the true pack torque over the true travel. Compared from the end of the
    // observer's settling (power-on while moving: the monitor keeps the cheap drive-carries
    // reading, untrusted, until then).
    let settle = (Config::physical_reading().thresholds.settle_time_s * TICK_HZ).round() as usize;
    let energy =
        last.friction_energy_j.to_num::<f64>() - trace[settle].2.friction_energy_j.to_num::<f64>();
    let plant_energy = plant.energy - plant.energy_log[settle];
    println!("{name}: friction energy after settling {energy:.3} J, plant {plant_energy:.3} J");
    assert!(
        (energy - plant_energy).abs() <= 0.05 * plant_energy,
        "energy {energy} vs {plant_energy}"
    );
    assert!(
        (hold - load).abs() <= 0.05 * load.abs(),
        "holding torque {hold} vs {load}"
    );
    assert!(
        (force - want_force).abs() <= 0.10 * want_force,
        "force {force} vs {want_force}"
    );
    assert_eq!(last.brake, BrakeState::Locked);
    assert_eq!(last.scene, Scene::Holding);
    // Powered on while driving along the load, the current alone cannot tell it from a light
    // load against the motion: the overrunning reading is a guess, its estimate untrusted.
    assert_eq!(last.trusted, load * speed < 0.0);
    assert!(!last.flags.any(), "false alarm: {:?}", last.flags);
    // Lock seen within 10 ms of the plant's (issue 4's target). The physical reading's dwell
    // is 1 ms, so the monitor may call the lock in the last ~1 ms of the plant's creep into
    // the stick band, just before the plant stops.
    assert!(
        (lock_seen - lock_true).abs() <= 0.01,
        "{lock_seen} vs {lock_true}"
    );
    // While driving (settled), physical reading: the drive carrying the load unloads the pack to
    // F_s/(1 + μ_d·c·k); a load running along the motion engages the ramps (overrunning).
    let k = ((0.15 * TICK_HZ).round() as usize).min(trace.len() - 1);
    let driving = trace[k].2;
    let force = driving.pressing_force_n.to_num::<f64>();
    let want = plant.drive_force_log[k];
    if load * speed < 0.0 {
        assert_eq!(driving.scene, Scene::Driving);
        assert_eq!(driving.brake, BrakeState::Released);
    } else {
        assert_eq!(driving.scene, Scene::Overrunning);
        assert_eq!(driving.brake, BrakeState::Slipping);
    }
    assert!((force - want).abs() <= 0.05 * want, "{force} vs {want}");
}

#[test]
fn forward_load_released_at_0_2_s_brakes_to_lock() {
    // Closing along the load: the drive holds the output back at 13.78 rad/s (back-driven).
    check_paper_case(20.3, 13.78, "forward");
}

#[test]
fn reverse_load_released_at_0_2_s_brakes_to_lock() {
    // Opening against the load: the drive lifts at 13.78 rad/s, the output coasts, reverses, locks.
    check_paper_case(20.3, -13.78, "reverse");
}

#[test]
fn negative_load_mirrors() {
    check_paper_case(-12.0, -8.0, "negative forward");
}

// The worn pack (μ × 0.5) of the paper reading is not a failure in the physical reading: with
// the drive off the pack still self-locks (μ_s·c·k·0.5 = 1.25 > 1) and holds the load. A pack
// that really fails to hold is tested on twin traces (`monitor_twin_faults.rs`:
// friction_loss 0.9 → brake_weak within 50 ms of the cut).

#[test]
fn pack_losing_grip_while_holding_raises_brake_slip() {
    let mut plant = Plant::new(20.3, 13.78);
    let mut monitor = Monitor::new(Config::physical_reading()).unwrap();
    let mut trace = run(&mut plant, &mut monitor, 13.78, 0.2, 0.5);
    assert!(!trace.last().unwrap().2.flags.any());
    // The spring breaks and μ drops: capacity 0.3 × nominal < load, and μ_s·c·k·0.3 < 1: the
    // pack no longer self-locks and the output creeps away under the load.
    plant.pack_factor = 0.3;
    let start = plant.theta;
    let limit = Config::physical_reading().thresholds.creep_limit_rad;
    let mut beyond = None;
    for k in 0..3000 {
        plant.tick(None);
        let e = monitor.step(&plant.inputs(false));
        let t = 0.5 + f64::from(k + 1) * H;
        if beyond.is_none() && (plant.theta - start).abs() > limit {
            beyond = Some(t);
        }
        trace.push((t, plant.omega, e));
    }
    let slip = first_time(&trace, |x| x.2.flags.brake_slip).unwrap();
    let moved = first_time(&trace, |x| x.0 > 0.5 && x.1 != 0.0).unwrap();
    let beyond = beyond.unwrap();
    println!(
        "slip: output moving at {moved:.4} s, beyond the creep limit at {beyond:.4} s, brake_slip at {slip:.4} s"
    );
    // The creep limit (0.15 rad) must exceed the rattle in the lost motion after an impact
    // stop (≈ 0.1 rad in the twin), so a slow creep (here 17 rad/s²) is flagged when it has
    // crossed the limit — within a tick and one encoder count of it — not within a fixed time.
    assert!(slip > moved, "{slip} vs {moved}");
    assert!(slip <= beyond + 0.001, "{slip} vs {beyond}");
    let last = trace.last().unwrap().2;
    assert!(
        !last.flags.sensor_fault && !last.flags.brake_drag,
        "{:?}",
        last.flags
    );
}

#[test]
fn dragging_pack_while_driving_raises_brake_drag() {
    // Drive, stop and hold (load learned), then drive again with a pack dragging 12 N·m more than nominal.
    let mut plant = Plant::new(-10.0, 5.0);
    let mut monitor = Monitor::new(Config::physical_reading()).unwrap();
    let mut trace = run(&mut plant, &mut monitor, 5.0, 0.3, 0.6);
    assert!(
        !trace.last().unwrap().2.flags.any(),
        "{:?}",
        trace.last().unwrap().2.flags
    );
    plant.extra_drag_nm = 12.0;
    let restart = trace.last().unwrap().0;
    for k in 0..4000 {
        plant.tick(Some(5.0));
        let e = monitor.step(&plant.inputs(true));
        trace.push((restart + f64::from(k + 1) * H, plant.omega, e));
    }
    let drag = first_time(&trace, |x| x.2.flags.brake_drag).unwrap();
    let last = trace.last().unwrap().2;
    println!("drag: restart {restart:.4} s, brake_drag at {drag:.4} s");
    assert!(drag > restart && drag - restart <= 0.2, "{drag}");
    assert!(
        !last.flags.brake_slip && !last.flags.sensor_fault,
        "{:?}",
        last.flags
    );
}

/// Drives at `speed` under a negative `load` (positive speed: against it, the drive carries the
/// load; negative: along it, overrunning) for 0.4 s, then changes the plant with `change` and
/// drives 0.3 s more; returns the trace and the time of the change.
fn drive_with_a_change(
    load: f64,
    speed: f64,
    change: impl Fn(&mut Plant, f64),
) -> (Vec<(f64, f64, Estimate)>, f64) {
    drive_with_a_change_at(load, speed, 0.4, change)
}

/// [`drive_with_a_change`] with the change at `at` (s after power-on), 0.7 s in all.
fn drive_with_a_change_at(
    load: f64,
    speed: f64,
    at: f64,
    change: impl Fn(&mut Plant, f64),
) -> (Vec<(f64, f64, Estimate)>, f64) {
    let mut plant = Plant::new(load, speed);
    let mut monitor = Monitor::new(Config::physical_reading()).unwrap();
    let mut trace = Vec::new();
    for k in 0..7000 {
        let t = f64::from(k) * H;
        change(&mut plant, t - at);
        plant.tick(Some(speed));
        let e = monitor.step(&plant.inputs(true));
        trace.push((t + H, plant.omega, e));
    }
    (trace, at)
}

#[test]
fn current_reading_losing_gain_mid_drive_raises_sensor_fault() {
    // Half the current lost (severity 0.5, the smallest the Monte Carlo draws) while the drive
    // carries a 20 N·m load: the drive torque seems to fall by 11 N·m at once. (Overrunning,
    // the drive torque is 2–4 N·m and half of it is near the 1.25 N·m step allowance:
    // docs/monitor.md counts those misses.)
    current_gain_lost_mid_drive_raises_sensor_fault(0.5, 0.4);
}

#[test]
fn current_reading_losing_most_of_its_gain_is_flagged_before_the_reading_can_change() {
    // 80 % of the current lost while the drive carries 20 N·m, 0.14 s after power-on (the
    // observer has settled, the load is not learned yet): the drive torque seems to fall from
    // ≈ 22 to ≈ 4.4 N·m, where the overrunning reading (a load along the motion) looks
    // possible too. The step check keeps running while that change of reading is pending
    // (20 ms): were it to wait, the switch would re-seed its history past the step.
    current_gain_lost_mid_drive_raises_sensor_fault(0.2, 0.14);
}

/// The current reading keeps `gain` of its value from `at` on while the drive carries 20 N·m:
/// `sensor_fault` within 50 ms, never `brake_drag`.
fn current_gain_lost_mid_drive_raises_sensor_fault(gain: f64, at: f64) {
    let (trace, at) = drive_with_a_change_at(-20.0, 5.0, at, |p, since| {
        p.current_gain = if since >= 0.0 { gain } else { 1.0 };
    });
    flagged_within_50_ms(
        &trace,
        at,
        Scene::Driving,
        |f| f.sensor_fault,
        |f| f.brake_drag,
    );
}

#[test]
fn pack_starting_to_drag_mid_drive_raises_brake_drag() {
    // 5 N·m more drag, below the 8 N·m allowance against the drive's start: only the step sees it.
    for (load, speed, scene) in [
        (-20.0, 5.0, Scene::Driving),
        (-10.0, -5.0, Scene::Overrunning),
    ] {
        let (trace, at) = drive_with_a_change(load, speed, |p, since| {
            p.extra_drag_nm = if since >= 0.0 { 5.0 } else { 0.0 };
        });
        flagged_within_50_ms(&trace, at, scene, |f| f.brake_drag, |f| f.sensor_fault);
    }
}

/// Before `at` the monitor is in `scene` with no flag; `wanted` rises within 50 ms after it and
/// `other` never does.
fn flagged_within_50_ms(
    trace: &[(f64, f64, Estimate)],
    at: f64,
    scene: Scene,
    wanted: impl Fn(&Flags) -> bool,
    other: impl Fn(&Flags) -> bool,
) {
    let before = trace.iter().rfind(|x| x.0 < at).unwrap().2;
    assert!(!before.flags.any(), "{:?}", before.flags);
    assert_eq!(before.scene, scene);
    let seen = first_time(trace, |x| wanted(&x.2.flags)).expect("the flag rises");
    println!("{scene:?}: change at {at} s, flagged at {seen:.4} s");
    assert!(seen > at && seen - at <= 0.05, "{seen}");
    assert!(!other(&trace.last().unwrap().2.flags));
}

#[test]
fn load_changing_at_a_door_like_rate_mid_drive_raises_nothing() {
    // The load grows and shrinks by 6 N·m at 20 N·m/s (a door's aerodynamic load over its
    // stroke changes by tens of N·m per second at most): slower than the step history follows.
    // (A 10 N·m load against the drive seen first at power-on is read as overrunning — the
    // ambiguity of docs/monitor-design.md — and a later change of its reading compares loads
    // learned under two readings: that case raises brake_drag and is left out here.)
    for (load, speed) in [(-20.0, 5.0), (-10.0, -5.0)] {
        for sign in [1.0, -1.0] {
            let (trace, _) = drive_with_a_change(load, speed, |p, since| {
                p.load_nm = load - sign * (20.0 * since).clamp(0.0, 6.0);
            });
            let last = trace.last().unwrap().2;
            assert!(
                !last.flags.any(),
                "speed {speed}, load ramp {sign}: {:?}",
                last.flags
            );
        }
    }
}

#[test]
fn nominal_restart_raises_nothing() {
    let mut plant = Plant::new(-10.0, 5.0);
    let mut monitor = Monitor::new(Config::physical_reading()).unwrap();
    let mut trace = run(&mut plant, &mut monitor, 5.0, 0.3, 0.6);
    let restart = trace.last().unwrap().0;
    for k in 0..6000 {
        let drive = k < 4000;
        plant.tick(drive.then_some(-5.0));
        let e = monitor.step(&plant.inputs(drive));
        trace.push((restart + f64::from(k + 1) * H, plant.omega, e));
    }
    dump(&trace, "restart");
    let last = trace.last().unwrap().2;
    assert!(!last.flags.any(), "{:?}", last.flags);
    assert_eq!(last.brake, BrakeState::Locked);
    let hold = last.braking_torque_nm.to_num::<f64>();
    assert!((hold + 10.0).abs() <= 0.5, "{hold}");
}

/// Powered on at rest with the drive starting at once (the ideal servo accelerating at
/// 50 rad/s² to its speed): the power-on seeding finds the output still, so the observer starts
/// at rest with its torque balanced, and the drive checks, armed after the short power-on
/// settling, must not read the start as a drag or a lost current gain — at either load
/// direction and at the drive envelope's speeds.
#[test]
fn power_on_with_the_drive_starting_from_rest_raises_nothing() {
    for load in [-25.0, -10.0, 10.0, 25.0] {
        for speed in [5.0, 20.0] {
            let mut plant = Plant::new(load, 0.0);
            let mut monitor = Monitor::new(Config::physical_reading()).unwrap();
            let trace = run(&mut plant, &mut monitor, speed, 0.6, 1.2);
            let flagged = trace.iter().find(|x| x.2.flags.any());
            assert!(
                flagged.is_none(),
                "load {load}, {speed} rad/s: {:?} at {:?} s",
                flagged.map(|x| x.2.flags),
                flagged.map(|x| x.0)
            );
            assert_eq!(trace.last().map(|x| x.2.brake), Some(BrakeState::Locked));
        }
    }
}
