//! A real part's sensors through the HAL, behind `noback::board`'s traits: the phase current
//! on ADC1 (PA3, continuous conversion: the tick reads the latest result), the motor encoder
//! on TIM4's encoder mode (PB6/PB7, 16-bit as the monitor expects), the output encoder on
//! TIM5's (PA0/PA1; an SPI absolute encoder would implement `EncoderCounter` the same way),
//! the drive command on PB0. The monitor's configuration is the block in the last flash sector
//! (`config_sector`).

use noback::board::{BoardSensors, CurrentAdc, EncoderCounter};
use stm32f4xx_hal::adc::config::{AdcConfig, Continuous, SampleTime, Sequence};
use stm32f4xx_hal::adc::Adc;
use stm32f4xx_hal::gpio::{Input, PA0, PA1, PA3, PB0, PB6, PB7};
use stm32f4xx_hal::hal_02::Qei as _;
use stm32f4xx_hal::pac::{ADC1, TIM4, TIM5};
use stm32f4xx_hal::qei::{self, Qei};
use stm32f4xx_hal::rcc::Rcc;

/// ADC1 converting the phase-current channel continuously.
pub struct PhaseCurrent(Adc<ADC1>);

impl CurrentAdc for PhaseCurrent {
    fn read_code(&mut self) -> u16 {
        self.0.current_sample()
    }
}

/// A timer in encoder mode.
pub struct Encoder<T: qei::Instance>(Qei<T>);

impl<T: qei::Instance> EncoderCounter for Encoder<T>
where
    T::Width: Into<u32>,
{
    fn read_count(&mut self) -> u32 {
        self.0.count().into()
    }
}

/// The part's four inputs.
pub type Sensors = BoardSensors<PhaseCurrent, Encoder<TIM4>, Encoder<TIM5>, PB0<Input>>;

/// The part's pins and peripherals the sensors use.
pub struct Wiring {
    /// ADC1 and its phase-current pin.
    pub adc: (ADC1, PA3),
    /// TIM4 and the motor encoder's A/B pins.
    pub motor: (TIM4, PB6, PB7),
    /// TIM5 and the output encoder's A/B pins.
    pub output: (TIM5, PA0, PA1),
    /// The drive-command input.
    pub drive: PB0,
}

/// Configures the sensors and the monitor (the unit's configuration block).
pub fn setup(rcc: &mut Rcc, w: Wiring) -> (crate::io::Stream, Sensors) {
    let (adc1, pa3) = w.adc;
    let config = AdcConfig::default().continuous(Continuous::Continuous);
    let mut adc = Adc::new(adc1, true, config, rcc);
    let pin = pa3.into_analog();
    adc.configure_channel(&pin, Sequence::One, SampleTime::Cycles_56);
    adc.start_conversion();
    let (tim4, pb6, pb7) = w.motor;
    let motor = Encoder(Qei::new(tim4, (pb6, pb7), rcc));
    let (tim5, pa0, pa1) = w.output;
    let output = Encoder(Qei::new(tim5, (pa0, pa1), rcc));
    let drive = w.drive.into_input();
    let sensors = BoardSensors::new(PhaseCurrent(adc), motor, output, drive);
    (crate::io::Stream, sensors)
}
