//! One schedule: every rate the monitor runs at, named once, and the slot of each tick.
//!
//! Two priorities. The **tick** (`Config::tick_hz`, 10 kHz by default, the interrupt) senses
//! and observes. The **background**, after every tick at a lower priority, runs that tick's
//! events, per-tick checks (braking envelope, creep) and the pack torque the observer's model
//! feeds forward, then the **slow lane** ([`SLOW`], 2.5 kHz), one part per slot, so that no
//! background carries two of the costly parts, and last, with the drive on and its command
//! given, the command check's sample:
//!
//! | slot (tick mod 4) | work | module |
//! |---|---|---|
//! | 0 [`Slot::Classify`] | scene; load filter or pack health; once per [`WINDOW`] the load cache | `scene`, `load` |
//! | 1 [`Slot::Estimate`] | the reported estimate at the classification, input speed, friction energy | `estimate`, `sense` |
//! | 2 [`Slot::Checks`] | capacity margin, common slip (drive off), drive checks (drive on) | `checks` |
//! | 3, by [`WINDOW`] (625 Hz): 7 / 15 | synchronism window / dead-current block (drive on) | `scene`, `checks` |
//!
//! After every slot's work, while the crew has requested it, the functional test ([`EVERY_TICK`]).
//! The braking model (`tick_hz / braking_model_hz`) steps on odd ticks. A lane's filter gains
//! and persistence counts are those of its own rate: each part counts the ticks it covers.

/// A lane: periodic work every `ticks` ticks (a power of two, so the slot is a mask).
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Lane {
    /// Ticks between two runs.
    pub ticks: u32,
}

impl Lane {
    /// The slot (0..ticks) `tick` falls on.
    #[inline]
    pub const fn slot(self, tick: u32) -> u32 {
        tick & (self.ticks - 1)
    }

    /// Ticks one run covers when `n` ticks elapsed since the last call (saturating).
    #[inline]
    pub const fn covered(self, n: u32) -> u32 {
        n.saturating_mul(self.ticks)
    }
}

/// The slow lane: 2.5 kHz at 10 kHz.
pub const SLOW: Lane = Lane { ticks: 4 };
/// Every tick, in the slow lane's context: the commanded functional test, while requested.
pub const EVERY_TICK: Lane = Lane { ticks: 1 };
/// The window lane: 625 Hz at 10 kHz (1.6 ms windows).
pub const WINDOW: Lane = Lane { ticks: 16 };

/// What slow-lane work a tick carries.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slot {
    /// The scene, the load filter (drive on) or pack health (drive off).
    Classify,
    /// The reported estimate, input speed and friction energy.
    Estimate,
    /// Capacity margin; drive checks (drive on) or the common-slip check (drive off).
    Checks,
    /// Synchronism window (drive on).
    Sync,
    /// Dead-current block sample (drive on).
    DeadCurrent,
    /// Nothing periodic.
    Free,
}

impl Slot {
    /// The slot of `tick`.
    #[inline]
    pub const fn of(tick: u32) -> Slot {
        match SLOW.slot(tick) {
            0 => Slot::Classify,
            1 => Slot::Estimate,
            2 => Slot::Checks,
            _ => match WINDOW.slot(tick) {
                7 => Slot::Sync,
                15 => Slot::DeadCurrent,
                _ => Slot::Free,
            },
        }
    }

    /// Whether the braking model may step on this tick (odd ticks).
    #[inline]
    pub const fn braking_model_may_step(tick: u32) -> bool {
        tick & 1 == 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_tick_carries_two_parts_and_every_part_has_its_slot() {
        let mut seen = [0_u32; 6];
        for tick in 0..WINDOW.ticks {
            let i = Slot::of(tick) as usize;
            if let Some(count) = seen.get_mut(i) {
                *count += 1;
            }
        }
        // Four slow-lane slots per window each for the first three, one each for the window's
        // two, two free.
        assert_eq!(seen, [4, 4, 4, 1, 1, 2]);
    }
}
