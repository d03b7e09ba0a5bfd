//! Property tests over the operating envelope: the fixed-point step against f64 shadows.

use super::*;
use proptest::prelude::*;

/// Ticks the plant's output must have stood still before a holding estimate reports exactly
/// the load: the impact estimate looks back 2 × 16 ticks from the slow lane's last
/// classification, which reaches the report up to `SLOW.ticks` ticks later.
const QUIET_TICKS: u32 = 33 + noback::monitor::schedule::SLOW.ticks;

/// For each estimate of a trace, whether the plant's output has been at rest for
/// [`QUIET_TICKS`] ticks.
fn quiet(trace: &[(f64, f64, Estimate)]) -> Vec<bool> {
    let mut still = 0_u32;
    trace
        .iter()
        .map(|(_, w, _)| {
            still = if *w == 0.0 { still + 1 } else { 0 };
            still >= QUIET_TICKS
        })
        .collect()
}

/// Shadow of the estimate's derived fields, recomputed in f64 from its own estimates (load,
/// drive torque, braking torque) with the physical reading's laws. `quiet`: the output has
/// been at rest long enough for the holding torque to be the load alone (otherwise it also
/// carries the output's inertia torque, checked in the library's unit test).
fn check_shadow(e: &Estimate, quiet: bool) -> Result<(), TestCaseError> {
    let m = TABLE2;
    let load = e.load_torque_nm.to_num::<f64>();
    let spring = m.spring_preload_n();
    let k = m.ramp_factor_per_m();
    let a = m.pack_torque_per_newton_m(m.mu_dynamic);
    let ak = a * k;
    let got = e.pressing_force_n.to_num::<f64>();
    let torque = e.braking_torque_nm.to_num::<f64>();
    let (force, want_torque) = match e.scene {
        // Drive carrying the load: the input ramps unload the pack.
        Scene::Driving => (spring / (1.0 + ak), None),
        // Overrunning: equilibrium torque from the drive torque along the motion.
        Scene::Overrunning => {
            let s = e.output_speed_rad_s.to_num::<f64>().signum();
            let v = s * e.drive_torque_nm.to_num::<f64>();
            let y = ((2.0 * ak * v - a * spring) / (ak - 1.0)).max(0.0);
            ((spring + k * (y - 2.0 * v)).max(0.0), Some(s * y))
        }
        // Drive off: both faces clamp, F = F_s + k·|T|.
        Scene::FaultBraking | Scene::Holding => (spring + k * torque.abs(), None),
    };
    prop_assert!(
        (got - force).abs() <= 1e-3 * force + 0.05,
        "{:?}: force {} vs {}",
        e.scene,
        got,
        force
    );
    if let Some(want) = want_torque {
        prop_assert!(
            (torque - want).abs() <= 1e-3 * want.abs() + 0.01,
            "overrunning torque {} vs {}",
            torque,
            want
        );
    }
    // The margin: capacity at the largest expected load over that load, times the health;
    // its lower bound takes the model's spread off and credits no health above 1.
    let c = Config::physical_reading();
    let max = c.thresholds.max_load_nm;
    let service = m.pack_capacity_nm(m.quasi_static_pressing_force_n(max), c.capacity_mu) / max;
    let h = e.pack_health.to_num::<f64>();
    let low = h.min(1.0) * service * (1.0 - c.thresholds.capacity_uncertainty);
    // None once the pack was seen holding less than a load it met.
    let weak = if e.flags.pack_weak() { 0.0 } else { 1.0 };
    for (got, want) in [
        (e.capacity_margin, weak * h * service),
        (e.capacity_margin_low, weak * low),
    ] {
        let got = got.to_num::<f64>();
        prop_assert!(
            (got - want).abs() <= 1e-4 * want + 1e-4,
            "margin {} vs {}",
            got,
            want
        );
    }
    if e.brake == BrakeState::Locked && quiet {
        prop_assert!(
            (torque - load).abs() <= 1e-4,
            "holding {} vs {}",
            torque,
            load
        );
    }
    Ok(())
}

/// For a load against the motion whose steady drive torque `v` also fits an overrunning
/// load `M' = y(v) − v` inside the envelope, `Some(M')` (signed along the motion). The
/// envelope's edges are widened by what the monitor cannot resolve there: `M'` moves by
/// `dM'/dv ≈ 5.9` per N·m of drive torque, and the drive torque is read to the current's
/// resolution through the plant's ADC noise (`adc_noise + 1` counts, 0.02 N·m a count:
/// ±0.35 N·m of `M'`). A load that close to an edge may be read either way (seen at
/// `M'` = 60.2 N·m, 10.27 N·m against at 2 rad/s: the monitor's `M'` converges to 59.9).
fn ambiguous_reading(plant: &Plant, load: f64, speed: f64) -> Option<f64> {
    let m = TABLE2;
    if load * speed >= 0.0 {
        return None;
    }
    let a = m.pack_torque_per_newton_m(m.mu_dynamic);
    let ak = a * m.ramp_factor_per_m();
    let v = load.abs() + plant.drive_drag(-load.abs());
    let along = (2.0 * ak * v - a * m.spring_preload_n()) / (ak - 1.0) - v;
    let per_count = plant
        .sensors
        .input_torque_nm(plant.sensors.amps_per_count());
    let slope = 2.0 * ak / (ak - 1.0) - 1.0;
    let edge = slope * f64::from(plant.adc_noise + 1) * per_count;
    let t = Config::physical_reading().thresholds;
    (along > t.min_load_nm - edge && along <= t.max_load_nm + edge)
        .then_some(speed.signum() * along)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// The Monte Carlo range of issue 4 (load 5–30 N·m either way, 5–20 rad/s either way,
    /// here widened to 2 N·m and 2 rad/s): released at 0.3 s, the output locks and the
    /// monitor holds the load within 5 %, with no flag. Loads whose power-on drive torque
    /// is ambiguous are the next test's.
    #[test]
    fn release_to_lock_across_the_drive_envelope(
        load in 2.0_f64..30.0, load_neg in any::<bool>(),
        speed in 2.0_f64..20.0, speed_neg in any::<bool>(),
        offset in 0.0_f64..16_384.0,
    ) {
        let load = if load_neg { -load } else { load };
        let speed = if speed_neg { -speed } else { speed };
        let mut plant = Plant::new(load, speed);
        prop_assume!(ambiguous_reading(&plant, load, speed).is_none());
        plant.out_offset = offset;
        let mut monitor = Monitor::new(Config::physical_reading()).unwrap();
        let trace = run(&mut plant, &mut monitor, speed, 0.3, 1.0);
        for ((t, w, e), q) in trace.iter().zip(quiet(&trace)) {
            check_shadow(e, q)?;
            if *t > 0.15 {
                let got = e.output_speed_rad_s.to_num::<f64>();
                prop_assert!((got - w).abs() <= 0.5 + 0.05 * w.abs(), "t {} speed {} vs {}", t, got, w);
            }
        }
        let last = trace.last().unwrap().2;
        prop_assert_eq!(last.brake, BrakeState::Locked);
        prop_assert!(!last.flags.any(), "{:?}", last.flags);
        // Along the load the power-on reading is a guess (`check_paper_case`): untrusted.
        prop_assert_eq!(last.trusted, load * speed < 0.0);
        let hold = last.braking_torque_nm.to_num::<f64>();
        prop_assert!((hold - load).abs() <= 0.05 * load.abs(), "hold {} vs {}", hold, load);
    }

    /// Powered on while driving, the monitor sees one steady drive torque `v`. In the
    /// physical reading a load `M` against the motion gives `v = |M| + T_drive`, and a load
    /// `M'` along it gives the same `v` when `M' = y(v) − v` (overrunning equilibrium); with
    /// no load known the monitor takes the overrunning reading whenever `M'` lies in the
    /// envelope (docs/monitor-design.md, "ambiguity at power-on"). For such against-loads
    /// (|M| up to about 10 N·m) the monitor must still stay consistent — the derived fields
    /// match their shadows, the output locks, no flag — and hold one of the two readings,
    /// normally `M'`, within 5 %. (The speed check of the previous test does not apply: the model brakes
    /// the wrong load for the first milliseconds after the cut.)
    #[test]
    fn power_on_while_driving_in_the_ambiguous_band(
        load in 2.0_f64..12.0,
        speed in 2.0_f64..20.0, speed_neg in any::<bool>(),
        offset in 0.0_f64..16_384.0,
    ) {
        let speed = if speed_neg { -speed } else { speed };
        let load = -speed.signum() * load;
        let mut plant = Plant::new(load, speed);
        let along = ambiguous_reading(&plant, load, speed);
        prop_assume!(along.is_some());
        let want = along.unwrap_or(load);
        plant.out_offset = offset;
        let mut monitor = Monitor::new(Config::physical_reading()).unwrap();
        let trace = run(&mut plant, &mut monitor, speed, 0.3, 1.0);
        for ((_, _, e), q) in trace.iter().zip(quiet(&trace)) {
            check_shadow(e, q)?;
        }
        let last = trace.last().unwrap().2;
        prop_assert_eq!(last.brake, BrakeState::Locked);
        prop_assert!(!last.flags.any(), "{:?}", last.flags);
        let hold = last.braking_torque_nm.to_num::<f64>();
        // At the band's edge (M' near the envelope limit) noise may show the drive-carries
        // reading first, which is then kept: either consistent reading is right.
        prop_assert!(
            (hold - want).abs() <= 0.05 * want.abs() || (hold - load).abs() <= 0.05 * load.abs(),
            "hold {} vs {} or {}", hold, want, load
        );
    }

    /// Power-on with the drive off anywhere in the envelope (load ±60 N·m, ±50 rad/s): no
    /// overflow — the speed tracks the plant, the derived fields match their f64 shadows —
    /// no sensor fault, and a lock once the plant has stopped.
    #[test]
    fn power_on_braking_across_the_full_envelope(
        load in -60.0_f64..60.0,
        speed in -50.0_f64..50.0,
        offset in 0.0_f64..16_384.0,
    ) {
        let mut plant = Plant::new(load, speed);
        plant.out_offset = offset;
        let mut monitor = Monitor::new(Config::physical_reading()).unwrap();
        let trace = run(&mut plant, &mut monitor, 0.0, 0.0, 1.5);
        // The observer needs its settling time after power-on and after the plant stops
        // abruptly (up to 440 rad/s² to rest in one tick, unknown load): 0.1 s and 50 ms are
        // left out of the speed comparison.
        let mut stopped_at = f64::NEG_INFINITY;
        let mut prev_w = speed;
        for ((t, w, e), q) in trace.iter().zip(quiet(&trace)) {
            check_shadow(e, q)?;
            if *w == 0.0 && prev_w != 0.0 {
                stopped_at = *t;
            }
            prev_w = *w;
            if *t > 0.1 && *t - stopped_at > 0.05 {
                let got = e.output_speed_rad_s.to_num::<f64>();
                prop_assert!((got - w).abs() <= 1.0 + 0.05 * w.abs(), "t {} speed {} vs {}", t, got, w);
            }
            prop_assert!(!e.flags.sensor_fault && !e.flags.overrun, "t {} {:?}", t, e.flags);
        }
        let last = trace.last().unwrap();
        if last.1 == 0.0 && trace.iter().rev().nth(500).is_some_and(|x| x.1 == 0.0) {
            prop_assert_eq!(last.2.brake, BrakeState::Locked);
        }
    }
}
