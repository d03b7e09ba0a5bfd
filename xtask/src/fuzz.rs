//! `cargo xtask fuzz [TARGET|all] [--seconds N]` — the fuzz targets under libFuzzer (cargo-fuzz,
//! nightly) for as long as asked. Installs cargo-fuzz from crates.io when missing; needs a
//! nightly toolchain (it says so if there is none). Each run appends its statistics to the
//! committed record `fuzz/long-runs.json`, which `cargo xtask reliability` summarises. The same
//! bodies run briefly on stable in `cargo xtask test` (host-tests/tests/fuzz_brief.rs).

use crate::shell::{self, workspace_root};
use host_tests::fuzz::TARGETS;
use serde_json::{json, Value};
use std::process::Command;

/// The committed record of long fuzzing runs: a JSON array, one object per run (`target`,
/// `seconds`, `execs`, `corpus_files`, `crashed`; `runs` when one object sums several).
pub fn record_path() -> std::path::PathBuf {
    workspace_root().join("fuzz").join("long-runs.json")
}

/// The runs recorded so far (none when the file is missing).
pub fn read_record() -> Result<Vec<Value>, String> {
    let path = record_path();
    match std::fs::read_to_string(&path) {
        Ok(text) => serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display())),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Vec::new()),
        Err(e) => Err(format!("{}: {e}", path.display())),
    }
}

/// A clap value parser: a fuzz target or `all`.
fn target_arg(s: &str) -> Result<String, String> {
    if s == "all" || TARGETS.contains(&s) {
        Ok(s.to_string())
    } else {
        Err(format!("expected one of {} or all", TARGETS.join(", ")))
    }
}

/// `cargo xtask fuzz`'s options.
#[derive(clap::Args, Debug)]
pub struct FuzzArgs {
    /// The fuzz target (default: all).
    #[arg(value_parser = target_arg, value_name = "TARGET|all")]
    pub target: Option<String>,
    /// Seconds per target.
    #[arg(long, allow_hyphen_values = true, value_parser = clap::value_parser!(u64).range(1..), default_value_t = 60)]
    pub seconds: u64,
}

/// Entry.
pub fn main(a: &FuzzArgs) -> Result<i32, String> {
    let seconds = a.seconds;
    let targets: Vec<&str> = match a.target.as_deref() {
        None | Some("all") => TARGETS.to_vec(),
        Some(t) => TARGETS.iter().copied().filter(|x| *x == t).collect(),
    };
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
        let mut record = read_record()?;
        record.push(entry);
        let text = serde_json::to_string_pretty(&record).map_err(|e| e.to_string())? + "\n";
        std::fs::write(record_path(), text).map_err(|e| e.to_string())?;
        if crashed {
            eprintln!("{log}");
            return Err(format!(
                "fuzz target {target} found a failure (artifacts in fuzz/artifacts/{target}/)"
            ));
        }
    }
    Ok(0)
}
