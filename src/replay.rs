//! Replay traces: the compact binary form of a twin trace, played one record per tick. The xtask
//! writes it from the twin's CSV. Under QEMU the firmware streams it from the host ([`Streamed`]
//! fed by a [`Feeder`], any length); host tests read it whole ([`Replay`]) with the same record
//! decoding, so both sides step the monitor on identical inputs.
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
//! Eight bytes a tick: one second at 10 kHz is 80 KB, streamed through a ring of
//! [`STREAM_SLOTS`] − 1 records.

use crate::board::SampleSource;
use crate::monitor::Inputs;
use heapless::spsc::{Consumer, Producer, Queue};

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

impl<'a> Replay<'a> {
    /// Checks the header and the length; records are decoded as they are played.
    pub fn parse(bytes: &'a [u8]) -> Result<Replay<'a>, ReplayError> {
        let (count, tick_hz) = parse_header(bytes)?;
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
            tick_hz,
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
        let mut record = [0_u8; RECORD_BYTES];
        record.copy_from_slice(self.records.get(at..at + RECORD_BYTES)?);
        Some(decode(&record))
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

/// One record's bytes.
pub type Record = [u8; RECORD_BYTES];

/// Slots of the stream's ring (one is kept free): 511 records, 51 ms at 10 kHz, 4 KB of RAM.
pub const STREAM_SLOTS: usize = 512;

/// Records the feeder moves at a time (the main loop's read buffer: 512 bytes).
pub const FEED_CHUNK: usize = 64;

/// The ring between the main loop (producer) and the tick (consumer).
pub type StreamRing = Queue<Record, STREAM_SLOTS>;

/// A record's inputs (its reserved bits are checked where it enters: [`Replay::parse`],
/// [`Feeder::push`]).
pub fn decode(r: &Record) -> Inputs {
    let [a0, a1, m0, m1, o0, o1, flags, _] = *r;
    Inputs::new(
        u16::from_le_bytes([a0, a1]),
        u32::from(u16::from_le_bytes([m0, m1])),
        u32::from(u16::from_le_bytes([o0, o1])),
        flags & 1 != 0,
    )
}

/// The header's record count and tick rate.
pub fn parse_header(bytes: &[u8]) -> Result<(u32, u32), ReplayError> {
    if bytes.len() < HEADER_BYTES {
        return Err(ReplayError::TooShort { len: bytes.len() });
    }
    if bytes.get(..4) != Some(&MAGIC[..]) {
        return Err(ReplayError::BadMagic);
    }
    if u32_at(bytes, 12) != 0 {
        return Err(ReplayError::Reserved { offset: 12 });
    }
    Ok((u32_at(bytes, 4), u32_at(bytes, 8)))
}

/// Splits `ring` into the main loop's [`Feeder`] and the tick's [`Streamed`] source for a trace
/// whose header is `header`.
pub fn stream<'a>(
    header: &[u8],
    ring: &'a mut StreamRing,
) -> Result<(Feeder<'a>, Streamed<'a>), ReplayError> {
    let (count, tick_hz) = parse_header(header)?;
    let (tx, rx) = ring.split();
    Ok((
        Feeder {
            tx,
            remaining: count,
            offset: HEADER_BYTES,
        },
        Streamed {
            rx,
            count,
            taken: 0,
            owed: 0,
            starved: 0,
            tick_hz,
            last: Inputs::new(0, 0, 0, false),
        },
    ))
}

/// The main loop's half of a stream: checks records and moves them into the ring. It never
/// blocks the tick: the ring is lock-free (one producer, one consumer).
pub struct Feeder<'a> {
    tx: Producer<'a, Record>,
    remaining: u32,
    offset: usize,
}

impl Feeder<'_> {
    /// Records to read now: a whole [`FEED_CHUNK`] when the ring has room for one, the last
    /// few at the end, else 0.
    pub fn wanted(&self) -> usize {
        let free = self.tx.capacity() - self.tx.len();
        let left = self.remaining as usize;
        if left <= free.min(FEED_CHUNK) {
            left
        } else if free >= FEED_CHUNK {
            FEED_CHUNK
        } else {
            0
        }
    }

    /// Records not yet pushed.
    pub fn remaining(&self) -> u32 {
        self.remaining
    }

    /// Pushes whole records from `bytes` (at most [`Feeder::wanted`] of them); returns how many.
    pub fn push(&mut self, bytes: &[u8]) -> Result<usize, ReplayError> {
        let mut pushed = 0;
        for r in bytes.chunks_exact(RECORD_BYTES) {
            if self.remaining == 0 {
                break;
            }
            let mut record = [0_u8; RECORD_BYTES];
            record.copy_from_slice(r);
            if record[6] & !1 != 0 {
                return Err(ReplayError::Reserved {
                    offset: self.offset + 6,
                });
            }
            if record[7] != 0 {
                return Err(ReplayError::Reserved {
                    offset: self.offset + 7,
                });
            }
            if self.tx.enqueue(record).is_err() {
                break;
            }
            self.remaining -= 1;
            self.offset += RECORD_BYTES;
            pushed += 1;
        }
        Ok(pushed)
    }
}

/// The tick's half of a stream: one record per tick from the ring. A tick that finds the ring
/// empty before the trace's end holds the last reading and counts as starved (it must not
/// happen: the xtask fails a run with any).
pub struct Streamed<'a> {
    rx: Consumer<'a, Record>,
    count: u32,
    taken: u32,
    owed: u32,
    starved: u32,
    tick_hz: u32,
    last: Inputs,
}

impl Streamed<'_> {
    /// Records in the trace.
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

    /// Ticks that found the ring empty before the trace's end.
    pub fn starved(&self) -> u32 {
        self.starved
    }
}

impl SampleSource for Streamed<'_> {
    fn sample(&mut self) -> Option<Inputs> {
        // Records a missed deadline skipped before they arrived are dropped first.
        while self.owed > 0 && self.rx.dequeue().is_some() {
            self.owed -= 1;
        }
        if self.taken >= self.count {
            return None;
        }
        if self.owed == 0 {
            if let Some(record) = self.rx.dequeue() {
                self.taken += 1;
                self.last = decode(&record);
                return Some(self.last);
            }
        }
        self.starved = self.starved.saturating_add(1);
        Some(self.last)
    }

    fn skip(&mut self, ticks: u32) {
        let ticks = ticks.min(self.count - self.taken);
        self.taken += ticks;
        self.owed = self.owed.saturating_add(ticks);
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

    /// Feeds `bytes` through a ring in the feeder's chunks, ticking `per_feed` times between
    /// feeds; returns what the stream played and how often it starved.
    fn streamed(bytes: &[u8], per_feed: usize, skip_at: Option<usize>) -> (Vec<Inputs>, u32) {
        let mut ring = StreamRing::new();
        let (mut feeder, mut source) = stream(bytes, &mut ring).unwrap();
        let mut at = HEADER_BYTES;
        let mut played = Vec::new();
        loop {
            let n = feeder.wanted();
            let chunk = &bytes[at..at + n * RECORD_BYTES];
            at += feeder.push(chunk).unwrap() * RECORD_BYTES;
            for _ in 0..per_feed {
                if skip_at == Some(played.len()) {
                    source.skip(3);
                }
                match source.sample() {
                    Some(s) => played.push(s),
                    None => return (played, source.starved()),
                }
            }
        }
    }

    #[test]
    fn a_stream_plays_what_the_whole_trace_plays() {
        let samples: Vec<Inputs> = (0..2000_u32)
            .map(|i| Inputs::new((i % 4096) as u16, i * 7 % 65_536, i % 16_384, i % 3 == 0))
            .collect();
        let bytes = trace(&samples);
        // Fed often enough: never starved, every record in order.
        let (played, starved) = streamed(&bytes, FEED_CHUNK, None);
        assert_eq!((played.as_slice(), starved), (samples.as_slice(), 0));
        // A missed deadline skips records exactly as the whole replay does.
        let mut whole = Replay::parse(&bytes).unwrap();
        let mut expected = Vec::new();
        while let Some(s) = whole.sample() {
            expected.push(s);
            if expected.len() == 700 {
                whole.skip(3);
            }
        }
        let (played, starved) = streamed(&bytes, 50, Some(700));
        assert_eq!((played, starved), (expected, 0));
        // Fed too rarely: the ticks that found the ring empty are counted.
        let (_, starved) = streamed(&bytes, STREAM_SLOTS + 10, None);
        assert!(starved > 0);
    }

    #[test]
    fn a_stream_checks_what_it_is_fed() {
        let mut bytes = trace(&[Inputs::new(1, 2, 3, false); 3]);
        let mut ring = StreamRing::new();
        assert_eq!(
            stream(&bytes[..5], &mut ring).err(),
            Some(ReplayError::TooShort { len: 5 })
        );
        bytes[16 + 8 + 7] = 1;
        let (mut feeder, _) = stream(&bytes, &mut ring).unwrap();
        assert_eq!(
            feeder.push(&bytes[16..]),
            Err(ReplayError::Reserved { offset: 31 })
        );
    }
}
