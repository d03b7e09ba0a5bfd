//! `cargo xtask` — noback's commands. Automation only: no physics lives here.
//!
//! Each command is one file; this one parses the command line and dispatches. The README's two
//! commands are `cargo xtask run` (the main job) and `cargo xtask test` (every test).

mod bench;
mod bootstrap;
mod cores;
mod defmt_log;
mod elf_size;
mod fuzz;
mod golden;
mod monitor;
mod monitor_mc;
mod opt_level;
mod qemu;
mod reliability;
mod replay;
mod run;
mod shell;
mod snapshot;
mod test;
#[cfg(test)]
mod tidy;
mod twin_bench;

use std::process::ExitCode;

/// Every command, with its one-line help. The tidy test checks the README names only these.
pub const COMMANDS: &[(&str, &str)] = &[
    (
        "run",
        "[--scene NAME|FILE] [--core m0|m3|m4f] [--json]: the firmware replays a twin scene at 10 kHz under QEMU",
    ),
    (
        "test",
        "[--core C] [--bless]: every test: fmt, clippy, tidy, host tests, QEMU tests on M0/M3/M4F",
    ),
    (
        "qemu",
        "ELF [--core m0|m3|m4f] [--timeout S] [--icount SHIFT]: boot an ELF in QEMU, decode defmt (the cargo runner)",
    ),
    (
        "twin",
        "SCENE|FILE [--reading paper|physical] [--out DIR] [--json]: run the digital twin",
    ),
    (
        "twin-bench",
        "[--tolerance TOL] [--no-scipy] [--json]: twin and scipy Radau against the converged references; writes docs/results/twin-speed.md",
    ),
    (
        "paper",
        "[--json]: the paper protocol and both readings; writes docs/paper-comparison.md (--json: prints only)",
    ),
    (
        "sweep",
        "pressing-force | PARAM=a..b [--scene S]: design sweeps (CSV + SVG)",
    ),
    (
        "monitor",
        "SCENE|FILE [--json] [--out DIR]: the monitor against the twin (accuracy, flags, latency)",
    ),
    (
        "monitor-mc",
        "[--runs N] [--fault-runs K] [--seed S] [--json] [--no-doc] [--power-on-settle S] [--pre-roll S]: detection by Monte Carlo; writes docs/monitor.md",
    ),
    (
        "fuzz",
        "[TARGET|all] [--seconds N]: the fuzz targets under libFuzzer (nightly, cargo-fuzz)",
    ),
    (
        "golden",
        "regenerate the golden twin traces in host-tests/golden/",
    ),
    (
        "opt-level",
        "measure flash and instructions at each opt-level; writes docs/results/opt-level.md",
    ),
    (
        "reliability",
        "input classes, fuzzing, panic-never proof; writes docs/reliability.md",
    ),
    (
        "bench",
        "[--quick] [--json]: speed against accuracy; writes docs/results/speed-accuracy.*, stability.*, cheapest-per-scene.md",
    ),
    (
        "bootstrap",
        "add missing rustup targets and install qemu-system-arm if missing",
    ),
];

fn usage() -> ExitCode {
    eprintln!("usage: cargo xtask <command> [args]\n\ncommands:");
    for (name, help) in COMMANDS {
        eprintln!("  {name:<10} {help}");
    }
    ExitCode::from(2)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some((command, rest)) = args.split_first() else {
        return usage();
    };
    let result = match command.as_str() {
        "run" => run::main(rest),
        "test" => test::main(rest),
        "qemu" => qemu::main(rest),
        "twin" => Ok(noback_twin::cli::twin_main(rest)),
        "paper" => Ok(noback_twin::cli::paper_main(rest)),
        "twin-bench" => twin_bench::main(rest),
        "sweep" => Ok(noback_twin::sweep::sweep_main(rest)),
        "monitor" => monitor::main(rest),
        "monitor-mc" => monitor_mc::main(rest),
        "fuzz" => fuzz::main(rest),
        "golden" => golden::main(rest),
        "opt-level" => opt_level::main(rest),
        "reliability" => reliability::main(rest),
        "bench" => bench::main(rest),
        "bootstrap" => bootstrap::ensure_all().map(|()| 0),
        "-h" | "--help" | "help" => return usage(),
        other => {
            eprintln!("xtask: unknown command `{other}`");
            return usage();
        }
    };
    match result {
        Ok(code) => ExitCode::from(u8::try_from(code).unwrap_or(1)),
        Err(e) => {
            eprintln!("xtask {command}: error: {e}");
            ExitCode::from(1)
        }
    }
}
