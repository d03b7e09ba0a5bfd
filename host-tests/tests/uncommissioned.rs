//! Issue 16, out of the box: the uncommissioned monitor (`Config::default()`) raises nothing on
//! the healthy built-in scenes of both readings over the door's load range, and the settings
//! set for the physical reading differ from it only where the family needs wider ones.
//!
//! Loads span the Monte Carlo's 5–30 N·m (a drive stalled at its current limit: to the scene
//! schema's 500 N·m). Above capacity/1.5 the margin is below the limit by
//! definition (`brake_weak` is the right answer); below 5 N·m the paper reading's drag while
//! driving (3.7–7.8 N·m against the model's 1.98) leaves the reading ambiguous uncommissioned
//! (docs/decisions.md). A plant whose input comes apart from its output (the paper
//! reading's closing at loads up to 8 N·m) is not healthy: the monitor must flag it.

use host_tests::accuracy::{
    compare, detection_latency_s, run_monitor, run_monitor_with, scene_trace, Accuracy,
};
use host_tests::family::Family;
use host_tests::mc::{draw_in, draw_trace, not_driven, Draw};
use noback::monitor::{Config, Thresholds};
use noback_twin::fault::FaultKind;
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::trace::Trace;

const KINDS: [SceneKind; 5] = [
    SceneKind::ReverseLoad,
    SceneKind::ForwardLoad,
    SceneKind::ContinuousClosing,
    SceneKind::Hold,
    SceneKind::Drive,
];

/// Healthy draw `run` of the plant family at `seed`, and its twin trace.
fn family_draw(seed: u64, run: u64) -> (Draw, Trace) {
    let d = draw_in(Family::Plant, seed, run, None);
    let trace = draw_trace(&d).expect("twin");
    (d, trace)
}

/// The same, for a draw with no fault whose input stays with its output (counted, not apart).
fn counted_draw(seed: u64, run: u64) -> (Draw, Trace) {
    let (d, trace) = family_draw(seed, run);
    assert!(d.scene.faults.is_empty() && !not_driven(&trace, &d.scene.sensors));
    (d, trace)
}

/// What the monitor set with `config` makes of a trace.
fn monitor(trace: &Trace, config: Config) -> Accuracy {
    compare(trace, &run_monitor(trace, config).expect("monitor"))
}

/// How far the output came back (rad) from the point farthest from where the drive was cut.
fn turned_back(trace: &Trace) -> f64 {
    let cut = trace
        .rows
        .iter()
        .rposition(|r| r.drive_on)
        .expect("a drive");
    let from = trace.rows[cut].output_angle_rad;
    let farthest = trace.rows[cut..]
        .iter()
        .map(|r| r.output_angle_rad)
        .fold(from, |a, b| {
            if (b - from).abs() > (a - from).abs() {
                b
            } else {
                a
            }
        });
    (farthest - trace.rows.last().expect("rows").output_angle_rad).abs()
}

/// Asserts that the family's uncommissioned monitor raises nothing on `trace`.
fn assert_quiet(trace: &Trace) {
    let acc = monitor(trace, Family::Plant.config());
    assert!(acc.flags.is_empty(), "{:?}", acc.flag_times());
}

/// Asserts that the monitor set with `config` raises `flag` on `trace`.
fn assert_raises(trace: &Trace, config: Config, flag: &str) {
    let acc = monitor(trace, config);
    assert!(
        acc.flags.iter().any(|f| f.flag == flag),
        "{:?}",
        acc.flag_times()
    );
}

#[test]
fn healthy_scenes_of_both_readings_raise_nothing_uncommissioned() {
    let (mut alarms, mut not_moving) = (Vec::new(), 0);
    for reading in [Reading::Paper, Reading::Physical] {
        for kind in KINDS {
            for load in [5.0, 12.0, 20.3, 30.0] {
                let mut scene = Scene::builtin(kind, reading);
                scene.load_torque_nm = load;
                let trace = scene_trace(&scene).expect("twin");
                let acc = monitor(&trace, Config::default());
                if not_driven(&trace, &scene.sensors) {
                    not_moving += 1;
                    assert!(
                        !acc.flags.is_empty(),
                        "{reading:?} {kind:?} {load}: not flagged"
                    );
                } else if !acc.flags.is_empty() {
                    alarms.push((reading, kind, load, acc.flag_times()));
                }
            }
        }
    }
    assert!(alarms.is_empty(), "false alarms: {alarms:?}");
    assert!(
        not_moving <= 1,
        "{not_moving} plants that do not move (paper closing at 5 N·m)"
    );
}

#[test]
fn a_drive_stalled_at_its_current_limit_reads_below_the_rail_and_raises_nothing() {
    // Loads to the scene schema's 500 N·m: the physical drive stalls at its 25 A limit, which
    // reads below the ±30 A sensor's rail; the paper reading's drive has no limit and clips.
    for (reading, kind, load) in [
        (Reading::Physical, SceneKind::Drive, 60.0),
        (Reading::Physical, SceneKind::ReverseLoad, 150.0),
        (Reading::Physical, SceneKind::ForwardLoad, 500.0),
        (Reading::Physical, SceneKind::ContinuousClosing, 500.0),
        (Reading::Paper, SceneKind::Drive, 500.0),
    ] {
        let mut scene = Scene::builtin(kind, reading);
        scene.load_torque_nm = load;
        let trace = scene_trace(&scene).expect("twin");
        let s = &scene.sensors;
        let (mid, max_code) = (
            1_i32 << (s.current_adc_bits - 1),
            (1_u16 << s.current_adc_bits) - 1,
        );
        let at_rail = trace
            .rows
            .iter()
            .any(|r| r.current_code == 0 || r.current_code >= max_code);
        let peak_a = trace
            .rows
            .iter()
            .map(|r| f64::from((i32::from(r.current_code) - mid).abs()) * s.amps_per_count())
            .fold(0.0, f64::max);
        let limit_a = scene.open.drive_current_limit_a;
        match reading {
            Reading::Physical => assert!(
                peak_a > 0.95 * limit_a && !at_rail,
                "{kind:?} {load}: peak {peak_a} A, limit {limit_a} A, at the rail {at_rail}"
            ),
            Reading::Paper => assert!(at_rail, "{kind:?} {load}: peak {peak_a} A"),
        }
        let acc = monitor(&trace, Config::default());
        assert!(
            acc.flags.is_empty(),
            "{reading:?} {kind:?} {load}: {:?}",
            acc.flag_times()
        );
        // A load the stall hides is not reported as a confident holding torque.
        if let Some((twin, est)) = acc.holding_torque_nm {
            let off = (est - twin).abs() > 0.02 * twin.abs();
            assert!(
                !(off && acc.trusted_at_end),
                "{kind:?} {load}: {est} vs {twin}, trusted"
            );
        }
    }
}

#[test]
fn the_physical_readings_settings_tighten_only_the_family_wide_limits() {
    let (u, p) = (Thresholds::DEFAULT, Thresholds::PHYSICAL_READING);
    assert!(u.opposed_braking_share < p.opposed_braking_share);
    assert!(u.dead_current_nm < p.dead_current_nm);
    assert!(u.braking_angle_allowance_rad > p.braking_angle_allowance_rad);
    assert!(u.braking_angle_factor > p.braking_angle_factor);
    assert!(u.driven_torque_nm > p.driven_torque_nm);
    let same = Thresholds {
        opposed_braking_share: p.opposed_braking_share,
        dead_current_nm: p.dead_current_nm,
        braking_angle_allowance_rad: p.braking_angle_allowance_rad,
        braking_angle_factor: p.braking_angle_factor,
        driven_torque_nm: p.driven_torque_nm,
        ..u
    };
    assert_eq!(same, p, "every other threshold is shared");
    assert_eq!(
        Config::physical_reading(),
        Config {
            thresholds: p,
            commissioned: true,
            ..Config::default()
        }
    );
}

/// Tuning seed 1616's run 2875 (paper form, reverse load 27.4 N·m): after the stop the load
/// turns the output back ≈ 0.2 rad through the ramps' lost motion before the pack clamps and
/// slows it; the creep check allowed that span only while the output decelerates.
#[test]
fn a_load_turning_the_output_back_until_the_ramps_clamp_is_no_slip() {
    let (_, trace) = family_draw(1616, 2875);
    let back = turned_back(&trace);
    assert!(
        back > 0.15,
        "turned back {back:.3} rad, more than the creep limit"
    );
    assert_quiet(&trace);
}

/// Tuning seed 1616's run 791 (paper form, forward load 5.7 N·m, sliding at μ_d): after the cut
/// the pack slows the output from 14.5 rad/s at ≈ 25 rad/s², a third of the nominal model's
/// deceleration, through ≈ 4 rad (it needs 2.7× the model's braking angle); the uncommissioned
/// envelope allows 4×, so this healthy plant raises nothing.
#[test]
fn a_pack_braking_at_a_third_of_the_model_is_not_weak_uncommissioned() {
    let (d, trace) = family_draw(1616, 791);
    assert!(d.scene.faults.is_empty());
    let cut = trace.rows.iter().position(|r| !r.drive_on).expect("a cut");
    let from = trace.rows[cut].output_angle_rad;
    let travel = trace.rows[cut..]
        .iter()
        .map(|r| (r.output_angle_rad - from).abs())
        .fold(0.0, f64::max);
    assert!(travel > 3.0, "braked within {travel:.2} rad");
    assert_quiet(&trace);
    // With the physical reading's factor (2×) and nothing else changed, it is called weak.
    let tight = Config {
        thresholds: Thresholds {
            braking_angle_factor: Thresholds::PHYSICAL_READING.braking_angle_factor,
            ..Thresholds::DEFAULT
        },
        ..Config::default()
    };
    assert_raises(&trace, tight, "brake_weak");
}

/// Tuning seed 1616's run 5115 (paper form, forward load 5.1 N·m, sliding at μ_s): the pack
/// holds the door on its spring while the drive's reference runs on, and at the stop the
/// reading re-seats its input on the far face, a 0.76 rad step of the motor encoder. Counted
/// apart, and flagged; run 8289 (physical form, forward load), the most input travel against a
/// still output of any healthy draw of that seed's first 10 000, is a healthy plant.
#[test]
fn an_input_that_comes_apart_from_its_output_is_counted_apart_and_flagged() {
    let (d, trace) = family_draw(1616, 5115);
    assert!(not_driven(&trace, &d.scene.sensors));
    assert_raises(&trace, Family::Plant.config(), "sensor_fault");
    let (d, trace) = family_draw(1616, 8289);
    assert!(!not_driven(&trace, &d.scene.sensors));
}

/// Tuning seed 4242's run 3716 (physical form, continuous closing at 5.4 N·m with a
/// 26.7 N·m·s/rad servo): after each of the chatter's pack pulses the observer's net torque
/// stays 8–10 N·m low for ≈ 25 ms, which the drag check read as `brake_drag` until it learned
/// to wait the observer's settling after a pending change of reading.
#[test]
fn continuous_closings_chatter_at_a_light_load_and_a_soft_servo_is_no_drag() {
    let (_, trace) = family_draw(4242, 3716);
    assert_quiet(&trace);
}

/// Tuning seed 1729's runs 5137 and 62115 (physical form, continuous closing at 7.1 and
/// 8.4 N·m): the chatter's quiet spells sank the load estimate below the smallest load and the
/// reading turned to driving; the pack's next pulse, against the drive's 6.6 and 7.0 N·m
/// reference along the motion, read as a drag (`brake_drag` at 0.19 and 0.86 s).
#[test]
fn a_chatter_read_as_driving_on_an_aiding_reference_is_no_drag() {
    for run in [5137, 62115] {
        let (_, trace) = counted_draw(1729, run);
        assert_quiet(&trace);
    }
}

/// Tuning seed 7's run 9297 (physical form, reverse load): at power-on a seated contact sat at
/// zero penetration within rounding, and its event fired at every step until the twin gave up
/// ("events fire without time advancing"). A contact's event now fires at 1e-15 m.
#[test]
fn a_contact_seated_at_zero_penetration_does_not_stop_the_twin() {
    let (_, trace) = family_draw(7, 9297);
    assert!(!trace.rows.is_empty());
}

/// Tuning seed 4242's run 2301 (paper form, forward load 15.4 N·m aiding, sliding at μ_d): the
/// pack's self-energising at μ_d exceeds the load by little, so the door, cut at 18.8 rad/s,
/// still turns at ≈ 2 rad/s 0.66 s later, 2.8× the model's angle. Its time stretches as its
/// angle does; the envelope allows both the same factor, so this healthy plant raises nothing.
#[test]
fn a_braking_slower_in_time_as_in_angle_is_not_weak_uncommissioned() {
    let (d, trace) = family_draw(4242, 2301);
    assert!(d.scene.faults.is_empty());
    let cut = trace.rows.iter().position(|r| !r.drive_on).expect("a cut");
    let at = |s: f64| &trace.rows[cut + (s * 1e4) as usize];
    let speed = (at(0.67).output_angle_rad - at(0.66).output_angle_rad).abs() / 0.01;
    assert!(
        speed > 1.0,
        "turning at {speed:.2} rad/s 0.66 s after the cut"
    );
    assert_quiet(&trace);
}

/// Tuning seed 4242's run 76699 (physical form, forward load 17.9 N·m): the drive's chatter
/// has the output accelerating at ≈ 120 rad/s² at the cut, 1.4 rad/s ahead of the observer,
/// and it gains ≈ 0.02 rad on the observed cut speed before the pack clamps. Called a brake
/// that does not brake at the 0.01 rad allowance; nothing at today's.
#[test]
fn an_output_accelerating_in_the_chatter_at_the_cut_is_braked_not_undecelerated() {
    let (d, trace) = family_draw(4242, 76699);
    assert!(d.scene.faults.is_empty());
    assert_quiet(&trace);
    let mut tight = Family::Plant.config();
    tight.thresholds.undecelerated_allowance_rad = 0.01;
    assert_raises(&trace, tight, "brake_weak");
}

/// Tuning seed 4242's run 13514 (physical form, forward load 6.4 N·m): powered on into the
/// running drive, the monitor guesses the overrunning reading and seeds the step check's
/// history 50 ms in, while the servo still settles: the drive torque falls ≈ 2 N·m over the
/// next 20 ms, which the lighter half read as a lost gain (`sensor_fault` at 67 ms).
#[test]
fn the_servos_settling_after_a_power_on_guess_is_no_lost_gain() {
    let (d, trace) = family_draw(4242, 13514);
    assert!(d.scene.faults.is_empty());
    assert_quiet(&trace);
}

/// Healthy paper-form turn-backs the pack slows: braking, not a slip. Tuning seed 4242's run
/// 26510 (reverse load 24.8 N·m, μ_d ≈ 13 % above it) slows from 3.4 rad/s over ≈ 0.2 s, past
/// twice the creep limit (`brake_slip` at 0.47 s before the slowing windows); tuning seed 6174's
/// run 76667 (29.4 N·m, μ_d ≈ 5 % above it) slows at ≈ 10 rad/s² from 3.8 rad/s, 1/19 of its
/// speed per 20 ms window, through 0.7 rad (`brake_slip` at 0.23 s while the windows asked 1/16
/// and the peak ⅞).
#[test]
fn a_turn_back_the_pack_keeps_slowing_is_no_slip() {
    let limit = Family::Plant.config().thresholds.creep_limit_rad;
    for (seed, run, times) in [(4242, 26510, 2.0), (6174, 76667, 4.0)] {
        let (d, trace) = family_draw(seed, run);
        assert!(d.scene.faults.is_empty());
        let back = turned_back(&trace);
        assert!(back > times * limit, "run {run} turned back {back:.3} rad");
        assert_quiet(&trace);
    }
}

/// Tuning seed 4711's runs 74912 and 132810 (physical forward loads of 7.5 and 11.9 N·m): the
/// monitor powers on into an overrunning chatter and seeds the step check's floor on a pulse
/// (74912) or the servo's settling (132810); the quiet spells then read as a lost gain.
/// Given the drive's current command, which falls with the reading, they raise nothing.
#[test]
fn a_power_on_into_a_chatter_is_no_lost_gain_given_the_command() {
    for run in [74912, 132810] {
        let (_, trace) = counted_draw(4711, run);
        assert_raises(&trace, Family::Plant.config(), "sensor_fault");
        let with = run_monitor_with(&trace, Family::Plant.config(), true).expect("monitor");
        let acc = compare(&trace, &with);
        assert!(acc.flags.is_empty(), "run {run}: {:?}", acc.flag_times());
    }
}

/// Tuning seed 4242's runs 42355 and 66709 (paper form, continuous closing at 8.1 and 8.9 N·m):
/// the pack holds the door while the ideal speed input turns on at 12.9 rad/s with 0.4 N·m of
/// drive torque (the sensor's offset). Not counted apart (its output counter ticks now and
/// then); on the build before, `sensor_fault` from the stuck counter at 0.2 rad.
#[test]
fn an_input_turning_free_of_a_held_output_is_given_the_free_span() {
    for run in [42355, 66709] {
        let (_, trace) = counted_draw(4242, run);
        assert_quiet(&trace);
        let mut tight = Family::Plant.config();
        tight.thresholds.driven_torque_nm = 0.0;
        assert_raises(&trace, tight, "sensor_fault");
    }
}

/// Tuning seed 1616's encoder_stuck run 22 (paper form, continuous closing at 25.2 N·m): the
/// output encoder freezes while the ideal speed input drives the door with no drive torque,
/// which the sensors cannot tell from an input turning free: called at the free span, the
/// slowest of that seed's such runs, 37.5 ms after manifesting (20.3 ms at 0.2 rad).
#[test]
fn a_stuck_output_encoder_with_no_drive_torque_is_called_at_the_free_span() {
    let d = draw_in(Family::Plant, 1616, 22, Some(FaultKind::EncoderStuck));
    let trace = draw_trace(&d).expect("twin");
    let fault = d.scene.faults.first().expect("a fault");
    let acc = monitor(&trace, Family::Plant.config());
    let latency = detection_latency_s(fault, &trace, &acc).expect("detected");
    assert!(latency <= 0.05, "{latency} s after manifesting");
}

/// Tuning seed 4242's runs 18198 and 57429 (paper form, forward loads of 7.5 and 8.2 N·m, just
/// under the spring's 8.4): the ideal speed input runs 0.55–0.64 rad/s ahead of the door, and
/// after the cut the door coasts on the spring's drag until it has caught the input up
/// (0.25–0.27 rad), then stops in 30 ms. On the build before, the pack health learned while
/// it coasted fell to 0.15–0.19 and the capacity margin raised `brake_weak`.
#[test]
fn a_braking_after_an_input_ran_ahead_teaches_no_pack_health() {
    for run in [18198, 57429] {
        let (d, trace) = counted_draw(4242, run);
        let est = run_monitor(&trace, Family::Plant.config()).expect("monitor");
        let cut = (d.scene.release_at_s.expect("a cut") * trace.sample_rate_hz) as usize;
        assert!(est[cut..]
            .iter()
            .all(|e| e.pack_health == est[cut].pack_health));
        assert_quiet(&trace);
    }
}

/// Tuning seed 4242's runs 79848 and 82985 (physical form, forward loads of 9.8 and 9.2 N·m at
/// 18.7 and 6.5 rad/s): overrunning, the pack's engagement pulses the drive torque from 2 to
/// 12 N·m every ≈ 46 ms; the step check's history sits at their mean, and on the build before
/// the quiet spells between them read as a lost gain (`sensor_fault` at 113 and 119 ms).
#[test]
fn an_overrunning_chatters_quiet_spells_are_no_lost_gain() {
    for run in [79848, 82985] {
        assert_quiet(&counted_draw(4242, run).1);
    }
}
