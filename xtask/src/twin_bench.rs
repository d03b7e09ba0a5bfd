//! `cargo xtask twin-bench [--tolerance TOL] [--no-scipy] [--json]` — the twin's speed and
//! worst error against its converged reference on each paper scene (release build), beside an
//! independent solve of the same equations with scipy's `solve_ivp(method="Radau")`
//! (`bench/radau.py`). Installs scipy with pip when it is missing (and says so). Writes
//! `docs/results/twin-speed.md` (a benchmark page naming its machine); `--json` only prints.

use crate::shell::{self, cargo, workspace_root};
use std::process::Command;

/// Entry.
pub fn main(args: &[String]) -> Result<i32, String> {
    let scipy = !args.iter().any(|a| a == "--no-scipy");
    if scipy {
        let have = Command::new("python3")
            .args(["-c", "import scipy"])
            .status()
            .is_ok_and(|s| s.success());
        if !have {
            eprintln!("twin-bench: scipy is missing; installing it with pip");
            shell::run(Command::new("python3").args(["-m", "pip", "install", "--quiet", "scipy"]))?;
        }
    }
    let mut cmd = cargo();
    cmd.args([
        "run",
        "--quiet",
        "--release",
        "-p",
        "noback-twin",
        "--features",
        "peer",
        "--example",
        "bench",
        "--",
    ])
    .args(args);
    eprintln!("$ {}", shell::describe(&cmd));
    let out = cmd
        .output()
        .map_err(|e| format!("starting the twin bench: {e}"))?;
    let table = String::from_utf8_lossy(&out.stdout);
    print!("{table}");
    if !out.status.success() {
        eprintln!("{}", String::from_utf8_lossy(&out.stderr));
        return Err("the twin bench failed".into());
    }
    if args.iter().any(|a| a == "--json") {
        return Ok(0);
    }
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|c| {
            c.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let doc = format!(
        "# Twin speed against scipy Radau (benchmark page)\n\nWritten by `cargo xtask twin-bench {}`; do not edit. \
         Release build, physical reading, same equations and tolerance on both sides. Wall times \
         from one run on {cpu} ({cores} cores, shared): a benchmark, not a test, and they change \
         from run to run. Errors are against the converged references \
         (`twin/tests/reference/converged.json`, tolerance 1e-10; braking time and angle, the \
         metrics both sides report); a speed ratio is given only where both sides hold them within 1 % (continuous closing has \
         neither, so no ratio).\n\n{table}",
        args.join(" ")
    );
    let path = workspace_root()
        .join("docs")
        .join("results")
        .join("twin-speed.md");
    std::fs::write(&path, doc).map_err(|e| format!("{}: {e}", path.display()))?;
    eprintln!("wrote {}", path.display());
    Ok(0)
}
