//! The event log between the 10 kHz interrupt and the logger: a fixed-size ring buffer that
//! never blocks the interrupt and counts every event it had to overwrite.
//!
//! The interrupt pushes; the main loop pops and formats (defmt). When the logger falls behind,
//! the oldest event is dropped and [`EventLog::overwritten`] says how many were — nothing is
//! lost silently. Flags themselves are latched in the monitor, so a dropped *event* never loses
//! a flag.

use crate::monitor::{BrakeState, Flags, Scene};
use heapless::Deque;

/// What the tick reports to the logger.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Event {
    /// Decimated state line.
    State {
        /// Monitor tick.
        tick: u32,
        /// Recognised scene.
        scene: Scene,
        /// Pack state.
        brake: BrakeState,
        /// Pressing force (N), I16F16 bits.
        pressing_force_bits: i32,
        /// Braking torque (N·m), I16F16 bits.
        braking_torque_bits: i32,
        /// Latched flags.
        flags: Flags,
    },
    /// The latched flags changed (raised, or cleared by a reset).
    FlagsChanged {
        /// Monitor tick.
        tick: u32,
        /// Flags before.
        before: Flags,
        /// Flags now.
        now: Flags,
    },
    /// The interrupt missed its deadline: `missed` ticks were skipped.
    Overrun {
        /// Monitor tick.
        tick: u32,
        /// Ticks missed.
        missed: u32,
    },
}

/// A fixed-point value as the log prints it: sign, whole part and fraction digits, so the
/// logger writes engineering units (`force=1184.4 N`) rather than raw Q16 bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Decimal {
    /// Below zero (after rounding).
    pub negative: bool,
    /// Whole units.
    pub whole: u32,
    /// Fraction, in units of 1/`scale` (print zero-padded to the scale's digits).
    pub frac: u32,
}

impl Decimal {
    /// I16F16 `bits` rounded to 1/`scale` (10 for tenths, 100 for hundredths).
    pub fn from_q16(bits: i32, scale: u32) -> Decimal {
        let scale = u64::from(scale.max(1));
        let scaled = (u64::from(bits.unsigned_abs()) * scale + (1 << 15)) >> 16;
        Decimal {
            negative: bits < 0 && scaled != 0,
            whole: u32::try_from(scaled.checked_div(scale).unwrap_or(0)).unwrap_or(u32::MAX),
            frac: u32::try_from(scaled.checked_rem(scale).unwrap_or(0)).unwrap_or(0),
        }
    }

    /// `"-"` or `""`.
    pub fn sign(&self) -> &'static str {
        if self.negative {
            "-"
        } else {
            ""
        }
    }
}

/// The time (s) of the sample a monitor tick stepped on, as whole seconds and 1/10 000 s: the
/// trace's time base (sample `i` at `i`/10 kHz is stepped as tick `i + 1`).
pub fn tick_time(tick: u32) -> (u32, u32) {
    let sample = tick.saturating_sub(1);
    (sample / 10_000, sample % 10_000)
}

/// Ring buffer of `N` events.
pub struct EventLog<const N: usize> {
    queue: Deque<Event, N>,
    overwritten: u32,
}

impl<const N: usize> Default for EventLog<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> EventLog<N> {
    /// An empty log.
    pub const fn new() -> Self {
        EventLog {
            queue: Deque::new(),
            overwritten: 0,
        }
    }

    /// Appends an event, overwriting (and counting) the oldest when full.
    pub fn push(&mut self, event: Event) {
        if self.queue.is_full() {
            let _ = self.queue.pop_front();
            self.overwritten = self.overwritten.saturating_add(1);
        }
        // Cannot fail: there is room now. A zero-capacity log counts the event as overwritten.
        if self.queue.push_back(event).is_err() {
            self.overwritten = self.overwritten.saturating_add(1);
        }
    }

    /// The oldest event, if any.
    pub fn pop(&mut self) -> Option<Event> {
        self.queue.pop_front()
    }

    /// Events dropped because the log was full.
    pub fn overwritten(&self) -> u32 {
        self.overwritten
    }

    /// Events waiting.
    pub fn len(&self) -> usize {
        self.queue.len()
    }

    /// Whether no event is waiting.
    pub fn is_empty(&self) -> bool {
        self.queue.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn overrun(tick: u32) -> Event {
        Event::Overrun { tick, missed: 1 }
    }

    #[test]
    fn fixed_point_prints_as_decimals_and_ticks_as_sample_times() {
        let q16 = |v: f64| (v * 65_536.0).round() as i32;
        let d = Decimal::from_q16(q16(1184.41), 10);
        assert_eq!((d.sign(), d.whole, d.frac), ("", 1184, 4));
        let d = Decimal::from_q16(q16(-1.98), 100);
        assert_eq!((d.sign(), d.whole, d.frac), ("-", 1, 98));
        let d = Decimal::from_q16(q16(-0.001), 100);
        assert_eq!((d.sign(), d.whole, d.frac), ("", 0, 0));
        assert_eq!(tick_time(4173), (0, 4172));
        assert_eq!(tick_time(20_001), (2, 0));
    }

    #[test]
    fn overwrites_oldest_and_counts() {
        let mut log = EventLog::<2>::new();
        log.push(overrun(1));
        log.push(overrun(2));
        log.push(overrun(3));
        assert_eq!(log.overwritten(), 1);
        assert_eq!(log.pop(), Some(overrun(2)));
        assert_eq!(log.pop(), Some(overrun(3)));
        assert_eq!(log.pop(), None);
    }
}
