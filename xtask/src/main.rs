//! `cargo xtask` — noback's commands. Automation only: no physics lives here.
//!
//! Each command is one file; this one parses the command line (clap, by the convention of
//! `noback_twin::args`: `--help` exits 0, a bad argument exits 2 with one line naming it) and
//! dispatches. The README's two commands are `cargo xtask run` and `cargo xtask test`.

mod bench;
mod board_pin;
mod board_test;
mod bootstrap;
mod commission;
mod commissioned;
mod cores;
mod defmt_log;
mod elf_size;
mod fuzz;
mod golden;
mod machine;
mod monitor;
mod monitor_mc;
mod opt_level;
mod pages;
mod profile;
mod qemu;
mod reliability;
mod replay;
mod run;
mod shell;
mod slurm_test;
mod snapshot;
mod stack_bound;
mod test;
#[cfg(test)]
mod tidy;
mod trip_log;
mod twin_bench;

use clap::{CommandFactory, Parser, Subcommand};
use cores::Core;
use noback_twin::args as convention;
use std::process::ExitCode;

/// noback's commands: the README's two are `run` (main job) and `test` (every test).
#[derive(Parser)]
#[command(name = "cargo xtask", about, disable_help_subcommand = true)]
struct Cli {
    #[command(subcommand)]
    command: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// The firmware streams a twin scene's trace at 10 kHz under QEMU and reports.
    Run(run::RunArgs),
    /// Every test: fmt, clippy, tidy, host tests, QEMU tests on M0/M3/M4F.
    Test(test::TestArgs),
    /// Boot an ELF in QEMU and decode defmt (the cargo runner of the thumb targets).
    Qemu(qemu::QemuArgs),
    /// Run the digital twin on one scene.
    Twin(noback_twin::cli::TwinArgs),
    /// Twin and scipy Radau against the converged references; writes docs/results/twin-speed.md.
    TwinBench(TwinBenchArgs),
    /// The paper protocol and both readings; writes docs/paper-comparison.md (--json: prints only).
    Paper(noback_twin::cli::PaperArgs),
    /// Design sweeps (CSV + SVG).
    Sweep(noback_twin::sweep::SweepArgs),
    /// The monitor against the twin on one scene or trace (accuracy, flags, latency).
    Monitor(monitor::MonitorArgs),
    /// The unit's settings from its recorded acceptance run, as a configuration file.
    Commission(commission::CommissionArgs),
    /// Detection by Monte Carlo; writes docs/monitor.md (its own options: see its --help).
    #[command(disable_help_flag = true)]
    MonitorMc(Passthrough),
    /// The fuzz targets under libFuzzer (nightly, cargo-fuzz); extends fuzz/long-runs.json.
    Fuzz(fuzz::FuzzArgs),
    /// Regenerate the golden twin traces in host-tests/golden/.
    Golden,
    /// Flash and instructions at each opt-level; writes docs/results/opt-level.md.
    OptLevel,
    /// Input classes, fuzzing, panic-never proof; writes docs/reliability.md.
    Reliability(reliability::ReliabilityArgs),
    /// Speed against accuracy of model variants; writes docs/results/speed-accuracy.* etc.
    Bench(BenchArgs),
    /// The trip log on the host: record a scene's trips, dump a flash region, replay a record.
    Log(trip_log::LogArgs),
    /// The trip log's power-loss test: a cut at every flash step, records lost and corrupt.
    PowerFail(trip_log::PowerFailArgs),
    /// Where the monitor's instructions go per step, by stage (QEMU, one instruction a block).
    Profile(profile::ProfileArgs),
    /// Add missing rustup targets and install qemu-system-arm if missing.
    Bootstrap,
}

/// Arguments handed whole to a command that parses its own.
#[derive(clap::Args)]
struct Passthrough {
    #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
    args: Vec<String>,
}

/// `bench`'s options, checked here; `bench::main` reads the same words.
#[derive(clap::Args)]
struct BenchArgs {
    /// Fewer variants and runs.
    #[arg(long)]
    quick: bool,
    /// Print the results as one JSON object.
    #[arg(long)]
    json: bool,
}

/// `twin-bench`'s options, checked here; `twin_bench::main` reads the same words.
#[derive(clap::Args)]
struct TwinBenchArgs {
    /// The integrators' tolerance, in (1e-10, 1e-2).
    #[arg(long, allow_hyphen_values = true, value_parser = convention::tolerance, value_name = "TOL")]
    tolerance: Option<f64>,
    /// Measure the twin only.
    #[arg(long)]
    no_scipy: bool,
    /// Print the comparison as one JSON object (and write nothing).
    #[arg(long)]
    json: bool,
}

/// A clap value parser: a core name.
pub fn core_arg(s: &str) -> Result<Core, String> {
    Core::parse(s).map_err(|_| "expected m0, m3, m4f or m7".into())
}

/// Parses `--board` (the real parts with a board crate: `stm32f405`).
pub fn board_arg(s: &str) -> Result<Core, String> {
    (s == Core::Stm32f405.name())
        .then_some(Core::Stm32f405)
        .ok_or_else(|| "expected stm32f405".into())
}

/// Every command's name (the tidy test checks the README and docs name only these).
pub fn command_names() -> Vec<String> {
    Cli::command()
        .get_subcommands()
        .map(|c| c.get_name().to_string())
        .collect()
}

/// Parses and runs a command line (without the program name); returns the exit code.
fn dispatch(args: &[String]) -> i32 {
    let name = args
        .first()
        .filter(|a| !a.starts_with('-'))
        .map_or("", String::as_str);
    let known = command_names().iter().any(|c| c == name);
    let cli = match convention::parse::<Cli>(if known { name } else { "" }, args) {
        Ok(cli) => cli,
        Err(code) => return code,
    };
    // Bench and twin-bench were checked above; they read their own words from the same list.
    let rest = args.get(1..).unwrap_or_default();
    let result = match cli.command {
        Cmd::Run(a) => run::main(&a),
        Cmd::Test(a) => test::main(&a),
        Cmd::Qemu(a) => qemu::main(&a),
        Cmd::Twin(a) => Ok(noback_twin::cli::twin_run(&a)),
        Cmd::Paper(a) => Ok(noback_twin::cli::paper_run(&a)),
        Cmd::Sweep(a) => Ok(noback_twin::sweep::sweep_run(&a)),
        Cmd::TwinBench(_) => twin_bench::main(rest),
        Cmd::Monitor(a) => monitor::main(&a),
        Cmd::Commission(a) => commission::main(&a),
        Cmd::MonitorMc(a) => monitor_mc::main(&a.args),
        Cmd::Fuzz(a) => fuzz::main(&a),
        Cmd::Golden => golden::main(),
        Cmd::OptLevel => opt_level::main(),
        Cmd::Reliability(a) => reliability::main(&a),
        Cmd::Bench(_) => bench::main(rest),
        Cmd::Log(a) => trip_log::main(&a),
        Cmd::PowerFail(a) => trip_log::power_fail(&a),
        Cmd::Profile(a) => profile::main(&a),
        Cmd::Bootstrap => bootstrap::ensure_all().map(|()| 0),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("xtask {name}: error: {}", convention::capped(&e));
            1
        }
    }
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let code = dispatch(&args);
    ExitCode::from(u8::try_from(code).unwrap_or(1))
}

#[cfg(test)]
mod tests {
    #[test]
    fn help_exits_zero_and_bad_arguments_two() {
        let words = |s: &str| s.split_whitespace().map(String::from).collect::<Vec<_>>();
        assert_eq!(super::dispatch(&words("--help")), 0);
        assert_eq!(super::dispatch(&words("run --help")), 0);
        assert_eq!(
            super::dispatch(&words("run --core m9")),
            noback_twin::args::EXIT_USAGE
        );
        assert_eq!(
            super::dispatch(&words("nonsense")),
            noback_twin::args::EXIT_USAGE
        );
        assert_eq!(super::dispatch(&[]), noback_twin::args::EXIT_USAGE);
    }
}
