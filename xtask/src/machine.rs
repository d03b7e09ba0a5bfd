//! The machine a benchmark page ran on, as the page states it: wall times are true only of it.

use std::fmt;

/// The CPU model, the cores the OS reports and the load average when the benchmark started.
pub struct Machine {
    pub cpu: String,
    pub cores: usize,
    pub load: String,
}

/// This machine, now.
pub fn this() -> Machine {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|v| v.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string());
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    Machine {
        cpu,
        cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
        load: load.split_whitespace().next().unwrap_or("?").to_string(),
    }
}

impl fmt::Display for Machine {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}, {} cores as the OS reports them, load average {} when it started",
            self.cpu, self.cores, self.load
        )
    }
}
