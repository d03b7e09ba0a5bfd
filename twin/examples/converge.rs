//! Convergence study (issue 18): every metric of every built-in scene in both readings at
//! tolerances 1e-4 … 1e-10. Writes `twin/tests/reference/converged.json` (the committed
//! references) and `docs/results/convergence.md`. Heavy (minutes): run it niced, not in tests.
//!
//! `cargo run --release -p noback-twin --example converge`
use noback_twin::convergence::{self, Entry};
use noback_twin::reading::Reading;
use noback_twin::scene::SceneKind;

fn main() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let mut all: Vec<Entry> = Vec::new();
    for reading in [Reading::Paper, Reading::Physical] {
        for kind in SceneKind::ALL {
            eprintln!("converge: {} {}", kind.name(), reading.name());
            match convergence::study(kind, reading) {
                Ok(e) => all.extend(e),
                Err(e) => {
                    eprintln!("error: {} {}: {e}", kind.name(), reading.name());
                    std::process::exit(1);
                }
            }
        }
    }
    let json = match serde_json::to_string_pretty(&all) {
        Ok(j) => j,
        Err(e) => {
            eprintln!("error: json: {e}");
            std::process::exit(1);
        }
    };
    let jpath = format!("{root}/twin/tests/reference/converged.json");
    let mpath = format!("{root}/docs/results/convergence.md");
    for (path, text) in [(&jpath, json + "\n"), (&mpath, convergence::markdown(&all))] {
        if let Err(e) = std::fs::write(path, text) {
            eprintln!("error: cannot write {path}: {e}");
            std::process::exit(1);
        }
        eprintln!("wrote {path}");
    }
}
