//! The plant family commissioned unit by unit (docs/decisions.md, "Commissioning"): each healthy
//! draw of `monitor-mc --family plant` is commissioned on its own acceptance runs (the same plant
//! at 13.78 rad/s, cut at 0.2 s, held; PLAN `one`: opening against 20.3 N·m; `two`: and against
//! 8 N·m; `cycle`: and closing with 20.3 N·m), then its drawn scene is run uncommissioned and
//! commissioned. Per form: runs, refused commissionings, false alarms, the holding-torque error
//! on the braking scenes.
//!
//! `cargo run --release -p host-tests --example commissioned_family -- [RUNS] [SEED] [PLAN]`
//! (defaults 300, 4242, cycle).

use host_tests::accuracy::{compare, run_monitor};
use host_tests::commission::{commission_unit, ACCEPTANCE};
use host_tests::family::{form, runs_and_seed, Family};
use host_tests::mc::{draw_in, draw_trace, not_driven};
use noback::monitor::Config;
use noback_twin::scene::SceneKind;
use std::collections::BTreeMap;

#[derive(Default)]
struct Tally {
    runs: usize,
    refused: usize,
    fa_uncommissioned: usize,
    fa_commissioned: usize,
    braking: usize,
    hold_within_2pct_uncommissioned: usize,
    hold_within_2pct: usize,
    hold_err_max: f64,
}

fn main() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let (runs, seed) = runs_and_seed(&mut args, 300, 4242);
    // (kind, load) of each acceptance run.
    let plan: &[(SceneKind, f64)] = match args.next().as_deref() {
        None | Some("cycle") => &ACCEPTANCE,
        Some("two") => &ACCEPTANCE[..2],
        Some("one") => &ACCEPTANCE[..1],
        Some(other) => return Err(format!("PLAN: `{other}`: expected one, two or cycle")),
    };
    let mut by: BTreeMap<String, Tally> = BTreeMap::new();
    // (form, braking scene) → (runs within 2 %, runs, median error sum helper)
    let mut by_kind: BTreeMap<String, (usize, usize, Vec<f64>)> = BTreeMap::new();
    for i in 0..runs {
        let d = draw_in(Family::Plant, seed, i, None);
        let trace = draw_trace(&d)?;
        if not_driven(&trace, &d.scene.sensors) {
            continue;
        }
        let t = by.entry(form(&d.scene).to_string()).or_default();
        t.runs += 1;
        let uncommissioned = compare(&trace, &run_monitor(&trace, Config::default())?);
        t.fa_uncommissioned += usize::from(!uncommissioned.flags.is_empty());
        let c = match commission_unit(&d.scene, plan, |t| d.mount(t)) {
            Ok(c) => c,
            Err(e) => {
                t.refused += 1;
                eprintln!("draw {i} ({}): refused: {e}", form(&d.scene));
                continue;
            }
        };
        let acc = compare(&trace, &run_monitor(&trace, c.config)?);
        t.fa_commissioned += usize::from(!acc.flags.is_empty());
        if matches!(
            d.scene.kind,
            SceneKind::ReverseLoad | SceneKind::ForwardLoad
        ) {
            if let Some(err) = acc.holding_torque_err_pct() {
                t.braking += 1;
                let e = by_kind
                    .entry(format!("{} {}", form(&d.scene), d.scene.kind.name()))
                    .or_default();
                e.0 += usize::from(err <= 2.0);
                e.1 += 1;
                e.2.push(err);
                t.hold_within_2pct += usize::from(err <= 2.0);
                t.hold_within_2pct_uncommissioned += usize::from(
                    uncommissioned
                        .holding_torque_err_pct()
                        .is_some_and(|e| e <= 2.0),
                );
                t.hold_err_max = t.hold_err_max.max(err);
            }
        }
    }
    println!("healthy driven draws of seed {seed} (first {runs}), per form:");
    println!("| form | runs | commissioning refused | false alarms uncommissioned | commissioned | braking runs with holding torque within 2 %, uncommissioned | commissioned | worst commissioned |");
    println!("|---|---|---|---|---|---|---|---|");
    for (f, t) in &by {
        println!(
            "| {f} | {} | {} | {} | {} | {}/{} | {}/{} | {:.1} % |",
            t.runs,
            t.refused,
            t.fa_uncommissioned,
            t.fa_commissioned,
            t.hold_within_2pct_uncommissioned,
            t.braking,
            t.hold_within_2pct,
            t.braking,
            t.hold_err_max
        );
    }
    println!("\nper braking scene, commissioned:\n| form, scene | within 2 % | median error |\n|---|---|---|");
    for (k, (within, n, mut errs)) in by_kind {
        errs.sort_by(f64::total_cmp);
        println!("| {k} | {within}/{n} | {:.1} % |", errs[errs.len() / 2]);
    }
    Ok(())
}
