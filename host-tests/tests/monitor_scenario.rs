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
//! The plant is written here, independently of the monitor's code, from the same
//! `noback::mechanism` and `noback::sensors` numbers (one source of truth for parameters).

use noback::mechanism::{Mechanism, TABLE2};
use noback::monitor::{BrakeState, Config, Estimate, Flags, Inputs, Monitor, Scene};
use noback::sensors::{SensorConfig, DEFAULT_SENSORS};

const TICK_HZ: f64 = 10_000.0;
const H: f64 = 1.0 / TICK_HZ;
const SUBSTEPS: u32 = 20;

/// The f64 plant.
struct Plant {
    mech: Mechanism,
    sensors: SensorConfig,
    load_nm: f64,
    /// Pack capacity factor (1 = nominal μ); a worn pack is < 1.
    pack_factor: f64,
    /// Extra pack torque while driving (N·m), a dragging pack.
    extra_drag_nm: f64,
    theta: f64,
    omega: f64,
    theta_in: f64,
    drive_torque: f64,
    adc_noise: u32,
    rng: u32,
    /// Output-encoder offset (counts) so that the trace crosses the 14-bit wrap.
    out_offset: f64,
    /// Friction energy dissipated in the pack (J).
    energy: f64,
    /// `energy` after each tick.
    energy_log: Vec<f64>,
    /// Gain of the current reading (1 = healthy; 0 = open wire).
    current_gain: f64,
    /// Pressing force while driving (N), the last sub-step of the tick.
    drive_force: f64,
    /// `drive_force` after each tick.
    drive_force_log: Vec<f64>,
}

impl Plant {
    fn new(load_nm: f64, omega: f64) -> Plant {
        Plant {
            mech: TABLE2,
            sensors: DEFAULT_SENSORS,
            load_nm,
            pack_factor: 1.0,
            extra_drag_nm: 0.0,
            theta: 0.0,
            omega,
            theta_in: 0.0,
            drive_torque: 0.0,
            adc_noise: 2,
            rng: 0x1234_5678,
            out_offset: 16_300.0,
            energy: 0.0,
            energy_log: Vec::new(),
            current_gain: 1.0,
            drive_force: 0.0,
            drive_force_log: Vec::new(),
        }
    }

    fn per_newton(&self) -> f64 {
        self.mech.pack_torque_per_newton_m(self.mech.mu_static) * self.pack_factor
    }

    /// Sliding self-locking ratio μ_d·c·k of the physical reading.
    fn sliding_ratio(&self) -> f64 {
        self.mech.pack_torque_per_newton_m(self.mech.mu_dynamic)
            * self.pack_factor
            * self.mech.ramp_factor_per_m()
    }

    /// Pack torque while driving (physical reading, quasi-static, pack slipping at μ_d): the
    /// drive carries the load (`along ≤ 0`): `μ_d·c·F_s/(1 + μ_d·c·k)`; the load runs along the
    /// motion (`along` = the output ramps' torque along the motion):
    /// `μ_d·c·(F_s + 2k·along)/(1 + μ_d·c·k)`.
    fn drive_drag(&self, along: f64) -> f64 {
        let a = self.mech.pack_torque_per_newton_m(self.mech.mu_dynamic) * self.pack_factor;
        let k = self.mech.ramp_factor_per_m();
        a * (self.mech.spring_preload_n() + 2.0 * k * along.max(0.0)) / (1.0 + self.sliding_ratio())
    }

    /// Capacity with the ramps engaged (pressing force from the load, quasi-static).
    fn engaged_capacity(&self) -> f64 {
        self.per_newton() * self.mech.quasi_static_pressing_force_n(self.load_nm)
    }

    /// Advances one tick. `drive = Some(speed_ref)` runs the ideal speed servo.
    fn tick(&mut self, drive: Option<f64>) {
        let dt = H / f64::from(SUBSTEPS);
        let j = self.mech.output_inertia_kg_m2;
        let m = self.load_nm;
        let mut u_sum = 0.0;
        for _ in 0..SUBSTEPS {
            match drive {
                Some(w_ref) => {
                    // Ideal servo: the speed follows the reference with at most 50 rad/s² (within the drive's 25 A limit).
                    let dw = (w_ref - self.omega).clamp(-50.0 * dt, 50.0 * dt);
                    let w_new = self.omega + dw;
                    let s = if w_new > 0.0 {
                        1.0
                    } else if w_new < 0.0 {
                        -1.0
                    } else {
                        0.0
                    };
                    let along = s * (m - j * dw / dt);
                    let drag = self.drive_drag(along);
                    self.drive_force = drag
                        / (self.mech.pack_torque_per_newton_m(self.mech.mu_dynamic)
                            * self.pack_factor);
                    let pack = s * (drag + self.extra_drag_nm);
                    let u = if s == 0.0 { -m } else { j * dw / dt - m + pack };
                    u_sum += u;
                    self.energy += (pack * 0.5 * (self.omega + w_new)).abs() * dt;
                    self.theta += 0.5 * (self.omega + w_new) * dt;
                    self.theta_in += 0.5 * (self.omega + w_new) * dt;
                    self.omega = w_new;
                }
                None => {
                    // Drive off: both faces of the V sockets clamp the pack (physical reading).
                    let cap = self.engaged_capacity();
                    if self.omega == 0.0 {
                        if m.abs() <= cap {
                            continue; // stuck: the pack carries the load (Table 1)
                        }
                        let a = (m - m.signum() * cap) / j;
                        self.omega = a * dt;
                        self.theta += 0.5 * self.omega * dt;
                        self.energy += cap * (0.5 * self.omega * dt).abs();
                    } else {
                        let a = (m - self.omega.signum() * cap) / j;
                        let w_new = self.omega + a * dt;
                        if w_new.signum() != self.omega.signum() {
                            // Crossed zero inside the sub-step: stop there.
                            let travel = 0.5 * self.omega * (self.omega / -a);
                            self.theta += travel;
                            self.energy += cap * travel.abs();
                            self.omega = 0.0;
                        } else {
                            let travel = 0.5 * (self.omega + w_new) * dt;
                            self.theta += travel;
                            self.energy += cap * travel.abs();
                            self.omega = w_new;
                        }
                    }
                }
            }
        }
        self.drive_torque = u_sum / f64::from(SUBSTEPS);
        self.energy_log.push(self.energy);
        self.drive_force_log.push(self.drive_force);
    }

    fn next_noise(&mut self) -> i32 {
        let mut x = self.rng;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.rng = x;
        let span = 2 * self.adc_noise + 1;
        (x % span) as i32 - self.adc_noise as i32
    }

    fn inputs(&mut self, drive: bool) -> Inputs {
        let s = self.sensors;
        let u = if drive { self.drive_torque } else { 0.0 };
        let motoring = u * self.omega >= 0.0;
        let k = s.motor_torque_constant_nm_a * s.reducer_ratio;
        let current = if motoring {
            u / (k * s.reducer_efficiency)
        } else {
            u * s.reducer_efficiency / k
        };
        let noise = self.next_noise();
        let current = current * self.current_gain;
        let code = (2048.0 + (current / s.amps_per_count()).round()) as i32 + noise;
        let out = (self.theta / s.output_rad_per_count() + self.out_offset).floor() as i64;
        let motor = (self.theta_in / s.input_rad_per_motor_count()).floor() as i64;
        Inputs::new(
            code.clamp(0, 4095) as u16,
            motor.rem_euclid(1 << 16) as u32,
            out.rem_euclid(1 << 14) as u32,
            drive,
        )
    }
}

/// Runs `plant` for `seconds`, the drive on at `speed` until `cut_s`, and returns the trace.
fn run(
    plant: &mut Plant,
    monitor: &mut Monitor,
    speed: f64,
    cut_s: f64,
    seconds: f64,
) -> Vec<(f64, f64, Estimate)> {
    let ticks = (seconds * TICK_HZ).round() as u32;
    let mut trace = Vec::new();
    for k in 0..ticks {
        let t = f64::from(k) * H;
        let drive = t < cut_s;
        plant.tick(if drive { Some(speed) } else { None });
        let inputs = plant.inputs(drive);
        let e = monitor.step(&inputs);
        trace.push((t + H, plant.omega, e));
    }
    trace
}

fn first_time(
    trace: &[(f64, f64, Estimate)],
    pred: impl Fn(&(f64, f64, Estimate)) -> bool,
) -> Option<f64> {
    trace.iter().find(|x| pred(x)).map(|x| x.0)
}

/// Time at which the plant's output stopped for good.
fn true_lock_time(trace: &[(f64, f64, Estimate)], after: f64) -> Option<f64> {
    let last_moving = trace.iter().rev().find(|x| x.1 != 0.0)?;
    (last_moving.0 > after).then_some(last_moving.0)
}

fn dump(trace: &[(f64, f64, Estimate)], name: &str) {
    if std::env::var("MONITOR_DUMP").is_ok_and(|v| v == name) {
        for (t, w, e) in trace.iter().step_by(20) {
            println!(
                "{t:.4} w={w:8.3} scene={:?} brake={:?} w^={:8.3} load={:8.3} T={:8.3} Tm={:8.3} u={:8.3} h={:.3} trusted={} flags={:?}",
                e.scene, e.brake, e.output_speed_rad_s.to_num::<f64>(), e.load_torque_nm.to_num::<f64>(),
                e.braking_torque_nm.to_num::<f64>(), e.measured_braking_torque_nm.to_num::<f64>(),
                e.drive_torque_nm.to_num::<f64>(), e.pack_health.to_num::<f64>(), e.trusted, e.flags.bits()
            );
        }
    }
}

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

mod envelope {
    //! Property tests over the operating envelope: the fixed-point step against f64 shadows.

    use super::*;
    use proptest::prelude::*;

    /// Ticks the plant's output must have stood still before a holding estimate reports exactly
    /// the load: the impact estimate looks back 2 × 16 ticks from the slow lane's last
    /// classification, which reaches the report up to `SLOW.ticks` ticks later.
    const QUIET_TICKS: u32 = 33 + noback::monitor::schedule::SLOW.ticks;

    /// For each estimate of a trace, whether the plant's output has been at rest for
    /// [`QUIET_TICKS`] ticks.
    fn quiet(trace: &[(f64, f64, Estimate)]) -> Vec<bool> {
        let mut still = 0_u32;
        trace
            .iter()
            .map(|(_, w, _)| {
                still = if *w == 0.0 { still + 1 } else { 0 };
                still >= QUIET_TICKS
            })
            .collect()
    }

    /// Shadow of the estimate's derived fields, recomputed in f64 from its own estimates (load,
    /// drive torque, braking torque) with the physical reading's laws. `quiet`: the output has
    /// been at rest long enough for the holding torque to be the load alone (otherwise it also
    /// carries the output's inertia torque, checked in the library's unit test).
    fn check_shadow(e: &Estimate, quiet: bool) -> Result<(), TestCaseError> {
        let m = TABLE2;
        let load = e.load_torque_nm.to_num::<f64>();
        let spring = m.spring_preload_n();
        let k = m.ramp_factor_per_m();
        let a = m.pack_torque_per_newton_m(m.mu_dynamic);
        let ak = a * k;
        let got = e.pressing_force_n.to_num::<f64>();
        let torque = e.braking_torque_nm.to_num::<f64>();
        let (force, want_torque) = match e.scene {
            // Drive carrying the load: the input ramps unload the pack.
            Scene::Driving => (spring / (1.0 + ak), None),
            // Overrunning: equilibrium torque from the drive torque along the motion.
            Scene::Overrunning => {
                let s = e.output_speed_rad_s.to_num::<f64>().signum();
                let v = s * e.drive_torque_nm.to_num::<f64>();
                let y = ((2.0 * ak * v - a * spring) / (ak - 1.0)).max(0.0);
                ((spring + k * (y - 2.0 * v)).max(0.0), Some(s * y))
            }
            // Drive off: both faces clamp, F = F_s + k·|T|.
            Scene::FaultBraking | Scene::Holding => (spring + k * torque.abs(), None),
        };
        prop_assert!(
            (got - force).abs() <= 1e-3 * force + 0.05,
            "{:?}: force {} vs {}",
            e.scene,
            got,
            force
        );
        if let Some(want) = want_torque {
            prop_assert!(
                (torque - want).abs() <= 1e-3 * want.abs() + 0.01,
                "overrunning torque {} vs {}",
                torque,
                want
            );
        }
        // The margin: capacity at the largest expected load over that load, times the health;
        // its lower bound takes the model's spread off and credits no health above 1.
        let c = Config::physical_reading();
        let max = c.thresholds.max_load_nm;
        let service = m.pack_capacity_nm(m.quasi_static_pressing_force_n(max), c.capacity_mu) / max;
        let h = e.pack_health.to_num::<f64>();
        let low = h.min(1.0) * service * (1.0 - c.thresholds.capacity_uncertainty);
        // None once the pack was seen holding less than a load it met.
        let weak = if e.flags.pack_weak() { 0.0 } else { 1.0 };
        for (got, want) in [
            (e.capacity_margin, weak * h * service),
            (e.capacity_margin_low, weak * low),
        ] {
            let got = got.to_num::<f64>();
            prop_assert!(
                (got - want).abs() <= 1e-4 * want + 1e-4,
                "margin {} vs {}",
                got,
                want
            );
        }
        if e.brake == BrakeState::Locked && quiet {
            prop_assert!(
                (torque - load).abs() <= 1e-4,
                "holding {} vs {}",
                torque,
                load
            );
        }
        Ok(())
    }

    /// For a load against the motion whose steady drive torque `v` also fits an overrunning
    /// load `M' = y(v) − v` inside the envelope, `Some(M')` (signed along the motion). The
    /// envelope's edges are widened by what the monitor cannot resolve there: `M'` moves by
    /// `dM'/dv ≈ 5.9` per N·m of drive torque, and the drive torque is read to the current's
    /// resolution through the plant's ADC noise (`adc_noise + 1` counts, 0.02 N·m a count:
    /// ±0.35 N·m of `M'`). A load that close to an edge may be read either way (seen at
    /// `M'` = 60.2 N·m, 10.27 N·m against at 2 rad/s: the monitor's `M'` converges to 59.9).
    fn ambiguous_reading(plant: &Plant, load: f64, speed: f64) -> Option<f64> {
        let m = TABLE2;
        if load * speed >= 0.0 {
            return None;
        }
        let a = m.pack_torque_per_newton_m(m.mu_dynamic);
        let ak = a * m.ramp_factor_per_m();
        let v = load.abs() + plant.drive_drag(-load.abs());
        let along = (2.0 * ak * v - a * m.spring_preload_n()) / (ak - 1.0) - v;
        let per_count = plant
            .sensors
            .input_torque_nm(plant.sensors.amps_per_count());
        let slope = 2.0 * ak / (ak - 1.0) - 1.0;
        let edge = slope * f64::from(plant.adc_noise + 1) * per_count;
        let t = Config::physical_reading().thresholds;
        (along > t.min_load_nm - edge && along <= t.max_load_nm + edge)
            .then_some(speed.signum() * along)
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

        /// The Monte Carlo range of issue 4 (load 5–30 N·m either way, 5–20 rad/s either way,
        /// here widened to 2 N·m and 2 rad/s): released at 0.3 s, the output locks and the
        /// monitor holds the load within 5 %, with no flag. Loads whose power-on drive torque
        /// is ambiguous are the next test's.
        #[test]
        fn release_to_lock_across_the_drive_envelope(
            load in 2.0_f64..30.0, load_neg in any::<bool>(),
            speed in 2.0_f64..20.0, speed_neg in any::<bool>(),
            offset in 0.0_f64..16_384.0,
        ) {
            let load = if load_neg { -load } else { load };
            let speed = if speed_neg { -speed } else { speed };
            let mut plant = Plant::new(load, speed);
            prop_assume!(ambiguous_reading(&plant, load, speed).is_none());
            plant.out_offset = offset;
            let mut monitor = Monitor::new(Config::physical_reading()).unwrap();
            let trace = run(&mut plant, &mut monitor, speed, 0.3, 1.0);
            for ((t, w, e), q) in trace.iter().zip(quiet(&trace)) {
                check_shadow(e, q)?;
                if *t > 0.15 {
                    let got = e.output_speed_rad_s.to_num::<f64>();
                    prop_assert!((got - w).abs() <= 0.5 + 0.05 * w.abs(), "t {} speed {} vs {}", t, got, w);
                }
            }
            let last = trace.last().unwrap().2;
            prop_assert_eq!(last.brake, BrakeState::Locked);
            prop_assert!(!last.flags.any(), "{:?}", last.flags);
            // Along the load the power-on reading is a guess (`check_paper_case`): untrusted.
            prop_assert_eq!(last.trusted, load * speed < 0.0);
            let hold = last.braking_torque_nm.to_num::<f64>();
            prop_assert!((hold - load).abs() <= 0.05 * load.abs(), "hold {} vs {}", hold, load);
        }

        /// Powered on while driving, the monitor sees one steady drive torque `v`. In the
        /// physical reading a load `M` against the motion gives `v = |M| + T_drive`, and a load
        /// `M'` along it gives the same `v` when `M' = y(v) − v` (overrunning equilibrium); with
        /// no load known the monitor takes the overrunning reading whenever `M'` lies in the
        /// envelope (docs/monitor-design.md, "ambiguity at power-on"). For such against-loads
        /// (|M| up to about 10 N·m) the monitor must still stay consistent — the derived fields
        /// match their shadows, the output locks, no flag — and hold one of the two readings,
        /// normally `M'`, within 5 %. (The speed check of the previous test does not apply: the model brakes
        /// the wrong load for the first milliseconds after the cut.)
        #[test]
        fn power_on_while_driving_in_the_ambiguous_band(
            load in 2.0_f64..12.0,
            speed in 2.0_f64..20.0, speed_neg in any::<bool>(),
            offset in 0.0_f64..16_384.0,
        ) {
            let speed = if speed_neg { -speed } else { speed };
            let load = -speed.signum() * load;
            let mut plant = Plant::new(load, speed);
            let along = ambiguous_reading(&plant, load, speed);
            prop_assume!(along.is_some());
            let want = along.unwrap_or(load);
            plant.out_offset = offset;
            let mut monitor = Monitor::new(Config::physical_reading()).unwrap();
            let trace = run(&mut plant, &mut monitor, speed, 0.3, 1.0);
            for ((_, _, e), q) in trace.iter().zip(quiet(&trace)) {
                check_shadow(e, q)?;
            }
            let last = trace.last().unwrap().2;
            prop_assert_eq!(last.brake, BrakeState::Locked);
            prop_assert!(!last.flags.any(), "{:?}", last.flags);
            let hold = last.braking_torque_nm.to_num::<f64>();
            // At the band's edge (M' near the envelope limit) noise may show the drive-carries
            // reading first, which is then kept: either consistent reading is right.
            prop_assert!(
                (hold - want).abs() <= 0.05 * want.abs() || (hold - load).abs() <= 0.05 * load.abs(),
                "hold {} vs {} or {}", hold, want, load
            );
        }

        /// Power-on with the drive off anywhere in the envelope (load ±60 N·m, ±50 rad/s): no
        /// overflow — the speed tracks the plant, the derived fields match their f64 shadows —
        /// no sensor fault, and a lock once the plant has stopped.
        #[test]
        fn power_on_braking_across_the_full_envelope(
            load in -60.0_f64..60.0,
            speed in -50.0_f64..50.0,
            offset in 0.0_f64..16_384.0,
        ) {
            let mut plant = Plant::new(load, speed);
            plant.out_offset = offset;
            let mut monitor = Monitor::new(Config::physical_reading()).unwrap();
            let trace = run(&mut plant, &mut monitor, 0.0, 0.0, 1.5);
            // The observer needs its settling time after power-on and after the plant stops
            // abruptly (up to 440 rad/s² to rest in one tick, unknown load): 0.1 s and 50 ms are
            // left out of the speed comparison.
            let mut stopped_at = f64::NEG_INFINITY;
            let mut prev_w = speed;
            for ((t, w, e), q) in trace.iter().zip(quiet(&trace)) {
                check_shadow(e, q)?;
                if *w == 0.0 && prev_w != 0.0 {
                    stopped_at = *t;
                }
                prev_w = *w;
                if *t > 0.1 && *t - stopped_at > 0.05 {
                    let got = e.output_speed_rad_s.to_num::<f64>();
                    prop_assert!((got - w).abs() <= 1.0 + 0.05 * w.abs(), "t {} speed {} vs {}", t, got, w);
                }
                prop_assert!(!e.flags.sensor_fault && !e.flags.overrun, "t {} {:?}", t, e.flags);
            }
            let last = trace.last().unwrap();
            if last.1 == 0.0 && trace.iter().rev().nth(500).is_some_and(|x| x.1 == 0.0) {
                prop_assert_eq!(last.2.brake, BrakeState::Locked);
            }
        }
    }
}
