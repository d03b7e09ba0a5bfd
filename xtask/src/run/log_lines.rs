//! Reading the firmware's decoded log: a line's `key=value` fields, the flags it names, and the
//! bench line's instruction counts.

use crate::cores::Core;
use noback::monitor::Flags;
use std::collections::BTreeMap;

use super::BENCH_SHIFT;

/// `key=value` fields of a decoded log line.
pub fn fields(line: &str) -> BTreeMap<&str, &str> {
    line.split_whitespace()
        .filter_map(|token| token.split_once('='))
        .collect()
}

pub fn field<T: std::str::FromStr>(line: &BTreeMap<&str, &str>, key: &str) -> Result<T, String> {
    let raw = line
        .get(key)
        .ok_or_else(|| format!("no `{key}=` in the firmware's line"))?;
    let raw = raw.trim_start_matches("0x");
    raw.parse()
        .or_else(|_| {
            u64::from_str_radix(raw, 16)
                .map_err(|_| ())
                .and_then(|v| v.to_string().parse().map_err(|_| ()))
        })
        .map_err(|()| format!("`{key}={raw}` is not a number"))
}

pub fn hex(line: &BTreeMap<&str, &str>, key: &str) -> Result<u32, String> {
    let raw = line
        .get(key)
        .ok_or_else(|| format!("no `{key}=` in the firmware's line"))?;
    u32::from_str_radix(raw.trim_start_matches("0x"), 16)
        .map_err(|_| format!("`{key}={raw}` is not hex"))
}

/// The line of `lines` whose message starts with `word`.
pub fn line_with<'a>(
    lines: &'a [String],
    word: &str,
) -> Result<BTreeMap<&'a str, &'a str>, String> {
    lines
        .iter()
        .find(|l| l.split_whitespace().nth(1) == Some(word))
        .map(|l| fields(l))
        .ok_or_else(|| format!("the firmware printed no `{word}` line"))
}

pub fn flag_names(bits: u8) -> Vec<&'static str> {
    Flags::from_bits(bits)
        .named()
        .into_iter()
        .filter_map(|(on, name)| on.then_some(name))
        .collect()
}

/// Mean and largest instructions per step from a bench line's `steps`, `ticks_sum` and
/// `ticks_max` (SysTick ticks under `-icount shift=BENCH_SHIFT` on `core`).
pub fn step_insns(line: &BTreeMap<&str, &str>, core: Core) -> Result<(f64, f64), String> {
    insns_per_call(line, core, "ticks")
}

/// The same per `Monitor::background` call, from `bg_ticks_sum` and `bg_ticks_max`.
pub fn background_insns(line: &BTreeMap<&str, &str>, core: Core) -> Result<(f64, f64), String> {
    insns_per_call(line, core, "bg_ticks")
}

/// Mean and largest instructions per call from a bench line's `steps`, `{key}_sum`, `{key}_max`.
fn insns_per_call(
    line: &BTreeMap<&str, &str>,
    core: Core,
    key: &str,
) -> Result<(f64, f64), String> {
    let steps: f64 = field::<u32>(line, "steps")?.into();
    let sum = field::<u64>(line, &format!("{key}_sum"))? as f64;
    let max: f64 = field::<u32>(line, &format!("{key}_max"))?.into();
    let per = core.ticks_per_insn(BENCH_SHIFT);
    Ok((sum / steps.max(1.0) / per, max / per))
}
