//! The current reading against the drive's own command (`sensor_fault`): the drive's current
//! loop closes on its own sensing, so the current it commands is the current that flows; a
//! reading that has lost part of its gain reads less than the command whatever the load.
//!
//! Runs every tick with the drive on, only when the inputs carry the command
//! (`Inputs::current_command_code`; without it, nothing changes). Over a block of
//! [`BLOCK_TICKS`] samples, those whose command is at least the floor are summed: `S_c = Σ|c|`
//! and `S_m = Σ m·sgn(c)` (`m` the reading about its commissioned zero). The block is bad when
//! `|S_m − S_c| > tolerance·S_c` with at least half its samples used.
//!
//! Assumption: the command is the loop's reference and the loop follows it within a sample
//! (a 1 kHz current loop lags 0.16 ms). A drive whose loop closes on the monitor's own sensor
//! makes command and reading equal: the check then sees nothing (docs/monitor-limits.md).
//!
//! | quantity | format | range | resolution |
//! |---|---|---|---|
//! | command, reading | `i32` ADC counts about zero current | ±2^15 | 1 count |
//! | sums over a block | `i32` counts | 16 × 2^15 | 1 count |
//! | shortfall of the reading against the command | `i32` counts, exact | ±2^17 | 1 count |
//! | tolerance | `i64` product with `S_c` in Q16 | exact | 1.5e-5 |

use crate::monitor::config::{Config, ConfigError};
use crate::monitor::convert::{finite, require};
use crate::monitor::schedule::WINDOW;

/// Samples per block: every tick of one [`WINDOW`], 1.6 ms at 10 kHz. Ten time constants of a
/// 1 kHz current loop, so its lag after a step weighs ≤ 10 % of a block; a gain lost on a drive
/// cut within milliseconds is still called.
pub(crate) const BLOCK_TICKS: u8 = WINDOW.ticks as u8;
const _: () = assert!(WINDOW.ticks <= u8::MAX as u32, "a block's count is a u8");

/// The command check's constants.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct CommandSettings {
    /// The ADC code at zero commanded current (the converter's mid-scale).
    zero_code: i32,
    /// Smallest |command| that is summed (counts).
    floor: i32,
    /// `command_gain_tolerance` in Q16 (0: off).
    tolerance_q16: i64,
}

impl CommandSettings {
    /// The command's code as counts about zero current (|c| < 2^16).
    #[inline]
    fn counts(&self, command_code: u16) -> i32 {
        i32::from(command_code) - self.zero_code
    }

    /// How far the reading `current` falls short of the command `command_code` along the
    /// command (counts; negative when it reads more). Both are below 2^16: no overflow.
    #[inline]
    pub fn shortfall(&self, current: i32, command_code: u16) -> i32 {
        let c = self.counts(command_code);
        if c < 0 {
            current - c
        } else {
            c - current
        }
    }

    pub fn new(c: &Config) -> Result<CommandSettings, ConfigError> {
        let t = &c.thresholds;
        let tol = finite(
            t.command_gain_tolerance,
            "thresholds.command_gain_tolerance",
        )?;
        require(
            (0.0..1.0).contains(&tol),
            "thresholds.command_gain_tolerance",
        )?;
        let floor =
            finite(t.command_floor_a, "thresholds.command_floor_a")? / c.sensors.amps_per_count();
        let bits = c.sensors.current_adc_bits;
        require((4..=16).contains(&bits), "sensors.current_adc_bits")?;
        require(
            floor >= 1.0 && floor < f64::from(1_u32 << (bits - 1)),
            "thresholds.command_floor_a",
        )?;
        Ok(CommandSettings {
            zero_code: 1 << (bits - 1),
            // 1 ≤ floor < 2^15 (checked above).
            floor: floor as i32,
            tolerance_q16: (tol * 65_536.0) as i64,
        })
    }
}

/// The block being summed.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct CommandCheck {
    command_sum: i32,
    reading_sum: i32,
    samples: u8,
    used: u8,
}

impl CommandCheck {
    /// The drive started or stopped: the next block starts afresh.
    pub fn disarm(&mut self) {
        *self = CommandCheck::default();
    }

    /// One tick's sample: the reading `current` (counts about its commissioned zero) and the
    /// command's code. Returns whether the block it ends reads off the command.
    pub fn sample(&mut self, k: &CommandSettings, current: i32, command_code: u16) -> bool {
        if k.tolerance_q16 == 0 {
            return false;
        }
        let c = k.counts(command_code);
        if c.saturating_abs() >= k.floor {
            // |c|, |current| < 2^16 and 16 samples: the sums cannot overflow.
            self.command_sum = self.command_sum.saturating_add(c.saturating_abs());
            self.reading_sum =
                self.reading_sum
                    .saturating_add(if c > 0 { current } else { -current });
            self.used = self.used.saturating_add(1);
        }
        self.samples = self.samples.saturating_add(1);
        if self.samples < BLOCK_TICKS {
            return false;
        }
        let (s_c, s_m) = (i64::from(self.command_sum), i64::from(self.reading_sum));
        let bad = self.used >= BLOCK_TICKS / 2 && (s_m - s_c).abs() << 16 > k.tolerance_q16 * s_c;
        self.disarm();
        bad
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Default sensors: 12 bits, mid-scale 2048, 30 A full scale (≈ 68 counts per A).
    fn settings() -> CommandSettings {
        CommandSettings::new(&Config::default()).unwrap()
    }

    /// One block of `BLOCK_TICKS` samples, each commanding `c` counts about mid-scale and
    /// reading `gain·c + offset`; whether the block is called off.
    fn block(k: &CommandSettings, c: i32, gain: f64, offset: i32) -> bool {
        let mut check = CommandCheck::default();
        let reading = (gain * f64::from(c)) as i32 + offset;
        let code = (2048 + c) as u16;
        for _ in 1..BLOCK_TICKS {
            assert!(
                !check.sample(k, reading, code),
                "only the block's end decides"
            );
        }
        check.sample(k, reading, code)
    }

    #[test]
    fn a_reading_off_its_command_by_more_than_the_tolerance_is_called() {
        let k = settings();
        for c in [400, -400] {
            assert!(!block(&k, c, 1.0, 0), "healthy {c}");
            assert!(!block(&k, c, 0.8, 10), "gain 0.8 {c}");
            assert!(block(&k, c, 0.5, 0), "half the gain {c}");
            assert!(block(&k, c, 0.0, 0), "dead {c}");
            assert!(block(&k, c, 1.5, 0), "reading high {c}");
        }
    }

    #[test]
    fn commands_below_the_floor_and_the_check_off_call_nothing() {
        let k = settings();
        assert!(
            !block(&k, 100, 0.0, 0),
            "2.5 A floor ≈ 171 counts: 100 is below"
        );
        let off = CommandSettings {
            tolerance_q16: 0,
            ..k
        };
        assert!(!block(&off, 400, 0.0, 0));
    }
}
