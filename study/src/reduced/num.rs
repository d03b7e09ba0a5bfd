//! The number formats the reduced model is generic over, behind one small trait, [`Real`].
//!
//! | type | range | resolution | constants ([`Real::K`]) | arithmetic |
//! |---|---|---|---|---|
//! | `f64` | ±1.8e308 | 53-bit mantissa (≈1e-16 relative) | `f64` | IEEE (soft float on M0/M3/M4F) |
//! | `f32` | ±3.4e38 | 24-bit mantissa (≈6e-8 relative) | `f32` | IEEE (FPU on M4F, soft on M0/M3) |
//! | `I16F16` | ±32 768 | 2⁻¹⁶ ≈ 1.53e-5 | `Scale<S>` (the monitor's): i32 mantissa · 2⁻ˢ, ≥ 20 significant bits | **saturating** |
//! | `I32F32` | ±2.1e9 | 2⁻³² ≈ 2.3e-10 | `I32F32` | **saturating** |
//! | [`WrapQ16`] | ±32 768 | 2⁻¹⁶ | `Scale<S>` | **wrapping** (only to show what saturation prevents) |
//!
//! Fixed-point sums and products saturate on purpose: a clipped torque or force is the safe
//! answer, a wrapped one changes sign (`tests/bench_fixed_point.rs` shows the difference at
//! extreme loads). `I16F16` multiplies by constants through `noback::monitor::Scale<S>`, the
//! flight monitor's constant type, a 32-bit mantissa with the binary point `S` in the type
//! (one per role: [`crate::reduced`]'s `S_CAP`, `S_INV_J`, `S_DT`), because a step
//! `dt = 1e-4 s` is only 6.5 ulps of `I16F16` (7 % error): constants must not be stored in the
//! state's format. Floats and `I32F32` ignore `S`.
//!
//! Conversions from `f64` ([`Real::from_f64`], [`Real::konst`]) are for configuration time;
//! the step itself uses only [`Real::add`], [`Real::sub`], [`Real::mulk`], comparisons and
//! [`Widen::widen`].

use fixed::types::{I16F16, I32F32};
use noback::monitor::{Scale, ScaleError};
use noback::table1::Torque;

/// A number format of the reduced model (a [`Torque`] so that Table 1 applies to it).
pub trait Real: Torque + core::fmt::Debug {
    /// The format of multiplicative constants (`dt`, `1/J`, capacities per newton) with `S`
    /// fractional bits where the format has a binary point to choose.
    type K<const S: u32>: Copy + core::fmt::Debug;
    /// Short name used in tables (`f64`, `f32`, `I16F16`, `I32F32`, `wrapI16F16`).
    const NAME: &'static str;
    /// Converts (saturating for fixed point; NaN becomes 0).
    fn from_f64(x: f64) -> Self;
    /// The value as `f64` (for reports; exact for every format here).
    fn to_f64(self) -> f64;
    /// Converts a constant (fails where it does not fit `Scale<S>`).
    fn konst<const S: u32>(x: f64) -> Result<Self::K<S>, ScaleError>;
    /// `self + o`.
    fn add(self, o: Self) -> Self;
    /// `self − o`.
    fn sub(self, o: Self) -> Self;
    /// `self · k`.
    fn mulk<const S: u32>(self, k: Self::K<S>) -> Self;
    /// `−self`.
    fn neg(self) -> Self;
    /// False only for a non-finite float.
    fn is_finite(self) -> bool;
    /// `|self|`.
    fn abs(self) -> Self {
        if self < Self::ZERO {
            self.neg()
        } else {
            self
        }
    }
}

/// Lossless (or format-preserving) conversion of a speed into the angle format.
pub trait Widen<A> {
    /// The value in format `A`.
    fn widen(self) -> A;
}

impl<T: Real> Widen<T> for T {
    #[inline(always)]
    fn widen(self) -> T {
        self
    }
}

impl Widen<I32F32> for I16F16 {
    #[inline(always)]
    fn widen(self) -> I32F32 {
        I32F32::from_bits(i64::from(self.to_bits()) << 16)
    }
}

impl Real for f64 {
    type K<const S: u32> = f64;
    const NAME: &'static str = "f64";
    fn from_f64(x: f64) -> Self {
        x
    }
    fn to_f64(self) -> f64 {
        self
    }
    fn konst<const S: u32>(x: f64) -> Result<f64, ScaleError> {
        Ok(x)
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        self + o
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        self - o
    }
    #[inline(always)]
    fn mulk<const S: u32>(self, k: f64) -> Self {
        self * k
    }
    #[inline(always)]
    fn neg(self) -> Self {
        -self
    }
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
}

impl Real for f32 {
    type K<const S: u32> = f32;
    const NAME: &'static str = "f32";
    fn from_f64(x: f64) -> Self {
        x as f32
    }
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
    fn konst<const S: u32>(x: f64) -> Result<f32, ScaleError> {
        Ok(x as f32)
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        self + o
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        self - o
    }
    #[inline(always)]
    fn mulk<const S: u32>(self, k: f32) -> Self {
        self * k
    }
    #[inline(always)]
    fn neg(self) -> Self {
        -self
    }
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
}

impl Real for I16F16 {
    type K<const S: u32> = Scale<S>;
    const NAME: &'static str = "I16F16";
    fn from_f64(x: f64) -> Self {
        I16F16::saturating_from_num(if x.is_nan() { 0.0 } else { x })
    }
    fn to_f64(self) -> f64 {
        self.to_num::<f64>()
    }
    fn konst<const S: u32>(x: f64) -> Result<Scale<S>, ScaleError> {
        Scale::from_f64(x)
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        self.saturating_add(o)
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        self.saturating_sub(o)
    }
    #[inline(always)]
    fn mulk<const S: u32>(self, k: Scale<S>) -> Self {
        I16F16::from_bits(k.apply(self.to_bits()))
    }
    #[inline(always)]
    fn neg(self) -> Self {
        self.saturating_neg()
    }
    fn is_finite(self) -> bool {
        true
    }
}

impl Real for I32F32 {
    type K<const S: u32> = I32F32;
    const NAME: &'static str = "I32F32";
    fn from_f64(x: f64) -> Self {
        I32F32::saturating_from_num(if x.is_nan() { 0.0 } else { x })
    }
    fn to_f64(self) -> f64 {
        self.to_num::<f64>()
    }
    fn konst<const S: u32>(x: f64) -> Result<I32F32, ScaleError> {
        Ok(Self::from_f64(x))
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        self.saturating_add(o)
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        self.saturating_sub(o)
    }
    #[inline(always)]
    fn mulk<const S: u32>(self, k: I32F32) -> Self {
        self.saturating_mul(k)
    }
    #[inline(always)]
    fn neg(self) -> Self {
        self.saturating_neg()
    }
    fn is_finite(self) -> bool {
        true
    }
}

/// `I16F16` with **wrapping** arithmetic: the format a careless port would use. Only here to
/// demonstrate overflow (a wrapped pressing force turns negative); never shipped.
#[derive(Clone, Copy, Debug, PartialEq, PartialOrd)]
pub struct WrapQ16(pub I16F16);

impl Torque for WrapQ16 {
    const ZERO: Self = WrapQ16(I16F16::ZERO);
    fn negated(self) -> Self {
        WrapQ16(self.0.wrapping_neg())
    }
}

impl Real for WrapQ16 {
    type K<const S: u32> = Scale<S>;
    const NAME: &'static str = "wrapI16F16";
    fn from_f64(x: f64) -> Self {
        WrapQ16(I16F16::wrapping_from_num(if x.is_nan() { 0.0 } else { x }))
    }
    fn to_f64(self) -> f64 {
        self.0.to_num::<f64>()
    }
    fn konst<const S: u32>(x: f64) -> Result<Scale<S>, ScaleError> {
        Scale::from_f64(x)
    }
    fn add(self, o: Self) -> Self {
        WrapQ16(self.0.wrapping_add(o.0))
    }
    fn sub(self, o: Self) -> Self {
        WrapQ16(self.0.wrapping_sub(o.0))
    }
    fn mulk<const S: u32>(self, k: Scale<S>) -> Self {
        // `Scale::apply` rounded the same way, but wrapped instead of saturated.
        let wide = i64::from(self.0.to_bits()) * i64::from(k.mantissa()) + (1_i64 << (S - 1));
        WrapQ16(I16F16::from_bits((wide >> S) as i32))
    }
    fn neg(self) -> Self {
        WrapQ16(self.0.wrapping_neg())
    }
    fn is_finite(self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_keeps_small_constants_exact_enough() {
        let dt = I16F16::konst::<40>(1e-4).unwrap();
        assert!((dt.to_f64() - 1e-4).abs() < 1e-4 * 1e-7);
        // 13.78 rad/s × 1e-4 s in I16F16: one rounding of the product, not of dt.
        let w = I16F16::from_f64(13.78);
        let step = w.mulk(dt);
        assert!((step.to_f64() - 1.378e-3).abs() <= 2.0 / 65_536.0);
        assert_eq!(I16F16::from_f64(1e9), I16F16::MAX);
        let four = I16F16::konst::<26>(4.0).unwrap();
        assert_eq!(I16F16::MAX.mulk(four), I16F16::MAX);
        assert_eq!(I16F16::MIN.mulk(four), I16F16::MIN);
        assert!(WrapQ16(I16F16::MAX).mulk(four).to_f64() < 0.0);
    }

    #[test]
    fn widening_is_exact() {
        let x = I16F16::from_bits(-123_457);
        let w: I32F32 = x.widen();
        assert_eq!(w.to_num::<f64>(), x.to_num::<f64>());
    }

    #[test]
    fn wrapping_wraps_and_saturating_saturates() {
        let big = 30_000.0;
        assert!(WrapQ16::from_f64(big).add(WrapQ16::from_f64(big)).to_f64() < 0.0);
        assert_eq!(
            I16F16::from_f64(big).add(I16F16::from_f64(big)),
            I16F16::MAX
        );
    }
}
