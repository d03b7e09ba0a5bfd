//! The reproducibility check of `cargo xtask test`: a page written by its command on an
//! unchanged tree has the same bytes. `reliability` must reproduce its committed page; `paper`
//! and `monitor-mc` (at its seed, fewer runs, `--no-doc`) must give the same output twice.

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

/// A page's text less any table column headed `wall` (the paper page's solver wall times,
/// which its owner is moving to a benchmark page; drop this once they are gone).
fn without_wall_times(page: &str) -> String {
    let mut wall: Option<usize> = None;
    page.lines()
        .map(|line| {
            if !line.starts_with('|') {
                wall = None;
                return line.to_string();
            }
            let cells: Vec<&str> = line.split('|').collect();
            if wall.is_none() {
                wall = cells.iter().position(|c| c.trim().starts_with("wall"));
            }
            match wall {
                Some(at) => cells
                    .iter()
                    .enumerate()
                    .filter(|(i, _)| *i != at)
                    .map(|(_, c)| *c)
                    .collect::<Vec<_>>()
                    .join("|"),
                None => line.to_string(),
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
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

    let committed = workspace_root().join("docs").join("reliability.md");
    let committed =
        std::fs::read_to_string(&committed).map_err(|e| format!("{}: {e}", committed.display()))?;
    xtask(&["reliability", "--out", &path("reliability.md")])?;
    let now = std::fs::read_to_string(path("reliability.md")).map_err(|e| e.to_string())?;
    same("docs/reliability.md against its command", &committed, &now)?;

    let mut paper = Vec::new();
    for name in ["paper-1.md", "paper-2.md"] {
        xtask(&["paper", "--out", &path(name)])?;
        let text = std::fs::read_to_string(path(name)).map_err(|e| e.to_string())?;
        paper.push(without_wall_times(&text));
    }
    same("paper page written twice", &paper[0], &paper[1])?;

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
    fn only_the_wall_column_is_dropped() {
        let page = "x\n| a | wall (s) | b |\n|---|---|---|\n| 1 | 0.5 | 2 |\n\n| c |\n| 3 |";
        assert_eq!(
            without_wall_times(page),
            "x\n| a | b |\n|---|---|\n| 1 | 2 |\n\n| c |\n| 3 |"
        );
        assert!(same("t", "a\nb", "a\nc").is_err_and(|e| e.contains("line 2")));
    }
}
