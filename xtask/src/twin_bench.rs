//! `cargo xtask twin-bench [--tolerance TOL] [--no-scipy]` — the twin's speed on each paper
//! scene (release build) against an independent solve of the same equations with scipy's
//! `solve_ivp(method="Radau")` (`bench/radau.py`), in the same run, at the same tolerance.
//! Installs scipy with pip when it is missing (and says so). Writes
//! `docs/results/twin-speed.md`.

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
    let doc = format!(
        "# Twin speed against scipy Radau\n\nWritten by `cargo xtask twin-bench {}`; do not edit. \
         Release build, physical reading, same equations and tolerance on both sides; wall times \
         from one run on the machine that wrote this page (a benchmark, not a test).\n\n{table}",
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
