//! Would the opening drive torque just before the functional test take the test's load out?
//! (docs/decisions.md, issue 17.) Per physical draw of `monitor-mc --family plant`: the unit's
//! acceptance (an opening at 1 rad/s against the procedure's 20.3 N·m, then the test), then in
//! service healthy and with spring_broken 0.5…1 at a load within ±5 %; the spring's share from
//! both readings, `ΔC₀ = (ΔT_b − p·ΔT_open)/(q − p·d)` (Table 2 coefficients), against the
//! breakaway alone. The opening torque is the twin's (the monitor's from the current differs by
//! the sensor's gain, common to acceptance and service).
//!
//! `cargo run --release -p host-tests --example functional_test_opening -- [RUNS] [SEED]`

use host_tests::accuracy::{run_functional_test, scene_trace};
use host_tests::dormant::{from_start, test_scene, LOAD_TOLERANCE};
use host_tests::family::Family;
use host_tests::mc::{draw_in, run_rng};
use noback::mechanism::TABLE2;
use noback::monitor::functional_test::TestConfig;
use noback::monitor::Config;
use noback_twin::fault::{Fault, FaultKind};
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind, DEFAULT_TEST};

/// Mean drive torque over the last 0.2 s of a 0.5 s opening at 1 rad/s against `load_nm`.
fn opening_torque(base: &Scene, load_nm: f64, faults: &[Fault]) -> Result<f64, String> {
    let mut s = Scene::builtin(SceneKind::Drive, Reading::Physical);
    s.load_torque_nm = load_nm;
    s.initial_speed_rad_s = 1.0;
    s.mechanism = base.mechanism;
    s.sensors = base.sensors;
    s.open = base.open;
    s.faults = faults.to_vec();
    let r = noback_twin::sim::run(&s).map_err(|e| e.to_string())?;
    let tail: Vec<f64> = r
        .samples
        .iter()
        .filter(|x| x.t_s >= 0.3)
        .map(|x| x.drive_torque_nm.abs())
        .collect();
    Ok(tail.iter().sum::<f64>() / tail.len().max(1) as f64)
}

fn main() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let runs: u64 = args
        .next()
        .map_or(Ok(100), |s| s.parse())
        .map_err(|e| format!("RUNS: {e}"))?;
    let seed: u64 = args
        .next()
        .map_or(Ok(4242), |s| s.parse())
        .map_err(|e| format!("SEED: {e}"))?;
    // Table 2's sensitivities: T_b = p·L + q·C₀, T_open = L + d·C₀.
    let m = TABLE2;
    let per_n = m.pack_torque_per_newton_m(m.mu_static);
    let g = per_n * m.ramp_factor_per_m();
    let a = m.pack_torque_per_newton_m(m.mu_dynamic);
    let a_k = a * m.ramp_factor_per_m();
    let (p, q, d) = (
        (g - 1.0) / (1.0 + g),
        1.0 / (1.0 + g),
        a / per_n / (1.0 + a_k),
    );
    let c_e = |l: f64, t_b: f64| l + (1.0 + g) * t_b;
    println!(
        "p {p:.3} q {q:.3} d {d:.3}: ΔC0 = {:.2}·ΔT_b − {:.2}·ΔT_open",
        1.0 / (q - p * d),
        p / (q - p * d)
    );
    let l0 = TestConfig::DEFAULT.load_nm;
    let (mut healthy, mut spring, mut healthy_b, mut spring_b) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for i in 0..runs {
        let d0 = draw_in(Family::Plant, seed, i, None);
        if d0.scene.reading != Reading::Physical {
            continue;
        }
        let start = DEFAULT_TEST.start_s;
        let cfg = TestConfig::DEFAULT;
        let accepted = run_functional_test(
            &scene_trace(&test_scene(&d0.scene, l0, &[]))?,
            Config::default(),
            &cfg,
            start,
        )?;
        let (tb_c, to_c) = (
            accepted.breakaway_torque_nm.to_num::<f64>(),
            opening_torque(&d0.scene, l0, &[])?,
        );
        let cap_c = c_e(l0, tb_c);
        let mut rng = run_rng(seed ^ 0x0be7, i, None);
        for faulty in [false, true] {
            let load = l0 * (1.0 + LOAD_TOLERANCE * (2.0 * rng.uniform() - 1.0));
            let faults: Vec<Fault> = if faulty {
                vec![from_start(
                    FaultKind::SpringBroken,
                    0.5 + 0.5 * rng.uniform(),
                )]
            } else {
                Vec::new()
            };
            let mut s = test_scene(&d0.scene, load, &faults);
            s.noise.seed = rng.next_u64();
            let r = run_functional_test(&scene_trace(&s)?, Config::default(), &cfg, start)?;
            let (d_b, d_o) = (
                r.breakaway_torque_nm.to_num::<f64>() - tb_c,
                opening_torque(&d0.scene, load, &faults)? - to_c,
            );
            let d_c0 = (d_b - p * d_o) / (q - p * d);
            let both = (cap_c + d_c0) / cap_c;
            let alone = (cap_c + (1.0 + g) * d_b) / cap_c;
            if faulty {
                spring.push(both);
                spring_b.push(alone);
            } else {
                healthy.push(both);
                healthy_b.push(alone);
            }
        }
    }
    let span = |v: &[f64]| {
        (
            v.iter().copied().fold(f64::INFINITY, f64::min),
            v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        )
    };
    let below = |v: &[f64], x: f64| v.iter().filter(|m| **m < x).count();
    println!("seed {seed}, {} physical units", healthy.len());
    for (name, h, f) in [
        ("breakaway alone", &healthy_b, &spring_b),
        ("with the opening", &healthy, &spring),
    ] {
        let (hl, hh) = span(h);
        let (fl, fh) = span(f);
        println!("{name:>16}: healthy margin {hl:.3} … {hh:.3} (below 0.95: {}), spring 0.5…1 {fl:.3} … {fh:.3} (below 0.95: {}/{})", below(h, 0.95), below(f, 0.95), f.len());
    }
    Ok(())
}
