//! Running a scene: build the reading's model, integrate segment by segment (drive cut and
//! physics faults switch at segment boundaries), and sample every quantity at the trace rate.

use crate::fault::PhysicsFaults;
use crate::model::paper::Paper;
use crate::model::physical::Physical;
use crate::model::{Drive, ModelConfig, Sample, TwinModel};
use crate::reading::Reading;
use crate::scene::{Scene, SceneKind};
use crate::solver::{Integrator, Sampler, SolverError, SolverOptions, SolverStats};

/// Trace and sample rate (Hz): the monitor's 10 kHz.
pub const SAMPLE_RATE_HZ: f64 = 10_000.0;

/// The result of one run.
#[derive(Clone, Debug)]
pub struct Run {
    /// Samples at [`SAMPLE_RATE_HZ`] from t = 0.
    pub samples: Vec<Sample>,
    /// Integrator counters.
    pub stats: SolverStats,
    /// Wall-clock time of the integration (s).
    pub wall_s: f64,
}

/// The model configuration a scene implies.
pub fn model_config(scene: &Scene) -> ModelConfig {
    let speed = scene.signed_initial_speed_rad_s();
    ModelConfig {
        mechanism: scene.mechanism,
        sensors: scene.sensors,
        open: scene.open,
        load_torque_nm: scene.load_torque_nm,
        initial_speed_rad_s: speed,
        output_initial_speed_rad_s: if scene.kind == SceneKind::ContinuousClosing {
            0.0
        } else {
            speed
        },
        drive: Drive {
            on: scene.kind.drive_at_start(),
            ..scene_drive(scene, 0.0, true)
        },
    }
}

/// The drive a scene commands at time `t_s` (`on` = not yet cut): the scene's speed, and for
/// the functional test its opening, its rest and its push under the torque limit's ramp.
fn scene_drive(scene: &Scene, t_s: f64, on: bool) -> Drive {
    if scene.kind == SceneKind::FunctionalTest {
        let p = &scene.test;
        let t = t_s - p.start_s;
        // Opening, then slowing to rest over the settle's first third: a speed reference.
        let speed_ref = if t < p.open_s {
            Some(-p.creep_speed_rad_s)
        } else if t < p.open_s + p.settle_s / 3.0 {
            Some(-p.creep_speed_rad_s * (1.0 - (t - p.open_s) * 3.0 / p.settle_s))
        } else {
            None
        };
        return match (on, t >= 0.0, speed_ref) {
            // Stopped at the abort angle: the drive holds the door at rest, at full torque.
            (false, _, _) => Drive {
                on: true,
                speed_ref_rad_s: 0.0,
                torque_limit_nm: None,
            },
            (true, true, Some(w)) => Drive {
                on: true,
                speed_ref_rad_s: w,
                torque_limit_nm: None,
            },
            // At rest (no torque until the push starts), then the push's rising limit.
            _ => Drive {
                on: true,
                speed_ref_rad_s: p.creep_speed_rad_s,
                torque_limit_nm: Some(
                    (p.torque_rate_nm_s * (t_s - p.push_s())).clamp(0.0, p.torque_max_nm),
                ),
            },
        };
    }
    Drive {
        on: on && scene.kind.drive_at_start() && scene.release_at_s.is_none_or(|r| t_s < r),
        speed_ref_rad_s: scene.signed_initial_speed_rad_s(),
        torque_limit_nm: None,
    }
}

/// The functional test's torque ramp is stepped every millisecond, when the output's travel is
/// also checked against the abort angle (the firmware checks it every tick).
const TEST_SEGMENT_S: f64 = 1e-3;

/// Run a scene under its reading.
pub fn run(scene: &Scene) -> Result<Run, SolverError> {
    let cfg = model_config(scene);
    match scene.reading {
        Reading::Paper => run_model(scene, Paper::new(cfg)),
        Reading::Physical => run_model(scene, Physical::new(cfg)),
    }
}

/// Solver options for a scene.
pub fn solver_options(scene: &Scene) -> SolverOptions {
    SolverOptions {
        tolerance: scene.tolerance,
        ..SolverOptions::default()
    }
}

/// Run a scene under its reading with a given integrator (another method or settings).
pub fn run_with(scene: &Scene, integ: Integrator) -> Result<Run, SolverError> {
    let cfg = model_config(scene);
    match scene.reading {
        Reading::Paper => run_model_with(scene, Paper::new(cfg), integ),
        Reading::Physical => run_model_with(scene, Physical::new(cfg), integ),
    }
}

/// Run a scene with a given model.
pub fn run_model<M: TwinModel>(scene: &Scene, model: M) -> Result<Run, SolverError> {
    run_model_with(scene, model, Integrator::new(solver_options(scene)))
}

/// Run a scene with a given model and integrator.
pub fn run_model_with<M: TwinModel>(
    scene: &Scene,
    mut model: M,
    mut integ: Integrator,
) -> Result<Run, SolverError> {
    let start = std::time::Instant::now();
    let mut y = model.initial_state();
    let mut breaks: Vec<f64> = scene
        .faults
        .iter()
        .filter(|f| !f.kind.is_sensor())
        .map(|f| f.at_s)
        .collect();
    if let Some(r) = scene.release_at_s {
        breaks.push(r);
    }
    if scene.kind == SceneKind::FunctionalTest {
        let n = (scene.duration_s / TEST_SEGMENT_S).ceil() as usize;
        breaks.extend((1..n).map(|i| i as f64 * TEST_SEGMENT_S));
    }
    breaks.retain(|&b| b > 0.0 && b < scene.duration_s);
    breaks.push(scene.duration_s);
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    let dt = 1.0 / SAMPLE_RATE_HZ;
    let mut samples = Vec::with_capacity((scene.duration_s * SAMPLE_RATE_HZ) as usize + 2);
    let faults0 = PhysicsFaults::at(&scene.faults, 0.0);
    model.set_faults(faults0, &mut y);
    samples.push(model.sample(0.0, &y));
    let mut smp = Sampler::new(dt, dt);
    let mut t = 0.0;
    let mut rest_angle = None;
    let mut aborted = false;
    for &b in &breaks {
        integ.integrate(
            &mut model,
            (t, b),
            &mut y,
            &mut smp,
            &mut |m: &M, ts, ys| {
                samples.push(m.sample(ts, ys));
            },
        )?;
        t = b;
        if scene.kind == SceneKind::FunctionalTest && t >= scene.test.start_s + scene.test.open_s {
            let angle = samples.last().map_or(0.0, |s| s.output_angle_rad);
            let rest = *rest_angle.get_or_insert(angle);
            // Along the load only: the settle's own travel runs against it.
            let along = (angle - rest) * crate::model::load_sign(scene.load_torque_nm);
            aborted |= along >= scene.test.abort_angle_rad;
        }
        model.set_drive(scene_drive(scene, t, !aborted), &mut y);
        model.set_faults(PhysicsFaults::at(&scene.faults, t), &mut y);
    }
    Ok(Run {
        samples,
        stats: integ.stats,
        wall_s: start.elapsed().as_secs_f64(),
    })
}
