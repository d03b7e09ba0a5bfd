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
