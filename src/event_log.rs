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
