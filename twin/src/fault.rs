//! Faults injected into the physics or the sensors at a time `at_s`, with a severity in 0..1.
//!
//! | kind | severity means |
//! |---|---|
//! | `friction_loss` | pack μ_s and μ_d multiplied by `1 − severity` (contamination, glazing) |
//! | `spring_broken` | wave-spring stiffness multiplied by `1 − severity` (relaxation, breakage) |
//! | `pack_wear` | pack clearance g_p2 grows by `severity × 1 mm` (worn discs: less preload, more travel) |
//! | `ramp_jam` | the output balls cannot climb their sockets: the ramp's axial force on the pack × `1 − severity` (both readings; 1 = spring alone) |
//! | `drag` | an extra pressing force of `severity × 1000 N` (partial seizure, heat) |
//! | `encoder_stuck` | output-encoder reading frozen from `at_s` (severity ignored) |
//! | `encoder_jump` | output-encoder reading jumps by `severity × 2^bits / 8` counts at `at_s` |
//! | `current_open` | measured current scaled by `1 − severity` (1 = open wire: mid-scale code) |

/// Kind of a fault.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FaultKind {
    /// Loss of pack friction.
    FrictionLoss,
    /// Wave spring broken or relaxed.
    SpringBroken,
    /// Worn pack discs.
    PackWear,
    /// Jammed ball ramp.
    RampJam,
    /// Pack drag.
    Drag,
    /// Output encoder stuck.
    EncoderStuck,
    /// Output encoder jump.
    EncoderJump,
    /// Current sensor open.
    CurrentOpen,
}

impl FaultKind {
    /// Parse the scene-file name.
    pub fn parse(s: &str) -> Option<FaultKind> {
        Some(match s {
            "friction_loss" => FaultKind::FrictionLoss,
            "spring_broken" => FaultKind::SpringBroken,
            "pack_wear" => FaultKind::PackWear,
            "ramp_jam" => FaultKind::RampJam,
            "drag" => FaultKind::Drag,
            "encoder_stuck" => FaultKind::EncoderStuck,
            "encoder_jump" => FaultKind::EncoderJump,
            "current_open" => FaultKind::CurrentOpen,
            _ => return None,
        })
    }

    /// True for faults that weaken the hold (they show, if at all, in the drive-off slips).
    pub fn is_holding(self) -> bool {
        matches!(
            self,
            FaultKind::FrictionLoss
                | FaultKind::SpringBroken
                | FaultKind::PackWear
                | FaultKind::RampJam
        )
    }

    /// True for faults of the sensors (they leave the physics alone).
    pub fn is_sensor(self) -> bool {
        matches!(
            self,
            FaultKind::EncoderStuck | FaultKind::EncoderJump | FaultKind::CurrentOpen
        )
    }
}

/// One fault of a scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fault {
    /// What fails.
    pub kind: FaultKind,
    /// When (s).
    pub at_s: f64,
    /// How badly, 0..1.
    pub severity: f64,
}

/// The physics modifiers in force at one time (all faults with `at_s ≤ t`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhysicsFaults {
    /// Multiplier on μ_s and μ_d.
    pub mu_scale: f64,
    /// Multiplier on the wave-spring stiffness.
    pub spring_scale: f64,
    /// Extra pack clearance (m).
    pub extra_pack_clearance_m: f64,
    /// Ramp-jam severity (0 = healthy).
    pub ramp_jam: f64,
    /// Extra pressing force (N).
    pub drag_force_n: f64,
}

impl Default for PhysicsFaults {
    fn default() -> Self {
        PhysicsFaults {
            mu_scale: 1.0,
            spring_scale: 1.0,
            extra_pack_clearance_m: 0.0,
            ramp_jam: 0.0,
            drag_force_n: 0.0,
        }
    }
}

impl PhysicsFaults {
    /// The modifiers of all physics faults active at time `t_s`.
    pub fn at(faults: &[Fault], t_s: f64) -> PhysicsFaults {
        let mut p = PhysicsFaults::default();
        for f in faults.iter().filter(|f| f.at_s <= t_s) {
            let s = f.severity.clamp(0.0, 1.0);
            match f.kind {
                FaultKind::FrictionLoss => p.mu_scale *= 1.0 - s,
                FaultKind::SpringBroken => p.spring_scale *= 1.0 - s,
                FaultKind::PackWear => p.extra_pack_clearance_m += s * 1e-3,
                FaultKind::RampJam => p.ramp_jam = p.ramp_jam.max(s),
                FaultKind::Drag => p.drag_force_n += s * 1000.0,
                FaultKind::EncoderStuck | FaultKind::EncoderJump | FaultKind::CurrentOpen => {}
            }
        }
        p
    }
}
