//! Sensing: raw ADC code and counters into currents, counts and the output's angle word, with
//! their plausibility (`sensor_fault`), the input shaft's speed and the output's position
//! history (the holding estimate's impacts).
//!
//! | quantity | format | range | resolution |
//! |---|---|---|---|
//! | current | `i32` ADC counts about mid-scale | ±2^15 | 1 count |
//! | counter deltas | `i32` counts, wrapping difference | ±half the counter | 1 count |
//! | angle word | `u32`, wrapping | one turn | 2π/2³² rad |
//! | input speed | [`Q16`] rad/s, saturating | ±32 768 | 1.5e-5 rad/s |
//! | position history | `i16` counts mod 2^16, wrapping | differences over ≤ 63 ticks | 1 count |
//! | still span's \|current\| sum | `u32` counts, saturating (reads free after ≥ 13 s at full scale) | 2^32 | 1 count |

use super::config::{Config, ConfigError};
use super::convert::{
    counts, filter_gain, finite, positive, require, scale, ticks, Q16_ENVELOPE, Q16_ONE,
};
use super::scale::Scale;
use super::schedule::SLOW;
use super::Inputs;
use crate::fx::{lowpass, Gain, Q16};

/// Ticks of output-position history: a power of two above twice the longest impact window.
const POSITION_HISTORY: usize = 64;
/// A second difference this small (counts) is a held output's one-count dither (`0 1 0` gives
/// 2), not an impact: read as none.
const DITHER_COUNTS: u16 = 2;

/// The sensors' constants.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SenseSettings {
    adc_max_code: u16,
    /// The code at zero current: mid-scale plus the commissioned offset.
    adc_mid: i32,
    adc_rail_ticks: u32,
    current_off_counts: i32,
    pub out_bits: u8,
    out_mask: u32,
    /// `32 − bits`: a counter shifted to the top so that wrapping `i32` arithmetic is its modulo.
    out_shift: u32,
    /// Largest plausible output step in one tick (counts).
    pub out_jump_counts: i32,
    motor_mask: u32,
    motor_shift: u32,
    motor_jump_counts: i32,
    lost_motor_counts: u32,
    lost_out_counts: u32,
    /// The motor's span against a still output while the drive carries no torque.
    free_motor_counts: u32,
    /// Mean |current| (counts) over the still span at or above which the drive carries a load.
    driven_counts: u32,
    /// Motor counts over one slow-lane period → Q16 rad/s of the input shaft.
    input_speed: Scale<11>,
    input_alpha: Gain,
    /// Ticks `m` of the impact's second difference (1..=31).
    impact_window: u8,
    /// Second difference of the output position (counts) → Q16 N·m: `J_s·Δθ/(m·h)²`.
    impact_torque: Scale<8>,
}

impl SenseSettings {
    pub fn new(c: &Config) -> Result<SenseSettings, ConfigError> {
        let (s, t, tick_hz) = (&c.sensors, &c.thresholds, c.tick_hz);
        let h = 1.0 / tick_hz;
        let ratio = positive(s.reducer_ratio, "sensors.reducer_ratio")?;
        require(
            (4..=16).contains(&s.current_adc_bits),
            "sensors.current_adc_bits",
        )?;
        positive(s.current_full_scale_a, "sensors.current_full_scale_a")?;
        require(
            (8..=24).contains(&s.output_encoder_bits),
            "sensors.output_encoder_bits",
        )?;
        require(
            (8..=32).contains(&s.motor_counter_bits),
            "sensors.motor_counter_bits",
        )?;
        require(
            s.motor_encoder_counts_per_rev != 0,
            "sensors.motor_encoder_counts_per_rev",
        )?;
        require((1..=32).contains(&c.max_catchup_ticks), "max_catchup_ticks")?;
        let (out_rad, in_rad) = (s.output_rad_per_count(), s.input_rad_per_motor_count());
        let max_out = positive(
            t.max_output_speed_rad_s,
            "thresholds.max_output_speed_rad_s",
        )?;
        let max_motor = positive(t.max_motor_speed_rad_s, "thresholds.max_motor_speed_rad_s")?;
        if max_out > Q16_ENVELOPE || max_motor / ratio > Q16_ENVELOPE {
            return Err(ConfigError::Overflow {
                parameter: "thresholds.max_output_speed_rad_s",
            });
        }
        // A late step may cover `max_catchup_ticks` and must stay within half a counter period,
        // or the wrapping difference would alias.
        let catchup = f64::from(c.max_catchup_ticks);
        let out_jump = max_out * h / out_rad + 1.0;
        let motor_jump = max_motor * h / (in_rad * ratio) + 1.0;
        if out_jump * catchup >= f64::from(1_u32 << (s.output_encoder_bits - 1)) {
            return Err(ConfigError::Overflow {
                parameter: "sensors.output_encoder_bits",
            });
        }
        if motor_jump * catchup >= f64::from(1_u32 << (s.motor_counter_bits - 1).min(30)) {
            return Err(ConfigError::Overflow {
                parameter: "sensors.motor_counter_bits",
            });
        }
        let current_off =
            positive(t.current_off_max_a, "thresholds.current_off_max_a")? / s.amps_per_count();
        // The reading at zero current: mid-scale plus the commissioned offset, in whole counts.
        let offset = finite(c.current_offset_a, "current_offset_a")? / s.amps_per_count();
        require(
            offset.abs() <= f64::from(1_u32 << (s.current_adc_bits - 3)),
            "current_offset_a",
        )?;
        let lost = positive(t.max_lost_motion_rad, "thresholds.max_lost_motion_rad")?;
        let free = positive(t.free_input_travel_rad, "thresholds.free_input_travel_rad")?;
        require(free >= lost, "thresholds.free_input_travel_rad")?;
        let driven = finite(t.driven_torque_nm, "thresholds.driven_torque_nm")?;
        require(driven >= 0.0, "thresholds.driven_torque_nm")?;
        let driven = s.current_for_torque_a(driven) / s.amps_per_count();
        require(driven < 1.0e5, "thresholds.driven_torque_nm")?;
        let impact_m = positive(t.impact_window_s, "thresholds.impact_window_s")? * tick_hz + 0.5;
        require(
            (1.0..32.0).contains(&impact_m),
            "thresholds.impact_window_s",
        )?;
        let m = impact_m as u8; // 1 ≤ m < 32 (checked above)
        let mh = f64::from(m) * h;
        let j = c.mechanism.output_inertia_kg_m2;
        let slow_h = h * f64::from(SLOW.ticks);
        Ok(SenseSettings {
            adc_max_code: ((1_u32 << s.current_adc_bits) - 1) as u16,
            adc_mid: (1 << (s.current_adc_bits - 1)) + rounded(offset),
            adc_rail_ticks: ticks(t.adc_rail_time_s, tick_hz, "thresholds.adc_rail_time_s")?,
            current_off_counts: counts(current_off, "thresholds.current_off_max_a")?,
            out_bits: s.output_encoder_bits,
            out_mask: (1_u32 << s.output_encoder_bits) - 1,
            out_shift: 32 - u32::from(s.output_encoder_bits),
            out_jump_counts: counts(out_jump, "thresholds.max_output_speed_rad_s")?,
            motor_mask: u32::MAX >> (32 - u32::from(s.motor_counter_bits)),
            motor_shift: 32 - u32::from(s.motor_counter_bits),
            motor_jump_counts: counts(motor_jump, "thresholds.max_motor_speed_rad_s")?,
            lost_motor_counts: counts(lost / in_rad, "thresholds.max_lost_motion_rad")? as u32,
            lost_out_counts: counts(lost / out_rad, "thresholds.max_lost_motion_rad")? as u32,
            free_motor_counts: counts(free / in_rad, "thresholds.free_input_travel_rad")? as u32,
            driven_counts: rounded(driven) as u32, // 0 ≤ driven < 1e5 (checked above)
            input_speed: scale(
                in_rad / slow_h * Q16_ONE,
                "sensors.motor_encoder_counts_per_rev",
            )?,
            input_alpha: filter_gain(
                t.input_speed_filter_hz,
                tick_hz,
                SLOW,
                "thresholds.input_speed_filter_hz",
            )?,
            impact_window: m,
            impact_torque: scale(
                j * out_rad / (mh * mh) * Q16_ONE,
                "thresholds.impact_window_s",
            )?,
        })
    }
}

/// What sensing hands on for one call.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug)]
pub(crate) struct Sensed {
    /// Ticks covered (1 when on time, ≤ 255).
    pub n: u32,
    pub drive: bool,
    /// The drive command changed (and on the first call).
    pub drive_edge: bool,
    /// First call since power-on.
    pub first: bool,
    /// Output and motor counters (masked), the output as an angle word.
    pub out: u32,
    pub motor: u32,
    pub angle: u32,
    pub d_out: i32,
    pub out_ok: bool,
    /// Phase current (ADC counts about mid-scale).
    pub current: i32,
    /// The drive's current command (ADC code), if the inputs carry it.
    pub command_code: Option<u16>,
    /// An implausible reading this call.
    pub fault: bool,
    /// The part of `fault` known before the counters' steps (ADC code, rail, range).
    pub early_fault: bool,
}

impl Sensed {
    /// Before the first call.
    pub const NONE: Sensed = Sensed {
        n: 0,
        drive: false,
        drive_edge: false,
        first: false,
        out: 0,
        motor: 0,
        angle: 0,
        d_out: 0,
        out_ok: false,
        current: 0,
        command_code: None,
        fault: false,
        early_fault: false,
    };
}

/// The sensors' memory.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Debug)]
pub(crate) struct Sense {
    started: bool,
    prev_out: u32,
    prev_motor: u32,
    prev_drive: bool,
    rail_ticks: u32,
    /// Net travel (counts, saturating) of the motor while the output counter stands still,
    /// and of the output while the motor's does.
    still_out: i32,
    still_motor: i32,
    /// |current| summed (counts, saturating) and calls counted over the output's still span.
    still_current: u32,
    still_calls: u32,
    input_speed: Q16,
    /// The motor counter at the last input-speed sample.
    speed_motor: u32,
    #[cfg_attr(feature = "config-block", serde(with = "serde_big_array::BigArray"))]
    positions: [i16; POSITION_HISTORY],
    position_head: usize,
    /// Consecutive on-time plausible ticks with the drive off in the history.
    position_ticks: u32,
}

impl Sense {
    pub const fn new() -> Sense {
        Sense {
            started: false,
            prev_out: 0,
            prev_motor: 0,
            prev_drive: false,
            rail_ticks: 0,
            still_out: 0,
            still_motor: 0,
            still_current: 0,
            still_calls: 0,
            input_speed: Q16::ZERO,
            speed_motor: 0,
            positions: [0; POSITION_HISTORY],
            position_head: 0,
            position_ticks: 0,
        }
    }

    /// Reads one call's inputs. `carrying`: the previous call's scene was `Driving` (the stuck-
    /// counter check runs only there).
    pub fn read(&mut self, k: &SenseSettings, i: &Inputs, n: u32, carrying: bool) -> Sensed {
        let code = i.current_adc_code;
        let drive = i.drive_commanded;
        let out = i.output_counter & k.out_mask;
        let motor = i.motor_counter & k.motor_mask;
        // A drive at its current limit reads at the rail while the motor moves; a rail with
        // the motor still is the ADC.
        let at_rail = code == 0 || code >= k.adc_max_code;
        self.rail_ticks = if at_rail && (!drive || motor == self.prev_motor || !self.started) {
            self.rail_ticks.saturating_add(n)
        } else {
            0
        };
        let current = i32::from(code.min(k.adc_max_code)) - k.adc_mid;
        let early_fault = code > k.adc_max_code // the converter cannot produce it
            || self.rail_ticks >= k.adc_rail_ticks
            || (!drive && (current > k.current_off_counts || -current > k.current_off_counts))
            || out != i.output_counter
            || motor != i.motor_counter;
        let first = !self.started;
        if first {
            self.started = true;
            self.prev_out = out;
            self.prev_motor = motor;
            self.speed_motor = motor;
            self.prev_drive = !drive; // the first call is a drive edge
        }
        let d_out = wrapping_delta(self.prev_out, out, k.out_shift);
        let d_motor = wrapping_delta(self.prev_motor, motor, k.motor_shift);
        self.prev_out = out;
        self.prev_motor = motor;
        let (out_jump, motor_jump) = if n == 1 {
            (k.out_jump_counts, k.motor_jump_counts)
        } else {
            let n = n as i32; // ≤ 255
            (
                k.out_jump_counts.saturating_mul(n),
                k.motor_jump_counts.saturating_mul(n),
            )
        };
        // Jump limits are ≥ 1 (positive): the unsigned comparison is exact.
        let out_ok = d_out.unsigned_abs() <= out_jump as u32;
        let motor_ok = d_motor.unsigned_abs() <= motor_jump as u32;
        if !drive {
            self.record_position(d_out, n == 1 && out_ok);
        } else {
            self.position_ticks = 0;
        }
        let stuck = carrying
            && drive
            && out_ok
            && motor_ok
            && self.stuck_counter(k, d_out, d_motor, current);
        if !(carrying && drive && out_ok && motor_ok) {
            self.still_out = 0;
            self.still_motor = 0;
            (self.still_current, self.still_calls) = (0, 0);
        }
        let drive_edge = drive != self.prev_drive;
        self.prev_drive = drive;
        Sensed {
            n,
            drive,
            drive_edge,
            first,
            out,
            motor,
            angle: out << k.out_shift,
            d_out,
            out_ok,
            current,
            command_code: i.current_command_code,
            fault: early_fault || !out_ok || !motor_ok || stuck,
            early_fault,
        }
    }

    /// The input shaft's speed over the last slow-lane period (motor encoder ÷ ratio),
    /// filtered; run on the slow lane's classification slot.
    pub fn sample_input_speed(&mut self, k: &SenseSettings) {
        let d = wrapping_delta(self.speed_motor, self.prev_motor, k.motor_shift);
        self.speed_motor = self.prev_motor;
        let raw = Q16::from_bits(k.input_speed.apply(d));
        self.input_speed = lowpass(self.input_speed, raw, k.input_alpha);
    }

    /// Counters of the last call (the common-slip check restarts from them).
    pub fn counters(&self) -> (u32, u32) {
        (self.prev_out, self.prev_motor)
    }

    /// The input shaft's filtered speed.
    pub fn input_speed(&self) -> Q16 {
        self.input_speed
    }

    /// Stuck counter: while driving, one shaft's net travel passes the lost-motion limit while
    /// the other's counter stands still (net, not path: a servo dithering at rest goes nowhere);
    /// a motor turning against a still output with no drive torque has the free span.
    fn stuck_counter(&mut self, k: &SenseSettings, d_out: i32, d_motor: i32, current: i32) -> bool {
        if d_out == 0 {
            self.still_out = self.still_out.saturating_add(d_motor);
            self.still_current = self.still_current.saturating_add(current.unsigned_abs());
            self.still_calls = self.still_calls.saturating_add(1);
        } else {
            self.still_out = 0;
            (self.still_current, self.still_calls) = (0, 0);
        }
        self.still_motor = if d_motor == 0 {
            self.still_motor.saturating_add(d_out)
        } else {
            0
        };
        let far = self.still_out.unsigned_abs();
        (far > k.lost_motor_counts
            && (far > k.free_motor_counts
                || self.still_current >= self.still_calls.saturating_mul(k.driven_counts)))
            || self.still_motor.unsigned_abs() > k.lost_out_counts
    }

    /// One history entry per call with the drive off (counts mod 2^16, wrapping: only
    /// differences over ≤ 63 ticks are used); a late or implausible step restarts it.
    fn record_position(&mut self, d_out: i32, on_time_ok: bool) {
        let head = self.position_head % POSITION_HISTORY;
        let newest = self.positions.get(head).copied().unwrap_or(0);
        self.position_head = (head + 1) % POSITION_HISTORY;
        if let Some(slot) = self.positions.get_mut(self.position_head) {
            *slot = newest.wrapping_add(d_out as i16); // |d_out| ≤ out_jump when used
        }
        self.position_ticks = if on_time_ok {
            self.position_ticks.saturating_add(1)
        } else {
            0
        };
    }

    /// `J_s·α` from the second difference of the position over two windows of `m` ticks
    /// (`θ(t) − 2θ(t−m) + θ(t−2m)`); zero until the history holds `2m` on-time ticks, and
    /// within [`DITHER_COUNTS`].
    pub fn impact_torque(&self, k: &SenseSettings) -> Q16 {
        let m = usize::from(k.impact_window);
        if self.position_ticks < 2 * u32::from(k.impact_window) {
            return Q16::ZERO;
        }
        let at = |back: usize| {
            self.positions
                .get((self.position_head + POSITION_HISTORY - back) % POSITION_HISTORY)
                .copied()
                .unwrap_or(0)
        };
        // Wrapping (mod 2^16): the true second difference over 2m ≤ 62 ticks is far below 2^15.
        let second = at(0)
            .wrapping_sub(at(m).wrapping_mul(2))
            .wrapping_add(at(2 * m));
        let second = if second.unsigned_abs() <= DITHER_COUNTS {
            0
        } else {
            second
        };
        Q16::from_bits(k.impact_torque.apply(i32::from(second)))
    }
}

/// The signed difference `now − prev` of a counter shifted to the top by `shift` bits
/// (wrapping: the counter is modular).
#[inline]
fn wrapping_delta(prev: u32, now: u32, shift: u32) -> i32 {
    ((now << shift).wrapping_sub(prev << shift) as i32) >> shift
}

/// `x·n` for a tick count `n ≥ 1`, saturating; free when `n = 1` (every on-time call).
#[inline]
pub(crate) fn times(x: i32, n: i32) -> i32 {
    if n == 1 {
        x
    } else {
        x.saturating_mul(n)
    }
}

/// `x` rounded half away from zero (|x| checked to fit beforehand).
fn rounded(x: f64) -> i32 {
    if x < 0.0 {
        -((0.5 - x) as i32)
    } else {
        (x + 0.5) as i32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The motor moving `steps` (counts per tick) while the output counter stands still, the
    /// current reading `code`.
    fn stuck_after(code: u16, steps: impl Iterator<Item = i32>) -> bool {
        let k = SenseSettings::new(&Config::default()).expect("default configuration");
        let (mut sense, mut motor) = (Sense::new(), 0_u32);
        let mut stuck = false;
        for d in steps {
            motor = motor.wrapping_add_signed(d) & k.motor_mask;
            let x = sense.read(&k, &Inputs::new(code, motor, 100, true), 1, true);
            stuck |= x.fault;
        }
        stuck
    }

    /// A reading whose current carries `ratio` × the driven floor.
    fn driven_code(k: &SenseSettings, ratio: f64) -> u16 {
        (f64::from(k.adc_mid) + ratio * f64::from(k.driven_counts)) as u16
    }

    #[test]
    fn the_stuck_counter_counts_net_travel_not_a_dithering_path() {
        let k = SenseSettings::new(&Config::default()).expect("default configuration");
        let (limit, code) = (k.lost_motor_counts as i32, driven_code(&k, 2.0));
        // A servo dithering ±3 counts at rest for 10 limits' worth of path: not stuck.
        assert!(!stuck_after(
            code,
            (0..10 * limit / 3).map(|i| if i % 2 == 0 { 3 } else { -3 })
        ));
        // Turning one way 3 counts a tick past the limit: stuck.
        assert!(stuck_after(code, (0..limit / 3 + 2).map(|_| 3)));
        // Up to the limit: not yet.
        assert!(!stuck_after(code, (0..limit / 3 - 1).map(|_| 3)));
    }

    #[test]
    fn a_held_outputs_one_count_dither_is_no_impact() {
        let k = SenseSettings::new(&Config::default()).expect("default configuration");
        let mut sense = Sense::new();
        let mut largest = Q16::ZERO;
        let mut read = |out: u32| {
            sense.read(&k, &Inputs::new(k.adc_mid as u16, 0, out, false), 1, false);
            sense.impact_torque(&k).saturating_abs()
        };
        // A count's flicker now and then, and a count's step: no impact.
        for i in 0..200_u32 {
            largest = largest.max(read(100 + u32::from(i % 7 == 3 && i < 120 || i > 150)));
        }
        assert_eq!(largest, Q16::ZERO);
        // A knock of 4 counts is one.
        let knock = (0..40).map(|_| read(105)).fold(Q16::ZERO, Q16::max);
        assert!(knock > Q16::from_num(40), "{knock}");
    }

    #[test]
    fn a_motor_turning_free_of_a_still_output_has_the_free_span() {
        let k = SenseSettings::new(&Config::default()).expect("default configuration");
        let (lost, free) = (k.lost_motor_counts as i32, k.free_motor_counts as i32);
        assert!(k.driven_counts > 0 && free > lost + 6);
        // Past the lost motion with no drive torque (half the driven floor): not yet stuck.
        let idle = driven_code(&k, 0.5);
        assert!(!stuck_after(idle, (0..lost / 3 + 2).map(|_| 3)));
        // Past the free span: stuck, torque or not.
        assert!(stuck_after(idle, (0..free / 3 + 2).map(|_| 3)));
        // The same travel carrying the driven floor: stuck at the lost motion.
        assert!(stuck_after(
            driven_code(&k, 1.0),
            (0..lost / 3 + 2).map(|_| 3)
        ));
        // The physical reading's preset: the input never turns free.
        let p = SenseSettings::new(&Config::physical_reading()).expect("physical reading");
        assert_eq!(p.driven_counts, 0);
    }
}
