//! What goes into one monitor step ([`Inputs`]) and what comes out ([`Estimate`], [`Flags`],
//! [`Scene`], [`BrakeState`]).
//!
//! Every output field is an integer, a `bool` or a `fixed` number, so estimates can be streamed
//! and compared bit for bit ([`Estimate::to_words`]).

use crate::fx::Q16;
use fixed::types::U40F24;

/// The raw readings of one tick.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Inputs {
    /// Phase-current ADC code, offset binary (mid-scale = 0 A). Codes above the converter's
    /// full scale are impossible and raise `sensor_fault`.
    pub current_adc_code: u16,
    /// Motor-encoder counter register; wraps modulo 2^`motor_counter_bits` (bits above are
    /// ignored for the position but raise `sensor_fault`).
    pub motor_counter: u32,
    /// Output-shaft absolute encoder reading (`output_encoder_bits` wide, wraps once per turn).
    pub output_counter: u32,
    /// Whether the drive is commanded on.
    pub drive_commanded: bool,
    /// The drive's current command as the ADC code an ideal sensor would read for it, if the
    /// controller hands it on (`None`: the command check does not run).
    pub current_command_code: Option<u16>,
    /// Ticks since the previous call: 1 when on time; `n > 1` means `n − 1` ticks were missed
    /// (raises `overrun`; the model is advanced by `n` ticks). 0 is treated as 1.
    pub ticks_elapsed: u8,
}

impl Inputs {
    /// On-time inputs (`ticks_elapsed = 1`).
    pub const fn new(
        current_adc_code: u16,
        motor_counter: u32,
        output_counter: u32,
        drive_commanded: bool,
    ) -> Inputs {
        Inputs {
            current_adc_code,
            motor_counter,
            output_counter,
            drive_commanded,
            current_command_code: None,
            ticks_elapsed: 1,
        }
    }

    /// These inputs with the drive's current command (an ADC code).
    pub const fn with_command(self, current_command_code: Option<u16>) -> Inputs {
        Inputs {
            current_command_code,
            ..self
        }
    }
}

/// The situation the monitor recognised; it selects the model used in the step.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Scene {
    /// Drive on and the input leads: pack released to its spring drag, load learned.
    Driving = 0,
    /// Drive off and the output locked: the pack holds the load (Table 1, stuck row).
    Holding = 1,
    /// Drive off and the output moving: the brake must stop it (motor failure, power-on).
    FaultBraking = 2,
    /// Drive on but the output runs ahead of the input (load-aided closing): ramps engaged,
    /// pack slipping at capacity.
    Overrunning = 3,
}

/// The model the monitor runs in a scene: per scene, the cheapest candidate that meets the
/// accuracy targets in `docs/results/cheapest-per-scene.md` (written by `cargo xtask bench`;
/// a host test fails when the two differ). Its [`Display`](core::fmt::Display) is the table's
/// label.
///
/// ```
/// use noback::monitor::{Config, Monitor, Scene, SceneModel};
/// let monitor = Monitor::new(Config::default()).unwrap();
/// assert_eq!(monitor.scene_model(Scene::Holding), SceneModel::QuasiStatic);
/// assert_eq!(
///     monitor.scene_model(Scene::FaultBraking),
///     SceneModel::ReducedI16F16Euler { rate_hz: 1000 }
/// );
/// ```
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneModel {
    /// No state to advance: the output at rest under the pack (holding) or at the drive's
    /// speed (driving); pack torque and force are quasi-static.
    QuasiStatic,
    /// The overrunning equilibrium `T = g₁·v − g₀` from the drive torque; no state.
    Equilibrium,
    /// The reduced braking model (speed decreasing at `(T_all ∓ |M̂|)/J_s`, travel) stepped by
    /// explicit Euler in I16F16 every `tick_hz / rate_hz` ticks: the braking envelope.
    ReducedI16F16Euler {
        /// Model steps per second.
        rate_hz: u32,
    },
}

impl core::fmt::Display for SceneModel {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            SceneModel::QuasiStatic => f.write_str("quasi-static (no state)"),
            SceneModel::Equilibrium => f.write_str("quasi-static equilibrium"),
            SceneModel::ReducedI16F16Euler { rate_hz } => {
                write!(f, "reduced I16F16 euler {} kHz", f64::from(rate_hz) / 1e3)
            }
        }
    }
}

/// State of the friction pack.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum BrakeState {
    /// Ramps not carrying load: pressing force is the spring preload only (drag).
    Released = 0,
    /// Ramps engaged and the pack slipping: braking torque = capacity (Table 1).
    Slipping = 1,
    /// Output stuck: braking torque = load, up to capacity (Table 1).
    Locked = 2,
}

/// Failure flags. In [`Estimate::flags`] they are latched: once raised they stay until
/// `Monitor::reset_flags`.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Flags {
    /// The output moved beyond the creep limit with the drive off after the brake had locked.
    pub brake_slip: bool,
    /// Capacity margin below the limit, or braking time/angle beyond the envelope.
    pub brake_weak: bool,
    /// Pack torque while driving beyond the allowance, drive current above the model, or a
    /// step up of the drive's work while driving (a drag that appears).
    pub brake_drag: bool,
    /// Implausible encoder or current reading (jump, stuck counter, out-of-range code, a
    /// step down of the current-implied drive work — a current reading that lost gain — or a
    /// current reading dead while the drive moves the output).
    pub sensor_fault: bool,
    /// A tick was missed.
    pub overrun: bool,
    /// Warning, not an alarm: the pack did not carry an overrunning load (the drive held the
    /// motion back); it may not hold once the drive lets go (`checks/overrunning.rs`).
    pub brake_degraded: bool,
}

impl Flags {
    /// Packs the flags: bit 0 brake_slip, 1 brake_weak, 2 brake_drag, 3 sensor_fault, 4 overrun,
    /// 5 brake_degraded.
    ///
    /// ```
    /// use noback::monitor::Flags;
    /// let f = Flags { brake_weak: true, overrun: true, ..Flags::default() };
    /// assert_eq!(f.bits(), 0b1_0010);
    /// assert_eq!(Flags::from_bits(f.bits()), f);
    /// ```
    pub const fn bits(self) -> u8 {
        (self.brake_slip as u8)
            | (self.brake_weak as u8) << 1
            | (self.brake_drag as u8) << 2
            | (self.sensor_fault as u8) << 3
            | (self.overrun as u8) << 4
            | (self.brake_degraded as u8) << 5
    }

    /// Inverse of [`Flags::bits`]; bits 6 and 7 are ignored.
    pub const fn from_bits(bits: u8) -> Flags {
        Flags {
            brake_slip: bits & 1 != 0,
            brake_weak: bits & 2 != 0,
            brake_drag: bits & 4 != 0,
            sensor_fault: bits & 8 != 0,
            overrun: bits & 16 != 0,
            brake_degraded: bits & 32 != 0,
        }
    }

    /// Each flag with its name, in bit order.
    pub const fn named(self) -> [(bool, &'static str); 6] {
        [
            (self.brake_slip, "brake_slip"),
            (self.brake_weak, "brake_weak"),
            (self.brake_drag, "brake_drag"),
            (self.sensor_fault, "sensor_fault"),
            (self.overrun, "overrun"),
            (self.brake_degraded, "brake_degraded"),
        ]
    }

    /// Whether any flag is raised.
    pub const fn any(self) -> bool {
        self.bits() != 0
    }

    /// Whether an alarm is raised: a brake or sensor fault (every flag but `overrun`, a missed
    /// tick, and the `brake_degraded` warning).
    #[inline]
    pub const fn fault(&self) -> bool {
        self.brake_slip | self.brake_weak | self.brake_drag | self.sensor_fault
    }

    /// Whether the plant or a sensor is not the model's: an alarm ([`Flags::fault`]) or the
    /// `brake_degraded` warning. The estimate is untrusted from then on.
    #[inline]
    pub const fn distrusts(&self) -> bool {
        self.fault() | self.brake_degraded
    }

    /// Whether the pack was seen holding less than its model: it gave way, braked weakly or let
    /// an overrunning load through. The reported capacity margin is 0 from then on.
    #[inline]
    pub const fn pack_weak(&self) -> bool {
        self.brake_slip | self.brake_weak | self.brake_degraded
    }

    /// Flags raised in `self` or `other`.
    #[inline]
    pub const fn union(self, other: Flags) -> Flags {
        Flags {
            brake_slip: self.brake_slip | other.brake_slip,
            brake_weak: self.brake_weak | other.brake_weak,
            brake_drag: self.brake_drag | other.brake_drag,
            sensor_fault: self.sensor_fault | other.sensor_fault,
            overrun: self.overrun | other.overrun,
            brake_degraded: self.brake_degraded | other.brake_degraded,
        }
    }
}

/// Number of words in [`Estimate::to_words`].
pub const ESTIMATE_WORDS: usize = 15;

/// The monitor's output for one tick. Signs follow the output shaft: positive = the direction
/// in which a positive load torque turns it.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Estimate {
    /// Tick counter (wraps after 2^32 ticks, 5 days at 10 kHz).
    pub tick: u32,
    /// Recognised scene.
    pub scene: Scene,
    /// Pack state.
    pub brake: BrakeState,
    /// Pressing force on the pack (N): spring preload, plus |load|·tanθ/r when the ramps hold
    /// load.
    pub pressing_force_n: Q16,
    /// Braking torque of the pack by Table 1 (N·m, signed, opposing the output's motion).
    pub braking_torque_nm: Q16,
    /// Braking torque measured by the observer: load estimate − net torque (N·m).
    pub measured_braking_torque_nm: Q16,
    /// Load torque estimate on the output shaft (N·m); held while it cannot be observed.
    pub load_torque_nm: Q16,
    /// Drive torque at the no-back input from the motor current (N·m).
    pub drive_torque_nm: Q16,
    /// Output-shaft speed (rad/s), from the observer.
    pub output_speed_rad_s: Q16,
    /// Input-shaft speed (rad/s), motor encoder ÷ reducer ratio.
    pub input_speed_rad_s: Q16,
    /// Holding capacity over the largest expected load (`max_load_nm`), scaled by the pack
    /// health; 0 once the pack was seen holding less than a load it met ([`Flags::pack_weak`]).
    pub capacity_margin: Q16,
    /// Its lower bound: the model's spread (`capacity_uncertainty`) taken off, health above 1
    /// not credited.
    pub capacity_margin_low: Q16,
    /// Pack health: measured over model braking torque while slipping (1.0 nominal).
    pub pack_health: Q16,
    /// Friction energy dissipated in the pack since power-on (J).
    pub friction_energy_j: U40F24,
    /// Whether the estimate can be relied on (a commissioned monitor, load known and its sign
    /// not a power-on guess, observer settled, sensors plausible, no brake or sensor fault
    /// latched: a faulty plant is not the model the estimate assumes).
    pub trusted: bool,
    /// Latched failure flags.
    pub flags: Flags,
}

impl Estimate {
    /// Before the first classification: braking with nothing known.
    pub(crate) const NONE: Estimate = Estimate {
        tick: 0,
        scene: Scene::FaultBraking,
        brake: BrakeState::Slipping,
        pressing_force_n: Q16::ZERO,
        braking_torque_nm: Q16::ZERO,
        measured_braking_torque_nm: Q16::ZERO,
        load_torque_nm: Q16::ZERO,
        drive_torque_nm: Q16::ZERO,
        output_speed_rad_s: Q16::ZERO,
        input_speed_rad_s: Q16::ZERO,
        capacity_margin: Q16::ZERO,
        capacity_margin_low: Q16::ZERO,
        pack_health: Q16::ONE,
        friction_energy_j: U40F24::ZERO,
        trusted: false,
        flags: Flags::from_bits(0),
    };

    /// [`Estimate::NONE`] with the capacity margin and its lower bound.
    pub(crate) const fn with_margins((margin, low): (Q16, Q16)) -> Estimate {
        Estimate {
            capacity_margin: margin,
            capacity_margin_low: low,
            ..Estimate::NONE
        }
    }

    /// No margin claimed: the pack was seen holding less than a load it met.
    pub(crate) fn drop_margins(&mut self) {
        (self.capacity_margin, self.capacity_margin_low) = (Q16::ZERO, Q16::ZERO);
    }

    /// The estimate as words for streaming and digests: tick, force, braking torque, measured
    /// braking torque, load, drive torque, output speed, input speed, margin, its lower bound,
    /// health (Q16 bits as `u32`), energy low and high words, then `brake | scene << 8 |
    /// trusted << 16 | flags << 24`, then an FNV-1a checksum of the first 14 words.
    pub fn to_words(&self) -> [u32; ESTIMATE_WORDS] {
        let energy = self.friction_energy_j.to_bits();
        let packed = u32::from(self.brake as u8)
            | u32::from(self.scene as u8) << 8
            | u32::from(self.trusted) << 16
            | u32::from(self.flags.bits()) << 24;
        let body = [
            self.tick,
            self.pressing_force_n.to_bits() as u32,
            self.braking_torque_nm.to_bits() as u32,
            self.measured_braking_torque_nm.to_bits() as u32,
            self.load_torque_nm.to_bits() as u32,
            self.drive_torque_nm.to_bits() as u32,
            self.output_speed_rad_s.to_bits() as u32,
            self.input_speed_rad_s.to_bits() as u32,
            self.capacity_margin.to_bits() as u32,
            self.capacity_margin_low.to_bits() as u32,
            self.pack_health.to_bits() as u32,
            energy as u32,
            (energy >> 32) as u32,
            packed,
        ];
        let mut hash = 0x811C_9DC5_u32;
        for word in body {
            for byte in word.to_le_bytes() {
                hash = (hash ^ u32::from(byte)).wrapping_mul(0x0100_0193);
            }
        }
        let [w0, w1, w2, w3, w4, w5, w6, w7, w8, w9, w10, w11, w12, w13] = body;
        [
            w0, w1, w2, w3, w4, w5, w6, w7, w8, w9, w10, w11, w12, w13, hash,
        ]
    }
}
