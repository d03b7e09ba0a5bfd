//! A pack that drags while the output falls behind its input (`brake_drag`). With the drive on
//! and the output slower than the input, the ramps do not engage: they engage only as the output
//! gains on the input. The pack brakes with its spring drag (or an engagement's, until the input
//! catches up and releases it), and the output's acceleration torque `J_s·ω̇` holds at the load
//! less that braking. A lag starts when the output falls behind on the counters and on the
//! observer's speed, and lasts until it overtakes the input; it arms once `J_s·ω̇` has held
//! still for the persistence time (the observer still tracking an engagement's braking is no
//! reference). A lag from a level run of the persistence time (the output tracking its input,
//! the pack holding the load) arms at once on that run's `J_s·ω̇`: falling behind opens the
//! ramps. A fall of `J_s·ω̇` by more than the drag allowance for the persistence time is
//! then a pack that drags. This is where the drive checks see nothing: the paper reading's
//! continuous closing, whose drive leads the door with no torque at all.
//!
//! | quantity | format | range | resolution |
//! |---|---|---|---|
//! | `J_s·ω̇` along the motion, its reference | [`Q16`] N·m, saturating | ±32 768 N·m | 1.5e-5 N·m |
//! | lag and fall counts | `u32` ticks, saturating | 0 … 2^32 − 1 | 0.1 ms |
//! | level run | `u8` calls, saturating | 0 … 255 (102 ms) | 0.4 ms |

use super::drive::{follow, DriveSettings};
use crate::fx::Q16;
use crate::monitor::pack::Dir;
use crate::monitor::schedule::SLOW;

/// What the check reads of one slow-lane call.
pub(crate) struct LagTick {
    /// The output's direction of motion (±1).
    pub dir: Dir,
    /// The input gained on the output beyond the synchronism band over the last window, on the
    /// counters (the observer's speed lags a transient).
    pub lagging: bool,
    /// Output speed and the input's (rad/s): the observer's lag beyond the stick speed too (the
    /// counters' window alone reads a physical chatter's throw-backs as lagging).
    pub output_speed: Q16,
    pub input_speed: Q16,
    pub stick_speed: Q16,
    /// `J_s·ω̇` (N·m): the observer's net torque plus the drive torque, free of the current
    /// reading once the observer has settled.
    pub accel_torque: Q16,
    /// The output counter: a counter that stands still is left to the stuck-counter check.
    pub out: u32,
    /// Ticks since the previous call.
    pub ticks: u32,
}

/// The check's state.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Lagging {
    /// `J_s·ω̇` along the motion while the output lagged and did not fall (followed).
    reference: Q16,
    /// Ticks the lag has lasted since its reference last moved (0: no lag); armed past the
    /// persistence time.
    lag_ticks: u32,
    /// Ticks `J_s·ω̇` has stayed below the reference by the allowance with the output moving.
    fall_ticks: u32,
    dir: Dir,
    out: u32,
    /// Calls since the output counter last moved.
    still_calls: u8,
    /// Calls the output has run level with its input (neither lagging nor ahead), `reference`
    /// following `J_s·ω̇` meanwhile.
    level_calls: u8,
}

/// Calls the output counter may stand still and the fall still count (1.2 ms: ≥ 1 count at
/// 0.3 rad/s, the stick speed; a stuck counter adds at most this to the count).
const STILL_CALLS: u8 = 3;

impl Lagging {
    /// The drive is off, the output stopped, or a reading is unsettled.
    #[inline]
    pub fn disarm(&mut self) {
        *self = Lagging::default();
    }

    /// One call with the drive on and the output moving; returns whether the pack drags.
    #[inline(never)]
    pub fn sample(&mut self, p: &DriveSettings, t: &LagTick) -> bool {
        let lag = t.dir.apply(t.input_speed.saturating_sub(t.output_speed));
        // A lag starts on both readings and lasts until the output overtakes its input.
        let started = self.lag_ticks > 0;
        let starts = t.lagging && lag > t.stick_speed;
        let ahead = lag < t.stick_speed.saturating_neg();
        let along = t.dir.apply(t.accel_torque);
        if t.dir != self.dir || ahead || !(started || starts) {
            // Level with its input: its `J_s·ω̇` is followed as a lag's reference.
            let level = (t.dir == self.dir && !ahead).then(|| match self.level_calls {
                0 => (along, 1),
                n => (
                    follow(self.reference, along, p.reference_shift()),
                    n.saturating_add(1),
                ),
            });
            *self = Lagging {
                dir: t.dir,
                out: t.out,
                ..Lagging::default()
            };
            if let Some(run) = level {
                (self.reference, self.level_calls) = run;
            }
            return false;
        }
        self.still_calls = if t.out == self.out {
            self.still_calls.saturating_add(1)
        } else {
            0
        };
        self.out = t.out;
        let counted = SLOW.covered(t.ticks);
        // A lag after a level run of the persistence time (its calls × ticks per call: no
        // division) arms at once, on the run's `J_s·ω̇`.
        let level_run = u32::from(self.level_calls).saturating_mul(SLOW.ticks);
        if self.lag_ticks == 0 && level_run > p.persistence_ticks() {
            self.lag_ticks = p.persistence_ticks().saturating_add(1);
        }
        let armed = self.lag_ticks > p.persistence_ticks();
        // Arming waits for `J_s·ω̇` to hold still: an engagement's braking the observer is
        // still tracking when the output falls behind would read as a fall.
        let settling = along.saturating_sub(self.reference).saturating_abs() > p.settle_band();
        if !armed && (self.lag_ticks == 0 || settling) {
            (self.reference, self.lag_ticks) = (along, 0);
        }
        self.lag_ticks = self.lag_ticks.saturating_add(counted);
        if armed && along < self.reference.saturating_sub(p.drag_allowance()) {
            if self.still_calls < STILL_CALLS {
                self.fall_ticks = self.fall_ticks.saturating_add(counted);
            }
        } else {
            self.fall_ticks = 0;
            self.reference = follow(self.reference, along, p.reference_shift());
        }
        self.fall_ticks >= p.persistence_ticks()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::monitor::settings::Settings;
    use crate::monitor::Config;

    fn params() -> DriveSettings {
        Settings::new(&Config::default())
            .expect("default configuration")
            .checks
            .drive
    }

    /// A call's reading: the input at 10 rad/s, the output at `output`, the counters reading a
    /// lag or not, `J_s·ω̇` at `accel` N·m, the output counter at `out`.
    fn tick(lagging: bool, output: f64, accel: f64, out: u32) -> LagTick {
        LagTick {
            dir: Dir::of(Q16::ONE, Q16::ZERO),
            lagging,
            output_speed: Q16::from_num(output),
            input_speed: Q16::from_num(10.0),
            stick_speed: Q16::from_num(0.3),
            accel_torque: Q16::from_num(accel),
            out,
            ticks: 1,
        }
    }

    /// One call: the output lagging its input (at 5 rad/s) or ahead of it (at 15), `J_s·ω̇` at
    /// `accel` N·m; the output counter advances by `step` counts a call.
    fn call(check: &mut Lagging, p: &DriveSettings, lagging: bool, accel: f64, step: u32) -> bool {
        let output = if lagging { 5.0 } else { 15.0 };
        let out = check.out.wrapping_add(step);
        check.sample(p, &tick(lagging, output, accel, out))
    }

    /// One call with the output at `output` rad/s, counters reading a lag or not, `J_s·ω̇` at
    /// `accel` N·m.
    fn at_speed(
        check: &mut Lagging,
        p: &DriveSettings,
        lagging: bool,
        output: f64,
        accel: f64,
    ) -> bool {
        let out = check.out.wrapping_add(5);
        check.sample(p, &tick(lagging, output, accel, out))
    }

    /// Calls covering the persistence time, plus one.
    fn persistence_calls(p: &DriveSettings) -> u32 {
        p.persistence_ticks() / SLOW.ticks + 1
    }

    #[test]
    fn a_fall_past_the_allowance_while_the_output_lags_is_a_drag_and_a_smaller_one_is_not() {
        let p = params();
        let allowance = p.drag_allowance().to_num::<f64>();
        for (fall, drag) in [(allowance + 1.0, true), (allowance - 1.0, false)] {
            let mut check = Lagging::default();
            // The output lags, accelerated by the load less the spring's drag.
            for _ in 0..2 * persistence_calls(&p) {
                assert!(!call(&mut check, &p, true, 10.0, 5));
            }
            let raised =
                (0..persistence_calls(&p)).any(|_| call(&mut check, &p, true, 10.0 - fall, 5));
            assert_eq!(raised, drag, "fall {fall} N·m");
        }
    }

    #[test]
    fn an_engagement_that_began_before_the_output_fell_behind_is_no_drag() {
        // The ramps engage as the output overtakes the input and brake it below the input's
        // speed: the lag starts with the output already braked, and its release is a rise.
        let p = params();
        let mut check = Lagging::default();
        assert!(!call(&mut check, &p, false, -30.0, 20));
        for _ in 0..4 * persistence_calls(&p) {
            assert!(!call(&mut check, &p, true, -30.0, 10));
        }
        for _ in 0..4 * persistence_calls(&p) {
            assert!(!call(&mut check, &p, true, 10.0, 5));
        }
    }

    #[test]
    fn a_lag_on_the_counters_alone_or_the_observer_alone_is_no_lag() {
        // A physical chatter's throw-backs read as lagging on one window's counters; an observer
        // seeded at power-on lags an accelerating door. Either alone arms nothing.
        let p = params();
        for (counters, output) in [(true, 9.8), (false, 5.0)] {
            let mut check = Lagging::default();
            let raised = (0..4 * persistence_calls(&p)).any(|k| {
                let accel = if k < persistence_calls(&p) {
                    10.0
                } else {
                    -30.0
                };
                check.sample(&p, &tick(counters, output, accel, k * 5))
            });
            assert!(!raised, "counters {counters}, output {output} rad/s");
        }
    }

    #[test]
    fn a_standing_output_counter_is_left_to_the_stuck_counter_check() {
        // A counter stuck mid-motion: the observer sees the output brake hard, the counter
        // does not move, and the fall counts for at most `STILL_CALLS` calls.
        let p = params();
        let mut check = Lagging::default();
        for _ in 0..2 * persistence_calls(&p) {
            call(&mut check, &p, true, 10.0, 5);
        }
        for _ in 0..4 * persistence_calls(&p) {
            assert!(!call(&mut check, &p, true, -60.0, 0));
        }
        assert!(check.fall_ticks <= SLOW.covered(u32::from(STILL_CALLS)));
    }

    #[test]
    fn a_lag_begun_while_the_observer_still_tracks_a_braking_arms_once_it_holds_still() {
        // The ramps brake the output below the input's speed, `J_s·ω̇` still settling 1 N·m
        // a call: no reference until it holds; a fall from where it settles is a drag.
        let p = params();
        let mut check = Lagging::default();
        for k in 0..20 {
            assert!(
                !call(&mut check, &p, true, -40.0 - f64::from(k), 5),
                "call {k}"
            );
        }
        for _ in 0..2 * persistence_calls(&p) {
            assert!(!call(&mut check, &p, true, -60.0, 5));
        }
        let allowance = p.drag_allowance().to_num::<f64>();
        let raised =
            (0..persistence_calls(&p)).any(|_| call(&mut check, &p, true, -61.0 - allowance, 5));
        assert!(raised);
    }

    #[test]
    fn a_fall_behind_a_level_run_is_a_drag_at_once_and_behind_a_passing_level_waits() {
        // The output tracks its input (`J_s·ω̇` ≈ 0) until a drag brakes it behind: the run's
        // `J_s·ω̇` is the reference. An output only passing level (from ahead) sets none.
        let p = params();
        let allowance = p.drag_allowance().to_num::<f64>();
        for (level_calls, drag) in [(2 * persistence_calls(&p), true), (3, false)] {
            let mut check = Lagging::default();
            for _ in 0..level_calls {
                assert!(!at_speed(&mut check, &p, false, 10.0, 0.0));
            }
            let raised = (0..persistence_calls(&p))
                .any(|_| at_speed(&mut check, &p, true, 9.0, -1.0 - allowance));
            assert_eq!(raised, drag, "{level_calls} level calls");
        }
    }

    #[test]
    fn a_lag_lasts_until_the_output_overtakes_its_input() {
        // The output draws level with its input (the counters' band no longer reads a lag)
        // as the drag strikes: the lag holds, and the fall is a drag; once the output is
        // ahead, the lag is over and the same fall is an engagement.
        let p = params();
        let allowance = p.drag_allowance().to_num::<f64>();
        for (output, drag) in [(9.9, true), (10.5, false)] {
            let mut check = Lagging::default();
            for _ in 0..2 * persistence_calls(&p) {
                assert!(!at_speed(&mut check, &p, true, 8.0, 10.0));
            }
            let raised = (0..persistence_calls(&p))
                .any(|_| at_speed(&mut check, &p, false, output, 9.0 - allowance));
            assert_eq!(raised, drag, "output at {output} rad/s");
        }
    }
}
