//! The pack slipping under a held load, seen on both encoders at once (`brake_slip`).
//!
//! With the drive off the pack holds the connecting shaft; the output shaft and the input
//! shaft (the motor) each sit on their own ball ramps against it. Inside their lost motions
//! both can move without the pack slipping: the output rattles between the faces of its V
//! sockets (up to ±0.13 rad in the twin's physical reading, all of Table 2 ± 10 %) and every
//! impact kicks the motor back and forth (up to 0.035 rad of the input shaft). Only a slipping
//! pack turns the connecting shaft, and then it carries both shafts the same way. So the check
//! follows each shaft's current monotone excursion (its travel since it last turned back by
//! more than a hysteresis) and raises `brake_slip` when both run the same way beyond their
//! limits. It answers ≈ 20–30 ms after a slip starts, where the output's span alone
//! (`thresholds.creep_limit_rad`, which must stay above the rattle) needs 50–70 ms for a slow
//! slip. Limits and their margins: docs/monitor-design.md, "Common slip".
//!
//! Runs in the slow lane's `Checks` slot with the drive off, out of line, on the counters'
//! travel since the brake held.
//!
//! | quantity | format | range | resolution |
//! |---|---|---|---|
//! | positions | `i32` counts, wrapping difference of the counters | ±half the counter | 1 count |
//! | excursions | `i32` counts, saturating | ±2^31 counts | 1 count |

use crate::fx::counter_delta;
use crate::monitor::config::{Config, ConfigError};
use crate::monitor::convert::counts;

/// One shaft's monotone excursion: where the current run in one direction started and how far
/// it has gone.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, Default)]
struct Excursion {
    /// Position where the current run started (counts).
    start: i32,
    /// Furthest position of the current run (counts).
    extreme: i32,
    /// Direction of the current run (−1, 0 before the first move beyond the hysteresis, 1).
    dir: i32,
}

impl Excursion {
    /// Follows the shaft to `position`; returns the signed travel of the current run.
    fn follow(&mut self, position: i32, hysteresis: i32) -> i32 {
        let ahead = position.saturating_sub(self.extreme); // > 0: beyond the extreme upwards
        if self.dir == 0 {
            // Not yet moving: the extreme is the start; a move beyond the hysteresis either way
            // starts a run.
            let travel = position.saturating_sub(self.start);
            if travel > hysteresis {
                self.dir = 1;
            } else if travel < hysteresis.saturating_neg() {
                self.dir = -1;
            }
            if self.dir != 0 {
                self.extreme = position;
            }
        } else if (self.dir > 0 && ahead > 0) || (self.dir < 0 && ahead < 0) {
            self.extreme = position; // the run goes on
        } else if ahead.saturating_abs() > hysteresis {
            // Turned back beyond the hysteresis: a new run from the old extreme.
            self.start = self.extreme;
            self.extreme = position;
            self.dir = -self.dir;
        }
        self.extreme.saturating_sub(self.start)
    }
}

/// State of the common-slip check.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct SlipCheck {
    /// Following the shafts (from the brake's first hold after a cut until the drive runs).
    active: bool,
    /// The output and motor counters when the check was armed (masked raw values).
    out_at_arm: u32,
    motor_at_arm: u32,
    out: Excursion,
    motor: Excursion,
}

/// The check's limits, in counts (from the configuration).
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct SlipLimits {
    /// Output travel of a common run beyond which the pack slips.
    pub out_counts: i32,
    /// Motor travel of a common run beyond which the pack slips.
    pub motor_counts: i32,
    /// Turn-back that ends a run, output counts.
    pub out_hysteresis: i32,
    /// Turn-back that ends a run, motor counts.
    pub motor_hysteresis: i32,
    /// Counter widths (bits), for the wrapping differences.
    pub out_bits: u8,
    pub motor_bits: u8,
}

impl SlipLimits {
    pub fn new(c: &Config) -> Result<SlipLimits, ConfigError> {
        let (s, t) = (&c.sensors, &c.thresholds);
        let (out_rad, in_rad) = (s.output_rad_per_count(), s.input_rad_per_motor_count());
        Ok(SlipLimits {
            out_counts: within_quarter_counter(
                counts(
                    t.slip_output_travel_rad / out_rad,
                    "thresholds.slip_output_travel_rad",
                )?,
                s.output_encoder_bits,
                "thresholds.slip_output_travel_rad",
            )?,
            motor_counts: within_quarter_counter(
                counts(
                    t.slip_input_travel_rad / in_rad,
                    "thresholds.slip_input_travel_rad",
                )?,
                s.motor_counter_bits,
                "thresholds.slip_input_travel_rad",
            )?,
            out_hysteresis: counts(
                t.slip_reversal_rad / out_rad,
                "thresholds.slip_reversal_rad",
            )?,
            motor_hysteresis: counts(t.slip_reversal_rad / in_rad, "thresholds.slip_reversal_rad")?,
            out_bits: s.output_encoder_bits,
            motor_bits: s.motor_counter_bits,
        })
    }
}

/// A travel limit the check can measure on a wrapping counter: below a quarter of its range,
/// so that the travel since the brake held (up to twice the limit) stays within the half range
/// its wrapping difference resolves.
fn within_quarter_counter(limit: i32, bits: u8, key: &'static str) -> Result<i32, ConfigError> {
    let quarter = 1_i64 << (u32::from(bits.clamp(2, 32)) - 2);
    if i64::from(limit) < quarter {
        Ok(limit)
    } else {
        Err(ConfigError::OutOfRange { parameter: key })
    }
}

impl SlipCheck {
    /// Starts following both shafts from the present counter values (the brake has just
    /// held).
    #[inline]
    pub fn arm(&mut self, out_counter: u32, motor_counter: u32) {
        *self = SlipCheck {
            active: true,
            out_at_arm: out_counter,
            motor_at_arm: motor_counter,
            ..SlipCheck::default()
        };
    }

    /// Measures afresh from here if it is following (a flag reset while the brake holds).
    #[inline]
    pub fn restart(&mut self, out_counter: u32, motor_counter: u32) {
        if self.active {
            self.arm(out_counter, motor_counter);
        }
    }

    /// Stops following (the drive runs, an encoder reading is implausible, or the slip is
    /// flagged).
    #[inline]
    pub fn disarm(&mut self) {
        self.active = false;
    }

    /// One run of the check on the present counter values: `true` when both shafts run the
    /// same way beyond their limits. The positions are the counters' wrapping differences
    /// from the arming, exact while each shaft has turned less than half its counter's range
    /// (2^13 output counts, 3.1 rad; 2^15 motor counts, 1.7 rad of the input shaft with the
    /// default sensors): far beyond the limits, which flag and disarm first. An implausible
    /// step in between disarms the check (the caller, on the sensor fault).
    #[inline(never)]
    pub fn slipping(&mut self, l: &SlipLimits, out_counter: u32, motor_counter: u32) -> bool {
        if !self.active {
            return false;
        }
        let out_pos = counter_delta(self.out_at_arm, out_counter, l.out_bits);
        let motor_pos = counter_delta(self.motor_at_arm, motor_counter, l.motor_bits);
        let a = self.out.follow(out_pos, l.out_hysteresis);
        let b = self.motor.follow(motor_pos, l.motor_hysteresis);
        (a > l.out_counts && b > l.motor_counts)
            || (a < l.out_counts.saturating_neg() && b < l.motor_counts.saturating_neg())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const L: SlipLimits = SlipLimits {
        out_counts: 130,
        motor_counts: 1170,
        out_hysteresis: 2,
        motor_hysteresis: 19,
        out_bits: 14,
        motor_bits: 16,
    };

    /// Follows counters that start near their wrap and move by `(d_out, d_motor)` per call.
    struct Shafts {
        out: u32,
        motor: u32,
    }

    impl Shafts {
        fn new(c: &mut SlipCheck) -> Self {
            let s = Shafts {
                out: (1 << 14) - 50,
                motor: (1 << 16) - 500,
            };
            c.arm(s.out, s.motor);
            s
        }
        fn step(&mut self, c: &mut SlipCheck, d_out: i32, d_motor: i32) -> bool {
            self.out = self.out.wrapping_add_signed(d_out) & ((1 << 14) - 1);
            self.motor = self.motor.wrapping_add_signed(d_motor) & ((1 << 16) - 1);
            c.slipping(&L, self.out, self.motor)
        }
    }

    #[test]
    fn a_run_restarts_when_the_shaft_turns_back_beyond_the_hysteresis() {
        let mut e = Excursion::default();
        assert_eq!(e.follow(2, 2), 0); // within the hysteresis: no run yet
        assert_eq!(e.follow(10, 2), 10);
        assert_eq!(e.follow(9, 2), 10); // dither below the hysteresis
        assert_eq!(e.follow(7, 2), -3); // turned back by 3: a new run from 10
        assert_eq!(e.follow(-20, 2), -30);
    }

    #[test]
    fn both_shafts_carried_the_same_way_is_a_slip() {
        let mut c = SlipCheck::default();
        let mut s = Shafts::new(&mut c);
        let flagged_at = (0..200).find(|_| s.step(&mut c, 1, 10));
        // The motor passes 1170 counts at the 118th delta, the output 130 at the 131st.
        assert_eq!(flagged_at, Some(130));
    }

    #[test]
    fn a_rattle_or_one_shaft_alone_is_not() {
        let mut c = SlipCheck::default();
        let mut s = Shafts::new(&mut c);
        // The output crosses its lost motion both ways (300 counts) while the motor is kicked
        // back and forth by 800 counts: each run reverses before both limits are passed.
        for k in 0..2000 {
            let phase = (k / 300) % 2 == 0;
            let d_motor = if (k / 80) % 2 == 0 { 10 } else { -10 };
            assert!(
                !s.step(&mut c, if phase { 1 } else { -1 }, d_motor),
                "tick {k}"
            );
        }
        // The motor alone, far: not a slip of the pack (the output holds).
        let mut c = SlipCheck::default();
        let mut s = Shafts::new(&mut c);
        for k in 0..2000 {
            assert!(!s.step(&mut c, 0, 10), "tick {k}");
        }
        // Opposite ways: no.
        let mut c = SlipCheck::default();
        let mut s = Shafts::new(&mut c);
        for k in 0..2000 {
            assert!(!s.step(&mut c, 1, -10), "tick {k}");
        }
    }

    #[test]
    fn disarmed_it_neither_follows_nor_flags() {
        let mut c = SlipCheck::default();
        let mut s = Shafts::new(&mut c);
        c.disarm();
        for _ in 0..2000 {
            assert!(!s.step(&mut c, 1, 10));
        }
    }
}
