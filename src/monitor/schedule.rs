//! One schedule: every rate the monitor runs at, named once, and the slot of each tick.
//!
//! The tick (`Config::tick_hz`, 10 kHz by default) carries sensing, the observer, the scene
//! and the estimate. Periodic work runs in *lanes* that divide the tick, each on its own slot so
//! that no tick carries two of the costly parts:
//!
//! | lane | every | slot (tick mod lane) | drive on | drive off |
//! |---|---|---|---|---|
//! | [`SLOW`] | 4 ticks (2.5 kHz) | 0 | load filter | pack health |
//! | | | 1 | drive checks | common-slip check |
//! | | | 2 | friction energy | friction energy |
//! | [`WINDOW`] | 16 ticks (625 Hz) | 3 | load-cache refresh | — |
//! | | | 7 | synchronism window | — |
//! | | | 15 | dead-current block | — |
//! | braking model | `tick_hz / braking_model_hz` | odd ticks | — | nominal braking step |
//!
//! A lane's filter gains and persistence counts are those of its own rate: each lane counts the
//! ticks it covers (`Lane::covered`).

/// A lane: periodic work every `ticks` ticks (a power of two, so the slot is a mask).
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

    /// The lane's rate (Hz) at a tick rate.
    pub fn hz(self, tick_hz: f64) -> f64 {
        tick_hz / f64::from(self.ticks)
    }
}

/// The slow lane: 2.5 kHz at 10 kHz.
pub const SLOW: Lane = Lane { ticks: 4 };
/// The window lane: 625 Hz at 10 kHz (1.6 ms windows).
pub const WINDOW: Lane = Lane { ticks: 16 };

/// What periodic work a tick carries (in [`SLOW`], and in [`WINDOW`] on the slow lane's free
/// slot).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slot {
    /// Load filter (drive on) or pack health (drive off).
    LoadOrHealth,
    /// Drive checks (drive on) or the common-slip check (drive off).
    Checks,
    /// Friction energy.
    Energy,
    /// Load-cache refresh (drive on).
    Refresh,
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
            0 => Slot::LoadOrHealth,
            1 => Slot::Checks,
            2 => Slot::Energy,
            _ => match WINDOW.slot(tick) {
                3 => Slot::Refresh,
                7 => Slot::Sync,
                15 => Slot::DeadCurrent,
                _ => Slot::Free,
            },
        }
    }

    /// Whether the braking model may step on this tick (odd ticks: the even ones carry the
    /// pack-health update).
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
        let mut seen = [0_u32; 7];
        for tick in 0..WINDOW.ticks {
            let i = Slot::of(tick) as usize;
            if let Some(count) = seen.get_mut(i) {
                *count += 1;
            }
        }
        // Four slow-lane slots per window each for the first three, one each for the window's.
        assert_eq!(seen, [4, 4, 4, 1, 1, 1, 1]);
    }
}
