//! The monitor: the 10 kHz fixed-point reduced model that estimates pressing force and braking
//! torque and flags brake failure. The specification, with its reasons, is
//! docs/monitor-design.md; the decisions behind it, with their measurements, docs/decisions.md.
//!
//! ```
//! use noback::monitor::{Config, Inputs, Monitor};
//! let mut monitor = Monitor::new(Config::default()).unwrap();
//! // Drive off, no current (ADC mid-scale), both encoders at rest.
//! let mut estimate = monitor.step(&Inputs::new(2048, 0, 0, false));
//! for _ in 0..200 { estimate = monitor.step(&Inputs::new(2048, 0, 0, false)); }
//! assert_eq!(estimate.brake, noback::monitor::BrakeState::Locked);
//! assert!(!estimate.flags.any());
//! ```
//!
//! # Stages
//! [`Monitor::tick`] (the 10 kHz interrupt: sense, observe) and [`Monitor::background`] (the
//! rest, at a lower priority before the next tick) run them in data order; [`Monitor::step`] is
//! both. Each stage is a settings type, built once from [`Config`] by a builder beside it, and a
//! state type.
//!
//! | stage | module | in | out |
//! |---|---|---|---|
//! | schedule | `schedule` | tick counter | the tick's [`schedule::Slot`] |
//! | sense | `sense` | raw ADC code, counters, drive command | counts, deltas, plausibility |
//! | observe | `observe`, `observer` | current, output angle | drive torque, ω̂, `J_s·ω̇ − u`, settling |
//! | classify | `scene` | ω̂, drive torque, load | scene (one state machine), direction, overrunning torque |
//! | estimate | `load`, `aiding`, `pack`, `estimate` | all above | load (an aiding one at the lock), health, pressing force, braking torque, model torque |
//! | check | `checks` | all above | flags raised this tick |
//! | flag | here | raised flags | latched [`Flags`] in the [`Estimate`] |
//!
//! # Model
//! Only the output shaft's rotation is dynamic: `J_s·ω̇ = M + u − T`, with `u` the drive torque
//! from the motor current, `M` the load and `T` the pack torque (Table 1, `pack`). The axial
//! balance is quasi-static (the twin's physical reading). A three-state observer on the output
//! encoder tracks `J_s·ω̇ − u` with the model's `T̂` fed forward. The load is learned only while
//! driving, where the pack torque follows from the current alone, and held with the drive off;
//! a spring-only pack hides a load that aids the motion (it overruns on almost no drive torque).
//!
//! # Formats
//! | quantity | format | range | resolution |
//! |---|---|---|---|
//! | torque, force, speed, margin, health | [`Q16`] = `I16F16`, saturating | ±32 768 | 1.53e-5 |
//! | output angle (observer) | `u32` word, wrapping | one turn | 2π/2³² rad |
//! | constants | [`Scale<S>`]: `i32` mantissa · 2^-S | \|k\| < 2^(31−S) | ≥ 20 significant bits |
//! | friction energy | `U40F24`, saturating | 1.1e12 J | 6e-8 J |
//! | counters, timers | `i32`/`u32`, saturating; counter differences wrapping | — | 1 count / 1 tick |
//!
//! No floating point in [`Monitor::step`], and one division: at a lock after an aiding load
//! (`aiding`); every constant is derived in [`Monitor::new`].
//!
//! # Missed ticks
//! [`Inputs::ticks_elapsed`] is the number of ticks since the previous call (1 when on time).
//! Above 1 it latches `overrun`, advances the model by that many ticks and scales the
//! plausibility limits; above `max_catchup_ticks` the observer is re-seated on the measurement
//! and the estimate is untrusted until it settles again.

mod aiding;
mod checks;
mod config;
#[cfg(feature = "config-block")]
pub mod config_block;
mod convert;
mod estimate;
pub mod functional_test;
mod io;
mod load;
mod observe;
mod observer;
mod pack;
mod scale;
mod scene;
pub mod schedule;
mod sense;
mod settings;
#[cfg(feature = "snapshot")]
mod snapshot;
mod stop;

pub use crate::fx::mul_q16;
pub use config::{
    AidingBraking, Config, ConfigError, DrivingPack, LockTimes, ObserverGains, OverrunLine,
    Thresholds, DEFAULT_BRAKING_MODEL_HZ, DEFAULT_OBSERVER_BANDWIDTH_HZ, DEFAULT_TICK_HZ,
    MARGINAL_SELF_LOCKING, POWER_ON_SEED_TICKS,
};
pub use io::{BrakeState, Estimate, Flags, Inputs, Scene, SceneModel, ESTIMATE_WORDS};
pub use scale::{sat_i32, Scale, ScaleError};
#[cfg(feature = "snapshot")]
pub use snapshot::SnapshotError;

use crate::fx::Q16;
use aiding::Cut;
use checks::{BrakingTick, CheckInputs, Checks};
use estimate::{Energy, PackInputs};
use functional_test::{FunctionalTest, Procedure, TestReport};
use load::Load;
use observe::{Observe, Observed};
use pack::Dir;
use scene::{Classified, Classify};
use schedule::{Slot, WINDOW};
use sense::{Sense, Sensed};
pub use settings::Settings;

/// Largest capacity margin reported (the load stage's builder keeps margins below it).
pub const MARGIN_MAX: Q16 = Q16::from_bits(1000 << 16);

/// The monitor's state: one value per stage.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Debug)]
struct State {
    tick: u32,
    sense: Sense,
    observe: Observe,
    classify: Classify,
    /// The last classification and the observer at that tick (the estimate and the slow
    /// lane's checks read them).
    classified: Classified,
    observed: Observed,
    load: Load,
    /// The estimate of the last classification (the slow lane's snapshot).
    estimate: Estimate,
    energy: Energy,
    checks: Checks,
    flags: Flags,
    /// A flag that distrusts the model is latched (`Flags::distrusts`): no estimate is trusted.
    fault_latched: bool,
    /// The last background's slip checks saw the held brake give way (the next background's
    /// classification loses the hold).
    gave_way: bool,
    /// The last background changed the driving reading (bumpless for the observer).
    reading_switch: bool,
    /// The commanded functional test, from the crew's request.
    test: Option<FunctionalTest>,
    /// Where the drive was last cut, until the lock after it (`aiding`).
    cut: Cut,
}

/// The monitor: settings apart from state. One [`Monitor::step`] per tick.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Debug)]
pub struct Monitor {
    settings: Settings,
    state: State,
    /// The last tick's slow-lane work (sensing and the observer write it in place).
    job: Job,
    /// `job` waits for [`Monitor::background`].
    job_due: bool,
}

impl Monitor {
    /// Validates `config` and converts every constant of the step.
    ///
    /// ```
    /// use noback::monitor::{Config, ConfigError, Monitor};
    /// let mut config = Config::default();
    /// config.mechanism.output_inertia_kg_m2 = 0.0;
    /// assert_eq!(
    ///     Monitor::new(config).unwrap_err(),
    ///     ConfigError::OutOfRange { parameter: "mechanism.output_inertia_kg_m2" }
    /// );
    /// ```
    pub fn new(config: Config) -> Result<Monitor, ConfigError> {
        Ok(Monitor::with_settings(&Settings::new(&config)?))
    }

    /// A monitor at power-on on settings already converted (a configuration block's). Inlined,
    /// and reading them where they are, so a caller writing it into a static copies them once,
    /// there (the part's init stack).
    #[inline(always)]
    pub fn with_settings(settings: &Settings) -> Monitor {
        let mut load = Load::new();
        settings.refresh_load(&mut load);
        Monitor {
            settings: *settings,
            state: State {
                tick: 0,
                sense: Sense::new(),
                observe: Observe::new(),
                classify: Classify::new(),
                classified: Classified::NONE,
                observed: Observed::NONE,
                load,
                // A healthy pack's margins until the first classification.
                estimate: Estimate::with_margins(settings.load.margins(Q16::ONE)),
                energy: Energy::new(),
                checks: Checks::new(),
                flags: Flags::default(),
                fault_latched: false,
                gave_way: false,
                reading_switch: false,
                test: None,
                cut: Cut::NONE,
            },
            job: Job {
                x: Sensed::NONE,
                o: Observed::NONE,
            },
            job_due: false,
        }
    }

    /// The model this monitor runs in `scene` (the cheapest per scene,
    /// docs/results/cheapest-per-scene.md).
    pub fn scene_model(&self, scene: Scene) -> SceneModel {
        match scene {
            Scene::Holding | Scene::Driving => SceneModel::QuasiStatic,
            Scene::Overrunning => SceneModel::Equilibrium,
            Scene::FaultBraking => SceneModel::ReducedI16F16Euler {
                rate_hz: self.settings.checks.envelope.model_hz,
            },
        }
    }

    /// The latched flags.
    pub fn flags(&self) -> Flags {
        self.state.flags
    }

    /// Starts the commanded functional test of `procedure` with this tick's slow-lane work (the
    /// ground crew's request; the drive runs its ramp). A test already run is started afresh.
    /// `false` (nothing started) if the configuration has no such procedure.
    pub fn request_functional_test(&mut self, procedure: Procedure) -> bool {
        let configured = self.settings.functional_test.judge(procedure).is_some();
        if configured {
            self.state.test = Some(FunctionalTest::new(procedure));
        }
        configured
    }

    /// The functional test's report, once requested.
    pub fn functional_test(&self) -> Option<TestReport> {
        self.state.test.as_ref().map(FunctionalTest::report)
    }

    /// Clears the latched flags (a condition still present raises its flag again).
    pub fn reset_flags(&mut self) {
        self.state.flags = Flags::default();
        self.state.fault_latched = false;
        let counters = self.state.sense.counters();
        self.state.checks.reset(counters);
    }

    /// One tick on the host: [`Monitor::tick`] then [`Monitor::background`], as the target runs
    /// them. Never panics; every output is bounded by its format.
    pub fn step(&mut self, inputs: &Inputs) -> Estimate {
        let estimate = *self.tick(inputs);
        self.background();
        estimate
    }

    /// The 10 kHz interrupt's part: sense and observe, latch what they raised, report. The
    /// estimate is the slow lane's last, with this tick's count, trust and flags. A background
    /// that has not run since the last tick runs first: every tick's work runs once, in order.
    pub fn tick(&mut self, inputs: &Inputs) -> &Estimate {
        if self.job_due {
            self.background();
        }
        let (k, st, job) = (&self.settings, &mut self.state, &mut self.job);
        // Schedule: the tick count (modular on purpose).
        let n = u32::from(inputs.ticks_elapsed.max(1));
        st.tick = st.tick.wrapping_add(n);
        // Sense and observe.
        let carrying = st.classify.scene() == Scene::Driving;
        job.x = st.sense.read(&k.sense, inputs, n, carrying);
        let x = &job.x;
        job.o = st.observe.update(&k.observe, x);
        let o = &job.o;
        if x.first {
            // Until the first classification (the next background): the pack at rest as the
            // drive command leaves it, untrusted.
            let e = &mut st.estimate;
            (e.scene, e.brake, e.pressing_force_n) = if x.drive {
                (Scene::Driving, BrakeState::Released, k.pack.drive_force)
            } else {
                (
                    Scene::FaultBraking,
                    BrakeState::Slipping,
                    k.pack.spring_force,
                )
            };
        }
        if o.fault || n > 1 {
            st.latch(Flags {
                sensor_fault: o.fault,
                overrun: n > 1,
                ..Flags::default()
            });
        }
        self.job_due = true;
        st.report(o, k.commissioned)
    }

    /// The rest of the last [`Monitor::tick`]'s work, at a lower priority before the next tick:
    /// the tick's events, the per-tick checks (braking envelope, creep), the observer's
    /// feed-forward, then one slow-lane slot (classify, estimate, checks, window) and the
    /// command check. Its flags are latched here; the next tick reports them. Does nothing when
    /// called twice.
    pub fn background(&mut self) {
        if !core::mem::take(&mut self.job_due) {
            return;
        }
        let (k, st) = (&self.settings, &mut self.state);
        let Job { ref x, ref o } = self.job;
        let slot = Slot::of(st.tick);
        // The tick's events: a drive edge, an implausible step.
        st.classify.tick(x, o);
        st.checks.events(&k.checks, x, o);
        if x.drive_edge {
            st.cut = if !x.drive && k.aiding.is_some() {
                Cut::at(o)
            } else {
                Cut::NONE
            };
            if x.drive {
                st.load.drive_started();
            }
        } else if st.cut.armed() {
            let cut = &mut st.cut;
            cut.travel(x);
            if let Some(a) = k.aiding.as_ref().filter(|_| WINDOW.slot(st.tick) == 0) {
                cut.read_so_far(a);
            }
        }
        // Check: the braking envelope and creep, on this tick's motion.
        let dir = Dir::of(o.w, k.scene.stick_speed);
        let braking = st.classify.enveloped().then(|| BrakingTick {
            n: x.n,
            tick: st.tick,
            d_out: x.d_out,
            dir,
            load_dir: Dir::of(st.load.estimate.value(), k.scene.min_load),
            decel: st.load.cache.decel,
        });
        let (fast, gave_way) = st.checks.every_tick(&k.checks, x, o, braking);
        if gave_way || st.gave_way {
            st.classify.lose_hold();
        }
        // The pack torque the observer's model feeds forward into the next prediction.
        let model = estimate::model_torque(
            &k.pack,
            st.classify.locked(),
            st.classify.model_capacity(x.drive),
            dir,
            st.observe.disturbance().saturating_add(o.drive_torque),
            o.drive_torque,
            st.load.cache.capacity,
        );
        st.observe.set_model_torque(model, st.reading_switch);
        let mut reading_switch = false;
        match slot {
            _ if x.first => {
                reading_switch = st.classify(k, x, o);
                st.estimate(k);
            }
            Slot::Classify => {
                reading_switch = st.classify(k, x, o);
                // An aiding load a spring-only pack hid while driving, read at the lock.
                let locked = st.classified.just_locked.then(|| st.cut.take()).flatten();
                if aiding::read_at_lock(locked, k.aiding.as_ref(), &mut st.load) {
                    k.refresh_load(&mut st.load);
                }
            }
            Slot::Estimate => st.estimate(k),
            Slot::Sync if x.drive => st.classify.sync_window(&k.scene, x, o.w),
            _ => {}
        }
        let ci = CheckInputs {
            slot,
            drive_drag: k.pack.drive_drag,
            min_load: k.scene.min_load,
            settle_ticks: k.scene.engage_settle_ticks,
            input_speed: st.sense.input_speed(),
            stick_speed: k.scene.stick_speed,
            command_shortfall: x.command_code.filter(|_| slot == Slot::Checks).map(|code| {
                k.observe
                    .motoring_torque(k.checks.command.shortfall(x.current, code))
            }),
        };
        let (raised, gave_way) =
            st.checks
                .slow(&k.checks, x, o, &st.observed, &st.classified, &st.load, &ci);
        (st.gave_way, st.reading_switch) = (gave_way, reading_switch);
        st.latch(raised.union(fast));
        if let Some(test) = st.test.as_mut() {
            test.step(&k.functional_test, x, o.drive_torque, st.flags);
        }
    }
}

/// A tick's slow-lane work: what sensing and the observer handed on.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug)]
struct Job {
    x: Sensed,
    o: Observed,
}

impl State {
    /// The slow lane's [`Slot::Classify`]: the scene, then the load (learned while the drive
    /// runs steadily, cached once per window) or the pack health (slipping with the drive
    /// off). Returns whether the driving reading changed.
    fn classify(&mut self, k: &Settings, x: &Sensed, o: &Observed) -> bool {
        let step_counting = self.checks.step_counting(&k.checks);
        let c = self
            .classify
            .update(&k.scene, &k.pack, x, o, self.load.estimate, step_counting);
        (self.classified, self.observed) = (c, *o);
        if c.just_locked {
            self.checks.locked(x);
        }
        if c.lock_against && self.load.alt.is_some() {
            self.load.settle_against();
            k.refresh_load(&mut self.load);
        }
        if c.reading_switch {
            self.load.reading_changed();
        }
        let moving_ok = o.settled
            && o.sensors_ok
            && !c.dir.is_none()
            && c.scene != Scene::Holding
            && c.phase_settled
            && !c.pending;
        if moving_ok && x.drive && c.steady_for_learning {
            let pack = if c.engaged() {
                c.overrun_torque
            } else {
                k.pack.drive_drag
            };
            // The load a pack torque implies; on a guess, the driving reading's beside it.
            let implied = |t: Q16| o.net.saturating_add(c.dir.apply(t));
            let other = c.guessed.then(|| implied(k.pack.drive_drag));
            let unseen = k.pack.spring_only && c.dir.apply(implied(pack)) > Q16::ZERO;
            self.load.learn(&k.load, implied(pack), other, unseen, x.n);
        }
        let load = self.load.estimate.value();
        // The cache follows a changing load once per window while driving (never on a drive
        // edge); with the drive off the load is held, and so is the cache.
        if x.drive && !x.drive_edge && WINDOW.slot(self.tick) == 0 && self.load.cache_stale() {
            k.refresh_load(&mut self.load);
        }
        // The pack's torque is known against an opposing load only where both socket faces
        // clamp (`learn_opposed`), not on a guessed sign (`alt`) or an unseen load, nor where
        // the pack engages is unknown (an input that ran ahead, a spring-only pack's turn-back).
        let learnable = self.load.decided()
            && !self.load.unseen()
            && (k.load.learn_opposed || c.load_along)
            && self.classify.engagement_known(&k.scene);
        if moving_ok && !x.drive && learnable {
            let measured = load.saturating_sub(o.net);
            self.load.learn_health(&k.load, c.dir.apply(measured));
        }
        c.reading_switch
    }

    /// The slow lane's [`Slot::Estimate`]: the pack's force and torque at the last
    /// classification (its snapshot of the observer), the input speed, the friction energy.
    fn estimate(&mut self, k: &Settings) {
        let (c, o) = (&self.classified, &self.observed);
        self.sense.sample_input_speed(&k.sense);
        let load = self.load.estimate.value();
        let measured = load.saturating_sub(o.net);
        let locked = c.scene == Scene::Holding;
        let held = if locked {
            load.saturating_sub(self.sense.impact_torque(&k.sense))
        } else {
            load
        };
        let pe = estimate::pack(
            &k.pack,
            c,
            &PackInputs {
                locked,
                load,
                held_torque: held,
                measured,
                engaged_capacity: self.load.cache.capacity,
                drive_torque: o.drive_torque,
                braking_load: self.cut.so_far().filter(|_| self.load.unseen()),
            },
        );
        self.energy
            .update(&k.estimate, self.tick, pe.braking_torque, o.w, !locked);
        // A pack seen holding less than a load it met: no margin is claimed.
        let (margin, margin_low) = if self.flags.pack_weak() {
            (Q16::ZERO, Q16::ZERO)
        } else {
            k.load.margins(self.load.health)
        };
        self.estimate = Estimate {
            scene: c.scene,
            brake: if locked {
                BrakeState::Locked
            } else if c.engaged() {
                BrakeState::Slipping
            } else {
                BrakeState::Released
            },
            pressing_force_n: pe.force,
            braking_torque_nm: pe.braking_torque,
            measured_braking_torque_nm: measured,
            load_torque_nm: load,
            drive_torque_nm: o.drive_torque,
            output_speed_rad_s: o.w,
            input_speed_rad_s: self.sense.input_speed(),
            capacity_margin: margin,
            capacity_margin_low: margin_low,
            pack_health: self.load.health,
            friction_energy_j: self.energy.joules,
            ..self.estimate
        };
    }

    /// Latches `raised`: the one place flags are latched.
    fn latch(&mut self, raised: Flags) {
        if raised == Flags::default() {
            return; // the common case, cheaply
        }
        self.flags = self.flags.union(raised);
        self.fault_latched |= raised.distrusts();
        if raised.pack_weak() {
            self.estimate.drop_margins(); // from this tick on; the Estimate slot keeps them 0
        }
    }

    /// The estimate of this tick: the last classification's, with this tick's count, trust
    /// and flags, written in place.
    fn report(&mut self, o: &Observed, commissioned: bool) -> &Estimate {
        let e = &mut self.estimate;
        e.tick = self.tick;
        e.trusted = commissioned
            && self.load.trusted()
            && o.settled
            && o.sensors_ok
            && o.in_time
            && !self.fault_latched;
        e.flags = self.flags;
        e
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn holding_torque_carries_the_inertia_torque_of_an_impact() {
        extern crate std;
        let mut monitor = Monitor::new(Config::default()).unwrap_or_else(|_| unreachable!());
        let rad_per_count = core::f64::consts::TAU / 16_384.0;
        let count = |theta: f64| (theta / rad_per_count).floor().rem_euclid(16_384.0) as u32;
        // At rest, drive off: the brake holds (power-on: no load known, M̂ = 0).
        let mut e = monitor.step(&Inputs::new(2048, 0, count(0.0), false));
        for _ in 0..2000 {
            e = monitor.step(&Inputs::new(2048, 0, count(0.0), false));
        }
        assert_eq!(e.brake, BrakeState::Locked);
        assert_eq!(e.braking_torque_nm, e.load_torque_nm);
        // An impact: 2000 rad/s² for 5 ms inside the lost motion (0.025 rad).
        let alpha = 2000.0;
        let mut worst: f64 = 0.0;
        for k in 1..=50 {
            let t = f64::from(k) * 1e-4;
            e = monitor.step(&Inputs::new(2048, 0, count(0.5 * alpha * t * t), false));
            if k > 2 * 16 {
                assert_eq!(e.brake, BrakeState::Locked);
                let expected = e.load_torque_nm.to_num::<f64>() - 0.15 * alpha;
                worst = worst.max((e.braking_torque_nm.to_num::<f64>() - expected).abs());
            }
        }
        std::println!("impact torque error {worst:.1} N·m of {:.0}", 0.15 * alpha);
        // One count of the second difference is 22.5 N·m at m = 16; each of its three samples
        // is floored (error in [0, 1) count), so `θ₀ − 2θ_m + θ_2m` is within 2 counts of the
        // true parabola's: |error| < 45 N·m, against a 300 N·m impact.
        assert!(worst < 45.0, "{worst}");
    }
}
