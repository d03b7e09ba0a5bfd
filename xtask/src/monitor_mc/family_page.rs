//! `monitor-mc family`: the plant family (both readings, every open quantity over its range)
//! at a tuning seed and an evaluation seed, each uncommissioned and with every drawn unit
//! commissioned on its acceptance runs; per form, false alarms and detection per kind with
//! their 95 % intervals. Writes `docs/monitor-family.md`.

use super::report::{by_form, rate, FORMS};
use crate::shell::workspace_root;
use clap::Args;
use host_tests::accuracy::Braking;
use host_tests::family::{form, Family};
use host_tests::mc::{run_all, Campaign as Setup, FAULT_KINDS};
use serde_json::{json, Value};
use std::fmt::Write as _;

/// The seed the plant family's thresholds were chosen on (docs/decisions.md names it).
pub const TUNING_SEED: u64 = 1616;
/// A seed no threshold was chosen on, run only to report.
pub const EVALUATION_SEED: u64 = 5555;
/// The page.
pub const PAGE: &str = "docs/monitor-family.md";

#[derive(Args, Debug)]
pub struct FamilyArgs {
    /// Nominal runs per campaign.
    #[arg(long, default_value_t = 2000)]
    runs: u64,
    /// Runs per fault kind per campaign.
    #[arg(long, default_value_t = 100)]
    fault_runs: u64,
    /// Print the four campaigns' per-form reports as one JSON object; write no page.
    #[arg(long)]
    json: bool,
}

/// Issue 16's accuracy targets on a braking run: holding torque within 2 %, pressing-force RMS
/// within 10 % of its peak, lock time within 10 ms.
const HOLDING_PCT: f64 = 2.0;
const FORCE_RMS_PCT: f64 = 10.0;
const LOCK_S: f64 = 0.010;

/// One campaign's per-form report (`report::by_form`) with, per form, its nominal braking
/// runs' accuracy against issue 16's targets (`braking`).
fn campaign(seed: u64, commissioned: bool, a: &FamilyArgs) -> Result<Value, String> {
    let mut setup = Setup::for_family(Family::Plant);
    setup.commissioned = commissioned;
    let c = super::campaign_of(&setup, Family::Plant, seed, a.runs, a.fault_runs);
    let draws = super::draws_of(&c, 0..a.runs, 0..a.fault_runs);
    eprintln!(
        "monitor-mc family: seed {seed}, {}commissioned: {} runs",
        if commissioned { "" } else { "un" },
        draws.len()
    );
    let outcomes = run_all(&draws, &setup, super::threads(None), &|_, _| {});
    for e in outcomes.iter().filter_map(|o| o.error.as_deref()) {
        eprintln!("monitor-mc family: seed {seed}: {e}");
    }
    let forms: Vec<&str> = draws.iter().map(|d| form(&d.scene)).collect();
    let mut report = by_form(&outcomes, &forms, commissioned);
    for form in FORMS {
        let runs: Vec<Braking> = outcomes
            .iter()
            .zip(&forms)
            .filter(|(o, f)| **f == form && o.counts_as_nominal())
            .filter_map(|(o, _)| o.braking)
            .collect();
        let within =
            |ok: &dyn Fn(&Braking) -> bool| rate(runs.iter().filter(|b| ok(b)).count(), runs.len());
        let mut holding: Vec<f64> = runs.iter().map(|b| b.holding_err_pct).collect();
        holding.sort_by(f64::total_cmp);
        report[form]["braking"] = json!({
            "holding_within_2pct": within(&|b| b.holding_err_pct <= HOLDING_PCT),
            "force_rms_within_10pct": within(&|b| b.force_rms_pct <= FORCE_RMS_PCT),
            "lock_within_10ms": within(&|b| b.lock_err_s.is_some_and(|e| e <= LOCK_S)),
            "all_three": within(&|b| {
                b.holding_err_pct <= HOLDING_PCT
                    && b.force_rms_pct <= FORCE_RMS_PCT
                    && b.lock_err_s.is_some_and(|e| e <= LOCK_S)
            }),
            "holding_err_median_pct": holding.get(holding.len() / 2),
            "trusted": within(&|b| b.trusted),
            "trusted_beyond_2pct": within(&|b| b.trusted && b.holding_err_pct > HOLDING_PCT),
        });
    }
    Ok(report)
}

/// `k/n (lo–hi %)` of a `report::rate` value.
fn cell(r: &Value) -> String {
    let (k, n) = (&r["of"][0], &r["of"][1]);
    match (r["ci95"][0].as_f64(), r["ci95"][1].as_f64()) {
        (Some(lo), Some(hi)) if n.as_u64() > Some(0) => {
            format!("{k}/{n} ({:.0}–{:.0} %)", 100.0 * lo, 100.0 * hi)
        }
        _ => format!("{k}/{n}"),
    }
}

/// The false alarms' cell: the count and the 95 % upper bound per run.
fn alarm_cell(r: &Value) -> String {
    let hi = r["ci95"][1]
        .as_f64()
        .map_or("—".into(), |h| format!("{h:.1e}"));
    format!("{}/{} (≤ {hi})", r["of"][0], r["of"][1])
}

/// One seed's table: rows false alarms then each kind, columns form × commissioning.
fn table(s: &mut String, seed: u64, what: &str, unc: &Value, com: &Value) {
    let _ = writeln!(s, "\n### Seed {seed} ({what})\n");
    let mut head = String::from("| | ");
    let mut rule = String::from("|---|");
    for form in FORMS {
        let _ = write!(head, "{form}, uncommissioned | {form}, commissioned | ");
        rule.push_str("---|---|");
    }
    let _ = writeln!(s, "{}\n{rule}", head.trim_end());
    let mut row = |name: &str, f: &dyn Fn(&Value) -> String| {
        let mut line = format!("| {name} |");
        for form in FORMS {
            let _ = write!(line, " {} | {} |", f(&unc[form]), f(&com[form]));
        }
        let _ = writeln!(s, "{line}");
    };
    row("false alarms (nominal runs)", &|v| {
        alarm_cell(&v["false_alarm"])
    });
    row("functional tests failed (nominal runs tested)", &|v| {
        let t = &v["functional_tests_nominal"];
        format!(
            "{}/{}; {} rejected at acceptance",
            t["failed"], t["tested"], t["rejected_at_acceptance"]
        )
    });
    for kind in FAULT_KINDS {
        let k = format!("{kind:?}");
        row(&k, &|v| {
            let (d, a) = (
                &v["dormant"][k.as_str()],
                &v["not_driven_by_kind"][k.as_str()],
            );
            let found = &v["dormant_found"][k.as_str()];
            let tested = &v["dormant_functional_tested"][k.as_str()];
            let apart = match a.as_u64() {
                Some(n) if n > 0 => format!("; {n} plant apart"),
                _ => String::new(),
            };
            let cell = cell(&v["detection"][k.as_str()]);
            format!("{cell}; {d} dormant, {found} found, {tested} tested{apart}")
        });
    }
    row("with the drive's current command: false alarms", &|v| {
        alarm_cell(&v["false_alarm_with_command"])
    });
    row("with the drive's current command: CurrentOpen", &|v| {
        cell(&v["detection_with_command"]["CurrentOpen"])
    });
    row(
        "**nominal braking runs** (reverse_load, forward_load) ending locked",
        &|_| String::new(),
    );
    row("holding torque within 2 %", &|v| {
        cell(&v["braking"]["holding_within_2pct"])
    });
    row("pressing-force RMS within 10 % of peak", &|v| {
        cell(&v["braking"]["force_rms_within_10pct"])
    });
    row("lock time within 10 ms", &|v| {
        cell(&v["braking"]["lock_within_10ms"])
    });
    row("all three", &|v| cell(&v["braking"]["all_three"]));
    row("median holding-torque error", &|v| {
        v["braking"]["holding_err_median_pct"]
            .as_f64()
            .map_or("—".into(), |e| format!("{e:.1} %"))
    });
    row("estimate marked trusted at the end", &|v| {
        cell(&v["braking"]["trusted"])
    });
    row("marked trusted, holding torque beyond 2 %", &|v| {
        cell(&v["braking"]["trusted_beyond_2pct"])
    });
    row("acceptance refused the unit", &|v| {
        v.get("commissioning_refused")
            .map_or("—".into(), Value::to_string)
    });
    row("nominal runs not driven (counted apart)", &|v| {
        v["not_driven"].to_string()
    });
    row("runs lost to a twin error (counted in no rate)", &|v| {
        v["errors"].to_string()
    });
}

/// Entry.
pub fn main(a: &FamilyArgs) -> Result<(), String> {
    let mut all = serde_json::Map::new();
    for seed in [TUNING_SEED, EVALUATION_SEED] {
        for commissioned in [false, true] {
            let key = format!(
                "{seed}_{}",
                if commissioned {
                    "commissioned"
                } else {
                    "uncommissioned"
                }
            );
            all.insert(key, campaign(seed, commissioned, a)?);
        }
    }
    if a.json {
        println!("{}", Value::Object(all));
        return Ok(());
    }
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# The monitor on the plant family, uncommissioned and commissioned\n\n\
         Written by `cargo xtask monitor-mc family --runs {} --fault-runs {}`; do not edit. \
         The plant family, its forms and ranges: model.md, \"The plant family\"; how a run is \
         drawn, judged and counted: monitor.md, \"How it is measured\".\n\n\
         - Each campaign: {} nominal draws and {} per fault kind of the family `plant`; each \
         draw's form is the twin's reading (`paper`, `physical`).\n\
         - *Uncommissioned*: the shipped `Config::default()`. *Commissioned*: each drawn unit \
         is first taken, healthy, through the acceptance procedure on the twin \
         (`host_tests::commission::ACCEPTANCE`: openings against 20.3 and 8 N·m, closings \
         with 20.3 and 5 N·m), its pack modelled from its build record as inspection measures it \
         (`host_tests::as_built`: the spring's preload within 2 %, the ramps' chamfer within \
         0.25°, the radii within 0.5 %; commissioning.md, \"The build record\"), and runs on \
         what commissioning identified; a unit \
         acceptance refuses runs uncommissioned, counted in the row so named.\n\
         - Cells: detected within 50 ms / manifested, or false alarms / nominal runs, with the \
         two-sided 95 % Clopper–Pearson interval (false alarms: its upper bound per run); after \
         a kind's rate, its runs in that form whose fault never manifested (*dormant*, \
         monitor.md, \"How it is measured\"), how many of those were found, by the drive's \
         own cycle (`brake_degraded` in the run) or by the functional test after it (on a unit \
         commissioned as a spring-only pack, the loaded and the uncoupled push), and after \
         how many that test ran (*tested*; functional-test.md); and, where any, those whose plant came apart \
         without the fault (*plant apart*, counted apart as a nominal run is; model.md, \
         \"The plant family\"). Functional tests failed: of the nominal runs the test \
         followed (one in ten), how many healthy units failed it, and how many \
         healthy units their acceptance test against the design rejected. A run the twin could \
         not finish (its error printed by the command) counts in no rate and in the last row. \
         Accuracy: the nominal reverse_load and forward_load runs where twin and monitor both \
         end locked, against issue 16's targets for a commissioned unit (holding torque within \
         2 %, pressing-force RMS within 10 % of its peak, lock time within 10 ms), compared as \
         in monitor.md; and how many of them ended with the estimate marked trusted, and \
         trusted while its holding torque was more than 2 % off (issue 16's item 2: an \
         estimate the monitor cannot stand behind is marked untrusted).\n\
         - Rows *with the drive's current command*: the same runs with the command in the \
         monitor's inputs (`Inputs::current_command_code`, monitor-design.md); every other row \
         is without it.\n\
         - Seed {TUNING_SEED} is where the plant family's thresholds were chosen; seed \
         {EVALUATION_SEED} was never tuned on. Commissioning's rules were not chosen on \
         either, but for one: its refusal of a relieved pack whose runs give `a·k` below 1.05 \
         was added after a draw of seed {EVALUATION_SEED} ended trusted 97 % off (its bound \
         is `Monitor::new`'s; decisions.md, \"A unit's build record sets its pack's preload \
         and geometry at commissioning\").",
        a.runs, a.fault_runs, a.runs, a.fault_runs
    );
    let get = |k: &str| all.get(k).cloned().unwrap_or(Value::Null);
    for (seed, what) in [(TUNING_SEED, "tuning"), (EVALUATION_SEED, "evaluation")] {
        let unc = get(&format!("{seed}_uncommissioned"));
        let com = get(&format!("{seed}_commissioned"));
        table(&mut s, seed, what, &unc, &com);
    }
    let path = workspace_root().join(PAGE);
    std::fs::write(&path, s).map_err(|e| format!("{}: {e}", path.display()))?;
    eprintln!("wrote {}", path.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small commissioned campaign: every form has its false alarms, detection, refusals and
    /// braking accuracy, and the table shows a row for each with a cell per form × commissioning.
    #[test]
    fn each_form_reports_alarms_detection_refusals_and_braking_accuracy() {
        let a = FamilyArgs {
            runs: 10,
            fault_runs: 0,
            json: true,
        };
        let unc = campaign(11, false, &a).expect("uncommissioned");
        let com = campaign(11, true, &a).expect("commissioned");
        for form in FORMS {
            assert!(unc[form].get("commissioning_refused").is_none());
            assert!(com[form]["commissioning_refused"].as_u64().is_some());
            let braking = &com[form]["braking"]["all_three"]["of"];
            assert!(braking[0].as_u64() <= braking[1].as_u64(), "{form}");
        }
        let mut s = String::new();
        table(&mut s, 11, "test", &unc, &com);
        let rows: Vec<&str> = s.lines().filter(|l| l.starts_with("| ")).collect();
        // Header, false alarms, functional tests, each kind, the two with the command, the
        // braking block (title and seven rows), refused, not driven, twin errors.
        assert_eq!(rows.len(), 1 + 2 + FAULT_KINDS.len() + 2 + 8 + 3, "{s}");
        for form in FORMS {
            for c in [&unc, &com] {
                assert_eq!(c[form]["errors"].as_u64(), Some(0), "{form}: {s}");
            }
        }
        for form in FORMS {
            let fa = &unc[form]["false_alarm_with_command"]["of"];
            assert_eq!(
                fa[1], unc[form]["false_alarm"]["of"][1],
                "{form}: the same runs"
            );
        }
        assert!(rows.iter().all(|r| r.matches(" | ").count() >= 4), "{s}");
    }
}
