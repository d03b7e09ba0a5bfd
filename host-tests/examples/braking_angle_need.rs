//! How wide the uncommissioned braking envelope must be for the plant family's healthy paper
//! draws (docs/decisions.md, "A light aiding load braked at a third of the model"): for each
//! forward- or reverse-load draw that the physical reading's factor (2×) calls `brake_weak`,
//! the smallest `braking_angle_factor` that lets it through (bisection, 1e-3).
//!
//! `cargo run --release -p host-tests --example braking_angle_need -- [RUNS] [SEED]` (defaults
//! 10 000 and 1616).

use host_tests::accuracy::{compare, run_monitor};
use host_tests::family::{form, runs_and_seed, Family};
use host_tests::mc::{draw_in, draw_trace};
use noback_twin::scene::SceneKind;
use noback_twin::trace::Trace;

/// Whether the uncommissioned monitor with braking-angle factor `factor` calls `brake_weak` first.
fn weak(trace: &Trace, factor: f64) -> Result<bool, String> {
    let mut cfg = Family::Plant.config();
    cfg.thresholds.braking_angle_factor = factor;
    let acc = compare(trace, &run_monitor(trace, cfg)?);
    Ok(acc.flags.first().is_some_and(|f| f.flag == "brake_weak"))
}

fn main() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let (runs, seed) = runs_and_seed(&mut args, 10_000, 1616);
    let (mut worst, mut called) = (0.0_f64, 0);
    for i in 0..runs {
        let d = draw_in(Family::Plant, seed, i, None);
        if !matches!(
            d.scene.kind,
            SceneKind::ForwardLoad | SceneKind::ReverseLoad
        ) {
            continue;
        }
        let trace = draw_trace(&d)?;
        if !weak(&trace, 2.0)? {
            continue;
        }
        called += 1;
        let (mut lo, mut hi) = (2.0, 8.0);
        if weak(&trace, hi)? {
            println!(
                "run {i} ({} {:?}): weak at {hi}×",
                form(&d.scene),
                d.scene.kind
            );
            continue;
        }
        while hi - lo > 1e-3 {
            let mid = 0.5 * (lo + hi);
            if weak(&trace, mid)? {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        worst = worst.max(hi);
        println!(
            "run {i} ({} {:?}): needs {hi:.3}×",
            form(&d.scene),
            d.scene.kind
        );
    }
    println!("healthy runs {runs} of seed {seed}: {called} called weak at 2×; the most any needs: {worst:.3}×");
    Ok(())
}
