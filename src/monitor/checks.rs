//! Checking: every failure check, one module per family. Each returns the flags it raised
//! this tick; the monitor latches them in one place.
//!
//! | family | flag | runs | module |
//! |---|---|---|---|
//! | braking envelope | `brake_weak` | every tick, `FaultBraking` | `envelope.rs` |
//! | creep | `brake_slip` | every tick, drive off, held | `hold.rs` |
//! | capacity margin | `brake_weak` | slow lane, `Checks` | here |
//! | common slip | `brake_slip` | slow lane, `Checks`, drive off, held | `hold.rs`, `slip.rs` |
//! | drag, steps of the drive's work | `brake_drag`, `sensor_fault` | slow lane, `Checks`, drive on | `drive.rs` |
//! | dead current reading | `sensor_fault` | window lane, drive on | `dead_current.rs` |
//! | reading against the drive's command | `sensor_fault` | every tick, drive on, command given | `current_command.rs` |
//! | an overrunning load the pack let through | `brake_degraded` (warning) | slow lane, `Checks`, drive on, moving | `overrunning.rs` |
//! | drag while the output lags its input | `brake_drag` | slow lane, `Checks`, drive on, moving | `lagging.rs` |

mod current_command;
mod dead_current;
mod drive;
mod envelope;
mod hold;
mod lagging;
mod overrunning;
mod slip;

pub(crate) use current_command::CommandSettings;
pub(crate) use dead_current::DeadCurrentSettings;
pub(crate) use drive::DriveSettings;
pub(crate) use envelope::EnvelopeSettings;
pub(crate) use hold::HoldSettings;
pub(crate) use overrunning::OverrunningSettings;

use super::config::{Config, ConfigError};
use super::convert::ticks;
use super::load::Load;
use super::observe::Observed;
use super::pack::{Dir, PackRatios, PackSettings};
use super::scene::Classified;
use super::schedule::{Slot, SLOW};
use super::sense::Sensed;
use super::{Flags, Scene};
use crate::fx::Q16;
use current_command::CommandCheck;
use dead_current::DeadCurrent;
use drive::{DriveChecks, DriveTick};
use envelope::Envelope;
pub(crate) use envelope::{BrakingTick, Decel};
use hold::HoldChecks;
use lagging::{LagTick, Lagging};
use overrunning::Overrunning;

/// The checks' constants.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct CheckSettings {
    persistence_ticks: u32,
    pub envelope: EnvelopeSettings,
    pub hold: HoldSettings,
    pub drive: DriveSettings,
    pub dead_current: DeadCurrentSettings,
    pub command: CommandSettings,
    pub overrunning: OverrunningSettings,
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
            command: CommandSettings::new(c)?,
            overrunning: OverrunningSettings::new(c)?,
        })
    }
}

/// What the checks read besides the call's stages.
pub(crate) struct CheckInputs {
    pub slot: Slot,
    pub drive_drag: Q16,
    pub min_load: Q16,
    /// The observer's settling after a change of the pack's reading (ticks).
    pub settle_ticks: u32,
    /// The input shaft's filtered speed and the band within which a shaft stands.
    pub input_speed: Q16,
    pub stick_speed: Q16,
    /// On the `Checks` slot with the command in the inputs: how far the reading falls short of
    /// it, as motoring drive torque (N·m).
    pub command_shortfall: Option<Q16>,
}

/// The checks' state.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug)]
pub(crate) struct Checks {
    weak_ticks: u32,
    envelope: Envelope,
    hold: HoldChecks,
    drive: DriveChecks,
    dead_current: DeadCurrent,
    command: CommandCheck,
    overrunning: Overrunning,
    lagging: Lagging,
}

impl Checks {
    pub fn new() -> Checks {
        Checks {
            weak_ticks: 0,
            envelope: Envelope::default(),
            hold: HoldChecks::default(),
            drive: DriveChecks::default(),
            dead_current: DeadCurrent::default(),
            command: CommandCheck::default(),
            overrunning: Overrunning::default(),
            lagging: Lagging::default(),
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
        self.overrunning.disarm();
        self.lagging.disarm();
        self.envelope = Envelope::default();
        self.hold.restart(counters.0, counters.1);
    }

    /// Every tick, first: an implausible step is no travel; a drive edge restarts the checks.
    pub fn events(&mut self, k: &CheckSettings, x: &Sensed, o: &Observed) {
        if o.fault {
            self.hold.disarm_slip();
        }
        if x.drive_edge {
            if !x.drive {
                self.envelope.arm(&k.envelope, o.w);
                self.hold.drive_cut();
            }
            self.hold.disarm_slip();
            self.dead_current.disarm(x.out);
            self.command.disarm();
            self.overrunning.disarm();
        }
    }

    /// A new hold arms the held brake's checks.
    pub fn locked(&mut self, x: &Sensed) {
        self.hold.locked(x.out, x.motor);
    }

    /// The per-tick checks (braking envelope, creep); returns the flags raised and whether the
    /// held brake gave way.
    pub fn every_tick(
        &mut self,
        k: &CheckSettings,
        x: &Sensed,
        o: &Observed,
        braking: Option<BrakingTick>,
    ) -> (Flags, bool) {
        let mut raised = Flags::default();
        match braking {
            Some(_) if !o.settled => self.envelope.arm(&k.envelope, o.w),
            Some(b) if x.out_ok => raised.brake_weak = self.envelope.check(&k.envelope, &b),
            _ => {}
        }
        let gave_way = !x.drive && x.out_ok && self.hold.creep(&k.hold, x.d_out, o.w.to_bits());
        raised.brake_slip = gave_way;
        (raised, gave_way)
    }

    /// The slow lane's checks on their slots, then the command check's sample (`c`: the last
    /// classification, `oc` the observer at it; `o` this tick's); returns the flags raised and
    /// whether the held brake gave way.
    #[allow(clippy::too_many_arguments)]
    pub fn slow(
        &mut self,
        k: &CheckSettings,
        x: &Sensed,
        o: &Observed,
        oc: &Observed,
        c: &Classified,
        load: &Load,
        i: &CheckInputs,
    ) -> (Flags, bool) {
        let mut raised = Flags::default();
        let mut gave_way = false;
        let drive = x.drive;
        if i.slot == Slot::Checks {
            // Capacity margin.
            let load_abs = load.estimate.value().saturating_abs();
            let margin_low = load.estimate.known().is_some()
                && load_abs >= i.min_load
                && load.cache.available < load.cache.margin_floor;
            self.weak_ticks = if margin_low {
                self.weak_ticks.saturating_add(SLOW.covered(x.n))
            } else {
                0
            };
            raised.brake_weak = self.weak_ticks >= k.persistence_ticks;
            if !drive {
                self.hold.track_speed(&k.hold, o.w.to_bits(), x.n);
                gave_way = self.hold.common_slip(&k.hold, x.out, x.motor);
                raised.brake_slip = gave_way;
            }
            // The running drive's checks, once it has run steadily for the observer's settling.
            let checks_ok = oc.settled
                && oc.sensors_ok
                && !c.dir.is_none()
                && c.scene != Scene::Holding
                && c.phase_settled;
            // The pack carries an overrunning load: the drive must not hold the motion back.
            if drive && checks_ok {
                let input = Dir::of(i.input_speed, i.stick_speed);
                raised.brake_degraded =
                    self.overrunning
                        .sample(&k.overrunning, c.dir, input, c.along);
            } else {
                self.overrunning.disarm();
            }
            // A pack that drags while the output falls behind its input.
            if drive && oc.settled && oc.sensors_ok && !c.dir.is_none() && x.out_ok {
                let t = LagTick {
                    dir: c.dir,
                    lagging: c.input_gaining,
                    output_speed: oc.w,
                    input_speed: i.input_speed,
                    stick_speed: i.stick_speed,
                    accel_torque: oc.net.saturating_add(oc.drive_torque),
                    out: x.out,
                    ticks: x.n,
                };
                raised.brake_drag |= self.lagging.sample(&k.drive, &t);
            } else {
                self.lagging.disarm();
            }
            if drive && checks_ok && c.steady_for_checks {
                let t = DriveTick {
                    dir: c.dir,
                    net: oc.net,
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
                    guessed: c.guessed,
                    ticks: x.n,
                    settle_ticks: i.settle_ticks,
                    command_shortfall: i.command_shortfall,
                };
                raised = raised.union(self.drive.run(&k.drive, &t));
            } else {
                self.drive.disarm();
            }
        }
        // A dead current reading (unless a known load lies below the spring drag, where a pack
        // whose spring broke could be driven by almost nothing).
        if drive
            && i.slot == Slot::DeadCurrent
            && k.dead_current.on()
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
        // The reading against the drive's own command, when the inputs carry it.
        if let (true, Some(code)) = (drive, x.command_code) {
            if self.command.sample(&k.command, x.current, code) {
                raised.sensor_fault = true;
                self.drive.suspect_current();
            }
        }
        (raised, gave_way)
    }
}
