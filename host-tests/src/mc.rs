//! Monte Carlo of the monitor's detection: many twin scenes, nominal and faulty, each replayed
//! through the shipped monitor on the host.
//!
//! Nominal draws: a braking, holding or driving scene (reverse_load, forward_load, hold, drive,
//! continuous_closing)
//! with load 5–30 N·m, speed 5–20 rad/s, every mechanism parameter of Table 2 scaled by an
//! independent factor in [0.9, 1.1], current noise 0–0.1 A, and the load in either direction
//! (a mirrored run: every sensor reading negated, which is the mechanism's symmetry).
//! Each draw's twin run starts [`PRE_ROLL_S`] before the monitor is powered on: the monitor
//! meets a running actuator, not the twin's start-up transient; times are from its power-on.
//! Fault draws: the same, plus one fault of the given kind with onset uniform in the scene and
//! severity in [0.5, 1]. A fault is detected when a flag that answers its kind
//! ([`crate::accuracy::expected_flag`]) rises within [`DETECTION_WINDOW_S`] of the moment it
//! manifests ([`crate::accuracy::manifest_time`]). A nominal run with any flag is a false
//! alarm. Runs are spread over the machine's cores.

use crate::accuracy::scene_trace;
use crate::dormant::Verdict;
use crate::family::Family;
use noback::fx::counter_delta;
use noback::mechanism::Mechanism;
use noback::monitor::Config;
use noback::sensors::SensorConfig;
use noback_twin::fault::{Fault, FaultKind};
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::sensing::Rng;
use noback_twin::trace::Trace;

/// A fault counts as detected if flagged within this long after it manifests (s).
pub const DETECTION_WINDOW_S: f64 = 0.050;

/// Every fault kind of the scene schema.
pub const FAULT_KINDS: [FaultKind; 8] = [
    FaultKind::FrictionLoss,
    FaultKind::SpringBroken,
    FaultKind::PackWear,
    FaultKind::RampJam,
    FaultKind::Drag,
    FaultKind::EncoderStuck,
    FaultKind::EncoderJump,
    FaultKind::CurrentOpen,
];

/// One drawn run.
#[derive(Clone, Debug)]
pub struct Draw {
    /// The scene (with its fault, if any).
    pub scene: Scene,
    /// Whether the sensor readings are mirrored (load in the negative direction).
    pub mirrored: bool,
}

/// What one run gave.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The fault kind, `None` for a nominal run.
    pub fault: Option<FaultKind>,
    /// Detection latency (s), if detected at all after manifesting.
    pub latency_s: Option<f64>,
    /// The same with the drive's current command in the monitor's inputs.
    pub latency_with_command_s: Option<f64>,
    /// Whether the fault manifested within the scene.
    pub manifested: bool,
    /// Where the fault fell, for reading the misses (`None` in a nominal run).
    pub context: Option<Context>,
    /// Flags raised before the fault's onset (all flags in a nominal run).
    pub false_flags: usize,
    /// The same with the drive's current command in the monitor's inputs.
    pub false_flags_with_command: usize,
    /// The twin failed to run this draw (reported, never silently dropped).
    pub error: Option<String>,
    /// A draw whose plant, run without its fault, has its input come apart from its output
    /// ([`not_driven`]): counted apart from the false alarms and its kind's rates.
    pub not_driven: bool,
    /// The functional test after the run ([`crate::dormant`]): every dormant fault run and a
    /// share of the nominal runs ([`Campaign::test_every`]).
    pub test: Option<Verdict>,
    /// `brake_degraded` rose after the fault's onset: the drive's own cycle found the fault.
    pub warned: bool,
    /// A commissioned campaign's acceptance refused the unit: it ran uncommissioned.
    pub refused: bool,
    /// A nominal braking run's accuracy (reverse_load, forward_load; not kept in part files).
    pub braking: Option<crate::accuracy::Braking>,
}

impl Outcome {
    /// A run of `fault` (nominal: `None`) that raised nothing and found nothing.
    pub fn quiet(fault: Option<FaultKind>) -> Outcome {
        Outcome {
            fault,
            latency_s: None,
            latency_with_command_s: None,
            manifested: false,
            context: None,
            false_flags: 0,
            false_flags_with_command: 0,
            error: None,
            not_driven: false,
            test: None,
            warned: false,
            refused: false,
            braking: None,
        }
    }

    /// A run the rates count: the twin ran it and its plant was driven.
    pub fn counts(&self) -> bool {
        self.error.is_none() && !self.not_driven
    }

    /// A run the twin ran whose plant came apart: counted apart from the rates.
    pub fn counted_apart(&self) -> bool {
        self.error.is_none() && self.not_driven
    }

    /// A nominal run the false-alarm rate counts.
    pub fn counts_as_nominal(&self) -> bool {
        self.fault.is_none() && self.counts()
    }

    /// The fault was flagged within [`DETECTION_WINDOW_S`] of manifesting.
    pub fn detected(&self) -> bool {
        self.latency_s.is_some_and(|l| l <= DETECTION_WINDOW_S)
    }

    /// [`Outcome::detected`] with the drive's current command in the monitor's inputs.
    pub fn detected_with_command(&self) -> bool {
        self.latency_with_command_s
            .is_some_and(|l| l <= DETECTION_WINDOW_S)
    }
}

/// Input travel (rad, output side) against a still output beyond which a draw's plant has come
/// apart: no ramp lets its input turn that far (the lost motion is 0.03–0.1 rad) — a jammed or
/// decoupled actuator, which a monitor should flag. Healthy draws stay below 0.14 rad (seed 1616).
pub const NOT_DRIVEN_RAD: f64 = 0.3;

/// The largest step (rad, output side) a healthy input makes in one 10 kHz sample, ×5: 0.002
/// rad (20 rad/s) on every healthy draw of seed 1616. A larger step is the paper reading
/// re-seating its input, not a shaft turning.
pub const INPUT_STEP_RAD: f64 = 0.01;

/// Whether the trace's motor encoder turns its input by [`NOT_DRIVEN_RAD`] while the output
/// encoder stands still, with the drive on or off, or steps it by [`INPUT_STEP_RAD`] in one
/// sample (the paper reading re-seats a runaway input on the output's far face after the cut).
pub fn not_driven(trace: &Trace, sensors: &SensorConfig) -> bool {
    let rad_per_count = sensors.input_rad_per_motor_count();
    let (mut travel, mut out, mut motor) = (0.0, None, None);
    for r in &trace.rows {
        let step = motor.map_or(0, |m| {
            counter_delta(m, r.motor_count, sensors.motor_counter_bits)
        });
        let step_rad = f64::from(step.unsigned_abs()) * rad_per_count;
        if out != Some(r.output_count) {
            (travel, out) = (0.0, Some(r.output_count));
        } else {
            travel += step_rad;
        }
        if travel > NOT_DRIVEN_RAD || step_rad > INPUT_STEP_RAD {
            return true;
        }
        motor = Some(r.motor_count);
    }
    false
}

/// When, after power-on into a running drive, the drive checks have a history to judge a
/// step against (s): the observer's seeding ([`noback::monitor::POWER_ON_SEED_TICKS`]) and
/// the settling after it (`thresholds.power_on_settle_s`), when the driving reading is first
/// decided, plus the phase settling that follows a change of scene
/// (`thresholds.engage_settle_s`); the history is seeded then.
pub fn checks_armed_s(config: &Config) -> f64 {
    let t = &config.thresholds;
    f64::from(noback::monitor::POWER_ON_SEED_TICKS) / config.tick_hz
        + t.power_on_settle_s
        + t.engage_settle_s
}

/// Where a fault fell in its run: the classes the misses are reported by (docs/monitor.md).
/// The first that applies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Context {
    /// The onset fell before the drive checks were armed after power-on ([`checks_armed_s`]):
    /// no healthy reference yet — a drag or a current gain already there is read as part of the
    /// load, which only the current measures.
    Settling,
    /// The drive was running at the onset and was cut before the drive checks' phase settling
    /// (`thresholds.engage_settle_s`) had passed: the fault met less drive than any drive check
    /// needs.
    ShortDrive,
    /// Continuous closing: the drive on throughout, overrunning, with the pack's engagement
    /// chatter.
    ContinuousClosing,
    /// None of the above.
    Other,
}

impl Context {
    /// Every context, in the order of the report.
    pub const ALL: [Context; 4] = [
        Context::Settling,
        Context::ShortDrive,
        Context::ContinuousClosing,
        Context::Other,
    ];

    /// The context of a fault with onset `at_s` in `trace` of a `kind` scene, for a monitor
    /// configured with `config`.
    pub fn of(at_s: f64, trace: &Trace, kind: SceneKind, config: &Config) -> Context {
        let t = &config.thresholds;
        let start = trace.rows.first().map_or(0.0, |r| r.t_s);
        let mut after = trace.rows.iter().skip_while(|r| r.t_s < at_s);
        let driving_at_onset = after.clone().next().is_some_and(|r| r.drive_on);
        let cut = after.find(|r| !r.drive_on).map(|r| r.t_s);
        if at_s - start < checks_armed_s(config) {
            Context::Settling
        } else if driving_at_onset && cut.is_some_and(|c| c - at_s < t.engage_settle_s) {
            Context::ShortDrive
        } else if kind == SceneKind::ContinuousClosing {
            Context::ContinuousClosing
        } else {
            Context::Other
        }
    }
}

fn scale_all(m: &mut Mechanism, rng: &mut Rng) {
    let mut s = |x: &mut f64| *x *= 0.9 + 0.2 * rng.uniform();
    s(&mut m.output_shaft_mass_kg);
    s(&mut m.input_shaft_mass_kg);
    s(&mut m.ball_mass_kg);
    s(&mut m.connecting_shaft_mass_kg);
    s(&mut m.output_inertia_kg_m2);
    s(&mut m.input_inertia_kg_m2);
    s(&mut m.connecting_inertia_kg_m2);
    s(&mut m.ball_inertia_kg_m2);
    s(&mut m.spring_stiffness_n_m);
    s(&mut m.contact_stiffness);
    s(&mut m.spring_preload_m);
    s(&mut m.socket_radius_m);
    s(&mut m.output_friction_radius_m);
    s(&mut m.connecting_friction_radius_m);
    s(&mut m.input_friction_radius_m);
    s(&mut m.pack_inner_radius_m);
    s(&mut m.pack_outer_radius_m);
    s(&mut m.socket_clearance_m);
    s(&mut m.pack_clearance_m);
    s(&mut m.socket_chamfer_rad);
    s(&mut m.mu_static);
    s(&mut m.mu_dynamic);
    s(&mut m.restitution);
}

/// The name of the plant family [`draw`] draws from (recorded in every part of a sharded
/// campaign): the physical reading, Table 2 ± 10 %, the five scene kinds below.
pub const PLANT_FAMILY: &str = "physical-default";

/// The scene kinds of the nominal and fault draws.
pub const SCENE_KINDS: [SceneKind; 5] = [
    SceneKind::ReverseLoad,
    SceneKind::ForwardLoad,
    SceneKind::Hold,
    SceneKind::Drive,
    SceneKind::ContinuousClosing,
];

/// The random stream of one run: a generator whose state is the SplitMix hash of (`seed`,
/// stream, `index`), the stream being 0 for a nominal run and 1 + the kind's place in
/// [`FAULT_KINDS`] for a fault run. Each run's draws depend on that triple alone, so a
/// campaign cut into shards draws exactly what it draws whole.
pub fn run_rng(seed: u64, index: u64, fault: Option<FaultKind>) -> Rng {
    let hash = |x: u64| Rng::new(x).next_u64();
    Rng::new(hash(hash(hash(seed) ^ stream(fault)) ^ index))
}

fn stream(fault: Option<FaultKind>) -> u64 {
    fault.map_or(0, |k| {
        1 + FAULT_KINDS.iter().position(|f| *f == k).unwrap_or(0) as u64
    })
}

/// Draws run `index` of a campaign: deterministic in (`seed`, `index`, `fault`).
pub fn draw(seed: u64, index: u64, fault: Option<FaultKind>) -> Draw {
    draw_in(Family::PhysicalDefault, seed, index, fault)
}

/// [`draw`] from a plant family: the default family's draws, then the plant's form
/// ([`crate::family::draw_form`]) from the same stream.
pub fn draw_in(family: Family, seed: u64, index: u64, fault: Option<FaultKind>) -> Draw {
    let mut rng = run_rng(seed, index, fault);
    let mut d = draw_from(&SCENE_KINDS, &mut rng, index, fault);
    if family == Family::Plant {
        crate::family::draw_form(&mut d.scene, &mut rng);
    }
    d
}

/// A draw of the campaigns before issue 21, whose generator started at
/// `seed ^ index·φ ^ stream << 56` (nearby runs' streams overlapped), with the scene kind drawn
/// among `kinds` (before continuous closing joined: `&SCENE_KINDS[..4]`). The tests and
/// measurements that name a run of those campaigns reproduce it with this.
pub fn draw_among(kinds: &[SceneKind], seed: u64, index: u64, fault: Option<FaultKind>) -> Draw {
    let mut rng =
        Rng::new(seed ^ index.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (stream(fault) << 56));
    draw_from(kinds, &mut rng, index, fault)
}

/// [`draw_among`] the five scene kinds: run `index` of a campaign before issue 21.
pub fn draw_legacy(seed: u64, index: u64, fault: Option<FaultKind>) -> Draw {
    draw_among(&SCENE_KINDS, seed, index, fault)
}

fn draw_from(kinds: &[SceneKind], rng: &mut Rng, index: u64, fault: Option<FaultKind>) -> Draw {
    let kind = kinds
        .get((rng.next_u64() % kinds.len().max(1) as u64) as usize)
        .copied()
        .unwrap_or(SceneKind::Hold);
    let mut scene = Scene::builtin(kind, Reading::Physical);
    scene.name = format!("mc-{index}");
    scene.load_torque_nm = 5.0 + 25.0 * rng.uniform();
    if kind != SceneKind::Hold {
        scene.initial_speed_rad_s = 5.0 + 15.0 * rng.uniform();
    }
    if let Some(release) = scene.release_at_s.as_mut() {
        *release = 0.1 + 0.2 * rng.uniform();
    }
    scale_all(&mut scene.mechanism, rng);
    scene.noise.seed = rng.next_u64();
    scene.noise.current_noise_a = 0.1 * rng.uniform();
    if let Some(kind) = fault {
        scene.faults.push(Fault {
            kind,
            at_s: 0.05 + (scene.duration_s - 0.3).max(0.05) * rng.uniform(),
            severity: 0.5 + 0.5 * rng.uniform(),
        });
    }
    Draw {
        scene,
        mirrored: rng.uniform() < 0.5,
    }
}

/// The same trace with the load in the other direction: every reading negated.
pub fn mirror(trace: &mut Trace, adc_bits: u8, motor_bits: u8, output_bits: u8) {
    let adc_full = (1_u32 << adc_bits) - 1;
    let motor_mask = (1_u64 << motor_bits) - 1;
    let out_mask = (1_u64 << output_bits) - 1;
    // Offset binary about mid-scale: code c ↦ 2^bits − c, clamped to the converter.
    let negate = |c: u16| (adc_full + 1).saturating_sub(u32::from(c)).min(adc_full) as u16;
    for r in &mut trace.rows {
        r.current_code = negate(r.current_code);
        r.current_command_code = r.current_command_code.map(negate);
        r.motor_count = ((motor_mask + 1 - u64::from(r.motor_count)) & motor_mask) as u32;
        r.output_count = ((out_mask + 1 - u64::from(r.output_count)) & out_mask) as u32;
    }
}

/// How long the twin runs each draw's scene before the monitor is powered on (s): the twin's
/// scenes start mid-drive from a state that is not its drive's equilibrium (the proportional
/// speed servo starts with no speed error, so the drive torque swings from 0 to past its steady
/// value and back over the first ≈ 0.1 s), which no monitor powered on into a running
/// actuator meets. The scene's cut and fault onsets are shifted by it; the trace the monitor
/// sees starts after it, with its time origin at the monitor's power-on.
pub const PRE_ROLL_S: f64 = 0.2;

/// The sensor trace of one draw: the twin's run of its scene after [`PRE_ROLL_S`], mirrored
/// when the draw says so.
pub fn draw_trace(d: &Draw) -> Result<Trace, String> {
    draw_trace_after(d, PRE_ROLL_S)
}

/// The healthy braking draws (reverse_load, forward_load) among the first `runs` of the plant
/// family at `seed` that drive, each with its index and [`draw_trace`].
pub fn braking_draws(
    seed: u64,
    runs: u64,
) -> impl Iterator<Item = Result<(u64, Draw, Trace), String>> {
    (0..runs).filter_map(move |i| {
        let d = draw_in(Family::Plant, seed, i, None);
        if !matches!(
            d.scene.kind,
            SceneKind::ReverseLoad | SceneKind::ForwardLoad
        ) {
            return None;
        }
        match draw_trace(&d) {
            Ok(t) if not_driven(&t, &d.scene.sensors) => None,
            trace => Some(trace.map(|t| (i, d, t))),
        }
    })
}

/// The scene the twin runs for a draw whose monitor is powered on `pre_roll_s` into the run:
/// longer by the pre-roll, its cut and fault onsets shifted by it (twin time).
pub fn scene_after(d: &Draw, pre_roll_s: f64) -> Scene {
    let mut scene = d.scene.clone();
    scene.duration_s += pre_roll_s;
    if let Some(release) = scene.release_at_s.as_mut() {
        *release += pre_roll_s;
    }
    for f in &mut scene.faults {
        f.at_s += pre_roll_s;
    }
    scene
}

/// [`draw_trace`] with the monitor powered on `pre_roll_s` into the twin's run (0: at the
/// scene's start, in the twin's own start-up transient, as the campaigns before the pre-roll
/// did).
pub fn draw_trace_after(d: &Draw, pre_roll_s: f64) -> Result<Trace, String> {
    let mut trace = scene_trace(&scene_after(d, pre_roll_s))?;
    let skip = (pre_roll_s * trace.sample_rate_hz).round() as usize;
    trace.rows.drain(..skip.min(trace.rows.len()));
    for r in &mut trace.rows {
        r.t_s -= pre_roll_s;
    }
    d.mount(&mut trace);
    Ok(trace)
}

impl Draw {
    /// A trace of this draw's unit as its sensors are mounted: every reading negated
    /// ([`mirror`]) when the draw is mirrored.
    pub fn mount(&self, trace: &mut Trace) {
        let s = &self.scene.sensors;
        if self.mirrored {
            mirror(
                trace,
                s.current_adc_bits,
                s.motor_counter_bits,
                s.output_encoder_bits,
            );
        }
    }
}

mod run;
pub use run::{
    behaviour_digest, commission_draw, evaluate, run_all, Campaign, BEHAVIOUR_RUNS, TEST_EVERY,
};
