//! Snapshot of the paper table (both readings): fails when any figure moves. Regenerate with
//! `UPDATE_SNAPSHOTS=1 cargo test -p noback-twin --test paper_snapshot` after a deliberate
//! change, and say why in the commit.

use noback_twin::paper_table;

#[test]
fn paper_table_snapshot() {
    let table = paper_table::build(1e-5).unwrap();
    let now = table.snapshot();
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/snapshots/paper_table.txt");
    if std::env::var_os("UPDATE_SNAPSHOTS").is_some() {
        std::fs::write(&path, &now).unwrap();
        return;
    }
    let want = std::fs::read_to_string(&path).unwrap_or_default();
    assert_eq!(
        now,
        want,
        "paper table moved; diff against {}",
        path.display()
    );
}
