//! The paper protocol (docs/paper-comparison.md): the paper reading's scores under the gate,
//! and the damping reference speed fitted on the reverse braking time alone.

use noback_twin::paper_protocol::{self, FLOOR_RANGE_M_S};
use noback_twin::reading::{Reading, DEFAULT_OPEN};
use noback_twin::scene::SceneKind;

#[test]
fn paper_reading_scores_and_one_sample_lag() {
    let s = paper_protocol::score(Reading::Paper, DEFAULT_OPEN).unwrap();
    assert_eq!(s.rows.len(), 8);
    let lag = s
        .rows
        .iter()
        .find(|r| r.scene == "forward_load" && r.figure.starts_with("contact"))
        .unwrap();
    assert!(lag.one_sample && !lag.counts, "{lag:?}");
    let period = s
        .rows
        .iter()
        .find(|r| r.figure.starts_with("period"))
        .unwrap();
    assert!(
        period.within_25pct && period.dev_pct.unwrap().abs() < 10.0,
        "{period:?}"
    );
    assert_eq!(s.within_25pct, 4, "{:#?}", s.rows);
}

#[test]
fn floor_fit_hits_the_reverse_time_and_stays_in_range() {
    let v = paper_protocol::fit_floor().unwrap();
    assert!(v > FLOOR_RANGE_M_S.0 && v < FLOOR_RANGE_M_S.1, "{v}");
    let t = paper_protocol::braking_time(SceneKind::ReverseLoad, v)
        .unwrap()
        .unwrap();
    assert!((t - 0.44).abs() < 0.005, "fitted reverse braking time {t}");
}
