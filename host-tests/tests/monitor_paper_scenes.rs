//! Issue 4's accuracy targets on the paper's scenes, against the twin's physical reading (the
//! ground truth), through the same comparison `cargo xtask monitor SCENE --json` reports
//! (`host_tests::accuracy::compare`: the twin's force and torque after a 10 ms centred moving
//! average, which is how the contact-impact oscillations the monitor does not model are
//! compared).
//!
//! | target | reverse_load | forward_load | continuous_closing |
//! |---|---|---|---|
//! | holding torque within 5 % of the twin | asserted | asserted | — (never locks) |
//! | pressing-force RMS ≤ 10 % of the twin's peak | asserted | asserted | asserted |
//! | lock time within 10 ms | asserted | asserted | — |
//! | no flags | asserted | asserted | asserted |
//!
//! After the drive cut the output stops on impacts in the lost motion (10–38 kN peaks, still
//! 11–14 kN after the 10 ms average); while the brake holds, the monitor reports the load minus
//! the output's inertia torque `J_s·α` from the encoder's second difference (`Monitor::step`,
//! "impacts"), which is what brings reverse_load under the target (10.9 % → 9.0 %). The `hold`
//! and `drive` scenes are reported by `cargo xtask monitor`, not targeted (the hold scene's load
//! is unobservable from power-on).

use host_tests::accuracy::{compare, run_monitor, twin_trace, Accuracy};
use noback::monitor::Config;

const HOLD_PCT: f64 = 5.0;
const FORCE_RMS_PCT: f64 = 10.0;
const LOCK_S: f64 = 0.010;

fn accuracy(scene: &str) -> Accuracy {
    let trace = twin_trace(scene).expect("twin trace");
    let acc = compare(
        &trace,
        &run_monitor(&trace, Config::default()).expect("monitor"),
    );
    println!(
        "{scene}: force RMS {:.2} % of peak ({:.1} N), torque RMS {:.2} N·m, holding err {:?} %, lock err {:?} s, flags {:?}",
        acc.pressing_force_rmse_pct,
        acc.pressing_force_rmse_n,
        acc.braking_torque_rmse_nm,
        acc.holding_torque_err_pct(),
        acc.lock_time_err_s(),
        acc.flag_times()
    );
    acc
}

fn check_braking_scene(acc: &Accuracy) {
    let hold = acc.holding_torque_err_pct().expect("both lock");
    assert!(hold.abs() <= HOLD_PCT, "holding torque error {hold} %");
    let lock = acc.lock_time_err_s().expect("both lock");
    assert!(lock.abs() <= LOCK_S, "lock time error {lock} s");
    assert!(acc.flags.is_empty(), "flags {:?}", acc.flags);
}

#[test]
fn reverse_load_meets_every_target() {
    let acc = accuracy("reverse_load");
    check_braking_scene(&acc);
    assert!(
        acc.pressing_force_rmse_pct <= FORCE_RMS_PCT,
        "pressing-force RMS {} %",
        acc.pressing_force_rmse_pct
    );
}

#[test]
fn forward_load_meets_every_target() {
    let acc = accuracy("forward_load");
    check_braking_scene(&acc);
    assert!(
        acc.pressing_force_rmse_pct <= FORCE_RMS_PCT,
        "force RMS {} %",
        acc.pressing_force_rmse_pct
    );
}

#[test]
fn continuous_closing_meets_every_target() {
    let acc = accuracy("continuous_closing");
    assert!(
        acc.pressing_force_rmse_pct <= FORCE_RMS_PCT,
        "force RMS {} %",
        acc.pressing_force_rmse_pct
    );
    // Driving throughout (no hold, no lock time to compare).
    assert!(acc.flags.is_empty(), "flags {:?}", acc.flags);
}
