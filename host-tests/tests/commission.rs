//! Commissioning (docs/commissioning.md) tested on runs it did not see: set
//! from one acceptance run of each reading, evaluated on other loads, speeds, current noise and
//! noise seeds, and on closing runs.

use host_tests::accuracy::{compare, run_monitor, scene_trace};
use host_tests::commission::{commission, commission_unit, ACCEPTANCE};
use host_tests::mc::mirror;
use noback::monitor::{Config, DrivingPack};
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::trace::Trace;

fn scene(kind: SceneKind, reading: Reading, load: f64, speed: f64, noise: (u64, f64)) -> Scene {
    let mut s = Scene::builtin(kind, reading);
    s.load_torque_nm = load;
    s.initial_speed_rad_s = speed;
    s.noise.seed = noise.0;
    s.noise.current_noise_a = noise.1;
    s
}

/// The monitor set by `config` on `trace`: no flag and the holding torque within 2 %; returns
/// the holding-torque error (%).
fn holds_within_2pct(trace: &Trace, config: Config, what: &str) -> f64 {
    let acc = compare(trace, &run_monitor(trace, config).unwrap());
    assert!(acc.flags.is_empty(), "{what}: {:?}", acc.flags);
    let err = acc.holding_torque_err_pct().unwrap();
    assert!(err <= 2.0, "{what}: holding torque off by {err:.2} %");
    err
}

#[test]
fn settings_from_one_run_hold_on_runs_it_did_not_see() {
    for (reading, form) in [
        (Reading::Paper, DrivingPack::SpringOnly),
        (Reading::Physical, DrivingPack::Relieved),
    ] {
        let acceptance = scene(SceneKind::ReverseLoad, reading, 20.3, 13.78, (1, 0.0));
        let c = commission(&[(&scene_trace(&acceptance).unwrap(), 20.3)]).unwrap();
        assert_eq!(c.config.driving_pack, form, "{reading:?}");
        assert!(c.config.commissioned);
        for (load, speed, noise) in [(12.0, 9.0, (7, 0.05)), (30.0, 13.78, (11, 0.05))] {
            let s = scene(SceneKind::ReverseLoad, reading, load, speed, noise);
            let what = format!("{reading:?} reverse_load {load} N·m at {speed} rad/s");
            holds_within_2pct(&scene_trace(&s).unwrap(), c.config, &what);
        }
        let s = scene(SceneKind::ForwardLoad, reading, 25.0, 11.0, (3, 0.05));
        let trace = scene_trace(&s).unwrap();
        let acc = compare(&trace, &run_monitor(&trace, c.config).unwrap());
        assert!(
            acc.flags.is_empty(),
            "{reading:?} forward_load: {:?}",
            acc.flags
        );
    }
}

/// A unit whose current reads 8 % high through the motor constant, 2 % through the sensor, with
/// 0.2 A of offset and a reducer at 85 %: two acceptance runs identify gain and offset.
#[test]
fn two_loads_identify_the_current_gain_and_offset() {
    let unit = |s: &mut Scene| {
        s.sensors.motor_torque_constant_nm_a *= 0.92;
        s.sensors.reducer_efficiency = 0.85;
        s.noise.current_gain = 1.02;
        s.noise.current_offset_a = 0.2;
    };
    for reading in [Reading::Paper, Reading::Physical] {
        let runs: Vec<_> = [20.3, 8.0]
            .iter()
            .map(|&load| {
                let mut s = scene(SceneKind::ReverseLoad, reading, load, 13.78, (5, 0.02));
                unit(&mut s);
                (scene_trace(&s).unwrap(), load)
            })
            .collect();
        let pairs: Vec<_> = runs.iter().map(|(t, l)| (t, *l)).collect();
        let c = commission(&pairs).unwrap();
        assert!(
            (c.current_offset_a - 0.2).abs() < 0.02,
            "{reading:?}: offset {}",
            c.current_offset_a
        );
        for load in [12.0, 24.0] {
            let mut s = scene(SceneKind::ReverseLoad, reading, load, 10.0, (9, 0.02));
            unit(&mut s);
            let trace = scene_trace(&s).unwrap();
            let one = commission(&pairs[..1]).map(|c| {
                compare(&trace, &run_monitor(&trace, c.config).unwrap())
                    .holding_torque_err_pct()
                    .unwrap()
            });
            println!(
                "{reading:?} {load} N·m: gain {:.4}, one run: {one:?}",
                c.gain
            );
            let err = holds_within_2pct(&trace, c.config, &format!("{reading:?} {load} N·m"));
            println!("{reading:?} {load} N·m: holding error {err:.2} %");
        }
    }
}

/// A closing run in the acceptance cycle sets the overrunning equilibrium the closing estimate
/// rests on: the physical reading's forward_load at other loads and speeds within 2 %.
#[test]
fn a_closing_run_sets_the_overrunning_estimate() {
    let reading = Reading::Physical;
    let runs: Vec<_> = [
        (SceneKind::ReverseLoad, 20.3),
        (SceneKind::ReverseLoad, 8.0),
        (SceneKind::ForwardLoad, 20.3),
    ]
    .iter()
    .map(|&(kind, load)| {
        let s = scene(kind, reading, load, 13.78, (2, 0.02));
        (scene_trace(&s).unwrap(), load)
    })
    .collect();
    let pairs: Vec<_> = runs.iter().map(|(t, l)| (t, *l)).collect();
    let c = commission(&pairs).unwrap();
    assert!(c.runs[2].closing && c.config.driving_pack == DrivingPack::Relieved);
    for (load, speed) in [(10.0, 8.0), (28.0, 12.0)] {
        let s = scene(SceneKind::ForwardLoad, reading, load, speed, (13, 0.02));
        let what = format!("forward_load {load} N·m at {speed} rad/s");
        let err = holds_within_2pct(&scene_trace(&s).unwrap(), c.config, &what);
        println!("{what}: holding error {err:.2} %");
    }
}

#[test]
fn a_run_with_the_wrong_load_is_refused_or_misread_openly() {
    // The crew's load above what the drive took leaves no drag: refused, naming the load.
    let t = scene_trace(&Scene::builtin(SceneKind::ReverseLoad, Reading::Physical)).unwrap();
    let e = commission(&[(&t, 40.0)]).unwrap_err();
    assert!(e.contains("load"), "{e}");
    let e = commission(&[(&t, 0.5)]).unwrap_err();
    assert!(e.contains("below"), "{e}");
    // Two runs must span enough load to give the gain.
    let e = commission(&[(&t, 20.3), (&t, 21.0)]).unwrap_err();
    assert!(e.contains("span"), "{e}");
}

/// A unit mounted the other way (every reading negated, `mc::mirror`) opens in the positive
/// direction: its first run says so, and it is set as its twin mounted the usual way, the
/// current's offset negated. The unit's own forward_load then holds within 2 % as well.
#[test]
fn a_unit_mounted_the_other_way_is_set_alike() {
    let s = Scene::builtin(SceneKind::ReverseLoad, Reading::Physical).sensors;
    let negate = |t: &mut Trace| {
        mirror(
            t,
            s.current_adc_bits,
            s.motor_counter_bits,
            s.output_encoder_bits,
        )
    };
    let mut unit = scene(
        SceneKind::ReverseLoad,
        Reading::Physical,
        20.3,
        13.78,
        (4, 0.02),
    );
    unit.noise.current_offset_a = 0.15;
    let usual = commission_unit(&unit, &ACCEPTANCE, |_| {}).unwrap();
    let other = commission_unit(&unit, &ACCEPTANCE, negate).unwrap();
    assert!(other.runs[0].drive_speed_rad_s > 0.0 && other.runs[2].closing);
    assert_eq!(
        (other.gain, other.drive_drag_nm, other.braking_share),
        (usual.gain, usual.drive_drag_nm, usual.braking_share)
    );
    assert_eq!(other.current_offset_a, -usual.current_offset_a);
    assert_eq!(other.config.driving_pack, usual.config.driving_pack);
    let mut closing = scene(
        SceneKind::ForwardLoad,
        Reading::Physical,
        15.0,
        10.0,
        (8, 0.02),
    );
    closing.noise.current_offset_a = 0.15;
    let mut trace = scene_trace(&closing).unwrap();
    negate(&mut trace);
    let err = holds_within_2pct(&trace, other.config, "mounted the other way, forward_load");
    println!(
        "mounted the other way: offset {:.3} A, forward_load holding error {err:.2} %",
        other.current_offset_a
    );
}

/// A spring-only pack (the paper reading) overruns on almost no drive torque whatever the
/// load: commissioned, its closing's load is not seen while the drive runs, and no estimate
/// resting on it is trusted then. Its braking shows it (`aiding.rs`): from the lock the holding
/// torque is trusted within 2 % (it was untrusted, 53 % off: docs/monitor-family.md). A load
/// below the seated pack's drag, or a unit commissioned without a closing run, stays untrusted.
/// Opening against the load, and a relieved pack's closing (the physical reading), are seen.
#[test]
fn a_load_a_spring_only_pack_overruns_on_is_read_from_its_braking() {
    let end = |reading, kind, load, c: Config| {
        let s = scene(kind, reading, load, 11.0, (6, 0.02));
        let trace = scene_trace(&s).unwrap();
        let estimates = run_monitor(&trace, c).unwrap();
        let driving = trace
            .rows
            .iter()
            .zip(&estimates)
            .filter(|(r, _)| r.drive_on);
        let trusted_driving = driving.filter(|(_, e)| e.trusted).count();
        let acc = compare(&trace, &estimates);
        assert!(
            acc.flags.is_empty(),
            "{reading:?} {kind:?}: {:?}",
            acc.flags
        );
        let err = acc.holding_torque_err_pct().unwrap();
        (trusted_driving, acc.trusted_at_end, err)
    };
    let unit = |reading, plan: &[(SceneKind, f64)]| {
        let s = Scene::builtin(SceneKind::ReverseLoad, reading);
        commission_unit(&s, plan, |_| {}).unwrap().config
    };
    let paper = unit(Reading::Paper, &ACCEPTANCE);
    assert_eq!(paper.driving_pack, DrivingPack::SpringOnly);
    assert!(paper.aiding_braking.is_some());
    for load in [12.0, 18.0, 30.0] {
        let (driving, trusted, err) = end(Reading::Paper, SceneKind::ForwardLoad, load, paper);
        println!("paper forward_load {load} N·m: trusted driving {driving} ticks, at the end {trusted}, holding error {err:.2} %");
        assert_eq!(driving, 0, "{load} N·m: trusted while the load was unseen");
        assert!(trusted && err <= 2.0, "{load} N·m: {trusted} {err:.2} %");
    }
    let drag = paper.aiding_braking.map_or(0.0, |a| a.drag_nm);
    let (_, trusted, err) = end(Reading::Paper, SceneKind::ForwardLoad, 0.7 * drag, paper);
    assert!(!trusted, "below the drag: trusted at {err:.1} % off");
    let openings = unit(Reading::Paper, &ACCEPTANCE[..2]);
    assert_eq!(openings.aiding_braking, None);
    let (_, trusted, err) = end(Reading::Paper, SceneKind::ForwardLoad, 18.0, openings);
    assert!(!trusted, "no closing run: trusted at {err:.1} % off");
    let (_, trusted, err) = end(Reading::Paper, SceneKind::ReverseLoad, 18.0, paper);
    assert!(
        trusted && err <= 2.0,
        "paper reverse_load: {trusted} {err:.2} %"
    );
    let physical = unit(Reading::Physical, &ACCEPTANCE);
    let (_, _, err) = end(Reading::Physical, SceneKind::ForwardLoad, 18.0, physical);
    assert!(err <= 2.0, "physical forward_load: {err:.2} %");
}

/// A paper-form unit (a spring-only pack) commissioned on its acceptance runs, on reverse
/// braking runs it did not see: the output's turning point is not the lock (`stop.rs`), and
/// issue 16's item 4 holds: holding torque within 2 %, force RMS within 10 % of its peak, lock
/// within 10 ms. Before the turn-back rule: force 21 %, lock 35 ms early at 20.3 N·m.
#[test]
fn a_spring_only_unit_turning_back_meets_the_accuracy_targets() {
    let base = Scene::builtin(SceneKind::ReverseLoad, Reading::Paper);
    let c = commission_unit(&base, &ACCEPTANCE, |_| {}).unwrap();
    assert_eq!(c.config.driving_pack, DrivingPack::SpringOnly);
    // Below the spring's capacity (6 N·m: no turn-back) and above it.
    for (load, speed, seed) in [
        (6.0, 13.78, 2),
        (12.0, 9.0, 7),
        (25.0, 13.78, 11),
        (30.0, 11.0, 3),
    ] {
        let s = scene(
            SceneKind::ReverseLoad,
            Reading::Paper,
            load,
            speed,
            (seed, 0.05),
        );
        let trace = scene_trace(&s).unwrap();
        let acc = compare(&trace, &run_monitor(&trace, c.config).unwrap());
        let b = acc.braking().unwrap();
        let lock_ms = b.lock_err_s.map(|e| e * 1e3);
        println!(
            "{load} N·m at {speed} rad/s: holding {:.2} %, force {:.1} %, lock {lock_ms:?} ms",
            b.holding_err_pct, b.force_rms_pct
        );
        assert!(acc.flags.is_empty(), "{load} N·m: {:?}", acc.flags);
        assert!(
            b.holding_err_pct <= 2.0 && b.force_rms_pct <= 10.0,
            "{load} N·m: {b:?}"
        );
        assert!(
            lock_ms.is_some_and(|e| e.abs() <= 10.0),
            "{load} N·m: {b:?}"
        );
        assert!(b.trusted, "{load} N·m");
    }
}

/// The physical family's reverse_load draws, each commissioned on the acceptance cycle: the
/// estimates marked trusted hold within 2 % and 0.5 % on average. The load is learned with the
/// drag the openings measured; with the drag the closing run's `μ_d` implies, draw 162 ends
/// trusted 5.1 % off.
#[test]
fn a_commissioned_unit_learns_its_load_with_the_drag_its_openings_measured() {
    use host_tests::family::{form, Family};
    use host_tests::mc::{draw_in, draw_trace};
    let mut errs = Vec::new();
    for i in 0..600 {
        let d = draw_in(Family::Plant, 31, i, None);
        if errs.len() == 16 {
            break;
        }
        if form(&d.scene) != "physical" || d.scene.kind != SceneKind::ReverseLoad {
            continue;
        }
        let Ok(c) = commission_unit(&d.scene, &ACCEPTANCE, |t| d.mount(t)) else {
            continue;
        };
        assert_eq!(c.config.driving_drag_nm, Some(c.drive_drag_nm));
        let trace = draw_trace(&d).unwrap();
        let acc = compare(&trace, &run_monitor(&trace, c.config).unwrap());
        if acc.trusted_at_end {
            let err = acc.holding_torque_err_pct().unwrap();
            assert!(
                err <= 2.0,
                "draw {i}: trusted, holding torque off by {err:.2} %"
            );
            errs.push(err);
        }
    }
    assert_eq!(errs.len(), 16);
    let mean = errs.iter().sum::<f64>() / 16.0;
    println!(
        "trusted holding-torque error: mean {mean:.2} %, largest {:.2} %",
        errs.iter().cloned().fold(0.0, f64::max)
    );
    assert!(mean <= 0.5, "mean holding-torque error {mean:.2} %");
}

/// The physical family's forward_load draws, each commissioned on the acceptance cycle: its two
/// closings set the unit's own overrunning line, which reads the load the door closes with
/// within 2 % on more units than the model's line through one closing does.
#[test]
fn two_closings_set_the_units_overrunning_line() {
    use host_tests::family::{form, Family};
    use host_tests::mc::{draw_in, draw_trace};
    let (mut units, mut within_line, mut within_one) = (0, 0, 0);
    for i in 0..600 {
        let d = draw_in(Family::Plant, 31, i, None);
        if units == 12 {
            break;
        }
        if form(&d.scene) != "physical" || d.scene.kind != SceneKind::ForwardLoad {
            continue;
        }
        let (Ok(two), Ok(one)) = (
            commission_unit(&d.scene, &ACCEPTANCE, |t| d.mount(t)),
            commission_unit(&d.scene, &ACCEPTANCE[..3], |t| d.mount(t)),
        ) else {
            continue;
        };
        assert!(two.config.overrun_line.is_some() && one.config.overrun_line.is_none());
        let trace = draw_trace(&d).unwrap();
        let err = |c: Config| {
            compare(&trace, &run_monitor(&trace, c).unwrap())
                .holding_torque_err_pct()
                .unwrap_or(f64::INFINITY)
        };
        let (line, model) = (err(two.config), err(one.config));
        println!(
            "draw {i}: {} N·m, holding error {line:.2} % (one closing: {model:.2} %)",
            d.scene.load_torque_nm
        );
        units += 1;
        within_line += usize::from(line <= 2.0);
        within_one += usize::from(model <= 2.0);
    }
    assert_eq!(units, 12);
    println!("within 2 %: {within_line} of 12 (one closing: {within_one})");
    assert!(
        within_line >= 9 && within_line > within_one,
        "{within_line} vs {within_one}"
    );
}

/// A light opening load the current cannot tell from a closing one is read against the motion
/// at the first lock, which comes later than any closing's on that unit (`lock_times`), and
/// left untrusted; a closing load is never moved by it. Test seed 31.
#[test]
fn a_light_opening_load_is_read_at_its_late_lock() {
    use host_tests::family::{form, Family};
    use host_tests::mc::{draw_in, draw_trace};
    let (mut openings, mut closings) = (0, 0);
    for i in 0..2000 {
        let d = draw_in(Family::Plant, 31, i, None);
        if openings == 6 && closings == 6 {
            break;
        }
        let light_opening = d.scene.kind == SceneKind::ReverseLoad && d.scene.load_torque_nm < 11.0;
        let wanted = match d.scene.kind {
            _ if form(&d.scene) != "physical" => false,
            SceneKind::ForwardLoad => closings < 6,
            _ => light_opening && openings < 6,
        };
        if !wanted {
            continue;
        }
        let Ok(unit) = commission_unit(&d.scene, &ACCEPTANCE, |t| d.mount(t)) else {
            continue;
        };
        let Some(times) = unit.config.lock_times else {
            continue;
        };
        let trace = draw_trace(&d).unwrap();
        let with = run_monitor(&trace, unit.config).unwrap();
        let without = Config {
            lock_times: None,
            ..unit.config
        };
        let (read, guessed) = (
            *with.last().unwrap(),
            *run_monitor(&trace, without).unwrap().last().unwrap(),
        );
        println!(
            "draw {i}: {:?} {} N·m, lock times {times:?}: load {} (without: {}), trusted {}",
            d.scene.kind,
            d.scene.load_torque_nm,
            read.load_torque_nm,
            guessed.load_torque_nm,
            read.trusted
        );
        if d.scene.kind == SceneKind::ForwardLoad {
            closings += 1;
            assert_eq!(read.load_torque_nm, guessed.load_torque_nm, "draw {i}");
        } else if !guessed.trusted {
            openings += 1;
            let err = compare(&trace, &with)
                .holding_torque_err_pct()
                .unwrap_or(f64::INFINITY);
            // Settled, not trusted: a light load's size carries the drag's error (2.3–3.5 % on
            // four of 181 at tuning seed 1616).
            assert!(!read.trusted && err <= 2.0, "draw {i}: {err:.2} %");
        }
    }
    assert_eq!((openings, closings), (6, 6));
}

/// A relieved pack that barely self-locks while slipping (`a·k` ≈ 0.95 in the twin, a draw the
/// plant family makes) is refused: its closings' load would be read off `1/(a·k − 1)`.
#[test]
fn a_pack_that_barely_self_locks_while_slipping_is_refused() {
    let mut unit = Scene::builtin(SceneKind::ReverseLoad, Reading::Physical);
    let m = &unit.mechanism;
    let a_k = m.pack_torque_per_newton_m(m.mu_dynamic) * m.ramp_factor_per_m();
    unit.mechanism.mu_dynamic *= 0.95 / a_k;
    let e = commission_unit(&unit, &ACCEPTANCE, |_| {}).unwrap_err();
    assert!(e.contains("self-locks too little"), "{e}");
}
