//! Replay traces: the compact binary form of a twin trace that the firmware embeds at build time
//! and plays back, one record per tick, under QEMU. The xtask writes it from the twin's CSV;
//! host tests read it with the same code, so both sides step the monitor on identical inputs.
//!
//! Format `NBR1`, little-endian:
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 4 | magic `NBR1` |
//! | 4 | 4 | number of records |
//! | 8 | 4 | tick rate (Hz) |
//! | 12 | 4 | reserved, 0 |
//! | 16 + 8·i | 2 | current ADC code |
//! | +2 | 2 | motor-encoder counter (16-bit register) |
//! | +4 | 2 | output-encoder counter (≤ 16 bits) |
//! | +6 | 1 | bit 0: drive commanded; bits 1–7 zero |
//! | +7 | 1 | zero |
//!
//! Eight bytes a tick: one second at 10 kHz is 80 KB of flash.

use crate::board::SampleSource;
use crate::monitor::Inputs;

/// Header size in bytes.
pub const HEADER_BYTES: usize = 16;
/// Record size in bytes.
pub const RECORD_BYTES: usize = 8;
/// The format's magic.
pub const MAGIC: [u8; 4] = *b"NBR1";

/// Why bytes are not a replay trace; each names the byte offset where it went wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReplayError {
    /// Fewer than [`HEADER_BYTES`] bytes.
    TooShort {
        /// Bytes present.
        len: usize,
    },
    /// The first four bytes are not `NBR1` (another file, or another version).
    BadMagic,
    /// The header promises more records than the bytes hold.
    Truncated {
        /// Byte offset where the missing record would start.
        offset: usize,
    },
    /// A reserved byte or bit is set at this offset.
    Reserved {
        /// Byte offset.
        offset: usize,
    },
}

/// A parsed trace: the records borrowed in place, played one per tick.
#[derive(Clone, Debug)]
pub struct Replay<'a> {
    records: &'a [u8],
    count: u32,
    next: u32,
    tick_hz: u32,
}

fn u32_at(bytes: &[u8], offset: usize) -> u32 {
    let mut word = [0_u8; 4];
    if let Some(src) = bytes.get(offset..offset + 4) {
        word.copy_from_slice(src);
    }
    u32::from_le_bytes(word)
}

fn u16_at(bytes: &[u8], offset: usize) -> u16 {
    let mut half = [0_u8; 2];
    if let Some(src) = bytes.get(offset..offset + 2) {
        half.copy_from_slice(src);
    }
    u16::from_le_bytes(half)
}

impl<'a> Replay<'a> {
    /// Checks the header and the length; records are decoded as they are played.
    pub fn parse(bytes: &'a [u8]) -> Result<Replay<'a>, ReplayError> {
        if bytes.len() < HEADER_BYTES {
            return Err(ReplayError::TooShort { len: bytes.len() });
        }
        if bytes.get(..4) != Some(&MAGIC[..]) {
            return Err(ReplayError::BadMagic);
        }
        if u32_at(bytes, 12) != 0 {
            return Err(ReplayError::Reserved { offset: 12 });
        }
        let count = u32_at(bytes, 4);
        let records = bytes.get(HEADER_BYTES..).unwrap_or_default();
        let need = (count as usize).saturating_mul(RECORD_BYTES);
        if records.len() < need {
            let whole = records.len() / RECORD_BYTES;
            return Err(ReplayError::Truncated {
                offset: HEADER_BYTES + whole * RECORD_BYTES,
            });
        }
        for i in 0..count as usize {
            let at = i * RECORD_BYTES;
            let flags = records.get(at + 6).copied().unwrap_or(0);
            if flags & !1 != 0 {
                return Err(ReplayError::Reserved {
                    offset: HEADER_BYTES + at + 6,
                });
            }
            if records.get(at + 7).copied().unwrap_or(0) != 0 {
                return Err(ReplayError::Reserved {
                    offset: HEADER_BYTES + at + 7,
                });
            }
        }
        Ok(Replay {
            records,
            count,
            next: 0,
            tick_hz: u32_at(bytes, 8),
        })
    }

    /// Number of records.
    pub fn len(&self) -> u32 {
        self.count
    }

    /// Whether the trace has no records.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Tick rate the trace was sampled at (Hz).
    pub fn tick_hz(&self) -> u32 {
        self.tick_hz
    }

    /// Index of the next record to play.
    pub fn position(&self) -> u32 {
        self.next
    }

    /// Record `i`, if present.
    pub fn record(&self, i: u32) -> Option<Inputs> {
        if i >= self.count {
            return None;
        }
        let at = i as usize * RECORD_BYTES;
        let flags = self.records.get(at + 6).copied()?;
        Some(Inputs::new(
            u16_at(self.records, at),
            u32::from(u16_at(self.records, at + 2)),
            u32::from(u16_at(self.records, at + 4)),
            flags & 1 != 0,
        ))
    }
}

impl SampleSource for Replay<'_> {
    fn sample(&mut self) -> Option<Inputs> {
        let inputs = self.record(self.next)?;
        self.next += 1;
        Some(inputs)
    }

    fn skip(&mut self, ticks: u32) {
        self.next = self.next.saturating_add(ticks).min(self.count);
    }
}

/// The header for `count` records at `tick_hz`.
pub fn encode_header(count: u32, tick_hz: u32) -> [u8; HEADER_BYTES] {
    let mut out = [0_u8; HEADER_BYTES];
    let fields = [u32::from_le_bytes(MAGIC), count, tick_hz, 0];
    for (chunk, field) in out.chunks_exact_mut(4).zip(fields) {
        chunk.copy_from_slice(&field.to_le_bytes());
    }
    out
}

/// One record; `None` if a counter does not fit its 16-bit field.
pub fn encode_record(inputs: &Inputs) -> Option<[u8; RECORD_BYTES]> {
    let motor = u16::try_from(inputs.motor_counter).ok()?;
    let output = u16::try_from(inputs.output_counter).ok()?;
    let [a0, a1] = inputs.current_adc_code.to_le_bytes();
    let [m0, m1] = motor.to_le_bytes();
    let [o0, o1] = output.to_le_bytes();
    Some([a0, a1, m0, m1, o0, o1, u8::from(inputs.drive_commanded), 0])
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    fn trace(samples: &[Inputs]) -> Vec<u8> {
        let mut bytes = encode_header(samples.len() as u32, 10_000).to_vec();
        for s in samples {
            bytes.extend_from_slice(&encode_record(s).unwrap());
        }
        bytes
    }

    #[test]
    fn round_trip() {
        let samples = [
            Inputs::new(2048, 65_535, 16_383, true),
            Inputs::new(0, 0, 0, false),
        ];
        let bytes = trace(&samples);
        let mut replay = Replay::parse(&bytes).unwrap();
        assert_eq!(replay.len(), 2);
        assert_eq!(replay.tick_hz(), 10_000);
        assert_eq!(replay.sample(), Some(samples[0]));
        assert_eq!(replay.sample(), Some(samples[1]));
        assert_eq!(replay.sample(), None);
    }

    #[test]
    fn errors_name_the_offset() {
        let bytes = trace(&[Inputs::new(1, 2, 3, false); 3]);
        assert_eq!(
            Replay::parse(&bytes[..5]).unwrap_err(),
            ReplayError::TooShort { len: 5 }
        );
        let mut other = bytes.clone();
        other[3] = b'2';
        assert_eq!(Replay::parse(&other).unwrap_err(), ReplayError::BadMagic);
        assert_eq!(
            Replay::parse(&bytes[..bytes.len() - 1]).unwrap_err(),
            ReplayError::Truncated { offset: 32 }
        );
        let mut flagged = bytes.clone();
        flagged[16 + 8 + 6] = 2;
        assert_eq!(
            Replay::parse(&flagged).unwrap_err(),
            ReplayError::Reserved { offset: 30 }
        );
        assert_eq!(encode_record(&Inputs::new(0, 70_000, 0, false)), None);
    }
}
