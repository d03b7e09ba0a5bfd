//! `cargo xtask run` — the main job: build the firmware in release, boot it in QEMU, print its
//! decoded defmt log, and check its self-check digest against the host's.

use crate::cores::Core;
use crate::qemu::{self, Boot, Outcome};
use crate::shell::{self, cargo, workspace_root};
use crate::{bootstrap, test::BOOT_TIMEOUT};

/// Entry: `run [--core m0|m3|m4f]` (default M3 on lm3s6965evb).
pub fn main(args: &[String]) -> Result<i32, String> {
    let mut core = Core::M3;
    let mut it = args.iter();
    while let Some(arg) = it.next() {
        match arg.as_str() {
            "--core" => core = Core::parse(it.next().ok_or("--core needs a value")?)?,
            other => return Err(format!("unknown argument `{other}` (try --core m0|m3|m4f)")),
        }
    }
    bootstrap::ensure_all()?;
    let outcome = build_and_boot(core, true)?;
    let host = noback::vectors::run().digest;
    let target = crate::test::digest_in(&outcome.lines)?;
    println!(
        "\nsummary: core {} exit {}; fixed-point self-check digest {target:#010x} (host {host:#010x}): {}",
        core.name(),
        outcome.code,
        if target == host { "bit-identical" } else { "DIFFERENT" }
    );
    Ok(if outcome.code == 0 && target == host {
        0
    } else {
        1
    })
}

/// Builds `noback-fw` for `core` in release and boots it, echoing the decoded log.
pub fn build_and_boot(core: Core, echo: bool) -> Result<Outcome, String> {
    shell::run(cargo().args([
        "build",
        "--release",
        "-p",
        "noback",
        "--bin",
        "noback-fw",
        "--target",
        core.triple(),
    ]))?;
    let elf = workspace_root()
        .join("target")
        .join(core.triple())
        .join("release")
        .join("noback-fw");
    let elf = elf.to_string_lossy();
    println!("$ {}", shell::describe(&qemu::command(core, &elf, &[])));
    qemu::boot(&Boot {
        elf: &elf,
        core,
        timeout: BOOT_TIMEOUT,
        extra: Vec::new(),
        echo,
    })
}
