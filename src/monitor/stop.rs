//! Stopping: when the brake has stopped the output (the lock), with a spring-only pack's
//! turn-back (docs/monitor-design.md, "Turn-back").
//!
//! A spring-only pack cut against a known load is pressed by its spring alone (`F = F_s`, the
//! ramps open). A load the spring holds stops the output there, and the ramps stay open. A
//! load beyond the spring's capacity stops it only for a moment: the load turns it back through
//! the ramps' lost motion until they clamp (the output slows) and brake it to the lock.
//!
//! | turn | when | leaves |
//! |---|---|---|
//! | `None` | a relieved pack; no known load against the motion; locked after clamping | stopped 1 ms or thrown back → lock |
//! | `Against` | cut against a load the spring holds | as `None`; kept through the lock (ramps open) |
//! | `Expected` | cut against a load beyond [`TURN_BACK_SHARE`] of the spring's capacity | reversed → `Back`; stopped [`TURN_BACK_DWELL_S`] → lock |
//! | `Back` | turned back, ramps open | slowed by the stick speed → `Clamped`; beyond [`TURN_BACK_TRAVEL_RAD`] → lock |
//! | `Clamped` | the ramps clamp and brake | as `None`; beyond twice that travel → lock |
//!
//! A lock on a travel limit leaves the brake to the slip checks, which judge it from there.
//!
//! | quantity | format | range | resolution |
//! |---|---|---|---|
//! | travel since the turning point | `i32` counts, wrapping difference of the counter | ±half the counter | 1 count |
//! | peak speed since it | [`Q16`] rad/s | 0 … 32 768 | 1.5e-5 rad/s |

use super::config::{Config, ConfigError, DrivingPack};
use super::convert::{counts, q16, ticks};
use crate::fx::{counter_delta, Q16};

/// A spring-only pack cut against a known load above this share of its spring-only capacity
/// (μ_s·c·F_s) is expected to turn back; below it, the first stop is the lock.
pub const TURN_BACK_SHARE: f64 = 1.0;
/// An expected turning point that lasts this long is a lock after all (s).
pub const TURN_BACK_DWELL_S: f64 = 0.02;
/// Travel back within which the output must slow (rad): the plant family's largest lost motion
/// (0.056 rad, docs/model.md) and ≈ 10 ms of the observer seeing the clamp at 4 rad/s.
pub const TURN_BACK_TRAVEL_RAD: f64 = 0.1;

/// The stop rule's constants.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct StopSettings {
    lock_dwell_ticks: u32,
    /// The opposing load beyond which the output turns back (Q16 N·m; `MAX`: a relieved pack,
    /// no turn).
    turn_back_load: Q16,
    turn_back_dwell_ticks: u32,
    turn_back_counts: i32,
}

impl StopSettings {
    pub fn new(c: &Config) -> Result<StopSettings, ConfigError> {
        let (m, tick_hz) = (&c.mechanism, c.tick_hz);
        let spring_capacity = m.pack_torque_per_newton_m(c.capacity_mu) * m.spring_preload_n();
        Ok(StopSettings {
            lock_dwell_ticks: ticks(
                c.thresholds.lock_dwell_s,
                tick_hz,
                "thresholds.lock_dwell_s",
            )?,
            turn_back_load: match c.driving_pack {
                DrivingPack::Relieved => Q16::MAX,
                DrivingPack::SpringOnly => q16(TURN_BACK_SHARE * spring_capacity, "capacity_mu")?,
            },
            turn_back_dwell_ticks: ticks(TURN_BACK_DWELL_S, tick_hz, "tick_hz")?,
            turn_back_counts: counts(
                TURN_BACK_TRAVEL_RAD / c.sensors.output_rad_per_count(),
                "sensors.output_encoder_bits",
            )?,
        })
    }
}

/// The output at one classification while braking.
pub(crate) struct Motion {
    /// It turned since its last direction (outside the stick band).
    pub reversed: bool,
    /// Its counter, and the counter's width (bits).
    pub out: u32,
    pub out_bits: u8,
    /// Its speed, and the stick band's half-width.
    pub w: Q16,
    pub stick_speed: Q16,
}

/// Where a spring-only pack's braking stands (the module's table).
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Turn {
    None,
    Against,
    Expected,
    /// Turned back at this output count; the fastest speed since.
    Back(u32, Q16),
    /// Clamped after turning back at this output count.
    Clamped(u32),
}

impl Turn {
    /// While the drive runs: what a cut now starts, from the known load against the motion
    /// (N·m, ≤ 0 when none) beyond `min_load`.
    pub fn at_cut(k: &StopSettings, against: Q16, min_load: Q16) -> Turn {
        match against {
            _ if k.turn_back_load == Q16::MAX || against <= min_load => Turn::None,
            a if a > k.turn_back_load => Turn::Expected,
            _ => Turn::Against,
        }
    }

    /// One classification while braking (`still`: ticks in the stick band); whether the brake
    /// locks now.
    pub fn stops(&mut self, k: &StopSettings, still: &mut u32, m: &Motion) -> bool {
        let beyond = |at: u32, n: i32| counter_delta(at, m.out, m.out_bits).saturating_abs() > n;
        let (lock, next) = match *self {
            Turn::Expected if m.reversed => {
                *still = 0;
                (false, Turn::Back(m.out, Q16::ZERO))
            }
            Turn::Expected => (*still >= k.turn_back_dwell_ticks, Turn::Expected),
            Turn::Back(at, _) if beyond(at, k.turn_back_counts) => (true, Turn::None),
            Turn::Back(at, peak) => {
                let w = m.w.saturating_abs();
                let slowed = w < peak.saturating_sub(m.stick_speed);
                (
                    false,
                    if slowed {
                        Turn::Clamped(at)
                    } else {
                        Turn::Back(at, peak.max(w))
                    },
                )
            }
            Turn::Clamped(at) if beyond(at, k.turn_back_counts.saturating_mul(2)) => {
                (true, Turn::None)
            }
            t => (*still >= k.lock_dwell_ticks || m.reversed, t),
        };
        // Locked, only a spring-held pack keeps its ramps open.
        *self = if lock && next != Turn::Against {
            Turn::None
        } else {
            next
        };
        lock
    }

    /// The ramps are open (`F = F_s`): cut against the load and not clamped since.
    pub fn ramps_open(self) -> bool {
        matches!(self, Turn::Against | Turn::Expected | Turn::Back(..))
    }

    /// Turned back: the travel limits judge the braking, not the braking envelope.
    pub fn turned_back(self) -> bool {
        matches!(self, Turn::Back(..) | Turn::Clamped(_))
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    /// The stop rule of a unit (`spring_only` or relieved) fed one classification per step:
    /// (speed rad/s, output count); returns the step that locked, with the turn after it.
    fn run(spring_only: bool, against_nm: f64, steps: &[(f64, u32)]) -> Option<(usize, Turn)> {
        let mut c = Config::default();
        if spring_only {
            c.driving_pack = DrivingPack::SpringOnly;
        }
        let stick = Q16::from_num(c.thresholds.stick_speed_rad_s);
        let k = StopSettings::new(&c).expect("default configuration");
        let mut turn = Turn::at_cut(&k, Q16::from_num(against_nm), Q16::from_num(2));
        let (mut still, mut last) = (0_u32, 0_i32);
        for (i, &(w, out)) in steps.iter().enumerate() {
            let w = Q16::from_num(w);
            let dir = if w > stick {
                1
            } else if w < -stick {
                -1
            } else {
                0
            };
            still = if dir == 0 { still + 4 } else { 0 }; // a classification every 4 ticks
            let reversed = dir * last < 0;
            if dir != 0 {
                last = dir;
            }
            let m = Motion {
                reversed,
                out,
                out_bits: c.sensors.output_encoder_bits,
                w,
                stick_speed: stick,
            };
            if turn.stops(&k, &mut still, &m) {
                return Some((i, turn));
            }
        }
        None
    }

    /// The output slows at `decel` rad/s² from `w0`, turns back and runs on at `accel` until
    /// `clamp_after` steps past the turn, then slows to rest: (speed, count) per 0.4 ms step.
    fn turn_back(w0: f64, decel: f64, accel: f64, clamp_after: usize) -> Vec<(f64, u32)> {
        let (h, rad_per_count) = (0.0004, core::f64::consts::TAU / 16384.0);
        let (mut w, mut angle, mut out) = (-w0, 1.0, Vec::new());
        let mut turned = None;
        for i in 0..2000 {
            let a = match turned {
                None if w < 0.0 => decel,
                None => {
                    turned = Some(i);
                    accel
                }
                Some(t) if i < t + clamp_after => accel,
                Some(_) if w > 0.0 => -4.0 * accel,
                Some(_) => 0.0,
            };
            w = if turned.is_some() && a == 0.0 {
                0.0
            } else {
                w + a * h
            };
            angle += w * h;
            out.push((w, (angle / rad_per_count) as u32));
        }
        out
    }

    #[test]
    fn a_relieved_pack_locks_at_the_first_stop() {
        let steps = turn_back(5.0, 190.0, 80.0, 60);
        let (at, _) = run(false, 20.0, &steps).expect("locks");
        // The speed enters the stick band (0.3 rad/s) at ≈ 0.0248 s; 1 ms later it locks.
        assert!((60..=70).contains(&at), "{at}");
    }

    #[test]
    fn a_spring_only_pack_cut_against_a_load_beyond_its_spring_locks_after_turning_back() {
        let steps = turn_back(5.0, 190.0, 80.0, 60);
        let turned = steps.iter().position(|s| s.0 > 0.0).expect("turns");
        let stopped = steps.iter().rposition(|s| s.0 > 0.0).expect("stops") + 1;
        let (at, turn) = run(true, 20.0, &steps).expect("locks");
        assert!(
            at > turned + 60 && at <= stopped + 5,
            "{at}: turned {turned}, stopped {stopped}"
        );
        assert_eq!(turn, Turn::None, "clamped: the ramps carry the load");
    }

    #[test]
    fn a_spring_held_load_locks_at_the_first_stop_with_the_ramps_open() {
        let steps = turn_back(5.0, 190.0, 80.0, 60);
        let (at, turn) = run(true, 5.0, &steps).expect("locks");
        assert!((60..=70).contains(&at), "{at}");
        assert!(turn.ramps_open());
    }

    #[test]
    fn a_turn_back_that_never_clamps_is_locked_at_the_travel_limit_for_the_slip_checks() {
        // Accelerating back for ever: 0.1 rad at 80 rad/s² takes 50 ms (125 steps).
        let steps = turn_back(5.0, 190.0, 80.0, 100_000);
        let turned = steps.iter().position(|s| s.0 > 0.0).expect("turns");
        let (at, turn) = run(true, 20.0, &steps).expect("locks");
        assert!(
            (turned + 100..turned + 140).contains(&at),
            "{at}: turned {turned}"
        );
        assert_eq!(turn, Turn::None);
    }

    #[test]
    fn an_expected_turn_that_stays_stopped_is_a_lock_after_the_dwell() {
        let mut steps = turn_back(5.0, 190.0, 80.0, 60);
        let turned = steps.iter().position(|s| s.0 > 0.0).expect("turns");
        let hold = steps[turned - 1];
        steps
            .iter_mut()
            .skip(turned)
            .for_each(|s| *s = (0.0, hold.1));
        let (at, _) = run(true, 20.0, &steps).expect("locks");
        // In the band from ≈ step 62; 20 ms = 200 ticks = 50 classifications later.
        assert!((105..=120).contains(&at), "{at}");
    }
}
