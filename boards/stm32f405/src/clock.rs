//! The part's clocks and the tick timer's period, per build.
//!
//! QEMU's netduinoplus2 does not model the RCC and clocks TIM2–5 at a fixed 48 MHz; the HAL,
//! with the RCC left at reset, believes the timers run on the 16 MHz HSI. So under QEMU the
//! timer is set for 300 µs at 16 MHz: 4 800 counts, which QEMU runs in 100 µs.

use stm32f4xx_hal::pac::RCC;
use stm32f4xx_hal::rcc::Rcc;

/// SysTick counts per 100 µs tick at the core's 168 MHz (QEMU runs the core at it too).
#[cfg(feature = "qemu")]
pub const SYSTICK_PER_TICK: u32 = 16_800;

/// Counter clock of TIM3 as the HAL computes its prescaler (Hz): prescaler 1.
#[cfg(feature = "qemu")]
pub const TIMER_HZ: u32 = 16_000_000;
/// Timer counts per 100 µs tick (QEMU's 48 MHz × 100 µs).
#[cfg(feature = "qemu")]
pub const PERIOD_COUNTS: u32 = 4_800;

/// APB1 timer clock at 168 MHz SYSCLK (APB1 = 42 MHz, timers × 2).
#[cfg(feature = "hw")]
pub const TIMER_HZ: u32 = 84_000_000;
/// Timer counts per 100 µs tick.
#[cfg(feature = "hw")]
pub const PERIOD_COUNTS: u32 = 8_400;

/// Under QEMU: the RCC as reset left it (writing it would wait on ready bits QEMU never sets).
#[cfg(feature = "qemu")]
pub fn setup(rcc: RCC) -> Rcc {
    use stm32f4xx_hal::rcc::RccExt;
    rcc.constrain()
}

/// On the part: 8 MHz crystal, PLL to 168 MHz.
#[cfg(feature = "hw")]
pub fn setup(rcc: RCC) -> Rcc {
    use stm32f4xx_hal::prelude::*;
    use stm32f4xx_hal::rcc::{Config, RccExt};
    rcc.freeze(Config::hse(8.MHz()).sysclk(168.MHz()))
}

/// Stops with a reason: under QEMU a self-check failure exit, on a part the panic handler's
/// report to the probe.
pub fn halt(what: &str) -> ! {
    #[cfg(feature = "qemu")]
    noback::platform::session::fail(what);
    #[cfg(feature = "hw")]
    {
        defmt::error!("{=str}", what);
        cortex_m::asm::udf()
    }
}

/// SysTick's counter width.
const SYSTICK_MASK: u32 = 0x00FF_FFFF;

/// Starts SysTick free-running on the core clock, no interrupt: the meter of time used.
pub fn start_meter(mut syst: cortex_m::peripheral::SYST) {
    use cortex_m::peripheral::syst::SystClkSource;
    syst.disable_interrupt();
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(SYSTICK_MASK);
    syst.clear_current();
    syst.enable_counter();
}

/// SysTick counts from `start` to `end` (it counts down), modulo 2^24.
pub fn counts(start: u32, end: u32) -> u32 {
    start.wrapping_sub(end) & SYSTICK_MASK
}
