//! The pack carries an overrunning load (`brake_degraded`, a warning): with the drive on and
//! the shafts turning together, a healthy no-back brakes a load that runs along the motion, so
//! the drive pushes along the motion to unlock it. A drive that instead holds the motion back,
//! on the mean over a block of one direction, carries a load the pack let through: the pack may
//! not hold once the drive lets go. (In engagement chatter the output is thrown back against a
//! pushing drive, but the input does not follow it: such samples restart the block.)
//!
//! | quantity | format | range | resolution |
//! |---|---|---|---|
//! | drive torque along the motion | [`Q16`] N·m bits summed, saturating | ±2^31 bits | 1.5e-5 N·m |
//! | the block's held-back sum | `i32` Q16 N·m bits (`new` rejects beyond) | −2^31 … 0 | 1.5e-5 N·m |
//! | block | `u16` slow-lane calls | 1 … 2^16 − 1 | 0.4 ms |

use crate::fx::Q16;
use crate::monitor::config::{Config, ConfigError};
use crate::monitor::convert::{positive, q16, require};
use crate::monitor::pack::Dir;
use crate::monitor::schedule::SLOW;

/// The check's constants.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct OverrunningSettings {
    /// `−held_back_torque_nm · block` (Q16 bits): a block summing below it held the motion back.
    held_back_sum: i32,
    /// Slow-lane calls per block.
    block: u16,
}

impl OverrunningSettings {
    pub fn new(c: &Config) -> Result<OverrunningSettings, ConfigError> {
        let t = &c.thresholds;
        let limit = q16(
            positive(t.held_back_torque_nm, "thresholds.held_back_torque_nm")?,
            "thresholds.held_back_torque_nm",
        )?;
        let calls = positive(t.held_back_time_s, "thresholds.held_back_time_s")? * c.tick_hz
            / f64::from(SLOW.ticks);
        require(
            (1.0..f64::from(u16::MAX)).contains(&calls),
            "thresholds.held_back_time_s",
        )?;
        // 1 ≤ calls < 2^16 (checked above).
        let block = (calls + 0.5) as u16;
        let held_back_sum =
            i32::try_from(-i64::from(limit.to_bits()) * i64::from(block)).map_err(|_| {
                ConfigError::Overflow {
                    parameter: "thresholds.held_back_torque_nm",
                }
            })?;
        Ok(OverrunningSettings {
            held_back_sum,
            block,
        })
    }
}

/// The block being summed.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Overrunning {
    /// Σ drive torque along the motion (Q16 bits).
    sum: i32,
    calls: u16,
    /// The block's direction of motion.
    dir: Dir,
}

impl Overrunning {
    /// The output stopped, the drive is off, or a reading is unsettled: the block starts afresh.
    pub fn disarm(&mut self) {
        *self = Overrunning::default();
    }

    /// One call with the drive on and the output moving in `dir` (`input`: the input shaft's
    /// direction; `along`: the drive torque along the motion). Returns whether the block it
    /// ends held the motion back.
    pub fn sample(&mut self, k: &OverrunningSettings, dir: Dir, input: Dir, along: Q16) -> bool {
        if dir != self.dir || input != dir {
            *self = Overrunning {
                dir,
                ..Overrunning::default()
            };
            return false;
        }
        self.sum = self.sum.saturating_add(along.to_bits());
        self.calls = self.calls.saturating_add(1);
        if self.calls < k.block {
            return false;
        }
        // Mean below −limit, without a division: Σ < −limit·n.
        let held_back = self.sum < k.held_back_sum;
        self.disarm();
        held_back
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A first call to set the direction, then one block of `input` and `along_nm`.
    fn block_of(k: &OverrunningSettings, input: Dir, along_nm: f64) -> bool {
        let (mut check, dir, along) = (
            Overrunning::default(),
            Dir::of(Q16::ONE, Q16::ZERO),
            Q16::from_num(along_nm),
        );
        check.sample(k, dir, input, along);
        (0..k.block).any(|_| check.sample(k, dir, input, along))
    }

    #[test]
    fn a_drive_that_holds_the_motion_back_beyond_the_limit_is_called_at_the_block_end() {
        let c = Config::default();
        let k = OverrunningSettings::new(&c).expect("default configuration");
        let (limit, with) = (
            c.thresholds.held_back_torque_nm,
            Dir::of(Q16::ONE, Q16::ZERO),
        );
        assert!(block_of(&k, with, -limit - 0.1));
        assert!(!block_of(&k, with, -limit + 0.1));
        // A healthy overrunning drive pushes along the motion.
        assert!(!block_of(&k, with, 2.0));
        // The output thrown back while the input stands: no block.
        assert!(!block_of(&k, Dir::NONE, -limit - 10.0));
    }
}
