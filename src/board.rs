//! What the firmware needs from a board: one small trait per sensor, so a real board support
//! package plugs in with one implementation each.
//!
//! - [`CurrentAdc`]: the phase-current conversion result (our own trait: embedded-hal 1.0 has
//!   no ADC trait).
//! - [`EncoderCounter`]: a counter register (motor encoder, output absolute encoder).
//! - The drive-command input is an `embedded_hal::digital::InputPin` and the alarm output an
//!   `embedded_hal::digital::OutputPin`: the standard traits every HAL already implements.
//!
//! [`BoardSensors`] gathers the four into a [`SampleSource`], the one thing the 10 kHz tick
//! reads; a replayed twin trace (`crate::replay`) is another. Reads happen inside the interrupt,
//! so implementations must not block: return the latest completed conversion or latched count.

use crate::monitor::Inputs;
use embedded_hal::digital::InputPin;

/// The phase-current ADC.
pub trait CurrentAdc {
    /// The latest conversion, offset binary (mid-scale = 0 A).
    fn read_code(&mut self) -> u16;
}

/// An encoder counter register.
pub trait EncoderCounter {
    /// The counter's present value; it wraps at its register width.
    fn read_count(&mut self) -> u32;
}

/// Where one tick's raw readings come from.
pub trait SampleSource {
    /// The readings of this tick (`ticks_elapsed` = 1; the caller sets it), or `None` when the
    /// source has run out (the end of a replayed trace; a board never runs out).
    fn sample(&mut self) -> Option<Inputs>;

    /// `ticks` ticks went by unsampled (a missed deadline). A board reads the present state
    /// anyway, so the default does nothing; a replay skips as many records to stay in time.
    fn skip(&mut self, ticks: u32) {
        let _ = ticks;
    }
}

/// A real board's four inputs.
pub struct BoardSensors<A, M, O, D> {
    /// Phase-current ADC.
    pub adc: A,
    /// Motor-encoder counter.
    pub motor: M,
    /// Output-shaft encoder.
    pub output: O,
    /// Drive-command input (high = drive commanded).
    pub drive: D,
    /// Last good drive-command reading, held if a read fails.
    last_drive: bool,
}

impl<A, M, O, D> BoardSensors<A, M, O, D> {
    /// Gathers the four inputs.
    pub fn new(adc: A, motor: M, output: O, drive: D) -> Self {
        BoardSensors {
            adc,
            motor,
            output,
            drive,
            last_drive: false,
        }
    }
}

impl<A: CurrentAdc, M: EncoderCounter, O: EncoderCounter, D: InputPin> SampleSource
    for BoardSensors<A, M, O, D>
{
    fn sample(&mut self) -> Option<Inputs> {
        // A GPIO read cannot fail on the MCUs we target (`Infallible`); if a HAL's can, the last
        // good value is held rather than inventing a drive state.
        if let Ok(high) = self.drive.is_high() {
            self.last_drive = high;
        }
        Some(Inputs::new(
            self.adc.read_code(),
            self.motor.read_count(),
            self.output.read_count(),
            self.last_drive,
        ))
    }
}
