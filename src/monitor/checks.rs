//! Checking: every failure check, one module per family, run after the estimate on the call's
//! classification; [`Checks::run`] returns the flags raised this call (the monitor latches them
//! in one place).
//!
//! | family | flag | runs | module |
//! |---|---|---|---|
//! | capacity margin | `brake_weak` | every call | here |
//! | braking envelope | `brake_weak` | `FaultBraking` | `envelope.rs` |
//! | creep, common slip | `brake_slip` | drive off, held | `hold.rs`, `slip.rs` |
//! | drag, steps of the drive's work | `brake_drag`, `sensor_fault` | drive on, slow lane | `drive.rs` |
//! | dead current reading | `sensor_fault` | drive on, window lane | `dead_current.rs` |

mod dead_current;
mod drive;
mod envelope;
mod hold;
mod slip;

pub(crate) use dead_current::DeadCurrentSettings;
pub(crate) use drive::DriveSettings;
pub(crate) use envelope::EnvelopeSettings;
pub(crate) use hold::HoldSettings;

use super::config::{Config, ConfigError};
use super::convert::ticks;
use super::load::Load;
use super::observe::Observed;
use super::pack::{Dir, PackRatios, PackSettings};
use super::scene::Classified;
use super::schedule::Slot;
use super::sense::Sensed;
use super::{Flags, Scene};
use crate::fx::Q16;
use dead_current::DeadCurrent;
use drive::{DriveChecks, DriveTick};
use envelope::{BrakingTick, Envelope};
use hold::HoldChecks;

/// The checks' constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct CheckSettings {
    persistence_ticks: u32,
    pub envelope: EnvelopeSettings,
    pub hold: HoldSettings,
    pub drive: DriveSettings,
    pub dead_current: DeadCurrentSettings,
}

impl CheckSettings {
    pub fn new(
        c: &Config,
        pack: &PackSettings,
        r: &PackRatios,
    ) -> Result<CheckSettings, ConfigError> {
        Ok(CheckSettings {
            persistence_ticks: ticks(
                c.thresholds.flag_persistence_s,
                c.tick_hz,
                "thresholds.flag_persistence_s",
            )?,
            envelope: EnvelopeSettings::new(c)?,
            hold: HoldSettings::new(c)?,
            drive: DriveSettings::new(c, pack, r)?,
            dead_current: DeadCurrentSettings::new(c, r)?,
        })
    }
}

/// What the checks read besides the call's stages.
pub(crate) struct CheckInputs {
    pub tick: u32,
    pub slot: Slot,
    pub drive_drag: Q16,
    pub min_load: Q16,
}

/// The checks' state.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Checks {
    weak_ticks: u32,
    envelope: Envelope,
    hold: HoldChecks,
    drive: DriveChecks,
    dead_current: DeadCurrent,
}

impl Checks {
    pub fn new() -> Checks {
        Checks {
            weak_ticks: 0,
            envelope: Envelope::default(),
            hold: HoldChecks::default(),
            drive: DriveChecks::default(),
            dead_current: DeadCurrent::default(),
        }
    }

    /// A change of driving reading waits while the step check counts towards a verdict.
    pub fn step_counting(&self, k: &CheckSettings) -> bool {
        self.drive.counting_step(&k.drive)
    }

    /// `reset_flags`: the checks' counts and spans start afresh.
    pub fn reset(&mut self, counters: (u32, u32)) {
        self.weak_ticks = 0;
        self.drive.reset();
        self.envelope = Envelope::default();
        self.hold.restart(counters.0, counters.1);
    }

    /// Runs the checks of this call; returns the flags raised and whether the held brake gave
    /// way (the classifier then leaves `Holding`).
    pub fn run(
        &mut self,
        k: &CheckSettings,
        x: &Sensed,
        o: &Observed,
        c: &Classified,
        load: &Load,
        i: &CheckInputs,
    ) -> (Flags, bool) {
        let mut raised = Flags::default();
        let (n, drive) = (x.n, x.drive);
        // Events first: an implausible step is no travel; a drive edge restarts the checks;
        // a new hold arms the held brake's.
        if o.fault {
            self.hold.disarm_slip();
        }
        if x.drive_edge {
            if !drive {
                self.envelope.arm(&k.envelope, o.w);
                self.hold.drive_cut();
            }
            self.hold.disarm_slip();
            self.dead_current.disarm(x.out);
        }
        if c.just_locked {
            self.hold.locked(x.out, x.motor);
        }
        // Capacity margin.
        let load_abs = load.estimate.value().saturating_abs();
        let margin_low = load.estimate.known().is_some()
            && load_abs >= i.min_load
            && load.cache.available < load.cache.margin_floor;
        self.weak_ticks = if margin_low {
            self.weak_ticks.saturating_add(n)
        } else {
            0
        };
        raised.brake_weak |= self.weak_ticks >= k.persistence_ticks;
        // Braking envelope.
        if c.scene == Scene::FaultBraking && !o.settled {
            self.envelope.arm(&k.envelope, o.w);
        } else if c.scene == Scene::FaultBraking && x.out_ok {
            let b = BrakingTick {
                n,
                tick: i.tick,
                d_out: x.d_out,
                dir: c.dir,
                load_dir: Dir::of(load.estimate.value(), i.min_load),
                load_abs,
                capacity: load.cache.capacity,
            };
            raised.brake_weak |= self.envelope.check(&k.envelope, &b);
        }
        // The held brake.
        let mut gave_way = !drive && x.out_ok && self.hold.creep(&k.hold, x.d_out);
        if !drive && i.slot == Slot::Checks {
            gave_way |= self.hold.common_slip(&k.hold, x.out, x.motor);
        }
        raised.brake_slip |= gave_way;
        // A dead current reading (unless a known load lies below the spring drag, where a pack
        // whose spring broke could be driven by almost nothing).
        if drive
            && i.slot == Slot::DeadCurrent
            && self
                .dead_current
                .window(o.drive_torque, x.out, &k.dead_current)
            && o.settled
            && o.sensors_ok
            && load
                .estimate
                .known()
                .is_none_or(|l| l.saturating_abs() >= i.drive_drag)
        {
            raised.sensor_fault = true;
            self.drive.suspect_current();
        }
        // The running drive's checks, once it has run steadily for the observer's settling.
        if i.slot == Slot::Checks {
            let checks_ok = o.settled
                && o.sensors_ok
                && !c.dir.is_none()
                && c.scene != Scene::Holding
                && c.phase_settled;
            if drive && checks_ok && c.steady_for_checks {
                let t = DriveTick {
                    dir: c.dir,
                    net: o.net,
                    drive: c.along,
                    pack: if c.engaged() {
                        c.overrun_torque
                    } else {
                        i.drive_drag
                    },
                    engaged: c.engaged(),
                    carrying: c.scene == Scene::Driving,
                    load_ref: load.reference,
                    pending: c.pending,
                    ticks: n,
                };
                raised = raised.union(self.drive.run(&k.drive, &t));
            } else {
                self.drive.disarm();
            }
        }
        (raised, gave_way)
    }
}
