//! A dead current reading while the drive runs (`sensor_fault`): the output turns with the drive
//! on, its pack holding it now and then, and the current reads (almost) nothing.
//!
//! Why it holds: a no-back moves only under its drive's torque while its pack works. Against
//! the load the drive carries the load and the pack's spring drag; with the load along the
//! motion (overrunning) the ramps lock the output unless the drive keeps the input shaft
//! ahead, pushing. So with the drive on, the output turning and the pack seen holding it
//! lately (the lock of an overrunning chatter), the drive torque averaged over a block of
//! [`BLOCK_WINDOWS`] samples, one per 16 ticks (12.8 ms at 10 kHz), stays well above zero, even
//! in continuous closing's chatter, where the drive torque passes through zero for up to ≈ 10 ms
//! of each cycle (the margin: `cargo run --release -p host-tests --example dead_current_margin`,
//! docs/decisions.md). A reading that has lost (nearly) all its gain averages what is left of it
//! plus the magnitude of its noise. The step check (`drive.rs`) sees
//! a gain loss of any size as a step against a steady history; in continuous closing's
//! chatter that history never forms (the shafts do not stay synchronous for 0.1 s), and this
//! check is what is left there — it sees only a reading that is dead or nearly so
//! (docs/monitor-design.md, "A dead current reading"). A pack that cannot hold is the other
//! way an output turns with no drive torque (an overrunning load runs it): that output never
//! stands still, so a block is judged only if the pack held the output (stood it still, or
//! threw it back) within the last [`HOLD_MEMORY_WINDOWS`].
//!
//! Runs on the window lane's `DeadCurrent` slot (one tick in 16 with the drive on), out of
//! line: one sample of the drive torque and the output's travel since the last one per call.
//! The first block after the drive starts only arms it (the drive's start is not judged).
//!
//! Assumptions: the drive produces torque whenever it is commanded on (a speed or position
//! loop). A drive flagged on that commands no torque while the door coasts and rattles in its
//! lost motion would read as dead; so would a pack with a broken spring driven against a load
//! near zero (the caller skips a known load below the spring drag). A pack that fails within
//! the hold memory after its last lock, with the drive on and an overrunning load, would be
//! called a dead reading for up to 51 ms before it is called a brake failure at the cut.
//!
//! | quantity | format | range | resolution |
//! |---|---|---|---|
//! | drive torque sum | [`Q16`] N·m, saturating | 0 … 32 768 N·m (8 magnitudes ≤ 324 N·m at the ADC's rails) | 1.5e-5 N·m |
//! | output travel sum | `i32` counts, saturating | ±2^31 counts (8 windows ≤ 2000 counts at the plausible speed) | 1 count |

use crate::fx::{counter_delta, Q16};
use crate::monitor::config::{Config, ConfigError};
use crate::monitor::convert::{counts, finite, positive, q16, require};
use crate::monitor::pack::PackRatios;
use crate::monitor::schedule::WINDOW;

/// The dead-reading check's constants.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct DeadCurrentSettings {
    out_bits: u8,
    /// `dead_current_nm` × the block's samples: the drive-torque sum below which a block
    /// reads dead (N·m).
    drive_sum: Q16,
    /// `dead_current_speed_rad_s` as the output's travel summed over the block (counts).
    travel_sum: i32,
}

impl DeadCurrentSettings {
    /// Whether the check runs (`dead_current_nm` > 0): off, it has nothing to find.
    #[inline]
    pub fn on(&self) -> bool {
        self.drive_sum > Q16::ZERO
    }

    pub fn new(c: &Config, r: &PackRatios) -> Result<DeadCurrentSettings, ConfigError> {
        let t = &c.thresholds;
        let block = f64::from(BLOCK_WINDOWS);
        // 0 turns the check off (a sum of magnitudes is never below 0). Below the spring drag a
        // moving no-back's drive always carries.
        let dead = finite(t.dead_current_nm, "thresholds.dead_current_nm")?;
        require(dead >= 0.0, "thresholds.dead_current_nm")?;
        require(dead < r.drive_drag_nm, "thresholds.dead_current_nm")?;
        let speed = positive(
            t.dead_current_speed_rad_s,
            "thresholds.dead_current_speed_rad_s",
        )?;
        Ok(DeadCurrentSettings {
            out_bits: c.sensors.output_encoder_bits,
            drive_sum: q16(dead * block, "thresholds.dead_current_nm")?,
            travel_sum: counts(
                speed * f64::from(WINDOW.ticks) * (1.0 / c.tick_hz)
                    / c.sensors.output_rad_per_count()
                    * block,
                "thresholds.dead_current_speed_rad_s",
            )?,
        })
    }
}

/// Synchronism windows per block: 8 × 16 ticks = 12.8 ms at 10 kHz, longer than the drive
/// torque's passes through zero in overrunning chatter (≈ 10 ms), short enough that a dead
/// reading is called within two blocks.
pub(crate) const BLOCK_WINDOWS: u8 = 8;

/// State of the dead-reading check: the block being summed, and when the pack last held.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug)]
pub(crate) struct DeadCurrent {
    /// Sum of the drive torque's magnitude over the block's samples (N·m).
    drive_sum: Q16,
    /// Sum of the output's travel magnitude over the block's windows (counts).
    travel_sum: i32,
    /// Windows summed in this block (0..BLOCK_WINDOWS).
    windows: u8,
    /// A whole block has passed since the drive started: blocks are judged from now on.
    armed: bool,
    /// Output counter at the last window's end.
    out: u32,
    /// Direction of the output's last travel (−1, 0 before any, 1).
    dir: i32,
    /// Windows since the pack last held the output (saturating; `u8::MAX`: not seen).
    since_hold: u8,
}

/// Windows within which the pack must have been seen holding the output (standing still or
/// thrown back within a window) for a block to be judged: 32 × 1.6 ms = 51 ms, most of a
/// heavy chatter's cycle (≈ 60 ms in the twin: `monitor_chatter.rs`).
pub(crate) const HOLD_MEMORY_WINDOWS: u8 = 32;

/// Travel within a window (counts) that counts as the output standing still: one count of
/// the output encoder (0.24 rad/s over 1.6 ms at 14 bits).
const STILL_COUNTS: i32 = 1;

impl Default for DeadCurrent {
    fn default() -> Self {
        DeadCurrent {
            drive_sum: Q16::ZERO,
            travel_sum: 0,
            windows: 0,
            armed: false,
            out: 0,
            dir: 0,
            since_hold: u8::MAX,
        }
    }
}

impl DeadCurrent {
    /// Forgets the block and the pack's last hold, and disarms; the next window starts at
    /// the output counter `out_now` (a drive edge).
    #[inline]
    pub fn disarm(&mut self, out_now: u32) {
        *self = DeadCurrent {
            out: out_now,
            ..DeadCurrent::default()
        };
    }

    /// One window, closed at the output counter `out_now`: `drive` the drive torque sampled now
    /// (N·m, either sign); the output's travel over the window (counts, either sign) is the
    /// counter's wrapping difference. True when a block
    /// ends with the output turning (`dead_travel_sum`), the mean drive torque below
    /// `thresholds.dead_current_nm` (`dead_drive_sum`), and the pack seen holding the output
    /// within the last [`HOLD_MEMORY_WINDOWS`]: a pack that holds is what makes the drive's
    /// torque necessary. A pack that cannot hold lets an overrunning load run the output with
    /// no drive torque at all — a brake failure, not a sensor's, and the output then never
    /// stands still. The caller adds the load condition.
    #[inline(never)]
    pub fn window(&mut self, drive: Q16, out_now: u32, p: &DeadCurrentSettings) -> bool {
        let travel = counter_delta(self.out, out_now, p.out_bits);
        self.out = out_now;
        let thrown_back = travel.signum() * self.dir < 0; // both in {−1, 0, 1}
        self.since_hold = if travel.saturating_abs() <= STILL_COUNTS || thrown_back {
            0
        } else {
            self.since_hold.saturating_add(1)
        };
        if travel != 0 {
            self.dir = travel.signum();
        }
        self.drive_sum = self.drive_sum.saturating_add(drive.saturating_abs());
        self.travel_sum = self.travel_sum.saturating_add(travel.saturating_abs());
        self.windows = self.windows.saturating_add(1);
        if self.windows < BLOCK_WINDOWS {
            return false;
        }
        let dead = self.armed
            && self.since_hold < HOLD_MEMORY_WINDOWS
            && self.drive_sum < p.drive_sum
            && self.travel_sum > p.travel_sum;
        self.drive_sum = Q16::ZERO;
        self.travel_sum = 0;
        self.windows = 0;
        self.armed = true;
        dead
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::monitor::Config;

    fn params() -> DeadCurrentSettings {
        match crate::monitor::settings::Settings::new(&Config::physical_reading())
            .map(|s| s.checks.dead_current)
        {
            Ok(p) => p,
            Err(e) => panic!("defaults: {e:?}"),
        }
    }

    /// 2 rad/s over a 1.6 ms window is 8.3 counts of the 14-bit encoder: 20 counts turn.
    const TURNING: i32 = 20;

    /// The check and the output counter it reads (14 bits, starting near its wrap).
    struct Check {
        d: DeadCurrent,
        out: u32,
        p: DeadCurrentSettings,
    }

    impl Check {
        fn new() -> Check {
            let out = 16_300;
            let mut d = DeadCurrent::default();
            d.disarm(out);
            Check {
                d,
                out,
                p: params(),
            }
        }

        /// One window: the output travels `travel` counts, the drive torque is `drive_nm`.
        fn window(&mut self, drive_nm: f64, travel: i32) -> bool {
            self.out = self.out.wrapping_add_signed(travel) & 0x3FFF;
            self.d.window(Q16::from_num(drive_nm), self.out, &self.p)
        }

        /// Whole blocks of windows, the drive torque `drive_nm` in each; the output travels
        /// `travel` counts per window, except that its first window in each block stands
        /// still when `held` (the pack holding it: a chatter's lock). Each block's verdict.
        fn blocks(&mut self, drive_nm: f64, travel: i32, held: bool, n: usize) -> [bool; 4] {
            let mut out = [false; 4];
            for slot in out.iter_mut().take(n) {
                for w in 0..BLOCK_WINDOWS {
                    let t = if held && w == 0 { 0 } else { travel };
                    *slot = self.window(drive_nm, t);
                }
            }
            out
        }
    }

    #[test]
    fn a_dead_reading_with_the_output_turning_in_chatter_is_called_from_the_second_block() {
        // Across the output counter's wrap, too.
        let mut c = Check::new();
        assert_eq!(c.blocks(0.02, TURNING, true, 3), [false, true, true, false]);
    }

    #[test]
    fn either_sign_of_torque_and_travel_counts_and_a_throw_back_is_a_hold() {
        let mut c = Check::new();
        assert_eq!(c.blocks(-1.0, -TURNING, true, 2), [false; 4]);
        // The output thrown back (a rebound after the pack clamped) is the pack holding too.
        let mut last = false;
        for w in 0..BLOCK_WINDOWS {
            let t = if w == 3 { 2 * TURNING } else { -TURNING };
            last = c.window(-0.1, t);
        }
        assert!(last);
    }

    #[test]
    fn a_live_reading_or_a_still_output_is_not_dead() {
        let mut c = Check::new();
        // Above the 0.5 N·m default: healthy chatter's lowest block mean is 1.42 N·m.
        assert_eq!(c.blocks(0.6, TURNING, true, 3), [false; 4]);
        // Output still (a stall, or the drive's start): not judged.
        assert_eq!(c.blocks(0.0, 1, true, 3), [false; 4]);
    }

    #[test]
    fn an_output_the_pack_never_holds_is_a_brake_failure_not_a_dead_reading() {
        // An overrunning load running the output with no drive torque because the pack cannot
        // hold: the output never stands still.
        let mut c = Check::new();
        assert_eq!(c.blocks(0.0, TURNING, false, 4), [false; 4]);
        // Held once, then never again for longer than the memory: judged only within it.
        let mut c = Check::new();
        assert_eq!(c.blocks(0.0, TURNING, true, 1), [false; 4]);
        let per_block = usize::from(BLOCK_WINDOWS);
        let within = usize::from(HOLD_MEMORY_WINDOWS) / per_block;
        let mut verdicts = [false; 8];
        for v in verdicts.iter_mut().take(within + 2) {
            *v = c.blocks(0.0, TURNING, false, 1)[0];
        }
        assert!(verdicts.iter().take(within - 1).all(|v| *v), "{verdicts:?}");
        assert!(verdicts.iter().skip(within).all(|v| !*v), "{verdicts:?}");
    }

    #[test]
    fn disarm_restarts_the_block_and_the_arming() {
        let mut c = Check::new();
        c.blocks(0.0, TURNING, true, 1);
        for _ in 0..3 {
            c.window(0.0, TURNING);
        }
        c.d.disarm(c.out);
        assert_eq!(c.blocks(0.0, TURNING, true, 2), [false, true, false, false]);
    }

    #[test]
    fn the_drive_torque_sum_saturates_rather_than_wrapping_into_a_dead_verdict() {
        let mut c = Check::new();
        c.blocks(1.0, TURNING, true, 1);
        let mut last = true;
        for w in 0..BLOCK_WINDOWS {
            let t = if w == 0 { 0 } else { TURNING };
            c.out = c.out.wrapping_add_signed(t) & 0x3FFF;
            last = c.d.window(Q16::MIN, c.out, &c.p);
        }
        assert!(!last, "|Q16::MIN| saturates to the maximum: a live reading");
    }
}
