//! `cargo xtask run` — the main job: the firmware replays a twin scene at 10 kHz under QEMU.
//!
//! Steps: run the twin on the scene and convert its sensor trace to `NBR1`; build the firmware
//! (release) with the trace embedded; boot it in real time (SysTick at 10 kHz, `-icount` at 16
//! ns an instruction, about a 62 MIPS part) and print its decoded log; boot it again in bench
//! mode (`-icount` at 1 µs an instruction, for sub-instruction SysTick resolution) to count
//! instructions per step; run the same replay on the host; and end with a summary — ticks,
//! overruns, flags with times, estimate against the twin at key moments, instructions per step,
//! flash, RAM, stack, and whether the firmware's estimates equal the host's bit for bit.

use crate::cores::Core;
use crate::replay::{host_run, host_run_tested, nbr1, stress_trace, twin_trace, STRESS};
use crate::shell::workspace_root;
use crate::{bootstrap, elf_size};
use noback::monitor::config_block::{self, CONFIG_BLOCK_BYTES};
use noback::monitor::functional_test::{Procedure, TestConfig};
use noback::monitor::Config;
use noback_twin::scene::SceneKind;
use serde_json::json;

mod image;
mod log_lines;

pub use image::{boot, build, build_bin, build_package_bin};
use log_lines::hex;
pub use log_lines::{background_insns, field, fields, flag_names, line_with, step_insns};

/// In the stress run the operator "resets" the flags this often (ticks), so they keep changing.
pub const STRESS_RESET_EVERY: u32 = 50;

/// Real-time boot: 2^4 ns = 16 ns per instruction.
pub const REALTIME_SHIFT: u32 = 4;
/// The STM32F405's configuration sector (`boards/stm32f405/memory.x`, `CONFIG`).
const CONFIG_SECTOR: u32 = 0x080E_0000;
/// The monitor's tick rate (Hz).
const TICK_HZ: f64 = 10_000.0;
/// Bench boot: 2^10 ns per instruction, 12.8 (M0/M3) or 25.6 (M4F) SysTick ticks each.
pub const BENCH_SHIFT: u32 = 10;

/// `cargo xtask run`'s options.
#[derive(clap::Args, Debug)]
pub struct RunArgs {
    /// A built-in scene, a TOML scene file, or `stress` (synthetic hostile inputs).
    #[arg(long, value_name = "NAME|FILE|stress", default_value = "reverse_load")]
    pub scene: String,
    /// The emulated core.
    #[arg(long, value_parser = crate::core_arg, default_value = "m3", value_name = "m0|m3|m4f|m7")]
    pub core: Core,
    /// A real part instead of an evaluation board: `stm32f405` boots the board crate's image
    /// (stm32f4xx-hal, RTIC) on QEMU's netduinoplus2; it overrides `--core`.
    #[arg(long, value_parser = crate::board_arg, value_name = "stm32f405")]
    pub board: Option<Core>,
    /// Print the summary as one JSON object.
    #[arg(long)]
    pub json: bool,
    /// The monitor's configuration file (docs/commissioning.md), handed
    /// to the firmware as its configuration block; default: uncommissioned.
    #[arg(long, value_name = "FILE")]
    pub config: Option<std::path::PathBuf>,
    /// Burn time in this tick to provoke a missed deadline (the overrun test).
    #[arg(long, value_name = "TICK", allow_hyphen_values = true)]
    pub overrun_at: Option<u32>,
}

/// Writes `trace` as the replay file the firmware streams (target/replay/STEM.nbr1); returns
/// the directory, the scene's stem, the file and its bytes.
pub fn write_replay(
    scene: &str,
    trace: &noback_twin::trace::Trace,
) -> Result<(std::path::PathBuf, String, std::path::PathBuf, Vec<u8>), String> {
    let bytes = nbr1(trace)?;
    let dir = workspace_root().join("target").join("replay");
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let stem = std::path::Path::new(scene)
        .file_stem()
        .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
    let replay_path = dir.join(format!("{stem}.nbr1"));
    std::fs::write(&replay_path, &bytes).map_err(|e| e.to_string())?;
    Ok((dir, stem, replay_path, bytes))
}

/// Entry.
pub fn main(a: &RunArgs) -> Result<i32, String> {
    // A bad scene (no such name or file, a bad value in the file, a parameter combination the
    // twin cannot integrate) is bad input: exit 2 before anything is built.
    if a.scene != STRESS {
        if let Err(e) = noback_twin::cli::load_scene(&a.scene, None) {
            return Ok(noback_twin::args::bad_input("run", &e));
        }
    }
    bootstrap::ensure_all()?;
    let reset_every = (a.scene == STRESS).then_some(STRESS_RESET_EVERY);
    let core = a.board.unwrap_or(a.core);
    let config = match &a.config {
        None => None,
        Some(path) => match crate::monitor::config_from_file(path) {
            Ok(c) => Some(c),
            Err(e) => return Ok(noback_twin::args::bad_input("run", &e)),
        },
    };
    if let Some((kind, test, _)) = functional_test_of(&a.scene) {
        if let Err(e) = test_configuration(config, kind, test) {
            return Ok(noback_twin::args::bad_input("run", &e));
        }
    }
    let (report, ok) =
        match replay_report_with(&a.scene, core, a.overrun_at, reset_every, !a.json, config) {
            // The twin failing on a scene that passed the schema is still the scene's fault.
            Err(e) if e.starts_with("twin: ") => {
                return Ok(noback_twin::args::bad_input("run", &e))
            }
            other => other?,
        };
    if a.json {
        println!("{report}");
    } else {
        print_summary(&report);
    }
    Ok(if ok { 0 } else { 1 })
}

/// The functional test a scene asks for (which, its procedure, and when the crew requests
/// it), if it is a `functional_test` scene.
fn functional_test_of(scene: &str) -> Option<(Procedure, TestConfig, f64)> {
    let s = noback_twin::cli::load_scene(scene, None).ok()?;
    (s.kind == SceneKind::FunctionalTest).then(|| {
        let (kind, test) = host_tests::dormant::procedure_of(&s);
        (kind, test, s.test.start_s)
    })
}

/// The configuration a test scene runs on: a configuration file's (a commissioned unit's
/// acceptance readings), else the defaults with the loaded procedure as the scene sets it. The
/// uncoupled push needs a configuration carrying it.
pub fn test_configuration(
    config: Option<Config>,
    kind: Procedure,
    test: TestConfig,
) -> Result<Config, String> {
    match (config, kind) {
        (Some(c), Procedure::Uncoupled) if c.uncoupled_test.is_some() => Ok(c),
        (_, Procedure::Uncoupled) => Err(format!(
            "a functional_test scene at {} N·m is the uncoupled push: give a --config that carries one (commission the unit with it)",
            test.load_nm
        )),
        (Some(c), Procedure::Loaded) => Ok(c),
        (None, Procedure::Loaded) => Ok(Config {
            functional_test: test,
            ..Config::default()
        }),
    }
}

/// Runs a scene through the firmware under QEMU and the host; returns the summary and whether
/// the run was good (clean exits, bit-exact).
pub fn replay_report(
    scene: &str,
    core: Core,
    overrun_at: Option<u32>,
    reset_every: Option<u32>,
    echo: bool,
) -> Result<(serde_json::Value, bool), String> {
    replay_report_with(scene, core, overrun_at, reset_every, echo, None)
}

/// [`replay_report`] with the firmware given a configuration block (`config=FILE`) and the
/// host's monitor the same configuration.
pub fn replay_report_with(
    scene: &str,
    core: Core,
    overrun_at: Option<u32>,
    reset_every: Option<u32>,
    echo: bool,
    config: Option<Config>,
) -> Result<(serde_json::Value, bool), String> {
    let trace = if scene == STRESS {
        stress_trace()
    } else {
        if echo {
            println!("twin: scene `{scene}` (physical reading)");
        }
        twin_trace(scene)?
    };
    // A functional-test scene: the crew requests the test when its ramp starts.
    let (config, test_at) = match functional_test_of(scene) {
        Some((kind, test, start_s)) => {
            let c = test_configuration(config, kind, test)?;
            let at = (start_s * trace.sample_rate_hz).round() as u32;
            (Some(c), Some((at, kind)))
        }
        None => (config, None),
    };
    let (dir, stem, replay_path, bytes) = write_replay(scene, &trace)?;
    if echo {
        println!(
            "replay: {} samples, {} bytes -> {}",
            trace.rows.len(),
            bytes.len(),
            replay_path.display()
        );
    }

    let elf = build(core)?;
    let trace_arg = format!("trace={}", replay_path.display());
    let mut rt_args = vec!["realtime".to_string(), trace_arg.clone()];
    let mut bench_args = vec!["bench".to_string(), trace_arg];
    // The block: in the part's configuration sector (QEMU's loader writes it into the flash
    // image, as commissioning would), or named over semihosting on the evaluation boards.
    let mut block_flags = Vec::new();
    if let Some(c) = &config {
        let mut block = [0_u8; CONFIG_BLOCK_BYTES];
        let n = config_block::encode(c, &mut block).map_err(|e| format!("config block: {e:?}"))?;
        let path = dir.join(format!("{stem}.nbc"));
        std::fs::write(&path, &block[..n]).map_err(|e| e.to_string())?;
        if core == Core::Stm32f405 {
            block_flags = vec![
                "-device".to_string(),
                format!("loader,file={},addr={CONFIG_SECTOR:#x}", path.display()),
            ];
        } else {
            rt_args.push(format!("config={}", path.display()));
            bench_args.push(format!("config={}", path.display()));
        }
    }
    // The evaluation boards' image writes its trip log's region here at the end.
    let region = dir.join(format!("{stem}-{}.flash", core.name()));
    let _ = std::fs::remove_file(&region);
    let records_trips = core != Core::Stm32f405;
    if records_trips {
        rt_args.push(format!("trip-log={}", region.display()));
    }
    if let Some(n) = overrun_at {
        rt_args.push(format!("overrun-at={n}"));
    }
    if let Some(n) = reset_every {
        rt_args.push(format!("reset-every={n}"));
    }
    match test_at {
        Some((n, Procedure::Loaded)) => rt_args.push(format!("functional-test-at={n}")),
        Some((n, Procedure::Uncoupled)) => rt_args.push(format!("uncoupled-test-at={n}")),
        None => {}
    }
    // The board's GPIO is read back from QEMU's log of its (unmodelled) registers.
    let gpio_log = dir.join(format!("{stem}-{}-gpio.log", core.name()));
    let mut rt_extra = if core == Core::Stm32f405 {
        crate::board_pin::qemu_flags(&gpio_log)
    } else {
        Vec::new()
    };
    rt_extra.extend(block_flags.iter().cloned());
    let realtime = boot(core, &elf, REALTIME_SHIFT, rt_args, echo, &rt_extra)?;
    let bench = boot(core, &elf, BENCH_SHIFT, bench_args, false, &block_flags)?;

    let summary = line_with(&realtime.lines, "summary")?;
    let bench_line = line_with(&bench.lines, "bench")?;
    let overruns: Vec<(u32, u32)> = realtime
        .lines
        .iter()
        .filter(|l| l.split_whitespace().nth(1) == Some("overrun"))
        .map(|l| {
            let f = fields(l);
            Ok((field(&f, "tick")?, field(&f, "missed")?))
        })
        .collect::<Result<_, String>>()?;
    let config = config.unwrap_or_default();
    let host = host_run_tested(&bytes, &overruns, reset_every, config, test_at)?;
    let host_plain = host_run(&bytes, &[], None, config)?;
    let fw_digest = hex(&summary, "digest")?;
    let bench_digest = hex(&bench_line, "digest")?;
    let bit_exact = fw_digest == host.totals.digest && bench_digest == host_plain.totals.digest;

    let ticks: u32 = field(&summary, "ticks")?;
    let (insns_mean, insns_max) = step_insns(&bench_line, core)?;
    let (bg_mean, bg_max) = background_insns(&bench_line, core)?;
    // Worst step per recognised scene (0 where the scene never occurs in this trace).
    let scene_line = line_with(&bench.lines, "bench-scenes")?;
    let per_insn = core.ticks_per_insn(BENCH_SHIFT);
    let mut max_by_scene = serde_json::Map::new();
    for name in ["driving", "holding", "fault_braking", "overrunning"] {
        let ticks: f64 = field::<u32>(&scene_line, name)?.into();
        let at: u32 = field(&scene_line, &format!("{name}_at"))?;
        max_by_scene.insert(
            name.into(),
            json!({"insns": (ticks / per_insn).round(), "at_step": at}),
        );
    }
    let size = elf_size::of_file(&elf)?;
    let flash_bytes = size.flash_bytes;
    let starved = field::<u32>(&summary, "starved")? + field::<u32>(&bench_line, "starved")?;
    let stack_bytes: u32 = field(&summary, "stack_bytes")?;
    let isr_ticks_max: f64 = field::<u32>(&summary, "isr_ticks_max")?.into();
    let background_ticks_max: f64 = field::<u32>(&summary, "background_ticks_max")?.into();
    let period_ticks: f64 = field::<u32>(&summary, "period_ticks")?.into();

    // One time base: a flag raised on tick `n` was raised on the trace's sample `n − 1`, at
    // its time (what `monitor` reports).
    let rate = trace.sample_rate_hz;
    let flags: Vec<_> =
        realtime
            .lines
            .iter()
            .filter(|l| l.split_whitespace().nth(1) == Some("flags"))
            .filter_map(|l| {
                let f = fields(l);
                let tick: u32 = field(&f, "tick").ok()?;
                let before = hex(&f, "before").ok()? as u8;
                let now = hex(&f, "now").ok()? as u8;
                Some(flag_names(now & !before).into_iter().map(
                    move |name| json!({"flag": name, "tick": tick, "t_s": f64::from(tick.saturating_sub(1)) / rate}),
                ))
            })
            .flatten()
            .collect();

    // The estimate against the twin's truth every 0.1 s, from the host run (bit-identical to
    // the firmware's when bit_exact holds). Braking torque as a magnitude, the trace's
    // convention (the monitor's own field is signed, opposing the output's motion).
    let moments: Vec<_> = host
        .estimates
        .iter()
        .zip(&trace.rows)
        .step_by(1000)
        .map(|(e, row)| {
            json!({
                "t_s": (row.t_s * rate).round() / rate,
                "scene": format!("{:?}", e.scene),
                "brake": format!("{:?}", e.brake),
                "pressing_force_n": e.pressing_force_n.to_num::<f64>(),
                "twin_pressing_force_n": row.pressing_force_n,
                "braking_torque_nm": e.braking_torque_nm.to_num::<f64>().abs(),
                "twin_braking_torque_nm": row.braking_torque_nm,
            })
        })
        .collect();

    let isr_insns_max = (isr_ticks_max / core.ticks_per_insn(REALTIME_SHIFT)).round();
    let (alarm_pin, alarm_ok) = if core == Core::Stm32f405 {
        let log = std::fs::read_to_string(&gpio_log)
            .map_err(|e| format!("{}: {e}", gpio_log.display()))?;
        let first_flag = flags
            .first()
            .and_then(|f| f["tick"].as_u64())
            .map(|t| t as u32);
        crate::board_pin::report(
            &crate::board_pin::levels(&log)?,
            ticks,
            &overruns,
            first_flag,
        )
    } else {
        (serde_json::Value::Null, true)
    };
    let flight_hz = core.flight_clock_hz();
    // The trip log read back: on a run without operator resets, one record per flag change.
    let (trip_log, trips_ok) = if records_trips {
        let bytes = std::fs::read(&region).map_err(|e| format!("{}: {e}", region.display()))?;
        let (mut v, _) = crate::trip_log::report(bytes, &flags, config)?;
        let exact = v["replay_bit_exact"] == true;
        let ok = exact && (v["matches_flags"] == true || reset_every.is_some());
        let line = line_with(&realtime.lines, "trip-log")?;
        v["stored"] = json!(field::<u32>(&line, "stored")?);
        v["dropped"] = json!(field::<u32>(&line, "dropped")?);
        (v, ok)
    } else {
        (serde_json::Value::Null, true)
    };
    // The firmware's functional-test line, which must say what the host's test says.
    let (functional_test, test_ok) = match &host.functional_test {
        None => (serde_json::Value::Null, true),
        Some(h) => {
            let line = line_with(&realtime.lines, "functional-test")?;
            let result: String = field(&line, "result")?;
            let procedure: String = field(&line, "procedure")?;
            let num = |k: &str| field::<f64>(&line, k);
            let v = json!({
                "procedure": procedure,
                "result": result,
                "opening_torque_nm": num("opening_nm")?,
                "breakaway_torque_nm": num("breakaway_nm")?,
                "capacity_nm": num("capacity_nm")?,
                "margin": num("margin")?,
            });
            let milli = |q: noback::fx::Q16| (q.to_num::<f64>() * 1e3).round() / 1e3;
            let same = result == format!("{:?}", h.result).to_lowercase()
                && procedure == h.procedure.name()
                && (num("opening_nm")? - milli(h.opening_torque_nm)).abs() < 1.5e-3
                && (num("breakaway_nm")? - milli(h.breakaway_torque_nm)).abs() < 1.5e-3
                && (num("margin")? - milli(h.margin)).abs() < 1.5e-3;
            (v, same)
        }
    };
    // What the firmware announced it runs on: its block, or the uncommissioned defaults.
    let configuration = if realtime
        .lines
        .iter()
        .any(|l| l.contains("configuration from its block"))
    {
        "block"
    } else {
        "uncommissioned"
    };
    let report = json!({
        "scene": scene,
        "core": core.name(),
        "exit_code": realtime.code,
        "ticks": ticks,
        "overruns": field::<u32>(&summary, "overruns")?,
        "missed_ticks": field::<u32>(&summary, "missed")?,
        "stream_starved_ticks": starved,
        "log_overwritten": field::<u32>(&summary, "log_overwritten")?,
        "flags": flags,
        "insns_per_step_mean": (insns_mean * 10.0).round() / 10.0,
        "insns_per_step_max": insns_max.round(),
        "insns_per_step_max_by_scene": max_by_scene,
        "background_insns_per_call_mean": (bg_mean * 10.0).round() / 10.0,
        "background_insns_per_call_max": bg_max.round(),
        "cpu_share_pct_at_100mhz": (insns_mean + bg_mean).round() / 100.0,
        "isr_insns_max": isr_insns_max,
        "flight_clock_mhz": flight_hz / 1e6,
        "isr_deadline_pct_at_flight_clock": (1e5 * isr_insns_max * TICK_HZ / flight_hz).round() / 1e3,
        "alarm_pin": alarm_pin,
        "trip_log": trip_log,
        "functional_test": functional_test,
        "deadline_used_pct": (1000.0 * isr_ticks_max / period_ticks).round() / 10.0,
        "deadline_used_with_background_pct": (1000.0 * background_ticks_max / period_ticks).round() / 10.0,
        "flash_bytes": flash_bytes,
        "replay_bytes": bytes.len(),
        "ram_bytes": size.ram_bytes,
        "stack_bytes_max": stack_bytes,
        "bit_exact": bit_exact,
        "configuration": configuration,
        "firmware_digest": format!("{fw_digest:#010x}"),
        "fx_selfcheck_digest": format!("{:#010x}", crate::test::digest_in(&realtime.lines)?),
        "host_digest": format!("{:#010x}", host.totals.digest),
        "key_moments": moments,
    });
    let ok = realtime.code == 0
        && bench.code == 0
        && bit_exact
        && starved == 0
        && alarm_ok
        && trips_ok
        && test_ok;
    Ok((report, ok))
}

fn print_summary(r: &serde_json::Value) {
    println!("\n=== summary ({} on {}) ===", r["scene"], r["core"]);
    println!(
        "ticks {}  overruns {} (missed ticks {})  stream starved {}  log events overwritten {}",
        r["ticks"],
        r["overruns"],
        r["missed_ticks"],
        r["stream_starved_ticks"],
        r["log_overwritten"]
    );
    let flags = r["flags"].as_array().cloned().unwrap_or_default();
    if flags.is_empty() {
        println!("flags: none");
    }
    for f in flags {
        println!(
            "flag {} raised at t = {} s (tick {})",
            f["flag"], f["t_s"], f["tick"]
        );
    }
    println!(
        "instructions per tick (the 10 kHz interrupt's monitor work): mean {}, max {}; background (PendSV, per call): mean {}, max {} (QEMU -icount, bench boot); monitor CPU share at 100 MHz: {} %",
        r["insns_per_step_mean"],
        r["insns_per_step_max"],
        r["background_insns_per_call_mean"],
        r["background_insns_per_call_max"],
        r["cpu_share_pct_at_100mhz"]
    );
    println!(
        "whole tick (interrupt entry to exit, real-time boot): at most {} instructions, {} % of the 100 µs deadline; with its background work {} %",
        r["isr_insns_max"], r["deadline_used_pct"], r["deadline_used_with_background_pct"]
    );
    println!(
        "flash {} B (replay streamed from the host: {} B), static RAM {} B, stack high-water {} B",
        r["flash_bytes"], r["replay_bytes"], r["ram_bytes"], r["stack_bytes_max"]
    );
    println!("     t_s  scene          brake      force N  (twin)   torque N·m (twin)");
    for m in r["key_moments"].as_array().cloned().unwrap_or_default() {
        println!(
            "{:>8.3}  {:<13} {:<9} {:>8.1} ({:>7.1}) {:>8.2} ({:>7.2})",
            m["t_s"].as_f64().unwrap_or(f64::NAN),
            m["scene"].as_str().unwrap_or(""),
            m["brake"].as_str().unwrap_or(""),
            m["pressing_force_n"].as_f64().unwrap_or(f64::NAN),
            m["twin_pressing_force_n"].as_f64().unwrap_or(f64::NAN),
            m["braking_torque_nm"].as_f64().unwrap_or(f64::NAN),
            m["twin_braking_torque_nm"].as_f64().unwrap_or(f64::NAN),
        );
    }
    println!(
        "bit-exact against the host: {} (firmware {}, host {})",
        r["bit_exact"], r["firmware_digest"], r["host_digest"]
    );
}
