//! Property tests: each fixed-point helper the monitor ships (`noback::fx`, `mul_q16`,
//! `Scale::apply`) against its f64 reference.
//!
//! The bound in each test is the format's resolution (one LSB, 2⁻¹⁶), since the helpers
//! truncate toward −∞; anything larger is a bug, not rounding.

use noback::fx::{adc_centered, counter_delta, lowpass, Gain, Q16};
use noback::monitor::{mul_q16, Scale};
use proptest::prelude::*;

const LSB: f64 = 1.0 / 65_536.0;

proptest! {
    #[test]
    fn mul_q16_is_within_one_lsb_or_saturated(a in any::<i32>(), b in any::<i32>()) {
        let (qa, qb) = (Q16::from_bits(a), Q16::from_bits(b));
        let exact = qa.to_num::<f64>() * qb.to_num::<f64>();
        let got = mul_q16(qa, qb).to_num::<f64>();
        let clamped = exact.clamp(Q16::MIN.to_num::<f64>(), Q16::MAX.to_num::<f64>());
        prop_assert!((got - clamped).abs() <= LSB, "{} * {} = {} want {}", qa, qb, got, clamped);
    }

    #[test]
    fn lowpass_is_between_state_and_input(s in any::<i32>(), x in any::<i32>(), a in any::<u16>()) {
        let (qs, qx, ga) = (Q16::from_bits(s), Q16::from_bits(x), Gain::from_bits(a));
        let exact = qs.to_num::<f64>() + ga.to_num::<f64>() * (qx.to_num::<f64>() - qs.to_num::<f64>());
        let got = lowpass(qs, qx, ga).to_num::<f64>();
        prop_assert!((got - exact).abs() <= LSB);
        prop_assert!(got >= qs.min(qx).to_num::<f64>() && got <= qs.max(qx).to_num::<f64>());
    }

    #[test]
    fn counter_delta_recovers_small_steps(start in any::<u32>(), step in -8000_i32..8000, bits in 14_u8..=32) {
        let mask = if bits == 32 { u32::MAX } else { (1_u32 << bits) - 1 };
        let now = start.wrapping_add(step as u32) & mask;
        prop_assert_eq!(counter_delta(start & mask, now, bits), step);
    }

    #[test]
    fn adc_centered_is_bounded(code in any::<u16>(), bits in 1_u8..=16) {
        let c = adc_centered(code, bits);
        let half = 1_i32 << (bits - 1);
        prop_assert!(c >= -half && c < half);
    }

    #[test]
    fn scale_apply_is_within_half_an_lsb_or_saturated(x in -(1_i32 << 22)..(1 << 22), k in -3e4_f64..3e4) {
        // Rounded to nearest: within ½ LSB of x·k for the stored k (|x·mantissa| < 2^53, so
        // the f64 product is exact).
        let Ok(scale) = Scale::<16>::from_f64(k) else { return Ok(()) };
        let exact = f64::from(x) * scale.to_f64();
        let clamped = exact.clamp(f64::from(i32::MIN), f64::from(i32::MAX));
        prop_assert!((f64::from(scale.apply(x)) - clamped).abs() <= 0.5);
    }
}

#[test]
fn shared_vectors_pass_on_the_host() {
    let report = noback::vectors::run();
    assert_eq!(report.mismatches, 0, "{report:?}");
}
