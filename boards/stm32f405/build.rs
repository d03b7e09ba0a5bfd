//! Build script: this part's `memory.x`, cortex-m-rt's `link.x` (which takes the interrupt
//! vectors from the PAC's `device.x`) and defmt's `defmt.x` on the thumb link line.

use std::env;
use std::fs;
use std::path::PathBuf;

fn main() -> Result<(), String> {
    println!("cargo:rerun-if-changed=memory.x");
    if env::var("TARGET").is_ok_and(|t| t.starts_with("thumb")) {
        let out = PathBuf::from(env::var_os("OUT_DIR").ok_or("OUT_DIR is not set")?);
        fs::copy("memory.x", out.join("memory.x")).map_err(|e| format!("memory.x: {e}"))?;
        println!("cargo:rustc-link-search={}", out.display());
        for arg in ["--nmagic", "-Tlink.x", "-Tdefmt.x"] {
            println!("cargo:rustc-link-arg-bins={arg}");
        }
    }
    Ok(())
}
