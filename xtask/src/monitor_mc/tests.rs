//! A campaign cut into 2 or 3 shards, each run on a different number of threads and merged in
//! any order, gives the unsharded campaign's report and page byte for byte; merge refuses parts
//! that do not belong together or are not of this build's monitor; the per-form report counts
//! each kind's dormant runs; the committed certification campaign is of this build's
//! configuration and monitor.

use super::*;

const RUNS: u64 = 7;
const FAULT_RUNS: u64 = 2;

fn campaign() -> (Setup, Campaign) {
    let setup = Setup::default();
    (
        setup,
        campaign_of(&setup, Family::PhysicalDefault, 5, RUNS, FAULT_RUNS),
    )
}

/// A part as a merge reads it: through its file's text.
fn through_text(p: &Part) -> Part {
    serde_json::from_str(&serde_json::to_string(p).unwrap()).unwrap()
}

fn report(parts: &[(String, Part)]) -> (serde_json::Value, String) {
    let (c, outcomes) = part::merge(parts, false).expect("merge");
    report_of(&c, &outcomes, Setup::default()).expect("report")
}

#[test]
fn shards_merge_to_the_unsharded_campaign_byte_for_byte() {
    let (setup, c) = campaign();
    let whole = through_text(&run_part(&setup, c.clone(), 0, 1, 2));
    let (json, page) = report(&[("whole".into(), whole)]);
    assert_eq!(json["nominal_runs"], RUNS);
    assert!(json["false_alarm_rate"]["ci95"][1].as_f64().is_some());
    for n in [2, 3] {
        let mut parts: Vec<(String, Part)> = (0..n)
            .map(|k| {
                let p = run_part(&setup, c.clone(), k, n, 1 + k as usize);
                (format!("part-{k}"), through_text(&p))
            })
            .collect();
        parts.reverse();
        let (j, p) = report(&parts);
        assert_eq!(j.to_string(), json.to_string(), "{n} shards");
        assert_eq!(p, page, "{n} shards");
    }
}

#[test]
fn a_plant_family_campaign_reports_each_form_and_merges_exactly() {
    let setup = Setup::for_family(Family::Plant);
    let c = campaign_of(&setup, Family::Plant, 11, 12, 0);
    let whole = through_text(&run_part(&setup, c.clone(), 0, 1, 2));
    let (json, _) = report(&[("whole".into(), whole)]);
    let forms = json["by_form"]
        .as_object()
        .expect("a plant campaign reports per form");
    let nominal: u64 = forms
        .values()
        .map(|f| f["false_alarm"]["of"][1].as_u64().unwrap() + f["not_driven"].as_u64().unwrap())
        .sum();
    assert_eq!(nominal, 12, "every nominal run falls in one form");
    assert!(forms
        .values()
        .all(|f| f["false_alarm"]["of"][1].as_u64() > Some(0)));
    let parts: Vec<(String, Part)> = (0..2)
        .map(|k| {
            (
                format!("part-{k}"),
                through_text(&run_part(&setup, c.clone(), k, 2, 1)),
            )
        })
        .collect();
    assert_eq!(report(&parts).0.to_string(), json.to_string());
    // The default family's report has no per-form block.
    let (setup, d) = campaign();
    let plain = through_text(&run_part(&setup, d, 0, 1, 2));
    assert!(report(&[("whole".into(), plain)])
        .0
        .get("by_form")
        .is_none());
}

/// Every unit commissioned on its own acceptance runs: the shards still merge exactly, each
/// form counts the units acceptance refused, and the runs differ from uncommissioned ones only
/// where the configuration does.
#[test]
fn a_commissioned_campaign_counts_refusals_and_merges_exactly() {
    let mut setup = Setup::for_family(Family::Plant);
    setup.commissioned = true;
    let c = campaign_of(&setup, Family::Plant, 11, 8, 1);
    assert!(c.commissioned);
    let whole = through_text(&run_part(&setup, c.clone(), 0, 1, 2));
    let (json, _) = report(&[("whole".into(), whole)]);
    let forms = json["by_form"].as_object().expect("per form");
    assert!(forms
        .values()
        .all(|f| f["commissioning_refused"].as_u64().is_some()));
    assert!(json["commissioning_refused_runs"].as_u64().is_some());
    let parts: Vec<(String, Part)> = (0..2)
        .map(|k| {
            let p = run_part(&setup, c.clone(), k, 2, 1);
            (format!("part-{k}"), through_text(&p))
        })
        .collect();
    assert_eq!(report(&parts).0.to_string(), json.to_string());
}

#[test]
fn merge_refuses_parts_that_do_not_belong_together() {
    let (setup, c) = campaign();
    // Parts of no runs at all: the checks are on the records, not the outcomes.
    let empty = |c: &Campaign, nominal: std::ops::Range<u64>, faults: std::ops::Range<u64>| {
        let n = (nominal.end - nominal.start) as usize;
        let f = (faults.end - faults.start) as usize * FAULT_KINDS.len();
        let outcomes: Vec<_> = (0..n)
            .map(|_| None)
            .chain((0..f).map(|i| Some(FAULT_KINDS[i / (f / FAULT_KINDS.len())])))
            .map(host_tests::mc::Outcome::quiet)
            .collect();
        Part::new(c.clone(), [0, 1], nominal, faults, &outcomes)
    };
    let a = empty(&c, 0..4, 0..1);
    let b = empty(&c, 4..RUNS, 1..FAULT_RUNS);
    assert!(part::merge(&[("a".into(), a.clone()), ("b".into(), b.clone())], false).is_ok());
    let mut other = c.clone();
    other.seed = 6;
    let refused = |parts: &[(String, Part)], names: &str| {
        let e = part::merge(parts, false).expect_err("merged");
        assert!(e.starts_with(names), "{e}");
    };
    refused(
        &[
            ("a".into(), a.clone()),
            ("c".into(), empty(&other, 4..RUNS, 1..FAULT_RUNS)),
        ],
        "c: seed",
    );
    let mut family = c.clone();
    family.plant_family = "other".into();
    refused(
        &[
            ("a".into(), a.clone()),
            ("d".into(), empty(&family, 4..RUNS, 1..FAULT_RUNS)),
        ],
        "d: plant family",
    );
    let mut commissioned = c.clone();
    commissioned.commissioned = true;
    refused(
        &[
            ("a".into(), a.clone()),
            ("h".into(), empty(&commissioned, 4..RUNS, 1..FAULT_RUNS)),
        ],
        "h: commissioning",
    );
    let mut digest = c.clone();
    digest.config_digest = part::config_digest(&{
        let mut s = setup;
        s.config.thresholds.power_on_settle_s += 0.01;
        s.config
    });
    refused(
        &[
            ("a".into(), a.clone()),
            ("e".into(), empty(&digest, 4..RUNS, 1..FAULT_RUNS)),
        ],
        "e: configuration digest",
    );
    let mut code = c.clone();
    code.monitor_digest = Some("0x00000000".into());
    refused(
        &[
            ("a".into(), a.clone()),
            ("m".into(), empty(&code, 4..RUNS, 1..FAULT_RUNS)),
        ],
        "m: monitor digest",
    );
    refused(
        &[
            ("a".into(), a.clone()),
            ("f".into(), empty(&c, 3..RUNS, 1..FAULT_RUNS)),
        ],
        "f: nominal runs 3..7 overlap",
    );
    refused(
        &[
            ("a".into(), a.clone()),
            ("g".into(), empty(&c, 5..RUNS, 1..FAULT_RUNS)),
        ],
        "g: no part holds the nominal runs 4..5",
    );
    refused(
        &[("a".into(), a.clone())],
        "a: no part holds the nominal runs 4..7 after it",
    );
    assert_eq!(
        part::merge(&[("a".into(), a)], true).map(|(c, _)| c.runs),
        Ok(4)
    );
}

#[test]
fn merge_refuses_a_part_not_of_this_builds_monitor() {
    let (setup, mut c) = campaign();
    c.monitor_digest = Some(monitor_digest(&setup, &c));
    let part = |c: &Campaign| {
        let outcomes = vec![host_tests::mc::Outcome::quiet(None); RUNS as usize];
        vec![(
            "p".to_string(),
            Part::new(c.clone(), [0, 1], 0..RUNS, 0..0, &outcomes),
        )]
    };
    let refusal = |c: &Campaign| match setup_of_this_build(&part(c), setup) {
        Ok(_) => String::new(),
        Err(Fail::Input(e) | Fail::Run(e)) => e,
    };
    assert_eq!(refusal(&c), "");
    let mut altered = c.clone();
    altered.monitor_digest = Some("0x00000000".into());
    assert!(refusal(&altered).starts_with("p: monitor digest 0x00000000 is not this build's"));
    altered.monitor_digest = None;
    assert!(refusal(&altered).starts_with("p: no monitor digest (a part of an earlier build)"));
    altered = c.clone();
    altered.config_digest = "0x00000000".into();
    assert!(refusal(&altered).starts_with("p: configuration digest 0x00000000 is not this build's"));
}

#[test]
fn a_fault_run_that_never_manifests_counts_as_dormant_in_its_form_only_and_a_plant_apart_in_none() {
    use host_tests::mc::Outcome;
    use noback_twin::fault::FaultKind;
    let kind = Some(FaultKind::PackWear);
    let manifested = Outcome {
        manifested: true,
        ..Outcome::quiet(kind)
    };
    let failed = Outcome {
        error: Some("twin".into()),
        ..Outcome::quiet(kind)
    };
    // Draws whose plant came apart without the fault: neither detected, missed nor dormant.
    let apart = |manifested| Outcome {
        manifested,
        not_driven: true,
        ..Outcome::quiet(kind)
    };
    let found = Outcome {
        warned: true,
        ..Outcome::quiet(kind)
    };
    let outcomes = [
        manifested,
        found,
        failed,
        apart(true),
        apart(false),
        Outcome {
            test: Some(host_tests::dormant::Verdict::Pass),
            ..Outcome::quiet(kind)
        },
    ];
    let forms = ["paper", "paper", "paper", "paper", "paper", "physical"];
    let v = super::report::by_form(&outcomes, &forms, false);
    assert_eq!(v["paper"]["dormant"]["PackWear"], 1);
    assert_eq!(
        v["paper"]["detection"]["PackWear"]["of"],
        serde_json::json!([0, 1])
    );
    assert_eq!(v["paper"]["not_driven_by_kind"]["PackWear"], 2);
    assert_eq!(v["paper"]["not_driven"], 0, "the nominal runs' count");
    assert_eq!(v["physical"]["dormant"]["PackWear"], 1);
    assert_eq!(v["physical"]["dormant"]["Drag"], 0);
    // Found: by the run's own `brake_degraded` or the test; tested: the test ran.
    assert_eq!(v["paper"]["dormant_found"]["PackWear"], 1);
    assert_eq!(v["paper"]["dormant_functional_tested"]["PackWear"], 0);
    assert_eq!(v["physical"]["dormant_found"]["PackWear"], 0);
    assert_eq!(v["physical"]["dormant_functional_tested"]["PackWear"], 1);
}

#[test]
fn healthy_units_the_functional_test_failed_are_counted_per_form() {
    use host_tests::dormant::Verdict;
    use host_tests::mc::Outcome;
    let nominal = |test| Outcome {
        test,
        ..Outcome::quiet(None)
    };
    let outcomes = [
        nominal(Some(Verdict::Fail)),
        nominal(Some(Verdict::Pass)),
        nominal(Some(Verdict::Rejected)),
        nominal(None),
        nominal(Some(Verdict::Pass)),
    ];
    let forms = ["paper", "paper", "paper", "paper", "physical"];
    let v = super::report::by_form(&outcomes, &forms, false);
    let paper = &v["paper"]["functional_tests_nominal"];
    assert_eq!(paper["tested"], 2);
    assert_eq!(paper["failed"], 1);
    assert_eq!(paper["rejected_at_acceptance"], 1);
    assert_eq!(v["physical"]["functional_tests_nominal"]["failed"], 0);
    assert_eq!(v["physical"]["functional_tests_nominal"]["tested"], 1);
}

#[test]
fn a_fault_run_on_a_plant_apart_stays_apart_through_a_merge() {
    use host_tests::mc::Outcome;
    let (_, c) = campaign();
    let c = Campaign {
        runs: 0,
        fault_runs: 1,
        ..c
    };
    let apart = |k| k == FAULT_KINDS[2];
    let outcomes = FAULT_KINDS.map(|k| Outcome {
        not_driven: apart(k),
        ..Outcome::quiet(Some(k))
    });
    let p = through_text(&Part::new(c, [0, 1], 0..0, 0..1, &outcomes));
    let (_, merged) = part::merge(&[("p".into(), p)], false).expect("merge");
    let marked: Vec<_> = merged.iter().map(|o| o.not_driven).collect();
    assert_eq!(marked, FAULT_KINDS.map(apart).to_vec());
}

/// The committed certification campaign was run on the configuration this build ships for its
/// family and on this build's monitor: a change to `Config` (its `Debug` text), or to what the
/// monitor does on the campaign's first draws, without a rerun of the campaign fails here; so
/// does a record of another campaign than the plan's (seed, family, test share).
#[test]
fn the_committed_campaign_is_of_this_builds_monitor() {
    let path = crate::shell::workspace_root().join(page::CAMPAIGN_RECORD);
    let text = std::fs::read_to_string(&path).expect("the committed campaign record");
    let c: serde_json::Value = serde_json::from_str(&text).expect("campaign JSON");
    let family = c["plant_family"]
        .as_str()
        .and_then(Family::parse)
        .expect("its plant family");
    assert_eq!(
        c["config_digest"].as_str(),
        Some(part::config_digest(&family.config()).as_str()),
        "rerun the campaign (docs/monitor.md, \"Certification-scale nominal campaign\")"
    );
    assert!(
        c["measured_on"].is_null(),
        "the record names an earlier monitor"
    );
    let plan = &page::CAMPAIGN_PLAN;
    assert_eq!(
        (
            c["seed"].as_u64(),
            c["test_every"].as_u64(),
            c["plant_family"].as_str()
        ),
        (Some(plan.seed), Some(plan.test_every), Some(plan.family)),
        "the record is not of the planned campaign (page::CAMPAIGN_PLAN)"
    );
    let mut setup = Setup::for_family(family);
    setup.pre_roll_s = c["pre_roll_s"].as_f64().expect("pre-roll");
    setup.config.thresholds.power_on_settle_s = c["power_on_settle_s"].as_f64().expect("settling");
    setup.commissioned = !c["commissioning_refused_runs"].is_null();
    let seed = c["seed"].as_u64().expect("seed");
    let runs = c["runs"].as_u64().expect("runs");
    let campaign = campaign_of(&setup, family, seed, runs, 0);
    assert_eq!(
        c["monitor_digest"].as_str(),
        Some(monitor_digest(&setup, &campaign).as_str()),
        "the monitor's code changed since the campaign: rerun it"
    );
}
