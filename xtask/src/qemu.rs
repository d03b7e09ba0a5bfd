//! `cargo xtask qemu ELF` — boots a firmware or target-test ELF under QEMU (the cargo runner).
//!
//! It picks the board from the target triple in the ELF's path (or `--core`), decodes defmt
//! from semihosting stdout, passes QEMU's exit code through (semihosting exit), and ends a hung
//! QEMU after `--timeout` seconds with exit code 124 and a message: QEMU killed by a signal
//! would otherwise exit 0.

use crate::cores::Core;
use crate::defmt_log::LogTable;
use std::io::Read;
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// How long one firmware boot may take before it counts as hung.
pub const BOOT_TIMEOUT: Duration = Duration::from_secs(60);

/// Exit code for a run that QEMU did not finish in time.
pub const EXIT_TIMEOUT: i32 = 124;

/// How to boot one image.
pub struct Boot<'a> {
    /// Path of the ELF.
    pub elf: &'a str,
    /// Core to emulate.
    pub core: Core,
    /// Wall-clock limit.
    pub timeout: Duration,
    /// Extra QEMU flags (e.g. `-icount`).
    pub extra: Vec<String>,
    /// Print decoded lines as they arrive.
    pub echo: bool,
    /// Arguments the firmware reads over semihosting (after its own name).
    pub args: Vec<String>,
}

/// What a boot produced.
pub struct Outcome {
    /// QEMU's exit code (the firmware's semihosting exit code), or [`EXIT_TIMEOUT`].
    pub code: i32,
    /// Decoded defmt lines.
    pub lines: Vec<String>,
}

/// The QEMU command line for `core` booting `elf` with semihosting arguments `args`.
pub fn command(core: Core, elf: &str, extra: &[String], args: &[String]) -> Command {
    let (machine, cpu) = core.machine_cpu();
    let mut semihosting = String::from("enable=on,target=native");
    if !args.is_empty() {
        semihosting.push_str(",arg=firmware");
        for arg in args {
            semihosting.push_str(",arg=");
            semihosting.push_str(arg);
        }
    }
    let mut cmd = Command::new("qemu-system-arm");
    cmd.args(["-machine", machine, "-cpu", cpu])
        .args(["-nographic", "-monitor", "none", "-serial", "none"])
        .args(["-semihosting-config", &semihosting])
        .args(extra)
        .args(["-kernel", elf]);
    cmd
}

/// QEMU flags that make virtual time advance exactly 2^`shift` ns per executed instruction, so
/// SysTick counts instructions deterministically (see `Core::ticks_per_insn`).
pub fn icount(shift: u32) -> Vec<String> {
    vec![
        "-icount".into(),
        format!("shift={shift},align=off,sleep=off"),
    ]
}

/// Boots an image and decodes its log.
pub fn boot(boot: &Boot<'_>) -> Result<Outcome, String> {
    let elf_bytes = std::fs::read(boot.elf).map_err(|e| format!("reading {}: {e}", boot.elf))?;
    let log_table = LogTable::from_elf(&elf_bytes)?;
    let mut decoder = log_table.decoder();
    let mut child = command(boot.core, boot.elf, &boot.extra, &boot.args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("starting qemu-system-arm: {e} (run `cargo xtask bootstrap`)"))?;
    let mut stdout = child.stdout.take().ok_or("qemu stdout was not captured")?;
    if let Some(stderr) = child.stderr.take() {
        std::thread::spawn(move || forward_stderr(stderr));
    }
    let (tx, rx) = mpsc::channel::<Vec<u8>>();
    let reader = std::thread::spawn(move || {
        let mut buf = [0_u8; 4096];
        while let Ok(n) = stdout.read(&mut buf) {
            if n == 0 || tx.send(buf.get(..n).unwrap_or_default().to_vec()).is_err() {
                break;
            }
        }
    });
    let started = Instant::now();
    let mut lines = Vec::new();
    let mut take = |chunk: Vec<u8>, lines: &mut Vec<String>| {
        for line in decoder.feed(&chunk) {
            if boot.echo {
                println!("{line}");
            }
            lines.push(line);
        }
    };
    let code = loop {
        while let Ok(chunk) = rx.try_recv() {
            take(chunk, &mut lines);
        }
        if let Some(status) = child.try_wait().map_err(|e| e.to_string())? {
            break status.code().unwrap_or(EXIT_TIMEOUT);
        }
        if started.elapsed() > boot.timeout {
            let _ = child.kill();
            let _ = child.wait();
            eprintln!(
                "xtask qemu: {} did not finish within {:.0} s on {}; killed (exit {EXIT_TIMEOUT})",
                boot.elf,
                boot.timeout.as_secs_f64(),
                boot.core.name()
            );
            break EXIT_TIMEOUT;
        }
        if let Ok(chunk) = rx.recv_timeout(Duration::from_millis(20)) {
            take(chunk, &mut lines);
        }
    };
    let _ = reader.join();
    while let Ok(chunk) = rx.try_recv() {
        take(chunk, &mut lines);
    }
    if decoder.malformed > 0 {
        eprintln!("xtask qemu: {} malformed defmt frame(s)", decoder.malformed);
    }
    Ok(Outcome { code, lines })
}

/// QEMU's own messages, less the lm3s6965evb's harmless "Timer with period zero" notice.
fn forward_stderr(stderr: std::process::ChildStderr) {
    use std::io::BufRead;
    for line in std::io::BufReader::new(stderr)
        .lines()
        .map_while(Result::ok)
    {
        if line != "Timer with period zero, disabling" {
            eprintln!("qemu: {line}");
        }
    }
}

/// A clap value parser: a positive, finite number of seconds.
fn positive_seconds(s: &str) -> Result<f64, String> {
    match noback_twin::args::finite(s)? {
        t if t > 0.0 => Ok(t),
        _ => Err("must be > 0".into()),
    }
}

/// `cargo xtask qemu`'s options (it is the cargo runner: cargo appends test-harness arguments
/// after the ELF, which defmt-test does not take).
#[derive(clap::Args, Debug)]
pub struct QemuArgs {
    /// The image to boot.
    pub elf: String,
    /// The emulated core (default: from the target triple in the ELF's path).
    #[arg(long, value_parser = crate::core_arg, value_name = "m0|m3|m4f|m7")]
    pub core: Option<Core>,
    /// Wall-clock limit in seconds; a run past it ends with exit 124.
    #[arg(long, allow_hyphen_values = true, value_parser = positive_seconds, default_value_t = 60.0, value_name = "S")]
    pub timeout: f64,
    /// Count instructions: 2^SHIFT ns of virtual time each, 0..=10.
    #[arg(long, allow_hyphen_values = true, value_parser = clap::value_parser!(u32).range(0..=10), value_name = "SHIFT")]
    pub icount: Option<u32>,
    /// Test-harness arguments cargo passes after the ELF (ignored).
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, hide = true)]
    pub harness: Vec<String>,
}

/// The runner entry.
pub fn main(a: &QemuArgs) -> Result<i32, String> {
    let core = a.core.or_else(|| Core::from_path(&a.elf));
    let Some(core) = core else {
        return Ok(noback_twin::args::bad_input(
            "qemu",
            &format!(
                "cannot tell the core from `{}`: pass --core m0|m3|m4f|m7",
                noback_twin::args::short(&a.elf)
            ),
        ));
    };
    if !std::path::Path::new(&a.elf).is_file() {
        return Ok(noback_twin::args::bad_input(
            "qemu",
            &format!("`{}` is not a file", noback_twin::args::short(&a.elf)),
        ));
    }
    let outcome = boot(&Boot {
        elf: &a.elf,
        core,
        timeout: Duration::from_secs_f64(a.timeout),
        extra: a.icount.map(icount).unwrap_or_default(),
        echo: true,
        args: Vec::new(),
    })?;
    Ok(outcome.code)
}
