//! Build script: puts `memory.x` and the link scripts (cortex-m-rt's `link.x`, defmt's
//! `defmt.x`) on the thumb targets' link line, and places the
//! replay trace the firmware embeds at `$OUT_DIR/replay.bin` (from `$NOBACK_REPLAY`, which
//! `cargo xtask run` sets; an empty trace otherwise).

use std::env;
use std::fs;
use std::path::PathBuf;

/// An `NBR1` header with zero records (see `src/replay.rs`).
const EMPTY_TRACE: [u8; 16] = [
    b'N', b'B', b'R', b'1', 0, 0, 0, 0, 0x10, 0x27, 0, 0, 0, 0, 0, 0,
];

fn main() -> Result<(), String> {
    let out = PathBuf::from(env::var_os("OUT_DIR").ok_or("OUT_DIR is not set")?);
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-env-changed=NOBACK_REPLAY");
    if env::var("TARGET").is_ok_and(|t| t.starts_with("thumb")) {
        fs::copy("memory.x", out.join("memory.x")).map_err(|e| format!("memory.x: {e}"))?;
        println!("cargo:rustc-link-search={}", out.display());
        for arg in ["--nmagic", "-Tlink.x", "-Tdefmt.x"] {
            println!("cargo:rustc-link-arg={arg}");
        }
    }
    let replay = out.join("replay.bin");
    match env::var_os("NOBACK_REPLAY") {
        Some(path) => {
            println!("cargo:rerun-if-changed={}", path.to_string_lossy());
            fs::copy(&path, &replay)
                .map_err(|e| format!("NOBACK_REPLAY={}: {e}", path.to_string_lossy()))?;
        }
        None => {
            fs::write(&replay, EMPTY_TRACE).map_err(|e| format!("{}: {e}", replay.display()))?
        }
    }
    Ok(())
}
