//! Every manifested fault the Monte Carlo counts as missed, draw by draw: its form, scene,
//! severity, onset, where it fell (`Context`), its latency and every flag the monitor raised, so a
//! reviewer can read each miss the rates of docs/monitor.md and docs/monitor-family.md count.
//! Draws are judged as `cargo xtask monitor-mc` judges them (`host_tests::mc::evaluate`).
//!
//! `cargo run --release -p host-tests --example fault_misses -- [RUNS] [SEED] [plant]
//! [commissioned] [KIND …]` (defaults 100 and 1616; every kind; the default family unless `plant`).

use host_tests::accuracy::{compare, run_monitor};
use host_tests::family::{form, ExampleArgs};
use host_tests::mc::{draw_in, draw_trace_after, evaluate, Campaign, FAULT_KINDS};
use noback_twin::fault::FaultKind;

fn main() -> Result<(), String> {
    let args = ExampleArgs::parse(100, 1616);
    let mut kinds = Vec::new();
    for word in args
        .rest
        .iter()
        .filter(|w| !["plant", "commissioned"].contains(&w.as_str()))
    {
        match FaultKind::parse(word) {
            Some(k) => kinds.push(k),
            None => {
                eprintln!("error: `{word}` is not a fault kind, `plant` or `commissioned`");
                std::process::exit(2);
            }
        }
    }
    if kinds.is_empty() {
        kinds = FAULT_KINDS.to_vec();
    }
    let campaign = Campaign {
        commissioned: args.has("commissioned"),
        ..Campaign::for_family(args.family)
    };
    println!(
        "| kind | run | form | scene | severity | onset (s) | where | latency (ms) | flags (s) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let mut tally = Vec::new();
    for kind in kinds {
        let (mut manifested, mut missed) = (0, 0);
        for run in 0..args.runs {
            let d = draw_in(args.family, args.seed, run, Some(kind));
            let o = evaluate(&d, &campaign);
            if !o.counts() || !o.manifested {
                continue;
            }
            manifested += 1;
            if o.detected() {
                continue;
            }
            missed += 1;
            let trace = draw_trace_after(&d, campaign.pre_roll_s)?;
            let flags = compare(&trace, &run_monitor(&trace, campaign.config_for(&d).0)?).flags;
            let flags: Vec<String> = flags
                .iter()
                .map(|f| format!("{} {:.3}", f.flag, f.t_s))
                .collect();
            let fault = d.scene.faults[0];
            println!(
                "| {kind:?} | {run} | {} | {} | {:.2} | {:.3} | {} | {} | {} |",
                form(&d.scene),
                d.scene.kind.name(),
                fault.severity,
                fault.at_s,
                o.context.map_or("—".into(), |c| format!("{c:?}")),
                o.latency_s
                    .map_or("—".into(), |l| format!("{:.1}", 1e3 * l)),
                if flags.is_empty() {
                    "none".into()
                } else {
                    flags.join(", ")
                },
            );
        }
        tally.push(format!("{kind:?} {missed} of {manifested}"));
    }
    println!(
        "\nseed {}, {} runs per kind, family `{}`{}: missed {}",
        args.seed,
        args.runs,
        args.family.name(),
        if campaign.commissioned {
            ", commissioned"
        } else {
            ""
        },
        tally.join("; ")
    );
    Ok(())
}
