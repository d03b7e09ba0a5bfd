//! Turning the truth into the MCU's raw readings through `noback::sensors::SensorConfig`:
//! current ADC codes (offset binary, clamped), a wrapping motor-encoder counter and a wrapping
//! absolute output encoder, with deterministic seeded noise and the sensor faults.

use crate::fault::{Fault, FaultKind};
use crate::model::Sample;
use crate::scene::Noise;
use crate::trace::{Trace, TraceRow};
use noback::sensors::SensorConfig;

/// A tiny deterministic PRNG (SplitMix64) with Gaussian samples by Box–Muller.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// Seeded generator.
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in (0, 1].
    pub fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 1.0) / (1u64 << 53) as f64
    }

    /// Standard normal.
    pub fn normal(&mut self) -> f64 {
        let u1 = self.uniform();
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

/// ADC code of a current (A): offset binary, mid-scale = 0 A, clamped to the converter range.
pub fn current_code(s: &SensorConfig, current_a: f64) -> u16 {
    let full = 1u32 << s.current_adc_bits.clamp(1, 16);
    let code = (current_a / s.amps_per_count()).round() + f64::from(full / 2);
    code.clamp(0.0, f64::from(full - 1)) as u16
}

/// Wrap an integer count into `bits` bits.
fn wrap(count: i64, bits: u8) -> u32 {
    let modulus = 1i64 << bits.clamp(1, 32);
    count.rem_euclid(modulus) as u32
}

/// Build the sensor trace of a run.
pub fn trace(
    samples: &[Sample],
    sensors: &SensorConfig,
    noise: &Noise,
    faults: &[Fault],
    sample_rate_hz: f64,
) -> Trace {
    let mut rng = Rng::new(noise.seed);
    let out_bits = sensors.output_encoder_bits;
    let out_counts = 1i64 << out_bits.clamp(1, 24);
    let mut stuck_at: Option<u32> = None;
    let rows = samples
        .iter()
        .map(|s| {
            let commanded = sensors.current_for_torque_a(s.drive_torque_nm);
            let mut current = noise.current_gain * commanded + noise.current_offset_a;
            if noise.current_noise_a > 0.0 {
                current += noise.current_noise_a * rng.normal();
            }
            let mut current_scale = 1.0;
            let mut jump = 0i64;
            let mut stuck = false;
            for f in faults
                .iter()
                .filter(|f| f.kind.is_sensor() && f.at_s <= s.t_s)
            {
                match f.kind {
                    FaultKind::CurrentOpen => current_scale *= 1.0 - f.severity,
                    FaultKind::EncoderJump => {
                        jump += (f.severity * out_counts as f64 / 8.0).round() as i64
                    }
                    FaultKind::EncoderStuck => stuck = true,
                    _ => {}
                }
            }
            let motor = (s.input_angle_rad / sensors.input_rad_per_motor_count()).floor() as i64;
            let out_raw = wrap(
                (s.output_angle_rad / sensors.output_rad_per_count()).floor() as i64 + jump,
                out_bits,
            );
            let output_count = if stuck {
                *stuck_at.get_or_insert(out_raw)
            } else {
                out_raw
            };
            TraceRow {
                t_s: s.t_s,
                current_code: current_code(sensors, current * current_scale),
                motor_count: wrap(motor, sensors.motor_counter_bits),
                output_count,
                drive_on: s.drive_on,
                pressing_force_n: s.pressing_force_n,
                braking_torque_nm: s.braking_torque_nm,
                output_speed_rad_s: s.output_speed_rad_s,
                input_speed_rad_s: s.input_speed_rad_s,
                output_angle_rad: s.output_angle_rad,
                brake_state: s.brake_state,
                // The drive's current loop closes on its own sensing: its command is the current.
                current_command_code: Some(current_code(sensors, commanded)),
            }
        })
        .collect();
    Trace {
        sample_rate_hz,
        rows,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use noback::sensors::DEFAULT_SENSORS;

    #[test]
    fn codes_wrap_and_clamp() {
        let s = DEFAULT_SENSORS;
        assert_eq!(current_code(&s, 0.0), 2048);
        assert_eq!(current_code(&s, 100.0), 4095);
        assert_eq!(current_code(&s, -100.0), 0);
        assert_eq!(wrap(-1, 16), 65535);
        assert_eq!(wrap(65536 + 5, 16), 5);
        assert_eq!(wrap(-1, 14), 16383);
    }

    #[test]
    fn noise_is_deterministic() {
        let mut a = Rng::new(7);
        let mut b = Rng::new(7);
        for _ in 0..10 {
            assert_eq!(a.normal().to_bits(), b.normal().to_bits());
        }
        let mut r = Rng::new(3);
        let n = 20_000;
        let mean = (0..n).map(|_| r.normal()).sum::<f64>() / n as f64;
        assert!(mean.abs() < 0.03, "{mean}");
    }
}
