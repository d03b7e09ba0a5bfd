//! First-run setup, printed as it happens: the thumb targets and `qemu-system-arm` (and, for the
//! Slurm stage of the tests, Debian's `slurm-wlm` and `munge`).
//!
//! `RUSTUP_AUTO_INSTALL=0` on our machines means `rust-toolchain.toml` installs nothing by
//! itself, so the xtask adds missing targets. QEMU comes from Debian's packages, installed only
//! when missing and when we are root; otherwise we stop and name the package. A second run
//! only checks. Installers print to stderr: stdout stays the command's own (`--json`).

use crate::cores::Core;
use crate::shell::{self, workspace_root};
use std::process::Command;

/// Makes sure every target and QEMU are present.
pub fn ensure_all() -> Result<(), String> {
    ensure_targets()?;
    ensure_qemu()
}

/// Adds the thumb targets that `rustup` does not list as installed for the pinned toolchain.
pub fn ensure_targets() -> Result<(), String> {
    let listed = Command::new("rustup")
        .args(["target", "list", "--installed"])
        .current_dir(workspace_root())
        .output()
        .map_err(|e| format!("running rustup: {e} (noback needs rustup to add thumb targets)"))?;
    let installed = String::from_utf8_lossy(&listed.stdout);
    let missing: Vec<&str> = Core::ALL
        .iter()
        .map(|c| c.triple())
        .filter(|t| !installed.lines().any(|l| l.trim() == *t))
        .collect();
    if missing.is_empty() {
        return Ok(());
    }
    eprintln!("bootstrap: adding rustup targets {}", missing.join(" "));
    shell::run(
        Command::new("rustup")
            .args(["target", "add"])
            .args(&missing)
            .current_dir(workspace_root())
            .stdout(std::io::stderr()),
    )
}

/// Installs `qemu-system-arm` with apt-get when it is missing and we are root.
pub fn ensure_qemu() -> Result<(), String> {
    if shell::on_path("qemu-system-arm") {
        return Ok(());
    }
    apt_install(&["qemu-system-arm"], "qemu-system-arm")?;
    if shell::on_path("qemu-system-arm") {
        Ok(())
    } else {
        Err("apt-get installed qemu-system-arm but it is not on PATH".into())
    }
}

/// Where a daemon or tool is: on PATH, or in `/usr/sbin` (not on every root's PATH).
pub fn program(name: &str) -> Option<std::path::PathBuf> {
    if shell::on_path(name) {
        return Some(name.into());
    }
    let sbin = std::path::Path::new("/usr/sbin").join(name);
    sbin.is_file().then_some(sbin)
}

/// The Slurm daemons and commands and munge, for the Slurm stage of `cargo xtask test`.
pub const SLURM_PROGRAMS: [&str; 8] = [
    "slurmctld",
    "slurmd",
    "sbatch",
    "squeue",
    "sinfo",
    "scontrol",
    "munged",
    "mungekey",
];

/// Installs Debian's `slurm-wlm` and `munge` with apt-get when any Slurm program is missing.
pub fn ensure_slurm() -> Result<(), String> {
    let missing = || SLURM_PROGRAMS.iter().any(|p| program(p).is_none());
    if !missing() {
        return Ok(());
    }
    apt_install(&["slurm-wlm", "munge"], "slurmctld, slurmd or munged")?;
    if missing() {
        Err(format!(
            "apt-get installed slurm-wlm and munge but one of {SLURM_PROGRAMS:?} is missing"
        ))
    } else {
        Ok(())
    }
}

/// `apt-get install -y --no-install-recommends PACKAGES` as root (`apt-get update` first, once
/// per run); otherwise stops and names the packages.
fn apt_install(packages: &[&str], what: &str) -> Result<(), String> {
    static UPDATED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);
    let root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0");
    let list = packages.join(" ");
    if !root {
        return Err(format!(
            "{what} is missing: install Debian's {list} \
             (e.g. `sudo apt-get install --no-install-recommends {list}`) and rerun"
        ));
    }
    eprintln!("bootstrap: {what} is missing; installing {list} from Debian's packages");
    let quiet = [("DEBIAN_FRONTEND", "noninteractive")];
    if !UPDATED.swap(true, std::sync::atomic::Ordering::Relaxed) {
        shell::run(
            Command::new("apt-get")
                .arg("update")
                .envs(quiet)
                .stdout(std::io::stderr()),
        )?;
    }
    shell::run(
        Command::new("apt-get")
            .args(["install", "-y", "--no-install-recommends"])
            .args(packages)
            .envs(quiet)
            .stdout(std::io::stderr()),
    )
}
