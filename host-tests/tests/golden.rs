//! Golden traces (`host-tests/golden/`, written by `cargo xtask golden`, never by hand): the
//! twin must still write exactly these bytes — a change in the physics shows here and is
//! reviewed as a regenerated file — and the monitor is held to its accuracy targets on them.

use host_tests::accuracy::twin_trace;
use noback_twin::trace::Trace;
use std::path::PathBuf;

const SCENES: [&str; 4] = ["reverse_load", "forward_load", "hold", "drive"];

fn golden_path(scene: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("golden")
        .join(format!("{scene}.trace.csv"))
}

#[test]
fn the_twin_still_writes_the_golden_traces() {
    for scene in SCENES {
        let path = golden_path(scene);
        let saved = std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("{}: {e} (run `cargo xtask golden`)", path.display()));
        let mut now = Vec::new();
        twin_trace(scene).unwrap().write_to(&mut now).unwrap();
        let now = String::from_utf8(now).unwrap();
        if saved != now {
            let line = saved
                .lines()
                .zip(now.lines())
                .position(|(a, b)| a != b)
                .map_or(saved.lines().count().min(now.lines().count()), |i| i)
                + 1;
            panic!(
                "{scene}: the twin's trace moved from {} at line {line}; if intended, run \
                 `cargo xtask golden` and review the diff",
                path.display()
            );
        }
    }
}

#[test]
fn golden_traces_read_back_whole() {
    for scene in SCENES {
        let trace = Trace::read(&golden_path(scene)).unwrap();
        assert_eq!(trace.sample_rate_hz, 10_000.0);
        assert!(
            trace.rows.len() >= 5000,
            "{scene}: {} rows",
            trace.rows.len()
        );
    }
}
