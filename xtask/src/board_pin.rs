//! The STM32F405's alarm pin, read back from QEMU: netduinoplus2 does not model the GPIO
//! ports (they are "unimplemented devices"), so the firmware's reads of them return 0; QEMU's
//! `-d unimp` log records every write, and the pin's history is rebuilt from the BSRR writes.

use serde_json::json;

/// The alarm output: PA10.
pub const PORT: &str = "GPIOA";
/// Its bit in the port.
pub const PIN: u32 = 10;
/// GPIOx_BSRR's offset (RM0090 §8.4.7): bits 0–15 set a pin, bits 16–31 reset it.
const BSRR: u64 = 0x18;

/// QEMU flags that write the unimplemented-device log to `path`.
pub fn qemu_flags(path: &std::path::Path) -> Vec<String> {
    vec![
        "-d".into(),
        "unimp".into(),
        "-D".into(),
        path.display().to_string(),
    ]
}

/// The pin's level after each BSRR write to its port, in order (a write that leaves the pin
/// alone repeats the level before it).
pub fn levels(log: &str) -> Result<Vec<bool>, String> {
    let prefix = format!("{PORT}: unimplemented device write (size 4, offset ");
    let mut level = false;
    let mut out = Vec::new();
    for line in log.lines() {
        let Some(rest) = line.strip_prefix(&prefix) else {
            continue;
        };
        let (offset, value) = rest
            .trim_end_matches(')')
            .split_once(", value ")
            .ok_or_else(|| format!("unreadable QEMU log line `{line}`"))?;
        let hex = |s: &str| u64::from_str_radix(s.trim_start_matches("0x"), 16);
        let (offset, value) = (hex(offset), hex(value));
        let (Ok(offset), Ok(value)) = (offset, value) else {
            return Err(format!("unreadable QEMU log line `{line}`"));
        };
        if offset != BSRR {
            continue;
        }
        // RM0090: when both are written, the set bit wins.
        if value & (1 << PIN) != 0 {
            level = true;
        } else if value & (1 << (PIN + 16)) != 0 {
            level = false;
        }
        out.push(level);
    }
    Ok(out)
}

/// The pin's summary for a run of `ticks` stepped ticks whose first flag rose on monitor tick
/// `first_flag_tick`: the firmware writes the pin low before the first tick, then once per
/// stepped tick; each overrun `(stepped so far, missed)` moves the monitor's tick on by `missed`.
pub fn report(
    levels: &[bool],
    ticks: u32,
    overruns: &[(u32, u32)],
    first_flag_tick: Option<u32>,
) -> (serde_json::Value, bool) {
    let before = levels.len().saturating_sub(ticks as usize);
    let first_high = levels.iter().position(|&high| high).map(|k| {
        let stepped = (k + 1).saturating_sub(before) as u32;
        let missed: u32 = overruns
            .iter()
            .filter(|&&(at, _)| at < stepped)
            .map(|&(_, n)| n)
            .sum();
        stepped + missed
    });
    let matches = first_high == first_flag_tick;
    let value = json!({
        "pin": format!("P{}{PIN}", &PORT[4..]),
        "bsrr_writes": levels.len(),
        "first_high_tick": first_high,
        "high_at_end": levels.last().copied().unwrap_or(false),
        "matches_flags": matches,
    });
    (value, matches)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bsrr_writes_rebuild_the_pin() {
        let log = "RCC: unimplemented device write (size 4, offset 0x030, value 0x00000001)\n\
            GPIOA: unimplemented device write (size 4, offset 0x018, value 0x04000000)\n\
            GPIOA: unimplemented device write (size 4, offset 0x000, value 0x00100000)\n\
            GPIOA: unimplemented device write (size 4, offset 0x018, value 0x04000000)\n\
            GPIOA: unimplemented device write (size 4, offset 0x018, value 0x00000400)\n\
            GPIOB: unimplemented device write (size 4, offset 0x018, value 0x04000000)\n\
            GPIOA: unimplemented device write (size 4, offset 0x018, value 0x00000001)\n";
        let levels = levels(log).unwrap();
        assert_eq!(levels, [false, false, true, true]);
        // One write before the first tick, then ticks 1–3: the pin rose on tick 2.
        let (v, ok) = report(&levels, 3, &[], Some(2));
        assert!(ok);
        assert_eq!(v["pin"], "PA10");
        assert_eq!(v["high_at_end"], true);
        assert!(!report(&levels, 3, &[], None).1);
        assert!(!report(&levels, 3, &[], Some(3)).1);
        // Two ticks missed after the first: the monitor's tick runs two ahead from there.
        assert!(report(&levels, 3, &[(1, 2)], Some(4)).1);
        assert!(levels_err(
            "GPIOA: unimplemented device write (size 4, offset 0x0zz, value 0x1)"
        ));
    }

    fn levels_err(log: &str) -> bool {
        levels(log).is_err()
    }
}
