//! `cargo xtask fuzz [TARGET|all] [--seconds N]` — the fuzz targets under libFuzzer (cargo-fuzz,
//! nightly) for as long as asked. Installs cargo-fuzz from crates.io when missing; needs a
//! nightly toolchain (it says so if there is none). Each run appends its statistics to
//! `target/fuzz-log.jsonl`, which `cargo xtask reliability` summarises. The same bodies run
//! briefly on stable in `cargo xtask test` (host-tests/tests/fuzz_brief.rs).

use crate::shell::{self, workspace_root};
use host_tests::fuzz::TARGETS;
use serde_json::json;
use std::io::Write as _;
use std::process::Command;

/// Entry.
pub fn main(args: &[String]) -> Result<i32, String> {
    let mut targets: Vec<&str> = Vec::new();
    let mut seconds = 60_u64;
    let mut it = args.iter();
    while let Some(arg) = it.next() {
        match arg.as_str() {
            "--seconds" => {
                seconds = it
                    .next()
                    .and_then(|v| v.parse().ok())
                    .filter(|s| *s > 0)
                    .ok_or("--seconds needs a positive whole number")?;
            }
            "all" => targets.extend(TARGETS),
            t => {
                targets.push(TARGETS.iter().find(|x| **x == t).ok_or_else(|| {
                    format!("unknown fuzz target `{t}` (one of {TARGETS:?} or all)")
                })?)
            }
        }
    }
    if targets.is_empty() {
        targets.extend(TARGETS);
    }
    let nightly = Command::new("rustup")
        .args(["toolchain", "list"])
        .output()
        .is_ok_and(|o| {
            String::from_utf8_lossy(&o.stdout)
                .lines()
                .any(|l| l.starts_with("nightly"))
        });
    if !nightly {
        return Err(
            "cargo-fuzz needs a nightly toolchain: `rustup toolchain install nightly` \
                    (the brief fuzz runs of `cargo xtask test` need none)"
                .into(),
        );
    }
    if !shell::on_path("cargo-fuzz") {
        eprintln!("fuzz: cargo-fuzz is missing; installing it from crates.io");
        shell::run(Command::new("cargo").args(["install", "cargo-fuzz", "--locked"]))?;
    }
    let root = workspace_root();
    for target in targets {
        let corpus = root.join("target").join("fuzz-corpus").join(target);
        std::fs::create_dir_all(&corpus).map_err(|e| e.to_string())?;
        let seeds = root.join("fuzz").join("seeds").join(target);
        let mut cmd = Command::new("cargo");
        cmd.current_dir(&root)
            .args(["+nightly", "fuzz", "run", target])
            .arg(&corpus)
            .arg(&seeds)
            .args([
                "--",
                &format!("-max_total_time={seconds}"),
                "-print_final_stats=1",
            ]);
        eprintln!("$ {}", shell::describe(&cmd));
        let out = cmd
            .output()
            .map_err(|e| format!("starting cargo fuzz: {e}"))?;
        let log = String::from_utf8_lossy(&out.stderr);
        let stat = |name: &str| -> Option<u64> {
            log.lines()
                .find(|l| l.starts_with(&format!("stat::{name}:")))
                .and_then(|l| l.rsplit(':').next()?.trim().parse().ok())
        };
        let corpus_files = std::fs::read_dir(&corpus).map_or(0, |d| d.count());
        let crashed = !out.status.success();
        let entry = json!({
            "target": target,
            "seconds": seconds,
            "execs": stat("number_of_executed_units"),
            "peak_rss_mb": stat("peak_rss_mb"),
            "corpus_files": corpus_files,
            "crashed": crashed,
        });
        println!("{entry}");
        let mut f = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(root.join("target").join("fuzz-log.jsonl"))
            .map_err(|e| e.to_string())?;
        writeln!(f, "{entry}").map_err(|e| e.to_string())?;
        if crashed {
            eprintln!("{log}");
            return Err(format!(
                "fuzz target {target} found a failure (artifacts in fuzz/artifacts/{target}/)"
            ));
        }
    }
    Ok(0)
}
