//! Target-only glue (`cfg(target_os = "none")`): how a fault ends a run, and the defmt transport.
//!
//! A panic or a HardFault must never leave the MCU spinning silently: under QEMU both exit
//! through semihosting with a non-zero code, so `cargo xtask test` and `run` fail loudly; on a
//! real ECU a BSP would replace the exit with a safe-state reset. defmt frames go out over
//! semihosting (`defmt-semihosting`), which QEMU writes to stdout for the xtask to decode.

pub mod meter;
pub mod ram_flash;
pub mod session;
pub mod stack;

use crate::exit_code;
use cortex_m as _; // links its single-core critical-section implementation
use cortex_m_rt::{exception, ExceptionFrame};
use defmt_semihosting as _;

/// Ends the emulated run with `code` (semihosting `SYS_EXIT_EXTENDED`, then `SYS_EXIT`).
pub fn exit(code: i32) -> ! {
    semihosting::process::exit(code)
}

#[defmt::panic_handler]
fn defmt_panic() -> ! {
    exit(exit_code::PANIC)
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo<'_>) -> ! {
    defmt::error!("panic: {}", defmt::Display2Format(info));
    exit(exit_code::PANIC)
}

#[exception]
#[allow(unsafe_code)] // cortex-m-rt requires HardFault handlers to be `unsafe fn`.
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    defmt::error!("HardFault at pc={=u32:#010x}", frame.pc());
    exit(exit_code::HARDFAULT)
}
