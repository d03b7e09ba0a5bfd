//! Where the uncommissioned monitor false-alarms on the plant family (docs/decisions.md, "The
//! plant family in the Monte Carlo"): the healthy runs of `monitor-mc --family plant`, per
//! form and scene kind, with the first flag each raised, the runs that raised it, and whether
//! the paper reading's pack slips at μ_s. Words after `[RUNS] [SEED]` keep only the draws of
//! those forms and scene kinds (`physical ForwardLoad ContinuousClosing`): a rare class sooner.
//!
//! `cargo run --release -p host-tests --example family_false_alarms -- [RUNS] [SEED] [WORD …]`
//! (defaults 400 and 1616).

use host_tests::accuracy::{compare, run_monitor};
use host_tests::family::{form, ExampleArgs, Family};
use host_tests::mc::{draw_in, draw_trace, not_driven, SCENE_KINDS};
use std::collections::BTreeMap;

fn main() -> Result<(), String> {
    let a = ExampleArgs::parse(400, 1616);
    let (runs, seed) = (a.runs, a.seed);
    let (forms, kinds): (Vec<&String>, Vec<&String>) = a
        .rest
        .iter()
        .partition(|w| ["paper", "physical"].contains(&w.as_str()));
    if let Some(w) = kinds
        .iter()
        .find(|w| !SCENE_KINDS.iter().any(|k| format!("{k:?}") == ***w))
    {
        eprintln!(
            "error: '{w}' is neither a form (paper, physical) nor a scene kind {SCENE_KINDS:?}"
        );
        std::process::exit(2)
    }
    let mut runs_by: BTreeMap<String, usize> = BTreeMap::new();
    let mut flags_by: BTreeMap<String, Vec<u64>> = BTreeMap::new();
    let (mut apart, mut apart_quiet) = (0, 0);
    for i in 0..runs {
        let d = draw_in(Family::Plant, seed, i, None);
        let kind = format!("{:?}", d.scene.kind);
        if !(forms.is_empty() || forms.iter().any(|f| *f == form(&d.scene)))
            || !(kinds.is_empty() || kinds.contains(&&kind))
        {
            continue;
        }
        let key = format!("{} {kind}", form(&d.scene));
        *runs_by.entry(key.clone()).or_default() += 1;
        let trace = draw_trace(&d)?;
        let acc = compare(&trace, &run_monitor(&trace, Family::Plant.config())?);
        let is_apart = not_driven(&trace, &d.scene.sensors);
        if is_apart {
            apart += 1;
            apart_quiet += usize::from(acc.flags.is_empty());
        }
        if let Some(f) = acc.flags.first() {
            let mu = d.scene.open.paper_sliding_mu_static;
            let apart = if is_apart { ", not driven: apart" } else { "" };
            flags_by
                .entry(format!("{key}: {} (sliding μ_s {mu}{apart})", f.flag))
                .or_default()
                .push(i);
        }
    }
    println!("healthy draws 0..{runs} of seed {seed}, run by form and scene kind:");
    for (k, n) in &runs_by {
        println!("{n:6}  {k}");
    }
    println!("input apart from output (counted apart): {apart}, of which no flag: {apart_quiet}");
    println!("false alarms by first flag:");
    for (k, runs) in &flags_by {
        println!("{:6}  {k}: runs {runs:?}", runs.len());
    }
    Ok(())
}
