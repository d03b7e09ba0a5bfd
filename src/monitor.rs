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
//! torque. The axial force balance is quasi-static in the twin's **physical reading** (the
//! ground truth; docs/monitor-design.md, "The physical reading, per scene"): the light connecting
//! shaft gives `T = T_o + u` and `F = F_s + k·(T_o − u)`, the pack slipping at `μ_d` while the
//! drive runs (`a = μ_d·c`, `k = tanθ/r`, `a·k` = 1.42 > 1) and self-locking at `μ_s` with the
//! drive off. Table 1 with a Karnopp stick band gives `T`.
//!
//! A three-state observer (angle, speed, torque) on the 14-bit output encoder tracks
//! `J_s·ω̇ − u` with the model's `T̂` fed forward, so scene changes are bumpless. The load `M̂`
//! is learned only while driving, where the pack torque follows from the current alone, and is
//! held with the drive off (braking lasts milliseconds, a locked shaft hides the load).
//!
//! | scene | when | model |
//! |---|---|---|
//! | `Driving` | drive on, drive carries the load | `F = F_s/(1 + a·k)` = 70 N, drag `a·F` = 1.98 N·m; learn `M̂`; drag and stuck-counter checks |
//! | `Overrunning` | drive on, load along the motion (current-implied, see `step`) | `T = y = g₁·v − g₀` from the drive torque `v`, `F = y/a`; learn `M̂` |
//! | `FaultBraking` | drive off, output moving | both socket faces clamp: `F = F_s + k·|T|`, `T` measured; time/angle envelope |
//! | `Holding` | drive off, stopped 1 ms or reversed by an impact | `T = M̂ − J_s·α` (α: the encoder's second difference over 2 × 1.6 ms, the impacts of the rattle); creep-span check |
//!
//! Each scene runs the cheapest model that meets the accuracy targets
//! (docs/results/cheapest-per-scene.md, `cargo xtask bench`; [`Monitor::scene_model`]): no
//! state in `Driving`, `Holding` and `Overrunning` (quasi-static), and in `FaultBraking` the
//! nominal braking model of the envelope, stepped by explicit Euler in I16F16 at
//! [`Config::braking_model_hz`] (1 kHz). The observer and the plausibility checks run every
//! tick in every scene: they are the measurement, paced by the sensors.
//!
//! # Formats
//! | quantity | format | range | resolution |
//! |---|---|---|---|
//! | torque, force, speed, current, margin, health | [`Q16`] = `I16F16` | ±32 768 | 1.53e-5 |
//! | output angle (observer) | `u32` word, wrapping | one turn | 2π/2³² = 1.46e-9 rad |
//! | constants | [`Scale<S>`] = `i32` mantissa · 2^-S (S in the type, per constant) | \|k\| < 2^(31−S) | ≥ 20 significant bits (26–28 at the defaults) |
//! | friction energy | `U40F24` | 1.1e12 J | 6e-8 J |
//! | counters, timers | `i32`/`u32`, saturating | — | 1 count / 1 tick |
//! | output position history (impacts) | `i16` counts mod 2^16, wrapping | differences over ≤ 62 ticks (< 2^15 counts) | 1 count (22.5 N·m of `J_s·α` at m = 16) |
//!
//! Every multiplication by a constant is a [`Scale<S>`] product, rounded to nearest; sums and
//! products of physical quantities saturate; counter and angle arithmetic wraps (the encoders
//! are modular). There is no division and no floating point in [`Monitor::step`]; every
//! constant is derived in [`Monitor::new`].
//!
//! # Cost
//! `cargo xtask run --json` (Cortex-M3 under QEMU, the twin's reverse_load trace, release, LTO):
//! mean 852.4, max 988 instructions per step (budget 1000; the worst step per scene is in the
//! command's `insns_per_step_max_by_scene`: 995 on the hold scene). The periodic parts (load
//! filter or pack health, drive checks, friction energy, load-cache refresh, synchronism window,
//! dead-current-reading check) each have their own tick, so that no step carries two of them
//! (`step`, "Cost"; docs/monitor-design.md, "Cost").
//!
//! # Power-on
//! A monitor may be powered on (or reset) into a running actuator. After
//! [`POWER_ON_SEED_TICKS`] on-time ticks the observer starts from the output's measured speed,
//! its torque balanced, instead of at rest, and the estimate settles in
//! `thresholds.power_on_settle_s` (30 ms) instead of `settle_time_s` (0.1 s): the drive checks
//! are armed ≈ 52 ms after power-on. A late tick or an implausible sample meanwhile leaves it to
//! settle from rest (docs/monitor-design.md, "Power-on into a running drive").
//!
//! # Missed ticks
//! The caller sets [`Inputs::ticks_elapsed`] to the number of ticks since the previous call
//! (1 when on time). A value above 1 latches `overrun`, advances the model by that many ticks and
//! scales the plausibility limits; above `max_catchup_ticks` the observer is re-seated on the
//! measurement and the estimate is untrusted until it settles again.

mod config;
mod dead_current;
mod drive_checks;
mod io;
mod observer;
mod scale;
mod slip_check;

pub use config::{
    Config, ConfigError, ObserverGains, Thresholds, DEFAULT_BRAKING_MODEL_HZ,
    DEFAULT_OBSERVER_BANDWIDTH_HZ, DEFAULT_TICK_HZ, POWER_ON_SEED_TICKS,
};
pub use io::{BrakeState, Estimate, Flags, Inputs, Scene, SceneModel, ESTIMATE_WORDS};
pub use scale::{recip_q16, sat_i32, Scale, ScaleError};

use crate::fx::{adc_centered, counter_delta, lowpass, Q16};
use config::{Params, SYNC_WINDOW_TICKS};
use dead_current::DeadCurrent;
use drive_checks::{DriveChecks, DriveTick};
use fixed::types::U40F24;
use observer::Observer;
use slip_check::SlipCheck;

/// Largest capacity margin reported (loads below `min_load_nm` report this).
pub const MARGIN_MAX: Q16 = Q16::from_bits(1000 << 16);

/// `a·b` for two Q16 values, rounded toward −∞ and **saturated** to Q16: the same bits as
/// `fx::mul_sat` (`fixed`'s `saturating_mul`, tested below), written out as one 32×32→64
/// multiply, a shift and a clamp (cheaper on Cortex-M than the generic version).
#[inline]
fn mul_q16(a: Q16, b: Q16) -> Q16 {
    // |a·b| ≤ 2^62: the product fits an i64; `>> 16` is the floor.
    Q16::from_bits(sat_i32(
        (i64::from(a.to_bits()) * i64::from(b.to_bits())) >> 16,
    ))
}

/// Length of the output-position history (ticks): more than twice the longest impact window
/// (31 ticks), a power of two so that the ring index is a mask.
const POSITION_HISTORY: usize = 64;

/// The tick (modulo 16) on which a changed load refreshes the load cache.
const REFRESH_PHASE: u32 = 3;

/// The tick (modulo [`SYNC_WINDOW_TICKS`]) on which the shafts' synchronism is measured: ≡ 3
/// mod 4 like the refresh, which it never meets.
const SYNC_PHASE: u32 = 7;

/// The tick (modulo 16) on which the dead-current-reading check samples a running drive: ≡ 3
/// mod 4 like the refresh and the synchronism window, which it never meets — the drive-on
/// ticks with no other periodic work.
const DEAD_CURRENT_PHASE: u32 = 15;

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
    /// Ticks for which the other driving reading (overrunning or not) has been wanted.
    reading_ticks: u32,
    /// The driving reading of this drive has been decided once (settled observer).
    reading_decided: bool,
    scene: Scene,
    stick_ticks: u32,
    phase_ticks: u32,
    settle_ticks: u32,
    since_fault: u32,
    /// The observer's seeding after power-on.
    seed: PowerOnSeed,
    rail_ticks: u32,
    /// Recent peak |ω̂| (Q16 bits), decaying at `impact_decay` per tick: the energy an impact
    /// in the lost motion can still return.
    impact_speed: i32,
    /// Last non-zero direction of the output (−1, 0, 1).
    last_dir: i32,
    innovation_ticks: u32,
    envelope: BrakingEnvelope,
    /// Output position (counts, the encoder's deltas accumulated, wrapping) of the last
    /// [`POSITION_HISTORY`] ticks, newest at `position_head`: the impact estimate's history.
    positions: [i16; POSITION_HISTORY],
    position_head: usize,
    /// Consecutive on-time ticks with a plausible output encoder in the history.
    position_ticks: u32,
    /// Output and motor counters at the last synchronism sample.
    sync_out: u32,
    sync_motor: u32,
    creep_valid: bool,
    creep_counts: i32,
    creep_min: i32,
    creep_max: i32,
    /// Both shafts carried the same way while the brake holds.
    slip_check: SlipCheck,
    still_out: u32,
    still_motor: u32,
    weak_ticks: u32,
    /// The drag and step checks of a running drive.
    drive_checks: DriveChecks,
    /// The dead-current-reading check of a running drive.
    dead_current: DeadCurrent,
    /// Ticks of steady driving (the output moving with the input shaft), counted in steps of
    /// `SYNC_WINDOW_TICKS` on the synchronism tick: the load learning's and the drive checks'
    /// settling.
    drive_ticks: u32,
    health: Q16,
    energy: U40F24,
    /// Ticks since the friction energy was last sampled.
    energy_ticks: u32,
    flags: Flags,
    /// Quantities that depend only on the load estimate, recomputed when it changes.
    load_cache: LoadCache,
}

/// Engaged pressing force, capacity and `1/|M̂|` for one value of the load estimate.
#[derive(Clone, Copy, Debug)]
struct LoadCache {
    load: Q16,
    valid: bool,
    /// Static capacity `μ_s·c·(F_s + k·|M̂|)` of the pack clamped by the load (drive off).
    capacity: Q16,
    recip: Q16,
    /// `min_capacity_margin · |M̂|` (N·m).
    margin_floor: Q16,
    /// The pack health the two below were formed with.
    health: Q16,
    /// Capacity scaled by the health, `health · capacity` (N·m).
    available: Q16,
    /// `available / |M̂|`, at most [`MARGIN_MAX`].
    margin: Q16,
}

impl LoadCache {
    /// Forms `available` and `margin` for `health` (two products, only when the health or
    /// the load changed: most ticks reuse them).
    #[inline]
    fn with_health(&mut self, health: Q16) {
        self.health = health;
        self.available = mul_q16(health, self.capacity);
        self.margin = mul_q16(self.available, self.recip).min(MARGIN_MAX);
    }
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
    /// Ticks since the nominal model's last step.
    model_ticks: u32,
    /// Travel per tick at the cut speed (Q16 counts).
    free_tick: i32,
    /// Travel per usual model step at the cut speed (Q16 counts).
    free_step: i32,
    /// Travel at the cut speed, undecelerated, since the cut (Q16 counts, saturating).
    free_counts: i32,
}

impl BrakingEnvelope {
    /// Starts the envelope from the present output speed (`speed_to_counts`: Q16 rad/s → Q16
    /// counts per tick; `model_ticks`: ticks per usual step of the nominal model).
    fn arm(&mut self, speed: Q16, speed_to_counts: &Scale<28>, model_ticks: u32) {
        let speed = speed.saturating_abs();
        let free_tick = speed_to_counts.apply(speed.to_bits());
        *self = BrakingEnvelope {
            expected_speed: speed,
            free_tick,
            free_step: free_tick.times(i32::try_from(model_ticks).unwrap_or(i32::MAX)),
            ..BrakingEnvelope::default()
        };
    }
}

/// The observer's seeding after power-on (docs/monitor-design.md, "Power-on into a running
/// drive"): after [`POWER_ON_SEED_TICKS`] on-time, plausible ticks the observer starts from the
/// output's measured speed with the torque balanced, instead of at rest.
#[derive(Clone, Copy, Debug, Default)]
struct PowerOnSeed {
    /// Ticks left (0: done, or given up on a late or implausible tick).
    left: u32,
    /// Output counter at power-on (masked).
    out: u32,
}

impl PowerOnSeed {
    /// One tick while `left > 0` (out of line: the other ticks carry only that test). Returns
    /// the seeded observer when the last seeding tick has passed: the angle read now, the
    /// speed from the travel since power-on, and `d̂ = T̂ − u` (the previous tick's drive and
    /// model torques) so that the model does not accelerate. A late tick, a sensor fault
    /// (`give_up`) or an output step from `prev_out` beyond the plausible speed ends the
    /// seeding: the observer then settles from rest, the usual way.
    #[cold]
    #[inline(never)]
    fn tick(
        &mut self,
        give_up: bool,
        prev_out: u32,
        out_now: u32,
        drive_torque: i32,
        brake_model: Q16,
        p: &Params,
    ) -> Option<Observer> {
        let step = counter_delta(prev_out, out_now, p.out_bits);
        if give_up || step.saturating_abs() > p.out_jump_counts {
            self.left = 0;
            return None;
        }
        self.left = self.left.saturating_sub(1);
        (self.left == 0).then(|| Observer {
            theta: out_now << p.out_shift,
            v: p.seed_speed
                .apply(counter_delta(self.out, out_now, p.out_bits)),
            d: brake_model.to_bits().saturating_sub(drive_torque),
        })
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
            reading_ticks: 0,
            reading_decided: false,
            scene: Scene::FaultBraking,
            stick_ticks: 0,
            phase_ticks: 0,
            settle_ticks: 0,
            since_fault: 0,
            seed: PowerOnSeed::default(),
            rail_ticks: 0,
            impact_speed: 0,
            last_dir: 0,
            innovation_ticks: 0,
            envelope: BrakingEnvelope::default(),
            positions: [0; POSITION_HISTORY],
            position_head: 0,
            position_ticks: 0,
            sync_out: 0,
            sync_motor: 0,
            creep_valid: false,
            creep_counts: 0,
            creep_min: 0,
            creep_max: 0,
            slip_check: SlipCheck::default(),
            still_out: 0,
            still_motor: 0,
            weak_ticks: 0,
            drive_checks: DriveChecks::default(),
            dead_current: DeadCurrent::default(),
            drive_ticks: 0,
            health: Q16::ONE,
            energy: U40F24::ZERO,
            energy_ticks: 0,
            flags: Flags::default(),
            load_cache: LoadCache {
                load: Q16::ZERO,
                valid: false,
                capacity: Q16::ZERO,
                recip: Q16::ZERO,
                margin_floor: Q16::ZERO,
                health: Q16::ONE,
                available: Q16::ZERO,
                margin: Q16::ZERO,
            },
        })
    }

    /// The model this monitor runs in `scene` (issue 6: the cheapest per scene,
    /// docs/results/cheapest-per-scene.md).
    pub fn scene_model(&self, scene: Scene) -> SceneModel {
        match scene {
            Scene::Holding | Scene::Driving => SceneModel::QuasiStatic,
            Scene::Overrunning => SceneModel::Equilibrium,
            Scene::FaultBraking => SceneModel::ReducedI16F16Euler {
                rate_hz: self.p.braking_model_hz,
            },
        }
    }

    /// `J_s·α`, the output's inertia torque, from the second difference of its position over
    /// two windows of `m` ticks (`θ(t) − 2θ(t−m) + θ(t−2m)`, a triangular average of the
    /// acceleration over the last `2m` ticks); zero until the history holds `2m` on-time ticks.
    /// One count in the second difference is 22 N·m at the defaults (m = 16).
    fn impact_torque(&self) -> Q16 {
        let m = usize::from(self.p.impact_window);
        if self.position_ticks < 2 * u32::from(self.p.impact_window) {
            return Q16::ZERO;
        }
        let at = |back: usize| {
            self.positions
                .get((self.position_head + POSITION_HISTORY - back) % POSITION_HISTORY)
                .copied()
                .unwrap_or(0)
        };
        // Wrapping (mod 2^16): the true second difference over 2m ≤ 62 ticks is far below 2^15.
        let second = at(0)
            .wrapping_sub(at(m).wrapping_mul(2))
            .wrapping_add(at(2 * m));
        Q16::from_bits(self.p.impact_torque.apply(i32::from(second)))
    }

    /// The latched flags.
    pub fn flags(&self) -> Flags {
        self.flags
    }

    /// Clears the latched flags (a condition still present raises its flag again).
    pub fn reset_flags(&mut self) {
        self.flags = Flags::default();
        self.weak_ticks = 0;
        self.drive_checks.reset();
        self.envelope = BrakingEnvelope::default();
        // Creep is measured afresh from here (the span, not its validity: a reset while
        // holding keeps the slip check armed).
        self.creep_counts = 0;
        self.creep_min = 0;
        self.creep_max = 0;
        self.slip_check.restart(self.prev_out, self.prev_motor);
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
        let drive = inputs.drive_commanded;
        // A drive at its current limit reads at the rail (the default ADC range is the drive's
        // limit) while the motor moves; a rail with the motor encoder standing still is the ADC.
        let motor_still = (inputs.motor_counter & p.motor_mask) == self.prev_motor;
        if (code == 0 || code >= p.adc_max_code) && (!drive || motor_still || !self.started) {
            self.rail_ticks = self.rail_ticks.saturating_add(n);
        } else {
            self.rail_ticks = 0;
        }
        if self.rail_ticks >= p.adc_rail_ticks {
            fault = true;
        }
        let current = adc_centered(code, p.adc_bits); // |current| ≤ 2^15
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
        // ---- Power-on seeding (out of line: the other ticks carry only this test; from the
        // tick after power-on, so that the first tick does not carry it either).
        if self.seed.left > 0 {
            let (u, brake) = (self.drive_torque.to_bits(), self.brake_model);
            if let Some(obs) = self
                .seed
                .tick(n != 1 || fault, self.prev_out, out_now, u, brake, p)
            {
                self.obs = obs;
                let head = p.power_on_head_start;
                self.settle_ticks = self.settle_ticks.saturating_add(head);
                self.since_fault = self.since_fault.saturating_add(head);
                if drive {
                    self.drive_ticks = self.drive_ticks.saturating_add(head);
                }
            }
        }
        if !self.started {
            self.started = true;
            self.prev_out = out_now;
            self.prev_motor = motor_now;
            self.sync_out = out_now;
            self.sync_motor = motor_now;
            self.prev_drive = !drive; // forces the drive-edge bookkeeping below
            self.obs = Observer {
                theta: measured,
                v: 0,
                d: 0,
            };
            self.seed = PowerOnSeed {
                left: POWER_ON_SEED_TICKS,
                out: out_now,
            };
        }
        let d_out = counter_delta(self.prev_out, out_now, p.out_bits);
        let d_motor = counter_delta(self.prev_motor, motor_now, p.motor_bits);
        self.prev_out = out_now;
        self.prev_motor = motor_now;
        let out_ok = d_out.saturating_abs() <= p.out_jump_counts.times(n_i);
        let motor_ok = d_motor.saturating_abs() <= p.motor_jump_counts.times(n_i);
        // Position history with the drive off (the only place it is used), one entry per call.
        // Counts modulo 2^16, wrapping on purpose: only differences over ≤ 63 ticks are used,
        // far below 2^15 counts. A late step, an implausible count or the drive leave a hole:
        // the history restarts.
        if drive {
            self.position_ticks = 0;
        } else {
            let newest = self.positions.get(self.position_head).copied().unwrap_or(0);
            self.position_head = (self.position_head + 1) % POSITION_HISTORY;
            if let Some(slot) = self.positions.get_mut(self.position_head) {
                *slot = newest.wrapping_add(d_out as i16); // |d_out| ≤ out_jump when used
            }
            self.position_ticks = if n == 1 && out_ok {
                self.position_ticks.saturating_add(1)
            } else {
                0
            };
        }
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
        // Shortest signed angle (wrapping on purpose: the encoder is modular).
        let innovation = measured.wrapping_sub(self.obs.theta) as i32;
        // Plausible prediction error: one tick at the fastest speed, plus an impact in the lost
        // motion reversing the recent peak speed within `impact_time_s` (the twin's output
        // stops on impact within 2–10 ms of a cut and rattles at up to ±8 rad/s; with the drive
        // on, overrunning chatter reverses it at 7 rad/s after 570 N·m impacts).
        // The peak decays at IMPACT_DECAY_RAD_S2 (saturating: it never goes below 0 nor
        // wraps). The widened limit is only formed when the base limit is exceeded (cheaper on
        // every other tick).
        self.impact_speed = self
            .impact_speed
            .saturating_sub(p.impact_decay.times(n_i))
            .max(self.obs.v.saturating_abs());
        let base_limit = p.innovation_limit.times(n_i);
        let implausible = settled
            && innovation.saturating_abs() > base_limit
            && innovation.saturating_abs()
                > p.impact_words
                    .apply(self.impact_speed)
                    .saturating_add(base_limit);
        if implausible {
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
            self.slip_check.disarm(); // an implausible step is no travel
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
        let drive_edge = drive != self.prev_drive;
        if drive_edge {
            if drive {
                self.load_ref = self.load;
                self.load_ref_known = self.load_known;
            } else {
                self.envelope
                    .arm(w, &p.speed_to_counts, p.braking_model_ticks);
                self.creep_valid = false;
                self.creep_counts = 0;
            }
            self.slip_check.disarm();
            self.dead_current.disarm(out_now);
            self.drive_ticks = 0;
            self.prev_drive = drive;
        }

        // ---- Scene recognition and the stick/slip state machine.
        // Drive on (physical reading, quasi-static, pack slipping at μ_d, a = μ_d·c, k = tanθ/r,
        // a·k > 1): with the drive torque `v` along the motion, either the drive carries a
        // load against the motion (pack at the drive drag, `v = |M| + T_drive`), or the load
        // runs along it (overrunning) and the pack torque is `y = g₁·v − g₀` with the load
        // `y − v` along the motion. The current tells them apart only when the overrunning
        // reading's load lies outside the envelope; otherwise the learned load's sign decides,
        // and with no load known yet the overrunning reading is taken (docs: "ambiguity").
        let v = signed(s, self.drive_torque);
        // y is needed while overrunning, or to test for it unless a known load is against the
        // motion (then the reading is settled and the product is skipped: cheaper).
        // Saturating: a clipped torque is the safe answer.
        let load_along = signed(s, self.load) > min_load;
        let overrun_torque =
            if drive && s != 0 && (self.overrunning || !self.load_known || load_along) {
                Q16::from_bits(p.overrun_gain.apply(v.to_bits()))
                    .saturating_sub(p.overrun_offset)
                    .max(Q16::ZERO)
            } else {
                Q16::ZERO // not used: drive off, output still, or a known load against the motion
            };
        if drive && s != 0 {
            let implied = overrun_torque.saturating_sub(v);
            // Before the observer has settled (power-on) ω̂ and the drive torque are not in the
            // quasi-static balance the test needs: the cheaper drive-carries reading is kept.
            let possible =
                settled && v > p.drive_drag && implied > min_load && implied <= p.max_load;
            let wanted = possible && (!self.load_known || load_along);
            // Debounce: after the first settled decision of a drive, the other reading must
            // hold for the engage settling time before the scene switches, so that a transient
            // (crossing the lost motion) or noise at the envelope's edge cannot toggle the scene
            // and restart the load learning. Nor while the step check is counting towards a
            // verdict: a drag or a lost current gain can itself make the reading held
            // impossible, and the change would re-seed the check past the step.
            if settled && !self.reading_decided {
                self.reading_decided = true;
                self.overrunning = wanted;
                self.reading_ticks = 0;
            } else if wanted == self.overrunning {
                self.reading_ticks = 0;
            } else {
                self.reading_ticks = self.reading_ticks.saturating_add(n);
                if self.reading_ticks >= p.engage_settle_ticks
                    && !self.drive_checks.counting_step(p)
                {
                    self.overrunning = wanted;
                    self.reading_ticks = 0;
                }
            }
        } else {
            self.overrunning = false;
            self.reading_ticks = 0;
            self.reading_decided = false;
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
            // The brake stops the output: it dwells in the stick band, or an impact in the
            // lost motion reverses it within a tick or two.
            let reversed = s != 0 && s == -self.last_dir;
            if !self.locked && (self.stick_ticks >= p.lock_dwell_ticks || reversed) {
                // The output stopped under the brake: the pack holds. From here on it may only
                // move inside the lost motion (backlash, contact compliance, ball play).
                self.locked = true;
                if !self.creep_valid {
                    self.creep_valid = true;
                    self.creep_counts = 0;
                    self.creep_min = 0;
                    self.creep_max = 0;
                    self.slip_check.arm(self.prev_out, self.prev_motor);
                }
            }
        }
        if s != 0 {
            self.last_dir = s;
        }
        // Drive off: both faces of the V sockets push the pack, so the ramps clamp it whichever
        // way the output turns (the physical reading); drive on: only when overrunning.
        let engaged = !drive || self.overrunning;
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
        // A change between the two driving readings changes how the motion is read, not the
        // motion: the observer's model takes it over bumplessly (below).
        let reading_switch = drive
            && matches!(self.scene, Scene::Driving | Scene::Overrunning)
            && scene != self.scene;
        if scene != self.scene || engaged != self.engaged {
            self.phase_ticks = 0;
        } else {
            self.phase_ticks = self.phase_ticks.saturating_add(n);
        }
        self.scene = scene;
        self.engaged = engaged;
        let phase_settled = self.phase_ticks >= p.engage_settle_ticks;

        // ---- Load: learned where well conditioned, held elsewhere.
        // (No learning while a change of the driving reading is pending: the pack torque it
        // would use is the one being left.)
        // The drive checks (below) keep their sensor half running while a change of reading is
        // pending: a current reading that loses its gain can make the other reading look
        // possible, and waiting for the switch would re-seed their history past the step (test
        // `current_reading_losing_most_of_its_gain_is_flagged_before_the_reading_can_change`).
        let checks_ok = settled && sensors_ok && s != 0 && !self.locked && phase_settled;
        let moving_ok = checks_ok && self.reading_ticks == 0;
        // Cost: the periodic work is spread over the ticks so that no step carries two of the
        // expensive parts. Tick modulo 4 — 0: the load filter (drive on) or the pack-health
        // update (drive off); 1: the drive checks (drive on); 2: the friction energy; 3: with
        // the drive on, by tick modulo 16, the load cache's refresh (`REFRESH_PHASE`), the
        // synchronism window (`SYNC_PHASE`) and the dead-current-reading check
        // (`DEAD_CURRENT_PHASE`). The braking
        // model's step (drive off, every `braking_model_ticks`) waits for an odd tick. Each
        // periodic part counts the ticks it covers; time constants and persistence are those
        // of the tick rate.
        let even_tick = self.tick & 1 == 0;
        // While driving, the load is learned only once the output has moved with the input
        // shaft for the engage settling time, and the drive checks run (below) only after the
        // observer's settling time of it (`drive_ticks`, below): an output that runs away from
        // the input, or bounces in its lost motion (overrunning chatter), is where neither the
        // drive torque nor the pack torque is quasi-static. (Learning keeps the acceleration of
        // a drive's start, which tells the two driving readings apart.)
        let steady_drive = self.drive_ticks >= p.settle_ticks;
        if moving_ok && drive && self.drive_ticks >= p.engage_settle_ticks && self.tick & 3 == 0 {
            // The pack torque is known while the drive runs: the drive drag when the drive
            // carries the load, the overrunning equilibrium when the load runs along:
            // M = N + s·T_pack.
            let pack = if engaged {
                overrun_torque
            } else {
                p.drive_drag
            };
            let inst = net.saturating_add(signed(s, pack));
            self.load = lowpass(self.load, inst, p.load_alpha);
            self.load_learn_ticks = self.load_learn_ticks.saturating_add(n.saturating_mul(4));
            if self.load_learn_ticks >= p.load_known_ticks {
                if !self.load_known && !self.load_ref_known {
                    // First known load of a drive that started without one (power-on while
                    // driving): it is the drag check's reference from here on.
                    self.load_ref = self.load;
                    self.load_ref_known = true;
                }
                self.load_known = true;
            }
        }
        let load_abs = self.load.saturating_abs();
        // The cache follows a changing load (learned only while driving) once in 16 ticks (1.6 ms
        // at 10 kHz; the flags that use it persist 10 ms), never on the tick of a drive edge
        // (which has its own bookkeeping): its reciprocal and products are the most expensive
        // lines of a step. With the drive off the load is held, and so is the cache: it keeps
        // the load of at most 16 ticks before the cut (the held load differs from it by at
        // most the filter's movement over 1.6 ms, 9.5 % of its last step).
        if !self.load_cache.valid
            || (self.load_cache.load != self.load
                && drive
                && self.tick & 15 == REFRESH_PHASE
                && !drive_edge)
        {
            let force = p
                .spring_force
                .saturating_add(Q16::from_bits(p.ramp_factor.apply(load_abs.to_bits())));
            self.load_cache = LoadCache {
                load: self.load,
                valid: true,
                capacity: Q16::from_bits(p.capacity_per_n.apply(force.to_bits())),
                recip: Q16::from_bits(recip_q16(load_abs.to_bits())),
                margin_floor: Q16::from_bits(p.min_margin.apply(load_abs.to_bits())),
                health: self.health,
                available: Q16::ZERO,
                margin: Q16::ZERO,
            };
            self.load_cache.with_health(self.health);
        }
        let engaged_capacity = self.load_cache.capacity;
        let measured_brake = self.load.saturating_sub(net);

        // ---- Pack health (sign-LMS, no division): measured over model torque while slipping.
        // On ticks ≡ 0 mod 4 (the step covers four; see "Cost" above).
        if moving_ok && !drive && self.load_known && self.tick & 3 == 0 {
            let predicted = mul_q16(self.health, engaged_capacity);
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
        if self.load_cache.health != self.health {
            self.load_cache.with_health(self.health);
        }
        let available = self.load_cache.available;
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
        // (T_all − |M̂|)/J_s moving with the load, (T_all + |M̂|)/J_s against it: both socket
        // faces clamp) gives the expected speed and angle; the output may overrun them by the
        // allowances. (The twin's healthy pack stops on impact, far inside this envelope.)
        if scene == Scene::FaultBraking && !settled {
            self.envelope
                .arm(w, &p.speed_to_counts, p.braking_model_ticks);
        } else if scene == Scene::FaultBraking && out_ok {
            let env = &mut self.envelope;
            // The nominal braking model runs at its own rate (`braking_model_hz`, the
            // cheapest-per-scene table's choice): one explicit-Euler step over the ticks it
            // covers, travel with the old speed, then the speed.
            env.model_ticks = env.model_ticks.saturating_add(n);
            env.counts = env.counts.saturating_add(d_out.saturating_abs());
            // On odd ticks only (the pack-health update takes the even ones).
            if env.model_ticks >= p.braking_model_ticks && !even_tick {
                let decel = if s == load_sign {
                    engaged_capacity.saturating_sub(load_abs)
                } else {
                    engaged_capacity.saturating_add(load_abs)
                }
                .max(Q16::ZERO);
                // The usual step covers exactly `braking_model_ticks` ticks: its constants are
                // precomputed; a longer one (a late tick, or the first step after an arm on an
                // even tick) multiplies the per-tick ones.
                let (travel, dv, free) = if env.model_ticks == p.braking_model_ticks {
                    (
                        p.braking_travel.apply(env.expected_speed.to_bits()),
                        p.braking_speed.apply(decel.to_bits()),
                        env.free_step,
                    )
                } else {
                    // ≤ 1000 + 256 ticks (reset at each model step): fits an i32.
                    let k = i32::try_from(env.model_ticks).unwrap_or(i32::MAX);
                    (
                        p.speed_to_counts
                            .apply(env.expected_speed.to_bits())
                            .times(k),
                        p.obs.v_a.apply(decel.to_bits()).times(k),
                        env.free_tick.times(k),
                    )
                };
                env.model_ticks = 0;
                env.expected_counts = env.expected_counts.saturating_add(travel);
                env.expected_speed =
                    Q16::from_bits(env.expected_speed.to_bits().saturating_sub(dv).max(0));
                // A pack that does not brake: the output has gone further than it would at
                // its cut speed (a working pack decelerates it from the first millisecond).
                // Both sides < 2^48: exact in i64.
                env.free_counts = env.free_counts.saturating_add(free);
                if i64::from(env.counts) << 16
                    > i64::from(env.free_counts) + i64::from(p.undecelerated_allowance)
                {
                    self.flags.brake_weak = true;
                }
            }
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
        // Creep: the span of the output's travel since the brake first held. Rattling inside
        // the lost motion keeps it bounded; a slipping pack (steady or staircase) grows it.
        if !drive && self.creep_valid && out_ok {
            self.creep_counts = self.creep_counts.saturating_add(d_out);
            self.creep_min = self.creep_min.min(self.creep_counts);
            self.creep_max = self.creep_max.max(self.creep_counts);
            if self.creep_max.saturating_sub(self.creep_min) > p.creep_counts {
                self.flags.brake_slip = true;
                self.locked = false;
                self.creep_valid = false;
            }
        }
        // Common slip: both shafts carried the same way (slip_check.rs), on ticks ≡ 1 mod 4
        // with the drive off (the drive checks take them with the drive on). Armed when the
        // brake first holds, disarmed by the drive and by an implausible encoder step.
        if !drive
            && self.tick & 3 == 1
            && self
                .slip_check
                .slipping(&p.slip, self.prev_out, self.prev_motor)
        {
            self.flags.brake_slip = true;
            self.locked = false;
            self.creep_valid = false;
            self.slip_check.disarm();
        }
        // Ticks of steady driving: the output moving with the input shaft (within
        // `sync_speed_band`), the drive checks' and the load learning's settling at the
        // drive's start (a change of reading does not restart them: it is bumpless, below).
        // An output that runs away from the input — crossing its lost motion at a start, or
        // bouncing in it (overrunning chatter: the ramps engage, the pack clamps, the output
        // rebounds) — restarts them.
        // Measured on the counters, not on the observer (whose speed leaves the measurement
        // for a while when the model's torque steps): the travel of both shafts over the last
        // `SYNC_WINDOW_TICKS`, on one tick in 16 that carries no other periodic work.
        // `drive_ticks` is kept on that tick too (in steps of the window; the drive edge zeroes
        // it), so that the other ticks carry none of this.
        if drive && self.tick & (SYNC_WINDOW_TICKS - 1) == SYNC_PHASE {
            let d_o = counter_delta(self.sync_out, out_now, p.out_bits);
            let d_m = counter_delta(self.sync_motor, motor_now, p.motor_bits);
            self.sync_out = out_now;
            self.sync_motor = motor_now;
            let synchronous = p
                .motor_to_out
                .apply(d_m)
                .saturating_sub(d_o)
                .saturating_abs()
                <= p.sync_band_counts;
            self.drive_ticks = if s != 0 && synchronous {
                self.drive_ticks
                    .saturating_add(n.saturating_mul(SYNC_WINDOW_TICKS))
            } else {
                0
            };
        }
        // A dead current reading: the output turns with the drive on, the pack has held it
        // lately, and the drive torque averages next to nothing over a block of windows
        // (dead_current.rs, out of line on a tick of its own), unless the load is known to be
        // below the spring drag (a pack whose spring broke could then be driven by almost
        // nothing). The step check cannot see it where its history never forms (overrunning
        // chatter, where the load is never learned); once called, no `brake_drag` comes from
        // this reading.
        if drive
            && self.tick & (SYNC_WINDOW_TICKS - 1) == DEAD_CURRENT_PHASE
            && self.dead_current.window(self.drive_torque, out_now, p)
            && settled
            && sensors_ok
            && !(self.load_known && self.load.saturating_abs() < p.drive_drag)
        {
            self.flags.sensor_fault = true;
            self.drive_checks.suspect_current();
        }
        if self.tick & 3 == 1 {
            if drive && checks_ok && steady_drive {
                // Out of line: the drive-off ticks (braking, holding: the worst case) do not
                // carry these checks' registers.
                self.drive_checks.run(
                    &mut self.flags,
                    p,
                    &DriveTick {
                        s,
                        net,
                        drive: v,
                        pack: if engaged {
                            overrun_torque
                        } else {
                            p.drive_drag
                        },
                        engaged,
                        carrying: scene == Scene::Driving,
                        load_ref: self.load_ref_known.then_some(self.load_ref),
                        pending: self.reading_ticks != 0,
                        ticks: n,
                    },
                );
            } else {
                self.drive_checks.disarm();
            }
        }

        // ---- Table 1 with the stick band: the braking torque of this tick, fed forward into
        // the next prediction (with the load only once it is known, so that learning it cannot
        // feed back through the pack capacity).
        let stuck = self.locked || s == 0;
        let capacity = if engaged {
            engaged_capacity
        } else {
            p.drive_drag
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
        // Reported pack torque and pressing force (physical reading, quasi-static):
        // - drive carrying the load: the drive drag `T_drive = a·F_drive` at the unloaded
        //   force `F_drive = F_s/(1 + a·k)`;
        // - overrunning: the equilibrium torque `y` from the drive torque alone (no learned
        //   load needed), and the force of the light connecting shaft's axial balance
        //   `F = F_s + k·(T_o − v)` with `T_o = y − v` through the output ramps;
        // - drive off: both faces of the V sockets clamp, `F = F_s + k·|T|` with `T` the held
        //   load (stuck) or the measured braking torque (moving).
        let (force, braking_torque) = if drive && !engaged {
            (
                p.drive_force,
                table1(self.load.saturating_add(self.drive_torque), capacity),
            )
        } else if drive {
            let excess = overrun_torque.saturating_sub(v).saturating_sub(v); // T_o − v
            (
                p.spring_force
                    .saturating_add(Q16::from_bits(p.ramp_factor.apply(excess.to_bits())))
                    .max(Q16::ZERO),
                signed(s, overrun_torque),
            )
        } else {
            let t = if self.locked {
                // Holding: the pack carries the load minus the output's inertia torque, which
                // is zero at rest and large at the impacts of the rattle in the lost motion
                // (tens of kN of pressing force in the twin for a few ms).
                self.load.saturating_sub(self.impact_torque())
            } else if stuck {
                self.load
            } else {
                measured_brake
            };
            (
                p.spring_force.saturating_add(Q16::from_bits(
                    p.ramp_factor.apply(t.saturating_abs().to_bits()),
                )),
                t,
            )
        };
        // Table 1: the pack cannot carry more than its capacity at that force. Inside the
        // envelope this never binds (driving: `μ_d·c·F < μ_s·c·F`; drive off: a self-locking
        // pack, μ_s·c·k = 2.49 at Table 2, carries `T` at `F_s + k·|T|`); it bounds the
        // estimate when the force saturates (hostile inputs) or the pack does not self-lock.
        // (Driving with the drive carrying the load needs none: the drag `μ_d·c·F_drive` is a
        // constant below `μ_s·c·F_drive`; skipping it keeps the driving step cheaper.)
        let braking_torque = if drive && !engaged {
            braking_torque
        } else {
            let cap_now = Q16::from_bits(p.capacity_per_n.apply(force.to_bits())).max(Q16::ZERO);
            braking_torque.min(cap_now).max(cap_now.saturating_neg())
        };
        let model_capacity = if drive && engaged {
            overrun_torque
        } else {
            capacity
        };
        let brake_model = table1(
            Q16::from_bits(self.obs.d).saturating_add(self.drive_torque),
            model_capacity,
        );
        if reading_switch {
            // Bumpless transfer: the modelled pack torque steps (drive drag ↔ overrunning
            // equilibrium) and the disturbance state takes the same step, so that the net
            // torque `d̂ + u − T̂` the observer predicts with is continuous (without it the
            // observer rang for ≈ 50 ms after every change of reading). Saturating.
            self.obs.d = self.obs.d.saturating_add(
                brake_model
                    .to_bits()
                    .saturating_sub(self.brake_model.to_bits()),
            );
        }
        self.brake_model = brake_model;

        // ---- Friction energy: slip power |T·ω| integrated (saturating; monotone), sampled on
        // ticks ≡ 2 mod 4 over the ticks since the last sample (2.5 kHz: a heat estimate; the
        // other ticks carry the other periodic work).
        self.energy_ticks = self.energy_ticks.saturating_add(n);
        if self.tick & 3 == 2 {
            if !self.locked {
                let power = mul_q16(braking_torque, w).saturating_abs();
                let joules = p.energy_per_tick.apply(power.to_bits()).max(0) as u64
                    * u64::from(self.energy_ticks);
                self.energy = U40F24::from_bits(self.energy.to_bits().saturating_add(joules));
            }
            self.energy_ticks = 0;
        }

        let capacity_margin = if load_abs < min_load {
            MARGIN_MAX
        } else {
            self.load_cache.margin
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fx::mul_sat;

    #[test]
    fn holding_torque_carries_the_inertia_torque_of_an_impact() {
        extern crate std;
        let mut monitor = Monitor::new(Config::default()).unwrap_or_else(|_| unreachable!());
        let rad_per_count = core::f64::consts::TAU / 16_384.0;
        let count = |theta: f64| (theta / rad_per_count).floor().rem_euclid(16_384.0) as u32;
        // At rest, drive off: the brake holds (power-on: no load known, M̂ = 0).
        let mut e = monitor.step(&Inputs::new(2048, 0, count(0.0), false));
        for _ in 0..2000 {
            e = monitor.step(&Inputs::new(2048, 0, count(0.0), false));
        }
        assert_eq!(e.brake, BrakeState::Locked);
        assert_eq!(e.braking_torque_nm, e.load_torque_nm);
        // An impact: 2000 rad/s² for 5 ms inside the lost motion (0.025 rad).
        let alpha = 2000.0;
        let mut worst: f64 = 0.0;
        for k in 1..=50 {
            let t = f64::from(k) * 1e-4;
            e = monitor.step(&Inputs::new(2048, 0, count(0.5 * alpha * t * t), false));
            if k > 2 * 16 {
                assert_eq!(e.brake, BrakeState::Locked);
                let expected = e.load_torque_nm.to_num::<f64>() - 0.15 * alpha;
                worst = worst.max((e.braking_torque_nm.to_num::<f64>() - expected).abs());
            }
        }
        std::println!("impact torque error {worst:.1} N·m of {:.0}", 0.15 * alpha);
        // One count of the second difference is 22.5 N·m at m = 16; each of its three samples
        // is floored (error in [0, 1) count), so `θ₀ − 2θ_m + θ_2m` is within 2 counts of the
        // true parabola's: |error| < 45 N·m, against a 300 N·m impact.
        assert!(worst < 45.0, "{worst}");
    }

    #[test]
    fn mul_q16_has_the_bits_of_fixed_saturating_mul() {
        let mut x = 0x2545_F491_u32;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x as i32
        };
        let edges = [
            0,
            1,
            -1,
            65_536,
            -65_536,
            i32::MAX,
            i32::MIN,
            0x7FFF,
            -0x8000,
        ];
        for &a in &edges {
            for &b in &edges {
                let (qa, qb) = (Q16::from_bits(a), Q16::from_bits(b));
                assert_eq!(mul_q16(qa, qb), mul_sat(qa, qb), "{a} × {b}");
            }
        }
        for _ in 0..100_000 {
            // Full range, and values of physical size (|x| < 2^24 bits = 256).
            let (a, b) = (next(), next());
            let (c, d) = (next() >> 8, next() >> 8);
            for (a, b) in [(a, b), (c, d), (a, d)] {
                let (qa, qb) = (Q16::from_bits(a), Q16::from_bits(b));
                assert_eq!(mul_q16(qa, qb), mul_sat(qa, qb), "{a} × {b}");
            }
        }
    }
}
