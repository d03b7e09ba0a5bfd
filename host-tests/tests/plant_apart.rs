//! A fault draw is counted apart from its kind's rates exactly where the same draw without its
//! fault comes apart (`host_tests::mc::not_driven`, the rule nominal draws are counted by), and
//! never because the fault itself parts the encoders (docs/model.md, "The plant family").

use host_tests::family::Family;
use host_tests::mc::{draw_in, draw_trace_after, evaluate, not_driven, Campaign, PRE_ROLL_S};
use noback_twin::fault::FaultKind;

/// Evaluates draw `run` of `kind` at `seed`, and says whether its own faulted trace comes apart.
fn judged(seed: u64, run: u64, kind: FaultKind) -> (host_tests::mc::Outcome, bool) {
    let d = draw_in(Family::Plant, seed, run, Some(kind));
    let trace = draw_trace_after(&d, PRE_ROLL_S).expect("twin");
    let own = not_driven(&trace, &d.scene.sensors);
    (evaluate(&d, &Campaign::for_family(Family::Plant)), own)
}

/// Evaluation seed 5555's drag draw 54 (paper form, continuous closing): its plant comes apart
/// without the drag too, so the draw tells nothing of the drag.
#[test]
fn a_fault_draw_whose_plant_comes_apart_without_the_fault_is_counted_apart() {
    let (o, own) = judged(5555, 54, FaultKind::Drag);
    assert!(own);
    assert!(o.not_driven && !o.counts(), "{o:?}");
}

/// A frozen output encoder (tuning seed 1616's draw 22) and a drag that stops the output
/// (5555's draw 8) part the encoders themselves: that is the fault showing, and it counts.
#[test]
fn a_fault_that_parts_the_encoders_itself_counts_in_its_kinds_rates() {
    for (seed, run, kind) in [
        (1616, 22, FaultKind::EncoderStuck),
        (5555, 8, FaultKind::Drag),
    ] {
        let (o, own) = judged(seed, run, kind);
        assert!(own, "{seed} {run}: the faulted trace comes apart");
        assert!(!o.not_driven && o.counts(), "{seed} {run}: {o:?}");
    }
}
