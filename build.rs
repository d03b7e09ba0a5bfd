//! Build script: puts `memory.x` and the link scripts (cortex-m-rt's `link.x`, defmt's
//! `defmt.x`) on the thumb targets' link line. (The firmware no longer embeds a trace: it
//! streams one from the host, see `src/replay.rs`.)

use std::env;
use std::fs;
use std::path::PathBuf;

fn main() -> Result<(), String> {
    let out = PathBuf::from(env::var_os("OUT_DIR").ok_or("OUT_DIR is not set")?);
    println!("cargo:rerun-if-changed=memory.x");
    // ARMv6-M has no 32×32→64 multiply: `fx::widening_mul` forms it from 16-bit halves there.
    println!("cargo::rustc-check-cfg=cfg(armv6m)");
    if env::var("TARGET").is_ok_and(|t| t.starts_with("thumbv6m")) {
        println!("cargo::rustc-cfg=armv6m");
    }
    if env::var("TARGET").is_ok_and(|t| t.starts_with("thumb")) {
        fs::copy("memory.x", out.join("memory.x")).map_err(|e| format!("memory.x: {e}"))?;
        println!("cargo:rustc-link-search={}", out.display());
        for arg in ["--nmagic", "-Tlink.x", "-Tdefmt.x"] {
            println!("cargo:rustc-link-arg={arg}");
        }
    }
    Ok(())
}
