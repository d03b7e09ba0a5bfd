//! Configuration, in SI units and `f64`: what a user or the commissioning sets. Each stage's
//! builder checks it and converts it into fixed point once (`settings.rs`).

use super::convert::exp_neg;
use super::functional_test::TestConfig;
use crate::mechanism::{Mechanism, TABLE2};
use crate::sensors::{SensorConfig, DEFAULT_SENSORS};

/// Observer gains of the current-estimator form (see [`crate::monitor`]): the angle, speed and
/// acceleration corrections per unit of angle innovation.
#[cfg_attr(feature = "config-block", derive(serde::Serialize, serde::Deserialize))]
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

/// How fast the recent peak output speed that widens the innovation limit decays (rad/s per
/// s): an impact in the lost motion returns at most the speed the output had; after 1 s at
/// rest the widening is gone even from the 10 rad/s of a typical cut.
pub const IMPACT_DECAY_RAD_S2: f64 = 10.0;

/// Limits and time constants (SI). Defaults in [`Thresholds::DEFAULT`], with their reasons in
/// docs/monitor-design.md. With `config-block`, serde reads and writes them by field name (the
/// host's configuration file).
#[cfg_attr(feature = "config-block", derive(serde::Serialize, serde::Deserialize))]
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
    /// Braking envelope, time: how long past `braking_angle_factor` × the nominal model's stop
    /// time (started from the speed at the cut) the output may keep braking (s): `brake_weak`.
    pub braking_grace_s: f64,
    /// Braking envelope: the output's angle and time during braking may exceed the nominal
    /// model's by this factor …
    pub braking_angle_factor: f64,
    /// … plus this allowance (rad), before `brake_weak`.
    pub braking_angle_allowance_rad: f64,
    /// Braking envelope, a brake that does not brake: the output's travel since the cut may
    /// exceed what it would cover at its observed cut speed, undecelerated, by this much (rad)
    /// before `brake_weak`: a working pack's lost motion and the observer's lag behind a chatter.
    pub undecelerated_allowance_rad: f64,
    /// Braking against an opposing load: the share of the pack's capacity the nominal braking
    /// model counts on (0 … 1). Uncommissioned 0 (the paper reading's ramps clamp only once the
    /// output turns back, so the load alone slows it); 1 where both socket faces clamp at once.
    pub opposed_braking_share: f64,
    /// Lowest capacity margin (capacity over |load|) before `brake_weak`.
    pub min_capacity_margin: f64,
    /// Relative uncertainty of the pack's modelled capacity (0 … 1): the reported margin's
    /// lower bound is `1 − capacity_uncertainty` of the model's (Table 2 ± 10 %).
    pub capacity_uncertainty: f64,
    /// Loads below this (N·m) are too small for a margin or a load direction.
    pub min_load_nm: f64,
    /// Pack torque above the nominal spring drag allowed while driving (N·m): `brake_drag`.
    pub drag_allowance_nm: f64,
    /// Step of the current-implied load while driving (N·m), against its recent history (a
    /// low-pass at `step_reference_hz`): a pack that starts to drag (the drive pushes harder:
    /// `brake_drag`) or a current reading that loses gain (`sensor_fault`). Genuine load
    /// changes are slower than the history follows: a ramp lags the 5 Hz history by
    /// `rate/(2π·5 Hz)`, so 1.25 N·m lets door loads change at up to 39 N·m/s.
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
    /// The same span while the drive carries no torque (mean |drive torque| over the still
    /// span below `driven_torque_nm`): an input turning free of its output, as the paper
    /// reading's ideal speed input does along a load its pack holds (rad, output side).
    pub free_input_travel_rad: f64,
    /// Mean |drive torque| (N·m) over the still span at or above which the drive carries a
    /// load; 0: the input never counts as turning free.
    pub driven_torque_nm: f64,
    /// Largest plausible |current| with the drive off (A).
    pub current_off_max_a: f64,
    /// Time at an ADC rail before the current reading counts as failed (s).
    pub adc_rail_time_s: f64,
    /// Mean drive torque (N·m, magnitude, over a block of 12.8 ms) below which the current
    /// reading is dead while the drive is on, the output turns and the pack has lately held it
    /// (`sensor_fault`; `monitor/dead_current.rs`); 0 turns the check off (uncommissioned: the
    /// paper reading's closing needs almost no drive torque). Must lie below the pack's spring drag
    /// while driving (1.98 N·m with Table 2), around which a moving no-back's drive torque
    /// sits at its lowest (the healthy margin: `cargo run --release -p host-tests --example
    /// dead_current_margin`).
    pub dead_current_nm: f64,
    /// The output counts as turning for the dead-reading check above this mean speed over the
    /// block (rad/s).
    pub dead_current_speed_rad_s: f64,
    /// How far the current reading may lie from the drive's own command, as a share of the
    /// command, summed over a block of 1.6 ms (`sensor_fault`; `checks/current_command.rs`);
    /// runs only on inputs that carry the command; 0 turns it off.
    pub command_gain_tolerance: f64,
    /// Smallest commanded current (A, magnitude) the command check sums.
    pub command_floor_a: f64,
    /// Mean drive torque against the output's motion (N·m) over `held_back_time_s` with the
    /// drive on that says the pack let an overrunning load through (`brake_degraded`).
    pub held_back_torque_nm: f64,
    /// The block over which that mean is taken (s).
    pub held_back_time_s: f64,
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
    /// Uncommissioned defaults for Table 2 and the default sensors: no false alarm on any
    /// plant of the family (docs/model.md, "The plant family"); commissioning tightens them.
    pub const DEFAULT: Thresholds = Thresholds {
        max_load_nm: 60.0,
        stick_speed_rad_s: 0.3,
        lock_dwell_s: 0.001,
        creep_limit_rad: 0.15,
        slip_output_travel_rad: 0.05, // the output's rattle alone: ±0.13 rad
        slip_input_travel_rad: 0.045, // the kicks alone: ≤ 0.035 rad
        slip_reversal_rad: 0.001,
        braking_grace_s: 0.4,
        braking_angle_factor: 4.0, // the paper reading at μ_d: ≤ 2.7× the model's angle
        braking_angle_allowance_rad: 0.3, // the paper reading's pack: ≤ 0.2 rad past the model
        undecelerated_allowance_rad: 0.03, // 1.5× a chatter's gain at the cut (≤ 0.02 rad)
        opposed_braking_share: 0.0, // the paper reading: only the load slows the output
        min_capacity_margin: 1.5,
        capacity_uncertainty: 0.22, // Table 2 ± 10 %: 2.5 % of plants hold less than 0.79×
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
        max_lost_motion_rad: 0.2,   // the twin's lost motion is 0.03–0.1 rad
        free_input_travel_rad: 0.3, // where the Monte Carlo counts an input apart
        driven_torque_nm: 1.0,      // turning free ≤ 0.41 N·m (offset); driven ≥ 1.99 N·m
        current_off_max_a: 3.0,
        adc_rail_time_s: 0.01, // overrunning chatter stalls the motor at the current limit ≈ 3 ms
        dead_current_nm: 0.0,  // off: the paper reading closes on almost no drive torque
        dead_current_speed_rad_s: 2.0,
        command_gain_tolerance: 0.3,
        command_floor_a: 2.5,
        held_back_torque_nm: 3.0, // healthy ≥ −0.6 N·m; a pack that lets the load through: ≈ −M
        held_back_time_s: 0.02,
        health_rate_per_s: 25.0,
        impact_time_s: 0.01,
        impact_window_s: 0.0016,
    };

    /// Set for the twin's physical reading (the plant they were tuned on): what commissioning
    /// on that reading gives. Tighter than [`Thresholds::DEFAULT`] where the family differs.
    pub const PHYSICAL_READING: Thresholds = Thresholds {
        braking_angle_factor: 2.0,
        braking_angle_allowance_rad: 0.1, // the twin's healthy pack stops within 0.07 rad
        opposed_braking_share: 1.0,       // both socket faces clamp from the cut
        dead_current_nm: 0.5,             // healthy ≥ 1.42 N·m; a dead reading's noise ≈ 0.13 N·m
        driven_torque_nm: 0.0,            // a drive face: the input never turns free
        ..Thresholds::DEFAULT
    };
}

impl Default for Thresholds {
    fn default() -> Self {
        Thresholds::DEFAULT
    }
}

/// How the pack is pressed while the drive turns the output against the load: a plant fact the
/// paper leaves open (docs/model.md, "The plant family"), set by commissioning.
#[cfg_attr(feature = "config-block", derive(serde::Serialize, serde::Deserialize))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DrivingPack {
    /// The drive's pull on the ramps unloads the spring: `F = F_s/(1 + a·k)` (the physical
    /// reading; the default).
    Relieved,
    /// The ramps stay open: the spring alone presses the pack, `F = F_s` (the paper reading).
    SpringOnly,
}

/// What commissioning identified of a spring-only pack braking a load that aids the motion
/// (docs/commissioning.md): `J·α = D + g·M` from the cut to the lock (`aiding.rs`).
#[cfg_attr(feature = "config-block", derive(serde::Serialize, serde::Deserialize))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AidingBraking {
    /// `J`: the output's inertia as its braking shows it (kg·m²).
    pub inertia_kg_m2: f64,
    /// `D`: the pack's braking torque with the ramps seated (N·m).
    pub drag_nm: f64,
    /// `g = a·k − 1`: braking torque gained per N·m of the load, less the load.
    pub load_gain: f64,
}

/// The sliding self-locking ratio `a·k` a configuration without a measured overrunning line is
/// refused within (exclusive): the model's line divides by `a·k − 1`.
pub const MARGINAL_SELF_LOCKING: (f64, f64) = (0.95, 1.05);

/// A relieved pack's overrunning equilibrium `y = g₁·v − g₀` measured at commissioning from
/// closings at two loads (docs/commissioning.md); it stands for the one `sliding_mu` gives.
#[cfg_attr(feature = "config-block", derive(serde::Serialize, serde::Deserialize))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OverrunLine {
    /// `g₁`: pack torque per N·m of drive torque along the motion (> 2: the pack self-locks).
    pub gain: f64,
    /// `g₀` (N·m, > 0).
    pub offset_nm: f64,
}

impl OverrunLine {
    /// The `a·k` its gain implies: `g₁ = 2a·k/(a·k − 1)`.
    pub fn self_locking_ratio(&self) -> f64 {
        self.gain / (self.gain - 2.0)
    }
}

/// A relieved pack's time from the drive's cut to the monitor's first lock, measured at
/// commissioning: the longest of its closings (a load along the motion) and the shortest of its
/// openings (against it). Where they lie apart it settles the power-on guess at that lock.
#[cfg_attr(feature = "config-block", derive(serde::Serialize, serde::Deserialize))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LockTimes {
    /// The closings' longest (s).
    pub along_s: f64,
    /// The openings' shortest (s), at least [`LockTimes::MIN_GAP_S`] beyond `along_s`.
    pub against_s: f64,
}

impl LockTimes {
    /// The least gap (s) that leaves each reading a band of one slow-lane period (0.4 ms) at
    /// a quarter of the gap.
    pub const MIN_GAP_S: f64 = 0.0016;
}

/// Everything the monitor is configured with; separate from its state. With `config-block`,
/// serde writes it as the firmware's configuration block (`config_block`).
#[cfg_attr(feature = "config-block", derive(serde::Serialize, serde::Deserialize))]
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
    /// How the pack is pressed while driving against the load (its force and drag then).
    pub driving_pack: DrivingPack,
    /// The pack's drag while the drive carries the load (N·m at the output), measured at
    /// commissioning; `None`: the model's, `μ_d·c` times the driving force of `driving_pack`.
    pub driving_drag_nm: Option<f64>,
    /// A spring-only pack's braking of an aiding load, once identified (else `None`).
    pub aiding_braking: Option<AidingBraking>,
    /// The overrunning equilibrium, once measured (else `None`: `sliding_mu`'s).
    pub overrun_line: Option<OverrunLine>,
    /// The cut-to-lock times, once measured (else `None`: the power-on guess stands).
    pub lock_times: Option<LockTimes>,
    /// The phase-current reading at zero current (A), measured at commissioning with the drive
    /// off; subtracted in whole ADC counts (at most an eighth of full scale).
    pub current_offset_a: f64,
    /// Most ticks one late step may cover (1..=32); the observer must be stable when advanced
    /// by any of 1..=this many ticks with one correction.
    pub max_catchup_ticks: u8,
    /// Rate (Hz) of the fault-braking model (the nominal braking the envelope checks against),
    /// stepped by explicit Euler in I16F16; `tick_hz` must be a whole multiple of it. Default
    /// [`DEFAULT_BRAKING_MODEL_HZ`], the cheapest rate meeting the accuracy targets
    /// (docs/results/cheapest-per-scene.md, `cargo xtask bench`).
    pub braking_model_hz: f64,
    /// Whether the model constants were set for this plant. Uncommissioned (false) no estimate
    /// is trusted: on the plant family its errors reach 30–100 % (docs/monitor.md); flags run.
    pub commissioned: bool,
    /// The commanded functional test's procedure and pass floor.
    pub functional_test: TestConfig,
    /// The test with the output uncoupled from the door, for a spring-only pack (set by
    /// commissioning from its acceptance push; `None`: not run).
    pub uncoupled_test: Option<TestConfig>,
}

/// Default rate of the fault-braking model (Hz): the cheapest-per-scene table's choice for
/// both braking scenes (reduced I16F16 explicit Euler at 1 kHz).
pub const DEFAULT_BRAKING_MODEL_HZ: f64 = 1_000.0;

/// Default observer bandwidth (Hz).
pub const DEFAULT_OBSERVER_BANDWIDTH_HZ: f64 = 30.0;
/// Default tick rate (Hz).
pub const DEFAULT_TICK_HZ: f64 = 10_000.0;

impl Config {
    /// Defaults around a mechanism and sensors: 10 kHz, 30 Hz observer, μ_s in `T_all`.
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
            driving_pack: DrivingPack::Relieved,
            driving_drag_nm: None,
            aiding_braking: None,
            overrun_line: None,
            lock_times: None,
            current_offset_a: 0.0,
            max_catchup_ticks: 8,
            braking_model_hz: DEFAULT_BRAKING_MODEL_HZ,
            commissioned: false,
            functional_test: TestConfig::DEFAULT,
            uncoupled_test: None,
        }
    }
}

impl Config {
    /// The defaults with [`Thresholds::PHYSICAL_READING`]: the monitor set for the twin's
    /// physical reading, as a commissioning on that reading sets it.
    pub fn physical_reading() -> Config {
        Config {
            thresholds: Thresholds::PHYSICAL_READING,
            commissioned: true,
            ..Config::default()
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
    /// The same error naming `parameter` instead.
    pub(crate) const fn renamed(self, parameter: &'static str) -> ConfigError {
        match self {
            ConfigError::NotFinite { .. } => ConfigError::NotFinite { parameter },
            ConfigError::OutOfRange { .. } => ConfigError::OutOfRange { parameter },
            ConfigError::Overflow { .. } => ConfigError::Overflow { parameter },
            ConfigError::Unstable { .. } => ConfigError::Unstable { parameter },
        }
    }

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

/// Ticks after power-on over which the observer's starting speed is measured.
pub const POWER_ON_SEED_TICKS: u32 = 16;

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
}
