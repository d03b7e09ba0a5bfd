//! Physical units into fixed point, once: the helpers every stage's builder uses. Each checks
//! its value and names the configuration key on failure ([`ConfigError`]).

use super::config::ConfigError;
use super::scale::{Scale, ScaleError};
use super::schedule::Lane;
use crate::fx::{Gain, Q16};

/// Largest value (in its unit) any Q16 quantity of the envelope may reach: half the format's
/// range, so that sums of two envelope values cannot saturate.
pub(crate) const Q16_ENVELOPE: f64 = 16_384.0;
/// One in Q16 bits.
pub(crate) const Q16_ONE: f64 = 65_536.0;

pub(crate) fn finite(x: f64, key: &'static str) -> Result<f64, ConfigError> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(ConfigError::NotFinite { parameter: key })
    }
}

pub(crate) fn positive(x: f64, key: &'static str) -> Result<f64, ConfigError> {
    if finite(x, key)? > 0.0 {
        Ok(x)
    } else {
        Err(ConfigError::OutOfRange { parameter: key })
    }
}

/// `Err(OutOfRange)` naming `key` unless `ok`.
pub(crate) fn require(ok: bool, key: &'static str) -> Result<(), ConfigError> {
    if ok {
        Ok(())
    } else {
        Err(ConfigError::OutOfRange { parameter: key })
    }
}

/// A constant in its [`Scale`] format.
pub(crate) fn scale<const S: u32>(k: f64, key: &'static str) -> Result<Scale<S>, ConfigError> {
    Scale::from_f64(k).map_err(|e| match e {
        ScaleError::NotFinite => ConfigError::NotFinite { parameter: key },
        ScaleError::TooLarge => ConfigError::Overflow { parameter: key },
        ScaleError::TooFine => ConfigError::OutOfRange { parameter: key },
    })
}

/// A quantity of the envelope in Q16 (|x| ≤ [`Q16_ENVELOPE`]).
pub(crate) fn q16(x: f64, key: &'static str) -> Result<Q16, ConfigError> {
    let x = finite(x, key)?;
    if !(-Q16_ENVELOPE..=Q16_ENVELOPE).contains(&x) {
        return Err(ConfigError::Overflow { parameter: key });
    }
    // In range (checked above); `checked_` so that no panic path (NaN) is compiled in.
    Q16::checked_from_num(x).ok_or(ConfigError::Overflow { parameter: key })
}

/// A filter gain in (0, 1).
pub(crate) fn gain(alpha: f64, key: &'static str) -> Result<Gain, ConfigError> {
    if alpha > 0.0 && alpha < 1.0 {
        Gain::checked_from_num(alpha).ok_or(ConfigError::OutOfRange { parameter: key })
    } else {
        Err(ConfigError::OutOfRange { parameter: key })
    }
}

/// The gain `1 − e^(−2π·f·h·lane)` of a first-order low-pass at `hz` run once per `lane`.
pub(crate) fn filter_alpha(hz: f64, tick_hz: f64, lane: Lane) -> f64 {
    1.0 - exp_neg(core::f64::consts::TAU * hz * f64::from(lane.ticks) / tick_hz)
}

/// [`filter_alpha`] as a [`Gain`], `hz` checked.
pub(crate) fn filter_gain(
    hz: f64,
    tick_hz: f64,
    lane: Lane,
    key: &'static str,
) -> Result<Gain, ConfigError> {
    gain(filter_alpha(positive(hz, key)?, tick_hz, lane), key)
}

/// Seconds to ticks, at least 1, at most 2^31.
pub(crate) fn ticks(seconds: f64, tick_hz: f64, key: &'static str) -> Result<u32, ConfigError> {
    let t = positive(seconds, key)? * tick_hz;
    if t > 2_147_483_648.0 {
        return Err(ConfigError::Overflow { parameter: key });
    }
    Ok(((t + 0.5) as u32).max(1))
}

/// A count limit (≥ 1) that fits an i32 with room to spare.
pub(crate) fn counts(x: f64, key: &'static str) -> Result<i32, ConfigError> {
    let x = positive(x, key)?;
    if x > 1.0e9 {
        return Err(ConfigError::Overflow { parameter: key });
    }
    Ok(((x + 0.5) as i32).max(1))
}

/// The shift `k` whose gain `2^-k` is nearest to `gain` on a log scale (0 for gains ≥ 1/√2,
/// 30 at most).
pub(crate) fn nearest_shift(gain: f64) -> u32 {
    let mut k = 0;
    let mut x = gain;
    while x < core::f64::consts::FRAC_1_SQRT_2 && k < 30 {
        x *= 2.0;
        k += 1;
    }
    k
}

/// `e^-x` for `x ≥ 0` (configuration time only; `no_std` has no `exp`): halve until ≤ 1/64,
/// Taylor, square back.
pub(crate) fn exp_neg(x: f64) -> f64 {
    if x.is_nan() {
        return f64::NAN;
    }
    if x < 0.0 || !x.is_finite() {
        return 0.0;
    }
    let mut y = x;
    let mut halvings = 0;
    while y > 1.0 / 64.0 && halvings < 64 {
        y *= 0.5;
        halvings += 1;
    }
    let mut term = 1.0;
    let mut sum = 1.0;
    let mut k = 1.0;
    while k < 12.0 {
        term *= -y / k;
        sum += term;
        k += 1.0;
    }
    while halvings > 0 {
        sum *= sum;
        halvings -= 1;
    }
    sum
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    #[test]
    fn exp_neg_is_exact_enough() {
        for x in [0.0, 1e-6, 0.0125, 0.5, 1.0, 3.0, 20.0] {
            assert!(
                (exp_neg(x) - (-x).exp()).abs() < 1e-13 * 1.0_f64.max((-x).exp()),
                "{x}"
            );
        }
    }

    #[test]
    fn nearest_shift_rounds_on_a_log_scale() {
        assert_eq!(nearest_shift(1.0), 0);
        assert_eq!(nearest_shift(1.0 / 64.0), 6);
        assert_eq!(nearest_shift(0.0125), 6); // 1/80: nearer 1/64 than 1/128
    }
}
