//! The synthetic plant of `monitor_scenario.rs`: an f64 output shaft under a constant load,
//! an ideal speed-servo drive and a quasi-static pack, quantised into the monitor's inputs; and
//! the helpers that run it against the monitor.

use noback::mechanism::{Mechanism, TABLE2};
use noback::monitor::{Estimate, Inputs, Monitor};
use noback::sensors::{SensorConfig, DEFAULT_SENSORS};

pub(crate) const TICK_HZ: f64 = 10_000.0;
pub(crate) const H: f64 = 1.0 / TICK_HZ;
pub(crate) const SUBSTEPS: u32 = 20;

/// The f64 plant.
pub(crate) struct Plant {
    pub(crate) mech: Mechanism,
    pub(crate) sensors: SensorConfig,
    pub(crate) load_nm: f64,
    /// Pack capacity factor (1 = nominal μ); a worn pack is < 1.
    pub(crate) pack_factor: f64,
    /// Extra pack torque while driving (N·m), a dragging pack.
    pub(crate) extra_drag_nm: f64,
    pub(crate) theta: f64,
    pub(crate) omega: f64,
    pub(crate) theta_in: f64,
    pub(crate) drive_torque: f64,
    pub(crate) adc_noise: u32,
    pub(crate) rng: u32,
    /// Output-encoder offset (counts) so that the trace crosses the 14-bit wrap.
    pub(crate) out_offset: f64,
    /// Friction energy dissipated in the pack (J).
    pub(crate) energy: f64,
    /// `energy` after each tick.
    pub(crate) energy_log: Vec<f64>,
    /// Gain of the current reading (1 = healthy; 0 = open wire).
    pub(crate) current_gain: f64,
    /// Pressing force while driving (N), the last sub-step of the tick.
    pub(crate) drive_force: f64,
    /// `drive_force` after each tick.
    pub(crate) drive_force_log: Vec<f64>,
}

impl Plant {
    pub(crate) fn new(load_nm: f64, omega: f64) -> Plant {
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

    pub(crate) fn per_newton(&self) -> f64 {
        self.mech.pack_torque_per_newton_m(self.mech.mu_static) * self.pack_factor
    }

    /// Sliding self-locking ratio μ_d·c·k of the physical reading.
    pub(crate) fn sliding_ratio(&self) -> f64 {
        self.mech.pack_torque_per_newton_m(self.mech.mu_dynamic)
            * self.pack_factor
            * self.mech.ramp_factor_per_m()
    }

    /// Pack torque while driving (physical reading, quasi-static, pack slipping at μ_d): the
    /// drive carries the load (`along ≤ 0`): `μ_d·c·F_s/(1 + μ_d·c·k)`; the load runs along the
    /// motion (`along` = the output ramps' torque along the motion):
    /// `μ_d·c·(F_s + 2k·along)/(1 + μ_d·c·k)`.
    pub(crate) fn drive_drag(&self, along: f64) -> f64 {
        let a = self.mech.pack_torque_per_newton_m(self.mech.mu_dynamic) * self.pack_factor;
        let k = self.mech.ramp_factor_per_m();
        a * (self.mech.spring_preload_n() + 2.0 * k * along.max(0.0)) / (1.0 + self.sliding_ratio())
    }

    /// Capacity with the ramps engaged (pressing force from the load, quasi-static).
    pub(crate) fn engaged_capacity(&self) -> f64 {
        self.per_newton() * self.mech.quasi_static_pressing_force_n(self.load_nm)
    }

    /// Advances one tick. `drive = Some(speed_ref)` runs the ideal speed servo.
    pub(crate) fn tick(&mut self, drive: Option<f64>) {
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

    pub(crate) fn next_noise(&mut self) -> i32 {
        let mut x = self.rng;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.rng = x;
        let span = 2 * self.adc_noise + 1;
        (x % span) as i32 - self.adc_noise as i32
    }

    pub(crate) fn inputs(&mut self, drive: bool) -> Inputs {
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
pub(crate) fn run(
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

pub(crate) fn first_time(
    trace: &[(f64, f64, Estimate)],
    pred: impl Fn(&(f64, f64, Estimate)) -> bool,
) -> Option<f64> {
    trace.iter().find(|x| pred(x)).map(|x| x.0)
}

/// Time at which the plant's output stopped for good.
pub(crate) fn true_lock_time(trace: &[(f64, f64, Estimate)], after: f64) -> Option<f64> {
    let last_moving = trace.iter().rev().find(|x| x.1 != 0.0)?;
    (last_moving.0 > after).then_some(last_moving.0)
}

pub(crate) fn dump(trace: &[(f64, f64, Estimate)], name: &str) {
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
