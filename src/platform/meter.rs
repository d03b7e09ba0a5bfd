//! Deterministic cost measurement on the emulated MCU: SysTick as a free-running down-counter.
//!
//! QEMU is not cycle-accurate and DWT CYCCNT reads 0, but with `-icount shift=N,align=off,
//! sleep=off` virtual time advances exactly 2^N ns per executed instruction, and SysTick (on
//! the processor clock: 12.5 MHz on lm3s6965evb, 25 MHz on mps2-an386 — the an386's external
//! reference is only 1 MHz, too coarse) advances with it.
//! The firmware reports raw ticks; the xtask, which knows the board and the shift, converts them
//! to instructions. Repeated runs give identical counts. On real hardware the same ticks are
//! reference-clock time, which is what a deadline needs there.

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;

/// SysTick's counter is 24 bits wide.
const MASK: u32 = 0x00FF_FFFF;

/// A free-running SysTick.
pub struct Meter {
    syst: SYST,
}

impl Meter {
    /// Starts SysTick counting down from 2^24 − 1 on the processor clock, no interrupt.
    pub fn start(mut syst: SYST) -> Meter {
        syst.disable_interrupt();
        syst.set_clock_source(SystClkSource::Core);
        syst.set_reload(MASK);
        syst.clear_current();
        syst.enable_counter();
        Meter { syst }
    }

    /// Current counter value (counts down).
    #[inline(always)]
    pub fn now(&self) -> u32 {
        let _ = &self.syst;
        SYST::get_current()
    }

    /// Ticks from `start` to `end` (two [`Meter::now`] readings), modulo 2^24.
    #[inline(always)]
    pub fn ticks(start: u32, end: u32) -> u32 {
        start.wrapping_sub(end) & MASK
    }

    /// Gives SysTick back (e.g. to become the periodic tick).
    pub fn free(self) -> SYST {
        self.syst
    }
}
