//! Twin traces for the firmware: conversion of the twin's CSV trace to the `NBR1` replay file
//! the firmware embeds, and the host run of the same replay through the same `Ticker` — the
//! reference the firmware's digest must equal bit for bit.

pub use host_tests::accuracy::twin_trace;

/// A recorded trace (`.csv`, the twin's format) as it is, else a scene (built-in or file) run
/// through the twin, with the scene; the error names the input (`monitor`, `commission`).
pub fn trace_of(target: &str) -> Result<(Trace, Option<noback_twin::scene::Scene>), String> {
    if target.ends_with(".csv") {
        return Trace::read(std::path::Path::new(target))
            .map(|t| (t, None))
            .map_err(|e| format!("{}: {e}", noback_twin::args::short(target)));
    }
    let scene = noback_twin::cli::load_scene(target, None)?;
    Ok((host_tests::accuracy::scene_trace(&scene)?, Some(scene)))
}
use noback::app::{Ticker, Totals};
use noback::monitor::functional_test::{Procedure, TestReport};
use noback::monitor::{Config, Estimate, Inputs, Monitor};
use noback::replay::{encode_header, encode_record, Replay};
use noback_twin::trace::Trace;

/// Name of the synthetic stress replay (`cargo xtask run --scene stress`).
pub const STRESS: &str = "stress";

/// A synthetic second of hostile inputs for the load test: the drive flag toggling every 37
/// ticks, the current sweeping rail to rail and sitting on a rail, the output encoder jumping,
/// the motor counter stalling. Truth columns are zero (there is no physics behind it).
pub fn stress_trace() -> Trace {
    let rows = (0..10_000_u32)
        .map(|i| {
            let drive = (i / 37) % 2 == 0;
            let sweep = (i % 200) * 4095 / 199;
            let code = if i % 500 < 40 { 4095 } else { sweep };
            let out = (i + 3000 * (i / 1000)) % (1 << 14);
            let motor = if drive { (i * 8) % (1 << 16) } else { 0 };
            noback_twin::trace::TraceRow {
                t_s: f64::from(i) * 1e-4,
                current_code: code as u16,
                motor_count: motor,
                output_count: out,
                drive_on: drive,
                ..Default::default()
            }
        })
        .collect();
    Trace {
        sample_rate_hz: 10_000.0,
        rows,
    }
}

/// The `NBR1` bytes of a trace.
pub fn nbr1(trace: &Trace) -> Result<Vec<u8>, String> {
    let count = u32::try_from(trace.rows.len()).map_err(|_| "trace too long")?;
    let mut bytes = encode_header(count, trace.sample_rate_hz.round() as u32).to_vec();
    for (i, row) in trace.rows.iter().enumerate() {
        let inputs = Inputs::new(
            row.current_code,
            row.motor_count,
            row.output_count,
            row.drive_on,
        );
        let record = encode_record(&inputs)
            .ok_or_else(|| format!("trace row {i}: a counter does not fit 16 bits"))?;
        bytes.extend_from_slice(&record);
    }
    Ok(bytes)
}

/// The alarm pin of the host run: a latch.
#[derive(Default)]
pub struct HostPin(pub bool);

impl embedded_hal::digital::ErrorType for HostPin {
    type Error = core::convert::Infallible;
}

impl embedded_hal::digital::OutputPin for HostPin {
    fn set_low(&mut self) -> Result<(), Self::Error> {
        self.0 = false;
        Ok(())
    }
    fn set_high(&mut self) -> Result<(), Self::Error> {
        self.0 = true;
        Ok(())
    }
}

/// What the host run produced.
pub struct HostRun {
    /// Every estimate, in tick order.
    pub estimates: Vec<Estimate>,
    /// The run's counters and digest.
    pub totals: Totals,
    /// The functional test's report, if one was requested.
    pub functional_test: Option<TestReport>,
}

/// Steps the monitor (with `config`) over a replay on the host, applying the same missed deadlines
/// the firmware reported (`(ticks stepped before it, ticks missed)`) and the same operator
/// resets (after every `reset_every`-th tick), so both see identical inputs.
pub fn host_run(
    bytes: &[u8],
    overruns: &[(u32, u32)],
    reset_every: Option<u32>,
    config: Config,
) -> Result<HostRun, String> {
    host_run_tested(bytes, overruns, reset_every, config, None)
}

/// [`host_run`] with the crew's functional-test request before tick `test_at`, as the
/// firmware's `functional-test-at=N` (`uncoupled-test-at=N`).
pub fn host_run_tested(
    bytes: &[u8],
    overruns: &[(u32, u32)],
    reset_every: Option<u32>,
    config: Config,
    test_at: Option<(u32, Procedure)>,
) -> Result<HostRun, String> {
    let replay = Replay::parse(bytes).map_err(|e| format!("replay: {e:?}"))?;
    let monitor = Monitor::new(config).map_err(|e| format!("monitor: {e:?}"))?;
    let mut ticker: Ticker<_, _> = Ticker::new(monitor, replay, HostPin::default());
    if let Some((at, kind)) = test_at {
        ticker.request_functional_test_at(at, kind);
    }
    let mut estimates = Vec::new();
    loop {
        let stepped = u32::try_from(estimates.len()).unwrap_or(u32::MAX);
        let n = overruns
            .iter()
            .find(|(at, _)| *at == stepped)
            .map_or(1, |(_, missed)| 1 + (*missed).min(254) as u8);
        match ticker.tick(n) {
            Some(estimate) => estimates.push(estimate),
            None => break,
        }
        if reset_every.is_some_and(|every| every > 0 && (stepped + 1) % every == 0) {
            ticker.reset_flags();
        }
        // The firmware's lower-priority context, before the next tick.
        ticker.background();
        while ticker.next_event().is_some() {}
    }
    Ok(HostRun {
        estimates,
        totals: ticker.totals(),
        functional_test: ticker.monitor().functional_test(),
    })
}
