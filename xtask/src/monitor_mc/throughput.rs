//! `monitor-mc throughput`: the Monte Carlo's runs per second per core on this machine and the
//! wall time of a 10⁶-run campaign on N nodes; writes the benchmark page
//! `docs/results/mc-throughput.md` (machine-dependent, marked as such).

use crate::shell::workspace_root;
use clap::Args;
use host_tests::mc::{draw, run_all, Campaign, FAULT_KINDS};
use std::fmt::Write as _;
use std::time::Instant;

#[derive(Args, Debug)]
pub struct ThroughputArgs {
    /// Nominal runs timed (and a tenth as many per fault kind).
    #[arg(long, default_value_t = 200)]
    runs: u64,
}

fn first_line_with(path: &str, key: &str) -> String {
    std::fs::read_to_string(path)
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with(key))
                .and_then(|l| l.split(':').nth(1))
                .map(|v| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into())
}

/// Runs per second of `draws` on `threads` workers.
fn rate(draws: &[host_tests::mc::Draw], threads: usize) -> f64 {
    let started = Instant::now();
    let _ = run_all(draws, &Campaign::default(), threads, &|_, _| {});
    draws.len() as f64 / started.elapsed().as_secs_f64()
}

/// Entry.
pub fn main(a: &ThroughputArgs) -> Result<(), String> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let load = load.split_whitespace().next().unwrap_or("?").to_string();
    let cpu = first_line_with("/proc/cpuinfo", "model name");
    let nominal: Vec<_> = (0..a.runs).map(|i| draw(1, i, None)).collect();
    let faults: Vec<_> = FAULT_KINDS
        .iter()
        .flat_map(|k| (0..a.runs.div_ceil(10)).map(|i| draw(1, i, Some(*k))))
        .collect();
    eprintln!(
        "monitor-mc throughput: {} nominal and {} fault runs on 1 and {cores} threads",
        nominal.len(),
        faults.len()
    );
    let one = rate(&nominal, 1);
    let one_fault = rate(&faults, 1);
    let all = rate(&nominal, cores);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Monte Carlo throughput (benchmark: machine-dependent)\n\n\
         Written by `cargo xtask monitor-mc throughput --runs {}`; timings differ from run to run \
         and machine to machine, unlike `monitor.md`. Machine: {cpu}, {cores} cores as the OS \
         reports them, load average {load} when it started (the machine was shared).\n\n\
         | what | runs/s |\n|---|---|\n\
         | nominal runs, 1 thread (per core) | {one:.1} |\n\
         | fault runs, 1 thread (per core) | {one_fault:.1} |\n\
         | nominal runs, {cores} threads | {all:.1} |\n\n\
         A 10⁶-run nominal campaign at {one:.1} runs/s per core, shards spread evenly (one per \
         core, `slurm/`), merge not counted (seconds):\n\n\
         | nodes | cores each | wall time |\n|---|---|---|",
        a.runs
    );
    for (nodes, per) in [(1, cores), (10, 32), (50, 32), (100, 64)] {
        let hours = 1e6 / (one * (nodes * per) as f64) / 3600.0;
        let _ = writeln!(s, "| {nodes} | {per} | {hours:.2} h |");
    }
    let path = workspace_root().join("docs/results/mc-throughput.md");
    std::fs::write(&path, &s).map_err(|e| format!("{}: {e}", path.display()))?;
    eprintln!("wrote {}", path.display());
    print!("{s}");
    Ok(())
}
