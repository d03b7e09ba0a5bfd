//! Observing: the drive torque from the current, and the output shaft's angle, speed and
//! torque from its encoder (a three-state observer, `observer.rs`), with the plausibility of
//! each reading against it, settling and the power-on seeding.
//!
//! | quantity | format | range | resolution |
//! |---|---|---|---|
//! | drive torque, model torque | [`Q16`] N·m, saturating | ±32 768 | 1.5e-5 N·m |
//! | innovation | `i32` angle words (wrapping difference) | ±half a turn | 2π/2³² rad |
//! | recent peak speed | `i32` Q16 bits, saturating | ≥ 0 | 1.5e-5 rad/s |

use super::config::{Config, ConfigError, IMPACT_DECAY_RAD_S2, POWER_ON_SEED_TICKS};
use super::convert::{positive, q16, scale, ticks, Q16_ONE};
use super::observer::{Observer, ObserverScales};
use super::scale::Scale;
use super::sense::{times, SenseSettings, Sensed};
use crate::fx::{counter_delta, Q16};

/// The observer stage's constants.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ObserveSettings {
    pub obs: ObserverScales,
    max_catchup: u8,
    pub settle_ticks: u32,
    /// Settling ticks a seeded power-on skips (`settle_time_s − power_on_settle_s`).
    power_on_head_start: u32,
    /// Output counts over the seeding window → Q16 rad/s.
    seed_speed: Scale<16>,
    innovation_limit: i32,
    /// Q16 rad/s → angle words: the prediction error an impact reversing that speed can cause.
    impact_words: Scale<16>,
    /// Decay of the recent peak speed per tick (Q16 bits): [`IMPACT_DECAY_RAD_S2`]·h.
    impact_decay: i32,
    persistence_ticks: u32,
    out_bits: u8,
    out_jump_counts: i32,
    drive_motoring: Scale<16>,
    drive_backdriven: Scale<16>,
    /// The Karnopp band (rad/s): the drive is back-driven only outside it.
    pub stick_speed: Q16,
}

impl ObserveSettings {
    pub fn new(c: &Config, sense: &SenseSettings) -> Result<ObserveSettings, ConfigError> {
        let (s, t, tick_hz) = (&c.sensors, &c.thresholds, c.tick_hz);
        let h = 1.0 / tick_hz;
        let kt = positive(
            s.motor_torque_constant_nm_a,
            "sensors.motor_torque_constant_nm_a",
        )?;
        let ratio = positive(s.reducer_ratio, "sensors.reducer_ratio")?;
        let eff = positive(s.reducer_efficiency, "sensors.reducer_efficiency")?;
        super::convert::require(eff <= 1.0, "sensors.reducer_efficiency")?;
        let back = positive(c.backdrive_efficiency, "backdrive_efficiency")?;
        let full_scale = positive(s.current_full_scale_a, "sensors.current_full_scale_a")?;
        if full_scale * kt * ratio * eff.max(back) > super::convert::Q16_ENVELOPE {
            return Err(ConfigError::Overflow {
                parameter: "sensors.current_full_scale_a",
            });
        }
        let amps = s.amps_per_count();
        let out_rad = s.output_rad_per_count();
        let words_per_rad = 4_294_967_296.0 / core::f64::consts::TAU;
        let settle_ticks = ticks(t.settle_time_s, tick_hz, "thresholds.settle_time_s")?;
        let power_on = ticks(t.power_on_settle_s, tick_hz, "thresholds.power_on_settle_s")?;
        let obs = ObserverScales::new(c)?;
        Ok(ObserveSettings {
            obs,
            max_catchup: c.max_catchup_ticks,
            settle_ticks,
            // A seeded start settles sooner, never later.
            power_on_head_start: settle_ticks.checked_sub(power_on).ok_or(
                ConfigError::OutOfRange {
                    parameter: "thresholds.power_on_settle_s",
                },
            )?,
            seed_speed: scale(
                out_rad / h * Q16_ONE / f64::from(POWER_ON_SEED_TICKS),
                "sensors.output_encoder_bits",
            )?,
            innovation_limit: sense
                .out_jump_counts
                .saturating_mul(1_i32 << (32 - u32::from(sense.out_bits)).min(30)),
            impact_words: scale(
                2.0 * positive(t.impact_time_s, "thresholds.impact_time_s")? * words_per_rad
                    / Q16_ONE,
                "thresholds.impact_time_s",
            )?,
            // 1e-3 rad/s per tick at 10 kHz, ≥ 1 LSB at any tick rate (0 < value < 2^31).
            impact_decay: ((IMPACT_DECAY_RAD_S2 * h * Q16_ONE + 0.5) as i32).max(1),
            persistence_ticks: ticks(
                t.flag_persistence_s,
                tick_hz,
                "thresholds.flag_persistence_s",
            )?,
            out_bits: sense.out_bits,
            out_jump_counts: sense.out_jump_counts,
            drive_motoring: scale(
                amps * kt * ratio * eff * Q16_ONE,
                "sensors.reducer_efficiency",
            )?,
            drive_backdriven: scale(amps * kt * ratio * back * Q16_ONE, "backdrive_efficiency")?,
            stick_speed: q16(
                positive(t.stick_speed_rad_s, "thresholds.stick_speed_rad_s")?,
                "thresholds.stick_speed_rad_s",
            )?,
        })
    }

    /// Drive torque of `counts` of current while motoring (the command's shortfall).
    #[inline]
    pub(crate) fn motoring_torque(&self, counts: i32) -> Q16 {
        Q16::from_bits(self.drive_motoring.apply(counts))
    }
}

/// What the observer stage hands on.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug)]
pub(crate) struct Observed {
    /// Output speed ω̂.
    pub w: Q16,
    /// `J_s·ω̇ − u`: the observer's torque less the modelled pack torque.
    pub net: Q16,
    /// Drive torque at the no-back input from the current (zero with the drive off).
    pub drive_torque: Q16,
    /// The observer has settled since its last (re)start.
    pub settled: bool,
    /// No implausible reading for the settling time.
    pub sensors_ok: bool,
    /// A reading was implausible this call (sensing's or the encoder against the observer).
    pub fault: bool,
    /// The call was within the catch-up (the estimate can be trusted in time).
    pub in_time: bool,
    /// Settling ticks a power-on seeding skipped this call (0 on every other call).
    pub head_start: u32,
}

impl Observed {
    /// Before the first tick.
    pub const NONE: Observed = Observed {
        w: Q16::ZERO,
        net: Q16::ZERO,
        drive_torque: Q16::ZERO,
        settled: false,
        sensors_ok: false,
        fault: false,
        in_time: true,
        head_start: 0,
    };
}

/// The power-on seeding: after [`POWER_ON_SEED_TICKS`] on-time, plausible ticks the observer
/// starts from the output's measured speed with its torque balanced, instead of at rest.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, Default)]
struct PowerOnSeed {
    /// Ticks left (0: done, or given up).
    left: u32,
    /// Output counter at power-on.
    out: u32,
}

/// The observer stage's state.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug)]
pub(crate) struct Observe {
    obs: Observer,
    seed: PowerOnSeed,
    drive_torque: Q16,
    /// The modelled pack torque `T̂` fed forward into the prediction.
    model_torque: Q16,
    settle_ticks: u32,
    since_fault: u32,
    /// Recent peak |ω̂| (Q16 bits), decaying: the speed an impact in the lost motion can return.
    impact_speed: i32,
    innovation_ticks: u32,
}

impl Observe {
    pub const fn new() -> Observe {
        Observe {
            obs: Observer {
                theta: 0,
                v: 0,
                d: 0,
            },
            seed: PowerOnSeed { left: 0, out: 0 },
            drive_torque: Q16::ZERO,
            model_torque: Q16::ZERO,
            settle_ticks: 0,
            since_fault: 0,
            impact_speed: 0,
            innovation_ticks: 0,
        }
    }

    pub fn update(&mut self, k: &ObserveSettings, x: &Sensed) -> Observed {
        let n = x.n;
        let head_start = if self.seed.left > 0 {
            self.seed_tick(k, x)
        } else {
            0
        };
        if x.first {
            self.obs = Observer {
                theta: x.angle,
                v: 0,
                d: 0,
            };
            self.seed = PowerOnSeed {
                left: POWER_ON_SEED_TICKS,
                out: x.out,
            };
        }
        self.drive_torque = self.drive_torque(k, x);
        // Predict n ticks with the model torque; too late to extrapolate: re-seat.
        let tau = self
            .obs
            .d
            .saturating_add(self.drive_torque.to_bits())
            .saturating_sub(self.model_torque.to_bits());
        if n > u32::from(k.max_catchup) {
            self.obs.theta = x.angle;
            self.settle_ticks = 0;
        } else if n == 1 {
            self.obs.predict(tau, &k.obs);
        } else {
            for _ in 0..n {
                self.obs.predict(tau, &k.obs);
            }
        }
        self.settle_ticks = self.settle_ticks.saturating_add(n);
        let settled = self.settle_ticks >= k.settle_ticks;
        let fault = x.fault | self.correct(k, x, settled);
        self.since_fault = if fault {
            0
        } else {
            self.since_fault.saturating_add(n)
        };
        Observed {
            w: Q16::from_bits(self.obs.v),
            net: Q16::from_bits(self.obs.d).saturating_sub(self.model_torque),
            drive_torque: self.drive_torque,
            settled,
            sensors_ok: self.since_fault >= k.settle_ticks,
            fault,
            in_time: n <= u32::from(k.max_catchup),
            head_start,
        }
    }

    /// Corrects with the measured angle unless it disagrees with any plausible motion: one tick
    /// at the fastest speed plus an impact reversing the recent peak speed. Returns whether it
    /// was implausible (a persisting disagreement re-seats the angle).
    fn correct(&mut self, k: &ObserveSettings, x: &Sensed, settled: bool) -> bool {
        let n_i = x.n as i32;
        // Shortest signed angle (wrapping on purpose: the encoder is modular).
        let innovation = x.angle.wrapping_sub(self.obs.theta) as i32;
        self.impact_speed = self
            .impact_speed
            .saturating_sub(times(k.impact_decay, n_i))
            .max(self.obs.v.saturating_abs());
        let base_limit = times(k.innovation_limit, n_i);
        // The widened limit is formed only when the base limit is exceeded (cheaper).
        let implausible = settled
            && innovation.saturating_abs() > base_limit
            && innovation.saturating_abs()
                > k.impact_words
                    .apply(self.impact_speed)
                    .saturating_add(base_limit);
        if implausible {
            self.innovation_ticks = self.innovation_ticks.saturating_add(x.n);
            if self.innovation_ticks >= k.persistence_ticks {
                self.obs.theta = x.angle;
                self.innovation_ticks = 0;
            }
        } else {
            self.innovation_ticks = 0;
            if x.out_ok {
                self.obs.correct(x.angle, &k.obs);
            }
        }
        implausible
    }

    /// Drive torque from the current while the drive is commanded: `÷η` when the load
    /// back-drives the motor (current against the output's motion outside the stick band).
    fn drive_torque(&self, k: &ObserveSettings, x: &Sensed) -> Q16 {
        if !x.drive {
            return Q16::ZERO;
        }
        let stick = k.stick_speed.to_bits();
        let (c, v) = (x.current, self.obs.v);
        let backdriven = (c > 0 && v < -stick) || (c < 0 && v > stick);
        let scale = if backdriven {
            k.drive_backdriven
        } else {
            k.drive_motoring
        };
        Q16::from_bits(scale.apply(c))
    }

    /// One seeding tick (out of line: the other ticks carry only the test). A late tick, a
    /// sensor fault or an implausible output step gives up (the observer then settles from
    /// rest). On the last tick: the angle read now, the speed from the travel since power-on,
    /// `d̂ = T̂ − u` so that the model does not accelerate. Returns the settling skipped.
    #[cold]
    #[inline(never)]
    fn seed_tick(&mut self, k: &ObserveSettings, x: &Sensed) -> u32 {
        if x.n != 1 || x.early_fault || x.d_out.saturating_abs() > k.out_jump_counts {
            self.seed.left = 0;
            return 0;
        }
        self.seed.left = self.seed.left.saturating_sub(1);
        if self.seed.left != 0 {
            return 0;
        }
        self.obs = Observer {
            theta: x.angle,
            v: k.seed_speed
                .apply(counter_delta(self.seed.out, x.out, k.out_bits)),
            d: self
                .model_torque
                .to_bits()
                .saturating_sub(self.drive_torque.to_bits()),
        };
        self.settle_ticks = self.settle_ticks.saturating_add(k.power_on_head_start);
        self.since_fault = self.since_fault.saturating_add(k.power_on_head_start);
        k.power_on_head_start
    }

    /// Feeds this call's modelled pack torque forward into the next prediction. `bumpless`: the
    /// model changed how it reads the motion (not the motion), so the torque state takes the
    /// same step and the net torque stays continuous.
    pub fn set_model_torque(&mut self, model: Q16, bumpless: bool) {
        if bumpless {
            self.obs.d = self
                .obs
                .d
                .saturating_add(model.to_bits().saturating_sub(self.model_torque.to_bits()));
        }
        self.model_torque = model;
    }

    /// The observer's disturbance torque `d̂` (the model's own load state).
    pub fn disturbance(&self) -> Q16 {
        Q16::from_bits(self.obs.d)
    }
}
