//! The drive checks' unit tests.

#![cfg(test)]

use super::*;
use crate::monitor::Config;

fn settings() -> crate::monitor::settings::Settings {
    crate::monitor::settings::Settings::new(&Config::default()).expect("default configuration")
}

fn params() -> DriveSettings {
    settings().checks.drive
}

/// A steady drive carrying the load (the drive pushing `drive` N·m along the motion against
/// a load the observer sees as the net torque `−drive + drag`), one run per call.
fn carrying(drive: f64, pending: bool) -> DriveTick {
    let p = settings().pack;
    let drive = Q16::from_num(drive);
    DriveTick {
        dir: Dir::of(Q16::ONE, Q16::ZERO),
        net: drive.saturating_neg().saturating_add(p.drive_drag),
        drive,
        pack: p.drive_drag,
        engaged: false,
        carrying: true,
        load_ref: None,
        pending,
        guessed: false,
        ticks: 1,
        settle_ticks: settings().scene.engage_settle_ticks,
        command_shortfall: None,
    }
}

/// Overrunning at a steady speed (`J·ω̇ = 0`, net `−u`): the pack at the equilibrium
/// `y(u)`, the implied load along the motion `y(u) − u`.
fn overrunning(drive: f64, pending: bool) -> DriveTick {
    let p = settings().pack;
    let drive_q = Q16::from_num(drive);
    DriveTick {
        net: drive_q.saturating_neg(),
        pack: p.overrun_torque(drive_q),
        engaged: true,
        carrying: false,
        ..carrying(drive, pending)
    }
}

/// Runs the checks `runs` times (one tick in four each) and returns the flags.
fn run(c: &mut DriveChecks, t: &DriveTick, runs: u32) -> Flags {
    let p = params();
    let mut flags = Flags::default();
    for _ in 0..runs {
        flags = flags.union(c.run(&p, t));
    }
    flags
}

#[test]
fn a_drive_that_works_harder_is_a_drag_and_one_that_works_less_a_sensor_fault() {
    let mut c = DriveChecks::default();
    assert_eq!(run(&mut c, &carrying(20.0, false), 100), Flags::default());
    // 10 ms persistence at 10 kHz, one run in four: 25 runs.
    assert!(run(&mut c, &carrying(25.0, false), 26).brake_drag);
    let mut c = DriveChecks::default();
    run(&mut c, &carrying(20.0, false), 100);
    let f = run(&mut c, &carrying(15.0, false), 26);
    assert!(f.sensor_fault && !f.brake_drag, "{f:?}");
}

#[test]
fn a_history_seeded_on_a_guess_judges_no_lighter_step_before_its_time_constant() {
    // 5 Hz: 31.8 ms, 318 ticks, 80 runs. Seeded on a guess, a lost gain 20 runs in is
    // held until then and called 25 runs after; seeded on a decided reading, at once.
    let guessed = |drive| DriveTick {
        guessed: true,
        ..carrying(drive, false)
    };
    let mut c = DriveChecks::default();
    run(&mut c, &guessed(20.0), 20);
    assert!(!run(&mut c, &guessed(15.0), 60).sensor_fault);
    assert!(run(&mut c, &guessed(15.0), 26).sensor_fault);
    let mut c = DriveChecks::default();
    run(&mut c, &carrying(20.0, false), 20);
    assert!(run(&mut c, &carrying(15.0, false), 26).sensor_fault);
}

#[test]
fn with_the_command_a_lighter_step_is_a_lost_gain_only_if_the_reading_falls_short_of_it() {
    // 20 → 15 N·m read: the command falling with the reading (a drive that works less, its
    // shortfall 0.1 N·m as before) is no fault; the command held (shortfall 5 N·m) is.
    let read = |drive, short: f64| DriveTick {
        command_shortfall: Some(Q16::from_num(short)),
        ..carrying(drive, false)
    };
    let mut c = DriveChecks::default();
    run(&mut c, &read(20.0, 0.1), 100);
    assert_eq!(run(&mut c, &read(15.0, 0.1), 100), Flags::default());
    let mut c = DriveChecks::default();
    run(&mut c, &read(20.0, 0.1), 100);
    assert!(run(&mut c, &read(15.0, 5.1), 26).sensor_fault);
}

#[test]
fn the_drag_check_waits_the_observers_settling_after_a_pending_change() {
    // The pack torque 12 N·m beyond the load at the drive's start (limit: drag + 8 N·m),
    // a 6 N·m load against the motion.
    let mut dragging = carrying(20.0, false);
    dragging.load_ref = Some(dragging.net.saturating_add(Q16::from_num(12.0)));
    let pending = DriveTick {
        pending: true,
        ..dragging
    };
    let mut c = DriveChecks::default();
    assert!(run(&mut c, &dragging, 26).brake_drag, "25 runs persist");
    let mut c = DriveChecks::default();
    run(&mut c, &pending, 10);
    // 20 ms of settling (50 runs), then 10 ms of persistence (25 runs).
    assert!(!run(&mut c, &dragging, 73).brake_drag);
    assert!(run(&mut c, &dragging, 1).brake_drag);
}

#[test]
fn a_pack_that_engages_on_a_reference_aiding_beyond_the_drag_is_no_drag() {
    // Tuning seed 1729, run 5137: the chatter turned the reading to driving with the
    // reference 6.6 N·m along the motion; the pack's next pulse took 18 N·m, the drive
    // pushing 2.5 N·m.
    let mut engaging = carrying(2.5, false);
    engaging.net = Q16::from_num(-11.4);
    engaging.load_ref = Some(Q16::from_num(6.6));
    assert_eq!(
        run(&mut DriveChecks::default(), &engaging, 100),
        Flags::default()
    );
    // The same pack torque on a reference the drag carries (1.9 N·m along): a drag.
    let dragging = DriveTick {
        net: Q16::from_num(1.9 - 18.0),
        load_ref: Some(Q16::from_num(1.9)),
        ..engaging
    };
    assert!(run(&mut DriveChecks::default(), &dragging, 26).brake_drag);
    // On the aiding reference with the drive pushing past the allowance (8 N·m): a drag.
    let pushing = DriveTick {
        drive: Q16::from_num(8.5),
        ..engaging
    };
    assert!(run(&mut DriveChecks::default(), &pushing, 26).brake_drag);
}

#[test]
fn a_change_of_reading_waits_while_a_step_is_counted_and_not_longer() {
    let p = params();
    let mut c = DriveChecks::default();
    run(&mut c, &carrying(20.0, false), 100);
    assert!(!c.counting_step(&p));
    run(&mut c, &carrying(15.0, true), 5);
    assert!(
        c.counting_step(&p),
        "a lost gain is counted during a pending change"
    );
    run(&mut c, &carrying(15.0, true), 30);
    assert!(
        !c.counting_step(&p),
        "the verdict is in: the change may go ahead"
    );
}

#[test]
fn the_harder_half_waits_out_a_change_towards_overrunning_only() {
    let mut c = DriveChecks::default();
    run(&mut c, &carrying(20.0, false), 100);
    // Pending while the drive carries the load (a change towards overrunning): no count.
    assert!(!run(&mut c, &carrying(25.0, true), 40).brake_drag);
    // Pending while overrunning (a change away from it): counted.
    let mut c = DriveChecks::default();
    run(&mut c, &overrunning(5.0, false), 100);
    assert!(run(&mut c, &overrunning(8.0, true), 26).brake_drag);
}

#[test]
fn after_a_lost_gain_no_drag_is_read_from_the_current_until_the_flags_are_reset() {
    let mut c = DriveChecks::default();
    run(&mut c, &carrying(20.0, false), 100);
    assert!(run(&mut c, &carrying(15.0, false), 26).sensor_fault);
    c.disarm(); // a drive edge, a change of reading: the verdict stays
    run(&mut c, &carrying(15.0, false), 100);
    assert!(!run(&mut c, &carrying(22.0, false), 40).brake_drag);
    c.reset(); // `reset_flags`
    run(&mut c, &carrying(15.0, false), 100);
    assert!(run(&mut c, &carrying(22.0, false), 40).brake_drag);
}

#[test]
fn an_implied_load_step_the_drive_torque_explains_less_than_half_of_is_no_fault() {
    // Overrunning: the implied load falls by 11 N·m (the pack engaging and letting go moves
    // it through `J_s·ω̇`) while the drive torque falls by 0.9 N·m, more than half the
    // allowance but less than half of what a current step would need: no verdict.
    let before = overrunning(2.45, false);
    let mut after = overrunning(1.55, false);
    after.net = before.net.saturating_sub(Q16::from_num(11.0));
    after.pack = before.pack;
    let mut c = DriveChecks::default();
    run(&mut c, &before, 100);
    assert_eq!(run(&mut c, &after, 40), Flags::default());
    // The same fall with the drive torque falling by the share a lost gain gives: counted.
    let share = 11.0 / (2.0 * r_g1_minus_1());
    let mut lost = overrunning(2.45 - 1.1 * share, false);
    lost.net = after.net;
    lost.pack = before.pack;
    let mut c = DriveChecks::default();
    run(&mut c, &before, 100);
    assert!(run(&mut c, &lost, 26).sensor_fault);
}

#[test]
fn the_quiet_spells_of_an_overrunning_chatter_are_no_lighter_step() {
    // Tuning seed 4242, run 79848: the pack's engagement pulses the drive torque from 2 to
    // 12 N·m every ≈ 46 ms. The history sits above the quiet spells, the floor at them.
    // (Square pulses here, shorter than the persistence: the harder half stays out.)
    let mut c = DriveChecks::default();
    run(&mut c, &overrunning(2.0, false), 100);
    for _ in 0..6 {
        assert_eq!(run(&mut c, &overrunning(10.0, false), 20), Flags::default());
        assert_eq!(run(&mut c, &overrunning(2.0, false), 95), Flags::default());
    }
    // The same spell with the reading at half its gain is below the floor.
    assert!(run(&mut c, &overrunning(1.0, false), 26).sensor_fault);
}

/// `g₁ − 1`, the implied load's step per N·m of drive torque while overrunning.
fn r_g1_minus_1() -> f64 {
    let p = params();
    p.step_limit_overrun.to_num::<f64>() / p.step_limit.to_num::<f64>()
}

#[test]
fn a_lost_gain_that_drops_the_overrunning_pack_model_to_its_floor_is_a_sensor_fault() {
    let p = params();
    let (before, after) = (overrunning(3.0, false), overrunning(0.5, false));
    assert!(before.pack > Q16::ZERO && after.pack == Q16::ZERO);
    // The implied load falls by less than the overrunning limit (`g₁ − 1` allowances) but
    // by more than the plain one: only the plain limit at the floor sees the step.
    let fall = (before.net + before.pack) - (after.net + after.pack);
    assert!(fall < p.step_limit_overrun && fall > p.step_limit, "{fall}");
    let mut c = DriveChecks::default();
    run(&mut c, &before, 100);
    let f = run(&mut c, &after, 26);
    assert!(f.sensor_fault && !f.brake_drag, "{f:?}");
}
