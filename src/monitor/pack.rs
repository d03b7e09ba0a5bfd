//! The pack model of the physical reading (quasi-static, docs/monitor-design.md "Model"):
//! pressing force from torque, capacity from force, the drive-on equilibria, and Table 1.
//!
//! | constant | meaning | default |
//! |---|---|---|
//! | `spring_force` | `F_s`, the spring preload (N) | 169.2 N |
//! | `ramp_factor` | `k = tanθ/r`: N of pressing force per N·m through the ramps | 50 /m |
//! | `capacity_per_n` | `μ_s·c`: capacity per N of pressing force (m) | 0.0498 m |
//! | `drive_force`, `drive_drag` | `F_s/(1 + a·k)` (`F_s` with `DrivingPack::SpringOnly`) and `a·F` (or the commissioned `driving_drag_nm`) while the drive carries the load | 70 N, 1.98 N·m |
//! | `overrun_gain`, `overrun_offset` | `y = g₁·v − g₀`, the pack torque while overrunning (or the commissioned `overrun_line`) | 6.86, 11.6 N·m |

use super::config::{Config, ConfigError, DrivingPack, MARGINAL_SELF_LOCKING};
use super::convert::{finite, positive, q16, require, scale, Q16_ENVELOPE};
use super::scale::Scale;
use crate::fx::Q16;
use crate::table1::Motion;

/// Exact (f64) ratios of the pack that other stages' constants derive from.
#[cfg_attr(feature = "config-block", derive(serde::Serialize, serde::Deserialize))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PackRatios {
    /// `a·k = μ_d·c·tanθ/r`, the sliding self-locking ratio (1.42 at Table 2).
    pub a_k: f64,
    /// The drive drag `a·F_drive` (N·m).
    pub drive_drag_nm: f64,
}

/// The ratios' bit patterns (f64 has no `Hash`): a settings digest tells them apart exactly.
#[cfg(feature = "config-block")]
impl core::hash::Hash for PackRatios {
    fn hash<H: core::hash::Hasher>(&self, h: &mut H) {
        self.a_k.to_bits().hash(h);
        self.drive_drag_nm.to_bits().hash(h);
    }
}

/// The pack's constants, converted once.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PackSettings {
    pub spring_force: Q16,
    pub ramp_factor: Scale<21>,
    pub capacity_per_n: Scale<32>,
    pub drive_force: Q16,
    pub drive_drag: Q16,
    pub overrun_gain: Scale<24>,
    pub overrun_offset: Q16,
    /// `DrivingPack::SpringOnly`: against an opposing load the ramps stay open, `F = F_s`.
    pub spring_only: bool,
}

impl PackSettings {
    /// Checks the mechanism and derives the pack's constants; `max_load` (N·m) bounds the
    /// envelope the formats must hold. Also returns the ratios other stages derive from.
    pub fn new(c: &Config, max_load: f64) -> Result<(PackSettings, PackRatios), ConfigError> {
        let m = &c.mechanism;
        positive(m.output_inertia_kg_m2, "mechanism.output_inertia_kg_m2")?;
        positive(m.socket_radius_m, "mechanism.socket_radius_m")?;
        let chamfer = positive(m.socket_chamfer_rad, "mechanism.socket_chamfer_rad")?;
        require(
            chamfer < core::f64::consts::FRAC_PI_2,
            "mechanism.socket_chamfer_rad",
        )?;
        let r1 = positive(m.pack_inner_radius_m, "mechanism.pack_inner_radius_m")?;
        let r2 = positive(m.pack_outer_radius_m, "mechanism.pack_outer_radius_m")?;
        require(r2 > r1, "mechanism.pack_outer_radius_m")?;
        require(m.friction_discs != 0, "mechanism.friction_discs")?;
        let groove = finite(m.groove_angle_rad, "mechanism.groove_angle_rad")?;
        require(
            (0.0..core::f64::consts::TAU).contains(&groove),
            "mechanism.groove_angle_rad",
        )?;
        finite(m.spring_stiffness_n_m, "mechanism.spring_stiffness_n_m")?;
        finite(m.spring_preload_m, "mechanism.spring_preload_m")?;
        finite(m.pack_clearance_m, "mechanism.pack_clearance_m")?;
        require(
            m.spring_stiffness_n_m >= 0.0,
            "mechanism.spring_stiffness_n_m",
        )?;
        let mu = finite(c.capacity_mu, "capacity_mu")?;
        require(mu > 0.0 && mu <= 2.0, "capacity_mu")?;
        let ramp = m.ramp_factor_per_m();
        let per_n = m.pack_torque_per_newton_m(mu);
        let spring = m.spring_preload_n();
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
        require(mu_d > 0.0 && mu_d <= 2.0, "sliding_mu")?;
        // a·k = μ_d·c·tanθ/r (1.42 at Table 2): the overrunning equilibrium divides by a·k − 1.
        let a = m.pack_torque_per_newton_m(mu_d);
        let a_k = a * ramp;
        let drive_force = match c.driving_pack {
            DrivingPack::Relieved => spring / (1.0 + a_k),
            DrivingPack::SpringOnly => spring,
        };
        // A measured drag stands for the model's: at most what `sliding_mu`'s bound (μ = 2)
        // gives on the spring alone.
        let (drive_drag, drag_from) = match c.driving_drag_nm {
            Some(d) => {
                let d = finite(d, "driving_drag_nm")?;
                let most = m.pack_torque_per_newton_m(2.0) * spring;
                require(d > 0.0 && d <= most, "driving_drag_nm")?;
                (d, "driving_drag_nm")
            }
            None => (a * drive_force, "sliding_mu"),
        };
        // A measured line stands for the model's; `a·k` follows its gain, `g₁ = 2a·k/(a·k − 1)`.
        let ((gain, gain_from), (offset, offset_from), a_k) = match c.overrun_line {
            Some(l) => {
                let gain = finite(l.gain, "overrun_line.gain")?;
                require(gain > 2.0, "overrun_line.gain")?;
                let offset = positive(l.offset_nm, "overrun_line.offset_nm")?;
                (
                    (gain, "overrun_line.gain"),
                    (offset, "overrun_line.offset_nm"),
                    l.self_locking_ratio(),
                )
            }
            // The model's line divides by a·k − 1: refused near 1 (a measured line is not).
            None if a_k > MARGINAL_SELF_LOCKING.0 && a_k < MARGINAL_SELF_LOCKING.1 => {
                return Err(ConfigError::OutOfRange {
                    parameter: "sliding_mu",
                })
            }
            None => (
                (2.0 * a_k / (a_k - 1.0), "sliding_mu"),
                (a * spring / (a_k - 1.0), "sliding_mu"),
                a_k,
            ),
        };
        let settings = PackSettings {
            spring_force: q16(spring, "mechanism.spring_preload_m")?,
            ramp_factor: scale(ramp, "mechanism.socket_radius_m")?,
            capacity_per_n: scale(per_n, "capacity_mu")?,
            drive_force: q16(drive_force, "sliding_mu")?,
            drive_drag: q16(drive_drag, drag_from)?,
            overrun_gain: scale(gain, gain_from)?,
            overrun_offset: q16(offset, offset_from)?,
            spring_only: c.driving_pack == DrivingPack::SpringOnly,
        };
        let ratios = PackRatios {
            a_k,
            drive_drag_nm: drive_drag,
        };
        Ok((settings, ratios))
    }

    /// Pressing force `F_s + k·|t|` of a pack the ramps clamp with torque `t` (saturating).
    #[inline]
    pub fn clamped_force(&self, t: Q16) -> Q16 {
        self.spring_force.saturating_add(Q16::from_bits(
            self.ramp_factor.apply(t.saturating_abs().to_bits()),
        ))
    }

    /// Static capacity `μ_s·c·F` at pressing force `F`.
    #[inline]
    pub fn capacity(&self, force: Q16) -> Q16 {
        Q16::from_bits(self.capacity_per_n.apply(force.to_bits()))
    }

    /// Overrunning equilibrium `y = g₁·v − g₀` (≥ 0) for a drive torque `v` along the motion.
    #[inline]
    pub fn overrun_torque(&self, v: Q16) -> Q16 {
        Q16::from_bits(self.overrun_gain.apply(v.to_bits()))
            .saturating_sub(self.overrun_offset)
            .max(Q16::ZERO)
    }
}

/// Table 1 ([`crate::table1`]) with the Karnopp stick band: stuck (or no direction), the pack
/// carries the demand up to its capacity; slipping, its capacity along `dir`.
#[inline]
pub(crate) fn table1(stuck: bool, dir: Dir, demand: Q16, capacity: Q16) -> Q16 {
    let motion = if stuck || dir.is_none() {
        Motion::Stuck
    } else {
        Motion::Slipping { forward: dir.0 > 0 }
    };
    crate::table1::table1(motion, demand, capacity)
}

/// A direction of motion or load: −1, 0 (within a dead band) or +1.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub(crate) struct Dir(i32);

impl Dir {
    pub const NONE: Dir = Dir(0);

    /// The sign of `x` outside the band `±band`.
    #[inline]
    pub fn of(x: Q16, band: Q16) -> Dir {
        if x > band {
            Dir(1)
        } else if x < band.saturating_neg() {
            Dir(-1)
        } else {
            Dir(0)
        }
    }

    #[inline]
    pub fn is_none(self) -> bool {
        self.0 == 0
    }

    #[inline]
    pub fn opposes(self, other: Dir) -> bool {
        self.0 * other.0 < 0
    }

    /// `dir·x` for a count, saturating.
    #[inline]
    pub fn apply_count(self, x: i32) -> i32 {
        x.saturating_mul(self.0)
    }

    /// `dir·x`, saturating.
    #[inline]
    pub fn apply(self, x: Q16) -> Q16 {
        match self.0 {
            1 => x,
            -1 => x.saturating_neg(),
            _ => Q16::ZERO,
        }
    }
}
