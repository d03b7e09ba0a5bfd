//! The reproducibility check of `cargo xtask test`: a page written by its command on an
//! unchanged tree has the same bytes. `reliability` and `paper` must reproduce their committed
//! pages; `monitor-mc` (at its seed, fewer runs, `--no-doc`) must give the same output twice.

use crate::shell::workspace_root;
use std::process::Command;

/// Runs this xtask with `args`; returns its stdout, failing on a non-zero exit.
fn xtask(args: &[&str]) -> Result<String, String> {
    let exe = crate::shell::this_exe()?;
    println!("$ cargo xtask {}", args.join(" "));
    let out = Command::new(exe)
        .args(args)
        .output()
        .map_err(|e| e.to_string())?;
    if !out.status.success() {
        return Err(format!(
            "cargo xtask {} exited {}: {}",
            args.join(" "),
            out.status,
            noback_twin::args::capped(&String::from_utf8_lossy(&out.stderr))
        ));
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

fn same(what: &str, a: &str, b: &str) -> Result<(), String> {
    if a == b {
        println!("{what}: identical ({} bytes)", a.len());
        return Ok(());
    }
    let line = a
        .lines()
        .zip(b.lines())
        .position(|(x, y)| x != y)
        .map_or(a.lines().count().min(b.lines().count()), |i| i);
    Err(format!(
        "{what} does not reproduce: first difference at line {}",
        line + 1
    ))
}

/// The check.
pub fn reproduce() -> Result<(), String> {
    let dir = workspace_root().join("target").join("pages");
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let path = |name: &str| dir.join(name).to_string_lossy().into_owned();

    for (page, command) in [
        ("reliability.md", "reliability"),
        ("paper-comparison.md", "paper"),
    ] {
        let committed = workspace_root().join("docs").join(page);
        let committed = std::fs::read_to_string(&committed)
            .map_err(|e| format!("{}: {e}", committed.display()))?;
        xtask(&[command, "--out", &path(page)])?;
        let now = std::fs::read_to_string(path(page)).map_err(|e| e.to_string())?;
        same(
            &format!("docs/{page} against its command"),
            &committed,
            &now,
        )?;
    }

    let mc = [
        "monitor-mc",
        "--runs",
        "40",
        "--fault-runs",
        "4",
        "--no-doc",
        "--json",
    ];
    let (a, b) = (xtask(&mc)?, xtask(&mc)?);
    same("monitor-mc at its seed, run twice", &a, &b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_difference_names_its_line() {
        assert!(same("t", "a\nb", "a\nc").is_err_and(|e| e.contains("line 2")));
        assert!(same("t", "a", "a").is_ok());
    }
}
