//! The twin against the committed converged references (`tests/reference/converged.json`,
//! diffsol BDF at tolerance 1e-10, written by `examples/converge.rs`): every metric of every
//! built-in scene in both readings that settles at the tolerance tried or looser must be within
//! 1 % (or 1e-6 absolute) of its reference, and the same metrics must exist. Tried at the
//! default tolerance (1e-5), and under a second method (TR-BDF2 at 1e-6).

use noback_twin::convergence::{self, Entry};
use noback_twin::metrics;
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::sim::{self, Run};
use noback_twin::solver::{Integrator, Method, SolverError};

/// Checks every settled reference against `run` at `tolerance`; returns how many were checked.
fn holds_the_references(tolerance: f64, run: &dyn Fn(&Scene) -> Result<Run, SolverError>) -> usize {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/reference/converged.json"
    );
    let text = std::fs::read_to_string(path).unwrap();
    let refs: Vec<Entry> = serde_json::from_str(&text).unwrap();
    assert!(refs.len() > 50, "{} entries", refs.len());
    let mut checked = 0;
    for reading in [Reading::Paper, Reading::Physical] {
        for kind in SceneKind::ALL {
            let mut s = Scene::builtin(kind, reading);
            s.tolerance = tolerance;
            let r = run(&s).unwrap();
            let m = metrics::compute(&s, &r.samples, &r.stats, 0.0);
            for e in refs
                .iter()
                .filter(|e| e.scene == kind.name() && e.reading == reading.name())
            {
                if e.settles_at.is_none_or(|t| t < tolerance) {
                    continue;
                }
                let now = convergence::metric(&m, &e.metric);
                assert!(
                    convergence::close(now, e.reference),
                    "{} {} {} at {tolerance:e}: {now:?} against reference {:?}",
                    e.scene,
                    e.reading,
                    e.metric,
                    e.reference
                );
                checked += 1;
            }
        }
    }
    checked
}

#[test]
fn default_tolerance_matches_the_converged_references() {
    for reading in [Reading::Paper, Reading::Physical] {
        for kind in SceneKind::ALL {
            assert_eq!(Scene::builtin(kind, reading).tolerance, 1e-5);
        }
    }
    let checked = holds_the_references(1e-5, &sim::run);
    assert!(checked > 50, "only {checked} metrics checked");
}

#[test]
fn a_second_method_matches_the_converged_references() {
    let tr_bdf2 = |s: &Scene| {
        sim::run_with(
            s,
            Integrator::with_method(Method::TrBdf2, sim::solver_options(s)),
        )
    };
    let checked = holds_the_references(1e-6, &tr_bdf2);
    assert!(checked > 40, "only {checked} metrics checked");
}
