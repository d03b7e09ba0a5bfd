//! `cargo xtask profile` — where the monitor's instructions go: the bench boot of `run` under
//! QEMU with one instruction per translation block, every executed address counted, each
//! address resolved with its inlined frames (DWARF, `addr2line`), and the counts summed per
//! stage called from `Monitor::tick` (the 10 kHz interrupt) and `Monitor::background` (the
//! slow lane), per monitor step; monitor functions kept out of line are listed apart (an address
//! does not tell who called them). Deterministic: QEMU runs the same instructions each time.

use crate::cores::Core;
use crate::qemu::{self, Boot};
use crate::replay::twin_trace;
use crate::run::{self, BENCH_SHIFT};
use serde_json::json;
use std::collections::{BTreeMap, HashMap};
use std::io::{BufRead, BufReader};
use std::time::Duration;

/// `cargo xtask profile`'s options.
#[derive(clap::Args, Debug)]
pub struct ProfileArgs {
    /// A built-in scene or a TOML scene file.
    #[arg(long, value_name = "NAME|FILE", default_value = "drive")]
    pub scene: String,
    /// The emulated core.
    #[arg(long, value_parser = crate::core_arg, default_value = "m3", value_name = "m0|m3|m4f|m7")]
    pub core: Core,
    /// Print the profile as one JSON object.
    #[arg(long)]
    pub json: bool,
    /// Also list the N hottest source lines of the tick (innermost workspace frame, per step;
    /// `tick_lines` in the JSON).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub lines: usize,
}

/// The monitor's two entry points; a frame inside one of them is a stage of that lane.
const LANES: [(&str, &str); 2] = [
    ("tick", "noback::monitor::Monitor::tick"),
    ("background", "noback::monitor::Monitor::background"),
];

/// Monitor functions the compiler kept out of line: called from a lane, or from the bench
/// harness (which builds monitors and checksums estimates).
const OUT_OF_LINE: &str = "out of line (a lane, or the bench harness)";

/// A singlestepped boot logs ≈ 20 000 instructions a step: the drive scene takes minutes.
const PROFILE_TIMEOUT: Duration = Duration::from_secs(1800);

pub fn main(a: &ProfileArgs) -> Result<i32, String> {
    let trace = match twin_trace(&a.scene) {
        Ok(t) => t,
        Err(e) => return Ok(noback_twin::args::bad_input("profile", &e)),
    };
    let (dir, stem, replay, _) = run::write_replay(&a.scene, &trace)?;
    let elf = run::build(a.core)?;
    let fifo = dir.join(format!("{stem}-{}.exec", a.core.name()));
    let _ = std::fs::remove_file(&fifo);
    crate::shell::run(std::process::Command::new("mkfifo").arg(&fifo))?;
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || count_addresses(&fifo))
    };
    let mut extra = qemu::icount(BENCH_SHIFT);
    extra.extend(["-singlestep", "-d", "exec,nochain", "-D"].map(String::from));
    extra.push(fifo.to_string_lossy().into_owned());
    let outcome = qemu::boot(&Boot {
        elf: &elf,
        core: a.core,
        timeout: PROFILE_TIMEOUT,
        extra,
        echo: false,
        args: vec!["bench".into(), format!("trace={}", replay.display())],
    })?;
    let counts = reader
        .join()
        .map_err(|_| "the address counter panicked")??;
    let _ = std::fs::remove_file(&fifo);
    let bench = run::line_with(&outcome.lines, "bench")?;
    let steps: u64 = run::field(&bench, "steps")?;
    let (lanes, lines) = by_stage(&elf, &counts, a.lines > 0)?;
    let lines = &lines[..a.lines.min(lines.len())];
    let per_step = |n: u64| (n as f64 / steps.max(1) as f64 * 10.0).round() / 10.0;
    if a.json {
        let mut out = serde_json::Map::new();
        for (lane, stages) in &lanes {
            let total: u64 = stages.values().sum();
            let by: serde_json::Map<_, _> = stages
                .iter()
                .map(|(s, n)| (s.clone(), json!(per_step(*n))))
                .collect();
            out.insert(
                lane.to_string(),
                json!({"insns_per_step": per_step(total), "stages": by}),
            );
        }
        out.insert("scene".into(), json!(a.scene));
        out.insert("core".into(), json!(a.core.name()));
        out.insert("steps".into(), json!(steps));
        if a.lines > 0 {
            let rows: Vec<_> = lines
                .iter()
                .map(|(line, n)| json!({"line": line, "insns_per_step": per_step(*n)}))
                .collect();
            out.insert("tick_lines".into(), json!(rows));
        }
        println!("{}", serde_json::Value::Object(out));
        return Ok(0);
    }
    println!(
        "profile of the monitor, scene `{}` on {} ({steps} steps; instructions per step, QEMU bench boot):",
        a.scene,
        a.core.name()
    );
    for (lane, stages) in &lanes {
        let total: u64 = stages.values().sum();
        println!("{lane}: {}", per_step(total));
        let mut rows: Vec<_> = stages.iter().collect();
        rows.sort_by(|x, y| y.1.cmp(x.1).then(x.0.cmp(y.0)));
        for (stage, n) in rows.into_iter().filter(|(_, n)| per_step(**n) >= 1.0) {
            println!("  {:>7.1}  {stage}", per_step(*n));
        }
    }
    if a.lines > 0 {
        println!(
            "hottest lines of the tick (instructions per step, innermost frame in this workspace):"
        );
        for (line, n) in lines {
            println!("  {:>7.1}  {line}", per_step(*n));
        }
    }
    Ok(0)
}

/// Executions per address, from QEMU's `exec` log (`Trace N: HOST [CPU/PC/FLAGS/…] NAME`).
fn count_addresses(path: &std::path::Path) -> Result<HashMap<u32, u64>, String> {
    let file = std::fs::File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut counts = HashMap::new();
    for line in BufReader::with_capacity(1 << 20, file).lines() {
        let line = line.map_err(|e| e.to_string())?;
        if let Some(pc) = exec_address(&line) {
            *counts.entry(pc).or_insert(0) += 1;
        }
    }
    Ok(counts)
}

/// The guest address of one `exec` log line.
fn exec_address(line: &str) -> Option<u32> {
    let (_, rest) = line.split_once('[')?;
    let pc = rest.split('/').nth(1)?;
    u32::from_str_radix(pc, 16).ok()
}

/// Counts summed per lane and stage: the stage is the frame called from the lane's entry
/// point (with its hash and crate path cut), or the entry's own code.
/// With `lines`, also the tick's counts per source line ([`crate_line`]), hottest first.
fn by_stage(
    elf: &str,
    counts: &HashMap<u32, u64>,
    lines: bool,
) -> Result<(Lanes, Vec<(String, u64)>), String> {
    let loader = addr2line::Loader::new(elf).map_err(|e| format!("{elf}: {e}"))?;
    let mut lanes = Lanes::new();
    let mut tick_lines: HashMap<String, u64> = HashMap::new();
    for (&pc, &n) in counts {
        let names = frame_names(&loader, u64::from(pc))?;
        // The outermost frame that is a lane's entry point (frames run innermost first).
        let Some((at, lane)) = names.iter().enumerate().rev().find_map(|(i, name)| {
            LANES
                .iter()
                .find(|(_, entry)| name == entry)
                .map(|(lane, _)| (i, *lane))
        }) else {
            // A monitor function not inlined into its caller: no lane is known from the address.
            if let Some(f) = names.last().filter(|f| f.starts_with("noback::monitor::")) {
                *lanes
                    .entry(OUT_OF_LINE)
                    .or_default()
                    .entry(short(f))
                    .or_insert(0) += n;
            }
            continue;
        };
        let stage = match at.checked_sub(1).and_then(|i| names.get(i)) {
            Some(inner) => short(inner),
            None => format!("({lane}'s own code)"),
        };
        *lanes.entry(lane).or_default().entry(stage).or_insert(0) += n;
        if lines && lane == LANES[0].0 {
            *tick_lines
                .entry(crate_line(&loader, u64::from(pc))?)
                .or_insert(0) += n;
        }
    }
    let mut rows: Vec<_> = tick_lines.into_iter().collect();
    rows.sort_by(|x, y| y.1.cmp(&x.1).then(x.0.cmp(&y.0)));
    Ok((lanes, rows))
}

/// Counts per lane and stage.
type Lanes = BTreeMap<&'static str, BTreeMap<String, u64>>;

/// `file:line` of `pc`'s innermost frame in the workspace's code (not the standard library's).
fn crate_line(loader: &addr2line::Loader, pc: u64) -> Result<String, String> {
    let mut frames = loader.find_frames(pc).map_err(|e| e.to_string())?;
    while let Some(frame) = frames.next().map_err(|e| e.to_string())? {
        let Some(l) = frame.location else { continue };
        let file = l.file.unwrap_or("?");
        if file.contains("/rustc/")
            || file.contains("/library/")
            || file.contains(".cargo/registry")
        {
            continue;
        }
        let file = file.rsplit_once("/src/").map_or(file, |(_, f)| f);
        return Ok(format!("{file}:{}", l.line.unwrap_or(0)));
    }
    Ok("?".into())
}

/// The function names of `pc`'s frames, innermost first, without their hashes.
fn frame_names(loader: &addr2line::Loader, pc: u64) -> Result<Vec<String>, String> {
    let mut frames = loader.find_frames(pc).map_err(|e| e.to_string())?;
    let mut names = Vec::new();
    while let Some(frame) = frames.next().map_err(|e| e.to_string())? {
        if let Some(f) = frame.function {
            let name = f.demangle().map_err(|e| e.to_string())?;
            names.push(without_hash(&name).to_string());
        }
    }
    Ok(names)
}

/// `path::to::f::h0123456789abcdef` → `path::to::f`.
fn without_hash(name: &str) -> &str {
    match name.rsplit_once("::h") {
        Some((head, hash)) if hash.len() == 16 && hash.bytes().all(|b| b.is_ascii_hexdigit()) => {
            head
        }
        _ => name,
    }
}

/// The last two path segments (`Observe::update`), generic arguments dropped.
fn short(name: &str) -> String {
    let mut plain = String::new();
    let mut depth = 0_u32;
    for c in name.chars() {
        match c {
            '<' => depth += 1,
            '>' => depth = depth.saturating_sub(1),
            _ if depth == 0 => plain.push(c),
            _ => {}
        }
    }
    let parts: Vec<&str> = plain
        .rsplit("::")
        .filter(|p| !p.is_empty())
        .take(2)
        .collect();
    parts.into_iter().rev().collect::<Vec<_>>().join("::")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_exec_line_gives_its_guest_address() {
        let line = "Trace 0: 0x7f42e0000100 [00800400/00000400/00000110/ff020201] Reset";
        assert_eq!(exec_address(line), Some(0x400));
        assert_eq!(exec_address("chain 1182"), None);
    }

    #[test]
    fn names_lose_their_hash_and_path() {
        assert_eq!(
            without_hash("noback::monitor::Monitor::tick::hb733388895ee7da2"),
            "noback::monitor::Monitor::tick"
        );
        assert_eq!(without_hash("a::hash::h12"), "a::hash::h12");
        assert_eq!(
            short("noback::monitor::observe::Observe::update"),
            "Observe::update"
        );
        assert_eq!(
            short("noback::monitor::scale::Scale<_>::apply"),
            "Scale::apply"
        );
        assert_eq!(short("<i32>::saturating_add"), "saturating_add");
    }
}
