//! `cargo xtask log record|dump|replay` and `cargo xtask power-fail`: the trip log on the host.
//!
//! `log record` runs a scene through the twin and the monitor with the trip recorder and the
//! store on a simulated STM32F405 flash region (four 16 KB sectors), and writes the region's
//! bytes — what a ground crew reads off an ECU; `log dump` decodes a region's records;
//! `log replay FILE --record K` replays record K from its saved state and must end on the
//! recorded estimate, bit for bit. `power-fail` is the power-loss test (`host_tests::power_fail`).

use crate::shell::workspace_root;
use host_tests::sim_flash::{SimFlash, F405_SECTOR};
use noback::monitor::{Config, Flags, Inputs, Monitor};
use noback::trip_log::record::{decode, Record};
use noback::trip_log::store::Store;
use noback::trip_log::Recorder;
use noback_twin::args::bad_input;
use serde_json::json;
use std::path::PathBuf;

/// Sectors of the trip log's region.
pub const SECTORS: usize = 4;

type Flash = SimFlash<F405_SECTOR>;

/// `log`'s subcommands.
#[derive(clap::Subcommand, Debug)]
pub enum LogCmd {
    /// Run a scene on the host with the trip recorder; write the flash region's bytes.
    Record {
        /// A built-in scene or a TOML scene file.
        scene: String,
        /// Where the region goes (default target/trip-log/SCENE.flash).
        #[arg(long)]
        out: Option<PathBuf>,
        /// The unit's configuration file (`cargo xtask commission`'s; default: uncommissioned).
        #[arg(long)]
        config: Option<PathBuf>,
    },
    /// Decode the records of a flash region.
    Dump {
        /// A flash region's bytes (`log record`'s output).
        file: PathBuf,
        /// Print the records as one JSON array.
        #[arg(long)]
        json: bool,
    },
    /// Replay one record from its saved state; it must end on its estimate, bit for bit.
    Replay {
        /// A flash region's bytes.
        file: PathBuf,
        /// The record's index in `log dump`'s list.
        #[arg(long, default_value_t = 0)]
        record: usize,
        /// The configuration the unit ran (its record names its digest; default: uncommissioned).
        #[arg(long)]
        config: Option<PathBuf>,
    },
}

/// `cargo xtask log`'s options.
#[derive(clap::Args, Debug)]
pub struct LogArgs {
    #[command(subcommand)]
    pub cmd: LogCmd,
}

fn store(flash: Flash) -> Result<Store<Flash>, String> {
    Store::new(flash, 0..(SECTORS * F405_SECTOR) as u32).map_err(|e| format!("store: {e:?}"))
}

/// Entry of `log`.
pub fn main(a: &LogArgs) -> Result<i32, String> {
    match &a.cmd {
        LogCmd::Record { scene, out, config } => match unit_config(config.as_deref()) {
            Ok(c) => record(scene, out.as_ref(), c),
            Err(e) => Ok(bad_input("log", &e)),
        },
        LogCmd::Dump { file, json } => {
            let records = match read(file) {
                Ok(r) => r,
                Err(e) => return Ok(bad_input("log", &e)),
            };
            let rows: Vec<_> = records
                .iter()
                .filter_map(|b| decode(b).ok())
                .map(|r| describe(&r))
                .collect();
            if *json {
                println!("{}", serde_json::Value::Array(rows));
            } else {
                println!("{} records in {}", rows.len(), file.display());
                for (k, r) in rows.iter().enumerate() {
                    println!(
                        "{k}: tick {} (t = {} s) {} → {}, window {} inputs, state {} B, configuration {}",
                        r["tick"], r["t_s"], r["before"].as_str().unwrap_or(""), r["now"].as_str().unwrap_or(""),
                        r["window_inputs"], r["state_bytes"], r["config_digest"].as_str().unwrap_or("")
                    );
                }
            }
            Ok(0)
        }
        LogCmd::Replay {
            file,
            record,
            config,
        } => {
            let records = match read(file) {
                Ok(r) => r,
                Err(e) => return Ok(bad_input("log", &e)),
            };
            let Some(bytes) = records.get(*record) else {
                return Ok(bad_input(
                    "log",
                    &format!(
                        "--record {record}: the region holds {} records",
                        records.len()
                    ),
                ));
            };
            // A record replays only on the configuration it names (or a corrupt one not at all).
            let replayed = unit_config(config.as_deref()).and_then(|c| replay(bytes, c));
            match replayed {
                Ok((same, line)) => {
                    println!("{line}");
                    Ok(if same { 0 } else { 1 })
                }
                Err(e) => Ok(bad_input("log", &e)),
            }
        }
    }
}

/// Replays one record on `config` (the one the unit ran); returns whether it reproduced its
/// estimate and a line saying so.
pub fn replay(bytes: &[u8], config: Config) -> Result<(bool, String), String> {
    let r = decode(bytes).map_err(|e| format!("record: {e:?}"))?;
    let digest = Monitor::new(config)
        .map_err(|e| format!("{e:?}"))?
        .settings_digest();
    if digest != r.config_digest {
        return Err(format!(
            "the record's configuration digest {:#010x} is not that of the configuration it replays on, {digest:#010x}",
            r.config_digest
        ));
    }
    let last = r.replay(config).map_err(|e| format!("replay: {e:?}"))?;
    let same = last.to_words() == r.estimate && last.flags == r.now && last.tick == r.tick;
    Ok((
        same,
        format!(
            "record at tick {}: {} → {} over {} inputs from its saved state: {}",
            r.tick,
            names(r.before),
            names(r.now),
            r.window_len(),
            if same {
                "reproduced bit-exact"
            } else {
                "DIFFERENT"
            }
        ),
    ))
}

fn names(f: Flags) -> String {
    let n = crate::run::flag_names(f.bits());
    if n.is_empty() {
        "none".into()
    } else {
        n.join("+")
    }
}

fn describe(r: &Record<'_>) -> serde_json::Value {
    json!({
        "tick": r.tick,
        "t_s": f64::from(r.tick.saturating_sub(1)) / 10_000.0,
        "before": names(r.before),
        "now": names(r.now),
        "window_inputs": r.window_len(),
        "state_bytes": r.state.len(),
        "config_digest": format!("{:#010x}", r.config_digest),
    })
}

/// The firmware's region under QEMU: four 4 KB pages of RAM (`src/bin/noback-fw.rs`).
pub const QEMU_PAGE: usize = 4 * 1024;

/// The records of a region file, oldest first.
fn read(file: &PathBuf) -> Result<Vec<Vec<u8>>, String> {
    let bytes = std::fs::read(file).map_err(|e| format!("{}: {e}", file.display()))?;
    read_region(bytes).map_err(|e| format!("{}: {e}", file.display()))
}

/// The records of a region's bytes, by its size: four 16 KB sectors (`log record`) or four
/// 4 KB pages (the firmware under QEMU).
pub fn read_region(bytes: Vec<u8>) -> Result<Vec<Vec<u8>>, String> {
    match bytes.len() {
        n if n == SECTORS * F405_SECTOR => read_pages::<F405_SECTOR>(bytes),
        n if n == SECTORS * QEMU_PAGE => read_pages::<QEMU_PAGE>(bytes),
        n => Err(format!(
            "not a trip-log region ({n} bytes, expected {} or {})",
            SECTORS * F405_SECTOR,
            SECTORS * QEMU_PAGE
        )),
    }
}

fn read_pages<const PAGE: usize>(bytes: Vec<u8>) -> Result<Vec<Vec<u8>>, String> {
    let len = bytes.len() as u32;
    let mut s =
        Store::new(SimFlash::<PAGE>::from_bytes(bytes), 0..len).map_err(|e| format!("{e:?}"))?;
    let mut out = Vec::new();
    let mut buf = vec![0_u8; PAGE];
    s.for_each(&mut buf, |item| out.push(item.to_vec()))
        .map_err(|e| format!("{e:?}"))?;
    Ok(out)
}

/// The `trip_log` of a run's report: each record's tick, the flags it raised and whether it
/// replays bit-exact on the run's `config`; and whether the raisings equal `flags`
/// (`[{flag, tick}]`).
pub fn report(
    region: Vec<u8>,
    flags: &[serde_json::Value],
    config: Config,
) -> Result<(serde_json::Value, bool), String> {
    let mut entries = Vec::new();
    let mut raised = Vec::new();
    let mut all_exact = true;
    for bytes in read_region(region)? {
        let r = decode(&bytes).map_err(|e| format!("trip record: {e:?}"))?;
        let (exact, _) = replay(&bytes, config)?;
        all_exact &= exact;
        let new = Flags::from_bits(r.now.bits() & !r.before.bits());
        for name in crate::run::flag_names(new.bits()) {
            raised.push((name.to_string(), u64::from(r.tick)));
        }
        entries.push(json!({
            "tick": r.tick,
            "before": names(r.before),
            "now": names(r.now),
            "window_inputs": r.window_len(),
            "replay_bit_exact": exact,
        }));
    }
    let expected: Vec<(String, u64)> = flags
        .iter()
        .map(|f| {
            let name = f["flag"].as_str().unwrap_or("").to_string();
            (name, f["tick"].as_u64().unwrap_or(0))
        })
        .collect();
    let matches = raised == expected;
    let v = json!({"records": entries, "matches_flags": matches, "replay_bit_exact": all_exact});
    Ok((v, matches && all_exact))
}

/// A configuration file's monitor, else the uncommissioned defaults.
fn unit_config(file: Option<&std::path::Path>) -> Result<Config, String> {
    file.map_or(Ok(Config::default()), crate::monitor::config_from_file)
}

/// The records of a host run of `scene` on `config` (a record at each flag change) and the
/// region.
pub fn record_scene(scene: &str, config: Config) -> Result<(Vec<Vec<u8>>, Vec<u8>), String> {
    let s = noback_twin::cli::load_scene(scene, None)?;
    let trace = host_tests::accuracy::scene_trace(&s)?;
    let mut monitor = Monitor::new(config).map_err(|e| format!("{e:?}"))?;
    let mut recorder = Recorder::<{ noback::trip_log::RING_INPUTS }>::new();
    let mut st = store(Flash::new(SECTORS))?;
    let mut records = Vec::new();
    let mut before = Flags::default();
    let mut buf = vec![0_u8; 8192];
    for r in &trace.rows {
        let inputs = Inputs::new(r.current_code, r.motor_count, r.output_count, r.drive_on);
        recorder.before_step(&monitor, &inputs);
        let e = monitor.step(&inputs);
        if e.flags != before {
            let bytes = recorder
                .record(&mut buf, &e, before)
                .map_err(|e| format!("{e:?}"))?;
            st.push(bytes).map_err(|e| format!("store: {e:?}"))?;
            records.push(bytes.to_vec());
        }
        before = e.flags;
    }
    Ok((records, st.into_flash().bytes))
}

fn record(scene: &str, out: Option<&PathBuf>, config: Config) -> Result<i32, String> {
    if let Err(e) = noback_twin::cli::load_scene(scene, None) {
        return Ok(bad_input("log", &e));
    }
    let (records, region) = record_scene(scene, config)?;
    let stem = std::path::Path::new(scene)
        .file_stem()
        .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
    let path = out.cloned().unwrap_or_else(|| {
        workspace_root()
            .join("target")
            .join("trip-log")
            .join(format!("{stem}.flash"))
    });
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
    }
    std::fs::write(&path, region).map_err(|e| format!("{}: {e}", path.display()))?;
    println!(
        "{} records ({} bytes largest) -> {}",
        records.len(),
        records.iter().map(Vec::len).max().unwrap_or(0),
        path.display()
    );
    Ok(0)
}

/// `cargo xtask power-fail`'s options.
#[derive(clap::Args, Debug)]
pub struct PowerFailArgs {
    /// Print the figures as one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// Entry of `power-fail`: exit 1 if a record was lost or read corrupt.
pub fn power_fail(a: &PowerFailArgs) -> Result<i32, String> {
    let records = host_tests::power_fail::sample_records(14)?;
    let f = host_tests::power_fail::run(&records)?;
    let v = json!({
        "cuts": f.cuts,
        "records_lost": f.records_lost,
        "corrupt_reads": f.corrupt_reads,
        "in_flight_whole": f.in_flight_whole,
        "in_flight_absent": f.in_flight_absent,
        "stopped_working": f.stopped_working,
        "overflow": {"pushed": f.pushed, "kept": f.kept, "dropped_oldest": f.dropped},
        "record_bytes_max": f.record_bytes,
        "flash_steps": f.steps,
        "words_programmed_per_record": (f.words_per_record * 10.0).round() / 10.0,
        "erases_per_record": (f.erases_per_record * 1000.0).round() / 1000.0,
        "page_bytes": host_tests::power_fail::PAGE,
        "pages": host_tests::power_fail::PAGES,
    });
    if a.json {
        println!("{v}");
    } else {
        println!(
            "power cut at every one of {} steps: records lost {}, corrupt reads {}, the record in flight whole {} / absent {}, store stopped working {}; overflow: {} pushed, {} kept, {} oldest dropped",
            f.cuts, f.records_lost, f.corrupt_reads, f.in_flight_whole, f.in_flight_absent, f.stopped_working, f.pushed, f.kept, f.dropped
        );
    }
    Ok(
        if f.records_lost == 0 && f.corrupt_reads == 0 && f.stopped_working == 0 {
            0
        } else {
            1
        },
    )
}
