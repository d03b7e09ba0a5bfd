//! Build script: the bench image's thumb link line — the root's `memory.x` (read in place, as
//! `panic-check/` does), cortex-m-rt's `link.x` and defmt's `defmt.x`.

use std::env;
use std::fs;
use std::path::PathBuf;

fn main() -> Result<(), String> {
    println!("cargo:rerun-if-changed=../memory.x");
    if env::var("TARGET").is_ok_and(|t| t.starts_with("thumb")) {
        let out = PathBuf::from(env::var_os("OUT_DIR").ok_or("OUT_DIR is not set")?);
        fs::copy("../memory.x", out.join("memory.x")).map_err(|e| format!("memory.x: {e}"))?;
        println!("cargo:rustc-link-search={}", out.display());
        for arg in ["--nmagic", "-Tlink.x", "-Tdefmt.x"] {
            println!("cargo:rustc-link-arg-bins={arg}");
        }
    }
    Ok(())
}
