//! Shared shape of the fault probes: images that end badly on purpose, so `cargo xtask test` can
//! show that a panic, a HardFault and a hang each end the QEMU run with their own non-zero code
//! (101, 102, 124). Each probe file calls [`probe!`] with what it does after booting.

/// Defines the probe's entry point on the target and a stub `main` on the host.
#[macro_export]
macro_rules! probe {
    ($what:literal, $body:expr) => {
        #[cfg(target_os = "none")]
        #[cortex_m_rt::entry]
        fn main() -> ! {
            use noback as _; // panic handler, HardFault exit, defmt transport
            defmt::info!("probe {=str}", $what);
            $body
        }

        /// On the host the probes are stubs.
        #[cfg(not(target_os = "none"))]
        fn main() {
            println!("fault probes run under QEMU: use `cargo xtask test`");
        }
    };
}
