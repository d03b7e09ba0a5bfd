//! The number formats the reduced model is generic over, behind one small trait, [`Real`].
//!
//! | type | range | resolution | constants ([`Real::K`]) | arithmetic |
//! |---|---|---|---|---|
//! | `f64` | ±1.8e308 | 53-bit mantissa (≈1e-16 relative) | `f64` | IEEE (soft float on M0/M3/M4F) |
//! | `f32` | ±3.4e38 | 24-bit mantissa (≈6e-8 relative) | `f32` | IEEE (FPU on M4F, soft on M0/M3) |
//! | `I16F16` | ±32 768 | 2⁻¹⁶ ≈ 1.53e-5 | [`KQ16`]: i32 mantissa · 2⁻ˢ, ≥ 29 significant bits | **saturating** |
//! | `I32F32` | ±2.1e9 | 2⁻³² ≈ 2.3e-10 | `I32F32` | **saturating** |
//! | [`WrapQ16`] | ±32 768 | 2⁻¹⁶ | [`KQ16`] | **wrapping** (only to show what saturation prevents) |
//!
//! Fixed-point sums and products saturate on purpose: a clipped torque or force is the safe
//! answer, a wrapped one changes sign (`tests/bench_fixed_point.rs` shows the difference at
//! extreme loads). `I16F16` multiplies by constants through [`KQ16`], a 32-bit mantissa with
//! its own binary point, because a step `dt = 1e-4 s` is only 6.5 ulps of `I16F16` (7 %
//! error): constants must not be stored in the state's format. The monitor's `Scale<S>` would
//! do (one `S` per role) but halves the measured I16F16 step cost, so the study keeps the
//! figures it published (docs/decisions.md, issue 15).
//!
//! Conversions from `f64` ([`Real::from_f64`], [`Real::konst`]) are for configuration time;
//! the step itself uses only [`Real::add`], [`Real::sub`], [`Real::mulk`], comparisons and
//! [`Widen::widen`].

use fixed::types::{I16F16, I32F32};
use noback::fx::sat_i32 as sat32;
use noback::table1::Torque;

/// A number format of the reduced model (a [`Torque`] so that Table 1 applies to it).
pub trait Real: Torque + core::fmt::Debug {
    /// The format of multiplicative constants (`dt`, `1/J`, capacities per newton).
    type K: Copy + core::fmt::Debug;
    /// Short name used in tables (`f64`, `f32`, `I16F16`, `I32F32`, `wrapI16F16`).
    const NAME: &'static str;
    /// Converts (saturating for fixed point; NaN becomes 0).
    fn from_f64(x: f64) -> Self;
    /// The value as `f64` (for reports; exact for every format here).
    fn to_f64(self) -> f64;
    /// Converts a constant.
    fn konst(x: f64) -> Self::K;
    /// `self + o`.
    fn add(self, o: Self) -> Self;
    /// `self − o`.
    fn sub(self, o: Self) -> Self;
    /// `self · k`.
    fn mulk(self, k: Self::K) -> Self;
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
    type K = f64;
    const NAME: &'static str = "f64";
    fn from_f64(x: f64) -> Self {
        x
    }
    fn to_f64(self) -> f64 {
        self
    }
    fn konst(x: f64) -> f64 {
        x
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
    fn mulk(self, k: f64) -> Self {
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
    type K = f32;
    const NAME: &'static str = "f32";
    fn from_f64(x: f64) -> Self {
        x as f32
    }
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
    fn konst(x: f64) -> f32 {
        x as f32
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
    fn mulk(self, k: f32) -> Self {
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

/// A constant for [`I16F16`]: `m · 2^-s` with `|m| < 2^30` (≥ 29 significant bits for any
/// constant in `[2^-32, 2^30)`), applied to the raw bits with one 32×32→64 multiply, rounded
/// to nearest and saturated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct KQ16 {
    m: i32,
    s: u32,
}

impl KQ16 {
    /// Converts `k` (NaN → 0; magnitudes ≥ 2^30 saturate).
    pub fn from_f64(k: f64) -> KQ16 {
        if k.is_nan() || k == 0.0 {
            return KQ16 { m: 0, s: 0 };
        }
        let limit = 1_073_741_824.0; // 2^30
        let mut mag = if k < 0.0 { -k } else { k };
        let mut s = 0_u32;
        while mag * 2.0 < limit && s < 62 {
            mag *= 2.0;
            s += 1;
        }
        let m = if mag >= limit { limit - 1.0 } else { mag + 0.5 };
        let m = m as i32;
        KQ16 {
            m: if k < 0.0 { -m } else { m },
            s,
        }
    }

    /// The value as `f64`.
    pub fn to_f64(self) -> f64 {
        let mut v = f64::from(self.m);
        let mut s = self.s;
        while s > 0 {
            v *= 0.5;
            s -= 1;
        }
        v
    }

    /// `bits · k`, rounded to nearest, as an unclamped `i64`.
    #[inline(always)]
    fn apply_wide(self, bits: i32) -> i64 {
        let p = i64::from(bits) * i64::from(self.m);
        if self.s == 0 {
            p
        } else {
            (p + (1_i64 << (self.s - 1))) >> self.s
        }
    }
}

impl Real for I16F16 {
    type K = KQ16;
    const NAME: &'static str = "I16F16";
    fn from_f64(x: f64) -> Self {
        I16F16::saturating_from_num(if x.is_nan() { 0.0 } else { x })
    }
    fn to_f64(self) -> f64 {
        self.to_num::<f64>()
    }
    fn konst(x: f64) -> KQ16 {
        KQ16::from_f64(x)
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
    fn mulk(self, k: KQ16) -> Self {
        I16F16::from_bits(sat32(k.apply_wide(self.to_bits())))
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
    type K = I32F32;
    const NAME: &'static str = "I32F32";
    fn from_f64(x: f64) -> Self {
        I32F32::saturating_from_num(if x.is_nan() { 0.0 } else { x })
    }
    fn to_f64(self) -> f64 {
        self.to_num::<f64>()
    }
    fn konst(x: f64) -> I32F32 {
        Self::from_f64(x)
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
    fn mulk(self, k: I32F32) -> Self {
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
    type K = KQ16;
    const NAME: &'static str = "wrapI16F16";
    fn from_f64(x: f64) -> Self {
        WrapQ16(I16F16::wrapping_from_num(if x.is_nan() { 0.0 } else { x }))
    }
    fn to_f64(self) -> f64 {
        self.0.to_num::<f64>()
    }
    fn konst(x: f64) -> KQ16 {
        KQ16::from_f64(x)
    }
    fn add(self, o: Self) -> Self {
        WrapQ16(self.0.wrapping_add(o.0))
    }
    fn sub(self, o: Self) -> Self {
        WrapQ16(self.0.wrapping_sub(o.0))
    }
    fn mulk(self, k: KQ16) -> Self {
        WrapQ16(I16F16::from_bits(k.apply_wide(self.0.to_bits()) as i32))
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
    fn kq16_keeps_small_constants_exact_enough() {
        let dt = KQ16::from_f64(1e-4);
        assert!((dt.to_f64() - 1e-4).abs() < 1e-4 * 1e-8);
        // 13.78 rad/s × 1e-4 s in I16F16: one rounding of the product, not of dt.
        let w = I16F16::from_f64(13.78);
        let step = w.mulk(dt);
        assert!((step.to_f64() - 1.378e-3).abs() <= 2.0 / 65_536.0);
        assert_eq!(KQ16::from_f64(-2.5).to_f64(), -2.5);
        assert_eq!(I16F16::from_f64(1e9), I16F16::MAX);
        assert_eq!(I16F16::MAX.mulk(KQ16::from_f64(4.0)), I16F16::MAX);
        assert_eq!(I16F16::MIN.mulk(KQ16::from_f64(4.0)), I16F16::MIN);
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
