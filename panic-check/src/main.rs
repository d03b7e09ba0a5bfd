//! The panic-never proof of the real-time path, checked by the linker rather than by reading.
//!
//! This image calls `Monitor::new`, `Monitor::step` and the firmware's `Ticker::tick` and
//! `Ticker::background` on inputs the optimiser cannot see (`black_box`), and its panic
//! handler calls a function that does not exist. If any panic path (an `unwrap`, an index, an overflow check, a division by a possible
//! zero) survives optimisation anywhere in those calls, the release build fails to link with an
//! undefined symbol naming the problem. `cargo xtask test` builds it for the M0 and the M3.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod target {
    use core::hint::black_box;
    use cortex_m_rt::entry;
    use noback::app::Ticker;
    use noback::board::SampleSource;
    use noback::monitor::{Config, Inputs, Monitor};

    /// A sample source the optimiser knows nothing about.
    struct Opaque;
    impl SampleSource for Opaque {
        fn sample(&mut self) -> Option<Inputs> {
            black_box(Some(Inputs {
                current_adc_code: black_box(0),
                motor_counter: black_box(0),
                output_counter: black_box(0),
                drive_commanded: black_box(false),
                current_command_code: black_box(Some(0)),
                ticks_elapsed: black_box(1),
            }))
        }
        fn skip(&mut self, ticks: u32) {
            black_box(ticks);
        }
    }

    /// An alarm pin that does nothing.
    struct Pin;
    impl embedded_hal::digital::ErrorType for Pin {
        type Error = core::convert::Infallible;
    }
    impl embedded_hal::digital::OutputPin for Pin {
        fn set_low(&mut self) -> Result<(), Self::Error> {
            Ok(())
        }
        fn set_high(&mut self) -> Result<(), Self::Error> {
            Ok(())
        }
    }

    #[entry]
    fn main() -> ! {
        let config: Config = black_box(Config::default());
        let Ok(monitor) = Monitor::new(config) else {
            loop {
                black_box(());
            }
        };
        let mut ticker: Ticker<_, _> = Ticker::new(monitor, Opaque, Pin);
        loop {
            black_box(ticker.tick(black_box(1)));
            ticker.background();
            black_box(ticker.next_event());
            if black_box(false) {
                ticker.reset_flags();
            }
        }
    }

    #[panic_handler]
    fn panic(_: &core::panic::PanicInfo<'_>) -> ! {
        extern "Rust" {
            #[link_name = "\n\nnoback panic-check: a panic path survived in Monitor::new/step or Ticker::tick (see docs/reliability.md)\n\n"]
            fn panic_path_found() -> !;
        }
        #[allow(unsafe_code)]
        // SAFETY: never called; the symbol does not exist, so reaching this is a link error.
        unsafe {
            panic_path_found()
        }
    }
}

/// On the host the proof is a stub: it only means something for the release thumb build.
#[cfg(not(target_os = "none"))]
fn main() {
    println!(
        "panic-check is a link-time proof: `cargo xtask test` builds it for thumbv6m and thumbv7m"
    );
}
