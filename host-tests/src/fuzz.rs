//! Fuzz bodies: what the fuzz targets in `fuzz/` run on each input, shared with the brief
//! stable-toolchain runs in `host-tests/tests/fuzz_brief.rs` so that `cargo xtask test` exercises
//! exactly the code `cargo xtask fuzz` runs for hours.
//!
//! Each body returns `Err` with a description when an invariant breaks; a panic anywhere is a
//! failure by itself (libFuzzer reports it as a crash, the brief test as a failed test).

use noback::monitor::{Config, Estimate, Inputs, Monitor, MARGIN_MAX};
use noback::replay::Replay;

/// Bytes per tick in the monitor target's input.
pub const TICK_BYTES: usize = 11;

/// Decodes one tick: code (u16 LE), motor counter (u32 LE), output counter (u32 LE), control
/// byte (bit 0 drive commanded, bit 1 operator reset after this tick, bit 7 late, bits 2–6 the
/// number of missed ticks − 1 when late).
pub fn decode_tick(chunk: &[u8]) -> Option<(Inputs, bool)> {
    let b: &[u8; TICK_BYTES] = chunk.get(..TICK_BYTES)?.try_into().ok()?;
    let ctrl = b[10];
    let late = if ctrl & 0x80 != 0 {
        ((ctrl >> 2) & 0x1F) + 2
    } else {
        1
    };
    let inputs = Inputs {
        current_adc_code: u16::from_le_bytes([b[0], b[1]]),
        motor_counter: u32::from_le_bytes([b[2], b[3], b[4], b[5]]),
        output_counter: u32::from_le_bytes([b[6], b[7], b[8], b[9]]),
        drive_commanded: ctrl & 1 != 0,
        current_command_code: None,
        ticks_elapsed: late,
    };
    Some((inputs, ctrl & 2 != 0))
}

/// The invariants every estimate keeps, whatever the inputs.
pub fn check_estimate(
    e: &Estimate,
    prev: Option<&Estimate>,
    ticks: u32,
    reset: bool,
) -> Result<(), String> {
    let force = e.pressing_force_n.to_num::<f64>();
    if !(0.0..=32_768.0).contains(&force) {
        return Err(format!(
            "pressing force {force} N out of its format's positive range"
        ));
    }
    if e.capacity_margin < 0
        || e.capacity_margin > MARGIN_MAX
        || e.capacity_margin_low < 0
        || e.capacity_margin_low > e.capacity_margin
    {
        return Err(format!(
            "capacity margin {} (low {}) out of 0 ≤ low ≤ margin ≤ MARGIN_MAX",
            e.capacity_margin, e.capacity_margin_low
        ));
    }
    if let Some(p) = prev {
        if e.friction_energy_j < p.friction_energy_j {
            return Err("friction energy decreased".into());
        }
        if e.tick != p.tick.wrapping_add(ticks) {
            return Err(format!(
                "tick {} after {} with {ticks} elapsed",
                e.tick, p.tick
            ));
        }
        if !reset && e.flags.bits() & p.flags.bits() != p.flags.bits() {
            return Err(format!(
                "a latched flag cleared by itself: {:?} -> {:?}",
                p.flags, e.flags
            ));
        }
    }
    if ticks > 1 && !e.flags.overrun {
        return Err("a late step did not raise overrun".into());
    }
    Ok(())
}

/// Fuzz target `monitor_step`: any byte string as a stream of ticks.
pub fn monitor_step(data: &[u8]) -> Result<usize, String> {
    let mut monitor = Monitor::new(Config::default()).map_err(|e| format!("{e:?}"))?;
    let mut prev: Option<Estimate> = None;
    let mut reset = false;
    let mut steps = 0;
    for chunk in data.chunks_exact(TICK_BYTES) {
        let Some((inputs, reset_after)) = decode_tick(chunk) else {
            break;
        };
        let e = monitor.step(&inputs);
        check_estimate(&e, prev.as_ref(), u32::from(inputs.ticks_elapsed), reset)?;
        reset = reset_after;
        if reset {
            monitor.reset_flags();
        }
        prev = Some(e);
        steps += 1;
    }
    Ok(steps)
}

/// Fuzz target `scene_file`: any bytes as a TOML scene file. Either a clear error or a scene
/// whose numbers are all finite; never a panic.
pub fn scene_file(data: &[u8]) -> Result<bool, String> {
    let text = String::from_utf8_lossy(data);
    match noback_twin::scene::Scene::from_toml("fuzz", &text) {
        Err(e) => {
            if e.to_string().is_empty() {
                return Err("an empty error message".into());
            }
            Ok(false)
        }
        Ok(s) => {
            let numbers = [
                s.load_torque_nm,
                s.initial_speed_rad_s,
                s.duration_s,
                s.tolerance,
                s.mechanism.output_inertia_kg_m2,
                s.mechanism.mu_static,
            ];
            if numbers.iter().all(|x| x.is_finite()) {
                Ok(true)
            } else {
                Err(format!(
                    "accepted a scene with a non-finite number: {numbers:?}"
                ))
            }
        }
    }
}

/// Fuzz target `trace_files`: any bytes as a replay (`NBR1`) and as a trace CSV. Both parsers
/// must answer with a value or an error naming the place; never a panic.
pub fn trace_files(data: &[u8]) -> Result<(), String> {
    if let Ok(replay) = Replay::parse(data) {
        let mut n = 0;
        while replay.record(n).is_some() {
            n += 1;
        }
        if n != replay.len() {
            return Err(format!(
                "replay promised {} records, yielded {n}",
                replay.len()
            ));
        }
    }
    let _ = noback_twin::trace::Trace::parse(&String::from_utf8_lossy(data));
    Ok(())
}

/// What a brief campaign tried.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Campaign {
    /// Inputs tried.
    pub inputs: usize,
    /// Bytes fed in total.
    pub bytes: usize,
    /// Inputs the target accepted (a stream stepped, a scene parsed).
    pub accepted: usize,
    /// Invariant violations, with the input's index.
    pub failures: Vec<(usize, String)>,
}

/// The fuzz targets by name.
pub const TARGETS: [&str; 3] = ["monitor_step", "scene_file", "trace_files"];

fn run_target(target: &str, data: &[u8]) -> Result<bool, String> {
    match target {
        "monitor_step" => monitor_step(data).map(|n| n > 0),
        "scene_file" => scene_file(data),
        "trace_files" => trace_files(data).map(|()| true),
        other => Err(format!("no fuzz target `{other}`")),
    }
}

/// Deterministic bytes: xorshift64*.
struct Bytes(u64);

impl Bytes {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
}

/// Runs `target` on every seed input and on `random` inputs derived from them (random bytes,
/// and seeds with random bytes overwritten, cut or repeated), deterministically from `seed`.
pub fn brief_campaign(target: &str, seeds: &[Vec<u8>], random: usize, seed: u64) -> Campaign {
    let mut c = Campaign::default();
    let mut rng = Bytes(seed | 1);
    let try_one = |c: &mut Campaign, data: &[u8]| {
        let i = c.inputs;
        c.inputs += 1;
        c.bytes += data.len();
        match run_target(target, data) {
            Ok(accepted) => c.accepted += usize::from(accepted),
            Err(e) => c.failures.push((i, e)),
        }
    };
    for s in seeds {
        try_one(&mut c, s);
    }
    for _ in 0..random {
        let len = (rng.next() % 4096) as usize;
        let mut data: Vec<u8> = match seeds.get((rng.next() as usize) % seeds.len().max(1)) {
            Some(base) if !rng.next().is_multiple_of(4) => {
                let mut d = base.clone();
                for _ in 0..1 + rng.next() % 16 {
                    if d.is_empty() {
                        break;
                    }
                    let at = (rng.next() as usize) % d.len();
                    match rng.next() % 3 {
                        0 => d[at] = rng.next() as u8,
                        1 => d.truncate(at),
                        _ => {
                            let tail = d[at..].to_vec();
                            d.extend_from_slice(&tail);
                        }
                    }
                }
                d
            }
            _ => (0..len).map(|_| rng.next() as u8).collect(),
        };
        data.truncate(1 << 16);
        try_one(&mut c, &data);
    }
    c
}
