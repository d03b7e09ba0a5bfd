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
    if x > i64::from(i32::MAX) {
        i32::MAX
    } else if x < i64::from(i32::MIN) {
        i32::MIN
    } else {
        x as i32
    }
}

/// `a · b` in [`Q16`], **saturating** at the format's limits (a clipped torque is the safe answer).
///
/// ```
/// use noback::fx::{mul_sat, Q16};
/// assert_eq!(mul_sat(Q16::from_num(1.5), Q16::from_num(-2)), Q16::from_num(-3));
/// assert_eq!(mul_sat(Q16::from_num(300), Q16::from_num(300)), Q16::MAX);
/// ```
pub fn mul_sat(a: Q16, b: Q16) -> Q16 {
    a.saturating_mul(b)
}

/// Integer count times a [`Q16`] scale (e.g. ADC counts × amperes per count), **saturating**.
///
/// ```
/// use noback::fx::{scale_count, Q16};
/// assert_eq!(scale_count(-2048, Q16::from_num(0.5)), Q16::from_num(-1024));
/// assert_eq!(scale_count(i32::MAX, Q16::from_num(2)), Q16::MAX);
/// ```
pub fn scale_count(count: i32, scale: Q16) -> Q16 {
    let wide = i64::from(count) * i64::from(scale.to_bits());
    let clamped = wide.clamp(i64::from(i32::MIN), i64::from(i32::MAX));
    Q16::from_bits(i32::try_from(clamped).unwrap_or(i32::MAX))
}
