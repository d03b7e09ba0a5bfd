//! `cargo xtask opt-level` — the measurement behind the release profile's `opt-level`.
//!
//! Builds the firmware at each optimisation level for each core (LTO as shipped), reads flash
//! use from the ELF and counts the instructions of the fixed-point self-check deterministically
//! under QEMU `-icount`. Writes `docs/results/opt-level.md`. The self-check stands in for the
//! monitor's arithmetic until the monitor's own step is benchmarked (`cargo xtask bench`).

use crate::cores::Core;
use crate::qemu::{self, Boot};
use crate::shell::{self, cargo, workspace_root};
use crate::{bootstrap, elf_size};
use std::fmt::Write as _;
use std::time::Duration;

/// `-icount` shift for counting: 256 ns per instruction keeps the run inside SysTick's 24 bits.
pub const COUNT_SHIFT: u32 = 8;

const LEVELS: [&str; 5] = ["1", "2", "3", "s", "z"];

/// Entry: `opt-level` (no arguments).
pub fn main(_args: &[String]) -> Result<i32, String> {
    bootstrap::ensure_all()?;
    let mut table = String::from(
        "# Release opt-level, measured\n\nWritten by `cargo xtask opt-level`; do not edit. \
         Firmware `noback-fw` with `lto = \"fat\"`, `codegen-units = 1`. Instructions: the \
         fixed-point self-check (`noback::vectors::run`), counted under QEMU `-icount`.\n\n\
         | core | opt-level | flash bytes | self-check instructions |\n|---|---|---|---|\n",
    );
    let mut m3_best: Option<(&str, f64)> = None;
    for core in Core::ALL {
        for level in LEVELS {
            let dir = workspace_root()
                .join("target")
                .join("opt-level")
                .join(level);
            shell::run(
                cargo()
                    .args(["build", "--release", "-p", "noback", "--bin", "noback-fw"])
                    .args(["--target", core.triple(), "--target-dir"])
                    .arg(&dir)
                    .env("CARGO_PROFILE_RELEASE_OPT_LEVEL", level),
            )?;
            let elf = dir.join(core.triple()).join("release").join("noback-fw");
            let elf = elf.to_string_lossy();
            let size = elf_size::of_file(&elf)?;
            let insns = count_selfcheck(core, &elf)?;
            if core == Core::M3 && m3_best.is_none_or(|(_, best)| insns < best) {
                m3_best = Some((level, insns));
            }
            println!(
                "{} opt-level={level}: flash {} B, {insns:.0} instructions",
                core.name(),
                size.flash_bytes
            );
            let _ = writeln!(
                table,
                "| {} | {level} | {} | {insns:.0} |",
                core.name(),
                size.flash_bytes
            );
        }
    }
    // Criterion: fewest instructions on the M3 (the reference core of the budget); flash is far
    // below its budget at every level, so size only breaks ties.
    if let Some((level, insns)) = m3_best {
        let _ = writeln!(
            table,
            "\nFewest instructions on the M3 (the budget's reference core): opt-level {level} \
             ({insns:.0}). Flash is far below the 64 KB budget at every level, so size only breaks ties."
        );
    }
    let out = workspace_root().join("docs").join("results");
    std::fs::create_dir_all(&out).map_err(|e| e.to_string())?;
    std::fs::write(out.join("opt-level.md"), table).map_err(|e| e.to_string())?;
    println!("wrote docs/results/opt-level.md");
    Ok(0)
}

/// Instructions the self-check takes on `core`, from the firmware's SysTick reading.
pub fn count_selfcheck(core: Core, elf: &str) -> Result<f64, String> {
    let outcome = qemu::boot(&Boot {
        elf,
        core,
        timeout: Duration::from_secs(120),
        extra: qemu::icount(COUNT_SHIFT),
        echo: false,
        args: Vec::new(),
    })?;
    let field = |name: &str| -> Option<f64> {
        outcome
            .lines
            .iter()
            .find(|l| l.contains("fx-selfcheck"))
            .and_then(|l| {
                l.split(&format!("{name}="))
                    .nth(1)?
                    .split_whitespace()
                    .next()?
                    .parse()
                    .ok()
            })
    };
    let ticks = field("ticks").ok_or("no ticks= in the self-check line")?;
    let overhead = field("overhead").unwrap_or(0.0);
    Ok((ticks - overhead) / core.ticks_per_insn(COUNT_SHIFT))
}
