//! `cargo xtask monitor-mc` — detection measured by Monte Carlo (`host_tests::mc`) on every
//! core, with progress; writes `docs/monitor.md`. A campaign can be cut into shards
//! (`--shard K/N --out part-K.json`) and merged (`monitor-mc merge part-*.json`) with the same
//! bytes as the whole; `slurm/` runs the shards as a job array.

mod family_page;
mod page;
mod part;
mod report;
mod throughput;

use crate::shell::workspace_root;
use clap::{Args, Parser, Subcommand};
use host_tests::family::Family;
use host_tests::mc::{
    behaviour_digest, draw_in, draw_legacy, run_all, Campaign as Setup, Draw, BEHAVIOUR_RUNS,
    FAULT_KINDS,
};
use part::{Campaign, Part};
use std::io::Write as _;
use std::ops::Range;
use std::path::{Path, PathBuf};

#[derive(Parser, Debug)]
#[command(
    name = "cargo xtask monitor-mc",
    about = "Detection by Monte Carlo; writes docs/monitor.md",
    args_conflicts_with_subcommands = true
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    run: RunArgs,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Merge part files into the campaign's report (as the unsharded command would give it).
    Merge(MergeArgs),
    /// Runs per second per core; writes the benchmark page docs/results/mc-throughput.md.
    Throughput(throughput::ThroughputArgs),
    /// The plant family at a tuning and an evaluation seed, uncommissioned and commissioned,
    /// per form; writes docs/monitor-family.md.
    Family(family_page::FamilyArgs),
}

#[derive(Args, Debug)]
struct Output {
    /// Print the report as one JSON object.
    #[arg(long)]
    json: bool,
    /// Do not write docs/monitor.md.
    #[arg(long)]
    no_doc: bool,
}

#[derive(Args, Debug)]
struct RunArgs {
    /// Nominal runs.
    #[arg(long, default_value_t = 1000)]
    runs: u64,
    /// Runs per fault kind.
    #[arg(long, default_value_t = 100)]
    fault_runs: u64,
    /// The campaign's seed.
    #[arg(long, default_value_t = 2026)]
    seed: u64,
    #[command(flatten)]
    output: Output,
    /// Ablation: the monitor's settling after a seeded power-on (s); the page is not written.
    #[arg(long, value_parser = seconds)]
    power_on_settle: Option<f64>,
    /// Ablation: how long the twin runs before the monitor is powered on (s); no page.
    #[arg(long, value_parser = seconds)]
    pre_roll: Option<f64>,
    /// Run only shard K of N (0 ≤ K < N) and write it as a part file (needs --out).
    #[arg(long, value_parser = shard, value_name = "K/N", requires = "out")]
    shard: Option<(u64, u64)>,
    /// Write the runs' part file here (a shard's, or the whole campaign's).
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
    /// Draw as the campaigns before sharding did (`host_tests::mc::draw_legacy`), to compare
    /// figures across the change of random stream; the page is not written.
    #[arg(long)]
    legacy_draws: bool,
    /// The functional test follows one nominal run in K (and every run whose fault stayed
    /// dormant); 0: no test (default: `host_tests::mc::TEST_EVERY`).
    #[arg(long, value_name = "K")]
    test_every: Option<u64>,
    /// Worker threads (default: the machine's cores).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=1024))]
    threads: Option<u64>,
    /// The plants drawn: `physical-default` (the physical reading, its open items at their
    /// defaults) or `plant` (both readings and every open quantity over its range,
    /// docs/model.md), reported per form; the page is written for the default family only.
    #[arg(long, value_parser = family, default_value = "physical-default", value_name = "physical-default|plant")]
    family: Family,
    /// Commission each draw's unit on the acceptance procedure of its healthy plant and its
    /// build record as inspection measures it (docs/commissioning.md) and run it on that configuration (uncommissioned where
    /// acceptance refuses it, counted); the page is not written.
    #[arg(long)]
    commissioned: bool,
}

fn family(v: &str) -> Result<Family, String> {
    Family::parse(v).ok_or_else(|| "expected physical-default or plant".into())
}

#[derive(Args, Debug)]
struct MergeArgs {
    /// The part files (`--shard K/N --out FILE`), in any order.
    #[arg(required = true, value_name = "PART")]
    parts: Vec<PathBuf>,
    #[command(flatten)]
    output: Output,
    /// Also write the merged report (JSON) here.
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
    /// Accept parts that cover only the first runs of their campaign (shards lost or not yet
    /// run): the report is that of the smaller campaign, as if run whole.
    #[arg(long)]
    prefix: bool,
}

fn seconds(v: &str) -> Result<f64, String> {
    v.parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v >= 0.0)
        .ok_or_else(|| "needs a time in seconds, ≥ 0".into())
}

fn shard(v: &str) -> Result<(u64, u64), String> {
    let (k, n) = v.split_once('/').ok_or("needs K/N")?;
    let (k, n) = (k.parse::<u64>(), n.parse::<u64>());
    match (k, n) {
        (Ok(k), Ok(n)) if k < n => Ok((k, n)),
        _ => Err("needs K/N with 0 ≤ K < N".into()),
    }
}

/// Bad input (exit 2, one line naming it) or a failure while running.
enum Fail {
    Input(String),
    Run(String),
}

impl From<String> for Fail {
    fn from(e: String) -> Self {
        Fail::Run(e)
    }
}

/// Entry.
pub fn main(args: &[String]) -> Result<i32, String> {
    let argv = std::iter::once("monitor-mc".to_string()).chain(args.iter().cloned());
    let cli = match Cli::try_parse_from(argv) {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            print!("{e}");
            return Ok(0);
        }
        Err(e) => {
            // One line: clap's first, with the item it lists below a trailing colon.
            let text = e.to_string();
            let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
            let mut line = lines.next().unwrap_or("bad arguments").to_string();
            if line.ends_with(':') {
                line = format!("{line} {}", lines.next().unwrap_or(""));
            }
            eprintln!("monitor-mc: {}", line.trim_start_matches("error: "));
            return Ok(2);
        }
    };
    let result = match cli.command {
        Some(Command::Merge(m)) => merge_main(&m),
        Some(Command::Throughput(t)) => throughput::main(&t).map_err(Fail::Run),
        Some(Command::Family(f)) => family_page::main(&f).map_err(Fail::Run),
        None => run_main(&cli.run),
    };
    match result {
        Ok(()) => Ok(0),
        Err(Fail::Input(e)) => {
            eprintln!("monitor-mc: {e}");
            Ok(2)
        }
        Err(Fail::Run(e)) => Err(e),
    }
}

fn threads(given: Option<u64>) -> usize {
    given.map_or_else(
        || std::thread::available_parallelism().map_or(2, |n| n.get()),
        |t| t as usize,
    )
}

/// The plant family of [`RunArgs::legacy_draws`]: the default family, drawn by the old stream.
const LEGACY_FAMILY: &str = "physical-default, pre-sharding stream";

/// Runs shard `k` of `n` of a campaign and returns its part.
pub fn run_part(setup: &Setup, campaign: Campaign, k: u64, n: u64, threads: usize) -> Part {
    let nominal = part::slice(campaign.runs, k, n);
    let faults = part::slice(campaign.fault_runs, k, n);
    let seed = campaign.seed;
    let draws = draws_of(&campaign, nominal.clone(), faults.clone());
    eprintln!(
        "monitor-mc: shard {k}/{n}: nominal runs {}..{}, runs {}..{} of each fault kind ({} runs) on {threads} threads (seed {seed}, power-on settling {} s, pre-roll {} s)",
        nominal.start,
        nominal.end,
        faults.start,
        faults.end,
        draws.len(),
        setup.config.thresholds.power_on_settle_s,
        setup.pre_roll_s,
    );
    let progress = |done: usize, total: usize| {
        if done.is_multiple_of(50) || done == total {
            eprint!("\r  {done}/{total} runs");
            let _ = std::io::stderr().flush();
        }
    };
    let outcomes = run_all(&draws, setup, threads, &progress);
    eprintln!();
    Part::new(campaign, [k, n], nominal, faults, &outcomes)
}

/// A campaign's draws: the nominal runs `nominal`, then each fault kind's runs `faults`.
fn draws_of(campaign: &Campaign, nominal: Range<u64>, faults: Range<u64>) -> Vec<Draw> {
    let draw = |i, kind| draw_for(&campaign.plant_family, campaign.seed, i, kind);
    let mut draws: Vec<_> = nominal.map(|i| draw(i, None)).collect();
    for kind in FAULT_KINDS {
        draws.extend(faults.clone().map(|i| draw(i, Some(kind))));
    }
    draws
}

/// Run `index` of a campaign of the named plant family.
fn draw_for(
    family: &str,
    seed: u64,
    index: u64,
    fault: Option<noback_twin::fault::FaultKind>,
) -> Draw {
    if family == LEGACY_FAMILY {
        return draw_legacy(seed, index, fault);
    }
    draw_in(
        Family::parse(family).unwrap_or(Family::PhysicalDefault),
        seed,
        index,
        fault,
    )
}

/// The plant form of every run of a campaign, in the outcomes' order (nominal, then each
/// fault kind): a function of the draws alone, so a merge finds what the runs drew.
fn forms_of(campaign: &Campaign) -> Vec<&'static str> {
    draws_of(campaign, 0..campaign.runs, 0..campaign.fault_runs)
        .iter()
        .map(|d| host_tests::family::form(&d.scene))
        .collect()
}

/// [`behaviour_digest`] of a campaign's first nominal draws (at most [`BEHAVIOUR_RUNS`]).
pub fn monitor_digest(setup: &Setup, campaign: &Campaign) -> String {
    let draws: Vec<_> = (0..campaign.runs.min(BEHAVIOUR_RUNS))
        .map(|i| draw_for(&campaign.plant_family, campaign.seed, i, None))
        .collect();
    format!("{:#010x}", behaviour_digest(&draws, setup))
}

/// The campaign a run's arguments describe.
fn campaign_of(setup: &Setup, family: Family, seed: u64, runs: u64, fault_runs: u64) -> Campaign {
    Campaign {
        seed,
        plant_family: family.name().into(),
        config_digest: part::config_digest(&setup.config),
        monitor_digest: None,
        pre_roll_s: setup.pre_roll_s,
        power_on_settle_s: setup.config.thresholds.power_on_settle_s,
        runs,
        fault_runs,
        test_every: setup.test_every,
        commissioned: setup.commissioned,
    }
}

fn run_main(a: &RunArgs) -> Result<(), Fail> {
    let mut setup = Setup::for_family(a.family);
    if let Some(s) = a.power_on_settle {
        setup.config.thresholds.power_on_settle_s = s;
    }
    if let Some(s) = a.pre_roll {
        setup.pre_roll_s = s;
    }
    if let Some(k) = a.test_every {
        setup.test_every = k;
    }
    setup.commissioned = a.commissioned;
    noback::monitor::Monitor::new(setup.config)
        .map_err(|e| Fail::Input(format!("monitor configuration: {e:?}")))?;
    let mut campaign = campaign_of(&setup, a.family, a.seed, a.runs, a.fault_runs);
    if a.legacy_draws {
        campaign.plant_family = LEGACY_FAMILY.into();
    }
    campaign.monitor_digest = Some(monitor_digest(&setup, &campaign));
    let (k, n) = a.shard.unwrap_or((0, 1));
    let part = run_part(&setup, campaign, k, n, threads(a.threads));
    let text = serde_json::to_string(&part).map_err(|e| e.to_string())?;
    if let Some(out) = &a.out {
        std::fs::write(out, &text).map_err(|e| format!("{}: {e}", out.display()))?;
        eprintln!("wrote {}", out.display());
    }
    if a.shard.is_some() {
        return Ok(());
    }
    // The page describes the shipped monitor: an ablation does not overwrite it.
    let shipped = Setup::for_family(a.family);
    let ablation = setup.config != shipped.config
        || setup.pre_roll_s != shipped.pre_roll_s
        || a.legacy_draws
        || a.commissioned
        || a.family != Family::PhysicalDefault;
    // Through the part's text, as a merge reads it: the same bytes whichever way.
    let part = serde_json::from_str(&text).map_err(|e| e.to_string())?;
    let parts = [("the campaign".into(), part)];
    finish(&parts, false, &a.output, ablation, None, setup)
}

fn merge_main(m: &MergeArgs) -> Result<(), Fail> {
    let mut parts = Vec::new();
    for path in &m.parts {
        let name = path.display().to_string();
        let text =
            std::fs::read_to_string(path).map_err(|e| Fail::Input(format!("{name}: {e}")))?;
        let part: Part = serde_json::from_str(&text)
            .map_err(|e| Fail::Input(format!("{name}: not a monitor-mc part file ({e})")))?;
        parts.push((name, part));
    }
    let family = parts
        .first()
        .and_then(|(_, p)| Family::parse(&p.campaign.plant_family))
        .unwrap_or(Family::PhysicalDefault);
    let shipped = Setup::for_family(family);
    let setup = setup_of_this_build(&parts, shipped)?;
    // The page describes the default family's campaign drawn by today's stream.
    let other_family = parts
        .first()
        .is_some_and(|(_, p)| p.campaign.plant_family != Family::PhysicalDefault.name());
    let ablation = setup.config != shipped.config
        || setup.pre_roll_s != shipped.pre_roll_s
        || setup.commissioned
        || other_family;
    finish(
        &parts,
        m.prefix,
        &m.output,
        ablation,
        m.out.as_deref(),
        setup,
    )
}

/// The setup `parts` were run with (`shipped`'s, with the first part's settings), refused
/// unless it is this build's monitor: its configuration digest, and its behaviour digest
/// recomputed on the campaign's first draws (a part without one is of an earlier build).
fn setup_of_this_build(parts: &[(String, Part)], shipped: Setup) -> Result<Setup, Fail> {
    let mut setup = shipped;
    let Some((name, p)) = parts.first() else {
        return Ok(setup);
    };
    setup.pre_roll_s = p.campaign.pre_roll_s;
    setup.config.thresholds.power_on_settle_s = p.campaign.power_on_settle_s;
    setup.commissioned = p.campaign.commissioned;
    let digest = part::config_digest(&setup.config);
    if p.campaign.config_digest != digest {
        return Err(Fail::Input(format!(
            "{name}: configuration digest {} is not this build's monitor's ({digest})",
            p.campaign.config_digest
        )));
    }
    let digest = monitor_digest(&setup, &p.campaign);
    match &p.campaign.monitor_digest {
        Some(recorded) if *recorded == digest => Ok(setup),
        Some(recorded) => Err(Fail::Input(format!(
            "{name}: monitor digest {recorded} is not this build's monitor's ({digest})"
        ))),
        None => Err(Fail::Input(format!(
            "{name}: no monitor digest (a part of an earlier build): rerun it"
        ))),
    }
}

/// The report of merged `parts`: printed, and written to `docs/monitor.md` and `out`.
fn finish(
    parts: &[(String, Part)],
    prefix: bool,
    output: &Output,
    ablation: bool,
    out: Option<&Path>,
    setup: Setup,
) -> Result<(), Fail> {
    let (campaign, outcomes) = part::merge(parts, prefix).map_err(Fail::Input)?;
    let (report, doc) = report_of(&campaign, &outcomes, setup)?;
    if !output.no_doc && !ablation {
        let path = workspace_root().join("docs").join("monitor.md");
        std::fs::write(&path, doc).map_err(|e| format!("{}: {e}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    if let Some(out) = out {
        std::fs::write(out, format!("{report}\n"))
            .map_err(|e| format!("{}: {e}", out.display()))?;
        eprintln!("wrote {}", out.display());
    }
    if output.json {
        println!("{report}");
    } else {
        println!("{}", page::table(&report));
        if let Some(forms) = report["by_form"].as_object() {
            println!("{}", report::form_table(forms));
        }
    }
    Ok(())
}

/// The report (JSON text) of the shipped monitor's unsharded campaign, as `--json` prints it
/// (with its behaviour digest, as `run_main` gives it).
pub fn unsharded_report(seed: u64, runs: u64, fault_runs: u64) -> Result<String, String> {
    let setup = Setup::default();
    let mut campaign = campaign_of(&setup, Family::PhysicalDefault, seed, runs, fault_runs);
    campaign.monitor_digest = Some(monitor_digest(&setup, &campaign));
    let part = run_part(&setup, campaign, 0, 1, threads(None));
    let part: Part =
        serde_json::from_str(&serde_json::to_string(&part).map_err(|e| e.to_string())?)
            .map_err(|e| e.to_string())?;
    let (c, outcomes) = part::merge(&[("the campaign".into(), part)], false)?;
    Ok(report_of(&c, &outcomes, setup)?.0.to_string())
}

/// The report (JSON) and `docs/monitor.md` of a campaign's outcomes.
pub fn report_of(
    campaign: &Campaign,
    outcomes: &[host_tests::mc::Outcome],
    setup: Setup,
) -> Result<(serde_json::Value, String), String> {
    let meta = report::Meta {
        seed: campaign.seed,
        runs: campaign.runs,
        fault_runs: campaign.fault_runs,
        plant_family: campaign.plant_family.clone(),
        config_digest: campaign.config_digest.clone(),
        monitor_digest: campaign.monitor_digest.clone(),
        config: setup.config,
        pre_roll_s: campaign.pre_roll_s,
        test_every: campaign.test_every,
        commissioned: campaign.commissioned,
    };
    let mut report = report::build(&meta, outcomes)?;
    if campaign.plant_family == Family::Plant.name() {
        report["by_form"] = report::by_form(outcomes, &forms_of(campaign), campaign.commissioned);
    }
    let record_path = workspace_root().join(page::CAMPAIGN_RECORD);
    let record = match std::fs::read_to_string(&record_path) {
        Ok(text) => Some(
            serde_json::from_str(&text).map_err(|e| format!("{}: {e}", record_path.display()))?,
        ),
        Err(_) => None,
    };
    Ok((report.clone(), page::doc(&report, record.as_ref())))
}

#[cfg(test)]
mod tests;
