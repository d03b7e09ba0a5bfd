//! What every firmware image under QEMU shares, whatever its board: the semihosting arguments
//! (`trace=FILE`, `bench`, `overrun-at=N`, `reset-every=N`, `trip-log=FILE`, `config=FILE`,
//! `functional-test-at=N`, `uncoupled-test-at=N`), the trace it streams from the host, the boot
//! self-check, the bench loop that counts instructions, and the log lines the xtask decodes.

use crate::app::{estimate_checksum, Ticker};
use crate::board::SampleSource;
use crate::digest::Fnv1a;
use crate::event_log::{tick_time, Decimal, Event};
use crate::monitor::functional_test::{Procedure, TestResult};
use crate::monitor::{config_block, BrakeState, Config, Monitor, Scene};
use crate::platform::{self, meter::Meter, stack};
use crate::replay::{self, Feeder, StreamRing, Streamed, FEED_CHUNK, HEADER_BYTES, RECORD_BYTES};
use cortex_m::peripheral::SYST;
use semihosting::fs::File;
use semihosting::io::Read;

/// Longest trace path the firmware accepts (bytes, without the NUL).
const PATH_BYTES: usize = 255;

/// The boot's semihosting arguments (`trace=FILE`, `bench`, `overrun-at=N`, `reset-every=N`,
/// `trip-log=FILE`, `config=FILE`: the unit's configuration block, `monitor::config_block`).
pub struct Args {
    /// Count instructions back to back instead of running in real time.
    pub bench: bool,
    /// Burn time in this tick to provoke a missed deadline (`u32::MAX`: never).
    pub overrun_at: u32,
    /// Reset the flags after every this many ticks (0: never).
    pub reset_every: u32,
    /// The tick at which the ground crew requests the functional test (`u32::MAX`: never).
    pub functional_test_at: u32,
    /// Which (`uncoupled-test-at=N` asks for the uncoupled push).
    pub test_procedure: Procedure,
    path: [u8; PATH_BYTES + 1],
    trip_path: [u8; PATH_BYTES + 1],
    config_path: [u8; PATH_BYTES + 1],
}

impl Args {
    /// Where to write the trip log's region at the end (`trip-log=FILE`), if asked.
    pub fn trip_log(&self) -> Option<&core::ffi::CStr> {
        core::ffi::CStr::from_bytes_until_nul(&self.trip_path)
            .ok()
            .filter(|p| !p.is_empty())
    }
}

/// Reads the arguments QEMU passed.
pub fn args() -> Args {
    let mut a = Args {
        bench: false,
        overrun_at: u32::MAX,
        reset_every: 0,
        functional_test_at: u32::MAX,
        test_procedure: Procedure::Loaded,
        path: [0; PATH_BYTES + 1],
        trip_path: [0; PATH_BYTES + 1],
        config_path: [0; PATH_BYTES + 1],
    };
    if let Ok(args) = semihosting::experimental::env::args::<512>() {
        for arg in args.flatten() {
            if arg == "bench" {
                a.bench = true;
            } else if let Some(p) = arg.strip_prefix("trace=") {
                match a.path.get_mut(..p.len()) {
                    Some(dst) if p.len() <= PATH_BYTES => dst.copy_from_slice(p.as_bytes()),
                    _ => fail("the trace path is too long"),
                }
            } else if let Some(p) = arg.strip_prefix("trip-log=") {
                match a.trip_path.get_mut(..p.len()) {
                    Some(dst) if p.len() <= PATH_BYTES => dst.copy_from_slice(p.as_bytes()),
                    _ => fail("the trip log path is too long"),
                }
            } else if let Some(p) = arg.strip_prefix("config=") {
                match a.config_path.get_mut(..p.len()) {
                    Some(dst) if p.len() <= PATH_BYTES => dst.copy_from_slice(p.as_bytes()),
                    _ => fail("the configuration block's path is too long"),
                }
            } else if let Some(n) = arg.strip_prefix("overrun-at=") {
                a.overrun_at = n.parse().unwrap_or(u32::MAX);
            } else if let Some(n) = arg.strip_prefix("reset-every=") {
                a.reset_every = n.parse().unwrap_or(0);
            } else if let Some(n) = arg.strip_prefix("functional-test-at=") {
                a.functional_test_at = n.parse().unwrap_or(u32::MAX);
                a.test_procedure = Procedure::Loaded;
            } else if let Some(n) = arg.strip_prefix("uncoupled-test-at=") {
                a.functional_test_at = n.parse().unwrap_or(u32::MAX);
                a.test_procedure = Procedure::Uncoupled;
            }
        }
    }
    a
}

/// Ends the run with a self-check failure, naming what failed.
pub fn fail(what: &str) -> ! {
    defmt::error!("{=str}", what);
    platform::exit(crate::exit_code::SELFCHECK_FAILED)
}

/// The boot self-check of the fixed-point arithmetic; the xtask compares its digest with the
/// host's.
pub fn self_check() {
    let report = crate::vectors::run();
    defmt::info!(
        "fx-selfcheck cases={=u32} mismatches={=u32} digest={=u32:#010x}",
        report.cases,
        report.mismatches,
        report.digest
    );
}

/// The host file the trace streams from, and the ring's writing end.
pub struct Stream {
    feeder: Feeder<'static>,
    file: File,
}

/// Opens the trace named by `trace=FILE` and fills the sample ring; returns the stream and
/// the ring's reading end (the sample source).
pub fn open(args: &Args) -> (Stream, Streamed<'static>) {
    let Ok(path) = core::ffi::CStr::from_bytes_until_nul(&args.path) else {
        fail("the trace path is not terminated")
    };
    let Ok(mut file) = File::open(path) else {
        fail("cannot open the trace file (pass trace=FILE)")
    };
    let mut header = [0_u8; HEADER_BYTES];
    if file.read_exact(&mut header).is_err() {
        fail("cannot read the trace header")
    }
    let Some(ring) = cortex_m::singleton!(: StreamRing = StreamRing::new()) else {
        fail("the sample ring is already taken")
    };
    let Ok((feeder, replay)) = replay::stream(&header, ring) else {
        fail("the trace is not an NBR1 trace")
    };
    let mut stream = Stream { feeder, file };
    stream.feed();
    (stream, replay)
}

impl Stream {
    /// Moves what the ring has room for from the file into it; returns whether it moved any.
    /// A short or malformed file ends the run (the xtask wrote it: a fault, not a condition).
    pub fn feed(&mut self) -> bool {
        let mut moved = false;
        loop {
            let n = self.feeder.wanted();
            if n == 0 {
                return moved;
            }
            let mut chunk = [0_u8; FEED_CHUNK * RECORD_BYTES];
            let Some(buf) = chunk.get_mut(..n * RECORD_BYTES) else {
                return moved;
            };
            if self.file.read_exact(buf).is_err() {
                fail("the trace file ended before its header's count")
            }
            if self.feeder.push(buf) != Ok(n) {
                fail("a trace record has a reserved bit set")
            }
            moved = true;
        }
    }
}

/// The monitor on the unit's configuration: the block `config=FILE` names, else the board's
/// `resident` one (its flash sector), else the uncommissioned defaults. A refused `config=FILE`
/// stops the run.
fn configured(args: &Args, resident: Option<(Monitor, &'static str)>) -> (Monitor, &'static str) {
    let Some(path) = core::ffi::CStr::from_bytes_until_nul(&args.config_path)
        .ok()
        .filter(|p| !p.is_empty())
    else {
        if let Some(resident) = resident {
            return resident;
        }
        let Ok(monitor) = Monitor::new(Config::default()) else {
            fail("the default configuration was rejected")
        };
        return (monitor, "uncommissioned");
    };
    let Ok(mut file) = File::open(path) else {
        fail("cannot open the configuration block")
    };
    let mut block = [0_u8; config_block::CONFIG_BLOCK_BYTES];
    let mut n = 0;
    while let Some(rest) = block.get_mut(n..).filter(|r| !r.is_empty()) {
        match file.read(rest) {
            Ok(0) | Err(_) => break,
            Ok(k) => n += k,
        }
    }
    match config_block::decode(block.get(..n).unwrap_or(&[])) {
        Ok(monitor) => (monitor, "from its block"),
        Err(_) => fail("the configuration block is refused (layout or checksum)"),
    }
}

/// The monitor with the unit's configuration (see `configured`), announced with the run's
/// mode.
pub fn monitor(
    replay: &Streamed<'static>,
    args: &Args,
    board: &str,
    resident: Option<(Monitor, &'static str)>,
) -> Monitor {
    let (monitor, source) = configured(args, resident);
    defmt::info!(
        "noback firmware {=str} on {=str}: {=u32} samples at {=u32} Hz, mode {=str}, configuration {=str}",
        env!("CARGO_PKG_VERSION"),
        board,
        replay.len(),
        replay.tick_hz(),
        if args.bench { "bench" } else { "realtime" },
        source
    );
    monitor
}

/// Steps the monitor back to back on the replay, measuring each `Monitor::tick` and each
/// `Monitor::background` alone with SysTick (digest and logging stay outside the measured
/// spans). The digest equals the real-time run's: both fold every estimate in order.
pub fn run_bench(
    mut replay: Streamed<'static>,
    mut stream: Stream,
    mut monitor: Monitor,
    syst: SYST,
) -> ! {
    let meter = Meter::start(syst);
    let (a, b) = (meter.now(), meter.now());
    let overhead = Meter::ticks(a, b);
    let (mut sum, mut max, mut steps) = (0_u64, 0_u32, 0_u32);
    let (mut bg_sum, mut bg_max) = (0_u64, 0_u32);
    // Worst step per recognised scene (`Scene as u8`): what each scene's model costs.
    let mut scene_max = [0_u32; 4];
    let mut scene_max_at = [0_u32; 4];
    let mut digest = Fnv1a::new();
    loop {
        stream.feed();
        let Some(inputs) = replay.sample() else {
            break;
        };
        let start = meter.now();
        let estimate = monitor.tick(&inputs);
        let ticks = Meter::ticks(start, meter.now()).saturating_sub(overhead);
        let (scene, checksum) = (
            usize::from(estimate.scene as u8),
            estimate_checksum(estimate),
        );
        sum += u64::from(ticks);
        max = max.max(ticks);
        let start = meter.now();
        monitor.background();
        let bg = Meter::ticks(start, meter.now()).saturating_sub(overhead);
        bg_sum += u64::from(bg);
        bg_max = bg_max.max(bg);
        if let (Some(m), Some(at)) = (scene_max.get_mut(scene), scene_max_at.get_mut(scene)) {
            if ticks > *m {
                *m = ticks;
                *at = steps;
            }
        }
        steps += 1;
        digest.push(checksum);
    }
    defmt::info!(
        "bench steps={=u32} ticks_sum={=u64} ticks_max={=u32} bg_ticks_sum={=u64} bg_ticks_max={=u32} overhead={=u32} stack_bytes={=u32} starved={=u32} digest={=u32:#010x}",
        steps,
        sum,
        max,
        bg_sum,
        bg_max,
        overhead,
        stack::high_water_bytes(),
        replay.starved(),
        digest.value()
    );
    let [d, h, f, o] = scene_max;
    let [d_at, h_at, f_at, o_at] = scene_max_at;
    defmt::info!(
        "bench-scenes driving={=u32} holding={=u32} fault_braking={=u32} overrunning={=u32} driving_at={=u32} holding_at={=u32} fault_braking_at={=u32} overrunning_at={=u32}",
        d, h, f, o, d_at, h_at, f_at, o_at
    );
    platform::exit(crate::exit_code::SUCCESS)
}

/// A real-time run's timing, in the counts of the clock that paces its ticks.
pub struct Deadline {
    /// Most counts from a tick's start to the end of its interrupt handler.
    pub isr_max: u32,
    /// Most counts from a tick's start to the end of its background work.
    pub background_max: u32,
    /// Counts per tick period.
    pub period: u32,
}

/// The real-time run's `summary` line, then the exit.
pub fn finish<P: embedded_hal::digital::OutputPin>(
    app: &Ticker<Streamed<'static>, P>,
    deadline: &Deadline,
) -> ! {
    let t = app.totals();
    let last = app.last_estimate();
    if let Some(r) = app.monitor().functional_test() {
        let result = match r.result {
            TestResult::Running => defmt::intern!("running"),
            TestResult::Pass => defmt::intern!("pass"),
            TestResult::Fail => defmt::intern!("fail"),
            TestResult::Aborted => defmt::intern!("aborted"),
        };
        let (o, b, c) = (
            Decimal::from_q16(r.opening_torque_nm.to_bits(), 1000),
            Decimal::from_q16(r.breakaway_torque_nm.to_bits(), 1000),
            Decimal::from_q16(r.capacity_nm.to_bits(), 1000),
        );
        let m = Decimal::from_q16(r.margin.to_bits(), 1000);
        let procedure = match r.procedure {
            Procedure::Loaded => defmt::intern!("loaded"),
            Procedure::Uncoupled => defmt::intern!("uncoupled"),
        };
        defmt::info!(
            "functional-test procedure={=istr} result={=istr} opening_nm={=str}{=u32}.{=u32:03} breakaway_nm={=str}{=u32}.{=u32:03} capacity_nm={=str}{=u32}.{=u32:03} margin={=str}{=u32}.{=u32:03}",
            procedure,
            result,
            o.sign(), o.whole, o.frac,
            b.sign(), b.whole, b.frac,
            c.sign(), c.whole, c.frac,
            m.sign(), m.whole, m.frac
        );
    }
    defmt::info!(
        "summary ticks={=u32} overruns={=u32} missed={=u32} starved={=u32} log_overwritten={=u32} alarm_errors={=u32} flags={=u8:#04x} stack_bytes={=u32} isr_ticks_max={=u32} background_ticks_max={=u32} period_ticks={=u32} digest={=u32:#010x}",
        t.ticks,
        t.overruns,
        t.missed_ticks,
        app.source().starved(),
        t.log_overwritten,
        t.alarm_errors,
        last.map_or(0, |e| e.flags.bits()),
        stack::high_water_bytes(),
        deadline.isr_max,
        deadline.background_max,
        deadline.period,
        t.digest
    );
    platform::exit(crate::exit_code::SUCCESS)
}

fn scene_name(scene: Scene) -> defmt::Str {
    match scene {
        Scene::Driving => defmt::intern!("driving"),
        Scene::Holding => defmt::intern!("holding"),
        Scene::FaultBraking => defmt::intern!("fault_braking"),
        Scene::Overrunning => defmt::intern!("overrunning"),
    }
}

fn brake_name(brake: BrakeState) -> defmt::Str {
    match brake {
        BrakeState::Released => defmt::intern!("released"),
        BrakeState::Slipping => defmt::intern!("slipping"),
        BrakeState::Locked => defmt::intern!("locked"),
    }
}

/// One log line per event, in engineering units: `t` is the time of the sample the tick
/// stepped on (the trace's time base), forces in N, torques in N·m as magnitudes (the
/// trace's convention), flags as bits.
pub fn log(event: &Event) {
    match *event {
        Event::State {
            tick,
            scene,
            brake,
            pressing_force_bits,
            braking_torque_bits,
            flags,
        } => {
            let (s, frac) = tick_time(tick);
            let force = Decimal::from_q16(pressing_force_bits, 10);
            let torque = Decimal::from_q16(braking_torque_bits.saturating_abs(), 100);
            defmt::info!(
                "state t={=u32}.{=u32:04} s scene={=istr} brake={=istr} force={=str}{=u32}.{=u32:01} N torque={=u32}.{=u32:02} Nm flags={=u8:#04x}",
                s,
                frac,
                scene_name(scene),
                brake_name(brake),
                force.sign(),
                force.whole,
                force.frac,
                torque.whole,
                torque.frac,
                flags.bits()
            )
        }
        Event::FlagsChanged { tick, before, now } => {
            let (s, frac) = tick_time(tick);
            defmt::warn!(
                "flags t={=u32}.{=u32:04} s tick={=u32} before={=u8:#04x} now={=u8:#04x}",
                s,
                frac,
                tick,
                before.bits(),
                now.bits()
            )
        }
        Event::Overrun { tick, missed } => {
            defmt::warn!("overrun tick={=u32} missed={=u32}", tick, missed)
        }
    }
}
