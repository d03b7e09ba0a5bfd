//! Shared test vectors for the arithmetic the monitor ships, run natively and under QEMU.
//!
//! The vectors are generated, not stored: a fixed-seed xorshift32 stream plus the edge cases
//! (zero, ±1 LSB, the formats' limits). [`run`] feeds every vector through `fx::counter_delta`,
//! `fx::adc_centered`, `fx::lowpass`, `monitor::mul_q16` and `monitor::Scale::apply` at every
//! binary point the monitor uses, checks each result against an independent i128 reference, and folds the outputs into an FNV-1a digest. The host test and
//! the target test both call it; the xtask compares the digest printed under QEMU with the one
//! it computes natively, so "bit-identical" is checked by a third party rather than asserted by
//! the target about itself.

use crate::digest::Fnv1a;
use crate::fx::{adc_centered, counter_delta, lowpass, Gain, Q16};
use crate::monitor::{mul_q16, Scale};

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
        for (got, ok) in cases(a, b, third) {
            report.cases += 1;
            if !ok {
                report.mismatches += 1;
            }
            fnv.push(got);
        }
    }
    report.digest = fnv.value();
    report
}

/// Binary points of the `Scale<S>` constants in `src/monitor` (`grep 'Scale<' src/monitor`).
pub const SCALE_POINTS: [u32; 15] = [8, 11, 16, 20, 21, 24, 25, 26, 28, 30, 32, 33, 36, 37, 38];

/// Cases per vector: three `fx` helpers, `mul_q16`, one `Scale` per binary point.
pub const CASES_PER_VECTOR: u32 = 4 + SCALE_POINTS.len() as u32;

/// The helpers' outputs for one vector, each with whether it matches its i128 reference.
fn cases(a: u32, b: u32, c: u32) -> [(u32, bool); CASES_PER_VECTOR as usize] {
    let bits = (c % 32) as u8 + 1;
    let adc_bits = (c % 16) as u8 + 1;
    let (ia, ib) = (a as i32, b as i32);
    let (qa, qb) = (Q16::from_bits(ia), Q16::from_bits(ib));
    let alpha = Gain::from_bits((c >> 16) as u16);
    let exact = |got: i32, want: i128| (got as u32, i128::from(got) == want);
    // A mantissa the way `Scale::from_f64` stores one: 0 or 2^20 ≤ |m| < 2^31.
    let magnitude = (b & 0x7FFF_FFFF) | 0x0010_0000;
    let m = if c & 1 == 0 {
        0
    } else if b & 0x8000_0000 != 0 {
        -(magnitude as i32)
    } else {
        magnitude as i32
    };
    [
        exact(
            counter_delta(a, b, bits),
            ref_counter_delta(a, b, bits).into(),
        ),
        exact(
            adc_centered(a as u16, adc_bits),
            ref_adc_centered(a as u16, adc_bits).into(),
        ),
        exact(
            lowpass(qa, qb, alpha).to_bits(),
            ref_lowpass(ia, ib, (c >> 16) as u16),
        ),
        exact(mul_q16(qa, qb).to_bits(), ref_mul_q16(ia, ib)),
        scale_case::<8>(ia, m),
        scale_case::<11>(ia, m),
        scale_case::<16>(ia, m),
        scale_case::<20>(ia, m),
        scale_case::<21>(ia, m),
        scale_case::<24>(ia, m),
        scale_case::<25>(ia, m),
        scale_case::<26>(ia, m),
        scale_case::<28>(ia, m),
        scale_case::<30>(ia, m),
        scale_case::<32>(ia, m),
        scale_case::<33>(ia, m),
        scale_case::<36>(ia, m),
        scale_case::<37>(ia, m),
        scale_case::<38>(ia, m),
    ]
}

/// `Scale::<S>` with mantissa `m` (built through `from_f64`, exact for such `m`) applied to `x`,
/// against `x·m/2^S` rounded half up and saturated.
fn scale_case<const S: u32>(x: i32, m: i32) -> (u32, bool) {
    let k = f64::from(m) * const { 1.0 / (1_u64 << S) as f64 };
    let Ok(scale) = Scale::<S>::from_f64(k) else {
        return (0, false);
    };
    let got = scale.apply(x);
    let wide = (i128::from(x) * i128::from(m) + (1_i128 << (S - 1))).div_euclid(1_i128 << S);
    let want = wide.clamp(i128::from(i32::MIN), i128::from(i32::MAX));
    (got as u32, scale.mantissa() == m && i128::from(got) == want)
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

fn ref_lowpass(state: i32, input: i32, alpha: u16) -> i128 {
    let num = (i128::from(input) - i128::from(state)) * i128::from(alpha);
    // floor division by 2^16
    i128::from(state) + num.div_euclid(1 << 16)
}

fn ref_mul_q16(a: i32, b: i32) -> i128 {
    let p = (i128::from(a) * i128::from(b)).div_euclid(1 << 16);
    p.clamp(i128::from(i32::MIN), i128::from(i32::MAX))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_vector_matches_its_reference() {
        let report = run();
        assert_eq!(report.mismatches, 0, "{report:?}");
        assert_eq!(report.cases, CASES_PER_VECTOR * (100 + GENERATED));
    }
}
