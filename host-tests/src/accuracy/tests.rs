//! The accuracy comparison's unit tests.

use super::*;
use noback_twin::trace::TraceRow;
use std::f64::consts::TAU;

/// A 10 kHz truth trace of `samples` rows, drive off, with the output angle and brake
/// state at each time given by `at`.
fn trace(samples: usize, at: impl Fn(f64) -> (f64, u8)) -> Trace {
    Trace {
        sample_rate_hz: 10_000.0,
        rows: (0..samples)
            .map(|i| {
                let t_s = i as f64 * 1e-4;
                let (output_angle_rad, brake_state) = at(t_s);
                TraceRow {
                    t_s,
                    output_angle_rad,
                    brake_state,
                    ..TraceRow::default()
                }
            })
            .collect(),
    }
}

fn fault(kind: FaultKind) -> Fault {
    Fault {
        kind,
        at_s: 0.01,
        severity: 1.0,
    }
}

#[test]
fn a_frozen_output_reading_of_a_shaft_rattling_in_its_lost_motion_never_manifests() {
    // ±0.1 rad at 50 Hz for 0.5 s: a held output's rattle, whatever the encoder says.
    let t = trace(5000, |t| (0.1 * (50.0 * TAU * t).sin(), 2));
    assert_eq!(manifest_time(&fault(FaultKind::EncoderStuck), &t), None);
}

#[test]
fn a_frozen_output_reading_manifests_when_the_shaft_leaves_the_held_rattle() {
    // The output runs away at 5 rad/s: 0.13 rad beyond its angle at the onset (0.01 s)
    // 26 ms later.
    let t = trace(2000, |t| (5.0 * t, 0));
    let at = manifest_time(&fault(FaultKind::EncoderStuck), &t).expect("manifests");
    assert!((at - 0.0361).abs() < 2e-4, "{at}");
}

#[test]
fn a_failing_hold_manifests_when_the_output_leaves_the_held_rattle() {
    // The pack opens at 0.05 s and the output accelerates from rest at 40 rad/s²: it passes
    // 0.13 rad after 80.6 ms, long after the 20 ms a failing hold must last.
    let t = trace(3000, |t| {
        if t < 0.05 {
            (0.0, 2)
        } else {
            (20.0 * (t - 0.05) * (t - 0.05), 0)
        }
    });
    let at = manifest_time(&fault(FaultKind::PackWear), &t).expect("manifests");
    assert!((at - 0.1306).abs() < 2e-4, "{at}");
}

#[test]
fn a_pack_that_opens_without_letting_the_output_go_never_manifests() {
    // Open for 30 ms, the output inside the rattle, then locked again.
    let t = trace(3000, |t| {
        let open = (0.05..0.08).contains(&t);
        (if open { 0.05 } else { 0.0 }, if open { 0 } else { 2 })
    });
    assert_eq!(manifest_time(&fault(FaultKind::SpringBroken), &t), None);
}

/// An output that slips back 0.3 rad from 0.05 s at 10 rad/s (slipping), then locks.
fn turn_back(extra_rad: f64) -> Trace {
    let travel = 0.3 + extra_rad;
    trace(3000, move |t| {
        let moved = (10.0 * (t - 0.05)).clamp(0.0, travel);
        (moved, if t > 0.05 && moved < travel { 1 } else { 2 })
    })
}

#[test]
fn a_holding_fault_that_turns_the_output_back_only_as_far_as_a_healthy_pack_is_dormant() {
    // On the trace alone the 0.3 rad slip is a failing hold; beside the healthy run (the
    // same slip, 0.05 rad shorter) it never leaves the held rattle.
    let f = fault(FaultKind::PackWear);
    assert!(manifest_time(&f, &turn_back(0.05)).is_some());
    assert_eq!(
        manifest_time_beside(&f, &turn_back(0.05), &turn_back(0.0)),
        None
    );
}

#[test]
fn a_holding_fault_manifests_where_its_output_leaves_the_healthy_one() {
    // 0.2 rad further than the healthy slip: 0.13 rad beyond it 13 ms after the healthy
    // one locked at 0.08 s.
    let f = fault(FaultKind::PackWear);
    let at = manifest_time_beside(&f, &turn_back(0.2), &turn_back(0.0)).expect("manifests");
    assert!((at - 0.0931).abs() < 2e-4, "{at}");
}
