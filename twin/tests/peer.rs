//! The diffsol peer (`--features peer`) on the same equations reaches the twin's converged
//! references: at tolerance 1e-6, every metric of every built-in scene in both readings that
//! settles at 1e-6 or looser is within 1 % (or 1e-6 absolute) of its reference under BDF.
#![cfg(feature = "peer")]

use noback_twin::convergence::{self, Entry};
use noback_twin::metrics;
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::sim;
use noback_twin::solver::peer::{Method, Peer};

#[test]
fn diffsol_bdf_matches_the_converged_references() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/reference/converged.json"
    );
    let refs: Vec<Entry> = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let mut checked = 0;
    for reading in [Reading::Paper, Reading::Physical] {
        for kind in SceneKind::ALL {
            let mut s = Scene::builtin(kind, reading);
            s.tolerance = 1e-6;
            let r = sim::run_with(&s, Peer::new(Method::Bdf, sim::solver_options(&s))).unwrap();
            let m = metrics::compute(&s, &r.samples, &r.stats, 0.0);
            for e in refs
                .iter()
                .filter(|e| e.scene == kind.name() && e.reading == reading.name())
            {
                if e.settles_at.is_none_or(|t| t < 1e-6) {
                    continue;
                }
                let now = convergence::metric(&m, &e.metric);
                assert!(
                    convergence::close(now, e.reference),
                    "{} {} {}: {now:?} against {:?}",
                    e.scene,
                    e.reading,
                    e.metric,
                    e.reference
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 40, "{checked} checked");
}
