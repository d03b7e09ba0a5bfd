//! Where can a floor on the reported capacity margin sit? For each draw, the lowest margin the
//! monitor reported while no flag was up, in healthy draws and in draws with a holding fault
//! that raised nothing (dormant in the run): what `thresholds.margin_floor` is chosen from.
//!
//! `cargo run --release -p host-tests --example margin_floor -- [RUNS] [SEED] [plant]`
//! (defaults 300, 2026, the physical-default family).

use host_tests::accuracy::run_monitor;
use host_tests::family::{form, ExampleArgs};
use host_tests::mc::{draw_in, draw_trace};
use host_tests::stats::quantile_line;
use noback_twin::fault::FaultKind;

fn main() -> Result<(), String> {
    let a = ExampleArgs::parse(300, 2026);
    let (runs, seed, family) = (a.runs, a.seed, a.family);
    let c = family.config();
    println!(
        "family {}, seed {seed}, {runs} draws per row",
        family.name()
    );
    let kinds = [
        None,
        Some(FaultKind::FrictionLoss),
        Some(FaultKind::PackWear),
        Some(FaultKind::SpringBroken),
        Some(FaultKind::RampJam),
    ];
    for fault in kinds {
        // (form, lowest margin while unflagged, flagged at all)
        let mut seen: Vec<(&str, f64, bool)> = Vec::new();
        for i in 0..runs {
            let d = draw_in(family, seed, i, fault);
            let estimates = run_monitor(&draw_trace(&d)?, c)?;
            let low = estimates
                .iter()
                .filter(|e| !e.flags.any())
                .map(|e| e.capacity_margin.to_num::<f64>())
                .fold(f64::INFINITY, f64::min);
            let flagged = estimates.iter().any(|e| e.flags.any());
            seen.push((form(&d.scene), low, flagged));
        }
        for f in ["paper", "physical"] {
            let here: Vec<_> = seen.iter().filter(|s| s.0 == f).collect();
            if here.is_empty() {
                continue;
            }
            let quiet: Vec<f64> = here.iter().filter(|s| !s.2).map(|s| s.1).collect();
            println!(
                "{:13} {f:8}: {} runs, {} raised nothing; their lowest margin: {}",
                fault.map_or("healthy".into(), |k| format!("{k:?}")),
                here.len(),
                quiet.len(),
                quantile_line(quiet.clone(), &[0.001, 0.01, 0.1, 0.5])
            );
            for floor in [1.0, 1.25, 1.5, 1.75, 2.0] {
                let below = quiet.iter().filter(|m| **m < floor).count();
                print!("  <{floor}: {below}");
            }
            println!();
        }
    }
    Ok(())
}
