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

/// CPU seconds this process has used, all threads (`/proc/self/stat` utime + stime, at the
/// kernel's USER_HZ of 100).
fn cpu_s() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the command's closing parenthesis; utime and stime are the 12th and 13th.
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<&str> = rest.split_whitespace().collect();
    let field = |i: usize| f.get(i).and_then(|x| x.parse::<f64>().ok()).unwrap_or(0.0);
    (field(11) + field(12)) / 100.0
}

/// Runs per wall-clock second and per CPU second of `draws` on `threads` workers.
fn rate(draws: &[host_tests::mc::Draw], threads: usize) -> (f64, f64) {
    let (wall, cpu) = (Instant::now(), cpu_s());
    let _ = run_all(draws, &Campaign::default(), threads, &|_, _| {});
    let n = draws.len() as f64;
    (
        n / wall.elapsed().as_secs_f64(),
        n / (cpu_s() - cpu).max(0.01),
    )
}

/// Entry.
pub fn main(a: &ThroughputArgs) -> Result<(), String> {
    let machine = crate::machine::this();
    let cores = machine.cores;
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
    let (one, one_cpu) = rate(&nominal, 1);
    let (fault, fault_cpu) = rate(&faults, 1);
    let (all, _) = rate(&nominal, cores);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Monte Carlo throughput (benchmark: machine-dependent)\n\n\
         Written by `cargo xtask monitor-mc throughput --runs {}`; timings differ from run to run \
         and machine to machine, unlike `monitor.md`. Machine: {machine} (shared: wall-clock rates \
         fall with the load, rates per CPU second much less).\n\n\
         | what | runs per wall-clock second | runs per CPU second |\n|---|---|---|\n\
         | nominal runs, 1 thread | {one:.1} | {one_cpu:.1} |\n\
         | fault runs, 1 thread | {fault:.1} | {fault_cpu:.1} |\n\
         | nominal runs, {cores} threads | {all:.1} | |\n\n\
         A 10⁶-run nominal campaign at {one_cpu:.1} runs per CPU second per core (an unloaded \
         core), one shard per core (`slurm/submit.sh`), merge not counted:\n\n\
         | nodes | cores each | wall time |\n|---|---|---|",
        a.runs
    );
    for (nodes, per) in [(1, cores), (1, 32), (10, 32), (100, 32)] {
        let hours = 1e6 / (one_cpu * (nodes * per) as f64) / 3600.0;
        let wall = if hours >= 1.0 {
            format!("{hours:.1} h")
        } else {
            format!("{:.1} min", hours * 60.0)
        };
        let _ = writeln!(s, "| {nodes} | {per} | {wall} |");
    }
    let path = workspace_root().join("docs/results/mc-throughput.md");
    std::fs::write(&path, &s).map_err(|e| format!("{}: {e}", path.display()))?;
    eprintln!("wrote {}", path.display());
    print!("{s}");
    Ok(())
}
