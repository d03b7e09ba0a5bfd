//! Where samples come from and where the log goes, per build: under QEMU the shared session
//! (trace streamed from the host, defmt over semihosting); on a part the board's sensors and
//! defmt over RTT.

use crate::app::App;

/// Events the tick's log holds until the idle loop drains it: semihosting is slow under QEMU;
/// RTT takes each within microseconds on a part, whose RAM budget is 4 KB (issue 15).
#[cfg(feature = "qemu")]
pub const LOG_EVENTS: usize = noback::app::LOG_CAPACITY;
#[cfg(feature = "hw")]
pub const LOG_EVENTS: usize = 8;

/// The tick's sample source under QEMU: the twin's trace, streamed from the host.
#[cfg(feature = "qemu")]
pub type Source = noback::replay::Streamed<'static>;
#[cfg(feature = "qemu")]
pub use noback::platform::session::{log, Stream};

/// The `summary` line and the exit, at the trace's end.
#[cfg(feature = "qemu")]
pub fn finish(app: &App, isr_max: u32, background_max: u32) -> ! {
    let deadline = noback::platform::session::Deadline {
        isr_max,
        background_max,
        period: crate::clock::SYSTICK_PER_TICK,
    };
    noback::platform::session::finish(app, &deadline)
}

/// The tick's sample source on a part: ADC and encoder timers.
#[cfg(feature = "hw")]
pub type Source = crate::sensors::Sensors;

/// On a part nothing streams in: the idle loop only drains the log.
#[cfg(feature = "hw")]
pub struct Stream;

#[cfg(feature = "hw")]
impl Stream {
    /// Nothing to feed.
    pub fn feed(&mut self) -> bool {
        false
    }
}

/// One defmt line per event, over RTT: raw fields, decoded on the host (no `core::fmt` in the
/// image: its `Debug` formatting cost 2.7 KB of the 40 KB budget).
#[cfg(feature = "hw")]
pub fn log(event: &noback::event_log::Event) {
    use noback::event_log::Event;
    match *event {
        Event::State {
            tick,
            scene,
            brake,
            pressing_force_bits,
            braking_torque_bits,
            flags,
        } => defmt::info!(
            "state tick={=u32} scene={=u8} brake={=u8} force_q16={=i32} torque_q16={=i32} flags={=u8:#04x}",
            tick,
            scene as u8,
            brake as u8,
            pressing_force_bits,
            braking_torque_bits,
            flags.bits()
        ),
        Event::FlagsChanged { tick, before, now } => defmt::info!(
            "flags tick={=u32} before={=u8:#04x} now={=u8:#04x}",
            tick,
            before.bits(),
            now.bits()
        ),
        Event::Overrun { tick, missed } => {
            defmt::info!("overrun tick={=u32} missed={=u32}", tick, missed)
        }
    }
}

/// A part's sensors never run out, so this is never reached; it parks the core.
#[cfg(feature = "hw")]
pub fn finish(_app: &App, _isr_max: u32, _background_max: u32) -> ! {
    loop {
        cortex_m::asm::wfi();
    }
}
