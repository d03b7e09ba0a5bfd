//! The paper reading against the targets: holding torque and the two pack capacities
//! within 5 %, the continuous-closing cycle, and every qualitative finding.

use noback_twin::metrics;
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::sim;

fn run(kind: SceneKind) -> metrics::Metrics {
    let s = Scene::builtin(kind, Reading::Paper);
    let r = sim::run(&s).unwrap();
    metrics::compute(&s, &r.samples, &r.stats, r.wall_s)
}

#[test]
fn holding_torque_within_5_percent() {
    let h = run(SceneKind::Hold).holding_torque_nm.unwrap();
    assert!((h - 20.3).abs() <= 0.05 * 20.3, "{h}");
    for kind in [SceneKind::ReverseLoad, SceneKind::ForwardLoad] {
        let h = run(kind).holding_torque_nm.unwrap();
        assert!((h - 20.3).abs() <= 0.05 * 20.3, "{kind:?}: {h}");
    }
}

#[test]
fn continuous_closing_cycle() {
    let m = run(SceneKind::ContinuousClosing);
    // Pack capacities seen in the cycle: peaks ≈ 60, troughs ≈ 8.2 N·m, within 5 %.
    assert!(
        (m.peak_braking_torque_nm - 60.0).abs() <= 0.05 * 60.0,
        "{}",
        m.peak_braking_torque_nm
    );
    assert!(
        (m.trough_braking_torque_nm - 8.2).abs() <= 0.05 * 8.2,
        "{}",
        m.trough_braking_torque_nm
    );
    // The limit cycle of MODEL.md: period 2ω(1/a1 + 1/a2) = 0.455 s (paper 0.444, within 25 %),
    // output speed 0 … 2ω = 27.6 rad/s (paper 29).
    let p = m.period_s.unwrap();
    assert!((p - 0.455).abs() < 0.005, "{p}");
    assert!((p - 0.444).abs() <= 0.25 * 0.444);
    assert!(
        (m.max_output_speed_rad_s - 27.56).abs() < 0.1,
        "{}",
        m.max_output_speed_rad_s
    );
}

#[test]
fn qualitative_findings_hold() {
    let rev = run(SceneKind::ReverseLoad);
    let fwd = run(SceneKind::ForwardLoad);
    assert!(rev.braking_time_s.unwrap() > fwd.braking_time_s.unwrap());
    assert!(fwd.contact_lag_s.unwrap() < rev.contact_lag_s.unwrap());
    assert_eq!(fwd.output_reversals, 0, "forward never reverses");
    assert!(rev.output_reversals >= 1, "reverse reverses");
    assert!(rev.holding_torque_nm.is_some(), "then locks");
}

#[test]
fn reverse_angle_against_forward_depends_on_the_far_face() {
    // With the far face a stop (default) the reverse output overruns the stopped connecting
    // shaft and the reverse angle comes out larger than the forward one (the paper has it
    // smaller); with the input side left where it stopped the order is the paper's, at the
    // price of the reverse angle and lag (docs/model.md, "Open items").
    let fwd = run(SceneKind::ForwardLoad).braking_angle_rad.unwrap();
    let rev = run(SceneKind::ReverseLoad).braking_angle_rad.unwrap();
    assert!(rev > fwd, "{rev} vs {fwd}");
    let mut s = Scene::builtin(SceneKind::ReverseLoad, Reading::Paper);
    s.open.paper_far_face_stop = false;
    let r = sim::run(&s).unwrap();
    let rev_frozen = metrics::compute(&s, &r.samples, &r.stats, r.wall_s)
        .braking_angle_rad
        .unwrap();
    assert!(rev_frozen < fwd, "{rev_frozen} vs {fwd}");
}

#[test]
fn forward_braking_is_the_closed_form_and_tolerance_independent() {
    // Tracking before release, then the engaged pack (59.0 N·m with μ_s) against the load:
    // a = (T_all − M + M_sf)/J_s, t = ω/a, angle = ω²/2a.
    let m = noback::mechanism::TABLE2;
    let t_all = m.pack_capacity_nm(m.quasi_static_pressing_force_n(20.3), m.mu_static);
    let bearing = m.mu_dynamic * m.output_shaft_mass_kg * 9.81 * m.output_friction_radius_m;
    let a = (t_all - 20.3 + bearing) / m.output_inertia_kg_m2;
    for tol in [1e-4, 1e-7] {
        let mut s = Scene::builtin(SceneKind::ForwardLoad, Reading::Paper);
        s.tolerance = tol;
        let r = sim::run(&s).unwrap();
        let mm = metrics::compute(&s, &r.samples, &r.stats, r.wall_s);
        // Sampled at 10 kHz: the stop is seen within one sample (and the threshold 0.05 rad/s).
        assert!(
            (mm.braking_time_s.unwrap() - 13.78 / a).abs() < 2e-4,
            "{tol}: {mm:?}"
        );
        assert!(
            (mm.braking_angle_rad.unwrap() - 13.78 * 13.78 / (2.0 * a)).abs() < 2e-3,
            "{tol}: {mm:?}"
        );
        // No chatter at the engagement switch: a handful of events, not hundreds.
        assert!(mm.events < 10, "{tol}: {} events", mm.events);
    }
}

#[test]
fn tracking_reports_the_pressing_force_of_the_pack_torque() {
    // Before the release of `forward_load` the output tracks the input with the pack holding
    // exactly the load: the reported pressing force is the one that gives that torque (a
    // Filippov mean, 407.6 N), not the full quasi-static force (1184 N); after the release the
    // load face is fully engaged.
    let m = noback::mechanism::TABLE2;
    let per_n = m.pack_torque_per_newton_m(m.mu_static);
    let s = Scene::builtin(SceneKind::ForwardLoad, Reading::Paper);
    let r = sim::run(&s).unwrap();
    let before = r.samples.iter().find(|x| x.t_s > 0.1).unwrap();
    assert!(
        (before.pressing_force_n * per_n - before.braking_torque_nm).abs() < 1e-6,
        "{before:?}"
    );
    // The load less the output bearing's friction (3.5e-3 N·m).
    assert!((before.braking_torque_nm - 20.3).abs() < 0.01, "{before:?}");
    let after = r.samples.iter().find(|x| x.t_s > 0.21).unwrap();
    assert!(
        (after.pressing_force_n - m.quasi_static_pressing_force_n(20.3)).abs() < 1e-6,
        "{after:?}"
    );
}

#[test]
fn quasi_static_axial_travel_is_the_pack_deflection_range() {
    // Continuous closing swings the pressing force between the spring alone and spring + load;
    // the big shaft moves by the pack contact's deflection between the two,
    // (F/k)^(2/3): 0.0438 mm, not the paper's 1.73 mm (docs/model.md, "Against the paper").
    let m = noback::mechanism::TABLE2;
    let d = |f: f64| (f / m.contact_stiffness).powf(2.0 / 3.0);
    let want = d(m.quasi_static_pressing_force_n(20.3)) - d(m.spring_preload_n());
    let got = run(SceneKind::ContinuousClosing).axial_travel_mm.unwrap() * 1e-3;
    assert!((got - want).abs() < 1e-9, "{got} vs {want}");
    assert!(got < 0.25 * 1.73e-3);
}

#[test]
fn braking_times_stay_short_for_every_rigid_choice() {
    // The quantitative claim of docs/model.md ("Against the paper"): no choice of the open
    // items the rigid reading has (backlash 0.014–0.04 rad, far face stop or not, μ_s or μ_d
    // while slipping) brings either braking time within 25 % of the paper (0.44 / 0.335 s);
    // the reverse stays below 0.33 s (0.31 s at best: no far face and μ_d), the forward below
    // 0.17 s.
    for backlash in [0.01414, 0.0, 0.04] {
        for far in [true, false] {
            for mu_s in [true, false] {
                let mut times = [0.0; 2];
                for (i, kind) in [SceneKind::ReverseLoad, SceneKind::ForwardLoad]
                    .into_iter()
                    .enumerate()
                {
                    let mut s = Scene::builtin(kind, Reading::Paper);
                    s.open.paper_backlash_rad = backlash;
                    s.open.paper_far_face_stop = far;
                    s.open.paper_sliding_mu_static = mu_s;
                    let r = sim::run(&s).unwrap();
                    let mm = metrics::compute(&s, &r.samples, &r.stats, r.wall_s);
                    times[i] = mm.braking_time_s.unwrap();
                }
                let tag = format!("b={backlash} far={far} mu_s={mu_s}: {times:?}");
                assert!(times[0] < 0.75 * 0.44, "{tag}");
                // 0.17 s is also below 0.75 × 0.335 s.
                assert!(times[1] < 0.17, "{tag}");
            }
        }
    }
}

#[test]
fn backlash_option_moves_the_reverse_case_only() {
    // The backlash enters only through the far-face stop after the release: a larger one delays
    // the re-engagement (longer lag) and takes it off the net angle; forward and continuous
    // closing do not see it.
    let mut s = Scene::builtin(SceneKind::ReverseLoad, Reading::Paper);
    s.open.paper_backlash_rad = 0.04;
    let r = sim::run(&s).unwrap();
    let wide = metrics::compute(&s, &r.samples, &r.stats, r.wall_s);
    let derived = run(SceneKind::ReverseLoad);
    assert!(wide.contact_lag_s.unwrap() > derived.contact_lag_s.unwrap() + 0.003);
    assert!(wide.braking_angle_rad.unwrap() < derived.braking_angle_rad.unwrap() - 0.01);
    let mut f = Scene::builtin(SceneKind::ForwardLoad, Reading::Paper);
    f.open.paper_backlash_rad = 0.04;
    let r = sim::run(&f).unwrap();
    let fw = metrics::compute(&f, &r.samples, &r.stats, r.wall_s);
    assert_eq!(
        fw.braking_angle_rad,
        run(SceneKind::ForwardLoad).braking_angle_rad
    );
}

/// The functional test's push on the paper reading (docs/model.md, "The `paper` reading"): the
/// pack holds the load and the push together while the push relieves the load face, and breaks
/// away where the quasi-static closed form `C(L) − g·T = L + T` says.
#[test]
fn the_test_push_breaks_the_pack_away_at_the_closed_form_torque() {
    let s = Scene::builtin(SceneKind::FunctionalTest, Reading::Paper);
    let r = sim::run(&s).unwrap();
    let (m, l) = (&s.mechanism, s.load_torque_nm);
    let spring = noback_twin::spring::spring_force_n(m, m.pack_clearance_m, 1.0);
    let pressing = |t: f64| spring + (l - t) * m.ramp_factor_per_m();
    let cap = |t: f64| noback_twin::pack::capacity(m, pressing(t), 1.0, true).static_nm;
    let g = (cap(0.0) - cap(l)) / l;
    let t_b = (cap(0.0) - l) / (1.0 + g);
    let pushing = r.samples.iter().filter(|x| x.t_s >= s.test.push_s());
    let mut held = 0;
    for x in pushing.clone().take_while(|x| x.brake_state == 2) {
        let t = x.drive_torque_nm;
        assert!((x.braking_torque_nm - (l + t)).abs() < 1e-6, "{x:?}");
        assert!((x.pressing_force_n - pressing(t)).abs() < 1e-6, "{x:?}");
        held += 1;
    }
    assert!(held > 1000, "held {held} samples");
    let slip = pushing.clone().find(|x| x.brake_state != 2).unwrap();
    // The torque limit rises 0.02 N·m per millisecond step.
    assert!(
        (slip.drive_torque_nm - t_b).abs() <= 0.03,
        "{slip:?} against {t_b}"
    );
    assert!((10.0..12.0).contains(&t_b), "{t_b}");
}
