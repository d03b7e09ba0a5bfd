//! Configuration (SI, `f64`, checked once) and its conversion into the fixed-point constants the
//! step uses ([`Params`]). Every division and unit conversion of the monitor happens here.

use super::scale::{Scale, ScaleError};
use super::slip_check::SlipLimits;
use crate::fx::{Gain, Q16};
use crate::mechanism::{Mechanism, TABLE2};
use crate::sensors::{SensorConfig, DEFAULT_SENSORS};

/// Observer gains of the current-estimator form (see [`crate::monitor`]): the angle, speed and
/// acceleration corrections per unit of angle innovation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObserverGains {
    /// l₁, angle correction (dimensionless).
    pub angle: f64,
    /// l₂, speed correction (1/s).
    pub speed_per_s: f64,
    /// l₃, acceleration correction (1/s²); the torque correction is `J_s·l₃`.
    pub accel_per_s2: f64,
}

impl ObserverGains {
    /// Gains that put the three error poles at `p = exp(−2π·bandwidth_hz/tick_hz)`:
    /// `l₁ = 1 − p³`, `l₂ = 3(1 − p)²(1 + p)/(2h)`, `l₃ = (1 − p)³/h²`.
    pub fn triple_pole(bandwidth_hz: f64, tick_hz: f64) -> ObserverGains {
        let h = 1.0 / tick_hz;
        let p = exp_neg(core::f64::consts::TAU * bandwidth_hz * h);
        let q = 1.0 - p;
        ObserverGains {
            angle: 1.0 - p * p * p,
            speed_per_s: 3.0 * q * q * (1.0 + p) / (2.0 * h),
            accel_per_s2: q * q * q / (h * h),
        }
    }

    /// Coefficients `[a2, a1, a0]` of the error dynamics' characteristic polynomial
    /// `z³ + a2·z² + a1·z + a0` for a step of `h` seconds.
    pub fn characteristic(&self, h: f64) -> [f64; 3] {
        let (l1, l2, l3) = (self.angle, self.speed_per_s, self.accel_per_s2);
        [
            h * h * l3 / 2.0 + h * l2 + l1 - 3.0,
            h * h * l3 / 2.0 - h * l2 - 2.0 * l1 + 3.0,
            l1 - 1.0,
        ]
    }

    /// Jury test: all roots of the characteristic polynomial strictly inside the unit circle.
    pub fn is_stable(&self, h: f64) -> bool {
        let [a2, a1, a0] = self.characteristic(h);
        let p1 = 1.0 + a2 + a1 + a0;
        let pm1 = -1.0 + a2 - a1 + a0;
        let abs = |x: f64| if x < 0.0 { -x } else { x };
        p1 > 0.0 && pm1 < 0.0 && abs(a0) < 1.0 && abs(a0 * a0 - 1.0) > abs(a0 * a2 - a1)
    }
}

/// `e^-x` for `x ≥ 0` (configuration time only): halve until ≤ 1/64, Taylor, square back.
fn exp_neg(x: f64) -> f64 {
    if x.is_nan() {
        return f64::NAN;
    }
    if x < 0.0 || !x.is_finite() {
        return 0.0;
    }
    let mut y = x;
    let mut halvings = 0;
    while y > 1.0 / 64.0 && halvings < 64 {
        y *= 0.5;
        halvings += 1;
    }
    let mut term = 1.0;
    let mut sum = 1.0;
    let mut k = 1.0;
    while k < 12.0 {
        term *= -y / k;
        sum += term;
        k += 1.0;
    }
    while halvings > 0 {
        sum *= sum;
        halvings -= 1;
    }
    sum
}

/// How fast the recent peak output speed that widens the innovation limit decays (rad/s per
/// s): an impact in the lost motion returns at most the speed the output had; after 1 s at
/// rest the widening is gone even from the 10 rad/s of a typical cut.
pub const IMPACT_DECAY_RAD_S2: f64 = 10.0;

/// Limits and time constants (SI). Defaults in [`Thresholds::DEFAULT`], with their reasons in
/// docs/monitor-design.md.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Thresholds {
    /// Operating envelope of the load (N·m); an implied load beyond it while driving means the
    /// current is above the model (`brake_drag`).
    pub max_load_nm: f64,
    /// Karnopp band and lock detection: |ω_out| below this is "stuck" (rad/s).
    pub stick_speed_rad_s: f64,
    /// Time |ω_out| must stay in the stick band before the pack counts as locked (s).
    pub lock_dwell_s: f64,
    /// Output travel allowed after the brake locked with the drive off (rad): `brake_slip`.
    pub creep_limit_rad: f64,
    /// Common slip: output travel (rad) of a run that the input shaft follows the same way …
    pub slip_output_travel_rad: f64,
    /// … by more than this travel of the input shaft (rad, input side): `brake_slip`. Each
    /// limit lies above what its shaft does alone while the pack holds (the rattle).
    pub slip_input_travel_rad: f64,
    /// Turn-back that ends a shaft's run in the common-slip check (rad, each shaft's side).
    pub slip_reversal_rad: f64,
    /// Braking envelope, time: how long the output may keep moving (drive off) after the
    /// nominal model, started from the speed at the cut, has stopped it (s): `brake_weak`.
    pub braking_grace_s: f64,
    /// Braking envelope, angle: the output angle during braking may exceed the nominal model's
    /// by this factor …
    pub braking_angle_factor: f64,
    /// … plus this allowance (rad), before `brake_weak`.
    pub braking_angle_allowance_rad: f64,
    /// Braking envelope, a brake that does not brake: the output's travel since the cut may
    /// exceed what it would cover at its cut speed, undecelerated, by this much (rad) before
    /// `brake_weak` (a working pack decelerates it from the first millisecond).
    pub undecelerated_allowance_rad: f64,
    /// Lowest capacity margin (capacity over |load|) before `brake_weak`.
    pub min_capacity_margin: f64,
    /// Loads below this (N·m) are too small for a margin or a load direction.
    pub min_load_nm: f64,
    /// Pack torque above the nominal spring drag allowed while driving (N·m): `brake_drag`.
    pub drag_allowance_nm: f64,
    /// Step of the current-implied load while driving (N·m), against its recent history (a
    /// low-pass at `step_reference_hz`): a pack that starts to drag (the drive pushes harder:
    /// `brake_drag`) or a current reading that loses gain (`sensor_fault`). Genuine load
    /// changes are slower than the history follows: a ramp lags the 5 Hz history by
    /// `rate/(2π·5 Hz)`, so 1.25 N·m lets door loads change at up to 39 N·m/s (the Monte Carlo's
    /// first false alarms come at 0.25 N·m).
    pub step_allowance_nm: f64,
    /// Corner frequency of the implied load's recent history (Hz).
    pub step_reference_hz: f64,
    /// The output moves with the input shaft while their speeds differ by at most this
    /// (rad/s): the quasi-static readings of a drive hold only then (learning the load, the
    /// drive checks).
    pub sync_speed_band_rad_s: f64,
    /// A brake condition must persist this long before its flag latches (s).
    pub flag_persistence_s: f64,
    /// Observer settling time after a re-initialisation (a late step beyond the catch-up) or
    /// a power-on that could not be seeded (s); untrusted meanwhile.
    pub settle_time_s: f64,
    /// Settling time after power-on when the observer could be seeded from the first
    /// [`POWER_ON_SEED_TICKS`] ticks (speed from the output encoder's travel, torque balanced
    /// so that the output does not accelerate): it starts near the motion instead of at rest
    /// (s; at most `settle_time_s`).
    pub power_on_settle_s: f64,
    /// Time after the ramps engage before the pack health is learned (ramp backlash) (s).
    pub engage_settle_s: f64,
    /// Bandwidth of the load-estimate filter (Hz).
    pub load_filter_hz: f64,
    /// Bandwidth of the input-speed filter (Hz).
    pub input_speed_filter_hz: f64,
    /// Fastest plausible output speed (rad/s): larger encoder steps are a sensor fault.
    pub max_output_speed_rad_s: f64,
    /// Fastest plausible motor speed (rad/s, motor side).
    pub max_motor_speed_rad_s: f64,
    /// Travel of one shaft while the other's counter stands still, driving, before the still
    /// counter counts as stuck (rad, output side).
    pub max_lost_motion_rad: f64,
    /// Largest plausible |current| with the drive off (A).
    pub current_off_max_a: f64,
    /// Time at an ADC rail before the current reading counts as failed (s).
    pub adc_rail_time_s: f64,
    /// Mean drive torque (N·m, magnitude, over a block of 12.8 ms) below which the current
    /// reading is dead while the drive is on, the output turns and the pack has lately held it
    /// (`sensor_fault`; `monitor/dead_current.rs`). Must lie below the pack's spring drag
    /// while driving (1.98 N·m with Table 2), around which a moving no-back's drive torque
    /// sits at its lowest: healthy drives average ≥ 1.42 N·m over the blocks the check judges
    /// in the Monte Carlo (`cargo run --release -p host-tests --example dead_current_margin`).
    pub dead_current_nm: f64,
    /// The output counts as turning for the dead-reading check above this mean speed over the
    /// block (rad/s).
    pub dead_current_speed_rad_s: f64,
    /// Rate at which the pack-health estimate may move (1/s, sign-LMS step).
    pub health_rate_per_s: f64,
    /// Time over which an impact in the lost motion may reverse the output speed before the
    /// observer follows (s): widens the innovation limit by `2·|ω̂|·this`.
    pub impact_time_s: f64,
    /// Half-width of the encoder's second difference that measures an impact while holding
    /// (s; 1 to 31 ticks): the braking torque reported while the brake holds is
    /// `M̂ − J_s·α` with `α` the output's acceleration over the last two such windows.
    pub impact_window_s: f64,
}

impl Thresholds {
    /// Defaults for Table 2 and the default sensors.
    pub const DEFAULT: Thresholds = Thresholds {
        max_load_nm: 60.0,
        stick_speed_rad_s: 0.3,
        lock_dwell_s: 0.001,
        creep_limit_rad: 0.15,
        slip_output_travel_rad: 0.05, // the output's rattle alone: ±0.13 rad
        slip_input_travel_rad: 0.045, // the kicks alone: ≤ 0.035 rad; first false alarm at 0.03
        slip_reversal_rad: 0.001,
        braking_grace_s: 0.4,
        braking_angle_factor: 2.0,
        braking_angle_allowance_rad: 0.1, // the twin's healthy pack stops within 0.07 rad
        undecelerated_allowance_rad: 0.01,
        min_capacity_margin: 1.5,
        min_load_nm: 1.0,
        drag_allowance_nm: 8.0,
        step_allowance_nm: 1.25,
        step_reference_hz: 5.0,
        sync_speed_band_rad_s: 1.0,
        flag_persistence_s: 0.01,
        settle_time_s: 0.1,
        power_on_settle_s: 0.03,
        engage_settle_s: 0.02,
        load_filter_hz: 10.0,
        input_speed_filter_hz: 200.0,
        max_output_speed_rad_s: 60.0,
        max_motor_speed_rad_s: 1800.0,
        max_lost_motion_rad: 0.2, // the twin's lost motion is 0.03–0.1 rad
        current_off_max_a: 3.0,
        adc_rail_time_s: 0.01, // overrunning chatter stalls the motor at the current limit ≈ 3 ms
        dead_current_nm: 0.5,  // healthy ≥ 1.37 N·m; a dead reading's noise ≤ 0.06 N·m
        dead_current_speed_rad_s: 2.0,
        health_rate_per_s: 25.0,
        impact_time_s: 0.01,
        impact_window_s: 0.0016,
    };
}

impl Default for Thresholds {
    fn default() -> Self {
        Thresholds::DEFAULT
    }
}

/// Everything the monitor is configured with; separate from its state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    /// The mechanism (Table 2 by default).
    pub mechanism: Mechanism,
    /// Motor, reducer and sensors.
    pub sensors: SensorConfig,
    /// Flag limits and time constants.
    pub thresholds: Thresholds,
    /// Output-shaft observer gains.
    pub observer: ObserverGains,
    /// Step rate (Hz); the step is `h = 1/tick_hz`.
    pub tick_hz: f64,
    /// Friction coefficient in the pack capacity `T_all`; default μ_s (the paper's levels, see
    /// MODEL.md).
    pub capacity_mu: f64,
    /// Friction coefficient of the slipping pack while the drive runs (default μ_d): it sets the
    /// drag while driving and the overrunning equilibrium (docs/monitor-design.md, "physical
    /// reading").
    pub sliding_mu: f64,
    /// Factor from motor torque × ratio to output torque when the load back-drives the motor
    /// (power flowing to the motor); default `1/η`. When motoring, `η` is used.
    pub backdrive_efficiency: f64,
    /// Most ticks one late step may cover (1..=32); the observer must be stable when advanced
    /// by any of 1..=this many ticks with one correction.
    pub max_catchup_ticks: u8,
    /// Rate (Hz) of the fault-braking model (the nominal braking the envelope checks against),
    /// stepped by explicit Euler in I16F16; `tick_hz` must be a whole multiple of it. Default
    /// [`DEFAULT_BRAKING_MODEL_HZ`], the cheapest rate meeting the accuracy targets
    /// (docs/results/cheapest-per-scene.md, `cargo xtask bench`).
    pub braking_model_hz: f64,
}

/// Default rate of the fault-braking model (Hz): the cheapest-per-scene table's choice for
/// both braking scenes (reduced I16F16 explicit Euler at 1 kHz).
pub const DEFAULT_BRAKING_MODEL_HZ: f64 = 1_000.0;

/// Default observer bandwidth (Hz).
pub const DEFAULT_OBSERVER_BANDWIDTH_HZ: f64 = 30.0;
/// Default tick rate (Hz).
pub const DEFAULT_TICK_HZ: f64 = 10_000.0;

impl Config {
    /// Defaults around a mechanism and sensors: 10 kHz, 20 Hz observer, μ_s in `T_all`.
    pub fn new(mechanism: Mechanism, sensors: SensorConfig) -> Config {
        Config {
            mechanism,
            sensors,
            thresholds: Thresholds::DEFAULT,
            observer: ObserverGains::triple_pole(DEFAULT_OBSERVER_BANDWIDTH_HZ, DEFAULT_TICK_HZ),
            tick_hz: DEFAULT_TICK_HZ,
            capacity_mu: mechanism.mu_static,
            sliding_mu: mechanism.mu_dynamic,
            backdrive_efficiency: 1.0 / sensors.reducer_efficiency,
            max_catchup_ticks: 8,
            braking_model_hz: DEFAULT_BRAKING_MODEL_HZ,
        }
    }
}

impl Default for Config {
    fn default() -> Self {
        Config::new(TABLE2, DEFAULT_SENSORS)
    }
}

/// Why a configuration was rejected; each names the offending parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConfigError {
    /// NaN or infinite.
    NotFinite {
        /// The parameter's path, e.g. `"mechanism.output_inertia_kg_m2"`.
        parameter: &'static str,
    },
    /// Outside its physical or supported range (zero inertia, efficiency > 1, …).
    OutOfRange {
        /// The parameter's path.
        parameter: &'static str,
    },
    /// A derived constant or an envelope value would not fit its fixed-point format.
    Overflow {
        /// The parameter's path.
        parameter: &'static str,
    },
    /// The observer's error dynamics are not stable for some step count 1..=max_catchup_ticks.
    Unstable {
        /// The parameter's path.
        parameter: &'static str,
    },
}

impl ConfigError {
    /// The parameter the error names.
    pub const fn parameter(&self) -> &'static str {
        match self {
            ConfigError::NotFinite { parameter }
            | ConfigError::OutOfRange { parameter }
            | ConfigError::Overflow { parameter }
            | ConfigError::Unstable { parameter } => parameter,
        }
    }
}

impl core::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let what = match self {
            ConfigError::NotFinite { .. } => "is not finite",
            ConfigError::OutOfRange { .. } => "is out of range",
            ConfigError::Overflow { .. } => "overflows the fixed-point format",
            ConfigError::Unstable { .. } => "makes the observer unstable",
        };
        write!(f, "monitor configuration: {} {}", self.parameter(), what)
    }
}

/// The fixed-point constants of the step, all derived in [`Params::from_config`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Params {
    // Sensors.
    pub adc_bits: u8,
    pub adc_max_code: u16,
    pub adc_rail_ticks: u32,
    pub current_off_counts: i32,
    pub out_bits: u8,
    pub out_mask: u32,
    pub out_shift: u32,
    pub out_jump_counts: i32,
    pub motor_bits: u8,
    pub motor_mask: u32,
    pub motor_jump_counts: i32,
    pub lost_motor_counts: u32,
    pub lost_out_counts: u32,
    // Drive: ADC counts → output-side N·m (Q16 bits).
    pub drive_motoring: Scale<16>,
    pub drive_backdriven: Scale<16>,
    pub input_speed: Scale<11>,
    pub input_alpha: Gain,
    // Observer (see observer.rs for the units).
    pub obs: super::observer::ObserverScales,
    pub max_catchup: u8,
    // Pack.
    pub spring_force: Q16,
    pub ramp_factor: Scale<21>,
    pub capacity_per_n: Scale<32>,
    /// Pressing force while driving against the load: `F_s/(1 + μ_d·c·k)` (input ramps unload).
    pub drive_force: Q16,
    /// Pack drag while driving against the load: `μ_d·c·F_drive`.
    pub drive_drag: Q16,
    /// Overrunning equilibrium (load along the motion, drive on): pack torque
    /// `y = g₁·v − g₀` for a drive torque `v` along the motion; `g₁ = 2μ_d·c·k/(μ_d·c·k − 1)`.
    pub overrun_gain: Scale<24>,
    /// `g₀ = μ_d·c·F_s/(μ_d·c·k − 1)` (N·m).
    pub overrun_offset: Q16,
    // Thresholds.
    pub max_load: Q16,
    pub min_load: Q16,
    pub stick_speed: Q16,
    pub min_margin: Scale<26>,
    pub lock_dwell_ticks: u32,
    /// Ticks per step of the fault-braking model (`tick_hz / braking_model_hz`, ≥ 1).
    pub braking_model_ticks: u32,
    /// The fault-braking model's rate (Hz, rounded), for [`super::Monitor::scene_model`].
    pub braking_model_hz: u32,
    /// One braking-model step: Q16 rad/s → Q16 output counts travelled (`speed_to_counts` ×
    /// `braking_model_ticks`).
    pub braking_travel: Scale<20>,
    /// One braking-model step: Q16 N·m → Q16 rad/s of speed change (`h/J` ×
    /// `braking_model_ticks`).
    pub braking_speed: Scale<30>,
    pub persistence_ticks: u32,
    pub settle_ticks: u32,
    /// Ticks of settling a seeded power-on skips (`settle_time_s − power_on_settle_s`).
    pub power_on_head_start: u32,
    /// Output counts over the seeding window → Q16 rad/s.
    pub seed_speed: Scale<16>,
    pub engage_settle_ticks: u32,
    pub braking_grace_ticks: u32,
    pub creep_counts: i32,
    pub slip: SlipLimits,
    pub braking_angle_factor: Scale<25>,
    pub braking_angle_allowance: i32,
    /// Q16 output counts.
    pub undecelerated_allowance: i32,
    pub speed_to_counts: Scale<28>,
    pub innovation_limit: i32,
    /// Q16 rad/s → angle words: the prediction error an impact reversing that speed can cause.
    pub impact_words: Scale<16>,
    /// Decay of the recent peak speed per tick (Q16 rad/s bits): [`IMPACT_DECAY_RAD_S2`]·h.
    pub impact_decay: i32,
    /// Ticks `m` of the impact's second difference (1..=31).
    pub impact_window: u8,
    /// Second difference of the output position (counts) → Q16 N·m: `J_s·Δθ/(m·h)²`.
    pub impact_torque: Scale<8>,
    /// Gain of the load filter, run on every fourth tick.
    pub load_alpha: Gain,
    /// `T_drive + drag_allowance`: the pack torque above which a driving pack drags.
    pub drag_limit: Q16,
    /// Largest step of the implied load against its recent history (N·m) while the drive
    /// carries the load (`M = N + s·T_drive`: one N·m of drive torque is one N·m of load).
    pub step_limit: Q16,
    /// The same step of drive torque while overrunning, where the implied load `y(v) − v`
    /// moves by `g₁ − 1` ≈ 5.9 N·m per N·m of drive torque.
    pub step_limit_overrun: Q16,
    /// The drive torque's own step that must come with a step of the implied load (N·m): half
    /// the allowance (`DriveChecks::run`).
    pub step_drive_min: Q16,
    /// The drive torque's history follows by a shift of this many bits per run: the power of
    /// two nearest to `step_alpha` (1/64 with the defaults, a 6.2 Hz corner at 2.5 kHz).
    pub drive_ref_shift: u32,
    /// Gain of the implied load's recent history, run on one tick in four.
    pub step_alpha: Gain,
    /// Output counts of relative travel over [`SYNC_WINDOW_TICKS`] within the band.
    pub sync_band_counts: i32,
    /// `dead_current_nm` × the dead-reading check's block of windows: the sum of the drive
    /// torque samples below which a block reads dead (N·m).
    pub dead_drive_sum: Q16,
    /// `dead_current_speed_rad_s` as the output's travel summed over the block's windows
    /// (counts): the output turns above it.
    pub dead_travel_sum: i32,
    /// Motor counts → output counts (input shaft and output turn alike when synchronous).
    pub motor_to_out: Scale<30>,
    pub load_known_ticks: u32,
    /// Health change per update (Q16 bits; the update runs on one tick in four).
    pub health_step: i32,
    pub energy_per_tick: Scale<32>,
}

/// Largest value (in its unit) any Q16 quantity of the envelope may reach: half the format's
/// range, so that sums of two envelope values cannot saturate.
const Q16_ENVELOPE: f64 = 16_384.0;

fn finite(x: f64, parameter: &'static str) -> Result<f64, ConfigError> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(ConfigError::NotFinite { parameter })
    }
}

fn positive(x: f64, parameter: &'static str) -> Result<f64, ConfigError> {
    if finite(x, parameter)? > 0.0 {
        Ok(x)
    } else {
        Err(ConfigError::OutOfRange { parameter })
    }
}

/// A constant in its [`Scale`] format; the error names the parameter it derives from.
fn scale<const S: u32>(k: f64, parameter: &'static str) -> Result<Scale<S>, ConfigError> {
    Scale::from_f64(k).map_err(|e| match e {
        ScaleError::NotFinite => ConfigError::NotFinite { parameter },
        ScaleError::TooLarge => ConfigError::Overflow { parameter },
        ScaleError::TooFine => ConfigError::OutOfRange { parameter },
    })
}

fn q16(x: f64, parameter: &'static str) -> Result<Q16, ConfigError> {
    let x = finite(x, parameter)?;
    if !(-Q16_ENVELOPE..=Q16_ENVELOPE).contains(&x) {
        return Err(ConfigError::Overflow { parameter });
    }
    // In range (checked above); `checked_` so that no panic path (NaN) is compiled in.
    Q16::checked_from_num(x).ok_or(ConfigError::Overflow { parameter })
}

fn gain(alpha: f64, parameter: &'static str) -> Result<Gain, ConfigError> {
    if alpha > 0.0 && alpha < 1.0 {
        Gain::checked_from_num(alpha).ok_or(ConfigError::OutOfRange { parameter })
    } else {
        Err(ConfigError::OutOfRange { parameter })
    }
}

/// Seconds to ticks, at least 1, at most 2^31.
fn ticks(seconds: f64, tick_hz: f64, parameter: &'static str) -> Result<u32, ConfigError> {
    let t = positive(seconds, parameter)? * tick_hz;
    if t > 2_147_483_648.0 {
        return Err(ConfigError::Overflow { parameter });
    }
    Ok(((t + 0.5) as u32).max(1))
}

/// A count limit (≥ 1) that must fit an i32 with room to spare.
fn counts(x: f64, parameter: &'static str) -> Result<i32, ConfigError> {
    let x = positive(x, parameter)?;
    if x > 1.0e9 {
        return Err(ConfigError::Overflow { parameter });
    }
    Ok(((x + 0.5) as i32).max(1))
}

/// Ticks after power-on over which the observer's starting speed is measured.
pub const POWER_ON_SEED_TICKS: u32 = 16;

/// Ticks over which the output's and the input shaft's travel are compared for synchronism
/// (`Monitor::step`, "steady driving").
pub(crate) const SYNC_WINDOW_TICKS: u32 = 16;

/// The shift `k` whose gain `2^-k` is nearest to `gain` on a log scale (`gain` in (0, 1]; 0 for
/// larger, 30 at most).
fn nearest_shift(gain: f64) -> u32 {
    let mut k = 0;
    let mut x = gain;
    while x < core::f64::consts::FRAC_1_SQRT_2 && k < 30 {
        x *= 2.0;
        k += 1;
    }
    k
}

/// A travel limit the common-slip check can measure on a wrapping counter: below a quarter of
/// its range, so that the travel since the brake held (up to twice the limit before the check
/// flags) stays within the half range its wrapping difference resolves.
fn within_quarter_counter(
    limit: i32,
    bits: u8,
    parameter: &'static str,
) -> Result<i32, ConfigError> {
    let quarter = 1_i64 << (u32::from(bits.clamp(2, 32)) - 2);
    if i64::from(limit) < quarter {
        Ok(limit)
    } else {
        Err(ConfigError::OutOfRange { parameter })
    }
}

/// Ticks per step of the fault-braking model: `tick_hz / braking_model_hz`, a whole number from
/// 1 to 1000 (the model may not run faster than the ticks, and at 1/1000 of them it would not see
/// a braking event of tens of milliseconds at all).
fn model_ticks(model_hz: f64, tick_hz: f64) -> Result<u32, ConfigError> {
    const PARAMETER: &str = "braking_model_hz";
    let ratio = tick_hz / positive(model_hz, PARAMETER)?;
    let whole = (ratio + 0.5) as u32; // 0 < ratio ≤ 1e10: `as` saturates, never wraps
    if !(1..=1000).contains(&whole) || (ratio - f64::from(whole)).abs() > 1e-9 * ratio {
        return Err(ConfigError::OutOfRange {
            parameter: PARAMETER,
        });
    }
    Ok(whole)
}

impl Params {
    pub(crate) fn from_config(c: &Config) -> Result<Params, ConfigError> {
        let m = &c.mechanism;
        let s = &c.sensors;
        let t = &c.thresholds;
        let tick_hz = positive(c.tick_hz, "tick_hz")?;
        if !(100.0..=1.0e6).contains(&tick_hz) {
            return Err(ConfigError::OutOfRange {
                parameter: "tick_hz",
            });
        }
        let h = 1.0 / tick_hz;

        // --- Mechanism.
        let j = positive(m.output_inertia_kg_m2, "mechanism.output_inertia_kg_m2")?;
        positive(m.socket_radius_m, "mechanism.socket_radius_m")?;
        let chamfer = positive(m.socket_chamfer_rad, "mechanism.socket_chamfer_rad")?;
        if chamfer >= core::f64::consts::FRAC_PI_2 {
            return Err(ConfigError::OutOfRange {
                parameter: "mechanism.socket_chamfer_rad",
            });
        }
        let r1 = positive(m.pack_inner_radius_m, "mechanism.pack_inner_radius_m")?;
        let r2 = positive(m.pack_outer_radius_m, "mechanism.pack_outer_radius_m")?;
        if r2 <= r1 {
            return Err(ConfigError::OutOfRange {
                parameter: "mechanism.pack_outer_radius_m",
            });
        }
        if m.friction_discs == 0 {
            return Err(ConfigError::OutOfRange {
                parameter: "mechanism.friction_discs",
            });
        }
        let groove = finite(m.groove_angle_rad, "mechanism.groove_angle_rad")?;
        if !(0.0..core::f64::consts::TAU).contains(&groove) {
            return Err(ConfigError::OutOfRange {
                parameter: "mechanism.groove_angle_rad",
            });
        }
        finite(m.spring_stiffness_n_m, "mechanism.spring_stiffness_n_m")?;
        finite(m.spring_preload_m, "mechanism.spring_preload_m")?;
        finite(m.pack_clearance_m, "mechanism.pack_clearance_m")?;
        if m.spring_stiffness_n_m < 0.0 {
            return Err(ConfigError::OutOfRange {
                parameter: "mechanism.spring_stiffness_n_m",
            });
        }
        let mu = finite(c.capacity_mu, "capacity_mu")?;
        if !(0.0..=2.0).contains(&mu) || mu == 0.0 {
            return Err(ConfigError::OutOfRange {
                parameter: "capacity_mu",
            });
        }
        let ramp = m.ramp_factor_per_m(); // N per N·m
        let per_n = m.pack_torque_per_newton_m(mu); // N·m per N
        let spring = m.spring_preload_n();
        let max_load = positive(t.max_load_nm, "thresholds.max_load_nm")?;
        let max_force = spring + ramp * max_load;
        if !(0.0..=Q16_ENVELOPE).contains(&max_force) {
            return Err(ConfigError::Overflow {
                parameter: "mechanism.socket_radius_m",
            });
        }
        if !(0.0..=Q16_ENVELOPE).contains(&(per_n * max_force)) {
            return Err(ConfigError::Overflow {
                parameter: "capacity_mu",
            });
        }
        let mu_d = finite(c.sliding_mu, "sliding_mu")?;
        if !(0.0..=2.0).contains(&mu_d) || mu_d == 0.0 {
            return Err(ConfigError::OutOfRange {
                parameter: "sliding_mu",
            });
        }
        // Sliding self-locking ratio a·k = μ_d·c·tanθ/r (1.42 at Table 2): the overrunning
        // equilibrium divides by a·k − 1, so a·k ≈ 1 is rejected.
        let a_k = m.pack_torque_per_newton_m(mu_d) * ramp;
        if a_k > 0.95 && a_k < 1.05 {
            return Err(ConfigError::OutOfRange {
                parameter: "sliding_mu",
            });
        }
        let drive_force = spring / (1.0 + a_k);
        let drive_drag = m.pack_torque_per_newton_m(mu_d) * drive_force;

        // --- Sensors.
        let kt = positive(
            s.motor_torque_constant_nm_a,
            "sensors.motor_torque_constant_nm_a",
        )?;
        let ratio = positive(s.reducer_ratio, "sensors.reducer_ratio")?;
        let eff = positive(s.reducer_efficiency, "sensors.reducer_efficiency")?;
        if eff > 1.0 {
            return Err(ConfigError::OutOfRange {
                parameter: "sensors.reducer_efficiency",
            });
        }
        let back = positive(c.backdrive_efficiency, "backdrive_efficiency")?;
        if !(4..=16).contains(&s.current_adc_bits) {
            return Err(ConfigError::OutOfRange {
                parameter: "sensors.current_adc_bits",
            });
        }
        let full_scale = positive(s.current_full_scale_a, "sensors.current_full_scale_a")?;
        if !(8..=24).contains(&s.output_encoder_bits) {
            return Err(ConfigError::OutOfRange {
                parameter: "sensors.output_encoder_bits",
            });
        }
        if !(8..=32).contains(&s.motor_counter_bits) {
            return Err(ConfigError::OutOfRange {
                parameter: "sensors.motor_counter_bits",
            });
        }
        if s.motor_encoder_counts_per_rev == 0 {
            return Err(ConfigError::OutOfRange {
                parameter: "sensors.motor_encoder_counts_per_rev",
            });
        }
        let amps = s.amps_per_count();
        let max_drive = full_scale * kt * ratio * eff.max(back);
        if max_drive > Q16_ENVELOPE {
            return Err(ConfigError::Overflow {
                parameter: "sensors.current_full_scale_a",
            });
        }
        let out_rad = s.output_rad_per_count();
        let in_rad = s.input_rad_per_motor_count(); // input-shaft rad per motor count
        if !(1..=32).contains(&c.max_catchup_ticks) {
            return Err(ConfigError::OutOfRange {
                parameter: "max_catchup_ticks",
            });
        }
        let catchup = f64::from(c.max_catchup_ticks);
        let max_out_speed = positive(
            t.max_output_speed_rad_s,
            "thresholds.max_output_speed_rad_s",
        )?;
        let max_motor_speed =
            positive(t.max_motor_speed_rad_s, "thresholds.max_motor_speed_rad_s")?;
        if max_out_speed > Q16_ENVELOPE || max_motor_speed / ratio > Q16_ENVELOPE {
            return Err(ConfigError::Overflow {
                parameter: "thresholds.max_output_speed_rad_s",
            });
        }
        // Per-tick step limits; a late step may cover `catchup` ticks and must still be shorter
        // than half a counter period, or `counter_delta` would alias.
        let out_jump = max_out_speed * h / out_rad + 1.0;
        let motor_jump = max_motor_speed * h / (in_rad * ratio) + 1.0;
        let out_half = f64::from(1_u32 << (s.output_encoder_bits - 1));
        let motor_half = f64::from(1_u32 << (s.motor_counter_bits - 1).min(30));
        if out_jump * catchup >= out_half {
            return Err(ConfigError::Overflow {
                parameter: "sensors.output_encoder_bits",
            });
        }
        if motor_jump * catchup >= motor_half {
            return Err(ConfigError::Overflow {
                parameter: "sensors.motor_counter_bits",
            });
        }

        // --- Observer: stability for every step count it may be advanced by.
        let g = c.observer;
        finite(g.angle, "observer.angle")?;
        finite(g.speed_per_s, "observer.speed_per_s")?;
        finite(g.accel_per_s2, "observer.accel_per_s2")?;
        let mut k = 1;
        while k <= c.max_catchup_ticks {
            if !g.is_stable(h * f64::from(k)) {
                return Err(ConfigError::Unstable {
                    parameter: if k == 1 {
                        "observer"
                    } else {
                        "max_catchup_ticks"
                    },
                });
            }
            k += 1;
        }
        const Q16_ONE: f64 = 65_536.0;
        let words_per_rad = 4_294_967_296.0 / core::f64::consts::TAU;
        let obs = super::observer::ObserverScales {
            // θ [word] += ω [Q16 bits] · h · words/rad / 2^16
            theta_v: scale(h * words_per_rad / Q16_ONE, "tick_hz")?,
            // θ += a·h²/2 with a = τ/J: τ [Q16 bits] → words
            theta_a: scale(
                h * h / (2.0 * j) * words_per_rad / Q16_ONE,
                "mechanism.output_inertia_kg_m2",
            )?,
            // ω [Q16] += τ [Q16] · h/J
            v_a: scale(h / j, "mechanism.output_inertia_kg_m2")?,
            l_theta: scale(g.angle, "observer.angle")?,
            l_v: scale(
                g.speed_per_s / words_per_rad * Q16_ONE,
                "observer.speed_per_s",
            )?,
            l_d: scale(
                j * g.accel_per_s2 / words_per_rad * Q16_ONE,
                "observer.accel_per_s2",
            )?,
        };

        // --- Thresholds.
        let stick = positive(t.stick_speed_rad_s, "thresholds.stick_speed_rad_s")?;
        let min_margin = positive(t.min_capacity_margin, "thresholds.min_capacity_margin")?;
        let alpha = |hz: f64, parameter| -> Result<Gain, ConfigError> {
            let hz = positive(hz, parameter)?;
            gain(1.0 - exp_neg(core::f64::consts::TAU * hz * h), parameter)
        };
        let current_off = positive(t.current_off_max_a, "thresholds.current_off_max_a")? / amps;
        let lost = positive(t.max_lost_motion_rad, "thresholds.max_lost_motion_rad")?;
        let energy = h * 256.0; // Q16 W → U40F24 J per tick: P·2^-16·h·2^24
                                // The health update runs on one tick in four: its step covers four.
        let health_step = positive(t.health_rate_per_s, "thresholds.health_rate_per_s")? * 4.0 * h;
        if health_step >= 0.5 {
            return Err(ConfigError::OutOfRange {
                parameter: "thresholds.health_rate_per_s",
            });
        }
        let braking_ticks = model_ticks(c.braking_model_hz, tick_hz)?;
        let impact_m = {
            let m = positive(t.impact_window_s, "thresholds.impact_window_s")? * tick_hz + 0.5;
            if !(1.0..32.0).contains(&m) {
                return Err(ConfigError::OutOfRange {
                    parameter: "thresholds.impact_window_s",
                });
            }
            m as u8 // 1 ≤ m < 32 (checked above)
        };
        // Gain of the implied load's history, run on one tick in four.
        let step_alpha = 1.0
            - exp_neg(
                core::f64::consts::TAU
                    * positive(t.step_reference_hz, "thresholds.step_reference_hz")?
                    * 4.0
                    * h,
            );
        let settle_ticks = ticks(t.settle_time_s, tick_hz, "thresholds.settle_time_s")?;
        // The dead-reading check judges the sum over a block of synchronism windows; its
        // threshold must lie below the spring drag a moving no-back's drive always carries.
        let block = f64::from(super::dead_current::BLOCK_WINDOWS);
        let dead_current = positive(t.dead_current_nm, "thresholds.dead_current_nm")?;
        if dead_current >= drive_drag {
            return Err(ConfigError::OutOfRange {
                parameter: "thresholds.dead_current_nm",
            });
        }
        Ok(Params {
            adc_bits: s.current_adc_bits,
            adc_max_code: ((1_u32 << s.current_adc_bits) - 1) as u16,
            adc_rail_ticks: ticks(t.adc_rail_time_s, tick_hz, "thresholds.adc_rail_time_s")?,
            current_off_counts: counts(current_off, "thresholds.current_off_max_a")?,
            out_bits: s.output_encoder_bits,
            out_mask: (1_u32 << s.output_encoder_bits) - 1,
            out_shift: 32 - u32::from(s.output_encoder_bits),
            out_jump_counts: counts(out_jump, "thresholds.max_output_speed_rad_s")?,
            motor_bits: s.motor_counter_bits,
            motor_mask: u32::MAX >> (32 - u32::from(s.motor_counter_bits)),
            motor_jump_counts: counts(motor_jump, "thresholds.max_motor_speed_rad_s")?,
            lost_motor_counts: counts(lost / in_rad, "thresholds.max_lost_motion_rad")? as u32,
            lost_out_counts: counts(lost / out_rad, "thresholds.max_lost_motion_rad")? as u32,
            drive_motoring: scale(
                amps * kt * ratio * eff * Q16_ONE,
                "sensors.reducer_efficiency",
            )?,
            drive_backdriven: scale(amps * kt * ratio * back * Q16_ONE, "backdrive_efficiency")?,
            input_speed: scale(in_rad / h * Q16_ONE, "sensors.motor_encoder_counts_per_rev")?,
            input_alpha: alpha(t.input_speed_filter_hz, "thresholds.input_speed_filter_hz")?,
            obs,
            max_catchup: c.max_catchup_ticks,
            spring_force: q16(spring, "mechanism.spring_preload_m")?,
            ramp_factor: scale(ramp, "mechanism.socket_radius_m")?,
            capacity_per_n: scale(per_n, "capacity_mu")?,
            drive_force: q16(drive_force, "sliding_mu")?,
            drive_drag: q16(drive_drag, "sliding_mu")?,
            overrun_gain: scale(2.0 * a_k / (a_k - 1.0), "sliding_mu")?,
            overrun_offset: q16(
                m.pack_torque_per_newton_m(mu_d) * spring / (a_k - 1.0),
                "sliding_mu",
            )?,
            max_load: q16(max_load, "thresholds.max_load_nm")?,
            min_load: q16(
                positive(t.min_load_nm, "thresholds.min_load_nm")?,
                "thresholds.min_load_nm",
            )?,
            stick_speed: q16(stick, "thresholds.stick_speed_rad_s")?,
            min_margin: scale(min_margin, "thresholds.min_capacity_margin")?,
            lock_dwell_ticks: ticks(t.lock_dwell_s, tick_hz, "thresholds.lock_dwell_s")?,
            braking_model_ticks: braking_ticks,
            braking_travel: scale(h / out_rad * f64::from(braking_ticks), "braking_model_hz")?,
            braking_speed: scale(h / j * f64::from(braking_ticks), "braking_model_hz")?,
            // 100 Hz ≤ tick_hz ≤ 1 MHz and ticks ≥ 1: the rate fits a u32 (`as` is exact).
            braking_model_hz: (tick_hz / f64::from(braking_ticks) + 0.5) as u32,
            persistence_ticks: ticks(
                t.flag_persistence_s,
                tick_hz,
                "thresholds.flag_persistence_s",
            )?,
            settle_ticks,
            // A seeded start settles sooner, never later.
            power_on_head_start: settle_ticks
                .checked_sub(ticks(
                    t.power_on_settle_s,
                    tick_hz,
                    "thresholds.power_on_settle_s",
                )?)
                .ok_or(ConfigError::OutOfRange {
                    parameter: "thresholds.power_on_settle_s",
                })?,
            seed_speed: scale(
                out_rad / h * Q16_ONE / f64::from(POWER_ON_SEED_TICKS),
                "sensors.output_encoder_bits",
            )?,
            engage_settle_ticks: ticks(t.engage_settle_s, tick_hz, "thresholds.engage_settle_s")?,
            braking_grace_ticks: ticks(t.braking_grace_s, tick_hz, "thresholds.braking_grace_s")?,
            creep_counts: counts(
                positive(t.creep_limit_rad, "thresholds.creep_limit_rad")? / out_rad,
                "thresholds.creep_limit_rad",
            )?,
            slip: SlipLimits {
                out_counts: within_quarter_counter(
                    counts(
                        t.slip_output_travel_rad / out_rad,
                        "thresholds.slip_output_travel_rad",
                    )?,
                    s.output_encoder_bits,
                    "thresholds.slip_output_travel_rad",
                )?,
                motor_counts: within_quarter_counter(
                    counts(
                        t.slip_input_travel_rad / in_rad,
                        "thresholds.slip_input_travel_rad",
                    )?,
                    s.motor_counter_bits,
                    "thresholds.slip_input_travel_rad",
                )?,
                out_hysteresis: counts(
                    t.slip_reversal_rad / out_rad,
                    "thresholds.slip_reversal_rad",
                )?,
                motor_hysteresis: counts(
                    t.slip_reversal_rad / in_rad,
                    "thresholds.slip_reversal_rad",
                )?,
                out_bits: s.output_encoder_bits,
                motor_bits: s.motor_counter_bits,
            },
            braking_angle_factor: scale(
                positive(t.braking_angle_factor, "thresholds.braking_angle_factor")?,
                "thresholds.braking_angle_factor",
            )?,
            // Q16 output counts.
            braking_angle_allowance: counts(
                positive(
                    t.braking_angle_allowance_rad,
                    "thresholds.braking_angle_allowance_rad",
                )? / out_rad
                    * Q16_ONE,
                "thresholds.braking_angle_allowance_rad",
            )?,
            undecelerated_allowance: counts(
                positive(
                    t.undecelerated_allowance_rad,
                    "thresholds.undecelerated_allowance_rad",
                )? / out_rad
                    * Q16_ONE,
                "thresholds.undecelerated_allowance_rad",
            )?,
            // Q16 rad/s → Q16 output counts per tick.
            speed_to_counts: scale(h / out_rad, "sensors.output_encoder_bits")?,
            innovation_limit: counts(out_jump, "thresholds.max_output_speed_rad_s")?
                .saturating_mul(1_i32 << (32 - u32::from(s.output_encoder_bits)).min(30)),
            impact_words: scale(
                2.0 * positive(t.impact_time_s, "thresholds.impact_time_s")? * words_per_rad
                    / Q16_ONE,
                "thresholds.impact_time_s",
            )?,
            impact_window: impact_m,
            impact_torque: scale(
                j * out_rad / ((f64::from(impact_m) * h) * (f64::from(impact_m) * h)) * Q16_ONE,
                "thresholds.impact_window_s",
            )?,
            // 1e-3 rad/s per tick at 10 kHz, ≥ 1 LSB at any tick rate; `as` is exact here
            // (0 < value < 2^31 for any accepted tick rate).
            impact_decay: ((IMPACT_DECAY_RAD_S2 * h * Q16_ONE + 0.5) as i32).max(1),
            // The load filter runs on every fourth tick (Monitor::step, "cost"): its gain is
            // that of a filter sampled at tick_hz/4.
            load_alpha: gain(
                1.0 - exp_neg(
                    core::f64::consts::TAU
                        * positive(t.load_filter_hz, "thresholds.load_filter_hz")?
                        * 4.0
                        * h,
                ),
                "thresholds.load_filter_hz",
            )?,
            step_limit: q16(
                positive(t.step_allowance_nm, "thresholds.step_allowance_nm")?,
                "thresholds.step_allowance_nm",
            )?,
            sync_band_counts: counts(
                t.sync_speed_band_rad_s * f64::from(SYNC_WINDOW_TICKS) * h / out_rad,
                "thresholds.sync_speed_band_rad_s",
            )?,
            motor_to_out: scale(in_rad / out_rad, "sensors.motor_encoder_counts_per_rev")?,
            dead_drive_sum: q16(dead_current * block, "thresholds.dead_current_nm")?,
            dead_travel_sum: counts(
                positive(
                    t.dead_current_speed_rad_s,
                    "thresholds.dead_current_speed_rad_s",
                )? * f64::from(SYNC_WINDOW_TICKS)
                    * h
                    / out_rad
                    * block,
                "thresholds.dead_current_speed_rad_s",
            )?,
            step_drive_min: q16(t.step_allowance_nm / 2.0, "thresholds.step_allowance_nm")?,
            drive_ref_shift: nearest_shift(step_alpha),
            step_alpha: gain(step_alpha, "thresholds.step_reference_hz")?,
            step_limit_overrun: q16(
                t.step_allowance_nm * (2.0 * a_k / (a_k - 1.0) - 1.0),
                "thresholds.step_allowance_nm",
            )?,
            drag_limit: q16(
                drive_drag + positive(t.drag_allowance_nm, "thresholds.drag_allowance_nm")?,
                "thresholds.drag_allowance_nm",
            )?,
            // Three time constants of the load filter (95 %).
            load_known_ticks: ticks(
                3.0 / (core::f64::consts::TAU
                    * positive(t.load_filter_hz, "thresholds.load_filter_hz")?),
                tick_hz,
                "thresholds.load_filter_hz",
            )?,
            health_step: ((health_step * Q16_ONE + 0.5) as i32).max(1),
            energy_per_tick: scale(energy, "tick_hz")?,
        })
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    #[test]
    fn triple_pole_gains_are_stable_and_match_the_poles() {
        let g = ObserverGains::triple_pole(20.0, 10_000.0);
        assert!(g.is_stable(1e-4));
        // The characteristic polynomial is (z − p)³.
        let p = (-core::f64::consts::TAU * 20.0 * 1e-4).exp();
        let [a2, a1, a0] = g.characteristic(1e-4);
        assert!((a2 + 3.0 * p).abs() < 1e-12);
        assert!((a1 - 3.0 * p * p).abs() < 1e-12);
        assert!((a0 + p * p * p).abs() < 1e-12);
    }

    #[test]
    fn jury_rejects_unstable_gains() {
        let g = ObserverGains {
            angle: 1.5,
            speed_per_s: 0.0,
            accel_per_s2: 0.0,
        };
        assert!(!g.is_stable(1e-4));
        let fast = ObserverGains::triple_pole(3_000.0, 10_000.0);
        // Stable at the design step, unstable when advanced by many ticks at once.
        assert!(fast.is_stable(1e-4));
        assert!(!fast.is_stable(8e-4));
    }

    #[test]
    fn exp_neg_is_exact_enough() {
        for x in [0.0, 1e-6, 0.0125, 0.5, 1.0, 3.0, 20.0] {
            assert!(
                (exp_neg(x) - (-x).exp()).abs() < 1e-13 * 1.0_f64.max((-x).exp()),
                "{x}"
            );
        }
    }

    #[test]
    fn defaults_convert() {
        assert!(Params::from_config(&Config::default()).is_ok());
    }
}
