//! The work of one 10 kHz tick, portable so the host runs exactly what the interrupt runs:
//! sample the sensors, step the monitor, drive the alarm pin, queue log events, fold the
//! estimate into the running digest.
//!
//! Two priorities: [`Ticker::tick`] is the 10 kHz interrupt's work; [`Ticker::background`]
//! runs the monitor's slow-lane work for that tick at a lower priority, and must finish before
//! the next tick (the interrupt skips a tick that finds it unfinished). Their costs are counted
//! by `cargo xtask run` (instructions under QEMU). A missed deadline is reported by the caller
//! as `ticks_elapsed > 1`: it is counted, logged, passed to the monitor (which raises
//! `overrun`), and the sample source skips the missed samples so the model stays in time.

use crate::board::SampleSource;
use crate::digest::Fnv1a;
use crate::event_log::{Event, EventLog};
use crate::monitor::functional_test::Procedure;
use crate::monitor::{Estimate, Flags, Inputs, Monitor};
use embedded_hal::digital::OutputPin;

/// Events the log holds between two drains of the main loop (the default; an image whose logger
/// drains faster than semihosting may hold fewer).
pub const LOG_CAPACITY: usize = 32;

/// A state line every this many ticks (100 Hz at 10 kHz).
pub const STATE_EVERY_TICKS: u32 = 100;

/// The word a run's digest folds in per tick: the estimate's own FNV-1a checksum (the last of
/// [`Estimate::to_words`]), which already covers every field — folding all fourteen words
/// again would hash each estimate twice in the 10 kHz path.
pub fn estimate_checksum(estimate: &Estimate) -> u32 {
    estimate.to_words().last().copied().unwrap_or(0)
}

/// The tick's state: monitor, sensors, alarm, a log of `N` events, counters.
pub struct Ticker<S, P, const N: usize = LOG_CAPACITY> {
    monitor: Monitor,
    source: S,
    alarm: P,
    log: EventLog<N>,
    last_flags: Flags,
    ticks: u32,
    overruns: u32,
    missed_ticks: u32,
    alarm_errors: u32,
    digest: Fnv1a,
    last: Option<Estimate>,
    last_inputs: Option<Inputs>,
    /// The tick at which the crew requests the functional test (`u32::MAX`: never), and which.
    test_at: (u32, Procedure),
}

/// Counters a run reports at its end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Totals {
    /// Ticks stepped.
    pub ticks: u32,
    /// Deadline overruns (events).
    pub overruns: u32,
    /// Ticks missed in all overruns.
    pub missed_ticks: u32,
    /// Log events overwritten before they were printed.
    pub log_overwritten: u32,
    /// Alarm-pin writes that failed.
    pub alarm_errors: u32,
    /// FNV-1a digest of every estimate's checksum word, in order.
    pub digest: u32,
}

impl<S: SampleSource, P: OutputPin, const N: usize> Ticker<S, P, N> {
    /// Starts with the alarm off. Inlined, so a caller writing it into a static builds the
    /// monitor there (the part's init stack).
    #[inline(always)]
    pub fn new(monitor: Monitor, source: S, mut alarm: P) -> Self {
        let alarm_errors = u32::from(alarm.set_low().is_err());
        Ticker {
            monitor,
            source,
            alarm,
            log: EventLog::new(),
            last_flags: Flags::default(),
            ticks: 0,
            overruns: 0,
            missed_ticks: 0,
            alarm_errors,
            digest: Fnv1a::new(),
            last: None,
            last_inputs: None,
            test_at: (u32::MAX, Procedure::Loaded),
        }
    }

    /// Requests the monitor's functional test of `procedure` before tick `tick` (counted from 0)
    /// steps.
    pub fn request_functional_test_at(&mut self, tick: u32, procedure: Procedure) {
        self.test_at = (tick, procedure);
    }

    /// One tick. `ticks_elapsed` is 1 when on time, `n > 1` after a missed deadline. Returns
    /// the estimate, or `None` once the source has run out.
    pub fn tick(&mut self, ticks_elapsed: u8) -> Option<Estimate> {
        let n = ticks_elapsed.max(1);
        if n > 1 {
            let missed = u32::from(n - 1);
            self.source.skip(missed);
            self.overruns = self.overruns.saturating_add(1);
            self.missed_ticks = self.missed_ticks.saturating_add(missed);
            self.log.push(Event::Overrun {
                tick: self.ticks,
                missed,
            });
        }
        let mut inputs = self.source.sample()?;
        inputs.ticks_elapsed = n;
        self.last_inputs = Some(inputs);
        if self.ticks == self.test_at.0 {
            // Refused (nothing started) when the configuration has no such procedure.
            let _ = self.monitor.request_functional_test(self.test_at.1);
        }
        let estimate = *self.monitor.tick(&inputs);
        self.ticks = self.ticks.saturating_add(1);
        self.digest.push(estimate_checksum(&estimate));

        let flags = estimate.flags;
        let alarm = if flags.any() {
            self.alarm.set_high()
        } else {
            self.alarm.set_low()
        };
        if alarm.is_err() {
            self.alarm_errors = self.alarm_errors.saturating_add(1);
        }
        if flags != self.last_flags {
            self.log.push(Event::FlagsChanged {
                tick: estimate.tick,
                before: self.last_flags,
                now: flags,
            });
            self.last_flags = flags;
        }
        if self.ticks.is_multiple_of(STATE_EVERY_TICKS) {
            self.log.push(Event::State {
                tick: estimate.tick,
                scene: estimate.scene,
                brake: estimate.brake,
                pressing_force_bits: estimate.pressing_force_n.to_bits(),
                braking_torque_bits: estimate.braking_torque_nm.to_bits(),
                flags,
            });
        }
        self.last = Some(estimate);
        Some(estimate)
    }

    /// The monitor's slow-lane work for the last tick (the lower-priority context).
    pub fn background(&mut self) {
        self.monitor.background();
    }

    /// The oldest queued log event.
    pub fn next_event(&mut self) -> Option<Event> {
        self.log.pop()
    }

    /// Clears the monitor's latched flags (an operator action; logged through the next tick).
    pub fn reset_flags(&mut self) {
        self.monitor.reset_flags();
    }

    /// The last estimate.
    pub fn last_estimate(&self) -> Option<Estimate> {
        self.last
    }

    /// The inputs the last tick stepped on (as the monitor saw them: ticks elapsed included).
    pub fn last_inputs(&self) -> Option<Inputs> {
        self.last_inputs
    }

    /// The monitor (e.g. for the trip recorder's copy between two ticks).
    pub fn monitor(&self) -> &Monitor {
        &self.monitor
    }

    /// Counters so far.
    pub fn totals(&self) -> Totals {
        Totals {
            ticks: self.ticks,
            overruns: self.overruns,
            missed_ticks: self.missed_ticks,
            log_overwritten: self.log.overwritten(),
            alarm_errors: self.alarm_errors,
            digest: self.digest.value(),
        }
    }

    /// The sample source (e.g. to read a stream's counters at the end of a run).
    pub fn source(&self) -> &S {
        &self.source
    }

    /// The alarm pin (e.g. to read back its state in a test).
    pub fn alarm(&mut self) -> &mut P {
        &mut self.alarm
    }
}
