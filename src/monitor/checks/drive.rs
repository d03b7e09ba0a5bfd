//! The checks of a running drive, in the slow lane's `Checks` slot (`schedule.rs`):
//! `brake_drag` when the pack drags beyond its allowance, and the step check that
//! raises `brake_drag` or `sensor_fault` when the drive's work jumps. A pending change of the
//! driving reading waits while the step check counts (`counting_step`), and once it has called
//! the current reading low no `brake_drag` is raised from that reading until the flags are
//! reset (docs/monitor-design.md, "A change of reading waits for the step check").
//!
//! They live out of line (`#[inline(never)]`): the drive-off ticks — braking and holding, the
//! monitor's worst case — then do not carry their registers (docs/decisions.md).
//!
//! | quantity | format | range | resolution |
//! |---|---|---|---|
//! | implied load, drive torque, the command shortfall, their histories, the drive torque's floor | [`Q16`], saturating | ±32 768 N·m | 1.5e-5 N·m |
//! | persistence counters | `u32` ticks, saturating | — | 1 tick |

use crate::fx::{lowpass, Gain, Q16};
use crate::monitor::config::{Config, ConfigError};
use crate::monitor::convert::{filter_alpha, gain, nearest_shift, positive, q16, scale, ticks};
use crate::monitor::pack::{Dir, PackRatios, PackSettings};
use crate::monitor::scale::Scale;
use crate::monitor::schedule::SLOW;
use crate::monitor::Flags;

/// The drive torque's floor rises `2^FLOOR_RISE_SLOWER` times slower than its history follows
/// (16×: 0.4 s against 25.6 ms): a chatter's 10 N·m pulse of 20 ms lifts it ≤ 0.5 N·m.
const FLOOR_RISE_SLOWER: u32 = 4;

/// `state` moved towards `x` by `2^-shift` of the way (saturating difference; `shift` ≤ 31, so
/// the shift is exact).
#[inline]
pub(super) fn follow(state: Q16, x: Q16, shift: u32) -> Q16 {
    state.saturating_add(Q16::from_bits(
        x.saturating_sub(state).to_bits().wrapping_shr(shift),
    ))
}

/// The drive checks' constants.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct DriveSettings {
    persistence_ticks: u32,
    drive_drag: Q16,
    max_load: Q16,
    /// `T_drive + drag_allowance`: the pack torque above which a driving pack drags.
    drag_limit: Q16,
    /// Largest step of the implied load against its history while the drive carries the load.
    pub step_limit: Q16,
    /// The same step of drive torque while overrunning (`g₁ − 1` N·m of load per N·m).
    pub step_limit_overrun: Q16,
    /// The drive torque's own step that must come with a step of the implied load: half the
    /// allowance.
    step_drive_min: Q16,
    /// Overrunning, drive torque per N·m of implied load, halved: `1 / (2·(g₁ − 1))`.
    step_share_overrun: Scale<30>,
    /// The drive torque's history follows by this shift (the power of two nearest `step_alpha`).
    drive_ref_shift: u32,
    /// Gain of the implied load's history, in the slow lane.
    step_alpha: Gain,
    /// The history's time constant (ticks): a history seeded on a guessed reading judges no
    /// lighter step before it has followed this long.
    history_ticks: u32,
}

impl DriveSettings {
    /// The flags' persistence (ticks).
    pub fn persistence_ticks(&self) -> u32 {
        self.persistence_ticks
    }

    /// The drag a pack may add beyond the drive drag (N·m).
    pub fn drag_allowance(&self) -> Q16 {
        self.drag_limit.saturating_sub(self.drive_drag)
    }

    /// How far `J_s·ω̇` may move and still count as holding still: a quarter of the allowance.
    pub fn settle_band(&self) -> Q16 {
        Q16::from_bits(self.drag_allowance().to_bits() >> 2)
    }

    /// The histories' shift (`follow`).
    pub fn reference_shift(&self) -> u32 {
        self.drive_ref_shift
    }

    pub fn new(
        c: &Config,
        pack: &PackSettings,
        r: &PackRatios,
    ) -> Result<DriveSettings, ConfigError> {
        let (t, tick_hz) = (&c.thresholds, c.tick_hz);
        let allowance = positive(t.step_allowance_nm, "thresholds.step_allowance_nm")?;
        let alpha = filter_alpha(
            positive(t.step_reference_hz, "thresholds.step_reference_hz")?,
            tick_hz,
            SLOW,
        );
        Ok(DriveSettings {
            persistence_ticks: ticks(
                t.flag_persistence_s,
                tick_hz,
                "thresholds.flag_persistence_s",
            )?,
            drive_drag: pack.drive_drag,
            max_load: q16(
                positive(t.max_load_nm, "thresholds.max_load_nm")?,
                "thresholds.max_load_nm",
            )?,
            drag_limit: q16(
                r.drive_drag_nm + positive(t.drag_allowance_nm, "thresholds.drag_allowance_nm")?,
                "thresholds.drag_allowance_nm",
            )?,
            step_limit: q16(allowance, "thresholds.step_allowance_nm")?,
            step_limit_overrun: q16(
                allowance * (2.0 * r.a_k / (r.a_k - 1.0) - 1.0),
                "thresholds.step_allowance_nm",
            )?,
            step_drive_min: q16(allowance / 2.0, "thresholds.step_allowance_nm")?,
            step_share_overrun: scale(
                0.5 / (2.0 * r.a_k / (r.a_k - 1.0) - 1.0),
                "thresholds.step_allowance_nm",
            )?,
            drive_ref_shift: nearest_shift(alpha),
            step_alpha: gain(alpha, "thresholds.step_reference_hz")?,
            history_ticks: ticks(
                1.0 / (core::f64::consts::TAU * t.step_reference_hz),
                tick_hz,
                "thresholds.step_reference_hz",
            )?,
        })
    }
}

/// State of the drive checks.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct DriveChecks {
    /// Ticks the pack has dragged beyond the allowance.
    drag_ticks: u32,
    /// Recent history (low-pass) of the current-implied load along the motion.
    step_ref: Q16,
    /// Recent history (the same low-pass) of the drive torque along the motion.
    drive_ref: Q16,
    /// Recent history (the same low-pass) of the reading's shortfall against the command.
    shortfall_ref: Q16,
    /// Its floor: falls as the history does, rises 16× slower, so that the quiet spells of an
    /// overrunning chatter are no lighter step against the pulses between them.
    drive_floor: Q16,
    /// The history has been seeded in this phase of the drive.
    step_ref_valid: bool,
    /// Ticks a history seeded on a guessed reading still waits before it judges a lighter step
    /// (its time constant at the seeding, 0 on a decided reading).
    guess_wait_ticks: u32,
    /// Ticks the drive has worked harder than its history by more than the step limit.
    step_up_ticks: u32,
    /// Ticks it has seemed to work less (current reading low).
    step_down_ticks: u32,
    /// The step check has judged the current reading to have lost gain (`sensor_fault`):
    /// `brake_drag` is no longer raised from it until the flags are reset (a drag read from a
    /// reading known to be wrong would send maintenance to the brake). Kept across `disarm`.
    current_suspect: bool,
    /// Ticks the drag check still waits after a pending change of reading ended: the
    /// observer's net torque carries the pack's pulse for its settling time.
    drag_wait_ticks: u32,
}

/// What the step knows of this tick.
pub(crate) struct DriveTick {
    /// Direction of the output (±1: moving).
    pub dir: Dir,
    /// Observer net torque `J_s·ω̇ − u` (N·m).
    pub net: Q16,
    /// Drive torque along the motion, from the current (N·m).
    pub drive: Q16,
    /// The scene's pack torque magnitude: the drive drag, or the overrunning equilibrium.
    pub pack: Q16,
    /// Overrunning (the ramps engaged).
    pub engaged: bool,
    /// The drive carries the load (scene `Driving`).
    pub carrying: bool,
    /// The load learned at the start of this drive, if any: the drag check's reference.
    pub load_ref: Option<Q16>,
    /// A change of reading is pending: the step check runs against the history as it stood
    /// (its harder half only when the change is away from overrunning), the history is not
    /// updated and the drag check waits for the reading to settle.
    pub pending: bool,
    /// The reading is a guess (taken with no load known while the other fits the current too).
    pub guessed: bool,
    /// Ticks since the previous step.
    pub ticks: u32,
    /// The observer's settling after a change of the pack's reading (`engage_settle_s`).
    pub settle_ticks: u32,
    /// How far the reading falls short of the drive's command (N·m), when the inputs carry it.
    pub command_shortfall: Option<Q16>,
}

impl DriveChecks {
    /// Forgets the history and the persistence counts (drive off, output still, a change of
    /// reading), not the verdict on the current reading.
    #[inline]
    pub fn disarm(&mut self) {
        *self = DriveChecks {
            current_suspect: self.current_suspect,
            ..DriveChecks::default()
        };
    }

    /// Another check has found the current reading wrong (a dead reading): `brake_drag` is no
    /// longer raised from it until the flags are reset.
    #[inline]
    pub fn suspect_current(&mut self) {
        self.current_suspect = true;
    }

    /// Forgets everything, the verdict on the current reading too (`Monitor::reset_flags`).
    #[inline]
    pub fn reset(&mut self) {
        *self = DriveChecks::default();
    }

    /// The step check is counting a step of the drive's work (either way) and has not yet
    /// reached its verdict: a pending change of reading waits for it (the change would disarm
    /// the check and re-seed its history past the step; both faults it looks for can make the
    /// reading held impossible). At most the persistence time more.
    #[inline]
    pub fn counting_step(&self, p: &DriveSettings) -> bool {
        let counting = 1..p.persistence_ticks;
        counting.contains(&self.step_down_ticks) || counting.contains(&self.step_up_ticks)
    }

    /// One run (one tick in four, `t.ticks` ticks since the last step, counted four times).
    #[inline(never)]
    pub fn run(&mut self, p: &DriveSettings, t: &DriveTick) -> Flags {
        let mut flags = Flags::default();
        let counted = SLOW.covered(t.ticks);
        // Steps of the drive's work: the load the current implies along the motion (net torque
        // with the scene's pack model; the limit scaled by `g₁ − 1` when overrunning) against its
        // 5 Hz history, seeded once the phase has settled (docs/monitor-design.md, "Drive checks").
        let along = t.dir.apply(t.net.saturating_add(t.dir.apply(t.pack)));
        if self.step_ref_valid {
            let dev = along.saturating_sub(self.step_ref);
            let (harder, lighter) = if t.engaged {
                let limit = p.step_limit_overrun;
                // With the pack model at its floor (`y(v)` clamped at zero: the reading says the
                // ramps let go) the implied load moves by the drive torque's step alone, not
                // `g₁ − 1` times it: the plain limit.
                let lighter_limit = if t.pack == Q16::ZERO {
                    p.step_limit
                } else {
                    limit
                };
                (dev > limit, dev < lighter_limit.saturating_neg())
            } else {
                (dev < p.step_limit.saturating_neg(), dev > p.step_limit)
            };
            // Both faults move the current; the pack's own swings move the implied load through
            // `J_s·ω̇` alone. So the drive torque must step the same way by half the allowance and
            // half the implied load's step (÷ `g₁ − 1` with the ramps engaged).
            let dev_abs = dev.saturating_abs().to_bits();
            let share = Q16::from_bits(if t.engaged {
                p.step_share_overrun.apply(dev_abs)
            } else {
                dev_abs >> 1
            });
            let needed = share.max(p.step_drive_min);
            let drive_step = t.drive.saturating_sub(self.drive_ref);
            let below_floor = t.drive.saturating_sub(self.drive_floor);
            // A history seeded on a guess (a power-on into a running drive) may hold the
            // servo's settling: no lighter step until it has followed for its time constant.
            self.guess_wait_ticks = self.guess_wait_ticks.saturating_sub(counted);
            // With the command in the inputs, a lighter step is a lost gain only if the reading
            // fell short of the command too (by half the step asked): a drive that truly works
            // less moves its command with its current.
            let short_of_command = t.command_shortfall.is_none_or(|s| {
                s.saturating_sub(self.shortfall_ref) > Q16::from_bits(needed.to_bits() >> 1)
            });
            let (harder, lighter) = (
                harder && drive_step > needed,
                lighter
                    && below_floor < needed.saturating_neg()
                    && self.guess_wait_ticks == 0
                    && short_of_command,
            );
            // The harder half waits out a pending change towards overrunning (continuous closing's
            // chatter makes that reading possible on each 9 N·m pulse), not one away from it (a
            // drag under the overrunning reading pushes its load past the envelope).
            self.step_up_ticks = if harder && (!t.pending || t.engaged) {
                self.step_up_ticks.saturating_add(counted)
            } else {
                0
            };
            self.step_down_ticks = if lighter {
                self.step_down_ticks.saturating_add(counted)
            } else {
                0
            };
            if self.step_up_ticks >= p.persistence_ticks && !self.current_suspect {
                flags.brake_drag = true;
            }
            if self.step_down_ticks >= p.persistence_ticks {
                flags.sensor_fault = true;
                self.current_suspect = true;
            }
            if !t.pending {
                self.step_ref = lowpass(self.step_ref, along, p.step_alpha);
                // A shift for the gain (the power of two nearest the implied load's: 1/64, a
                // 6.2 Hz corner against 5 Hz): the direction of a step needs no more, and it is
                // cheaper than the multiply on the drive checks' tick, the drive's worst.
                self.drive_ref = follow(self.drive_ref, t.drive, p.drive_ref_shift);
                if let Some(s) = t.command_shortfall {
                    self.shortfall_ref = follow(self.shortfall_ref, s, p.drive_ref_shift);
                }
                let floor_shift = if t.drive > self.drive_floor {
                    p.drive_ref_shift.saturating_add(FLOOR_RISE_SLOWER).min(31)
                } else {
                    p.drive_ref_shift
                };
                self.drive_floor = follow(self.drive_floor, t.drive, floor_shift);
            }
        } else {
            self.step_ref = along;
            self.drive_ref = t.drive;
            self.drive_floor = t.drive;
            self.shortfall_ref = t.command_shortfall.unwrap_or(Q16::ZERO);
            self.step_ref_valid = true;
            self.guess_wait_ticks = if t.guessed { p.history_ticks } else { 0 };
        }
        // Drag against the drive's start: the load the current implies with a nominal drag
        // beyond the envelope, or the pack torque beyond the reference load by the allowance.
        // It waits the observer's settling after a pending change (continuous closing's chatter).
        self.drag_wait_ticks = if t.pending {
            t.settle_ticks
        } else {
            self.drag_wait_ticks.saturating_sub(counted)
        };
        if t.carrying && !t.pending && self.drag_wait_ticks == 0 {
            let implied = t.net.saturating_add(t.dir.apply(p.drive_drag)); // load if drag nominal
            let over_model = implied.saturating_abs() > p.max_load;
            // On a reference that aids the motion beyond the drag the output runs ahead and the
            // ramps engage, moving the net torque through `J_s·ω̇` (continuous closing's
            // chatter): there the drive itself must push past the allowance too.
            let excess = t.load_ref.is_some_and(|r| {
                t.dir.apply(r.saturating_sub(t.net)) > p.drag_limit
                    && (t.dir.apply(r) <= p.drive_drag
                        || t.drive > p.drag_limit.saturating_sub(p.drive_drag))
            });
            self.drag_ticks = if over_model || excess {
                self.drag_ticks.saturating_add(counted)
            } else {
                0
            };
            if self.drag_ticks >= p.persistence_ticks && !self.current_suspect {
                flags.brake_drag = true;
            }
        } else {
            self.drag_ticks = 0;
        }
        flags
    }
}

#[cfg(test)]
mod tests;
