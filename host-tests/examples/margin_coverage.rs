//! Does the reported capacity margin's lower bound hold? For each draw of a family, the run's
//! last estimate against the drawn plant's own margin at the largest expected load,
//! `μ_s·c·(F_s + k·M_max)/M_max` (friction loss: × (1 − severity), the twin's μ scale).
//! `spread`: the drawn plants' margin over the model's, without running anything (what
//! `thresholds.capacity_uncertainty` is chosen from).
//!
//! `cargo run --release -p host-tests --example margin_coverage -- [RUNS] [SEED] [plant]
//! [spread]` (defaults 300, 2026, the physical-default family).

use host_tests::accuracy::run_monitor;
use host_tests::family::{form, ExampleArgs};
use host_tests::mc::{draw_in, draw_trace};
use host_tests::stats::quantile_line;
use noback::mechanism::Mechanism;
use noback::monitor::Config;
use noback_twin::fault::FaultKind;

/// A plant's capacity over the largest expected load.
fn service(c: &Config, m: &Mechanism, mu: f64) -> f64 {
    let l = c.thresholds.max_load_nm;
    m.pack_capacity_nm(m.quasi_static_pressing_force_n(l), mu) / l
}

fn main() -> Result<(), String> {
    let a = ExampleArgs::parse(300, 2026);
    let (runs, seed, family) = (a.runs, a.seed, a.family);
    let c = family.config();
    let model = service(&c, &c.mechanism, c.capacity_mu);
    if a.has("spread") {
        let r = (0..runs)
            .map(|i| {
                let m = draw_in(family, seed, i, None).scene.mechanism;
                service(&c, &m, m.mu_static) / model
            })
            .collect();
        println!(
            "family {}, seed {seed}, {runs} draws: model margin {model:.3}; drawn over model: {}",
            family.name(),
            quantile_line(r, &[0.01, 0.025, 0.5])
        );
        return Ok(());
    }
    println!(
        "family {}, seed {seed}, {runs} draws per row; model margin {model:.3}",
        family.name()
    );
    for fault in [None, Some(FaultKind::FrictionLoss)] {
        // (form, reported margin over the truth, whether the bound held)
        let mut seen: Vec<(&str, f64, bool)> = Vec::new();
        for i in 0..runs {
            let d = draw_in(family, seed, i, fault);
            let estimates = run_monitor(&draw_trace(&d)?, c)?;
            let Some(last) = estimates.last() else {
                continue;
            };
            let m = &d.scene.mechanism;
            let scale = d
                .scene
                .faults
                .first()
                .map_or(1.0, |f| 1.0 - f.severity.clamp(0.0, 1.0));
            let truth = service(&c, m, m.mu_static) * scale;
            let low = last.capacity_margin_low.to_num::<f64>();
            seen.push((
                form(&d.scene),
                last.capacity_margin.to_num::<f64>() / truth,
                low <= truth,
            ));
        }
        for f in ["paper", "physical"] {
            let here: Vec<_> = seen.iter().filter(|s| s.0 == f).collect();
            if here.is_empty() {
                continue;
            }
            let held = here.iter().filter(|s| s.2).count();
            println!(
                "{:13} {f:8}: lower bound held in {held} of {} runs; margin over the truth: {}",
                fault.map_or("healthy".into(), |k| format!("{k:?}")),
                here.len(),
                quantile_line(here.iter().map(|s| s.1).collect(), &[0.01, 0.025, 0.5])
            );
        }
    }
    Ok(())
}
