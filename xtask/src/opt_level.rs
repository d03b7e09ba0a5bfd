//! `cargo xtask opt-level` — the measurement behind the release profile's `opt-level`.
//!
//! Builds the firmware at each optimisation level for each core (LTO as shipped), reads flash
//! use from the ELF, and counts the instructions of the interrupt's monitor work per tick on the
//! paper's reverse-load trace, streamed, deterministically under QEMU `-icount` (the firmware's
//! bench mode, as `cargo xtask run` does). Writes `docs/results/opt-level.md`.

use crate::cores::Core;
use crate::replay::{nbr1, twin_trace};
use crate::run::{self, BENCH_SHIFT};
use crate::shell::workspace_root;
use crate::{bootstrap, elf_size};
use std::fmt::Write as _;

const LEVELS: [&str; 5] = ["1", "2", "3", "s", "z"];

/// Entry: `opt-level` (no arguments).
pub fn main() -> Result<i32, String> {
    bootstrap::ensure_all()?;
    let replay = workspace_root()
        .join("target")
        .join("replay")
        .join("opt-level.nbr1");
    if let Some(dir) = replay.parent() {
        std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
    }
    let bytes = nbr1(&twin_trace("reverse_load")?)?;
    std::fs::write(&replay, &bytes).map_err(|e| e.to_string())?;
    let mut table = String::from(
        "# Release opt-level, measured\n\nWritten by `cargo xtask opt-level`; do not edit. \
         Firmware `noback-fw` with `lto = \"fat\"`, `codegen-units = 1`, replaying the \
         reverse-load trace; instructions per tick of the 10 kHz interrupt's monitor work (the \
         background not counted) under QEMU `-icount` (bench mode); flash of the QEMU image \
         (trip log, functional test, configuration block decoding; the trace is streamed). \
         Issue 15's 40 KB flash budget is the STM32F405's flight image, which `cargo xtask \
         test` measures at the release profile's level.\n\n\
         | core | opt-level | flash bytes | instructions/step mean | max |\n|---|---|---|---|---|\n",
    );
    let mut m3_best: Option<(&str, f64)> = None;
    for core in Core::ALL {
        for level in LEVELS {
            let dir = workspace_root()
                .join("target")
                .join("opt-level")
                .join(level);
            let elf = run::build_bin(
                "noback-fw",
                core,
                Some(&dir),
                &[("CARGO_PROFILE_RELEASE_OPT_LEVEL", level.as_ref())],
            )?;
            let flash = elf_size::of_file(&elf)?.flash_bytes;
            let args = vec!["bench".into(), format!("trace={}", replay.display())];
            let out = run::boot(core, &elf, BENCH_SHIFT, args, false, &[])?;
            let line = run::line_with(&out.lines, "bench")?;
            let (mean, max) = run::step_insns(&line, core)?;
            if core == Core::M3 && m3_best.is_none_or(|(_, best)| mean < best) {
                m3_best = Some((level, mean));
            }
            println!(
                "{} opt-level={level}: flash {flash} B, {mean:.1} / {max:.0} instructions per step",
                core.name(),
            );
            let _ = writeln!(
                table,
                "| {} | {level} | {flash} | {mean:.1} | {max:.0} |",
                core.name(),
            );
        }
    }
    // Criterion: fewest instructions per step on average on the M3 (the budget's reference
    // core), the same criterion as the first measurement on the fixed-point self-check; the
    // worst cases are listed beside it.
    if let Some((level, insns)) = m3_best {
        let _ = writeln!(
            table,
            "\nFewest instructions per step on average on the M3 (the budget's reference core): \
             opt-level {level} ({insns:.1}); compare the worst cases in the last column before \
             changing it."
        );
    }
    let out = workspace_root().join("docs").join("results");
    std::fs::create_dir_all(&out).map_err(|e| e.to_string())?;
    std::fs::write(out.join("opt-level.md"), table).map_err(|e| e.to_string())?;
    println!("wrote docs/results/opt-level.md");
    Ok(0)
}
