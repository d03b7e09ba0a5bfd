//! Shared test vectors for the fixed-point helpers, run natively and under QEMU.
//!
//! The vectors are generated, not stored: a fixed-seed xorshift32 stream plus the edge cases
//! (zero, ±1 LSB, the formats' limits). [`run`] feeds every vector through every helper in
//! [`crate::fx`], checks each result against an independent wide-integer reference, and folds
//! the outputs into an FNV-1a digest. The host test and the target test both call it; the xtask
//! compares the digest printed under QEMU with the one it computes natively, so "bit-identical"
//! is checked by a third party rather than asserted by the target about itself.

use crate::digest::Fnv1a;
use crate::fx::{adc_centered, counter_delta, lowpass, mul_sat, scale_count, Gain, Q16};

/// Number of generated vectors per helper (the edge cases come on top).
pub const GENERATED: u32 = 2000;

/// What one pass over the vectors found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Report {
    /// Cases evaluated.
    pub cases: u32,
    /// Cases whose result differed from the wide-integer reference.
    pub mismatches: u32,
    /// FNV-1a digest of every result, in order.
    pub digest: u32,
}

/// Edge values of a 32-bit word that every helper is fed.
const EDGES: [u32; 10] = [
    0,
    1,
    2,
    0x7FFF_FFFF,
    0x8000_0000,
    0x8000_0001,
    0xFFFF_FFFF,
    0xFFFF_FFFE,
    0x0001_0000,
    0xFFFF_0000,
];

struct Xorshift32(u32);

impl Xorshift32 {
    fn next(&mut self) -> u32 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.0 = x;
        x
    }
}

/// Runs every helper over every vector; see the module doc.
pub fn run() -> Report {
    let mut report = Report {
        cases: 0,
        mismatches: 0,
        digest: 0,
    };
    let mut fnv = Fnv1a::new();
    let mut rng = Xorshift32(0x2545_F491);
    let mut pairs = EDGES
        .iter()
        .flat_map(|&a| EDGES.iter().map(move |&b| (a, b)));
    let mut generated = 0;
    loop {
        let (a, b) = if let Some(pair) = pairs.next() {
            pair
        } else if generated < GENERATED {
            generated += 1;
            (rng.next(), rng.next())
        } else {
            break;
        };
        let third = rng.next();
        for (got, want) in cases(a, b, third) {
            report.cases += 1;
            if got != want {
                report.mismatches += 1;
            }
            fnv.push(got);
        }
    }
    report.digest = fnv.value();
    report
}

/// The helpers' outputs for one vector, each beside its wide-integer reference.
fn cases(a: u32, b: u32, c: u32) -> [(u32, u32); 5] {
    let bits = (c % 32) as u8 + 1;
    let adc_bits = (c % 16) as u8 + 1;
    let (qa, qb) = (Q16::from_bits(a as i32), Q16::from_bits(b as i32));
    let alpha = Gain::from_bits((c >> 16) as u16);
    [
        (
            counter_delta(a, b, bits) as u32,
            ref_counter_delta(a, b, bits) as u32,
        ),
        (
            adc_centered(a as u16, adc_bits) as u32,
            ref_adc_centered(a as u16, adc_bits) as u32,
        ),
        (
            lowpass(qa, qb, alpha).to_bits() as u32,
            ref_lowpass(a as i32, b as i32, (c >> 16) as u16) as u32,
        ),
        (
            mul_sat(qa, qb).to_bits() as u32,
            ref_mul_sat(a as i32, b as i32) as u32,
        ),
        (
            scale_count(a as i32, qb).to_bits() as u32,
            ref_scale(a as i32, b as i32) as u32,
        ),
    ]
}

fn ref_counter_delta(prev: u32, now: u32, bits: u8) -> i64 {
    let modulus = 1_i64 << bits;
    let mask = modulus - 1;
    let mut d = (i64::from(now) & mask) - (i64::from(prev) & mask);
    d = d.rem_euclid(modulus);
    if d >= modulus / 2 {
        d -= modulus;
    }
    d
}

fn ref_adc_centered(code: u16, bits: u8) -> i64 {
    let full = (1_i64 << bits) - 1;
    i64::from(code).min(full) - (1_i64 << (bits - 1))
}

fn ref_lowpass(state: i32, input: i32, alpha: u16) -> i64 {
    let num = (i128::from(input) - i128::from(state)) * i128::from(alpha);
    // floor division by 2^16
    let step = num.div_euclid(1 << 16);
    (i128::from(state) + step) as i64
}

fn ref_mul_sat(a: i32, b: i32) -> i64 {
    let p = (i128::from(a) * i128::from(b)).div_euclid(1 << 16);
    p.clamp(i128::from(i32::MIN), i128::from(i32::MAX)) as i64
}

fn ref_scale(count: i32, scale: i32) -> i64 {
    let p = i128::from(count) * i128::from(scale);
    p.clamp(i128::from(i32::MIN), i128::from(i32::MAX)) as i64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_vector_matches_its_reference() {
        let report = run();
        assert_eq!(report.mismatches, 0, "{report:?}");
        assert_eq!(report.cases, 5 * (100 + GENERATED));
    }
}
