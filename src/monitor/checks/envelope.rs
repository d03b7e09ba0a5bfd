//! The braking envelope (`brake_weak`): from the drive's cut, a nominal braking model —
//! speed decreasing at `(T_all ∓ |M̂|)/J_s`, both socket faces clamping (no faster than an
//! opposing load allows while the load's sign is a guess) — stepped by explicit
//! Euler in I16F16 at `braking_model_hz`, gives the speed, angle and stop time a working pack
//! allows; the output may overrun the angle and the time by one factor (a healthy pack slipping
//! at μ_d brakes slower alike in both) plus their allowances. A pack that does not brake at
//! all is caught sooner: the output going further than it would at its cut speed, undecelerated.
//!
//! | quantity | format | range | resolution |
//! |---|---|---|---|
//! | travel, expected travel | `i32` Q16 output counts, saturating (compared in `i64`) | ±2^15 counts | 2^-16 count |
//! | expected speed | [`Q16`] rad/s | 0 … 32 768 | 1.5e-5 rad/s |

use crate::fx::Q16;
use crate::monitor::config::{Config, ConfigError};
use crate::monitor::convert::{counts, finite, positive, q16, require, scale, ticks, Q16_ONE};
use crate::monitor::mul_q16;
use crate::monitor::pack::Dir;
use crate::monitor::scale::Scale;
use crate::monitor::schedule::Slot;
use crate::monitor::sense::times;

/// The envelope's constants.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct EnvelopeSettings {
    /// Ticks per step of the nominal braking model (`tick_hz / braking_model_hz`).
    pub model_ticks: u32,
    /// The model's rate (Hz, rounded).
    pub model_hz: u32,
    /// One model step: Q16 rad/s → Q16 output counts travelled.
    travel: Scale<20>,
    /// One model step: Q16 N·m → Q16 rad/s of speed change.
    speed: Scale<30>,
    /// Q16 rad/s → Q16 output counts per tick.
    speed_to_counts: Scale<28>,
    /// Q16 N·m → Q16 rad/s per tick (`h/J_s`).
    decel_per_tick: Scale<37>,
    grace_ticks: u32,
    angle_factor: Scale<25>,
    /// Q16 output counts.
    angle_allowance: i32,
    /// Q16 output counts.
    undecelerated_allowance: i32,
    /// Share of the capacity counted on against an opposing load (Q16, 0 … 1).
    opposed_share: Q16,
}

impl EnvelopeSettings {
    pub fn new(c: &Config) -> Result<EnvelopeSettings, ConfigError> {
        let (t, tick_hz) = (&c.thresholds, c.tick_hz);
        let h = 1.0 / tick_hz;
        let j = positive(
            c.mechanism.output_inertia_kg_m2,
            "mechanism.output_inertia_kg_m2",
        )?;
        let out_rad = c.sensors.output_rad_per_count();
        let model_ticks = model_ticks(c.braking_model_hz, tick_hz)?;
        let per_step = f64::from(model_ticks);
        let q16_counts = |rad: f64, key| counts(positive(rad, key)? / out_rad * Q16_ONE, key);
        Ok(EnvelopeSettings {
            model_ticks,
            // 100 Hz ≤ tick_hz ≤ 1 MHz and ticks ≥ 1: the rate fits a u32.
            model_hz: (tick_hz / per_step + 0.5) as u32,
            travel: scale(h / out_rad * per_step, "braking_model_hz")?,
            speed: scale(h / j * per_step, "braking_model_hz")?,
            speed_to_counts: scale(h / out_rad, "sensors.output_encoder_bits")?,
            decel_per_tick: scale(h / j, "mechanism.output_inertia_kg_m2")?,
            grace_ticks: ticks(t.braking_grace_s, tick_hz, "thresholds.braking_grace_s")?,
            angle_factor: scale(
                positive(t.braking_angle_factor, "thresholds.braking_angle_factor")?,
                "thresholds.braking_angle_factor",
            )?,
            angle_allowance: q16_counts(
                t.braking_angle_allowance_rad,
                "thresholds.braking_angle_allowance_rad",
            )?,
            opposed_share: {
                let share = finite(t.opposed_braking_share, "thresholds.opposed_braking_share")?;
                require(
                    (0.0..=1.0).contains(&share),
                    "thresholds.opposed_braking_share",
                )?;
                q16(share, "thresholds.opposed_braking_share")?
            },
            undecelerated_allowance: q16_counts(
                t.undecelerated_allowance_rad,
                "thresholds.undecelerated_allowance_rad",
            )?,
        })
    }
}

/// Ticks per step of the braking model: a whole number from 1 to 1000 (the model may not run
/// faster than the ticks, and at 1/1000 of them it would not see a braking event at all).
fn model_ticks(model_hz: f64, tick_hz: f64) -> Result<u32, ConfigError> {
    const KEY: &str = "braking_model_hz";
    let ratio = tick_hz / positive(model_hz, KEY)?;
    let whole = (ratio + 0.5) as u32; // 0 < ratio ≤ 1e10: `as` saturates, never wraps
    if !(1..=1000).contains(&whole) || (ratio - f64::from(whole)).abs() > 1e-9 * ratio {
        return Err(ConfigError::OutOfRange { parameter: KEY });
    }
    Ok(whole)
}

/// One braking event's envelope (drive cut to lock).
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Envelope {
    /// Output travel since the cut (counts, saturating).
    counts: i32,
    expected_speed: Q16,
    /// Q16 counts, saturating.
    expected_counts: i32,
    /// Ticks the model ran until it stopped.
    model_run_ticks: u32,
    /// Ticks braking on past the model's stop stretched by the angle's factor (from
    /// `−(factor − 1)·run` at the stop); overdue beyond the grace.
    overdue_ticks: i32,
    /// Ticks since the model's last step.
    model_ticks: u32,
    /// Travel per tick and per usual model step at the cut speed (Q16 counts).
    free_tick: i32,
    free_step: i32,
    /// Travel at the cut speed, undecelerated, since the cut (Q16 counts, saturating).
    free_counts: i32,
}

/// What one envelope call reads.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug)]
pub(crate) struct BrakingTick {
    pub n: u32,
    pub tick: u32,
    pub d_out: i32,
    pub dir: Dir,
    pub load_dir: Dir,
    /// The model's deceleration torque moving with the load and against it
    /// ([`EnvelopeSettings::decelerations`], cached with the load).
    pub decel: Decel,
}

/// The braking model's deceleration torques (N·m, ≥ 0) for one load.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub(crate) struct Decel {
    pub along: Q16,
    pub opposed: Q16,
}

impl EnvelopeSettings {
    /// `T_all − |M̂|` moving with the load, `s·T_all + |M̂|` against it; while the load's sign
    /// is a guess (`other`: the load under the other reading), moving with it no more than
    /// against `other`.
    pub fn decelerations(&self, capacity: Q16, load: Q16, other: Option<Q16>) -> Decel {
        let (share, load_abs) = (mul_q16(self.opposed_share, capacity), load.saturating_abs());
        let mut along = capacity.saturating_sub(load_abs);
        if let Some(other) = other {
            along = along.min(share.saturating_add(other.saturating_abs()));
        }
        Decel {
            along: along.max(Q16::ZERO),
            opposed: share.saturating_add(load_abs).max(Q16::ZERO),
        }
    }
}

impl Envelope {
    /// Starts from the present output speed.
    pub fn arm(&mut self, k: &EnvelopeSettings, speed: Q16) {
        let speed = speed.saturating_abs();
        let free_tick = k.speed_to_counts.apply(speed.to_bits());
        *self = Envelope {
            expected_speed: speed,
            free_tick,
            free_step: times(free_tick, i32::try_from(k.model_ticks).unwrap_or(i32::MAX)),
            ..Envelope::default()
        };
    }

    /// One braking call; returns whether the output left the envelope.
    pub fn check(&mut self, k: &EnvelopeSettings, b: &BrakingTick) -> bool {
        let mut weak = false;
        self.model_ticks = self.model_ticks.saturating_add(b.n);
        self.counts = self.counts.saturating_add(b.d_out.saturating_abs());
        if self.model_ticks >= k.model_ticks && Slot::braking_model_may_step(b.tick) {
            weak |= self.model_step(k, b);
        }
        if self.expected_speed == Q16::ZERO {
            self.overdue_ticks = self.overdue_ticks.saturating_add_unsigned(b.n);
        }
        // Both sides < 2^47: exact in i64.
        let angle_limit =
            i64::from(k.angle_factor.apply(self.expected_counts)) + i64::from(k.angle_allowance);
        let overdue = i64::from(self.overdue_ticks) > i64::from(k.grace_ticks);
        weak || overdue || i64::from(self.counts) << 16 > angle_limit
    }

    /// One explicit-Euler step over the ticks it covers: travel with the old speed, then the
    /// speed. Returns whether the pack is not braking at all.
    fn model_step(&mut self, k: &EnvelopeSettings, b: &BrakingTick) -> bool {
        let decel = if b.dir == b.load_dir {
            b.decel.along
        } else {
            b.decel.opposed
        };
        // The usual step's constants are precomputed; a longer one (a late tick, or the first
        // step after an arm on an even tick) multiplies the per-tick ones.
        let (travel, dv, free) = if self.model_ticks == k.model_ticks {
            (
                k.travel.apply(self.expected_speed.to_bits()),
                k.speed.apply(decel.to_bits()),
                self.free_step,
            )
        } else {
            // ≤ 1000 + 256 ticks (reset at each model step): fits an i32.
            let n = i32::try_from(self.model_ticks).unwrap_or(i32::MAX);
            (
                times(k.speed_to_counts.apply(self.expected_speed.to_bits()), n),
                times(k.decel_per_tick.apply(decel.to_bits()), n),
                times(self.free_tick, n),
            )
        };
        let was_moving = self.expected_speed != Q16::ZERO;
        if was_moving {
            self.model_run_ticks = self.model_run_ticks.saturating_add(self.model_ticks);
        }
        self.model_ticks = 0;
        self.expected_counts = self.expected_counts.saturating_add(travel);
        self.expected_speed =
            Q16::from_bits(self.expected_speed.to_bits().saturating_sub(dv).max(0));
        if was_moving && self.expected_speed == Q16::ZERO {
            // Overdue counts from the run stretched by the angle's factor (never before the stop).
            let run = i32::try_from(self.model_run_ticks).unwrap_or(i32::MAX);
            self.overdue_ticks = run.saturating_sub(k.angle_factor.apply(run)).min(0);
        }
        self.free_counts = self.free_counts.saturating_add(free);
        // Both sides < 2^48: exact in i64.
        i64::from(self.counts) << 16
            > i64::from(self.free_counts) + i64::from(k.undecelerated_allowance)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Ticks until `check` calls the output weak while braking goes on under `decel` (N·m), the
    /// output's counter still (so only the time rule can call it).
    fn ticks_to_weak(e: &mut Envelope, k: &EnvelopeSettings, decel: f64) -> u32 {
        let one = Dir::of(Q16::ONE, Q16::ZERO);
        let d = Q16::from_num(decel);
        for tick in 1..200_000_u32 {
            let b = BrakingTick {
                n: 1,
                tick,
                d_out: 0,
                dir: one,
                load_dir: one,
                decel: Decel {
                    along: d,
                    opposed: d,
                },
            };
            if e.check(k, &b) {
                return tick;
            }
        }
        u32::MAX
    }

    #[test]
    fn the_output_is_overdue_past_the_factor_times_the_models_stop_plus_the_grace() {
        let k = EnvelopeSettings::new(&Config::default()).expect("default settings");
        let factor = k.angle_factor.to_f64();
        // Not armed (a reset mid-braking) or armed at rest: the model has no run, the grace.
        assert_eq!(
            ticks_to_weak(&mut Envelope::default(), &k, 10.0),
            k.grace_ticks + 1
        );
        // Armed at 2 rad/s under 10 N·m: the model stops after `run` ticks.
        let mut e = Envelope::default();
        e.arm(&k, Q16::from_num(2.0));
        let weak_at = ticks_to_weak(&mut e, &k, 10.0);
        let run = e.model_run_ticks;
        assert!(run > 100, "the model ran {run} ticks");
        let expected = (factor * f64::from(run)).round() as u32 + k.grace_ticks + 1;
        assert!(
            weak_at.abs_diff(expected) <= 1,
            "weak at {weak_at}, expected {expected}"
        );
    }
}
