//! The campaign's report from its runs' outcomes: rates with their 95 % Clopper–Pearson
//! intervals, the false-alarm bound per flight hour, the paper scenes' accuracy; as JSON, as a
//! text table and as `docs/monitor.md`. A pure function of the outcomes, so a merged campaign
//! reports byte for byte what the unsharded one does.

use crate::replay::twin_trace;
use host_tests::accuracy::{compare, run_monitor};
use host_tests::dormant::Verdict;
use host_tests::mc::{Context, Outcome, FAULT_KINDS};
use host_tests::stats::clopper_pearson;
use noback::monitor::Config;
use serde_json::{json, Value};

/// Target: every fault kind detected in at least this fraction of its runs.
pub const DETECTION_TARGET: f64 = 0.95;

/// Door cycles per flight hour the per-hour bound assumes: a hatch door opens and closes once
/// per turnaround, short-haul sectors last about an hour, doubled for maintenance cycles.
pub const DOOR_CYCLES_PER_FLIGHT_HOUR: f64 = 2.0;

/// Monte Carlo runs one door cycle exposes the monitor to: a cycle is ≈ 12 s of travel and
/// holds (open, hold, close under load, hold), a run ≈ 1.2 s of monitored operation on average.
pub const RUNS_PER_DOOR_CYCLE: f64 = 10.0;

/// What the report says about the campaign besides its outcomes.
pub struct Meta {
    pub seed: u64,
    pub runs: u64,
    pub fault_runs: u64,
    pub plant_family: String,
    pub config_digest: String,
    /// The monitor's behaviour digest, when the campaign recorded one.
    pub monitor_digest: Option<String>,
    pub config: Config,
    pub pre_roll_s: f64,
    /// The functional test followed one nominal run in this many (0: none).
    pub test_every: u64,
    /// Each draw's unit commissioned on its acceptance runs.
    pub commissioned: bool,
}

/// `k` of `n` as `{"rate", "ci95": [lo, hi], "of": [k, n]}` (rate and bounds null when `n` = 0).
pub fn rate(k: usize, n: usize) -> Value {
    let ci = clopper_pearson(k as u64, n as u64);
    json!({
        "rate": (n > 0).then(|| k as f64 / n as f64),
        "ci95": ci.map(|(lo, hi)| [lo, hi]),
        "of": [k, n],
    })
}

/// A dormant fault found: by the drive's own cycle (`brake_degraded` in the run) or by the
/// functional test after it.
fn is_found(o: &Outcome) -> bool {
    o.warned || o.test == Some(Verdict::Fail)
}

/// The functional test ran after the run (the unit was not rejected at acceptance).
fn is_tested(o: &Outcome) -> bool {
    matches!(o.test, Some(Verdict::Pass | Verdict::Fail))
}

/// The report of a campaign whose outcomes are `outcomes` (nominal first, then each fault kind
/// in [`FAULT_KINDS`] order, each by run index).
pub fn build(meta: &Meta, outcomes: &[Outcome]) -> Result<Value, String> {
    let errors: Vec<&str> = outcomes.iter().filter_map(|o| o.error.as_deref()).collect();
    let not_driven = outcomes
        .iter()
        .filter(|o| o.fault.is_none() && o.counted_apart())
        .count();
    let nominal: Vec<&Outcome> = outcomes.iter().filter(|o| o.counts_as_nominal()).collect();
    let false_alarm_runs = nominal.iter().filter(|o| o.false_flags > 0).count();
    let false_alarm = rate(false_alarm_runs, nominal.len());
    let false_alarm_runs_with_command = nominal
        .iter()
        .filter(|o| o.false_flags_with_command > 0)
        .count();
    let per_hour = false_alarm["ci95"][1]
        .as_f64()
        .map(|hi| (hi * RUNS_PER_DOOR_CYCLE * DOOR_CYCLES_PER_FLIGHT_HOUR).min(1.0));
    let mut rows = Vec::new();
    let mut all_ok = errors.is_empty() && false_alarm_runs == 0;
    for kind in FAULT_KINDS {
        let of_kind = || outcomes.iter().filter(|o| o.fault == Some(kind));
        let runs: Vec<&Outcome> = of_kind().filter(|o| o.counts()).collect();
        let manifested: Vec<&Outcome> = runs.iter().copied().filter(|o| o.manifested).collect();
        let mut latencies: Vec<f64> = manifested
            .iter()
            .filter(|o| o.detected())
            .filter_map(|o| o.latency_s)
            .collect();
        latencies.sort_by(f64::total_cmp);
        let hits = latencies.len();
        let hits_with_command = manifested
            .iter()
            .filter(|o| o.detected_with_command())
            .count();
        // No manifested run leaves the target unproven: it counts as not met, shown as "—".
        let detection = rate(hits, manifested.len());
        all_ok &= detection["rate"]
            .as_f64()
            .is_some_and(|r| r >= DETECTION_TARGET);
        // The same among the runs whose onset came after the monitor had settled.
        let settled: Vec<&Outcome> = manifested
            .iter()
            .copied()
            .filter(|o| o.context != Some(Context::Settling))
            .collect();
        let hits_settled = settled.iter().filter(|o| o.detected()).count();
        let by_context: Vec<_> = Context::ALL
            .iter()
            .map(|c| {
                let here = manifested.iter().filter(|o| o.context == Some(*c));
                json!({
                    "context": context_name(*c),
                    "manifested": here.clone().count(),
                    "missed": here.filter(|o| !o.detected()).count(),
                })
            })
            .collect();
        // Dormant: the fault never manifested in its scene; found by the drive's own cycle
        // (`brake_degraded` in the run) or by the functional test after it.
        let dormant: Vec<&Outcome> = runs.iter().copied().filter(|o| !o.manifested).collect();
        let tested: Vec<&Outcome> = dormant
            .iter()
            .copied()
            .filter(|o| o.warned || is_tested(o))
            .collect();
        let warned = dormant.iter().filter(|o| o.warned).count();
        let found = tested.iter().filter(|o| is_found(o)).count();
        rows.push(json!({
            "kind": format!("{kind:?}"),
            "runs": runs.len(),
            "not_driven": of_kind().filter(|o| o.counted_apart()).count(),
            "dormant": dormant.len(),
            "dormant_tested": tested.len(),
            "dormant_warned": warned,
            "dormant_found": found,
            "dormant_found_rate": rate(found, tested.len()),
            "dormant_rejected_at_acceptance": dormant.iter().filter(|o| o.test == Some(Verdict::Rejected)).count(),
            "manifested": manifested.len(),
            "detected_within_window": hits,
            "detection_rate": detection,
            "detected_with_command": hits_with_command,
            "detection_rate_with_command": rate(hits_with_command, manifested.len()),
            "manifested_after_settling": settled.len(),
            "detected_after_settling": hits_settled,
            "detection_rate_after_settling": rate(hits_settled, settled.len()),
            "by_context": by_context,
            "latency_median_s": latencies.get(hits / 2),
            "latency_max_s": latencies.last(),
            "false_alarms_before_onset": runs.iter().filter(|o| o.false_flags > 0).count(),
        }));
    }
    let mut report = json!({
        "seed": meta.seed,
        "runs": meta.runs,
        "fault_runs": meta.fault_runs,
        "plant_family": meta.plant_family,
        "config_digest": meta.config_digest,
        "monitor_digest": meta.monitor_digest,
        "power_on_settle_s": meta.config.thresholds.power_on_settle_s,
        "pre_roll_s": meta.pre_roll_s,
        "test_every": meta.test_every,
        "nominal_runs": nominal.len(),
        "false_alarm_runs": false_alarm_runs,
        "false_alarm_rate": false_alarm,
        "false_alarm_runs_with_command": false_alarm_runs_with_command,
        "false_alarm_rate_with_command": rate(false_alarm_runs_with_command, nominal.len()),
        "door_cycles_per_flight_hour": DOOR_CYCLES_PER_FLIGHT_HOUR,
        "runs_per_door_cycle": RUNS_PER_DOOR_CYCLE,
        "false_alarm_per_flight_hour_upper95": per_hour,
        "functional_tests_nominal": functional_tests(&nominal),
        "fault_kinds": rows,
        "twin_errors": errors,
        "not_driven_runs": not_driven,
        "paper_scenes": paper_scenes()?,
        "targets_met": all_ok,
    });
    if meta.commissioned {
        report["commissioning_refused_runs"] = json!(outcomes.iter().filter(|o| o.refused).count());
    }
    Ok(report)
}

/// The functional tests after nominal runs: tested in service, failed (a false fail), and
/// healthy units rejected at their acceptance test against the design.
fn functional_tests(nominal: &[&Outcome]) -> Value {
    let count = |v: Verdict| nominal.iter().filter(|o| o.test == Some(v)).count();
    let (pass, fail) = (count(Verdict::Pass), count(Verdict::Fail));
    json!({
        "tested": pass + fail,
        "failed": fail,
        "failed_rate": rate(fail, pass + fail),
        "rejected_at_acceptance": count(Verdict::Rejected),
    })
}

/// Accuracy on the paper's scenes (physical reading), for the same page.
fn paper_scenes() -> Result<Vec<Value>, String> {
    let mut scenes = Vec::new();
    for name in [
        "reverse_load",
        "forward_load",
        "continuous_closing",
        "hold",
        "drive",
    ] {
        let trace = twin_trace(name)?;
        let acc = compare(&trace, &run_monitor(&trace, Config::default())?);
        scenes.push(json!({
            "scene": name,
            "pressing_force_rmse_pct": acc.pressing_force_rmse_pct,
            "braking_torque_rmse_nm": acc.braking_torque_rmse_nm,
            "holding_torque_err_pct": acc.holding_torque_err_pct(),
            "lock_time_err_s": acc.lock_time_err_s().filter(|e| e.is_finite()),
            "flags": acc.flags.iter().map(|f| json!({"flag": f.flag, "t_s": f.t_s})).collect::<Vec<_>>(),
        }));
    }
    Ok(scenes)
}

/// A context's name in the report.
pub fn context_name(c: Context) -> &'static str {
    match c {
        Context::Settling => "onset while the monitor settles",
        Context::ShortDrive => "drive cut before the drive checks settle",
        Context::ContinuousClosing => "continuous closing",
        Context::Other => "elsewhere",
    }
}

/// The plant forms a report groups runs by (`host_tests::family::form`).
pub const FORMS: [&str; 2] = ["paper", "physical"];

/// Per plant form: its nominal runs' false-alarm rate and each fault kind's detection among
/// its manifested runs, with their intervals. `forms` is aligned with `outcomes`. A
/// `commissioned` campaign also counts the units acceptance refused.
pub fn by_form(outcomes: &[Outcome], forms: &[&str], commissioned: bool) -> Value {
    let mut out = serde_json::Map::new();
    for form in FORMS {
        let mine: Vec<&Outcome> = outcomes
            .iter()
            .zip(forms)
            .filter(|(_, f)| **f == form)
            .map(|(o, _)| o)
            .collect();
        let nominal: Vec<&&Outcome> = mine.iter().filter(|o| o.counts_as_nominal()).collect();
        let false_alarms = nominal.iter().filter(|o| o.false_flags > 0).count();
        let false_alarms_with_command = nominal
            .iter()
            .filter(|o| o.false_flags_with_command > 0)
            .count();
        let (mut detection, mut detection_with_command) =
            (serde_json::Map::new(), serde_json::Map::new());
        let (mut dormant, mut dormant_found, mut dormant_tested, mut apart) = (
            serde_json::Map::new(),
            serde_json::Map::new(),
            serde_json::Map::new(),
            serde_json::Map::new(),
        );
        for kind in FAULT_KINDS {
            let of_kind = || mine.iter().filter(|o| o.fault == Some(kind));
            let (manifested, never): (Vec<&&Outcome>, Vec<&&Outcome>) =
                of_kind().filter(|o| o.counts()).partition(|o| o.manifested);
            let hits = |d: fn(&Outcome) -> bool| manifested.iter().filter(|o| d(o)).count();
            let name = format!("{kind:?}");
            detection.insert(
                name.clone(),
                rate(hits(Outcome::detected), manifested.len()),
            );
            detection_with_command.insert(
                name.clone(),
                rate(hits(Outcome::detected_with_command), manifested.len()),
            );
            dormant.insert(name.clone(), json!(never.len()));
            let found_here = never.iter().filter(|o| is_found(o)).count();
            dormant_found.insert(name.clone(), json!(found_here));
            let tested_here = never.iter().filter(|o| is_tested(o)).count();
            dormant_tested.insert(name.clone(), json!(tested_here));
            apart.insert(name, json!(of_kind().filter(|o| o.counted_apart()).count()));
        }
        let mut v = json!({
            "false_alarm": rate(false_alarms, nominal.len()),
            "false_alarm_with_command": rate(false_alarms_with_command, nominal.len()),
            "detection_with_command": detection_with_command,
            "errors": mine.iter().filter(|o| o.error.is_some()).count(),
            "not_driven": mine.iter().filter(|o| o.fault.is_none() && o.counted_apart()).count(),
            "detection": detection,
            "dormant": dormant,
            "dormant_found": dormant_found,
            "dormant_functional_tested": dormant_tested,
            "not_driven_by_kind": apart,
            "functional_tests_nominal": functional_tests(&nominal.iter().map(|o| **o).collect::<Vec<_>>()),
        });
        if commissioned {
            v["commissioning_refused"] = json!(mine.iter().filter(|o| o.refused).count());
        }
        out.insert(form.into(), v);
    }
    Value::Object(out)
}

/// [`by_form`] as text, one block per form.
pub fn form_table(forms: &serde_json::Map<String, Value>) -> String {
    let of = |v: &Value| {
        let hi = v["ci95"][1]
            .as_f64()
            .map_or("—".into(), |h| format!("{h:.2e}"));
        format!("{}/{} (95 % upper {hi})", v["of"][0], v["of"][1])
    };
    let mut text = String::from("per plant form:\n");
    for (form, v) in forms {
        text.push_str(&format!(
            "  {form}: false alarms {}, twin errors {}, not driven {}\n",
            of(&v["false_alarm"]),
            v["errors"],
            v["not_driven"]
        ));
        if let Some(n) = v.get("commissioning_refused") {
            text.push_str(&format!(
                "    commissioning refused {n} (run uncommissioned)\n"
            ));
        }
        if let Some(d) = v["detection"].as_object() {
            for (kind, r) in d {
                let lo = r["ci95"][0]
                    .as_f64()
                    .map_or("—".into(), |l| format!("{l:.3}"));
                text.push_str(&format!(
                    "    {kind:<13} detected {}/{} (95 % lower {lo})\n",
                    r["of"][0], r["of"][1]
                ));
            }
        }
    }
    text
}
