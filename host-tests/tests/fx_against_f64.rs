//! Property tests: each fixed-point helper in `noback::fx` against its f64 reference.
//!
//! The bound in each test is the format's resolution (one LSB, 2⁻¹⁶), since the helpers
//! truncate toward −∞; anything larger is a bug, not rounding.

use noback::fx::{adc_centered, counter_delta, lowpass, mul_sat, scale_count, Gain, Q16};
use proptest::prelude::*;

const LSB: f64 = 1.0 / 65_536.0;

proptest! {
    #[test]
    fn mul_sat_is_within_one_lsb_or_saturated(a in any::<i32>(), b in any::<i32>()) {
        let (qa, qb) = (Q16::from_bits(a), Q16::from_bits(b));
        let exact = qa.to_num::<f64>() * qb.to_num::<f64>();
        let got = mul_sat(qa, qb).to_num::<f64>();
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
    fn scale_count_matches_f64(count in -1_000_000_i32..1_000_000, scale in -100.0_f64..100.0) {
        let q = Q16::from_num(scale);
        let exact = f64::from(count) * q.to_num::<f64>();
        let clamped = exact.clamp(Q16::MIN.to_num::<f64>(), Q16::MAX.to_num::<f64>());
        prop_assert!((scale_count(count, q).to_num::<f64>() - clamped).abs() <= LSB);
    }
}

#[test]
fn shared_vectors_pass_on_the_host() {
    let report = noback::vectors::run();
    assert_eq!(report.mismatches, 0, "{report:?}");
}
