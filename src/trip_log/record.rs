//! A trip record's bytes: what a flag change stores in flash, self-checking, decoded the same
//! on the host and the target.
//!
//! | bytes | field |
//! |---|---|
//! | 4 | magic `NBT7` |
//! | 4 | tick of the flag change (the monitor's tick count) |
//! | 1 + 1 | flags before, flags now ([`Flags::bits`]) |
//! | 2 | state bytes `S` |
//! | 4 | configuration digest ([`Monitor::settings_digest`]) |
//! | 4 × 14 | the estimate of the tick ([`Estimate::to_words`]) |
//! | 2 | window inputs `W` |
//! | S | the monitor's state at the window's start ([`Monitor::save_state`]) |
//! | 12 × W | the window's inputs ([`encode_inputs`]) |
//! | 4 | FNV-1a of everything before, as little-endian words (bytes zero-padded) |

use crate::digest::Fnv1a;
use crate::monitor::{Estimate, Flags, Inputs, Monitor, ESTIMATE_WORDS};

/// The record's magic.
pub const MAGIC: [u8; 4] = *b"NBT7";
/// Bytes per input of the window.
pub const INPUT_BYTES: usize = 12;
/// Bytes before the state.
pub const HEADER_BYTES: usize = 4 + 4 + 2 + 2 + 4 + 4 * ESTIMATE_WORDS + 2;

/// Why a record could not be written or read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RecordError {
    /// The buffer is too small.
    BufferFull,
    /// Not a record: wrong magic or length.
    NotARecord,
    /// The checksum does not match: a torn or corrupt record.
    Checksum,
    /// The state does not decode.
    State,
}

/// Bit of an input's flags byte: the operator reset the flags after this step.
pub const RESET_AFTER: u8 = 2;

/// One input as 12 bytes: the ADC code, both counters whole, the drive command (bit 0 of the
/// flags byte), the ticks elapsed (a missed deadline replays as it was stepped).
pub fn encode_inputs(i: &Inputs) -> [u8; INPUT_BYTES] {
    let [a0, a1] = i.current_adc_code.to_le_bytes();
    let [m0, m1, m2, m3] = i.motor_counter.to_le_bytes();
    let [o0, o1, o2, o3] = i.output_counter.to_le_bytes();
    let drive = u8::from(i.drive_commanded);
    [
        a0,
        a1,
        m0,
        m1,
        m2,
        m3,
        o0,
        o1,
        o2,
        o3,
        drive,
        i.ticks_elapsed,
    ]
}

/// The inverse of [`encode_inputs`].
pub fn decode_inputs(b: &[u8; INPUT_BYTES]) -> Inputs {
    let [a0, a1, m0, m1, m2, m3, o0, o1, o2, o3, drive, elapsed] = *b;
    let mut i = Inputs::new(
        u16::from_le_bytes([a0, a1]),
        u32::from_le_bytes([m0, m1, m2, m3]),
        u32::from_le_bytes([o0, o1, o2, o3]),
        drive & 1 != 0,
    );
    i.ticks_elapsed = elapsed;
    i
}

/// A decoded record, borrowing its bytes.
#[derive(Clone, Copy, Debug)]
pub struct Record<'a> {
    /// Tick of the flag change.
    pub tick: u32,
    /// Flags before the change.
    pub before: Flags,
    /// Flags after it.
    pub now: Flags,
    /// Digest of the settings the monitor ran with.
    pub config_digest: u32,
    /// The estimate of the tick.
    pub estimate: [u32; ESTIMATE_WORDS],
    /// The monitor's state at the window's start.
    pub state: &'a [u8],
    inputs: &'a [u8],
}

impl<'a> Record<'a> {
    /// The window's inputs, oldest first (the last is the tick of the change), each with
    /// whether the operator reset the flags after it.
    pub fn inputs(&self) -> impl Iterator<Item = (Inputs, bool)> + 'a {
        self.inputs
            .chunks_exact(INPUT_BYTES)
            .filter_map(|c| c.try_into().ok())
            .map(|c: &[u8; INPUT_BYTES]| {
                let [.., flags, _] = *c;
                (decode_inputs(c), flags & RESET_AFTER != 0)
            })
    }

    /// Inputs in the window.
    pub fn window_len(&self) -> usize {
        self.inputs.len() / INPUT_BYTES
    }

    /// Replays the window through a monitor of `config` restored to the record's state; returns
    /// the last estimate, which must equal [`Record::estimate`] word for word.
    pub fn replay(&self, config: crate::monitor::Config) -> Result<Estimate, RecordError> {
        let mut monitor = Monitor::restore(config, self.state).map_err(|_| RecordError::State)?;
        let mut last = None;
        for (i, reset) in self.inputs() {
            last = Some(monitor.step(&i));
            if reset {
                monitor.reset_flags();
            }
        }
        last.ok_or(RecordError::NotARecord)
    }
}

fn checksum(bytes: &[u8]) -> u32 {
    let mut d = Fnv1a::new();
    for chunk in bytes.chunks(4) {
        let mut w = [0_u8; 4];
        w.iter_mut().zip(chunk).for_each(|(a, b)| *a = *b);
        d.push(u32::from_le_bytes(w));
    }
    d.value()
}

/// A little cursor that writes fields in order and fails when the buffer ends.
struct Writer<'b> {
    buf: &'b mut [u8],
    at: usize,
}

impl Writer<'_> {
    fn put(&mut self, bytes: &[u8]) -> Result<(), RecordError> {
        let end = self.at + bytes.len();
        let dst = self
            .buf
            .get_mut(self.at..end)
            .ok_or(RecordError::BufferFull)?;
        dst.copy_from_slice(bytes);
        self.at = end;
        Ok(())
    }
}

/// Writes the record of a flag change at `estimate` (flags `before` → `estimate.flags`) whose
/// window starts at `start` (the monitor as it was) and runs through `inputs`; returns the
/// bytes used.
pub fn encode<'b>(
    buf: &'b mut [u8],
    start: &Monitor,
    estimate: &Estimate,
    before: Flags,
    inputs: impl ExactSizeIterator<Item = [u8; INPUT_BYTES]>,
) -> Result<&'b [u8], RecordError> {
    let window = u16::try_from(inputs.len()).map_err(|_| RecordError::BufferFull)?;
    // The state goes after the fixed header, its length back-filled.
    let state_len = {
        let tail = buf.get_mut(HEADER_BYTES..).ok_or(RecordError::BufferFull)?;
        let state = start
            .save_state(tail)
            .map_err(|_| RecordError::BufferFull)?;
        u16::try_from(state.len()).map_err(|_| RecordError::BufferFull)?
    };
    let mut w = Writer { buf, at: 0 };
    w.put(&MAGIC)?;
    w.put(&estimate.tick.to_le_bytes())?;
    w.put(&[before.bits(), estimate.flags.bits()])?;
    w.put(&state_len.to_le_bytes())?;
    w.put(&start.settings_digest().to_le_bytes())?;
    for word in estimate.to_words() {
        w.put(&word.to_le_bytes())?;
    }
    w.put(&window.to_le_bytes())?;
    w.at += usize::from(state_len);
    for i in inputs {
        w.put(&i)?;
    }
    let sum = checksum(w.buf.get(..w.at).ok_or(RecordError::BufferFull)?);
    w.put(&sum.to_le_bytes())?;
    let end = w.at;
    buf.get(..end).ok_or(RecordError::BufferFull)
}

fn u16_at(b: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_le_bytes(b.get(at..at + 2)?.try_into().ok()?))
}

fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?))
}

/// Reads a record; a torn or corrupt one is refused, never misread.
pub fn decode(bytes: &[u8]) -> Result<Record<'_>, RecordError> {
    let bad = RecordError::NotARecord;
    if bytes.get(..4) != Some(&MAGIC[..]) {
        return Err(bad);
    }
    let state_len = usize::from(u16_at(bytes, 10).ok_or(bad)?);
    let window = usize::from(u16_at(bytes, HEADER_BYTES - 2).ok_or(bad)?);
    let body = HEADER_BYTES + state_len + INPUT_BYTES * window;
    if bytes.len() != body + 4 {
        return Err(bad);
    }
    let (content, sum) = (bytes.get(..body).ok_or(bad)?, bytes.get(body..).ok_or(bad)?);
    if u32_at(sum, 0) != Some(checksum(content)) {
        return Err(RecordError::Checksum);
    }
    let mut estimate = [0_u32; ESTIMATE_WORDS];
    for (k, word) in estimate.iter_mut().enumerate() {
        *word = u32_at(bytes, 16 + 4 * k).ok_or(bad)?;
    }
    let flag = |at: usize| bytes.get(at).copied().map(Flags::from_bits).ok_or(bad);
    Ok(Record {
        tick: u32_at(bytes, 4).ok_or(bad)?,
        before: flag(8)?,
        now: flag(9)?,
        config_digest: u32_at(bytes, 12).ok_or(bad)?,
        estimate,
        state: bytes
            .get(HEADER_BYTES..HEADER_BYTES + state_len)
            .ok_or(bad)?,
        inputs: bytes.get(HEADER_BYTES + state_len..body).ok_or(bad)?,
    })
}
