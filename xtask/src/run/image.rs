//! Building the firmware's image and booting it under QEMU.

use crate::cores::{Core, Firmware};
use crate::qemu::{self, Boot, Outcome, BOOT_TIMEOUT};
use crate::shell::{self, cargo, workspace_root};

/// Builds the firmware for `core` in release; returns the ELF path. It streams its trace from
/// the file named by its `trace=FILE` argument.
pub fn build(core: Core) -> Result<String, String> {
    match core.firmware() {
        (Firmware::Package(package), bin) => build_package_bin(package, bin, core, None, &[]),
        (Firmware::Manifest(manifest), bin) => {
            let dir = workspace_root().join("target");
            let manifest = workspace_root().join(manifest);
            shell::run(
                cargo()
                    .args(["build", "--release", "--bin", bin, "--manifest-path"])
                    .arg(&manifest)
                    .args(["--target", core.triple(), "--target-dir"])
                    .arg(&dir),
            )?;
            let elf = dir.join(core.triple()).join("release").join(bin);
            Ok(elf.to_string_lossy().into_owned())
        }
    }
}

/// Builds a target binary of the `noback` package in release for `core` (into `target_dir`,
/// `target/` by default) with extra environment; returns the ELF path.
pub fn build_bin(
    bin: &str,
    core: Core,
    target_dir: Option<&std::path::Path>,
    envs: &[(&str, &std::ffi::OsStr)],
) -> Result<String, String> {
    build_package_bin("noback", bin, core, target_dir, envs)
}

/// [`build_bin`] for a binary of another workspace package (the study crate's bench image).
pub fn build_package_bin(
    package: &str,
    bin: &str,
    core: Core,
    target_dir: Option<&std::path::Path>,
    envs: &[(&str, &std::ffi::OsStr)],
) -> Result<String, String> {
    let dir = target_dir.map_or_else(|| workspace_root().join("target"), std::path::PathBuf::from);
    shell::run(
        cargo()
            .args(["build", "--release", "-p", package, "--bin", bin])
            .args(["--target", core.triple(), "--target-dir"])
            .arg(&dir)
            .envs(envs.iter().copied()),
    )?;
    let elf = dir.join(core.triple()).join("release").join(bin);
    Ok(elf.to_string_lossy().into_owned())
}

/// Boots the firmware once.
pub fn boot(
    core: Core,
    elf: &str,
    shift: u32,
    args: Vec<String>,
    echo: bool,
    more: &[String],
) -> Result<Outcome, String> {
    let mut extra = qemu::icount(shift);
    extra.extend_from_slice(more);
    if echo {
        println!(
            "$ {}",
            shell::describe(&qemu::command(core, elf, &extra, &args))
        );
    }
    let outcome = qemu::boot(&Boot {
        elf,
        core,
        timeout: BOOT_TIMEOUT,
        extra,
        echo,
        args,
    })?;
    if outcome.code != 0 {
        return Err(format!(
            "the firmware exited with code {} on {}",
            outcome.code,
            core.name()
        ));
    }
    Ok(outcome)
}
