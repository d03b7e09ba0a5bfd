//! A shard's result file and the merge of shards: each part records the campaign it belongs to
//! (seed, plant family, the monitor's configuration and behaviour digests, pre-roll, the
//! campaign's size) and the runs it covers; merge refuses parts that do not belong together,
//! overlap or leave gaps.

use host_tests::dormant::Verdict;
use host_tests::mc::{Context, Outcome, FAULT_KINDS};
use noback::digest::Fnv1a;
use noback::monitor::Config;
use serde::{Deserialize, Serialize};
use std::ops::Range;

/// The part files' format tag (`/2`: a fault run records `not_driven`).
pub const FORMAT: &str = "noback-monitor-mc-part/2";

/// What every part of one campaign shares.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct Campaign {
    pub seed: u64,
    pub plant_family: String,
    pub config_digest: String,
    /// The monitor's behaviour digest ([`host_tests::mc::behaviour_digest`]): what the
    /// configuration digest misses, a change of the monitor's code.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub monitor_digest: Option<String>,
    pub pre_roll_s: f64,
    /// The monitor's settling after a seeded power-on (s), the one setting an ablation changes.
    pub power_on_settle_s: f64,
    /// Nominal runs of the whole campaign.
    pub runs: u64,
    /// Runs per fault kind of the whole campaign.
    pub fault_runs: u64,
    /// The functional test's share of nominal runs (`host_tests::mc::Campaign::test_every`).
    #[serde(default)]
    pub test_every: u64,
    /// Each draw's unit commissioned on its acceptance runs (`--commissioned`).
    #[serde(default)]
    pub commissioned: bool,
}

/// One fault run's outcome.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct FaultRun {
    pub kind: String,
    pub index: u64,
    pub manifested: bool,
    pub latency_s: Option<f64>,
    /// With the drive's current command in the monitor's inputs.
    #[serde(default)]
    pub latency_with_command_s: Option<f64>,
    pub context: Option<String>,
    pub false_flags: usize,
    #[serde(default)]
    pub false_flags_with_command: usize,
    pub error: Option<String>,
    /// The draw's plant, run without its fault, came apart (`mc::not_driven`): counted apart.
    #[serde(default)]
    pub not_driven: bool,
    /// The functional test after the run: `rejected`, `pass` or `fail`; absent if not run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub test: Option<String>,
    /// `brake_degraded` rose after the onset.
    #[serde(default)]
    pub warned: bool,
    /// Acceptance refused the unit (a commissioned campaign): it ran uncommissioned.
    #[serde(default)]
    pub refused: bool,
}

/// A nominal run the twin could not run.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct RunError {
    pub index: u64,
    pub error: String,
}

/// One shard's result.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct Part {
    pub format: String,
    pub campaign: Campaign,
    /// `[K, N]` as given to `--shard` (for reading; the ranges are what merge checks).
    pub shard: [u64; 2],
    /// The nominal run indices covered, `[start, end)`.
    pub nominal: [u64; 2],
    /// The run indices covered of every fault kind, `[start, end)`.
    pub faults: [u64; 2],
    /// Nominal runs with any flag (not-driven runs apart).
    pub false_alarm_runs: Vec<u64>,
    /// The same with the drive's current command in the monitor's inputs.
    #[serde(default)]
    pub false_alarm_runs_with_command: Vec<u64>,
    /// Nominal runs whose plant did not move its output while driven (`mc::not_driven`).
    #[serde(default)]
    pub not_driven_runs: Vec<u64>,
    /// Nominal runs whose unit acceptance refused (a commissioned campaign).
    #[serde(default)]
    pub refused_runs: Vec<u64>,
    pub nominal_errors: Vec<RunError>,
    /// The nominal runs the functional test followed, each `(index, verdict)`.
    #[serde(default)]
    pub nominal_tests: Vec<(u64, String)>,
    /// Every fault run, kind by kind in `FAULT_KINDS` order, each by index.
    pub fault_runs: Vec<FaultRun>,
}

/// The digest of the monitor's configuration (FNV-1a over the bytes of its `Debug` form, which
/// prints every field and every float exactly).
pub fn config_digest(config: &Config) -> String {
    let mut d = Fnv1a::new();
    for b in format!("{config:?}").bytes() {
        d.push(u32::from(b));
    }
    format!("{:#010x}", d.value())
}

/// The indices shard `k` of `n` covers out of `total`: the `k`-th of `n` near-equal slices.
pub fn slice(total: u64, k: u64, n: u64) -> Range<u64> {
    let at = |i: u64| (u128::from(total) * u128::from(i) / u128::from(n.max(1))) as u64;
    at(k)..at(k + 1)
}

fn verdict_tag(v: Verdict) -> &'static str {
    match v {
        Verdict::Rejected => "rejected",
        Verdict::Pass => "pass",
        Verdict::Fail => "fail",
    }
}

fn verdict_of(tag: &str) -> Result<Verdict, String> {
    [Verdict::Rejected, Verdict::Pass, Verdict::Fail]
        .into_iter()
        .find(|v| verdict_tag(*v) == tag)
        .ok_or_else(|| format!("unknown functional-test verdict `{tag}`"))
}

fn context_tag(c: Context) -> &'static str {
    match c {
        Context::Settling => "settling",
        Context::ShortDrive => "short_drive",
        Context::ContinuousClosing => "continuous_closing",
        Context::Other => "other",
    }
}

impl Part {
    /// The part of `outcomes`: the nominal runs `nominal` then, for each fault kind, the runs
    /// `faults`, in that order.
    pub fn new(
        campaign: Campaign,
        shard: [u64; 2],
        nominal: Range<u64>,
        faults: Range<u64>,
        outcomes: &[Outcome],
    ) -> Part {
        let (nom, flt) = outcomes.split_at((nominal.end - nominal.start) as usize);
        let fault_indices = FAULT_KINDS.iter().flat_map(|_| faults.clone());
        let nominal_where = |keep: fn(&Outcome) -> bool| -> Vec<u64> {
            nominal
                .clone()
                .zip(nom)
                .filter(|(_, o)| keep(o))
                .map(|(i, _)| i)
                .collect()
        };
        Part {
            format: FORMAT.into(),
            campaign,
            shard,
            nominal: [nominal.start, nominal.end],
            faults: [faults.start, faults.end],
            false_alarm_runs: nominal_where(|o| o.counts_as_nominal() && o.false_flags > 0),
            false_alarm_runs_with_command: nominal_where(|o| {
                o.counts_as_nominal() && o.false_flags_with_command > 0
            }),
            not_driven_runs: nominal_where(Outcome::counted_apart),
            refused_runs: nominal_where(|o| o.refused),
            nominal_errors: nominal
                .clone()
                .zip(nom)
                .filter_map(|(index, o)| {
                    let error = o.error.clone()?;
                    Some(RunError { index, error })
                })
                .collect(),
            nominal_tests: nominal
                .zip(nom)
                .filter_map(|(index, o)| Some((index, verdict_tag(o.test?).to_string())))
                .collect(),
            fault_runs: fault_indices
                .zip(flt)
                .map(|(index, o)| FaultRun {
                    kind: o.fault.map(|k| format!("{k:?}")).unwrap_or_default(),
                    index,
                    manifested: o.manifested,
                    latency_s: o.latency_s,
                    latency_with_command_s: o.latency_with_command_s,
                    context: o.context.map(|c| context_tag(c).into()),
                    false_flags: o.false_flags,
                    false_flags_with_command: o.false_flags_with_command,
                    error: o.error.clone(),
                    not_driven: o.not_driven,
                    test: o.test.map(|v| verdict_tag(v).into()),
                    warned: o.warned,
                    refused: o.refused,
                })
                .collect(),
        }
    }
}

fn outcome_of(r: &FaultRun) -> Result<Outcome, String> {
    let fault = FAULT_KINDS
        .iter()
        .copied()
        .find(|k| format!("{k:?}") == r.kind)
        .ok_or_else(|| format!("unknown fault kind `{}`", r.kind))?;
    let context = match r.context.as_deref() {
        None => None,
        Some(tag) => Some(
            Context::ALL
                .into_iter()
                .find(|c| context_tag(*c) == tag)
                .ok_or_else(|| format!("unknown context `{tag}`"))?,
        ),
    };
    Ok(Outcome {
        fault: Some(fault),
        latency_s: r.latency_s,
        latency_with_command_s: r.latency_with_command_s,
        manifested: r.manifested,
        context,
        false_flags: r.false_flags,
        false_flags_with_command: r.false_flags_with_command,
        error: r.error.clone(),
        not_driven: r.not_driven,
        test: r.test.as_deref().map(verdict_of).transpose()?,
        warned: r.warned,
        refused: r.refused,
        braking: None,
    })
}

/// Checks that `ranges` (name, `[start, end)`) tile `0..total` exactly, or with `prefix` some
/// `0..end` with end ≤ total; returns the end.
fn tile(
    what: &str,
    ranges: &mut [(&str, [u64; 2])],
    total: u64,
    prefix: bool,
) -> Result<u64, String> {
    ranges.sort_by_key(|(_, r)| (r[0], r[1]));
    let mut end = 0;
    let mut last = "";
    for (name, r) in ranges.iter() {
        if r[0] > r[1] || r[1] > total {
            return Err(format!(
                "{name}: {what} runs {}..{} are not within 0..{total}",
                r[0], r[1]
            ));
        }
        if r[0] < end {
            return Err(format!(
                "{name}: {what} runs {}..{} overlap {last}'s",
                r[0], r[1]
            ));
        }
        if r[0] > end {
            return Err(format!(
                "{name}: no part holds the {what} runs {end}..{} before it",
                r[0]
            ));
        }
        end = r[1];
        last = name;
    }
    if end < total && !prefix {
        return Err(format!(
            "{last}: no part holds the {what} runs {end}..{total} after it"
        ));
    }
    Ok(end)
}

/// Checks one part against the campaign and its own ranges.
fn check(name: &str, p: &Part, first: &(String, Campaign)) -> Result<(), String> {
    if p.format != FORMAT {
        return Err(format!("{name}: format `{}`, not `{FORMAT}`", p.format));
    }
    let c = &p.campaign;
    let f = &first.1;
    let differs = |what: &str, a: String, b: String| {
        Err(format!("{name}: {what} {a} differs from {}'s {b}", first.0))
    };
    if c.seed != f.seed {
        return differs("seed", c.seed.to_string(), f.seed.to_string());
    }
    if c.plant_family != f.plant_family {
        return differs(
            "plant family",
            c.plant_family.clone(),
            f.plant_family.clone(),
        );
    }
    if c.config_digest != f.config_digest {
        return differs(
            "configuration digest",
            c.config_digest.clone(),
            f.config_digest.clone(),
        );
    }
    if c.monitor_digest != f.monitor_digest {
        let text = |d: &Option<String>| d.clone().unwrap_or_else(|| "none".into());
        return differs(
            "monitor digest",
            text(&c.monitor_digest),
            text(&f.monitor_digest),
        );
    }
    if c.power_on_settle_s.to_bits() != f.power_on_settle_s.to_bits() {
        let (a, b) = (c.power_on_settle_s, f.power_on_settle_s);
        return differs("power-on settling", a.to_string(), b.to_string());
    }
    if c.pre_roll_s.to_bits() != f.pre_roll_s.to_bits() {
        return differs(
            "pre-roll",
            c.pre_roll_s.to_string(),
            f.pre_roll_s.to_string(),
        );
    }
    if c.commissioned != f.commissioned {
        return differs(
            "commissioning",
            c.commissioned.to_string(),
            f.commissioned.to_string(),
        );
    }
    if c.test_every != f.test_every {
        return differs(
            "functional-test share",
            c.test_every.to_string(),
            f.test_every.to_string(),
        );
    }
    if (c.runs, c.fault_runs) != (f.runs, f.fault_runs) {
        return differs(
            "campaign size",
            format!("{}+{}", c.runs, c.fault_runs),
            format!("{}+{}", f.runs, f.fault_runs),
        );
    }
    let in_nominal = |i: &u64| (p.nominal[0]..p.nominal[1]).contains(i);
    if !p.false_alarm_runs.iter().all(in_nominal)
        || !p.not_driven_runs.iter().all(in_nominal)
        || !p.refused_runs.iter().all(in_nominal)
        || !p.nominal_errors.iter().all(|e| in_nominal(&e.index))
        || !p.nominal_tests.iter().all(|(i, _)| in_nominal(i))
    {
        return Err(format!("{name}: names a nominal run outside its range"));
    }
    let expected = FAULT_KINDS
        .iter()
        .flat_map(|k| (p.faults[0]..p.faults[1]).map(move |i| (format!("{k:?}"), i)));
    let listed = p.fault_runs.iter().map(|r| (r.kind.clone(), r.index));
    if p.faults[0] > p.faults[1] || !expected.eq(listed) {
        return Err(format!(
            "{name}: its fault runs are not its range's, kind by kind"
        ));
    }
    Ok(())
}

/// The campaign and its outcomes (nominal, then each fault kind, by index) from `parts`
/// (name, part); an error names the part at fault. With `prefix`, parts that cover only the
/// first runs of their campaign give the campaign of that size (a run's draws do not depend
/// on the campaign's size: the same outcomes as the smaller campaign run whole).
pub fn merge(parts: &[(String, Part)], prefix: bool) -> Result<(Campaign, Vec<Outcome>), String> {
    let Some((first_name, first)) = parts.first() else {
        return Err("merge needs at least one part".into());
    };
    let reference = (first_name.clone(), first.campaign.clone());
    for (name, p) in parts {
        check(name, p, &reference)?;
    }
    let mut c = reference.1;
    let mut ranges: Vec<_> = parts.iter().map(|(n, p)| (n.as_str(), p.nominal)).collect();
    c.runs = tile("nominal", &mut ranges, c.runs, prefix)?;
    let mut ranges: Vec<_> = parts.iter().map(|(n, p)| (n.as_str(), p.faults)).collect();
    c.fault_runs = tile("fault", &mut ranges, c.fault_runs, prefix)?;

    let mut nominal = vec![Outcome::quiet(None); c.runs as usize];
    let mut faults: Vec<Option<Outcome>> = vec![None; FAULT_KINDS.len() * c.fault_runs as usize];
    for (name, p) in parts {
        for &i in &p.false_alarm_runs {
            nominal[i as usize].false_flags = 1;
        }
        for &i in &p.false_alarm_runs_with_command {
            nominal[i as usize].false_flags_with_command = 1;
        }
        for &i in &p.not_driven_runs {
            nominal[i as usize].not_driven = true;
        }
        for &i in &p.refused_runs {
            nominal[i as usize].refused = true;
        }
        for e in &p.nominal_errors {
            nominal[e.index as usize].error = Some(e.error.clone());
        }
        for (i, v) in &p.nominal_tests {
            nominal[*i as usize].test = Some(verdict_of(v).map_err(|e| format!("{name}: {e}"))?);
        }
        for r in &p.fault_runs {
            let o = outcome_of(r).map_err(|e| format!("{name}: {e}"))?;
            let k = FAULT_KINDS
                .iter()
                .position(|k| Some(*k) == o.fault)
                .unwrap_or(0);
            faults[k * c.fault_runs as usize + r.index as usize] = Some(o);
        }
    }
    nominal.extend(faults.into_iter().flatten());
    Ok((c, nominal))
}
