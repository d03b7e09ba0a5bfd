//! Where the fixed-point formats fail (issue 6), and the shipped-like choices avoiding it:
//! - angle resolution at slow creep: an `I16F16` angle (2⁻¹⁶ rad) cannot accumulate 1 mrad/s at
//!   10 kHz (1e-7 rad a step) and stays at zero; the mixed format's `I32F32` angle tracks it;
//! - overflow at extreme loads: at 700 N·m the ramp force (35 kN) leaves `I16F16`'s range; with
//!   wrapping arithmetic the pressing force turns negative and the held door runs away, with
//!   the saturating arithmetic the pack still holds (capacity clipped at 32 767 N, still above
//!   the load).

use fixed::types::{I16F16, I32F32};
use noback::mechanism::TABLE2;
use noback_study::reduced::num::{Real, Widen, WrapQ16};
use noback_study::reduced::{Method, Params, Reduced};

fn creep<N: Real + Widen<A>, A: Real>() -> f64 {
    let p = Params::from_mechanism(&TABLE2, 20.3, 10_000.0);
    let mut m = Reduced::<N, A>::new(p, Method::SemiImplicitEuler);
    m.set_drive(true, -1e-3);
    for _ in 0..10_000 {
        m.step();
    }
    m.state.theta.to_f64()
}

#[test]
fn i16f16_angle_cannot_see_slow_creep_and_the_mixed_format_can() {
    let pure = creep::<I16F16, I16F16>();
    let mixed = creep::<I16F16, I32F32>();
    let float = creep::<f64, f64>();
    assert!((float + 1e-3).abs() < 1e-9, "{float}");
    assert!(pure.abs() < 1e-6, "I16F16 angle moved: {pure}");
    // The speed itself is I16F16 (1 mrad/s = 65.5 ulps): 1 % quantisation remains.
    assert!((mixed + 1e-3).abs() < 0.02e-3, "{mixed}");
}

fn hold_extreme<N: Real + Widen<A>, A: Real>(load: f64) -> (f64, bool) {
    let p = Params::from_mechanism(&TABLE2, load, 10_000.0);
    let mut m = Reduced::<N, A>::new(p, Method::SemiImplicitEuler);
    for _ in 0..1_000 {
        m.step();
    }
    (m.state.omega.to_f64(), m.stuck())
}

#[test]
fn extreme_load_overflow_wraps_and_saturation_holds() {
    let load = 700.0;
    assert!(TABLE2.quasi_static_pressing_force_n(load) > 32_768.0);
    let (w_f64, stuck_f64) = hold_extreme::<f64, f64>(load);
    assert!(stuck_f64 && w_f64 == 0.0);
    let (w_sat, stuck_sat) = hold_extreme::<I16F16, I32F32>(load);
    assert!(stuck_sat && w_sat == 0.0, "saturating: {w_sat}");
    let (w_wrap, stuck_wrap) = hold_extreme::<WrapQ16, WrapQ16>(load);
    assert!(!stuck_wrap && w_wrap.abs() > 1.0, "wrapping: {w_wrap}");
    // Below the range both agree.
    let (w, stuck) = hold_extreme::<WrapQ16, WrapQ16>(300.0);
    assert!(stuck && w == 0.0);
}
