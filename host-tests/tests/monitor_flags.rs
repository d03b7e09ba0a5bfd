//! Flag logic, encoder wrap, missed ticks and constructor errors of the monitor, on hand-built
//! input streams.

use noback::monitor::{
    BrakeState, Config, ConfigError, Estimate, Flags, Inputs, Monitor, ObserverGains, Scene,
    ESTIMATE_WORDS,
};

const MID: u16 = 2048;

fn at_rest(monitor: &mut Monitor, out: u32, motor: u32, ticks: u32) -> Estimate {
    let mut e = monitor.step(&Inputs::new(MID, motor, out, false));
    for _ in 1..ticks {
        e = monitor.step(&Inputs::new(MID, motor, out, false));
    }
    e
}

#[test]
fn power_on_at_rest_locks_without_flags() {
    let mut m = Monitor::new(Config::physical_reading()).unwrap();
    let e = at_rest(&mut m, 1234, 555, 500);
    assert_eq!(e.brake, BrakeState::Locked);
    assert_eq!(e.scene, Scene::Holding);
    assert!(!e.flags.any());
    // The load has never been observed: the estimate says so.
    assert!(!e.trusted);
    assert_eq!(e.tick, 500);
}

#[test]
fn out_of_range_adc_code_latches_sensor_fault_until_reset() {
    let mut m = Monitor::new(Config::physical_reading()).unwrap();
    at_rest(&mut m, 0, 0, 100);
    let e = m.step(&Inputs::new(4096, 0, 0, false)); // a 12-bit ADC cannot produce it
    assert!(e.flags.sensor_fault);
    assert!(!e.trusted);
    // Latched: good readings do not clear it.
    let e = at_rest(&mut m, 0, 0, 2000);
    assert!(e.flags.sensor_fault);
    assert_eq!(e.flags.bits(), 0b0_1000);
    m.reset_flags();
    let e = at_rest(&mut m, 0, 0, 10);
    assert!(!e.flags.any());
    // And it comes back if the condition does.
    let e = m.step(&Inputs::new(u16::MAX, 0, 0, false));
    assert!(e.flags.sensor_fault);
}

#[test]
fn adc_stuck_at_a_rail_is_a_sensor_fault_but_a_single_rail_sample_is_not() {
    let mut m = Monitor::new(Config::physical_reading()).unwrap();
    at_rest(&mut m, 0, 0, 100);
    // The rail must last `adc_rail_time_s` (10 ms: the motor stalls at the current limit for
    // ≈ 3 ms in overrunning chatter, reading the rail with the encoder still).
    let rail_ticks =
        (Config::physical_reading().thresholds.adc_rail_time_s * 10_000.0).round() as usize;
    for k in 1..rail_ticks {
        let e = m.step(&Inputs::new(0, 0, 0, true));
        assert!(!e.flags.sensor_fault, "after {k} ticks at the rail");
    }
    let e = m.step(&Inputs::new(0, 0, 0, true));
    assert!(e.flags.sensor_fault);
}

#[test]
fn current_with_the_drive_off_is_implausible() {
    let mut m = Monitor::new(Config::physical_reading()).unwrap();
    at_rest(&mut m, 0, 0, 100);
    // 5 A with the drive off (3 A allowed): 5/(60/4096) ≈ 341 counts.
    let e = m.step(&Inputs::new(MID + 341, 0, 0, false));
    assert!(e.flags.sensor_fault);
    let mut m = Monitor::new(Config::physical_reading()).unwrap();
    at_rest(&mut m, 0, 0, 100);
    let e = m.step(&Inputs::new(MID + 164, 0, 0, false)); // 2.4 A: within the allowance
    assert!(!e.flags.sensor_fault);
}

#[test]
fn output_encoder_wrap_is_motion_not_a_jump() {
    // Creep across the 14-bit wrap at 0.77 rad/s (2 counts every 10 ticks) with the drive on.
    let mut m = Monitor::new(Config::physical_reading()).unwrap();
    let mut out: u32 = 16_300;
    let mut motor: u32 = 65_000;
    let mut e = m.step(&Inputs::new(MID, motor, out, true));
    for k in 0..3000_u32 {
        if k % 10 == 0 {
            out = (out + 2) & 0x3FFF;
        }
        // 2 output counts ≈ 15 motor counts: 1.5 counts per tick, starting near the 16-bit wrap.
        motor = (motor + 1 + k % 2) & 0xFFFF;
        e = m.step(&Inputs::new(MID, motor, out, true));
    }
    assert!(motor < 65_000, "the motor counter wrapped");
    assert!(out < 16_300, "the trace wrapped");
    assert!(!e.flags.sensor_fault, "{:?}", e.flags);
    let speed = e.output_speed_rad_s.to_num::<f64>();
    let want = 2.0 * core::f64::consts::TAU / 16_384.0 / 10.0 * 10_000.0;
    assert!((speed - want).abs() < 0.05 * want, "{speed} vs {want}");
    let input = e.input_speed_rad_s.to_num::<f64>();
    let want_in = 15.0 * core::f64::consts::TAU / (4096.0 * 30.0) / 10.0 * 10_000.0;
    assert!(
        (input - want_in).abs() < 0.1 * want_in,
        "{input} vs {want_in}"
    );
}

#[test]
fn output_encoder_jump_is_a_sensor_fault_and_a_glitch_leaves_no_brake_flag() {
    let mut m = Monitor::new(Config::physical_reading()).unwrap();
    at_rest(&mut m, 8000, 0, 2000);
    // One corrupted sample 3000 counts away, then back.
    let e = m.step(&Inputs::new(MID, 0, 11_000, false));
    assert!(e.flags.sensor_fault);
    let e = at_rest(&mut m, 8000, 0, 3000);
    assert_eq!(
        e.flags,
        Flags {
            sensor_fault: true,
            ..Flags::default()
        }
    );
    assert_eq!(e.brake, BrakeState::Locked);
    assert!(e.output_speed_rad_s.abs().to_num::<f64>() < 0.01);
}

#[test]
fn counter_bits_above_the_register_width_are_implausible() {
    let mut m = Monitor::new(Config::physical_reading()).unwrap();
    at_rest(&mut m, 0, 0, 10);
    assert!(
        m.step(&Inputs::new(MID, 0, 1 << 14, false))
            .flags
            .sensor_fault
    );
    let mut m = Monitor::new(Config::physical_reading()).unwrap();
    at_rest(&mut m, 0, 0, 10);
    assert!(
        m.step(&Inputs::new(MID, 1 << 16, 0, false))
            .flags
            .sensor_fault
    );
}

#[test]
fn stuck_output_encoder_while_driving_is_detected() {
    // Drive on, motor turning at 100 rad/s motor side, output counter frozen.
    let mut m = Monitor::new(Config::physical_reading()).unwrap();
    let mut motor: u32 = 0;
    let mut e = m.step(&Inputs::new(MID + 100, motor, 5, true));
    for _ in 0..20_000 {
        motor = (motor + 7) & 0xFFFF; // 7 counts/tick = 107 rad/s at the motor
        e = m.step(&Inputs::new(MID + 100, motor, 5, true));
        if e.flags.sensor_fault {
            break;
        }
    }
    assert!(e.flags.sensor_fault);
    // Lost-motion limit 0.2 rad at the input shaft ≈ 3 910 motor counts ≈ 560 ticks.
    assert!(e.tick > 500 && e.tick < 650, "{}", e.tick);
}

#[test]
fn missed_tick_latches_overrun() {
    let mut m = Monitor::new(Config::physical_reading()).unwrap();
    at_rest(&mut m, 0, 0, 200);
    let late = Inputs {
        ticks_elapsed: 3,
        ..Inputs::new(MID, 0, 0, false)
    };
    let e = m.step(&late);
    assert!(e.flags.overrun);
    assert!(!e.flags.sensor_fault);
    assert_eq!(e.tick, 203);
    let e = at_rest(&mut m, 0, 0, 100);
    assert!(e.flags.overrun);
    m.reset_flags();
    assert!(!m.flags().any());
    // ticks_elapsed = 0 counts as an on-time tick.
    let e = m.step(&Inputs {
        ticks_elapsed: 0,
        ..Inputs::new(MID, 0, 0, false)
    });
    assert!(!e.flags.overrun);
    assert_eq!(e.tick, 304);
}

#[test]
fn very_late_step_reseats_the_observer_and_is_untrusted() {
    let mut m = Monitor::new(Config::physical_reading()).unwrap();
    at_rest(&mut m, 100, 0, 200);
    let e = m.step(&Inputs {
        ticks_elapsed: 200,
        ..Inputs::new(MID, 0, 150, false)
    });
    assert!(e.flags.overrun);
    assert!(!e.flags.sensor_fault, "50 counts in 200 ticks is plausible");
    assert!(!e.trusted);
}

#[test]
fn missed_ticks_while_moving_keep_tracking() {
    // 4 output counts per tick (15.3 rad/s), every fourth call covers two ticks. The drive
    // carries ≈ 3.6 N·m (150 ADC counts): a moving no-back's drive always carries some, and a
    // reading of zero while the output turns is a dead current sensor (`sensor_fault`).
    let code = MID + 150;
    let mut m = Monitor::new(Config::physical_reading()).unwrap();
    let (mut out, mut motor) = (0_u32, 0_u32);
    let mut e = m.step(&Inputs::new(code, motor, out, true));
    for k in 0..4000_u32 {
        let n = if k % 4 == 3 { 2 } else { 1 };
        out = (out + 4 * n) & 0x3FFF;
        motor = (motor + 30 * n) & 0xFFFF;
        e = m.step(&Inputs {
            ticks_elapsed: n as u8,
            ..Inputs::new(code, motor, out, true)
        });
    }
    assert!(e.flags.overrun && !e.flags.sensor_fault, "{:?}", e.flags);
    let want = 4.0 * core::f64::consts::TAU / 16_384.0 * 10_000.0;
    let got = e.output_speed_rad_s.to_num::<f64>();
    assert!((got - want).abs() < 0.02 * want, "{got} vs {want}");
}

#[test]
fn estimate_words_round_trip_the_fields() {
    let mut m = Monitor::new(Config::physical_reading()).unwrap();
    let e = at_rest(&mut m, 77, 0, 300);
    let w = e.to_words();
    assert_eq!(w.len(), ESTIMATE_WORDS);
    assert_eq!(w[0], 300);
    assert_eq!(w[1] as i32, e.pressing_force_n.to_bits());
    assert_eq!(w[8] as i32, e.capacity_margin.to_bits());
    assert_eq!(w[9] as i32, e.capacity_margin_low.to_bits());
    assert_eq!(w[13] & 0xFF, BrakeState::Locked as u32);
    assert_eq!((w[13] >> 8) & 0xFF, Scene::Holding as u32);
    assert_eq!(w[13] >> 24, u32::from(e.flags.bits()));
    // The checksum covers the body: a changed field changes it.
    let mut other = e;
    other.tick += 1;
    assert_ne!(other.to_words()[14], w[14]);
}

fn err(config: Config) -> ConfigError {
    Monitor::new(config).unwrap_err()
}

#[test]
fn constructor_rejects_non_finite_parameters() {
    let mut c = Config::physical_reading();
    c.mechanism.socket_radius_m = f64::NAN;
    assert_eq!(
        err(c),
        ConfigError::NotFinite {
            parameter: "mechanism.socket_radius_m"
        }
    );
    let mut c = Config::physical_reading();
    c.thresholds.creep_limit_rad = f64::INFINITY;
    assert_eq!(
        err(c),
        ConfigError::NotFinite {
            parameter: "thresholds.creep_limit_rad"
        }
    );
}

#[test]
fn constructor_rejects_out_of_range_parameters() {
    let mut c = Config::physical_reading();
    c.mechanism.output_inertia_kg_m2 = -0.15;
    assert_eq!(
        err(c),
        ConfigError::OutOfRange {
            parameter: "mechanism.output_inertia_kg_m2"
        }
    );
    // a·k = μ_d·c·tanθ/r at 1: the model's overrunning line divides by a·k − 1, a measured
    // line does not.
    let mut c = Config::physical_reading();
    c.sliding_mu =
        1.0 / (c.mechanism.pack_torque_per_newton_m(1.0) * c.mechanism.ramp_factor_per_m());
    assert_eq!(
        err(c),
        ConfigError::OutOfRange {
            parameter: "sliding_mu"
        }
    );
    c.overrun_line = Some(noback::monitor::OverrunLine {
        gain: 6.9,
        offset_nm: 11.6,
    });
    assert!(Monitor::new(c).is_ok());
    let mut c = Config::physical_reading();
    c.sensors.reducer_efficiency = 1.2;
    assert_eq!(
        err(c),
        ConfigError::OutOfRange {
            parameter: "sensors.reducer_efficiency"
        }
    );
    // A seeded power-on settles sooner than the observer's full settling, never later.
    let mut c = Config::physical_reading();
    c.thresholds.power_on_settle_s = c.thresholds.settle_time_s + 0.01;
    assert_eq!(
        err(c),
        ConfigError::OutOfRange {
            parameter: "thresholds.power_on_settle_s"
        }
    );
    // A dead current reading is one well below the spring drag a moving no-back's drive
    // carries (1.98 N·m with Table 2): a threshold at or above it would call healthy drives
    // dead.
    let mut c = Config::physical_reading();
    c.thresholds.dead_current_nm = 2.0;
    assert_eq!(
        err(c),
        ConfigError::OutOfRange {
            parameter: "thresholds.dead_current_nm"
        }
    );
    let mut c = Config::physical_reading();
    c.thresholds.dead_current_speed_rad_s = 0.0;
    assert_eq!(
        err(c),
        ConfigError::OutOfRange {
            parameter: "thresholds.dead_current_speed_rad_s"
        }
    );
    let mut c = Config::physical_reading();
    c.thresholds.impact_time_s = 0.0;
    assert_eq!(
        err(c),
        ConfigError::OutOfRange {
            parameter: "thresholds.impact_time_s"
        }
    );
    // μ_d·c·k = 1 would make the overrunning equilibrium singular (0.17 gives 1.42).
    let c = Config {
        sliding_mu: 0.17 / 1.417,
        ..Config::physical_reading()
    };
    assert_eq!(
        err(c),
        ConfigError::OutOfRange {
            parameter: "sliding_mu"
        }
    );
    // A measured driving drag: positive, and no more than μ = 2 gives on the spring alone.
    for drag in [0.0, -1.0, f64::NAN, 200.0] {
        let c = Config {
            driving_drag_nm: Some(drag),
            ..Config::physical_reading()
        };
        let parameter = "driving_drag_nm";
        let expected = if drag.is_nan() {
            ConfigError::NotFinite { parameter }
        } else {
            ConfigError::OutOfRange { parameter }
        };
        assert_eq!(err(c), expected, "{drag}");
    }
    let mut c = Config::physical_reading();
    c.sensors.output_encoder_bits = 30;
    assert_eq!(
        err(c),
        ConfigError::OutOfRange {
            parameter: "sensors.output_encoder_bits"
        }
    );
    // The common-slip check measures travel on the wrapping counters: a limit of a quarter
    // turn of the 14-bit output encoder (1.57 rad) or beyond cannot be resolved.
    let mut c = Config::physical_reading();
    c.thresholds.slip_output_travel_rad = 1.6;
    assert_eq!(
        err(c),
        ConfigError::OutOfRange {
            parameter: "thresholds.slip_output_travel_rad"
        }
    );
    let mut c = Config::physical_reading();
    c.thresholds.slip_input_travel_rad = -0.045;
    assert_eq!(
        err(c),
        ConfigError::OutOfRange {
            parameter: "thresholds.slip_input_travel_rad"
        }
    );
    let mut c = Config::physical_reading();
    c.thresholds.undecelerated_allowance_rad = 0.0;
    assert_eq!(
        err(c),
        ConfigError::OutOfRange {
            parameter: "thresholds.undecelerated_allowance_rad"
        }
    );
    // Just inside the quarter turn: accepted.
    let mut c = Config::physical_reading();
    c.thresholds.slip_output_travel_rad = 1.5;
    assert!(noback::monitor::Monitor::new(c).is_ok());
}

#[test]
fn constructor_rejects_formats_that_would_overflow() {
    // A 0.2 mm socket radius makes the ramp force of 60 N·m 300 kN: beyond Q16.
    let mut c = Config::physical_reading();
    c.mechanism.socket_radius_m = 0.0002;
    assert_eq!(
        err(c),
        ConfigError::Overflow {
            parameter: "mechanism.socket_radius_m"
        }
    );
    // A 100 kA current sensor: drive torque beyond Q16.
    let mut c = Config::physical_reading();
    c.sensors.current_full_scale_a = 100_000.0;
    assert_eq!(
        err(c),
        ConfigError::Overflow {
            parameter: "sensors.current_full_scale_a"
        }
    );
    // A 10-bit motor counter aliases at 1800 rad/s over 8 late ticks.
    let mut c = Config::physical_reading();
    c.sensors.motor_counter_bits = 10;
    assert_eq!(
        err(c),
        ConfigError::Overflow {
            parameter: "sensors.motor_counter_bits"
        }
    );
}

#[test]
fn constructor_rejects_an_unstable_observer() {
    let c = Config {
        observer: ObserverGains {
            angle: 2.5,
            speed_per_s: 10.0,
            accel_per_s2: 10.0,
        },
        ..Config::physical_reading()
    };
    assert_eq!(
        err(c),
        ConfigError::Unstable {
            parameter: "observer"
        }
    );
    // Stable at one tick, unstable when a late step advances it by six or more (Jury test on
    // (I − LC)·A^n): rejected with the default catch-up of 8, accepted with 5.
    let gains = ObserverGains {
        angle: 0.05,
        speed_per_s: 100.0,
        accel_per_s2: 10_000.0,
    };
    assert!(gains.is_stable(1e-4) && gains.is_stable(5e-4) && !gains.is_stable(6e-4));
    let mut c = Config {
        observer: gains,
        ..Config::physical_reading()
    };
    assert_eq!(
        err(c),
        ConfigError::Unstable {
            parameter: "max_catchup_ticks"
        }
    );
    c.max_catchup_ticks = 5;
    assert!(Monitor::new(c).is_ok());
    // A slower tick with the same gains: outside the stability region.
    let c = Config {
        tick_hz: 1_000.0,
        ..Config::physical_reading()
    };
    assert_eq!(
        err(c),
        ConfigError::Unstable {
            parameter: "observer"
        }
    );
}

#[test]
fn constructor_rejects_gains_beyond_their_format() {
    // A 300 Hz triple pole: l₂ (∝ bandwidth²) no longer fits its Scale<36> mantissa (nor l₃,
    // ∝ bandwidth³, its Scale<33>; the first one checked is named).
    let c = Config {
        observer: ObserverGains::triple_pole(300.0, 10_000.0),
        ..Config::physical_reading()
    };
    assert_eq!(
        err(c),
        ConfigError::Overflow {
            parameter: "observer.speed_per_s"
        }
    );
    // A 3 Hz one: l₂ would keep fewer than 20 significant bits in its Scale<36>.
    let c = Config {
        observer: ObserverGains::triple_pole(3.0, 10_000.0),
        ..Config::physical_reading()
    };
    assert_eq!(
        err(c),
        ConfigError::OutOfRange {
            parameter: "observer.speed_per_s"
        }
    );
}

#[test]
fn errors_name_their_parameter_in_the_message() {
    let e = ConfigError::Overflow {
        parameter: "capacity_mu",
    };
    assert_eq!(e.parameter(), "capacity_mu");
    assert_eq!(
        e.to_string(),
        "monitor configuration: capacity_mu overflows the fixed-point format"
    );
}

/// Powered on into a running drive, the observer starts from the output's measured speed once
/// `POWER_ON_SEED_TICKS` ticks have passed, not from rest — unless a tick is late meanwhile:
/// then it settles from rest, the usual way (docs/monitor-design.md, "Power-on into a running
/// drive").
#[test]
fn power_on_into_a_running_drive_seeds_the_observer_speed_unless_a_tick_is_late() {
    let sensors = Config::physical_reading().sensors;
    let out_per_tick = 3_u32; // 3 counts a tick: 11.5 rad/s
    let speed = f64::from(out_per_tick) * sensors.output_rad_per_count() * 10_000.0;
    let motor_per_out = sensors.output_rad_per_count() / sensors.input_rad_per_motor_count();
    let speed_after = |late_at: Option<u32>| {
        let mut m = Monitor::new(Config::physical_reading()).unwrap();
        let mut e = None;
        let mut ticks = 0_u32;
        // The estimate is the slow lane's snapshot: one slow period more before it shows.
        let slow = noback::monitor::schedule::SLOW.ticks;
        for k in 0..noback::monitor::POWER_ON_SEED_TICKS + 4 + slow {
            let n = if late_at == Some(k) { 2 } else { 1 };
            ticks += n;
            let out = (1000 + out_per_tick * ticks) & 0x3FFF;
            let motor = (f64::from(out_per_tick * ticks) * motor_per_out) as u32 & 0xFFFF;
            let mut inputs = Inputs::new(MID + 200, motor, out, true);
            inputs.ticks_elapsed = n as u8;
            e = Some(m.step(&inputs));
        }
        e.map_or(f64::NAN, |e| e.output_speed_rad_s.to_num::<f64>())
    };
    let seeded = speed_after(None);
    assert!(
        (seeded - speed).abs() < 0.02 * speed,
        "seeded {seeded} rad/s, moving at {speed}"
    );
    let from_rest = speed_after(Some(5));
    assert!(
        from_rest < 0.5 * speed,
        "a late tick should leave the observer to settle from rest: {from_rest} rad/s"
    );
}
