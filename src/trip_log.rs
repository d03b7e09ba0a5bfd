//! The trip log: each flag change recorded with the raw inputs that led to it and the
//! monitor's state where they start, so the host replays the trip bit-exact
//! (`cargo xtask log replay`). [`record`] is the bytes; [`Recorder`] keeps, in RAM, what a
//! record needs: a copy of the monitor every [`Recorder::EVERY`] inputs, the last two kept,
//! and the inputs since the older. A change's window therefore starts at the older copy and
//! holds between `EVERY` + 1 and `2 × EVERY` inputs, through the tick of the change.

pub mod record;
pub mod store;

use crate::monitor::{Estimate, Flags, Inputs, Monitor};
use record::{encode_inputs, RecordError, INPUT_BYTES, RESET_AFTER};

/// Inputs the recorder's ring holds by default: 256 (25.6 ms at 10 kHz), so a window holds
/// 12.9–25.6 ms of inputs before its change (the state at its start makes any length replay).
pub const RING_INPUTS: usize = 256;

/// What a record needs, kept in RAM: two copies of the monitor and a ring of `RING` inputs.
pub struct Recorder<const RING: usize = RING_INPUTS> {
    ring: [[u8; INPUT_BYTES]; RING],
    /// Inputs seen so far.
    seen: u32,
    /// Two copies of the monitor with the input count each was taken at; `newest` is the
    /// index of the later one.
    copies: [Option<(u32, Monitor)>; 2],
    newest: usize,
}

impl<const RING: usize> Default for Recorder<RING> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const RING: usize> Recorder<RING> {
    /// Inputs between two copies of the monitor.
    pub const EVERY: u32 = (RING / 2) as u32;

    /// An empty recorder.
    pub const fn new() -> Self {
        Recorder {
            ring: [[0; INPUT_BYTES]; RING],
            seen: 0,
            copies: [None, None],
            newest: 1,
        }
    }

    /// Before `monitor` steps on `inputs`: [`Self::snapshot_if_due`], then [`Self::push_input`].
    pub fn before_step(&mut self, monitor: &Monitor, inputs: &Inputs) {
        self.snapshot_if_due(monitor);
        self.push_input(inputs);
    }

    /// Between two steps (on a target: after the background work): a copy of the monitor
    /// every [`Self::EVERY`] inputs.
    pub fn snapshot_if_due(&mut self, monitor: &Monitor) {
        if self.seen.is_multiple_of(Self::EVERY.max(1)) {
            // The older slot becomes the newest, overwritten in place (no copy on the stack).
            self.newest = 1 - self.newest.min(1);
            if let Some(slot) = self.copies.get_mut(self.newest) {
                match slot {
                    Some((at, copy)) => {
                        *at = self.seen;
                        copy.clone_from(monitor);
                    }
                    None => *slot = Some((self.seen, monitor.clone())),
                }
            }
        }
    }

    /// The inputs of the step about to run, into the ring (12 bytes).
    pub fn push_input(&mut self, inputs: &Inputs) {
        if let Some(slot) = self.ring.get_mut(self.seen as usize % RING.max(1)) {
            *slot = encode_inputs(inputs);
        }
        self.seen = self.seen.wrapping_add(1);
    }

    /// The operator reset the flags after the last step (replayed after it).
    pub fn mark_reset(&mut self) {
        let last = self.seen.wrapping_sub(1) as usize % RING.max(1);
        if let Some(flags) = self.ring.get_mut(last).and_then(|slot| slot.get_mut(10)) {
            *flags |= RESET_AFTER;
        }
    }

    /// The window of a change seen on the last step: the monitor where it starts and its
    /// inputs (encoded) through the last one.
    pub fn window(
        &self,
    ) -> Option<(
        &Monitor,
        impl ExactSizeIterator<Item = [u8; INPUT_BYTES]> + '_,
    )> {
        let older = self.copies.get(1 - self.newest.min(1))?.as_ref();
        let newer = self.copies.get(self.newest)?.as_ref();
        let (start, monitor) = older.or(newer)?;
        let from = *start;
        let n = self.seen.wrapping_sub(from) as usize;
        let inputs = (0..n).map(move |k| {
            let at = from.wrapping_add(k as u32) as usize % RING.max(1);
            self.ring.get(at).copied().unwrap_or([0; INPUT_BYTES])
        });
        Some((monitor, inputs))
    }

    /// Writes the record of the change from `before` to `estimate.flags` seen on the last step.
    pub fn record<'b>(
        &self,
        buf: &'b mut [u8],
        estimate: &Estimate,
        before: Flags,
    ) -> Result<&'b [u8], RecordError> {
        let (monitor, inputs) = self.window().ok_or(RecordError::NotARecord)?;
        record::encode(buf, monitor, estimate, before, inputs)
    }
}
