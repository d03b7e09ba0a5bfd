//! Fixed-point formats and the small helpers the 10 kHz monitor is built from.
//!
//! Every helper is total: no input panics, and each says whether it wraps (counters, which are
//! modular by nature) or saturates (physical quantities, where a clipped value is the safe
//! answer). Formats, with range and resolution:
//!
//! | alias | format | range | resolution | used for |
//! |---|---|---|---|---|
//! | [`Q16`] | `I16F16` | ±32 768 | 1.53e-5 | torques (N·m), speeds (rad/s), currents (A) |
//! | [`Gain`] | `U0F16` | [0, 1) | 1.53e-5 | filter coefficients |
//!
//! The same bits come out on the host and on thumbv6m/v7m/v7em: only integer operations are used.

use fixed::types::{I16F16, U0F16};

/// General-purpose signed format: range ±32 768, resolution 2⁻¹⁶ ≈ 1.53e-5.
pub type Q16 = I16F16;
/// Filter gain in [0, 1), resolution 2⁻¹⁶.
pub type Gain = U0F16;

/// `a·b`, exact. On ARMv6-M from 16-bit halves ([`widening_mul_by_halves`]): the runtime's
/// `__aeabi_lmul` multiplies 64 × 64 bits out of line; elsewhere the core's own long multiply.
#[inline]
pub fn widening_mul(a: i32, b: i32) -> i64 {
    #[cfg(armv6m)]
    {
        widening_mul_by_halves(a, b)
    }
    #[cfg(not(armv6m))]
    {
        i64::from(a) * i64::from(b)
    }
}

/// `a·b` from four 16 × 16-bit products, each exact in 32 bits (|aₕ·b_l| < 2³¹): the same
/// value as the 64-bit product, for cores without a long multiply.
#[inline]
pub fn widening_mul_by_halves(a: i32, b: i32) -> i64 {
    let (ah, al) = (a >> 16, a & 0xFFFF);
    let (bh, bl) = (b >> 16, b & 0xFFFF);
    // None of these overflows; wrapping keeps every profile free of a panic path.
    let low = i64::from((al as u32).wrapping_mul(bl as u32));
    let mid = i64::from(ah.wrapping_mul(bl)).wrapping_add(i64::from(al.wrapping_mul(bh)));
    (i64::from(ah.wrapping_mul(bh)) << 32)
        .wrapping_add(mid << 16)
        .wrapping_add(low)
}

/// Signed difference `now − prev` of an `bits`-wide up/down counter, **wrapping** by design:
/// the result is the shortest signed step in `[-2^(bits-1), 2^(bits-1))`. Bits above `bits` in the
/// inputs are ignored; `bits` is clamped to 1..=32.
///
/// ```
/// use noback::fx::counter_delta;
/// assert_eq!(counter_delta(16_380, 3, 14), 7);      // 14-bit encoder wrapped forward
/// assert_eq!(counter_delta(3, 16_380, 14), -7);     // and backward
/// assert_eq!(counter_delta(u32::MAX, 0, 32), 1);
/// ```
pub fn counter_delta(prev: u32, now: u32, bits: u8) -> i32 {
    let bits = u32::from(bits.clamp(1, 32));
    let shift = 32 - bits;
    // Shift the counter into the top bits so that i32 wrapping arithmetic does the modulo.
    let diff = (now << shift).wrapping_sub(prev << shift) as i32;
    diff >> shift
}

/// Offset-binary ADC code to a signed count about mid-scale, **saturating** codes above full
/// scale (a `bits`-bit converter cannot produce them; a corrupted read is clipped, not wrapped).
/// `bits` is clamped to 1..=16.
///
/// ```
/// use noback::fx::adc_centered;
/// assert_eq!(adc_centered(2048, 12), 0);
/// assert_eq!(adc_centered(0, 12), -2048);
/// assert_eq!(adc_centered(u16::MAX, 12), 2047);   // out-of-range code saturates
/// ```
pub fn adc_centered(code: u16, bits: u8) -> i32 {
    let bits = u32::from(bits.clamp(1, 16));
    let full = (1_i32 << bits) - 1;
    let mid = 1_i32 << (bits - 1);
    i32::from(code).min(full) - mid
}

/// First-order low-pass step `state + alpha·(input − state)`, exact to the last bit (truncating
/// toward −∞) and free of overflow: the difference is formed in 64 bits and the result lies
/// between `state` and `input`, so it always fits.
///
/// ```
/// use noback::fx::{lowpass, Gain, Q16};
/// let y = lowpass(Q16::from_num(0), Q16::from_num(10), Gain::from_num(0.25));
/// assert_eq!(y, Q16::from_num(2.5));
/// // Extreme inputs cannot overflow.
/// let y = lowpass(Q16::MIN, Q16::MAX, Gain::MAX);
/// assert!(y > Q16::from_num(32_766) && y <= Q16::MAX);
/// ```
pub fn lowpass(state: Q16, input: Q16, alpha: Gain) -> Q16 {
    let s = i64::from(state.to_bits());
    let d = i64::from(input.to_bits()) - s;
    let step = (d * i64::from(alpha.to_bits())) >> 16;
    // |step| < |d|, so s + step lies between state and input: the conversion cannot fail.
    Q16::from_bits(i32::try_from(s + step).unwrap_or(state.to_bits()))
}

/// Clamps an `i64` to `i32`, **saturating**: the last step of every widened fixed-point
/// product or sum.
///
/// ```
/// use noback::fx::sat_i32;
/// assert_eq!(sat_i32(1 << 40), i32::MAX);
/// assert_eq!(sat_i32(-(1 << 40)), i32::MIN);
/// assert_eq!(sat_i32(-7), -7);
/// ```
#[inline(always)]
pub fn sat_i32(x: i64) -> i32 {
    // x fits i32 iff its high word is the low word's sign extension: one 32-bit compare on a
    // 32-bit core instead of two 64-bit ones; else MIN or MAX by the sign of x.
    let lo = x as i32;
    if (x >> 32) as i32 == lo >> 31 {
        lo
    } else {
        ((x >> 63) as i32) ^ i32::MAX
    }
}

/// `a·b` for two Q16 values, rounded toward −∞ and saturated: the bits of `fixed`'s
/// `saturating_mul`, as one 32×32→64 multiply, a shift and a clamp (cheaper on Cortex-M).
#[inline]
pub fn mul_q16(a: Q16, b: Q16) -> Q16 {
    // |a·b| ≤ 2^62: the product fits an i64; `>> 16` is the floor.
    Q16::from_bits(sat_i32(widening_mul(a.to_bits(), b.to_bits()) >> 16))
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::{mul_q16, sat_i32, widening_mul_by_halves, Q16};

    #[test]
    fn the_product_by_halves_is_the_long_product() {
        let edges = [
            i32::MIN,
            i32::MIN + 1,
            -65_537,
            -65_536,
            -65_535,
            -1,
            0,
            1,
            65_535,
            65_536,
            i32::MAX,
        ];
        let mut state = 0x9E37_79B9_u32; // xorshift: a fixed, reproducible spread of operands
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state as i32
        };
        let randoms: std::vec::Vec<i32> = (0..2_000).map(|_| next()).collect();
        for &a in edges.iter().chain(&randoms) {
            for &b in edges.iter().chain(&randoms[..200]) {
                assert_eq!(
                    widening_mul_by_halves(a, b),
                    i64::from(a) * i64::from(b),
                    "{a}·{b}"
                );
            }
        }
    }

    /// The clamp `sat_i32` replaces (two 64-bit compares).
    fn clamp_reference(x: i64) -> i32 {
        x.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32
    }

    #[test]
    fn sat_i32_is_the_clamp() {
        for base in [
            0,
            i64::from(i32::MAX),
            i64::from(i32::MIN),
            1 << 32,
            -(1 << 32),
        ] {
            for d in -3..=3 {
                let x = base.wrapping_add(d);
                assert_eq!(sat_i32(x), clamp_reference(x), "{x}");
            }
        }
        for x in [
            i64::MAX,
            i64::MIN,
            i64::MAX - 1,
            i64::MIN + 1,
            1 << 62,
            -(1 << 62),
        ] {
            assert_eq!(sat_i32(x), clamp_reference(x), "{x}");
        }
        let mut s = 0x9E37_79B9_7F4A_7C15_u64;
        for _ in 0..1_000_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            // Full range, then every magnitude from 2^0 to 2^63.
            let x = s as i64;
            let y = x >> (s >> 58);
            assert_eq!(sat_i32(x), clamp_reference(x), "{x}");
            assert_eq!(sat_i32(y), clamp_reference(y), "{y}");
        }
    }

    #[test]
    fn mul_q16_has_the_bits_of_fixed_saturating_mul() {
        let mut x = 0x2545_F491_u32;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x as i32
        };
        let edges = [
            0,
            1,
            -1,
            65_536,
            -65_536,
            i32::MAX,
            i32::MIN,
            0x7FFF,
            -0x8000,
        ];
        for &a in &edges {
            for &b in &edges {
                let (qa, qb) = (Q16::from_bits(a), Q16::from_bits(b));
                assert_eq!(mul_q16(qa, qb), qa.saturating_mul(qb), "{a} × {b}");
            }
        }
        for _ in 0..100_000 {
            // Full range, and values of physical size (|x| < 2^24 bits = 256).
            let (a, b) = (next(), next());
            let (c, d) = (next() >> 8, next() >> 8);
            for (a, b) in [(a, b), (c, d), (a, d)] {
                let (qa, qb) = (Q16::from_bits(a), Q16::from_bits(b));
                assert_eq!(mul_q16(qa, qb), qa.saturating_mul(qb), "{a} × {b}");
            }
        }
    }
}
