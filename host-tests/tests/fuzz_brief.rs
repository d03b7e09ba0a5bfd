//! The fuzz targets run briefly on the stable toolchain: every seed in `fuzz/seeds/<target>/`
//! plus a few thousand random and mutated inputs, deterministic per target. `cargo xtask fuzz`
//! runs the same bodies under libFuzzer for as long as asked.

use host_tests::fuzz::{brief_campaign, TARGETS};
use std::path::PathBuf;

/// Random inputs per target in the brief run.
const RANDOM_INPUTS: usize = 20_000;

fn seeds(target: &str) -> Vec<Vec<u8>> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../fuzz/seeds")
        .join(target);
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .flatten()
        .map(|e| e.path())
        .collect();
    files.sort();
    files.iter().map(|p| std::fs::read(p).unwrap()).collect()
}

#[test]
fn every_target_survives_its_brief_campaign() {
    for (i, target) in TARGETS.iter().enumerate() {
        let seeds = seeds(target);
        assert!(!seeds.is_empty(), "no seeds for {target}");
        let c = brief_campaign(target, &seeds, RANDOM_INPUTS, 0x5EED + i as u64);
        assert!(c.failures.is_empty(), "{target}: {:?}", c.failures);
        assert_eq!(c.inputs, seeds.len() + RANDOM_INPUTS);
        // The campaign must reach past the parsers' first checks: some inputs are accepted.
        assert!(
            c.accepted > 0,
            "{target}: no input accepted in {} tries",
            c.inputs
        );
    }
}

#[test]
fn the_monitor_target_catches_a_broken_invariant() {
    // A stream whose second tick is late must raise overrun; the checker itself must notice
    // when it does not, or the campaign above proves nothing.
    use host_tests::fuzz::check_estimate;
    use noback::monitor::{Config, Inputs, Monitor};
    let mut m = Monitor::new(Config::default()).unwrap();
    let a = m.step(&Inputs::new(2048, 0, 0, false));
    let b = m.step(&Inputs::new(2048, 0, 0, false));
    assert!(check_estimate(&b, Some(&a), 1, false).is_ok());
    assert!(
        check_estimate(&b, Some(&a), 3, false).is_err(),
        "tick mismatch not caught"
    );
    let mut cleared = b;
    cleared.flags = Default::default();
    let mut raised = a;
    raised.flags.brake_slip = true;
    assert!(
        check_estimate(&cleared, Some(&raised), 1, false).is_err(),
        "cleared latch not caught"
    );
    assert!(check_estimate(&cleared, Some(&raised), 1, true).is_ok());
}
