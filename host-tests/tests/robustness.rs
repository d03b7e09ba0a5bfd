//! Every input class of `host_tests::robustness` gives its expected outcome (the table in
//! docs/reliability.md is written from the same runs by `cargo xtask reliability`).

#[test]
fn every_input_class_gives_its_expected_outcome() {
    let classes = host_tests::robustness::all_classes();
    assert!(classes.len() >= 7);
    for c in &classes {
        assert!(c.streams > 0 && c.steps > 0, "{}: nothing tried", c.class);
        assert!(
            c.failures.is_empty(),
            "{}: {:#?}",
            c.class,
            &c.failures[..c.failures.len().min(5)]
        );
    }
}
