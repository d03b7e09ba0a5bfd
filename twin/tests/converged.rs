//! The twin at its default tolerance (1e-5) against the committed converged references
//! (`tests/reference/converged.json`, tolerance 1e-10, written by `examples/converge.rs`):
//! every metric that settles at 1e-5 or looser must be within 1 % (or 1e-6 absolute) of its
//! reference, and the same metrics must exist.

use noback_twin::convergence::{self, Entry};
use noback_twin::metrics;
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::sim;

#[test]
fn default_tolerance_matches_the_converged_references() {
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
            let s = Scene::builtin(kind, reading);
            assert_eq!(s.tolerance, 1e-5);
            let r = sim::run(&s).unwrap();
            let m = metrics::compute(&s, &r.samples, &r.stats, 0.0);
            for e in refs
                .iter()
                .filter(|e| e.scene == kind.name() && e.reading == reading.name())
            {
                if e.settles_at.is_none_or(|t| t < 1e-5) {
                    continue;
                }
                let now = convergence::metric(&m, &e.metric);
                assert!(
                    convergence::close(now, e.reference),
                    "{} {} {}: {now:?} against reference {:?}",
                    e.scene,
                    e.reading,
                    e.metric,
                    e.reference
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 50, "only {checked} metrics checked");
}
