//! The QEMU snapshot test: the flags the firmware raises on the default scene, with their tick
//! numbers, must not move silently. `cargo xtask test --bless` rewrites the snapshot after a
//! change that moves them on purpose; the diff then shows in review.

use crate::shell::workspace_root;
use serde_json::{json, Value};

/// Where the snapshot lives.
fn path() -> std::path::PathBuf {
    workspace_root()
        .join("xtask")
        .join("snapshots")
        .join("run-reverse_load-m3.json")
}

/// The part of a run report that the snapshot pins.
fn pinned(report: &Value) -> Value {
    let flags: Vec<Value> = report["flags"]
        .as_array()
        .into_iter()
        .flatten()
        .map(|f| json!({"flag": f["flag"], "tick": f["tick"]}))
        .collect();
    json!({
        "scene": report["scene"],
        "core": report["core"],
        "ticks": report["ticks"],
        "overruns": report["overruns"],
        "flags": flags,
    })
}

/// Compares a report with the snapshot, or rewrites the snapshot when `bless`.
pub fn check(report: &Value, bless: bool) -> Result<(), String> {
    let now = pinned(report);
    let text = serde_json::to_string_pretty(&now).map_err(|e| e.to_string())? + "\n";
    let file = path();
    if bless {
        if let Some(dir) = file.parent() {
            std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
        }
        std::fs::write(&file, text).map_err(|e| e.to_string())?;
        println!("snapshot: rewrote {}", file.display());
        return Ok(());
    }
    let saved = std::fs::read_to_string(&file).map_err(|e| {
        format!(
            "snapshot {}: {e} (create it with `cargo xtask test --bless`)",
            file.display()
        )
    })?;
    let saved: Value =
        serde_json::from_str(&saved).map_err(|e| format!("snapshot {}: {e}", file.display()))?;
    if saved == now {
        println!("snapshot: {} matches", file.display());
        Ok(())
    } else {
        Err(format!(
            "the QEMU run moved from its snapshot {}:\n  saved: {saved}\n  now:   {now}\n\
             If the change is intended, rerun with `cargo xtask test --bless` and commit the diff.",
            file.display()
        ))
    }
}
