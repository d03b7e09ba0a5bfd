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
    use noback::monitor::{Estimate, Flags};
    use noback::platform::ram_flash::RamFlash;
    use noback::platform::session::{self, fail, Deadline, Stream};
    use noback::replay::Streamed;
    use noback::trip_log::store::Store;
    use noback::trip_log::Recorder;

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

    struct TripCell(UnsafeCell<Trip>);
    // SAFETY: the access protocol above gives one context at a time on this single core.
    #[allow(unsafe_code)]
    unsafe impl Sync for TripCell {}
    struct Trip {
        recorder: Recorder,
        /// A flag change waiting for PendSV to freeze the recorder: the estimate, the flags before.
        pending: Option<(Estimate, Flags)>,
    }
    static TRIP: TripCell = TripCell(UnsafeCell::new(Trip {
        recorder: Recorder::new(),
        pending: None,
    }));
    /// Who holds the recorder: SysTick and PendSV while recording; the main loop while frozen
    /// (a trip to store); PendSV alone while restarting (a fresh recorder from the monitor).
    static TRIP_STATE: AtomicU8 = AtomicU8::new(RECORDING);
    const RECORDING: u8 = 0;
    const FROZEN: u8 = 1;
    const RESTARTING: u8 = 2;
    /// Flags after the last stepped tick (SysTick's own).
    static LAST_FLAGS: AtomicU8 = AtomicU8::new(0);
    /// Flag changes not recorded: the recorder was busy with the last one or had no copy yet.
    static TRIPS_DROPPED: AtomicU32 = AtomicU32::new(0);
    static TRIPS_STORED: AtomicU32 = AtomicU32::new(0);

    /// The trip recorder. SAFETY: the caller holds its turn under [`TripCell`]'s protocol.
    #[allow(unsafe_code)]
    unsafe fn trip() -> &'static mut Trip {
        // SAFETY: one context at a time (the protocol), so this is the only reference.
        unsafe { &mut *TRIP.0.get() }
    }

    /// The trip log's region: four 4 KB pages of RAM (QEMU's flash cannot be programmed).
    const REGION_BYTES: usize = 16 * 1024;
    const REGION_PAGE: usize = 4 * 1024;
    type Region = RamFlash<REGION_BYTES, REGION_PAGE>;

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

    #[entry]
    fn main() -> ! {
        let Some(peripherals) = cortex_m::Peripherals::take() else {
            fail("peripherals already taken")
        };
        let args = session::args();
        OVERRUN_AT.store(args.overrun_at, Ordering::Relaxed);
        RESET_EVERY.store(args.reset_every, Ordering::Relaxed);
        session::self_check();
        let (stream, replay) = session::open(&args);
        let monitor = session::monitor(&replay, &args, "an evaluation board", None);
        if args.bench {
            session::run_bench(replay, stream, monitor, peripherals.SYST)
        } else {
            let mut app: App = Ticker::new(monitor, replay, AlarmPin { high: false });
            app.request_functional_test_at(args.functional_test_at, args.test_procedure);
            run_realtime(
                app,
                stream,
                peripherals.SYST,
                peripherals.SCB,
                args.trip_log(),
            )
        }
    }

    /// SysTick at 10 kHz drives the ticks; the main loop refills the sample ring and logs.
    #[allow(unsafe_code)] // the shared application (`Shared`) and PendSV's priority
    fn run_realtime(
        app: App,
        mut stream: Stream,
        mut syst: SYST,
        mut scb: SCB,
        trip_log: Option<&core::ffi::CStr>,
    ) -> ! {
        let Some(region) = cortex_m::singleton!(: [u8; REGION_BYTES] = [0; REGION_BYTES]) else {
            fail("the trip log's region is already taken")
        };
        let Ok(mut store) = Store::new(Region::new(region), 0..REGION_BYTES as u32) else {
            fail("the trip log's region is not whole pages")
        };
        let Some(buf) = cortex_m::singleton!(: [u8; REGION_PAGE] = [0; REGION_PAGE]) else {
            fail("the trip record buffer is already taken")
        };
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
            if TRIP_STATE.load(Ordering::Acquire) == FROZEN {
                store_trip(&mut store, buf);
            }
            let fed = stream.feed();
            // SAFETY: inside a critical section neither handler runs.
            let event =
                critical_section::with(|_| unsafe { shared_app() }.and_then(Ticker::next_event));
            match event {
                Some(event) => session::log(&event),
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
        if TRIP_STATE.load(Ordering::Acquire) == FROZEN {
            store_trip(&mut store, buf);
        }
        let region = store.into_flash();
        if let Some(path) = trip_log {
            if semihosting::fs::write(path, region.bytes()).is_err() {
                fail("cannot write the trip log's region to the host")
            }
        }
        defmt::info!(
            "trip-log stored={=u32} dropped={=u32}",
            TRIPS_STORED.load(Ordering::Relaxed),
            TRIPS_DROPPED.load(Ordering::Relaxed)
        );
        let deadline = Deadline {
            isr_max: ISR_TICKS_MAX.load(Ordering::Relaxed),
            background_max: BACKGROUND_TICKS_MAX.load(Ordering::Relaxed),
            period: CLOCK_HZ / TICK_HZ,
        };
        if let Some(app) = unsafe { shared_app() } {
            session::finish(app, &deadline)
        }
        fail("the application state vanished")
    }

    /// Writes the frozen trip's record to the store, then has PendSV restart the recorder
    /// (the inputs it missed while frozen would break the next window).
    #[allow(unsafe_code)] // the trip recorder (`TripCell`)
    fn store_trip(store: &mut Store<Region>, buf: &mut [u8]) {
        // SAFETY: TRIP_STATE is FROZEN: SysTick and PendSV leave the recorder alone.
        let t = unsafe { trip() };
        let stored = t.pending.take().is_some_and(|(estimate, before)| {
            t.recorder
                .record(buf, &estimate, before)
                .is_ok_and(|bytes| store.push(bytes).is_ok())
        });
        count(if stored {
            &TRIPS_STORED
        } else {
            &TRIPS_DROPPED
        });
        TRIP_STATE.store(RESTARTING, Ordering::Release);
    }

    /// One more (load and store: thumbv6m has no atomic read-modify-write).
    fn count(counter: &AtomicU32) {
        counter.store(
            counter.load(Ordering::Relaxed).wrapping_add(1),
            Ordering::Relaxed,
        );
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
            if let (Some(e), Some(inputs)) = (estimate, app.last_inputs()) {
                record_input(&e, &inputs);
            }
            if reset_every != 0 && tick_no.wrapping_add(1).is_multiple_of(reset_every) {
                app.reset_flags();
                record_reset();
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

    /// The tick's inputs into the recorder's ring, and a flag change noted for PendSV; a
    /// change while the recorder is not recording is counted, not recorded.
    #[allow(unsafe_code)] // the trip recorder (`TripCell`)
    fn record_input(e: &Estimate, inputs: &noback::monitor::Inputs) {
        let before = Flags::from_bits(LAST_FLAGS.load(Ordering::Relaxed));
        LAST_FLAGS.store(e.flags.bits(), Ordering::Relaxed);
        let changed = e.flags != before;
        if TRIP_STATE.load(Ordering::Acquire) != RECORDING {
            if changed {
                count(&TRIPS_DROPPED);
            }
            return;
        }
        // SAFETY: RECORDING, and PendSV is not running (BACKGROUND_DUE was clear).
        let t = unsafe { trip() };
        t.recorder.push_input(inputs);
        if changed {
            if t.pending.is_some() {
                count(&TRIPS_DROPPED);
            }
            t.pending = Some((*e, before));
        }
    }

    /// The operator's flag reset after this tick, into the recorder's ring (it replays).
    #[allow(unsafe_code)] // the trip recorder (`TripCell`)
    fn record_reset() {
        if TRIP_STATE.load(Ordering::Acquire) == RECORDING {
            // SAFETY: RECORDING, and PendSV is not running (BACKGROUND_DUE was clear).
            unsafe { trip() }.recorder.mark_reset();
        }
        LAST_FLAGS.store(0, Ordering::Relaxed);
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
            // SAFETY: RECORDING or RESTARTING, and SysTick leaves the application (and so the
            // recorder) alone while BACKGROUND_DUE is set.
            match TRIP_STATE.load(Ordering::Acquire) {
                RECORDING => {
                    let t = unsafe { trip() };
                    if t.pending.is_some() {
                        TRIP_STATE.store(FROZEN, Ordering::Release);
                    } else {
                        t.recorder.snapshot_if_due(app.monitor());
                    }
                }
                RESTARTING => {
                    let t = unsafe { trip() };
                    t.recorder = Recorder::new();
                    t.recorder.snapshot_if_due(app.monitor());
                    TRIP_STATE.store(RECORDING, Ordering::Release);
                }
                _ => {}
            }
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
