//! Build script: this part's `memory.x`, cortex-m-rt's `link.x` (which takes the interrupt
//! vectors from the PAC's `device.x`) and defmt's `defmt.x` on the thumb link line; and the
//! uncommissioned configuration block (`Config::default()` converted here, not on the part).

use std::env;
use std::fs;
use std::path::PathBuf;

use noback::monitor::config_block::{encode, CONFIG_BLOCK_BYTES};
use noback::monitor::Config;

fn main() -> Result<(), String> {
    println!("cargo:rerun-if-changed=memory.x");
    let out = PathBuf::from(env::var_os("OUT_DIR").ok_or("OUT_DIR is not set")?);
    let mut block = [0_u8; CONFIG_BLOCK_BYTES];
    let n = encode(&Config::default(), &mut block).map_err(|e| format!("default block: {e:?}"))?;
    let block = block.get(..n).ok_or("default block: length")?;
    fs::write(out.join("uncommissioned.nbc"), block).map_err(|e| format!("default block: {e}"))?;
    if env::var("TARGET").is_ok_and(|t| t.starts_with("thumb")) {
        fs::copy("memory.x", out.join("memory.x")).map_err(|e| format!("memory.x: {e}"))?;
        println!("cargo:rustc-link-search={}", out.display());
        for arg in ["--nmagic", "-Tlink.x", "-Tdefmt.x"] {
            println!("cargo:rustc-link-arg-bins={arg}");
        }
    }
    Ok(())
}
