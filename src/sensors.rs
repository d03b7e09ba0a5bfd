//! The sensor and drive-train model both halves share: what the MCU measures and how a physical
//! quantity becomes a raw reading.
//!
//! These are our defaults (MODEL.md, "Sensors and actuator"), not the paper's; every field is
//! configurable. The twin uses the f64 forward maps here to quantise its traces; the monitor
//! converts the same numbers once, in its constructor, into fixed-point scale factors.

/// Motor, reducer and sensor parameters.
#[cfg_attr(feature = "config-block", derive(serde::Serialize, serde::Deserialize))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorConfig {
    /// Motor torque constant (N·m/A).
    pub motor_torque_constant_nm_a: f64,
    /// Main reducer ratio, motor turns per input-shaft turn.
    pub reducer_ratio: f64,
    /// Main reducer efficiency (0..1].
    pub reducer_efficiency: f64,
    /// Phase-current ADC resolution (bits); offset binary, mid-scale = 0 A.
    pub current_adc_bits: u8,
    /// Current at ADC full scale (A): the converter spans ±this value.
    pub current_full_scale_a: f64,
    /// Motor encoder counts per motor revolution (before the reducer).
    pub motor_encoder_counts_per_rev: u32,
    /// Output-shaft absolute encoder resolution (bits per revolution).
    pub output_encoder_bits: u8,
    /// Width of the motor-encoder counter register (bits); it wraps modulo 2^bits.
    pub motor_counter_bits: u8,
}

/// Defaults from MODEL.md: 0.06 N·m/A, ratio 30 at 0.9, 12-bit ADC over ±30 A,
/// 4096 counts/rev motor encoder in a 16-bit counter, 14-bit output encoder.
pub const DEFAULT_SENSORS: SensorConfig = SensorConfig {
    motor_torque_constant_nm_a: 0.06,
    reducer_ratio: 30.0,
    reducer_efficiency: 0.9,
    current_adc_bits: 12,
    current_full_scale_a: 30.0,
    motor_encoder_counts_per_rev: 4096,
    output_encoder_bits: 14,
    motor_counter_bits: 16,
};

impl Default for SensorConfig {
    fn default() -> Self {
        DEFAULT_SENSORS
    }
}

const TAU: f64 = core::f64::consts::TAU;

impl SensorConfig {
    /// Amperes per ADC count.
    pub fn amps_per_count(&self) -> f64 {
        2.0 * self.current_full_scale_a / f64::from(1_u32 << self.current_adc_bits.clamp(1, 16))
    }

    /// Input-shaft torque (N·m) produced by a motor current (A), through reducer and efficiency.
    pub fn input_torque_nm(&self, current_a: f64) -> f64 {
        current_a * self.motor_torque_constant_nm_a * self.reducer_ratio * self.reducer_efficiency
    }

    /// Motor current (A) that produces an input-shaft torque (N·m); inverse of [`Self::input_torque_nm`].
    pub fn current_for_torque_a(&self, input_torque_nm: f64) -> f64 {
        input_torque_nm
            / (self.motor_torque_constant_nm_a * self.reducer_ratio * self.reducer_efficiency)
    }

    /// Input-shaft radians per motor-encoder count.
    pub fn input_rad_per_motor_count(&self) -> f64 {
        TAU / (f64::from(self.motor_encoder_counts_per_rev) * self.reducer_ratio)
    }

    /// Output-shaft radians per output-encoder count.
    pub fn output_rad_per_count(&self) -> f64 {
        TAU / f64::from(1_u32 << self.output_encoder_bits.clamp(1, 24))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_give_the_expected_resolutions() {
        let s = DEFAULT_SENSORS;
        assert!((s.amps_per_count() - 60.0 / 4096.0).abs() < 1e-15);
        // One motor count is 2π/(4096·30) rad at the input shaft: 51 µrad.
        assert!((s.input_rad_per_motor_count() - 5.113e-5).abs() < 1e-8);
        assert!((s.output_rad_per_count() - 3.835e-4).abs() < 1e-7);
        let torque = s.input_torque_nm(10.0);
        assert!((s.current_for_torque_a(torque) - 10.0).abs() < 1e-12);
    }
}
