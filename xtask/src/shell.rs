//! Running other programs: print each command before it runs, fail with its name on error.

use std::path::PathBuf;
use std::process::Command;

/// An error message for the user; every xtask failure ends as one of these.
pub type Error = String;

/// The workspace root (the parent of `xtask/`).
pub fn workspace_root() -> PathBuf {
    let manifest = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    manifest.parent().map(PathBuf::from).unwrap_or(manifest)
}

/// `cargo` as the user invoked it (respects `$CARGO`, set by cargo for its subcommands).
pub fn cargo() -> Command {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut cmd = Command::new(cargo);
    cmd.current_dir(workspace_root());
    cmd
}

/// Describes a command the way a user would type it.
pub fn describe(cmd: &Command) -> String {
    let mut s = cmd.get_program().to_string_lossy().into_owned();
    if s.ends_with("/cargo") {
        s = "cargo".into();
    }
    for arg in cmd.get_args() {
        s.push(' ');
        s.push_str(&arg.to_string_lossy());
    }
    s
}

/// Runs `cmd` with inherited stdio, printing it first; an error names it if it fails.
pub fn run(cmd: &mut Command) -> Result<(), Error> {
    let text = describe(cmd);
    eprintln!("$ {text}");
    let status = cmd
        .status()
        .map_err(|e| format!("could not start `{text}`: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("`{text}` failed ({status})"))
    }
}

/// Whether `program` is found on `PATH`.
pub fn on_path(program: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|paths| std::env::split_paths(&paths).any(|dir| dir.join(program).is_file()))
}

/// Runs a `cargo build` and returns `(target name, executable path)` for every executable it
/// produced, read from cargo's JSON messages.
pub fn built_executables(cmd: &mut Command) -> Result<Vec<(String, String)>, Error> {
    cmd.args(["--message-format", "json-render-diagnostics"])
        .stdout(std::process::Stdio::piped());
    let text = describe(cmd);
    eprintln!("$ {text}");
    let out = cmd
        .output()
        .map_err(|e| format!("could not start `{text}`: {e}"))?;
    if !out.status.success() {
        return Err(format!("`{text}` failed ({})", out.status));
    }
    let mut found = Vec::new();
    for line in String::from_utf8_lossy(&out.stdout).lines() {
        let Ok(msg) = serde_json::from_str::<serde_json::Value>(line) else {
            continue;
        };
        if let (Some(name), Some(exe)) =
            (msg["target"]["name"].as_str(), msg["executable"].as_str())
        {
            found.push((name.to_string(), exe.to_string()));
        }
    }
    Ok(found)
}

/// This xtask's executable, to run it again. `cargo test --workspace` (a stage of `xtask test`)
/// relinks `target/debug/xtask` for the command-line tests, after which Linux names the running
/// image `… (deleted)`; the file now at its path is built from the same sources.
pub fn this_exe() -> Result<PathBuf, Error> {
    let exe = std::env::current_exe().map_err(|e| format!("this executable: {e}"))?;
    let name = exe.to_string_lossy();
    Ok(match name.strip_suffix(" (deleted)") {
        Some(path) => PathBuf::from(path),
        None => exe,
    })
}
