//! The reduced model in the shipped-like fixed format (`I16F16` speeds and torques, `I32F32`
//! angle; semi-implicit Euler at 10 kHz) is stable over the parameter envelope — every Table 2
//! value the model uses ±10 %, loads 5–30 N·m, both braking cases — and with ±20 % tick jitter:
//! it locks, holds exactly the load, never saturates, and its braking angle stays within
//! 5 mrad of an f64 RK4 run of the same model at 50 kHz (issue 6).

use fixed::types::{I16F16, I32F32};
use noback::mechanism::{Mechanism, TABLE2};
use noback_study::reduced::num::{Real, Widen};
use noback_study::reduced::{BrakingScene, Method, Params, Reduced};

/// Runs 1 s of a braking scene; `jitter` scales each step by `1 ± 0.2`. Returns the final
/// angle, whether the pack holds, the braking torque and the largest pressing force seen.
fn run<N: Real + Widen<A>, A: Real>(
    m: &Mechanism,
    load: f64,
    scene: BrakingScene,
    method: Method,
    rate: u32,
    jitter: bool,
) -> (f64, bool, f64, f64) {
    let p = Params::from_mechanism(m, load, f64::from(rate));
    let dt = p.dt_s;
    let mut model = Reduced::<N, A>::new(p, method);
    model.set_drive(true, scene.speed_ref_rad_s);
    let mut t = 0.0;
    let mut released = false;
    let mut seed = 0x2545_f491_u32;
    let mut max_force: f64 = 0.0;
    while t < 1.0 {
        if !released && t >= scene.release_s - 1e-12 {
            model.set_drive(false, 0.0);
            released = true;
        }
        let h = if jitter {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            let u = f64::from(seed >> 8) / f64::from(1_u32 << 24) * 2.0 - 1.0;
            dt * (1.0 + 0.2 * u)
        } else {
            dt
        };
        if jitter {
            model.set_dt(h);
        }
        model.step();
        t += h;
        max_force = max_force.max(model.output().pressing_n.to_f64());
    }
    let o = model.output();
    (
        model.state.theta.to_f64(),
        o.stuck,
        o.braking_nm.to_f64(),
        max_force,
    )
}

fn envelope() -> Vec<Mechanism> {
    let mut v = vec![TABLE2];
    for s in [0.9, 1.1] {
        let scaled = |f: fn(&mut Mechanism, f64)| {
            let mut m = TABLE2;
            f(&mut m, s);
            m
        };
        v.push(scaled(|m, s| m.output_inertia_kg_m2 *= s));
        v.push(scaled(|m, s| m.mu_static *= s));
        v.push(scaled(|m, s| m.socket_radius_m *= s));
        v.push(scaled(|m, s| m.socket_chamfer_rad *= s));
        v.push(scaled(|m, s| m.spring_stiffness_n_m *= s));
        v.push(scaled(|m, s| m.spring_preload_m *= s));
        v.push(scaled(|m, s| m.socket_clearance_m *= s));
        v.push(scaled(|m, s| {
            m.output_inertia_kg_m2 *= s;
            m.mu_static *= 2.0 - s;
            m.spring_stiffness_n_m *= 2.0 - s;
            m.socket_radius_m *= s;
        }));
    }
    v
}

fn check(jitter: bool) {
    let mut cases = 0;
    for m in envelope() {
        for load in [5.0, 12.0, 20.3, 30.0] {
            for scene in [BrakingScene::REVERSE, BrakingScene::FORWARD] {
                let (a, stuck, hold, fmax) = run::<I16F16, I32F32>(
                    &m,
                    load,
                    scene,
                    Method::SemiImplicitEuler,
                    10_000,
                    jitter,
                );
                let (a_ref, stuck_ref, _, _) =
                    run::<f64, f64>(&m, load, scene, Method::Rk4, 50_000, false);
                assert!(stuck && stuck_ref, "{m:?} {load} {scene:?}: not locked");
                assert!((hold - load).abs() < 1e-3, "{load} {scene:?}: holds {hold}");
                assert!(fmax < 30_000.0, "pressing force near saturation: {fmax}");
                assert!(
                    (a - a_ref).abs() < 5e-3,
                    "{m:?} {load} {scene:?} jitter={jitter}: angle {a} vs {a_ref}"
                );
                cases += 1;
            }
        }
    }
    assert_eq!(cases, 17 * 4 * 2);
}

#[test]
fn shipped_like_format_is_stable_over_the_envelope_at_10_khz() {
    check(false);
}

#[test]
fn shipped_like_format_is_stable_with_20_percent_tick_jitter() {
    check(true);
}
