//! Constant multipliers: the only arithmetic the 10 kHz step needs besides additions and
//! `mul_q16`.
//!
//! Every physical constant the step multiplies by (gains, unit conversions, `h/J_s`, …) is
//! converted once, in `Monitor::new`, into a [`Scale<S>`]: a 32-bit mantissa with the binary
//! point fixed **in the type**, `k = mul · 2^-S`. Each use site picks `S` so that the default
//! constant's mantissa is about 2^26–2^28: every constant keeps ≥ 20 significant bits over a
//! ×64 range below its default and ×8–×32 above it; outside that range `Monitor::new` rejects
//! the configuration, naming the parameter. The product of an `i32` input with the mantissa
//! fits an `i64` (|x·mul| < 2^62); it is rounded to nearest (ties up) and, when `S < 32`,
//! **saturated** to `i32` (the inputs are physical quantities: a clipped value is the safe
//! answer). With `S ≥ 32` the result is below 2^30 and cannot saturate, and the shift is the
//! product's high word plus one 32-bit shift: about 6 instructions on Cortex-M3.

pub use crate::fx::sat_i32;
/// Why a constant does not fit a [`Scale<S>`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScaleError {
    /// NaN or infinite.
    NotFinite,
    /// `|k|·2^S ≥ 2^31`: the mantissa would overflow.
    TooLarge,
    /// `0 < |k|·2^S < 2^20`: fewer than 20 significant bits would be left.
    TooFine,
}

/// A constant `k = mul · 2^-S`, applied to `i32` fixed-point bits. `S` is the number of
/// fractional bits of the mantissa (1 ≤ S ≤ 62).
///
/// ```
/// use noback::monitor::Scale;
/// let k = Scale::<30>::from_f64(0.1).unwrap();
/// assert_eq!(k.apply(1_000), 100);
/// assert_eq!(k.apply(-15), -1);          // −1.5 rounds half up to −1
/// let big = Scale::<8>::from_f64(1.0e6).unwrap();
/// assert_eq!(big.apply(1 << 20), i32::MAX); // saturates
/// assert!(Scale::<30>::from_f64(4.0).is_err()); // 4·2^30 does not fit 31 bits
/// ```
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Scale<const S: u32> {
    mul: i32,
}

/// 2^31 and 2^20 as f64.
const MANTISSA_LIMIT: f64 = 2_147_483_648.0;
const MANTISSA_FLOOR: f64 = 1_048_576.0;

impl<const S: u32> Scale<S> {
    /// Zero.
    pub const ZERO: Self = Scale { mul: 0 };

    /// Converts `k`; see [`ScaleError`] for the limits.
    pub fn from_f64(k: f64) -> Result<Self, ScaleError> {
        const { assert!(S >= 1 && S <= 62, "Scale<S>: 1 ≤ S ≤ 62") };
        if !k.is_finite() {
            return Err(ScaleError::NotFinite);
        }
        let mut scaled = if k < 0.0 { -k } else { k };
        let mut s = 0;
        while s < S {
            scaled *= 2.0;
            s += 1;
        }
        if scaled + 0.5 >= MANTISSA_LIMIT {
            return Err(ScaleError::TooLarge);
        }
        if scaled != 0.0 && scaled < MANTISSA_FLOOR {
            return Err(ScaleError::TooFine);
        }
        let mul = (scaled + 0.5) as i32; // `as` truncates; 0 ≤ scaled + 0.5 < 2^31
        Ok(Scale {
            mul: if k < 0.0 { -mul } else { mul },
        })
    }

    /// `x · k`, rounded to nearest; saturated to `i32` when `S < 32` (it cannot overflow
    /// otherwise).
    #[inline]
    pub fn apply(self, x: i32) -> i32 {
        // |x·mul| < 2^31·2^31 = 2^62 and the rounding term ≤ 2^61: the sum fits an i64.
        let wide = crate::fx::widening_mul(x, self.mul) + (1_i64 << (S - 1));
        if S >= 32 {
            // |wide| < 2^62 + 2^61 → |wide >> S| < 2^31: exact conversion.
            (wide >> S) as i32
        } else {
            sat_i32(wide >> S)
        }
    }

    /// The value this scale represents (for tests and documentation; not used by the step).
    pub fn to_f64(self) -> f64 {
        let mut v = f64::from(self.mul);
        let mut s = 0;
        while s < S {
            v *= 0.5;
            s += 1;
        }
        v
    }

    /// The mantissa (`k = mul · 2^-S`).
    pub const fn mantissa(self) -> i32 {
        self.mul
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    #[test]
    fn scale_keeps_20_bits_and_rejects_the_rest() {
        for k in [1.0e-3, 3.7e-4, 0.25, 0.4999, -0.0498] {
            let s = Scale::<32>::from_f64(k).unwrap_or(Scale::ZERO);
            assert!((s.to_f64() - k).abs() <= 2f64.powi(-33), "{k}");
        }
        assert_eq!(Scale::<32>::from_f64(f64::NAN), Err(ScaleError::NotFinite));
        assert_eq!(Scale::<32>::from_f64(0.5), Err(ScaleError::TooLarge));
        assert_eq!(Scale::<32>::from_f64(1.0e-7), Err(ScaleError::TooFine));
        assert_eq!(Scale::<32>::from_f64(0.0), Ok(Scale::ZERO));
    }

    #[test]
    fn apply_rounds_to_nearest() {
        let third = Scale::<32>::from_f64(1.0 / 3.0).unwrap_or(Scale::ZERO);
        assert_eq!(third.apply(3), 1);
        assert_eq!(third.apply(2), 1);
        assert_eq!(third.apply(1), 0);
        assert_eq!(third.apply(-2), -1);
        // The stored 1/3 is (2^32 − 1)/3 · 2^-32, so −2^31·k = −715 827 882.5: ties round up.
        assert_eq!(third.apply(i32::MIN), -715_827_882);
        let big = Scale::<16>::from_f64(1000.0).unwrap_or(Scale::ZERO);
        assert_eq!(big.apply(i32::MIN), i32::MIN);
        assert_eq!(big.apply(-2_000), -2_000_000);
    }
}
