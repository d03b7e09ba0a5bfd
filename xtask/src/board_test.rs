//! `cargo xtask test`'s stage for the board crate (`boards/stm32f405`): lint both builds, build
//! the real-part image, and run the QEMU image (netduinoplus2) through the same checks as the
//! evaluation boards: bit-exact, no overrun, the alarm pin's writes at the flags, a provoked
//! overrun counted. Returns the boot self-check digest for the bit-identity table.

use crate::cores::{Core, BOARD_MANIFEST};
use crate::run;
use crate::shell::{self, cargo};
use crate::test::{fault_scene, overrun_is_counted_and_flagged, SNAPSHOT_SCENE};

const PACKAGE: &str = "noback-stm32f405";
/// Issue 15's budget for the image that flies: flash (code and constants; the configuration
/// sector apart) and static RAM + the stack's static bound.
const FLIGHT_FLASH_BUDGET: u64 = 40 * 1024;
const FLIGHT_RAM_BUDGET: u64 = 4 * 1024;

/// `cargo` on the board crate's own workspace.
fn board_cargo(subcommand: &str) -> std::process::Command {
    let mut cmd = cargo();
    cmd.arg(subcommand)
        .arg("--manifest-path")
        .arg(crate::shell::workspace_root().join(BOARD_MANIFEST));
    cmd
}

/// Runs the stage.
pub fn stage() -> Result<u32, String> {
    let triple = Core::Stm32f405.triple();
    section(&format!("format ({PACKAGE})"));
    shell::run(board_cargo("fmt").args(["--", "--check"]))?;
    for (build, features) in [
        ("QEMU", &["--features", "qemu"][..]),
        ("part", &["--no-default-features", "--features", "hw"][..]),
    ] {
        section(&format!("clippy ({PACKAGE}, {build} build)"));
        shell::run(
            board_cargo("clippy")
                .args(["--target", triple, "--target-dir"])
                .arg(part_dir())
                .args(features)
                .args(["--", "-D", "warnings"]),
        )?;
    }
    section(&format!(
        "build the real part's image ({PACKAGE}, defmt over RTT)"
    ));
    shell::run(
        board_cargo("build")
            .args(["--release", "--target", triple, "--target-dir"])
            .arg(part_dir())
            .args(["--no-default-features", "--features", "hw"]),
    )?;
    let elf = part_dir().join(triple).join("release").join(PACKAGE);
    let size = crate::elf_size::of_file(&elf.to_string_lossy())?;
    println!(
        "the part's image: flash {} B, static RAM {} B (no trace ring, no semihosting; budget {} B, {} B)",
        size.flash_bytes, size.ram_bytes, FLIGHT_FLASH_BUDGET, FLIGHT_RAM_BUDGET
    );
    if size.flash_bytes > FLIGHT_FLASH_BUDGET || size.ram_bytes > FLIGHT_RAM_BUDGET {
        return Err("the part's image is over issue 15's flash or RAM budget".into());
    }
    check_stack_bound(&elf.to_string_lossy(), size.ram_bytes)?;

    section(&format!(
        "STM32F405 replaying `{SNAPSHOT_SCENE}` under QEMU (netduinoplus2)"
    ));
    let (report, ok) = run::replay_report(SNAPSHOT_SCENE, Core::Stm32f405, None, None, false)?;
    print_line(&report);
    if !ok
        || report["overruns"] != 0
        || report["alarm_pin"]["first_high_tick"] != serde_json::Value::Null
    {
        return Err(
            "the STM32F405 image is not bit-exact, overran, or raised its alarm on a healthy scene"
                .into(),
        );
    }
    section("STM32F405: a commissioned unit's block in its configuration sector");
    crate::commissioned::block_is_bit_exact(Core::Stm32f405)?;
    section("STM32F405: a fault scene drives the alarm pin at the flag's tick");
    let (fault, ok) = run::replay_report(&fault_scene()?, Core::Stm32f405, None, None, false)?;
    print_line(&fault);
    let raised = fault["flags"].as_array().is_some_and(|f| !f.is_empty());
    if !ok || !raised || fault["alarm_pin"]["matches_flags"] != true {
        return Err("the STM32F405's alarm pin did not rise at the first flag's tick".into());
    }
    section("STM32F405: provoked overrun");
    let over = overrun_is_counted_and_flagged(Core::Stm32f405)?;
    print_line(&over);
    let digest = report["fx_selfcheck_digest"].as_str().unwrap_or("");
    u32::from_str_radix(digest.trim_start_matches("0x"), 16)
        .map_err(|e| format!("self-check digest: {e}"))
}

/// The part's static stack bound (`stack_bound`) and static RAM against issue 15's budget.
fn check_stack_bound(elf: &str, ram_bytes: u64) -> Result<(), String> {
    let b = crate::stack_bound::bound(elf)?;
    let total = b.total().map(|t| u64::from(t) + ram_bytes);
    println!(
        "the part's image: static RAM + stack {} (budget {FLIGHT_RAM_BUDGET} B)",
        total.map_or("unknown".into(), |t| format!("{t} B")),
    );
    println!("{b}");
    match total {
        Some(t) if t <= FLIGHT_RAM_BUDGET => Ok(()),
        Some(_) => Err("the part's static RAM + stack is over issue 15's budget".into()),
        None => Err("the part's stack has no static bound".into()),
    }
}

fn print_line(r: &serde_json::Value) {
    println!(
        "ticks {}, overruns {} (missed {}), flags {}, alarm pin {}, instructions per tick {} mean / {} max, whole interrupt {} ({} % of 100 µs at 168 MHz), bit-exact {}",
        r["ticks"], r["overruns"], r["missed_ticks"], r["flags"], r["alarm_pin"], r["insns_per_step_mean"], r["insns_per_step_max"], r["isr_insns_max"], r["isr_deadline_pct_at_flight_clock"], r["bit_exact"]
    );
}

/// The part's build has a target directory of its own, so the QEMU image beside it stays built.
fn part_dir() -> std::path::PathBuf {
    crate::shell::workspace_root().join("target").join("part")
}

fn section(title: &str) {
    println!("\n=== {title} ===");
}
