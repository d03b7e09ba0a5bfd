//! Classifying: which scene the actuator is in, as one state machine, and with it the output's
//! direction, the drive torque along the motion and the overrunning equilibrium.
//!
//! | state | when | leaves |
//! |---|---|---|
//! | `Driving(reading)` | drive on | drive off → `Braking` |
//! | `Braking` | drive off, output moving | the stop rule (`stop.rs`) → `Holding`; drive on |
//! | `Holding` | drive off, the pack holds | a slip check → `Braking`; drive on |
//!
//! While driving, the *reading* says who carries the load: the drive (`Driving` scene: pack at
//! its drag) or the pack (`Overrunning`: the load runs along the motion). The current tells
//! them apart only when the overrunning reading's load lies outside the envelope; otherwise the
//! learned load's sign decides, and with no load known yet the overrunning reading is taken (the
//! driving one for a `DrivingPack::SpringOnly` pack) as a guess (`Classified::guessed`).
//! After the first settled decision of a drive, the other reading must be wanted for
//! `engage_settle_s` (and the step check must not be counting) before it switches.
//!
//! | quantity | format | range | resolution |
//! |---|---|---|---|
//! | shafts' travel per window, averaged | `i32` counts × 32, saturating | ±2^26 counts a window | 1/32 count |

use super::config::{Config, ConfigError, DrivingPack, LockTimes};
use super::convert::{counts, positive, q16, require, ticks};
use super::estimate::ModelCapacity;
use super::load::LoadEstimate;
use super::observe::Observed;
use super::pack::{Dir, PackSettings};
use super::scale::Scale;
use super::schedule::WINDOW;
use super::sense::Sensed;
use super::stop::{Motion, StopSettings, Turn};
use super::{convert::scale, Scene};
use crate::fx::{counter_delta, Q16};

/// `Classify::since_cut` with no cut awaiting its first lock (a count saturates there too:
/// a lock 5 days after its cut is not timed).
const NO_CUT: u32 = u32::MAX;

/// Windows each shaft's travel is averaged over (51 ms at 10 kHz): a power of two.
const AHEAD_SHIFT: u32 = 5;
const AHEAD_WINDOWS: u32 = 1 << AHEAD_SHIFT;

/// The classifier's constants.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SceneSettings {
    pub stick_speed: Q16,
    pub min_load: Q16,
    pub max_load: Q16,
    stop: StopSettings,
    pub engage_settle_ticks: u32,
    settle_ticks: u32,
    out_bits: u8,
    motor_bits: u8,
    /// Motor counts → output counts (the shafts turn alike when synchronous).
    motor_to_out: Scale<30>,
    /// Relative travel (output counts) over a window within the synchronism band.
    sync_band_counts: i32,
    /// The input's mean gain on the output per window (output counts × [`AHEAD_WINDOWS`])
    /// beyond which it runs ahead: the stick speed.
    ahead_counts: i32,
    /// With no load known, take the overrunning reading (a relieved pack: its overrunning
    /// drive torque lies above the drag); a spring-only pack overruns on almost none.
    overrun_when_unknown: bool,
    /// A first lock after a cut this many ticks or more after it puts the load against the
    /// motion (`Config::lock_times`: a quarter of the gap short of the openings' shortest; 0:
    /// none given).
    lock_against_ticks: u32,
}

impl SceneSettings {
    pub fn new(c: &Config, settle_ticks: u32) -> Result<SceneSettings, ConfigError> {
        let (s, t, tick_hz) = (&c.sensors, &c.thresholds, c.tick_hz);
        let (out_rad, in_rad) = (s.output_rad_per_count(), s.input_rad_per_motor_count());
        let stick_speed = q16(
            positive(t.stick_speed_rad_s, "thresholds.stick_speed_rad_s")?,
            "thresholds.stick_speed_rad_s",
        )?;
        Ok(SceneSettings {
            stick_speed,
            min_load: q16(
                positive(t.min_load_nm, "thresholds.min_load_nm")?,
                "thresholds.min_load_nm",
            )?,
            max_load: q16(
                positive(t.max_load_nm, "thresholds.max_load_nm")?,
                "thresholds.max_load_nm",
            )?,
            stop: StopSettings::new(c)?,
            engage_settle_ticks: ticks(t.engage_settle_s, tick_hz, "thresholds.engage_settle_s")?,
            settle_ticks,
            out_bits: s.output_encoder_bits,
            motor_bits: s.motor_counter_bits,
            motor_to_out: scale(in_rad / out_rad, "sensors.motor_encoder_counts_per_rev")?,
            sync_band_counts: counts(
                t.sync_speed_band_rad_s * f64::from(WINDOW.ticks) * (1.0 / tick_hz) / out_rad,
                "thresholds.sync_speed_band_rad_s",
            )?,
            ahead_counts: counts(
                t.stick_speed_rad_s * f64::from(WINDOW.ticks * AHEAD_WINDOWS) / tick_hz / out_rad,
                "thresholds.stick_speed_rad_s",
            )?,
            overrun_when_unknown: c.driving_pack == DrivingPack::Relieved,
            lock_against_ticks: match c.lock_times {
                Some(l) => {
                    let gap = l.against_s - l.along_s;
                    require(l.along_s > 0.0 && gap >= LockTimes::MIN_GAP_S, "lock_times")?;
                    ticks(l.against_s - gap / 4.0, tick_hz, "lock_times")?
                }
                None => 0,
            },
        })
    }
}

/// Who carries the load while the drive runs.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Reading {
    pub overrunning: bool,
    /// The overrunning reading was taken with no load known while the driving one fitted the
    /// current as well: the load's sign is a guess until a later decision.
    guessed: bool,
    /// Decided once this drive, on a settled observer.
    decided: bool,
    /// Ticks the other reading has been wanted.
    pending_ticks: u32,
}

/// The scene state machine.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Phase {
    Driving(Reading),
    Braking,
    Holding,
}

/// What classifying hands on.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug)]
pub(crate) struct Classified {
    pub scene: Scene,
    /// Output direction (outside the stick band).
    pub dir: Dir,
    /// Drive torque along the motion.
    pub along: Q16,
    /// Overrunning equilibrium `y` (computed only where it is needed, else zero).
    pub overrun_torque: Q16,
    /// The load estimate lies along the motion, beyond `min_load_nm` (it aids the motion).
    pub load_along: bool,
    /// A change of driving reading is pending.
    pub pending: bool,
    /// Overrunning on the power-on guess: the driving reading fitted the current as well.
    pub guessed: bool,
    /// The reading changed this call (bumpless for the observer).
    pub reading_switch: bool,
    /// The brake locked this call.
    pub just_locked: bool,
    /// The first lock since the cut came late enough (`lock_times`) to put the load against
    /// the motion.
    pub lock_against: bool,
    /// A spring-only pack's ramps open (`F = F_s`): cut against the load, not clamped since.
    pub ramps_open: bool,
    /// The scene has lasted `engage_settle_s`.
    pub phase_settled: bool,
    /// The drive has run steadily (output with the input) for `engage_settle_s` / the
    /// observer's settling time.
    pub steady_for_learning: bool,
    pub steady_for_checks: bool,
    /// Over the last synchronism window the input gained on the output beyond the band, along
    /// the motion (the counters: the output lags).
    pub input_gaining: bool,
}

impl Classified {
    /// Before the first classification.
    pub const NONE: Classified = Classified {
        scene: Scene::FaultBraking,
        dir: Dir::NONE,
        along: Q16::ZERO,
        overrun_torque: Q16::ZERO,
        load_along: false,
        pending: false,
        guessed: false,
        reading_switch: false,
        just_locked: false,
        lock_against: false,
        ramps_open: false,
        phase_settled: false,
        steady_for_learning: false,
        steady_for_checks: false,
        input_gaining: false,
    };

    /// Ramps engaged: the drive off (both socket faces clamp) or overrunning.
    #[inline]
    pub fn engaged(&self) -> bool {
        self.scene != Scene::Driving
    }
}

/// The classifier's state.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug)]
pub(crate) struct Classify {
    pub phase: Phase,
    scene: Scene,
    stick_ticks: u32,
    phase_ticks: u32,
    last_dir: Dir,
    /// Ticks of steady driving, counted in windows on the synchronism slot.
    steady_ticks: u32,
    /// Each shaft's travel along the motion per window (motor, output counts), averaged over
    /// the last [`AHEAD_WINDOWS`] of the drive (× [`AHEAD_WINDOWS`], saturating).
    ahead_motor: i32,
    ahead_out: i32,
    sync_out: u32,
    sync_motor: u32,
    /// The last window's input gained on the output beyond the band (along the motion).
    input_gaining: bool,
    /// Ticks since the last classification.
    since: u32,
    /// Ticks since the drive's cut, until the first lock after it ([`NO_CUT`] otherwise).
    since_cut: u32,
    turn: Turn,
}

impl Classify {
    pub const fn new() -> Classify {
        Classify {
            phase: Phase::Braking,
            scene: Scene::FaultBraking,
            stick_ticks: 0,
            phase_ticks: 0,
            last_dir: Dir::NONE,
            steady_ticks: 0,
            ahead_motor: 0,
            ahead_out: 0,
            sync_out: 0,
            sync_motor: 0,
            input_gaining: false,
            since: 0,
            since_cut: NO_CUT,
            turn: Turn::None,
        }
    }

    /// Every tick, before anything else reads the classification: counts the tick; at power-on
    /// takes the counters; at a drive edge leaves the held or driving state at once (the rest
    /// waits for the next classification).
    pub fn tick(&mut self, x: &Sensed, o: &Observed) {
        self.since = self.since.saturating_add(x.n);
        self.since_cut = self.since_cut.saturating_add(x.n);
        if x.first {
            (self.sync_out, self.sync_motor) = (x.out, x.motor);
        }
        if x.drive && o.head_start > 0 {
            self.steady_ticks = self.steady_ticks.saturating_add(o.head_start);
        }
        if x.drive_edge {
            (self.steady_ticks, self.input_gaining) = (0, false);
            self.phase = if x.drive {
                (self.ahead_motor, self.ahead_out) = (0, 0);
                self.since_cut = NO_CUT;
                Phase::Driving(Reading::none())
            } else {
                self.since_cut = 0;
                Phase::Braking
            };
        }
    }

    /// The previous call's scene.
    pub fn scene(&self) -> Scene {
        self.scene
    }

    /// Classifies the ticks since the last call (the slow lane's [`Slot::Classify`]).
    pub fn update(
        &mut self,
        k: &SceneSettings,
        pack: &PackSettings,
        x: &Sensed,
        o: &Observed,
        load: LoadEstimate,
        step_counting: bool,
    ) -> Classified {
        let n = core::mem::replace(&mut self.since, 0);
        let dir = Dir::of(o.w, k.stick_speed);
        let along = dir.apply(o.drive_torque);
        let known = load.known().is_some();
        let load_along = dir.apply(load.value()) > k.min_load;
        // y is needed while overrunning, or to test for it unless a known load is against the
        // motion (then the reading is settled and the product is skipped).
        let mut overrun_torque = Q16::ZERO;
        let mut just_locked = false;
        let mut lock_against = false;
        let prev = self.phase;
        if x.drive {
            let against = dir
                .apply(load.known().unwrap_or(Q16::ZERO))
                .saturating_neg();
            self.turn = Turn::at_cut(&k.stop, against, k.min_load);
        }
        self.phase = match (x.drive, prev) {
            (true, _) if dir.is_none() => Phase::Driving(Reading::none()),
            (true, p) => {
                let r = match p {
                    Phase::Driving(r) => r,
                    _ => Reading::none(),
                };
                if r.overrunning || !known || load_along {
                    overrun_torque = pack.overrun_torque(along);
                }
                let implied = overrun_torque.saturating_sub(along);
                let possible = o.settled
                    && along > pack.drive_drag
                    && implied > k.min_load
                    && implied <= k.max_load;
                let wanted = possible && (load_along || (!known && k.overrun_when_unknown));
                let guess = !known && wanted;
                Phase::Driving(r.next(
                    wanted,
                    guess,
                    o.settled,
                    n,
                    k.engage_settle_ticks,
                    step_counting,
                ))
            }
            (false, p) => {
                self.stick_ticks = if o.w.saturating_abs() < k.stick_speed {
                    self.stick_ticks.saturating_add(n)
                } else {
                    0
                };
                // The brake stops the output: it dwells in the stick band, or an impact in the
                // lost motion throws it back within a tick or two.
                let reversed = dir.opposes(self.last_dir);
                let m = Motion {
                    reversed,
                    out: x.out,
                    out_bits: k.out_bits,
                    w: o.w,
                    stick_speed: k.stick_speed,
                };
                match p {
                    Phase::Holding => Phase::Holding,
                    _ if self.turn.stops(&k.stop, &mut self.stick_ticks, &m) => {
                        just_locked = true;
                        let t = core::mem::replace(&mut self.since_cut, NO_CUT);
                        lock_against =
                            k.lock_against_ticks != 0 && t != NO_CUT && t >= k.lock_against_ticks;
                        Phase::Holding
                    }
                    _ => Phase::Braking,
                }
            }
        };
        if x.drive {
            self.stick_ticks = 0;
        }
        if !dir.is_none() {
            self.last_dir = dir;
        }
        let scene = match self.phase {
            Phase::Driving(r) if r.overrunning => Scene::Overrunning,
            Phase::Driving(_) => Scene::Driving,
            Phase::Braking => Scene::FaultBraking,
            Phase::Holding => Scene::Holding,
        };
        // A change between the two driving readings changes how the motion is read, not it.
        let reading_switch = x.drive
            && matches!(self.scene, Scene::Driving | Scene::Overrunning)
            && scene != self.scene;
        self.phase_ticks = if scene != self.scene {
            0
        } else {
            self.phase_ticks.saturating_add(n)
        };
        self.scene = scene;
        let steady_for_learning = self.steady_ticks >= k.engage_settle_ticks;
        let steady_for_checks = self.steady_ticks >= k.settle_ticks;
        Classified {
            scene,
            dir,
            along,
            overrun_torque,
            load_along,
            pending: matches!(self.phase, Phase::Driving(r) if r.pending_ticks != 0),
            guessed: matches!(self.phase, Phase::Driving(r) if r.overrunning && r.guessed),
            reading_switch,
            just_locked,
            lock_against,
            ramps_open: self.turn.ramps_open(),
            phase_settled: self.phase_ticks >= k.engage_settle_ticks,
            steady_for_learning,
            steady_for_checks,
            input_gaining: self.input_gaining,
        }
    }

    /// A slip check saw the pack give way: the brake no longer holds.
    pub fn lose_hold(&mut self) {
        if self.phase == Phase::Holding {
            (self.phase, self.turn) = (Phase::Braking, Turn::None);
        }
    }

    /// The last drive's input ran ahead of the output along the motion (the paper reading's
    /// ideal speed input on a load its pack nearly holds): drive off, the pack engages only
    /// once the output has caught it up, somewhere unknown.
    pub fn input_ran_ahead(&self, k: &SceneSettings) -> bool {
        k.motor_to_out
            .apply(self.ahead_motor)
            .saturating_sub(self.ahead_out)
            > k.ahead_counts
    }

    /// Where the pack engages is known: the input did not run ahead of the output, and a
    /// spring-only pack cut against the load is not braking before its lock (`stop.rs`).
    pub fn engagement_known(&self, k: &SceneSettings) -> bool {
        let turning = self.phase == Phase::Braking && self.turn != Turn::None;
        !(turning || self.input_ran_ahead(k))
    }

    /// The capacity the observer's pack model takes: the drag while the drive carries the
    /// load or a spring-only pack's ramps are open.
    pub fn model_capacity(&self, drive: bool) -> ModelCapacity {
        match (drive, self.phase) {
            (true, Phase::Driving(r)) if r.overrunning => ModelCapacity::Overrunning,
            (true, _) => ModelCapacity::Drag,
            (false, Phase::Braking) if self.turn.ramps_open() => ModelCapacity::Drag,
            (false, _) => ModelCapacity::Engaged,
        }
    }

    /// Braking, judged by the braking envelope (after a turn-back the stop rule's travel limits
    /// judge it).
    pub fn enveloped(&self) -> bool {
        self.scene == Scene::FaultBraking && !self.turn.turned_back()
    }

    /// Whether the brake is locked (holding).
    pub fn locked(&self) -> bool {
        self.phase == Phase::Holding
    }

    /// Steady driving: the travel of both shafts over the last window agrees within the band
    /// (measured on the counters, not the observer, whose speed lags a step of the model's
    /// torque). An output that runs away from the input restarts the count. Each shaft's
    /// travel is averaged too ([`Classify::input_ran_ahead`]).
    /// On the window lane's [`Slot::Sync`] with the drive on.
    pub fn sync_window(&mut self, k: &SceneSettings, x: &Sensed, w: Q16) {
        let dir = Dir::of(w, k.stick_speed);
        let d_o = counter_delta(self.sync_out, x.out, k.out_bits);
        let d_m = counter_delta(self.sync_motor, x.motor, k.motor_bits);
        (self.sync_out, self.sync_motor) = (x.out, x.motor);
        let gain = k.motor_to_out.apply(d_m).saturating_sub(d_o);
        let synchronous = gain.saturating_abs() <= k.sync_band_counts;
        self.input_gaining = dir.apply_count(gain) > k.sync_band_counts;
        if !dir.is_none() {
            let average = |mean: i32, d: i32| {
                mean.saturating_add(dir.apply_count(d))
                    .saturating_sub(mean >> AHEAD_SHIFT)
            };
            self.ahead_motor = average(self.ahead_motor, d_m);
            self.ahead_out = average(self.ahead_out, d_o);
        }
        self.steady_ticks = if !dir.is_none() && synchronous {
            self.steady_ticks
                .saturating_add(x.n.saturating_mul(WINDOW.ticks))
        } else {
            0
        };
    }
}

impl Reading {
    const fn none() -> Reading {
        Reading {
            overrunning: false,
            guessed: false,
            decided: false,
            pending_ticks: 0,
        }
    }

    /// Debounced: the first settled decision of a drive is taken at once; a later change only
    /// once wanted for `settle` ticks and not while the step check counts towards a verdict.
    /// A decision made on the power-on default (`guess`) is marked so.
    fn next(
        self,
        wanted: bool,
        guess: bool,
        settled: bool,
        n: u32,
        settle: u32,
        step_counting: bool,
    ) -> Reading {
        let mut r = self;
        if settled && !r.decided {
            r = Reading {
                overrunning: wanted,
                guessed: guess,
                decided: true,
                pending_ticks: 0,
            };
        } else if wanted == r.overrunning {
            r.pending_ticks = 0;
        } else {
            r.pending_ticks = r.pending_ticks.saturating_add(n);
            if r.pending_ticks >= settle && !step_counting {
                (r.overrunning, r.guessed) = (wanted, guess);
                r.pending_ticks = 0;
            }
        }
        r
    }
}

#[cfg(test)]
mod tests;
