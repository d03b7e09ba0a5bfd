//! The actuator firmware image (`cargo xtask run` builds it for thumbv7m and boots it in QEMU).
//!
//! Until the firmware issue fills it in, it runs the fixed-point self-check that the host also
//! runs and prints its digest; the xtask compares that digest with its own native run.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod target {
    use cortex_m_rt::entry;
    use noback::platform::{self, meter::Meter};

    #[entry]
    fn main() -> ! {
        defmt::info!("noback firmware {=str}", env!("CARGO_PKG_VERSION"));
        let Some(peripherals) = cortex_m::Peripherals::take() else {
            platform::exit(noback::exit_code::PANIC)
        };
        let meter = Meter::start(peripherals.SYST);
        // Cost of an empty measurement, to subtract on the host side.
        let (a, b) = (meter.now(), meter.now());
        let start = meter.now();
        let report = noback::vectors::run();
        let end = meter.now();
        defmt::info!(
            "fx-selfcheck cases={=u32} mismatches={=u32} digest={=u32:#010x} ticks={=u32} overhead={=u32}",
            report.cases,
            report.mismatches,
            report.digest,
            Meter::ticks(start, end),
            Meter::ticks(a, b)
        );
        platform::exit(if report.mismatches == 0 {
            noback::exit_code::SUCCESS
        } else {
            noback::exit_code::SELFCHECK_FAILED
        })
    }
}

/// On the host this binary only says where it runs.
#[cfg(not(target_os = "none"))]
fn main() {
    println!("noback-fw runs on a Cortex-M: use `cargo xtask run` to boot it under QEMU");
}
