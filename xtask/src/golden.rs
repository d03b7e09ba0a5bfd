//! `cargo xtask golden` — regenerates the golden traces in `host-tests/golden/` from the twin
//! (physical reading). They are never edited by hand: the host tests check that the twin still
//! writes exactly these bytes, and run the monitor on them.

use crate::replay::twin_trace;
use crate::shell::workspace_root;

/// The scenes with a golden trace (the paper's braking cases, holding and driving; continuous
/// closing is 3 s of trace and is compared on the fly by `cargo xtask monitor`).
pub const GOLDEN_SCENES: [&str; 4] = ["reverse_load", "forward_load", "hold", "drive"];

/// Entry.
pub fn main() -> Result<i32, String> {
    let dir = workspace_root().join("host-tests").join("golden");
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    for scene in GOLDEN_SCENES {
        let trace = twin_trace(scene)?;
        let path = dir.join(format!("{scene}.trace.csv"));
        trace
            .write(&path)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        eprintln!("wrote {} ({} samples)", path.display(), trace.rows.len());
    }
    Ok(0)
}
