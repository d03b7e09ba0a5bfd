//! Property tests of the monitor's fixed-point helpers against f64, and of `Monitor::step` on
//! arbitrary input streams (never panics, outputs bounded, flags latch).

use noback::mechanism::TABLE2;
use noback::monitor::{
    Config, Estimate, Inputs, Monitor, ObserverGains, Scale, ScaleError, MARGIN_MAX,
};
use proptest::prelude::*;

/// Exact value of a [`Scale`] applied to `x` (rounded half up, saturated), in i128.
fn scale_ref<const S: u32>(k: Scale<S>, x: i32) -> i64 {
    let p = i128::from(x) * i128::from(k.mantissa()) + (1_i128 << (S - 1));
    (p >> S).clamp(i128::from(i32::MIN), i128::from(i32::MAX)) as i64
}

fn check_scale<const S: u32>(mant: f64, neg: bool, x: i32) -> Result<(), TestCaseError> {
    // A constant whose mantissa lies in [2^20, 2^31): representable.
    let k = mant * 2f64.powi(28 - S as i32) * if neg { -1.0 } else { 1.0 };
    let s = Scale::<S>::from_f64(k).unwrap();
    // Rounded to the nearest 2^-S: at least 20 significant bits.
    prop_assert!((s.to_f64() - k).abs() <= 2f64.powi(-(S as i32) - 1));
    prop_assert!((s.to_f64() - k).abs() <= k.abs() * 2f64.powi(-20));
    // The product: exactly the rounded, saturated product of the stored constant, and within
    // ½ LSB plus the constant's own rounding of the f64 product x·k.
    let got = i64::from(s.apply(x));
    prop_assert_eq!(got, scale_ref(s, x));
    let exact = (f64::from(x) * k).clamp(f64::from(i32::MIN), f64::from(i32::MAX));
    let bound = 0.5 + f64::from(x).abs() * 2f64.powi(-(S as i32) - 1) + 1e-6;
    prop_assert!(
        (got as f64 - exact).abs() <= bound,
        "{} * {} = {} vs {}",
        x,
        k,
        got,
        exact
    );
    // Outside the mantissa's range: rejected.
    prop_assert_eq!(Scale::<S>::from_f64(k * 16.0), Err(ScaleError::TooLarge));
    prop_assert_eq!(Scale::<S>::from_f64(k / 1024.0), Err(ScaleError::TooFine));
    Ok(())
}

proptest! {
    #[test]
    fn scale_matches_its_f64_value(mant in 0.5_f64..1.0, neg in any::<bool>(), x in any::<i32>()) {
        // Every format the monitor uses.
        check_scale::<11>(mant, neg, x)?;
        check_scale::<16>(mant, neg, x)?;
        check_scale::<21>(mant, neg, x)?;
        check_scale::<26>(mant, neg, x)?;
        check_scale::<32>(mant, neg, x)?;
        check_scale::<38>(mant, neg, x)?;
    }

    #[test]
    fn triple_pole_gains_are_stable_up_to_the_catchup(bandwidth in 8.0_f64..80.0) {
        let g = ObserverGains::triple_pole(bandwidth, 10_000.0);
        for n in 1..=8 {
            prop_assert!(g.is_stable(f64::from(n) * 1e-4), "{} Hz at {} ticks", bandwidth, n);
        }
        let c = Config { observer: g, ..Config::physical_reading() };
        prop_assert!(Monitor::new(c).is_ok());
    }
}

/// One tick of an arbitrary stream.
#[derive(Clone, Debug)]
struct Tick {
    code: u16,
    motor: u32,
    output: u32,
    drive: bool,
    late: u8,
    command: Option<u16>,
}

fn tick() -> impl Strategy<Value = Tick> {
    (
        prop_oneof![any::<u16>(), 1900_u16..2200, Just(0_u16), Just(4095_u16)],
        prop_oneof![any::<u32>(), 0_u32..70_000],
        prop_oneof![any::<u32>(), 0_u32..16_384, 16_370_u32..16_400],
        any::<bool>(),
        prop_oneof![8 => Just(1_u8), 1 => any::<u8>()],
        prop_oneof![
            Just(None),
            (1500_u16..2600).prop_map(Some),
            any::<u16>().prop_map(Some)
        ],
    )
        .prop_map(|(code, motor, output, drive, late, command)| Tick {
            code,
            motor,
            output,
            drive,
            late,
            command,
        })
}

/// A stream that is physical most of the time (small counter steps) with arbitrary bursts.
fn stream() -> impl Strategy<Value = Vec<Tick>> {
    prop::collection::vec((tick(), -20_i32..20, -150_i32..150, any::<bool>()), 1..600).prop_map(
        |raw| {
            let (mut out, mut motor) = (0_u32, 0_u32);
            raw.into_iter()
                .map(|(t, d_out, d_motor, physical)| {
                    if physical {
                        out = out.wrapping_add(d_out as u32) & 0x3FFF;
                        motor = motor.wrapping_add(d_motor as u32) & 0xFFFF;
                        Tick {
                            output: out,
                            motor,
                            ..t
                        }
                    } else {
                        t
                    }
                })
                .collect()
        },
    )
}

fn bounded(e: &Estimate, prev: Option<&Estimate>, n: u32) -> Result<(), TestCaseError> {
    // Physical reading: the input ramps unload the pack below the spring force while the
    // drive pushes (down to 0), never below.
    let force = e.pressing_force_n.to_num::<f64>();
    prop_assert!((0.0..=32_768.0).contains(&force), "force {}", force);
    prop_assert!(e.capacity_margin >= 0 && e.capacity_margin <= MARGIN_MAX);
    prop_assert!(e.capacity_margin_low >= 0 && e.capacity_margin_low <= e.capacity_margin);
    let health = e.pack_health.to_num::<f64>();
    prop_assert!((0.0..=2.0).contains(&health));
    // |braking torque| never exceeds the capacity at the reported pressing force.
    let cap = TABLE2.pack_capacity_nm(force, TABLE2.mu_static);
    prop_assert!(e.braking_torque_nm.abs().to_num::<f64>() <= cap * (1.0 + 1e-6) + 1e-3);
    if let Some(p) = prev {
        prop_assert!(
            e.friction_energy_j >= p.friction_energy_j,
            "energy decreased"
        );
        prop_assert_eq!(e.tick, p.tick.wrapping_add(n));
        // Latched: a raised flag never clears by itself.
        prop_assert_eq!(e.flags.bits() & p.flags.bits(), p.flags.bits());
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn any_stream_never_panics_and_stays_bounded(ticks in stream()) {
        let mut m = Monitor::new(Config::physical_reading()).unwrap();
        let mut prev: Option<Estimate> = None;
        for t in &ticks {
            let inputs = Inputs {
                current_adc_code: t.code,
                motor_counter: t.motor,
                output_counter: t.output,
                drive_commanded: t.drive,
                current_command_code: t.command,
                ticks_elapsed: t.late,
            };
            let e = m.step(&inputs);
            bounded(&e, prev.as_ref(), u32::from(t.late.max(1)))?;
            if t.late > 1 {
                prop_assert!(e.flags.overrun);
                prop_assert!(m.flags().overrun);
            }
            if t.code > 4095 {
                prop_assert!(e.flags.sensor_fault && !e.trusted);
            }
            // The words are a pure function of the estimate.
            prop_assert_eq!(e.to_words(), e.to_words());
            prev = Some(e);
        }
    }

    #[test]
    fn reset_clears_and_same_stream_gives_same_bits(ticks in stream()) {
        let run = |ticks: &[Tick]| {
            let mut m = Monitor::new(Config::physical_reading()).unwrap();
            let mut words = Vec::new();
            for t in ticks {
                let e = m.step(&Inputs {
                    current_adc_code: t.code,
                    motor_counter: t.motor,
                    output_counter: t.output,
                    drive_commanded: t.drive,
                    current_command_code: t.command,
                    ticks_elapsed: t.late,
                });
                words.push(e.to_words());
            }
            m.reset_flags();
            (words, m.flags())
        };
        let (a, flags) = run(&ticks);
        let (b, _) = run(&ticks);
        prop_assert_eq!(a, b);
        prop_assert!(!flags.any());
    }
}
