//! The trip log: each flag change recorded with the raw inputs that led to it and the
//! monitor's state where they start, so the host replays the trip bit-exact
//! (`cargo xtask log replay`). [`record`] is the bytes; [`Recorder`] keeps, in RAM, what a
//! record needs: a copy of the monitor every [`Recorder::EVERY`] inputs, the last two kept,
//! and the inputs since the older. A change's window therefore starts at the older copy and
//! holds between `EVERY` + 1 and `2 × EVERY` inputs, through the tick of the change.

pub mod record;
pub mod store;

use crate::monitor::{Estimate, Flags, Inputs, Monitor};
use record::{decode_inputs, encode_inputs, RecordError, INPUT_BYTES};

/// Inputs the recorder's ring holds by default: 256 (25.6 ms at 10 kHz), so a window holds
/// 12.9–25.6 ms of inputs before its change (the state at its start makes any length replay).
pub const RING_INPUTS: usize = 256;

/// What a record needs, kept in RAM: two copies of the monitor and a ring of `RING` inputs.
pub struct Recorder<const RING: usize = RING_INPUTS> {
    ring: [[u8; INPUT_BYTES]; RING],
    /// Inputs seen so far.
    seen: u32,
    older: Option<(u32, Monitor)>,
    newer: Option<(u32, Monitor)>,
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
            older: None,
            newer: None,
        }
    }

    /// Before `monitor` steps on `inputs`: a copy of it every [`Self::EVERY`] inputs, and the
    /// inputs into the ring.
    pub fn before_step(&mut self, monitor: &Monitor, inputs: &Inputs) {
        if self.seen.is_multiple_of(Self::EVERY.max(1)) {
            self.older = self.newer.take();
            self.newer = Some((self.seen, monitor.clone()));
        }
        if let Some(slot) = self.ring.get_mut(self.seen as usize % RING.max(1)) {
            *slot = encode_inputs(inputs);
        }
        self.seen = self.seen.wrapping_add(1);
    }

    /// The window of a change seen on the last step: the monitor where it starts and its
    /// inputs through the last one.
    pub fn window(&self) -> Option<(&Monitor, impl ExactSizeIterator<Item = Inputs> + '_)> {
        let (start, monitor) = self.older.as_ref().or(self.newer.as_ref())?;
        let from = *start;
        let n = self.seen.wrapping_sub(from) as usize;
        let inputs = (0..n).map(move |k| {
            let at = from.wrapping_add(k as u32) as usize % RING.max(1);
            self.ring
                .get(at)
                .map_or(Inputs::new(0, 0, 0, false), decode_inputs)
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
