//! Stability boundaries of explicit fixed steps on the full physical contact model (issue 6):
//! explicit Euler and RK4 are stable at 0.5–1 µs and diverge at steps of a few µs, and the
//! fixed-step integrator of `cargo xtask bench` reports the divergence (with its time) instead
//! of returning NaN.

#[allow(dead_code)]
#[path = "../../xtask/src/bench/explicit.rs"]
mod explicit;

use explicit::{integrate, Explicit, FixedRun, Verdict};
use noback_twin::model::physical::Physical;
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::sim::model_config;

/// The window integrated (s): the drive carrying the output against the load from t = 0.
const WINDOW_S: f64 = 0.01;

fn fixed(method: Explicit, h_us: f64) -> FixedRun {
    let scene = Scene::builtin(SceneKind::ReverseLoad, Reading::Physical);
    let mut model = Physical::new(model_config(&scene));
    integrate(&mut model, method, h_us * 1e-6, WINDOW_S, 1e-4)
}

fn all_finite(r: &FixedRun) -> bool {
    r.samples
        .iter()
        .all(|(t, a, w)| t.is_finite() && a.is_finite() && w.is_finite())
}

#[test]
fn small_explicit_steps_are_stable() {
    // Stable = finishes with every sample bounded: the drive keeps the output between rest
    // and 1.5 × its speed reference (accuracy is the bench's "inaccurate" column, not this).
    for (method, h) in [
        (Explicit::Euler, 1.0),
        (Explicit::Rk4, 1.0),
        (Explicit::Rk4, 2.0),
    ] {
        let r = fixed(method, h);
        assert_eq!(r.verdict, Verdict::Finished, "{method:?} at {h} µs");
        assert!(all_finite(&r));
        assert_eq!(r.samples.len(), 101);
        assert!(
            r.samples.iter().all(|s| s.2 <= 0.5 && s.2 >= -1.5 * 13.78),
            "{method:?} at {h} µs left the physical range"
        );
    }
}

#[test]
fn explicit_steps_of_a_few_microseconds_diverge_and_say_so() {
    for (method, h) in [(Explicit::Euler, 10.0), (Explicit::Rk4, 5.0)] {
        let r = fixed(method, h);
        match r.verdict {
            Verdict::Diverged { at_s } => {
                assert!(at_s > 0.0 && at_s <= WINDOW_S, "{method:?}: {at_s}")
            }
            Verdict::Finished => panic!("{method:?} at {h} µs did not diverge"),
        }
        // The samples stop before the blow-up: never a NaN or an infinity.
        assert!(all_finite(&r), "{method:?}");
        assert!(r.samples.len() < 101);
    }
}
