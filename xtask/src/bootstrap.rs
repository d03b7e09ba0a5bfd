//! First-run setup, printed as it happens: the thumb targets and `qemu-system-arm`.
//!
//! `RUSTUP_AUTO_INSTALL=0` on our machines means `rust-toolchain.toml` installs nothing by
//! itself, so the xtask adds missing targets. QEMU comes from Debian's packages, installed only
//! when missing and when we are root; otherwise we stop and name the package. A second run
//! only checks.

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
            .current_dir(workspace_root()),
    )
}

/// Installs `qemu-system-arm` with apt-get when it is missing and we are root.
pub fn ensure_qemu() -> Result<(), String> {
    if shell::on_path("qemu-system-arm") {
        return Ok(());
    }
    let root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0");
    if !root {
        return Err(
            "qemu-system-arm is missing: install Debian's package `qemu-system-arm` \
             (e.g. `sudo apt-get install --no-install-recommends qemu-system-arm`) and rerun"
                .into(),
        );
    }
    eprintln!("bootstrap: qemu-system-arm is missing; installing it from Debian's packages");
    let quiet = [("DEBIAN_FRONTEND", "noninteractive")];
    shell::run(Command::new("apt-get").arg("update").envs(quiet))?;
    shell::run(
        Command::new("apt-get")
            .args([
                "install",
                "-y",
                "--no-install-recommends",
                "qemu-system-arm",
            ])
            .envs(quiet),
    )?;
    if shell::on_path("qemu-system-arm") {
        Ok(())
    } else {
        Err("apt-get installed qemu-system-arm but it is not on PATH".into())
    }
}
