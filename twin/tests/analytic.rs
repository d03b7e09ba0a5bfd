//! Analytic checks of the models: statics against closed forms, energy conservation of the
//! lossless model, and dissipation by the pack.

use noback::mechanism::TABLE2;
use noback::sensors::DEFAULT_SENSORS;
use noback_twin::model::physical::Physical;
use noback_twin::model::{Drive, ModelConfig, TwinModel};
use noback_twin::reading::{Reading, DEFAULT_OPEN};
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::sim;
use noback_twin::solver::{Integrator, Sampler, SolverOptions};

fn config(speed: f64, drive_on: bool) -> ModelConfig {
    ModelConfig {
        mechanism: TABLE2,
        sensors: DEFAULT_SENSORS,
        open: DEFAULT_OPEN,
        load_torque_nm: 20.3,
        initial_speed_rad_s: speed,
        output_initial_speed_rad_s: speed,
        drive: Drive {
            on: drive_on,
            speed_ref_rad_s: speed,
            torque_limit_nm: None,
        },
    }
}

#[test]
fn held_load_presses_the_pack_with_torque_times_ramp_factor() {
    // Physical reading, at rest under the load, drive off: once locked, the pressing force is
    // the spring preload plus M·tanθ/r (the ramps carry exactly M).
    let mut s = Scene::builtin(SceneKind::Hold, Reading::Physical);
    s.duration_s = 0.3;
    let run = sim::run(&s).unwrap();
    let last = run.samples.last().unwrap();
    let expected = TABLE2.quasi_static_pressing_force_n(20.3);
    assert_eq!(last.brake_state, 2, "locked");
    assert!(
        (last.pressing_force_n - expected).abs() < 0.01 * expected,
        "{} vs {expected}",
        last.pressing_force_n
    );
    assert!(
        (last.braking_torque_nm - 20.3).abs() < 0.01 * 20.3,
        "{}",
        last.braking_torque_nm
    );
}

#[test]
fn static_capacities_are_the_papers_levels() {
    let m = TABLE2;
    let spring = noback_twin::pack::capacity(&m, m.spring_preload_n(), 1.0, true).static_nm;
    let loaded =
        noback_twin::pack::capacity(&m, m.quasi_static_pressing_force_n(20.3), 1.0, true).static_nm;
    // The paper's trough 8.2 and peak ≈ 60 N·m, within 5 %.
    assert!((spring - 8.2).abs() < 0.05 * 8.2, "{spring}");
    assert!((loaded - 60.0).abs() < 0.05 * 60.0, "{loaded}");
}

#[test]
fn lossless_model_conserves_energy() {
    // No damping, no friction, no drive: the contacts, spring and load are conservative.
    let mut model = Physical::new(config(-5.0, false)).conservative();
    let mut y = model.initial_state();
    let e0 = model.energy_j(&y);
    let mut integ = Integrator::new(SolverOptions {
        tolerance: 1e-7,
        ..SolverOptions::default()
    });
    let mut smp = Sampler::new(0.0, 1e-4);
    let mut worst: f64 = 0.0;
    let mut energies = Vec::new();
    integ
        .integrate(
            &mut model,
            (0.0, 0.05),
            &mut y,
            &mut smp,
            &mut |m: &Physical, _, ys| {
                energies.push(m.energy_j(ys));
            },
        )
        .unwrap();
    let _ = &mut energies;
    for e in &energies {
        worst = worst.max((e - e0).abs());
    }
    let e1 = model.energy_j(&y);
    worst = worst.max((e1 - e0).abs());
    // Kinetic energy is ≈ ½·0.15·25 ≈ 1.9 J; the drift must stay far below the contact work.
    assert!(worst < 2e-3, "energy drift {worst} J of {e0} J");
    // And the contacts did work: the output was stopped and thrown back (it is not free flight).
    assert!(integ.stats.events > 0);
}

#[test]
fn the_pack_only_dissipates_after_release() {
    // Reverse load, physical: after the drive is cut nothing supplies energy, so the total
    // mechanical energy (kinetic + elastic − load potential) can only fall.
    let cfg = config(-13.78, false);
    let mut model = Physical::new(cfg);
    let mut y = model.initial_state();
    let mut integ = Integrator::new(SolverOptions {
        tolerance: 1e-6,
        ..SolverOptions::default()
    });
    let mut smp = Sampler::new(0.0, 1e-4);
    let mut energies = Vec::new();
    integ
        .integrate(
            &mut model,
            (0.0, 0.1),
            &mut y,
            &mut smp,
            &mut |m: &Physical, t, ys| {
                energies.push((t, m.energy_j(ys)));
            },
        )
        .unwrap();
    let mut rise: f64 = 0.0;
    for w in energies.windows(2) {
        rise = rise.max(w[1].1 - w[0].1);
    }
    let (first, last) = (energies[0].1, energies.last().unwrap().1);
    assert!(
        last < first - 1.0,
        "energy must be dissipated: {first} → {last}"
    );
    assert!(rise < 1e-3, "energy rose by {rise} J between samples");
}
