//! The noback firmware on an STM32F405 (Cortex-M4F, 168 MHz), through `stm32f4xx-hal` and
//! RTIC: TIM3's update interrupt paces the 10 kHz tick (priority 2), the monitor's slow lane
//! runs as a priority-1 task before the next tick, and the idle loop feeds and logs.
//!
//! | build | samples from | log | clocks |
//! |---|---|---|---|
//! | `qemu` (default; QEMU `netduinoplus2`) | the host's twin trace over semihosting | defmt over semihosting | RCC left at reset (QEMU does not model it) |
//! | `hw` (a real part, probe-rs) | ADC1 and the timers' encoder modes ([`sensors`]) | defmt over RTT | 8 MHz HSE → 168 MHz |
//!
//! The alarm is PA10 (the Netduino Plus 2's user LED) through the HAL's `OutputPin`. Under
//! QEMU the `bench` argument counts instructions as the evaluation boards' image does.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(all(target_os = "none", feature = "qemu", feature = "hw"))]
compile_error!("choose one build: `qemu` (the default) or `hw` (--no-default-features)");

#[cfg(all(target_os = "none", feature = "hw"))]
mod sensors;
// On a part: defmt frames over RTT, panics reported to the probe (its backtrace, no message).
#[cfg(all(target_os = "none", feature = "hw"))]
use {defmt_rtt as _, panic_probe as _};

#[cfg(target_os = "none")]
mod clock;
#[cfg(target_os = "none")]
mod config_sector;
#[cfg(target_os = "none")]
mod io;

/// The application: RTIC's generated code needs `unsafe` for its resource cells.
#[cfg(target_os = "none")]
#[allow(unsafe_code, missing_docs)]
#[rtic::app(device = stm32f4xx_hal::pac, dispatchers = [USART6])]
mod app {
    use crate::clock::{self, TIMER_HZ};
    use core::mem::MaybeUninit;
    use cortex_m::peripheral::SYST;
    use fugit::TimerDurationU32;
    use noback::app::Ticker;
    #[cfg(feature = "hw")]
    use noback::monitor::Settings;
    #[cfg(feature = "hw")]
    use noback::monitor::{config_block, Monitor};
    use stm32f4xx_hal::gpio::{Output, PA10};
    use stm32f4xx_hal::pac;
    use stm32f4xx_hal::prelude::*;
    use stm32f4xx_hal::timer::{Counter, Event, Flag};

    use crate::io::{self, Stream};
    #[cfg(feature = "qemu")]
    use noback::platform::session;

    /// The application: the monitor's tick with its sample source and alarm pin.
    pub type App = Ticker<io::Source, PA10<Output>, { io::LOG_EVENTS }>;

    #[shared]
    struct Shared {
        /// Built in place in `init`'s slot (a moved copy would double init's stack).
        app: &'static mut App,
        timer: Counter<pac::TIM3, TIMER_HZ>,
        /// The last tick's slow-lane work has not finished yet.
        background_due: bool,
        /// The source has run out (end of a replayed trace).
        done: bool,
        /// SysTick at the tick handler's entry.
        tick_entry: u32,
        /// Most SysTick counts from a tick handler's entry to its end / its background's end.
        isr_max: u32,
        background_max: u32,
    }

    #[local]
    struct Local {
        stream: Stream,
        /// Ticks elapsed to report on the next tick (2 after a missed deadline).
        elapsed: u8,
        tick_no: u32,
        overrun_at: u32,
        reset_every: u32,
    }

    #[init(local = [app_slot: MaybeUninit<App> = MaybeUninit::uninit()])]
    fn init(cx: init::Context) -> (Shared, Local) {
        let dp = cx.device;
        let mut rcc = clock::setup(dp.RCC);
        #[cfg(feature = "qemu")]
        let (args, stream, source, monitor) = {
            let args = session::args();
            session::self_check();
            let (stream, replay) = session::open(&args);
            let (block, from) = crate::config_sector::block();
            let Ok(monitor) = noback::monitor::config_block::decode(block) else {
                clock::halt("the configuration block does not decode")
            };
            let resident = (monitor, from);
            let monitor = session::monitor(&replay, &args, "STM32F405", Some(resident));
            if args.bench {
                session::run_bench(replay, stream, monitor, cx.core.SYST)
            }
            (args, stream, replay, monitor)
        };
        let gpioa = dp.GPIOA.split(&mut rcc);
        #[cfg(feature = "hw")]
        let (stream, source) = {
            let gpiob = dp.GPIOB.split(&mut rcc);
            let wiring = crate::sensors::Wiring {
                adc: (dp.ADC1, gpioa.pa3),
                motor: (dp.TIM4, gpiob.pb6, gpiob.pb7),
                output: (dp.TIM5, gpioa.pa0, gpioa.pa1),
                drive: gpiob.pb0,
            };
            crate::sensors::setup(&mut rcc, wiring)
        };
        let alarm = gpioa.pa10.into_push_pull_output();
        // The monitor is built in its static slot: a copy on init's stack would double it.
        #[cfg(feature = "hw")]
        let app = {
            let (block, from) = crate::config_sector::block();
            defmt::info!("noback firmware on STM32F405: configuration {=str}", from);
            install(cx.local.app_slot, block, source, alarm)
        };
        #[cfg(feature = "qemu")]
        let app = cx.local.app_slot.write(Ticker::new(monitor, source, alarm));
        // SysTick runs free on the core clock: the meter of each tick's time used.
        clock::start_meter(cx.core.SYST);
        let mut timer = dp.TIM3.counter::<TIMER_HZ>(&mut rcc);
        if timer
            .start(TimerDurationU32::from_ticks(clock::PERIOD_COUNTS))
            .is_err()
        {
            clock::halt("TIM3 rejected the tick period")
        }
        timer.listen(Event::Update);
        (
            Shared {
                app,
                timer,
                background_due: false,
                done: false,
                tick_entry: 0,
                isr_max: 0,
                background_max: 0,
            },
            Local {
                stream,
                elapsed: 1,
                tick_no: 0,
                #[cfg(feature = "qemu")]
                overrun_at: args.overrun_at,
                #[cfg(feature = "qemu")]
                reset_every: args.reset_every,
                #[cfg(feature = "hw")]
                overrun_at: u32::MAX,
                #[cfg(feature = "hw")]
                reset_every: 0,
            },
        )
    }

    /// Builds the application in `slot` on `block`'s settings, where they were decoded: one copy
    /// of them on the stack while the decoder runs, the monitor built after it returned (the
    /// part's stack budget).
    #[cfg(feature = "hw")]
    #[inline(never)]
    fn install(
        slot: &'static mut MaybeUninit<App>,
        block: &[u8],
        source: io::Source,
        alarm: PA10<Output>,
    ) -> &'static mut App {
        let built = config_block::read(block, |settings| build(slot, settings, source, alarm));
        built.unwrap_or_else(|_| clock::halt("the configuration block does not decode"))
    }

    /// The application on decoded settings: out of line, so its temporaries are not on the
    /// stack beside the decoder's.
    #[cfg(feature = "hw")]
    #[inline(never)]
    fn build(
        slot: &'static mut MaybeUninit<App>,
        settings: &Settings,
        source: io::Source,
        alarm: PA10<Output>,
    ) -> &'static mut App {
        slot.write(Ticker::new(Monitor::with_settings(settings), source, alarm))
    }

    /// Feeds the sample ring (under QEMU) and prints the log; at a trace's end, the summary.
    #[idle(shared = [app, timer, done, isr_max, background_max, background_due], local = [stream])]
    fn idle(mut cx: idle::Context) -> ! {
        loop {
            let fed = cx.local.stream.feed();
            match cx.shared.app.lock(|app| app.next_event()) {
                Some(event) => io::log(&event),
                None if cx.shared.done.lock(|d| *d) => break,
                None if fed => {}
                None => cortex_m::asm::wfi(),
            }
        }
        cx.shared.timer.lock(|t| t.unlisten(Event::Update));
        while cx.shared.background_due.lock(|d| *d) {
            core::hint::spin_loop();
        }
        let isr_max = cx.shared.isr_max.lock(|m| *m);
        let background_max = cx.shared.background_max.lock(|m| *m);
        cx.shared
            .app
            .lock(|app| io::finish(app, isr_max, background_max))
    }

    /// The 10 kHz tick: skipped (counted) while the last background work is unfinished.
    #[task(binds = TIM3, priority = 2, shared = [app, timer, background_due, done, tick_entry, isr_max], local = [elapsed, tick_no, overrun_at, reset_every])]
    fn tick(cx: tick::Context) {
        let entry = SYST::get_current();
        let tick::SharedResources {
            mut app,
            mut timer,
            mut background_due,
            mut done,
            mut tick_entry,
            mut isr_max,
            ..
        } = cx.shared;
        tick_entry.lock(|e| *e = entry);
        timer.lock(|t| t.clear_flags(Flag::Update));
        let n = *cx.local.elapsed;
        if background_due.lock(|d| *d) {
            *cx.local.elapsed = n.saturating_add(1);
            return;
        }
        *cx.local.elapsed = 1;
        let tick_no = *cx.local.tick_no;
        *cx.local.tick_no = tick_no.wrapping_add(1);
        let reset_every = *cx.local.reset_every;
        let stepped = app.lock(|app| {
            let estimate = app.tick(n);
            if reset_every != 0 && tick_no.wrapping_add(1).is_multiple_of(reset_every) {
                app.reset_flags();
            }
            estimate.is_some()
        });
        if stepped && background::spawn().is_ok() {
            background_due.lock(|d| *d = true);
        } else if !stepped {
            done.lock(|d| *d = true);
        }
        timer.lock(|t| {
            if tick_no == *cx.local.overrun_at {
                // Provoked overrun: run on until the next tick is due, then half a period more.
                while !t.flags().contains(Flag::Update) {}
                while t.now().ticks() % clock::PERIOD_COUNTS < clock::PERIOD_COUNTS / 2 {}
            }
            // The next update already flagged means this handler ran past its deadline.
            if t.flags().contains(Flag::Update) {
                *cx.local.elapsed = 2;
            } else {
                let used = clock::counts(entry, SYST::get_current());
                isr_max.lock(|m| *m = (*m).max(used));
            }
        });
    }

    /// The monitor's slow-lane work for the last tick.
    #[task(priority = 1, shared = [app, timer, background_due, tick_entry, background_max])]
    async fn background(mut cx: background::Context) {
        cx.shared.app.lock(|app| app.background());
        let entry = cx.shared.tick_entry.lock(|e| *e);
        let used = clock::counts(entry, SYST::get_current());
        let late = cx.shared.timer.lock(|t| t.flags().contains(Flag::Update));
        if !late {
            cx.shared.background_max.lock(|m| *m = (*m).max(used));
        }
        cx.shared.background_due.lock(|d| *d = false);
    }
}

/// On the host this binary only says where it runs.
#[cfg(not(target_os = "none"))]
fn main() {
    println!("noback-stm32f405 runs on an STM32F405: `cargo xtask run --board stm32f405` boots it under QEMU");
}
