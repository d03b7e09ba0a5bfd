//! The monitor: the 10 kHz fixed-point reduced model that estimates pressing force and braking
//! torque and flags brake failure (issue 4). The design, with its reasons, is in
//! docs/monitor-design.md; this doc is the short version.
//!
//! ```
//! use noback::monitor::{Config, Inputs, Monitor};
//! let mut monitor = Monitor::new(Config::default()).unwrap();
//! // Drive off, no current (ADC mid-scale), both encoders at rest.
//! let mut estimate = monitor.step(&Inputs::new(2048, 0, 0, false));
//! for _ in 0..200 {
//!     estimate = monitor.step(&Inputs::new(2048, 0, 0, false));
//! }
//! assert_eq!(estimate.brake, noback::monitor::BrakeState::Locked);
//! assert!(!estimate.flags.any());
//! ```
//!
//! # Model
//! Only the output shaft's rotation is dynamic: `J_s·ω̇ = M + u − T`, with `u` the drive torque
//! from the motor current (`k_t·ratio·η`, `÷η` when back-driven), `M` the load and `T` the pack
//! torque. The axial force balance is quasi-static: pressing force `F = F_spring` while the
//! ramps carry no load, `F_spring + |M̂|·tanθ/r` while they do (engaged). Pack capacity
//! `T_all = μ·(2N_f − 1)·r_f·F`; Table 1 with a Karnopp stick band gives `T`.
//!
//! A three-state observer (angle, speed, torque) on the 14-bit output encoder tracks
//! `J_s·ω̇ − u` with the model's `T̂` fed forward, so scene changes are bumpless. The load `M̂`
//! is learned only where it is well conditioned (pack released: `M = N + s·T_drag`), held where
//! it is unobservable (locked), and compared with the measured braking torque where the pack
//! slips (pack health).
//!
//! | scene | when | model |
//! |---|---|---|
//! | `Driving` | drive on, input leads | pack at spring drag; learn `M̂`; drag and stuck-counter checks |
//! | `Overrunning` | drive on, output faster than input | ramps engaged, pack slipping at `T_all(M̂)` |
//! | `FaultBraking` | drive off, output moving | engaged when moving with the load, else spring drag; time/angle envelope |
//! | `Holding` | drive off, output stuck ≥ dwell | `T = M̂` (≤ `T_all`); creep check |
//!
//! # Formats
//! | quantity | format | range | resolution |
//! |---|---|---|---|
//! | torque, force, speed, current, margin, health | [`Q16`] = `I16F16` | ±32 768 | 1.53e-5 |
//! | output angle (observer) | `u32` word, wrapping | one turn | 2π/2³² = 1.46e-9 rad |
//! | constants | [`Scale<S>`] = `i32` mantissa · 2^-S (S in the type, per constant) | \|k\| < 2^(31−S) | ≥ 20 significant bits (26–28 at the defaults) |
//! | friction energy | `U40F24` | 1.1e12 J | 6e-8 J |
//! | counters, timers | `i32`/`u32`, saturating | — | 1 count / 1 tick |
//!
//! Every multiplication by a constant is a [`Scale<S>`] product, rounded to nearest; sums and
//! products of physical quantities saturate; counter and angle arithmetic wraps (the encoders
//! are modular). There is no division and no floating point in [`Monitor::step`]; every
//! constant is derived in [`Monitor::new`].
//!
//! # Cost
//! Measured by single-stepping QEMU over a 4000-tick drive/cut/brake/hold stream (release,
//! LTO): Cortex-M3 mean 722, max 876 instructions per step; Cortex-M0 mean 1750, max 2423.
//!
//! # Missed ticks
//! The caller sets [`Inputs::ticks_elapsed`] to the number of ticks since the previous call
//! (1 when on time). A value above 1 latches `overrun`, advances the model by that many ticks and
//! scales the plausibility limits; above `max_catchup_ticks` the observer is re-seated on the
//! measurement and the estimate is untrusted until it settles again.

mod config;
mod io;
mod observer;
mod scale;

pub use config::{
    Config, ConfigError, ObserverGains, Thresholds, DEFAULT_OBSERVER_BANDWIDTH_HZ, DEFAULT_TICK_HZ,
};
pub use io::{BrakeState, Estimate, Flags, Inputs, Scene, ESTIMATE_WORDS};
pub use scale::{recip_q16, sat_i32, Scale, ScaleError};

use crate::fx::{adc_centered, counter_delta, lowpass, mul_sat, Q16};
use config::Params;
use fixed::types::U40F24;
use observer::Observer;

/// Largest capacity margin reported (loads below `min_load_nm` report this).
pub const MARGIN_MAX: Q16 = Q16::from_bits(1000 << 16);

/// Pack health is kept within [0, 2].
const HEALTH_MAX: i32 = 2 << 16;

/// The monitor: configuration constants plus state. One [`Monitor::step`] per tick.
#[derive(Clone, Debug)]
pub struct Monitor {
    p: Params,
    obs: Observer,
    started: bool,
    tick: u32,
    prev_out: u32,
    prev_motor: u32,
    prev_drive: bool,
    input_speed: Q16,
    drive_torque: Q16,
    load: Q16,
    load_known: bool,
    load_learn_ticks: u32,
    load_ref: Q16,
    load_ref_known: bool,
    brake_model: Q16,
    locked: bool,
    engaged: bool,
    overrunning: bool,
    scene: Scene,
    stick_ticks: u32,
    phase_ticks: u32,
    settle_ticks: u32,
    since_fault: u32,
    rail_ticks: u32,
    innovation_ticks: u32,
    envelope: BrakingEnvelope,
    creep_valid: bool,
    creep_counts: i32,
    still_out: u32,
    still_motor: u32,
    weak_ticks: u32,
    drag_ticks: u32,
    health: Q16,
    energy: U40F24,
    flags: Flags,
    /// Quantities that depend only on the load estimate, recomputed when it changes.
    load_cache: LoadCache,
}

/// Engaged pressing force, capacity and `1/|M̂|` for one value of the load estimate.
#[derive(Clone, Copy, Debug)]
struct LoadCache {
    load: Q16,
    valid: bool,
    force: Q16,
    capacity: Q16,
    recip: Q16,
    /// `min_capacity_margin · |M̂|` (N·m).
    margin_floor: Q16,
}

/// The braking envelope of one braking event (drive cut to lock).
#[derive(Clone, Copy, Debug, Default)]
struct BrakingEnvelope {
    /// Output travel since the cut (counts, saturating).
    counts: i32,
    /// Speed magnitude the nominal model predicts (Q16 rad/s).
    expected_speed: Q16,
    /// Travel the nominal model predicts (Q16 counts, saturating).
    expected_counts: i32,
    /// Ticks spent moving after the nominal model stopped.
    overdue_ticks: u32,
}

impl BrakingEnvelope {
    /// Starts the envelope from the present output speed.
    fn arm(&mut self, speed: Q16) {
        *self = BrakingEnvelope {
            expected_speed: speed.saturating_abs(),
            ..BrakingEnvelope::default()
        };
    }
}

/// `x·n` for a tick count `n ≥ 1`, **saturating**; free when `n = 1` (every on-time step).
trait Times {
    fn times(self, n: i32) -> i32;
}

impl Times for i32 {
    #[inline]
    fn times(self, n: i32) -> i32 {
        if n == 1 {
            self
        } else {
            self.saturating_mul(n)
        }
    }
}

/// `s·x` for a sign `s ∈ {−1, 0, 1}`, saturating.
#[inline]
fn signed(s: i32, x: Q16) -> Q16 {
    match s {
        1 => x,
        -1 => x.saturating_neg(),
        _ => Q16::ZERO,
    }
}

impl Monitor {
    /// Validates `config` and precomputes every constant of the step.
    ///
    /// ```
    /// use noback::monitor::{Config, ConfigError, Monitor};
    /// let mut config = Config::default();
    /// config.mechanism.output_inertia_kg_m2 = 0.0;
    /// assert_eq!(
    ///     Monitor::new(config).unwrap_err(),
    ///     ConfigError::OutOfRange { parameter: "mechanism.output_inertia_kg_m2" }
    /// );
    /// ```
    pub fn new(config: Config) -> Result<Monitor, ConfigError> {
        let p = Params::from_config(&config)?;
        Ok(Monitor {
            p,
            obs: Observer::default(),
            started: false,
            tick: 0,
            prev_out: 0,
            prev_motor: 0,
            prev_drive: false,
            input_speed: Q16::ZERO,
            drive_torque: Q16::ZERO,
            load: Q16::ZERO,
            load_known: false,
            load_learn_ticks: 0,
            load_ref: Q16::ZERO,
            load_ref_known: false,
            brake_model: Q16::ZERO,
            locked: false,
            engaged: true,
            overrunning: false,
            scene: Scene::FaultBraking,
            stick_ticks: 0,
            phase_ticks: 0,
            settle_ticks: 0,
            since_fault: 0,
            rail_ticks: 0,
            innovation_ticks: 0,
            envelope: BrakingEnvelope::default(),
            creep_valid: false,
            creep_counts: 0,
            still_out: 0,
            still_motor: 0,
            weak_ticks: 0,
            drag_ticks: 0,
            health: Q16::ONE,
            energy: U40F24::ZERO,
            flags: Flags::default(),
            load_cache: LoadCache {
                load: Q16::ZERO,
                valid: false,
                force: Q16::ZERO,
                capacity: Q16::ZERO,
                recip: Q16::ZERO,
                margin_floor: Q16::ZERO,
            },
        })
    }

    /// The latched flags.
    pub fn flags(&self) -> Flags {
        self.flags
    }

    /// Clears the latched flags (a condition still present raises its flag again).
    pub fn reset_flags(&mut self) {
        self.flags = Flags::default();
        self.weak_ticks = 0;
        self.drag_ticks = 0;
        self.envelope = BrakingEnvelope::default();
        self.creep_counts = 0;
    }

    /// One tick: reads the raw inputs, advances the model, returns the estimate. Never panics;
    /// every output is bounded by its format.
    pub fn step(&mut self, inputs: &Inputs) -> Estimate {
        let p = &self.p;
        let n = u32::from(inputs.ticks_elapsed.max(1));
        let n_i = n as i32; // ≤ 255
        let mut fault = false;
        if n > 1 {
            self.flags.overrun = true;
        }
        self.tick = self.tick.wrapping_add(n); // tick counter: modular on purpose

        // ---- Current: offset-binary code → counts about mid-scale (saturating helper).
        let code = inputs.current_adc_code;
        if code > p.adc_max_code {
            fault = true; // the converter cannot produce it
        }
        if code == 0 || code >= p.adc_max_code {
            self.rail_ticks = self.rail_ticks.saturating_add(n);
        } else {
            self.rail_ticks = 0;
        }
        if self.rail_ticks >= p.adc_rail_ticks {
            fault = true;
        }
        let current = adc_centered(code, p.adc_bits); // |current| ≤ 2^15
        let drive = inputs.drive_commanded;
        if !drive && current.saturating_abs() > p.current_off_counts {
            fault = true;
        }

        // ---- Encoders: wrapping deltas, plausibility against the fastest envelope speed.
        if inputs.output_counter > p.out_mask || inputs.motor_counter > p.motor_mask {
            fault = true;
        }
        let out_now = inputs.output_counter & p.out_mask;
        let motor_now = inputs.motor_counter & p.motor_mask;
        let measured = out_now << p.out_shift;
        if !self.started {
            self.started = true;
            self.prev_out = out_now;
            self.prev_motor = motor_now;
            self.prev_drive = !drive; // forces the drive-edge bookkeeping below
            self.obs = Observer {
                theta: measured,
                v: 0,
                d: 0,
            };
        }
        let d_out = counter_delta(self.prev_out, out_now, p.out_bits);
        let d_motor = counter_delta(self.prev_motor, motor_now, p.motor_bits);
        self.prev_out = out_now;
        self.prev_motor = motor_now;
        let out_ok = d_out.saturating_abs() <= p.out_jump_counts.times(n_i);
        let motor_ok = d_motor.saturating_abs() <= p.motor_jump_counts.times(n_i);
        if !out_ok || !motor_ok {
            fault = true;
        }
        // Stuck counter: while driving, one shaft travels beyond the lost-motion limit while the
        // other's counter stands still.
        if self.scene == Scene::Driving && drive && out_ok && motor_ok {
            self.still_out = if d_out == 0 {
                self.still_out.saturating_add(d_motor.unsigned_abs())
            } else {
                0
            };
            self.still_motor = if d_motor == 0 {
                self.still_motor.saturating_add(d_out.unsigned_abs())
            } else {
                0
            };
            if self.still_out > p.lost_motor_counts || self.still_motor > p.lost_out_counts {
                fault = true;
            }
        } else {
            self.still_out = 0;
            self.still_motor = 0;
        }

        // ---- Input speed (motor encoder ÷ ratio), filtered; held over a late step.
        if motor_ok && n == 1 {
            let raw = Q16::from_bits(p.input_speed.apply(d_motor));
            self.input_speed = lowpass(self.input_speed, raw, p.input_alpha);
        }

        // ---- Drive torque from the current, only when the drive is commanded.
        let stick = p.stick_speed.to_bits();
        let u = if drive {
            let backdriven =
                (current > 0 && self.obs.v < -stick) || (current < 0 && self.obs.v > stick);
            let k = if backdriven {
                p.drive_backdriven
            } else {
                p.drive_motoring
            };
            k.apply(current)
        } else {
            0
        };
        self.drive_torque = Q16::from_bits(u);

        // ---- Observer: predict n ticks with the model torque, correct once.
        let tau = self
            .obs
            .d
            .saturating_add(u)
            .saturating_sub(self.brake_model.to_bits());
        if n > u32::from(p.max_catchup) {
            self.obs.theta = measured; // too late to extrapolate: re-seat
            self.settle_ticks = 0;
        } else {
            for _ in 0..n {
                self.obs.predict(tau, &p.obs);
            }
        }
        self.settle_ticks = self.settle_ticks.saturating_add(n);
        let settled = self.settle_ticks >= p.settle_ticks;
        let innovation = measured.wrapping_sub(self.obs.theta) as i32; // shortest angle
        if settled && innovation.saturating_abs() > p.innovation_limit.times(n_i) {
            // The encoder disagrees with any plausible motion: do not let it kick the model.
            self.innovation_ticks = self.innovation_ticks.saturating_add(n);
            fault = true;
            if self.innovation_ticks >= p.persistence_ticks {
                self.obs.theta = measured;
                self.innovation_ticks = 0;
            }
        } else {
            self.innovation_ticks = 0;
            if out_ok {
                self.obs.correct(measured, &p.obs);
            }
        }
        if fault {
            self.flags.sensor_fault = true;
            self.since_fault = 0;
        } else {
            self.since_fault = self.since_fault.saturating_add(n);
        }
        let sensors_ok = self.since_fault >= p.settle_ticks;

        // ---- Derived signals.
        let w = Q16::from_bits(self.obs.v);
        let net = Q16::from_bits(self.obs.d).saturating_sub(self.brake_model); // J·ω̇ − u
        let s: i32 = if w > p.stick_speed {
            1
        } else if w < p.stick_speed.saturating_neg() {
            -1
        } else {
            0
        };
        let min_load = p.min_load;
        let load_sign: i32 = if self.load > min_load {
            1
        } else if self.load < min_load.saturating_neg() {
            -1
        } else {
            0
        };

        // ---- Drive edges.
        if drive != self.prev_drive {
            if drive {
                self.load_ref = self.load;
                self.load_ref_known = self.load_known;
            } else {
                self.envelope.arm(w);
                self.creep_valid = false;
                self.creep_counts = 0;
            }
            self.prev_drive = drive;
        }

        // ---- Scene recognition and the stick/slip state machine (hysteresis: stick band,
        // dwell, breakaway speed above the band — no chatter at zero speed).
        if drive && s != 0 {
            let lead = signed(s, w.saturating_sub(self.input_speed));
            if lead > p.overrun_band {
                self.overrunning = true;
            } else if lead <= Q16::ZERO {
                self.overrunning = false;
            }
        } else {
            self.overrunning = false;
        }
        if drive {
            self.locked = false;
            self.stick_ticks = 0;
        } else {
            if w.saturating_abs() < p.stick_speed {
                self.stick_ticks = self.stick_ticks.saturating_add(n);
            } else {
                self.stick_ticks = 0;
            }
            if !self.locked && self.stick_ticks >= p.lock_dwell_ticks {
                self.locked = true;
            } else if self.locked && w.saturating_abs() > p.breakaway_speed {
                self.locked = false;
            }
        }
        let engaged = if drive {
            self.overrunning
        } else if self.locked || s == 0 {
            // Drive off and (nearly) still: the only torque that can move the output is the
            // load, and moving with the load engages the ramps.
            true
        } else {
            load_sign == 0 || s == load_sign
        };
        let scene = if drive {
            if self.overrunning {
                Scene::Overrunning
            } else {
                Scene::Driving
            }
        } else if self.locked {
            Scene::Holding
        } else {
            Scene::FaultBraking
        };
        if scene != self.scene || engaged != self.engaged {
            self.phase_ticks = 0;
        } else {
            self.phase_ticks = self.phase_ticks.saturating_add(n);
        }
        self.scene = scene;
        self.engaged = engaged;
        let phase_settled = self.phase_ticks >= p.engage_settle_ticks;

        // ---- Load: learned where well conditioned, held elsewhere.
        let moving_ok = settled && sensors_ok && s != 0 && !self.locked && phase_settled;
        if moving_ok && !engaged {
            // Pack at its spring drag: M = N + s·T_drag (κ = 1).
            let inst = net.saturating_add(signed(s, p.spring_drag));
            self.load = lowpass(self.load, inst, p.load_alpha);
            self.load_learn_ticks = self.load_learn_ticks.saturating_add(n);
            if self.load_learn_ticks >= p.load_known_ticks {
                self.load_known = true;
            }
        } else if moving_ok && engaged && !self.load_known {
            // Unknown load, ramps engaged (power-on while moving): invert the engaged balance
            // N = M(1 − μ'·tanθ/r) − s·T_drag assuming the load drives the motion. Untrusted.
            let inst = net.saturating_add(signed(s, p.spring_drag));
            let inst = Q16::from_bits(p.inv_engaged_kappa.apply(inst.to_bits()));
            self.load = lowpass(self.load, inst, p.load_alpha);
        }
        let load_abs = self.load.saturating_abs();
        if !self.load_cache.valid || self.load_cache.load != self.load {
            let force = p
                .spring_force
                .saturating_add(Q16::from_bits(p.ramp_factor.apply(load_abs.to_bits())));
            self.load_cache = LoadCache {
                load: self.load,
                valid: true,
                force,
                capacity: Q16::from_bits(p.capacity_per_n.apply(force.to_bits())),
                recip: Q16::from_bits(recip_q16(load_abs.to_bits())),
                margin_floor: Q16::from_bits(p.min_margin.apply(load_abs.to_bits())),
            };
        }
        let engaged_force = self.load_cache.force;
        let engaged_capacity = self.load_cache.capacity;
        let measured_brake = self.load.saturating_sub(net);

        // ---- Pack health (sign-LMS, no division): measured over model torque while slipping.
        if moving_ok && engaged && self.load_known {
            let predicted = mul_sat(self.health, engaged_capacity);
            let step = if signed(s, measured_brake) > predicted {
                p.health_step
            } else {
                -p.health_step
            };
            self.health = Q16::from_bits(
                self.health
                    .to_bits()
                    .saturating_add(step)
                    .clamp(0, HEALTH_MAX),
            );
        }

        // ---- Flags.
        let available = mul_sat(self.health, engaged_capacity);
        let margin_low =
            self.load_known && load_abs >= min_load && available < self.load_cache.margin_floor;
        self.weak_ticks = if margin_low {
            self.weak_ticks.saturating_add(n)
        } else {
            0
        };
        if self.weak_ticks >= p.persistence_ticks {
            self.flags.brake_weak = true;
        }
        // Braking envelope: a nominal model started at the cut (speed decreasing at
        // (T_all − |M̂|)/J_s while engaged, (|M̂| + T_drag)/J_s while coasting against the load)
        // gives the expected speed and angle; the output may overrun them by the allowances.
        if scene == Scene::FaultBraking && !settled {
            self.envelope.arm(w);
        } else if scene == Scene::FaultBraking && out_ok {
            let env = &mut self.envelope;
            let decel = if engaged {
                engaged_capacity.saturating_sub(load_abs)
            } else {
                load_abs.saturating_add(p.spring_drag)
            }
            .max(Q16::ZERO);
            let dv = p.obs.v_a.apply(decel.to_bits()).times(n_i);
            env.expected_speed =
                Q16::from_bits(env.expected_speed.to_bits().saturating_sub(dv).max(0));
            env.expected_counts = env.expected_counts.saturating_add(
                p.speed_to_counts
                    .apply(env.expected_speed.to_bits())
                    .times(n_i),
            );
            env.counts = env.counts.saturating_add(d_out.saturating_abs());
            if env.expected_speed == Q16::ZERO {
                env.overdue_ticks = env.overdue_ticks.saturating_add(n);
            }
            // Both sides < 2^47: the comparison is exact in i64.
            let angle_limit = i64::from(p.braking_angle_factor.apply(env.expected_counts))
                + i64::from(p.braking_angle_allowance);
            if env.overdue_ticks > p.braking_grace_ticks
                || i64::from(env.counts) << 16 > angle_limit
            {
                self.flags.brake_weak = true;
            }
        }
        if !drive {
            if self.locked {
                self.creep_valid = true;
            }
            if self.creep_valid && out_ok {
                self.creep_counts = self.creep_counts.saturating_add(d_out);
                if self.creep_counts.saturating_abs() > p.creep_counts {
                    self.flags.brake_slip = true;
                }
            }
        }
        if scene == Scene::Driving && moving_ok {
            let implied = net.saturating_add(signed(s, p.spring_drag)); // load if drag nominal
            let over_model = implied.saturating_abs() > p.max_load;
            let excess = self.load_ref_known
                && signed(s, self.load_ref.saturating_sub(net))
                    > p.spring_drag.saturating_add(p.drag_allowance);
            self.drag_ticks = if over_model || excess {
                self.drag_ticks.saturating_add(n)
            } else {
                0
            };
            if self.drag_ticks >= p.persistence_ticks {
                self.flags.brake_drag = true;
            }
        } else {
            self.drag_ticks = 0;
        }

        // ---- Table 1 with the stick band: the braking torque of this tick, fed forward into
        // the next prediction (with the load only once it is known, so that learning it cannot
        // feed back through the pack capacity).
        let force = if engaged {
            engaged_force
        } else {
            p.spring_force
        };
        let stuck = self.locked || s == 0;
        let capacity = if engaged {
            engaged_capacity
        } else {
            p.spring_drag
        };
        // Table 1: stuck → the pack carries the demand up to its capacity; slipping → capacity
        // against the motion. The reported torque's demand is the load estimate; the model's
        // demand is the observer's own load state, so that a stuck model stays at rest whatever
        // the observer has absorbed (Karnopp: no chatter at the band's edge).
        let table1 = |demand: Q16, cap: Q16| {
            if stuck {
                // min/max rather than `clamp`, which asserts min ≤ max: a capacity driven
                // negative by a bad health or scale must bound, not panic.
                let cap = cap.max(Q16::ZERO);
                demand.min(cap).max(cap.saturating_neg())
            } else {
                signed(s, cap)
            }
        };
        let braking_torque = table1(self.load.saturating_add(self.drive_torque), capacity);
        let model_capacity = if engaged && !self.load_known {
            p.spring_drag
        } else {
            capacity
        };
        self.brake_model = table1(
            Q16::from_bits(self.obs.d).saturating_add(self.drive_torque),
            model_capacity,
        );

        // ---- Friction energy: slip power |T·ω| integrated (saturating; monotone).
        if !self.locked {
            let power = mul_sat(braking_torque, w).saturating_abs();
            let joules = p.energy_per_tick.apply(power.to_bits()).max(0) as u64 * u64::from(n);
            self.energy = U40F24::from_bits(self.energy.to_bits().saturating_add(joules));
        }

        let capacity_margin = if load_abs < min_load {
            MARGIN_MAX
        } else {
            mul_sat(available, self.load_cache.recip).min(MARGIN_MAX)
        };
        let brake = if self.locked {
            BrakeState::Locked
        } else if engaged {
            BrakeState::Slipping
        } else {
            BrakeState::Released
        };
        Estimate {
            tick: self.tick,
            scene,
            brake,
            pressing_force_n: force,
            braking_torque_nm: braking_torque,
            measured_braking_torque_nm: measured_brake,
            load_torque_nm: self.load,
            drive_torque_nm: self.drive_torque,
            output_speed_rad_s: w,
            input_speed_rad_s: self.input_speed,
            capacity_margin,
            pack_health: self.health,
            friction_energy_j: self.energy,
            trusted: self.load_known && settled && sensors_ok && n <= u32::from(p.max_catchup),
            flags: self.flags,
        }
    }
}
