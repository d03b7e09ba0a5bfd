//! Estimating: the pack's pressing force and braking torque of this call (Table 1 in the
//! physical reading, quasi-static), the torque the observer's model feeds forward, and the
//! friction energy.
//!
//! | scene | pressing force | braking torque |
//! |---|---|---|
//! | `Driving` | `F_drive = F_s/(1 + a·k)` | Table 1 at the drive drag `a·F_drive` |
//! | `Overrunning` | `F_s + k·(T_o − v)`, `T_o = y − v` | `y = g₁·v − g₀` against the motion |
//! | `Holding` | `F_s + k·|T|` (`F_s`: a spring-only pack's ramps open) | `T = M̂ − J_s·α` (α from the impacts of the rattle) |
//! | `FaultBraking` | `F_s + k·|T|`; a spring-only pack: `F_s`, ramps open (against the load, turning back: `stop.rs`), else `F_s + k·|M̂|` (`M̂` unseen: the braking's so far, `aiding.rs`) | `T` measured: `M̂ − (J_s·ω̇ − u)` |
//!
//! Engaged, the torque is bounded by the capacity at that force (it binds only when the force
//! saturates or the pack does not self-lock).
//!
//! | quantity | format | range | resolution |
//! |---|---|---|---|
//! | force, torques | [`Q16`], saturating | ±32 768 | 1.5e-5 |
//! | friction energy | `U40F24` J, saturating | 1.1e12 J | 6e-8 J |

use super::config::{Config, ConfigError};
use super::convert::scale;
use super::pack::{table1, Dir, PackSettings};
use super::scale::Scale;
use super::scene::Classified;
use super::{mul_q16, Scene};
use crate::fx::Q16;
use fixed::types::U40F24;

/// The estimate's constants.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct EstimateSettings {
    /// Q16 W → U40F24 J per tick.
    energy_per_tick: Scale<32>,
}

impl EstimateSettings {
    pub fn new(c: &Config) -> Result<EstimateSettings, ConfigError> {
        // P·2^-16·h·2^24.
        Ok(EstimateSettings {
            energy_per_tick: scale(256.0 / c.tick_hz, "tick_hz")?,
        })
    }
}

/// The pack's state at the last classification.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug)]
pub(crate) struct PackEstimate {
    pub force: Q16,
    pub braking_torque: Q16,
}

/// Which capacity the observer's pack model takes (`Classify::model_capacity`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ModelCapacity {
    /// The pack's drag: the drive carries the load, or a spring-only pack's ramps are open.
    Drag,
    /// The overrunning equilibrium at the drive torque.
    Overrunning,
    /// The engaged pack's capacity at the load.
    Engaged,
}

/// The pack torque the observer's model feeds forward, every tick: Table 1 on the model's own
/// demand (its load state plus the drive torque), so that a stuck model stays at rest whatever
/// the observer has absorbed (Karnopp), with the capacity of the present reading.
#[inline]
pub(crate) fn model_torque(
    k: &PackSettings,
    locked: bool,
    model: ModelCapacity,
    dir: Dir,
    demand: Q16,
    drive_torque: Q16,
    engaged_capacity: Q16,
) -> Q16 {
    let capacity = match model {
        ModelCapacity::Engaged => engaged_capacity,
        ModelCapacity::Drag => k.drive_drag,
        ModelCapacity::Overrunning => k.overrun_torque(dir.apply(drive_torque)),
    };
    table1(locked || dir.is_none(), dir, demand, capacity)
}

/// What the pack estimate reads besides the classification.
pub(crate) struct PackInputs {
    pub locked: bool,
    pub load: Q16,
    /// `M̂ − J_s·α` while holding.
    pub held_torque: Q16,
    /// Measured braking torque `M̂ − net`.
    pub measured: Q16,
    /// Capacity of the engaged pack at the load.
    pub engaged_capacity: Q16,
    pub drive_torque: Q16,
    /// An unseen aiding load read from the braking since the cut (`aiding`), if any.
    pub braking_load: Option<Q16>,
}

/// Force and torques for one call.
pub(crate) fn pack(k: &PackSettings, c: &Classified, i: &PackInputs) -> PackEstimate {
    let dir = c.dir;
    let engaged = c.engaged();
    let stuck = i.locked || dir.is_none();
    let capacity = if engaged {
        i.engaged_capacity
    } else {
        k.drive_drag
    };
    let (force, torque) = match c.scene {
        Scene::Driving => (
            k.drive_force,
            table1(stuck, dir, i.load.saturating_add(i.drive_torque), capacity),
        ),
        Scene::Overrunning => {
            let excess = c
                .overrun_torque
                .saturating_sub(c.along)
                .saturating_sub(c.along);
            (
                k.spring_force
                    .saturating_add(Q16::from_bits(k.ramp_factor.apply(excess.to_bits())))
                    .max(Q16::ZERO),
                dir.apply(c.overrun_torque),
            )
        }
        Scene::Holding | Scene::FaultBraking => {
            let t = if i.locked {
                i.held_torque
            } else if stuck {
                i.load
            } else {
                i.measured
            };
            // A spring-only pack's ramps carry the load alone: open against it, clamped by it.
            let force = match (k.spring_only, c.scene) {
                _ if c.ramps_open => k.spring_force,
                (true, Scene::FaultBraking) if !c.load_along => k.spring_force,
                (true, Scene::FaultBraking) => k.clamped_force(i.braking_load.unwrap_or(i.load)),
                _ => k.clamped_force(t),
            };
            (force, t)
        }
    };
    // Carried by the drive, the drag is a constant below the capacity: no bound needed.
    let braking_torque = if c.scene == Scene::Driving {
        torque
    } else {
        let cap = k.capacity(force).max(Q16::ZERO);
        torque.min(cap).max(cap.saturating_neg())
    };
    PackEstimate {
        force,
        braking_torque,
    }
}

/// Friction energy: slip power `|T·ω|` integrated in the slow lane over the ticks since its
/// last sample (a heat estimate; saturating, monotone).
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug)]
pub(crate) struct Energy {
    pub joules: U40F24,
    /// The tick of the last sample.
    at: u32,
}

impl Energy {
    pub const fn new() -> Energy {
        Energy {
            joules: U40F24::ZERO,
            at: 0,
        }
    }

    /// On the slow lane's energy slot: the slip power over the ticks since the last sample.
    pub fn update(
        &mut self,
        k: &EstimateSettings,
        tick: u32,
        torque: Q16,
        speed: Q16,
        slipping: bool,
    ) {
        let ticks = tick.wrapping_sub(core::mem::replace(&mut self.at, tick)); // late ticks too
        if slipping {
            let power = mul_q16(torque, speed).saturating_abs();
            let joules = k.energy_per_tick.apply(power.to_bits()).max(0) as u64 * u64::from(ticks);
            self.joules = U40F24::from_bits(self.joules.to_bits().saturating_add(joules));
        }
    }
}
