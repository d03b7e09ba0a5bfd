//! `cargo xtask test` — every test, in the order that fails fastest:
//! format, clippy (host and each thumb target), host tests (library, host-tests, twin, tidy),
//! a sharded Monte Carlo on a single-node Slurm (`slurm_test`), then under QEMU on M0, M3 and
//! M4F: the defmt-test target tests and the release firmware.
//! The digest each target prints is compared here with the one computed natively: that is the
//! bit-identity check, made by the xtask rather than asserted by the target about itself.

use crate::bootstrap;
use crate::cores::Core;
use crate::shell::{self, cargo};
use crate::{qemu, run, snapshot};
use std::io::{BufRead, BufReader};
use std::process::Stdio;
use std::time::{Duration, Instant};

/// The scene whose QEMU run is the snapshot test: the paper's reverse-load motor failure.
pub const SNAPSHOT_SCENE: &str = "reverse_load";

/// `cargo xtask test`'s options.
#[derive(clap::Args, Debug)]
pub struct TestArgs {
    /// Test only these cores under QEMU (repeatable; default: all three).
    #[arg(long, value_parser = crate::core_arg, value_name = "m0|m3|m4f|m7")]
    pub core: Vec<Core>,
    /// Rewrite the QEMU snapshot instead of comparing with it.
    #[arg(long)]
    pub bless: bool,
}

/// Entry.
pub fn main(a: &TestArgs) -> Result<i32, String> {
    let mut cores = a.core.clone();
    let bless = a.bless;
    if cores.is_empty() {
        cores = Core::EVERY.to_vec();
    }
    // The M7 shares the M4F's target: its build stages run once per target.
    let mut targets: Vec<Core> = Vec::new();
    for &core in &cores {
        if !targets.iter().any(|t| t.triple() == core.triple()) {
            targets.push(core);
        }
    }
    let started = Instant::now();
    bootstrap::ensure_all()?;

    section("format");
    shell::run(cargo().args(["fmt", "--all", "--", "--check"]))?;
    section("clippy (host)");
    shell::run(cargo().args([
        "clippy",
        "--workspace",
        "--all-targets",
        "--",
        "-D",
        "warnings",
    ]))?;
    for &core in &targets {
        section(&format!("clippy ({})", core.triple()));
        shell::run(cargo().args([
            "clippy",
            "-p",
            "noback",
            "--target",
            core.triple(),
            "--lib",
            "--bins",
            "--test",
            "on_target",
            "--test",
            "probe_panic",
            "--test",
            "probe_hardfault",
            "--test",
            "probe_hang",
            "--",
            "-D",
            "warnings",
        ]))?;
    }
    for &core in &targets {
        section(&format!(
            "panic-never proof: link the real-time path ({})",
            core.triple()
        ));
        shell::run(cargo().args([
            "build",
            "--release",
            "-p",
            "panic-check",
            "--target",
            core.triple(),
        ]))?;
    }
    section("host tests (library, host-tests, twin, xtask tidy)");
    shell::run(cargo().args(["test", "--workspace"]))?;
    section(
        "pages reproduce (reliability and paper against their committed pages, monitor-mc twice)",
    );
    crate::pages::reproduce()?;
    section(
        "trip log: power cut at every flash step; each trip of a fault scene replayed bit-exact",
    );
    trip_log_holds()?;
    section("Slurm: a sharded Monte Carlo as a job array, merged = unsharded");
    crate::slurm_test::stage()?;

    let host_digest = noback::vectors::run().digest;
    let mut rows = Vec::new();
    for &core in &cores {
        // The cargo runner boots a test on its target's core: the M7 runs the firmware only.
        let test_digest = if core == Core::M7 {
            None
        } else {
            section(&format!("target tests under QEMU ({})", core.name()));
            let lines = target_tests(core)?;
            section(&format!("fault probes under QEMU ({})", core.name()));
            fault_probes(core)?;
            Some(digest_in(&lines)?)
        };
        section(&format!(
            "firmware replaying `{SNAPSHOT_SCENE}` under QEMU ({}, release)",
            core.name()
        ));
        let (report, ok) = run::replay_report(SNAPSHOT_SCENE, core, None, None, false)?;
        println!(
            "ticks {}, overruns {}, flags {}, {} instructions/step max, bit-exact {}",
            report["ticks"],
            report["overruns"],
            report["flags"],
            report["insns_per_step_max"],
            report["bit_exact"]
        );
        if !ok {
            return Err(format!(
                "the firmware on {} is not bit-exact with the host or exited badly",
                core.name()
            ));
        }
        if core == Core::M3 {
            snapshot::check(&report, bless)?;
            section("provoked overrun (m3)");
            overrun_is_counted_and_flagged(Core::M3)?;
            section("load: hostile inputs, flags reset every 50 ticks (m3)");
            stress_stays_within_its_deadline()?;
            section("one time base: a flag's time from run equals monitor's (m3)");
            run_and_monitor_agree_on_time()?;
            section("a commissioned unit: its configuration block, bit-exact (m3)");
            crate::commissioned::block_is_bit_exact(Core::M3)?;
            section("the functional test on the firmware: a healthy unit passes, half a spring fails (m3)");
            crate::commissioned::functional_test_on_firmware()?;
            section("the uncoupled push on the firmware: a spring-only unit passes, its pack worn by half fails (m3)");
            crate::commissioned::uncoupled_test_on_firmware()?;
        }
        let fw_digest = u32::from_str_radix(
            report["fx_selfcheck_digest"]
                .as_str()
                .unwrap_or("")
                .trim_start_matches("0x"),
            16,
        )
        .map_err(|e| format!("self-check digest: {e}"))?;
        rows.push((core, test_digest, fw_digest));
    }

    if a.core.is_empty() {
        rows.push((Core::Stm32f405, None, crate::board_test::stage()?));
    }

    section("bit-identity of the fixed-point vectors");
    println!("host digest {host_digest:#010x}");
    let mut identical = true;
    for (core, test_digest, fw_digest) in &rows {
        let ok = test_digest.is_none_or(|d| d == host_digest) && *fw_digest == host_digest;
        identical &= ok;
        let test = test_digest.map_or("—         ".to_string(), |d| format!("{d:#010x}"));
        println!(
            "{:<9} test {test}  firmware {fw_digest:#010x}  {}",
            core.name(),
            if ok { "identical" } else { "DIFFERENT" }
        );
    }
    if !identical {
        return Err("a target computed different bits from the host".into());
    }
    println!(
        "\nxtask test: all passed in {:.0} s",
        started.elapsed().as_secs_f64()
    );
    Ok(0)
}

fn section(title: &str) {
    println!("\n=== {title} ===");
}

/// Runs the defmt-test target tests for `core` under QEMU (this xtask as the cargo runner),
/// echoing and returning their output lines.
fn target_tests(core: Core) -> Result<Vec<String>, String> {
    let exe = crate::shell::this_exe()?;
    let runner_var = format!(
        "CARGO_TARGET_{}_RUNNER",
        core.triple().to_uppercase().replace('-', "_")
    );
    let mut cmd = cargo();
    cmd.args([
        "test",
        "-p",
        "noback",
        "--target",
        core.triple(),
        "--test",
        "on_target",
    ])
    .env(runner_var, format!("{} qemu --timeout 60", exe.display()))
    .stdout(Stdio::piped());
    println!("$ {}", shell::describe(&cmd));
    let mut child = cmd.spawn().map_err(|e| format!("starting cargo: {e}"))?;
    let mut lines = Vec::new();
    if let Some(out) = child.stdout.take() {
        for line in BufReader::new(out).lines().map_while(Result::ok) {
            println!("{line}");
            lines.push(line);
        }
    }
    let status = child.wait().map_err(|e| e.to_string())?;
    if !status.success() {
        return Err(format!("target tests failed on {} ({status})", core.name()));
    }
    Ok(lines)
}

/// Tick at which the overrun test makes the interrupt miss its deadline.
const OVERRUN_TICK: u32 = 3000;

/// Provokes one missed deadline on `core` and checks it is counted, flagged and replayed
/// identically; returns the run's report.
pub fn overrun_is_counted_and_flagged(core: Core) -> Result<serde_json::Value, String> {
    let (report, ok) = run::replay_report(SNAPSHOT_SCENE, core, Some(OVERRUN_TICK), None, false)?;
    let overruns = report["overruns"].as_u64().unwrap_or(0);
    let flagged = report["flags"]
        .as_array()
        .into_iter()
        .flatten()
        .find(|f| f["flag"] == "overrun")
        .and_then(|f| f["tick"].as_u64());
    println!(
        "overrun at tick {OVERRUN_TICK}: counted {overruns}, missed {}, flag raised at tick {flagged:?}, bit-exact {}",
        report["missed_ticks"], report["bit_exact"]
    );
    // The interrupt with index OVERRUN_TICK (0-based) overruns into the next period, so its
    // background (PendSV) has not run when the next interrupt comes: that one is skipped too,
    // and the one after steps the monitor by three ticks (OVERRUN_TICK + 1 + 3).
    let missed = report["missed_ticks"].as_u64();
    let flag_in_time = flagged == Some(u64::from(OVERRUN_TICK) + 4);
    if overruns == 1 && missed == Some(2) && flag_in_time && ok {
        Ok(report)
    } else {
        Err("the provoked overrun was not counted once (two ticks missed), flagged on the next stepped tick and replayed bit-exactly".into())
    }
}

/// The heaviest path — every flag changing, a burst of flag events, hostile inputs — must stay
/// inside the deadline, count what the log overwrote, and stay bit-exact with the host.
fn stress_stays_within_its_deadline() -> Result<(), String> {
    let (report, ok) = run::replay_report(
        crate::replay::STRESS,
        Core::M3,
        None,
        Some(run::STRESS_RESET_EVERY),
        false,
    )?;
    let kinds: std::collections::BTreeSet<&str> = report["flags"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|f| f["flag"].as_str())
        .collect();
    let raised = report["flags"].as_array().map_or(0, Vec::len);
    println!(
        "stress: {} flag raisings of {:?}, overruns {}, log events overwritten {}, whole tick at most {} instructions ({} % of the deadline), bit-exact {}",
        raised,
        kinds,
        report["overruns"],
        report["log_overwritten"],
        report["isr_insns_max"],
        report["deadline_used_pct"],
        report["bit_exact"]
    );
    let used = report["deadline_used_pct"]
        .as_f64()
        .unwrap_or(f64::INFINITY);
    if ok && report["overruns"] == 0 && used < 100.0 && raised > 10 && !kinds.is_empty() {
        Ok(())
    } else {
        Err(
            "the load test missed its deadline, lost bit-exactness or did not load the flag path"
                .into(),
        )
    }
}

/// A fault scene through the firmware and through `monitor`'s comparison on the host: each flag
/// must carry the same time (the trace's sample time) in both reports.
fn run_and_monitor_agree_on_time() -> Result<(), String> {
    let scene = fault_scene()?;
    let (report, ok) = run::replay_report(&scene, Core::M3, None, None, false)?;
    let trace = crate::replay::twin_trace(&scene)?;
    let estimates = host_tests::accuracy::run_monitor(&trace, noback::monitor::Config::default())?;
    let host = host_tests::accuracy::compare(&trace, &estimates);
    let run_flags: Vec<(String, f64)> = report["flags"]
        .as_array()
        .into_iter()
        .flatten()
        .map(|f| {
            (
                f["flag"].as_str().unwrap_or("").to_string(),
                f["t_s"].as_f64().unwrap_or(f64::NAN),
            )
        })
        .collect();
    let monitor_flags: Vec<(String, f64)> = host
        .flags
        .iter()
        .map(|f| (f.flag.to_string(), f.t_s))
        .collect();
    println!("run: {run_flags:?}\nmonitor: {monitor_flags:?}");
    println!(
        "trip log read back from the firmware: {}",
        report["trip_log"]
    );
    let agree = !run_flags.is_empty()
        && run_flags.len() == monitor_flags.len()
        && run_flags
            .iter()
            .zip(&monitor_flags)
            .all(|(a, b)| a.0 == b.0 && (a.1 - b.1).abs() < 0.5 / trace.sample_rate_hz);
    if ok && agree {
        Ok(())
    } else {
        Err("run and monitor report different flags or times on the same scene".into())
    }
}

/// The trip log's power-loss test and the replay of a fault scene's records (host side), on
/// the default configuration and on another, which replays only its own records.
fn trip_log_holds() -> Result<(), String> {
    use noback::monitor::Config;
    let code = crate::trip_log::power_fail(&crate::trip_log::PowerFailArgs { json: false })?;
    let mut all = code == 0;
    let (default, physical) = (Config::default(), Config::physical_reading());
    for (config, other) in [(default, physical), (physical, default)] {
        let (records, _) = crate::trip_log::record_scene(&fault_scene()?, config)?;
        all &= !records.is_empty();
        for bytes in &records {
            let (same, line) = crate::trip_log::replay(bytes, config)?;
            println!("{line}");
            all &= same;
        }
        all &= records
            .iter()
            .all(|b| crate::trip_log::replay(b, other).is_err());
    }
    if all {
        Ok(())
    } else {
        Err("the trip log lost or misread a record under power loss, or a record did not replay bit-exact".into())
    }
}

/// Writes the fault scene of the time-base and alarm-pin tests (an encoder sticking at 0.1 s
/// during reverse-load braking); returns its path.
pub fn fault_scene() -> Result<String, String> {
    let dir = crate::shell::workspace_root().join("target").join("replay");
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let scene = dir.join("time_base.toml");
    let text = "[scene]\nkind = \"reverse_load\"\n[[fault]]\nkind = \"encoder_stuck\"\nat_s = 0.1\nseverity = 1.0\n";
    std::fs::write(&scene, text).map_err(|e| e.to_string())?;
    Ok(scene.to_string_lossy().into_owned())
}

/// Boots the three fault probes and checks each ends with its own non-zero exit code.
fn fault_probes(core: Core) -> Result<(), String> {
    let expected = [
        ("probe_panic", noback::exit_code::PANIC),
        ("probe_hardfault", noback::exit_code::HARDFAULT),
        ("probe_hang", qemu::EXIT_TIMEOUT),
    ];
    let mut cmd = cargo();
    cmd.args(["build", "-p", "noback", "--target", core.triple()]);
    for (name, _) in expected {
        cmd.args(["--test", name]);
    }
    let elfs = shell::built_executables(&mut cmd)?;
    for (name, code) in expected {
        let elf = elfs
            .iter()
            .find(|(target, _)| target == name)
            .map(|(_, path)| path.clone())
            .ok_or_else(|| format!("cargo built no executable for {name}"))?;
        let outcome = qemu::boot(&qemu::Boot {
            elf: &elf,
            core,
            timeout: Duration::from_secs(3),
            extra: Vec::new(),
            echo: false,
            args: Vec::new(),
        })?;
        let verdict = if outcome.code == code { "ok" } else { "WRONG" };
        println!(
            "{name:<16} exit {:>3} (expected {code}) {verdict}",
            outcome.code
        );
        if outcome.code != code {
            return Err(format!(
                "{name} on {} exited {} instead of {code}",
                core.name(),
                outcome.code
            ));
        }
    }
    Ok(())
}

/// The `digest=0x…` value a self-check line carries.
pub fn digest_in(lines: &[String]) -> Result<u32, String> {
    lines
        .iter()
        .filter(|l| l.contains("fx-selfcheck"))
        .find_map(|l| {
            let hex = l.split("digest=0x").nth(1)?;
            u32::from_str_radix(hex.get(..8)?, 16).ok()
        })
        .ok_or_else(|| "no `fx-selfcheck … digest=0x…` line in the target's log".into())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn digest_is_found_in_a_decoded_line() {
        let lines = vec![
            "INFO noback".to_string(),
            "INFO fx-selfcheck cases=10 mismatches=0 digest=0x1a2b3c4d".to_string(),
        ];
        assert_eq!(digest_in(&lines), Ok(0x1a2b_3c4d));
        assert!(digest_in(&lines[..1]).is_err());
    }
}
