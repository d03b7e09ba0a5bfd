//! The actuator firmware image: the monitor at 10 kHz on a Cortex-M, here replaying a twin
//! trace under QEMU (`cargo xtask run` builds it and boots it with `trace=FILE`, which the main
//! loop streams from the host over semihosting into a ring the tick drains: any length).
//!
//! All target-only code of the product is in this file and `noback::platform`; the work of a
//! tick is the portable `noback::app::Ticker`, which the host tests run too. Two modes, chosen
//! by the semihosting argument QEMU passes:
//! - `realtime` (default): SysTick interrupts at 10 kHz; each interrupt runs the monitor's
//!   10 kHz part on the next sample, drives the alarm pin and pends PendSV, which runs the
//!   monitor's slow-lane work at the lowest priority before the next tick; the main loop
//!   refills the sample ring from the file and drains the log ring buffer to defmt, so neither
//!   reading nor logging blocks the interrupt. `overrun-at=N` burns time in tick N to
//!   provoke a missed deadline, which must be counted and flagged; `reset-every=N` has the
//!   operator reset the flags after every N-th tick (the load test: flags keep changing).
//! - `bench`: the same monitor steps back to back without interrupts, each `Monitor::tick` and
//!   `Monitor::background` measured alone with SysTick (the file reads stay outside the
//!   measured span), for deterministic instruction counts under QEMU `-icount`.
//!
//! Both end with a `summary` line carrying the digest of every estimate, which the xtask
//! compares with the host's run on the same trace.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod target {
    use core::cell::UnsafeCell;
    use core::sync::atomic::{AtomicBool, AtomicU32, AtomicU8, Ordering};
    use cortex_m::peripheral::scb::SystemHandler;
    use cortex_m::peripheral::{syst::SystClkSource, SCB, SYST};
    use cortex_m_rt::{entry, exception};
    use noback::app::Ticker;
    use noback::board::SampleSource;
    use noback::digest::Fnv1a;
    use noback::event_log::{tick_time, Decimal, Event};
    use noback::monitor::{BrakeState, Scene};
    use noback::monitor::{Config, Monitor};
    use noback::platform::{self, meter::Meter, stack};
    use noback::replay::RECORD_BYTES;
    use noback::replay::{self, Feeder, StreamRing, Streamed, FEED_CHUNK, HEADER_BYTES};
    use semihosting::fs::File;
    use semihosting::io::Read;

    /// Longest trace path the firmware accepts (bytes, without the NUL).
    const PATH_BYTES: usize = 255;

    /// Board clock under QEMU (Hz): lm3s6965evb 12.5 MHz, mps2-an386 25 MHz.
    #[cfg(not(target_abi = "eabihf"))]
    const CLOCK_HZ: u32 = 12_500_000;
    #[cfg(target_abi = "eabihf")]
    const CLOCK_HZ: u32 = 25_000_000;
    /// Tick rate.
    const TICK_HZ: u32 = 10_000;

    type App = Ticker<Streamed<'static>, AlarmPin>;

    /// The application, shared by three contexts without a lock: SysTick touches it only while
    /// [`BACKGROUND_DUE`] is clear, PendSV (lowest priority) only while it is set, and the main
    /// loop only inside a critical section (thread mode never runs inside a handler).
    struct Shared(UnsafeCell<Option<App>>);
    // SAFETY: the access protocol above gives one context at a time on this single core.
    #[allow(unsafe_code)]
    unsafe impl Sync for Shared {}
    static APP: Shared = Shared(UnsafeCell::new(None));
    /// Set by SysTick when it pends the background work, cleared by PendSV when it is done.
    static BACKGROUND_DUE: AtomicBool = AtomicBool::new(false);
    /// Most SysTick ticks from a tick's start to the end of its background work.
    static BACKGROUND_TICKS_MAX: AtomicU32 = AtomicU32::new(0);

    /// The application. SAFETY: the caller holds its turn under [`Shared`]'s protocol.
    #[allow(unsafe_code)]
    unsafe fn shared_app() -> Option<&'static mut App> {
        // SAFETY: one context at a time (the protocol), so this is the only reference.
        unsafe { (*APP.0.get()).as_mut() }
    }
    /// Ticks elapsed to report on the next interrupt (2 after a missed deadline).
    static ELAPSED: AtomicU8 = AtomicU8::new(1);
    static DONE: AtomicBool = AtomicBool::new(false);
    static OVERRUN_AT: AtomicU32 = AtomicU32::new(u32::MAX);
    /// Operator flag reset after every this many ticks (0 = never); the load test uses it.
    static RESET_EVERY: AtomicU32 = AtomicU32::new(0);
    static TICK_NO: AtomicU32 = AtomicU32::new(0);
    /// Most SysTick ticks from a tick's start to the end of its handler (deadline use).
    static ISR_TICKS_MAX: AtomicU32 = AtomicU32::new(0);

    /// The alarm output. Under QEMU a plain latch; a board passes its GPIO's `OutputPin`.
    pub struct AlarmPin {
        high: bool,
    }
    impl embedded_hal::digital::ErrorType for AlarmPin {
        type Error = core::convert::Infallible;
    }
    impl embedded_hal::digital::OutputPin for AlarmPin {
        fn set_low(&mut self) -> Result<(), Self::Error> {
            self.high = false;
            Ok(())
        }
        fn set_high(&mut self) -> Result<(), Self::Error> {
            self.high = true;
            Ok(())
        }
    }

    fn fail(what: &str) -> ! {
        defmt::error!("{=str}", what);
        platform::exit(noback::exit_code::SELFCHECK_FAILED)
    }

    #[entry]
    fn main() -> ! {
        let Some(peripherals) = cortex_m::Peripherals::take() else {
            fail("peripherals already taken")
        };
        let mut bench = false;
        let mut path = [0_u8; PATH_BYTES + 1];
        if let Ok(args) = semihosting::experimental::env::args::<512>() {
            for arg in args.flatten() {
                if arg == "bench" {
                    bench = true;
                } else if let Some(p) = arg.strip_prefix("trace=") {
                    match path.get_mut(..p.len()) {
                        Some(dst) if p.len() <= PATH_BYTES => dst.copy_from_slice(p.as_bytes()),
                        _ => fail("the trace path is too long"),
                    }
                } else if let Some(n) = arg.strip_prefix("overrun-at=") {
                    OVERRUN_AT.store(n.parse().unwrap_or(u32::MAX), Ordering::Relaxed);
                } else if let Some(n) = arg.strip_prefix("reset-every=") {
                    RESET_EVERY.store(n.parse().unwrap_or(0), Ordering::Relaxed);
                }
            }
        }
        let report = noback::vectors::run();
        defmt::info!(
            "fx-selfcheck cases={=u32} mismatches={=u32} digest={=u32:#010x}",
            report.cases,
            report.mismatches,
            report.digest
        );
        let Ok(path) = core::ffi::CStr::from_bytes_until_nul(&path) else {
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
        let Ok((mut feeder, replay)) = replay::stream(&header, ring) else {
            fail("the trace is not an NBR1 trace")
        };
        feed(&mut feeder, &mut file);
        let Ok(monitor) = Monitor::new(Config::default()) else {
            fail("the default monitor configuration was rejected")
        };
        defmt::info!(
            "noback firmware {=str}: {=u32} samples at {=u32} Hz, mode {=str}",
            env!("CARGO_PKG_VERSION"),
            replay.len(),
            replay.tick_hz(),
            if bench { "bench" } else { "realtime" }
        );
        if bench {
            run_bench(replay, feeder, file, monitor, peripherals.SYST)
        } else {
            let app = Ticker::new(monitor, replay, AlarmPin { high: false });
            run_realtime(app, feeder, file, peripherals.SYST, peripherals.SCB)
        }
    }

    /// Moves what the ring has room for from the file into it; returns whether it moved any.
    /// A short or malformed file ends the run (the xtask wrote it: a fault, not a condition).
    fn feed(feeder: &mut Feeder<'static>, file: &mut File) -> bool {
        let mut moved = false;
        loop {
            let n = feeder.wanted();
            if n == 0 {
                return moved;
            }
            let mut chunk = [0_u8; FEED_CHUNK * RECORD_BYTES];
            let Some(buf) = chunk.get_mut(..n * RECORD_BYTES) else {
                return moved;
            };
            if file.read_exact(buf).is_err() {
                fail("the trace file ended before its header's count")
            }
            if feeder.push(buf) != Ok(n) {
                fail("a trace record has a reserved bit set")
            }
            moved = true;
        }
    }

    /// Steps the monitor back to back on the replay, measuring each `Monitor::tick` and each
    /// `Monitor::background` alone (the digest and the logging stay outside the measured
    /// spans). The digest equals the real-time run's: both fold every estimate's words in order.
    fn run_bench(
        mut replay: Streamed<'static>,
        mut feeder: Feeder<'static>,
        mut file: File,
        mut monitor: Monitor,
        syst: SYST,
    ) -> ! {
        let meter = Meter::start(syst);
        let (a, b) = (meter.now(), meter.now());
        let overhead = Meter::ticks(a, b);
        let (mut sum, mut max, mut steps) = (0_u64, 0_u32, 0_u32);
        let (mut bg_sum, mut bg_max) = (0_u64, 0_u32);
        // Worst step per recognised scene (Scene as u8: Driving, Holding, FaultBraking,
        // Overrunning): what each scene's model costs.
        let mut scene_max = [0_u32; 4];
        let mut scene_max_at = [0_u32; 4];
        let mut digest = Fnv1a::new();
        loop {
            feed(&mut feeder, &mut file);
            let Some(inputs) = replay.sample() else {
                break;
            };
            let start = meter.now();
            let estimate = monitor.tick(&inputs);
            let ticks = Meter::ticks(start, meter.now()).saturating_sub(overhead);
            sum += u64::from(ticks);
            max = max.max(ticks);
            let start = meter.now();
            monitor.background();
            let bg = Meter::ticks(start, meter.now()).saturating_sub(overhead);
            bg_sum += u64::from(bg);
            bg_max = bg_max.max(bg);
            let scene = usize::from(estimate.scene as u8);
            if let (Some(m), Some(at)) = (scene_max.get_mut(scene), scene_max_at.get_mut(scene)) {
                if ticks > *m {
                    *m = ticks;
                    *at = steps;
                }
            }
            steps += 1;
            digest.push(noback::app::estimate_checksum(&estimate));
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
        defmt::info!(
            "bench-scenes driving={=u32} holding={=u32} fault_braking={=u32} overrunning={=u32} driving_at={=u32} holding_at={=u32} fault_braking_at={=u32} overrunning_at={=u32}",
            scene_max[0],
            scene_max[1],
            scene_max[2],
            scene_max[3],
            scene_max_at[0],
            scene_max_at[1],
            scene_max_at[2],
            scene_max_at[3]
        );
        platform::exit(noback::exit_code::SUCCESS)
    }

    /// SysTick at 10 kHz drives the ticks; the main loop refills the sample ring and logs.
    #[allow(unsafe_code)] // the shared application (`Shared`) and PendSV's priority
    fn run_realtime(
        app: App,
        mut feeder: Feeder<'static>,
        mut file: File,
        mut syst: SYST,
        mut scb: SCB,
    ) -> ! {
        // SAFETY: no interrupt is enabled yet: this is the only context.
        unsafe { *APP.0.get() = Some(app) };
        // SAFETY: PendSV at the lowest priority, so SysTick (priority 0) preempts it; no
        // priority-based critical section relies on these levels.
        unsafe { scb.set_priority(SystemHandler::PendSV, 0xFF) };
        syst.set_clock_source(SystClkSource::Core);
        syst.set_reload(CLOCK_HZ / TICK_HZ - 1);
        syst.clear_current();
        syst.enable_interrupt();
        syst.enable_counter();
        loop {
            let fed = feed(&mut feeder, &mut file);
            // SAFETY: inside a critical section neither handler runs.
            let event =
                critical_section::with(|_| unsafe { shared_app() }.and_then(Ticker::next_event));
            match event {
                Some(event) => log(&event),
                None if DONE.load(Ordering::Acquire) => break,
                None if fed => {}
                None => cortex_m::asm::wfi(),
            }
        }
        syst.disable_interrupt();
        syst.disable_counter();
        // The summary reads the state where it lives: taking it out would copy the whole
        // application (monitor, replay cursor, event log) onto the stack.
        // SAFETY: both interrupts are off for good (the background's last pend may run first).
        while BACKGROUND_DUE.load(Ordering::Acquire) {
            core::hint::spin_loop();
        }
        if let Some(app) = unsafe { shared_app() } {
            finish(app)
        }
        fail("the application state vanished")
    }

    fn finish(app: &App) -> ! {
        let t = app.totals();
        let last = app.last_estimate();
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
            ISR_TICKS_MAX.load(Ordering::Relaxed),
            BACKGROUND_TICKS_MAX.load(Ordering::Relaxed),
            CLOCK_HZ / TICK_HZ,
            t.digest
        );
        platform::exit(noback::exit_code::SUCCESS)
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
    fn log(event: &Event) {
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

    #[exception]
    #[allow(unsafe_code)] // the shared application (`Shared`)
    fn SysTick() {
        // Load and store, not swap: thumbv6m has no atomic read-modify-write, and only this
        // handler (which cannot preempt itself) writes ELAPSED.
        let n = ELAPSED.load(Ordering::Relaxed);
        if BACKGROUND_DUE.load(Ordering::Acquire) {
            // The last tick's background work is still running: this tick is missed.
            ELAPSED.store(n.saturating_add(1), Ordering::Relaxed);
            return;
        }
        ELAPSED.store(1, Ordering::Relaxed);
        let tick_no = TICK_NO.load(Ordering::Relaxed);
        TICK_NO.store(tick_no.wrapping_add(1), Ordering::Relaxed);
        let reset_every = RESET_EVERY.load(Ordering::Relaxed);
        // SAFETY: BACKGROUND_DUE is clear, so PendSV is not using the application.
        let stepped = unsafe { shared_app() }.is_some_and(|app| {
            let estimate = app.tick(n);
            if reset_every != 0 && tick_no.wrapping_add(1).is_multiple_of(reset_every) {
                app.reset_flags();
            }
            estimate.is_some()
        });
        if stepped {
            BACKGROUND_DUE.store(true, Ordering::Release);
            SCB::set_pendsv();
        } else {
            DONE.store(true, Ordering::Release);
        }
        if tick_no == OVERRUN_AT.load(Ordering::Relaxed) {
            // Provoked overrun: run on until the next tick is due, then half a period more.
            while !SCB::is_pendst_pending() {}
            while SYST::get_current() > CLOCK_HZ / TICK_HZ / 2 {}
        }
        // The next SysTick already pending means this handler ran past its deadline.
        if SCB::is_pendst_pending() {
            ELAPSED.store(2, Ordering::Relaxed);
        } else {
            record_max(&ISR_TICKS_MAX);
        }
    }

    /// The monitor's slow-lane work for the last tick, at the lowest priority.
    #[exception]
    #[allow(unsafe_code)] // the shared application (`Shared`)
    fn PendSV() {
        if !BACKGROUND_DUE.load(Ordering::Acquire) {
            return;
        }
        // SAFETY: BACKGROUND_DUE is set, so SysTick leaves the application alone.
        if let Some(app) = unsafe { shared_app() } {
            app.background();
        }
        if !SCB::is_pendst_pending() {
            record_max(&BACKGROUND_TICKS_MAX);
        }
        BACKGROUND_DUE.store(false, Ordering::Release);
    }

    /// Raises `max` to the time used of this period, entry latency included: SysTick counts
    /// down from the reload value, which it reloaded when this tick began.
    fn record_max(max: &AtomicU32) {
        let used = (CLOCK_HZ / TICK_HZ - 1).saturating_sub(SYST::get_current());
        if used > max.load(Ordering::Relaxed) {
            max.store(used, Ordering::Relaxed);
        }
    }
}

/// On the host this binary only says where it runs.
#[cfg(not(target_os = "none"))]
fn main() {
    println!("noback-fw runs on a Cortex-M: use `cargo xtask run` to boot it under QEMU");
}
