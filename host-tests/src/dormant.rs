//! The commanded functional test on the host (docs/functional-test.md): a scene's procedure, a
//! unit's acceptance, and the test at the end of a Monte Carlo run that finds dormant faults
//! (docs/monitor.md). There the unit is commissioned by its healthy acceptance test at the
//! procedure's load; in service the test runs with the run's faults in place, at a load within
//! ±5 % of the procedure's and with fresh sensor noise, on the draw's own reading.

use crate::accuracy::{run_functional_test, scene_trace};
use crate::mc::Draw;
use noback::monitor::functional_test::{TestConfig, TestResult};
use noback::monitor::Config;
use noback_twin::fault::{Fault, FaultKind};
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::sensing::Rng;
use noback_twin::trace::Trace;

/// How far the in-service test's load may lie from the procedure's (fraction).
pub const LOAD_TOLERANCE: f64 = 0.05;

/// A `functional_test` scene of `base`'s plant (mechanism, sensors, noise, open items) at
/// `load_nm`, with `faults` in place from the start.
pub fn test_scene(base: &Scene, load_nm: f64, faults: &[Fault]) -> Scene {
    let mut s = Scene::builtin(SceneKind::FunctionalTest, base.reading);
    s.name = format!("{}-test", base.name);
    s.load_torque_nm = load_nm;
    s.mechanism = base.mechanism;
    s.sensors = base.sensors;
    s.noise = base.noise;
    s.open = base.open;
    s.faults = faults.iter().map(|f| Fault { at_s: 0.0, ..*f }).collect();
    s
}

/// The procedure a `functional_test` scene runs: its load and its drive's ramp.
pub fn procedure_of(scene: &Scene) -> TestConfig {
    TestConfig {
        load_nm: scene.load_torque_nm,
        torque_rate_nm_s: scene.test.torque_rate_nm_s,
        max_torque_nm: scene.test.torque_max_nm,
        open_s: scene.test.open_s,
        settle_s: scene.test.settle_s,
        ..TestConfig::DEFAULT
    }
}

/// The acceptance test: `procedure` run on a healthy unit's `trace` (requested at `start_s`)
/// against the design; if it passes, the procedure commissioned on its breakaway and opening
/// torques, else `None`.
pub fn accept(
    trace: &Trace,
    config: Config,
    procedure: &TestConfig,
    start_s: f64,
) -> Result<Option<TestConfig>, String> {
    let r = run_functional_test(trace, config, procedure, start_s)?;
    Ok((r.result == TestResult::Pass).then(|| {
        procedure.commissioned(r.breakaway_torque_nm.to_num(), r.opening_torque_nm.to_num())
    }))
}

/// A fault of `kind` and `severity` present from the start.
pub fn from_start(kind: FaultKind, severity: f64) -> Fault {
    Fault {
        kind,
        at_s: 0.0,
        severity,
    }
}

/// What the functional test after a run said.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// The healthy unit failed its acceptance test against the design (rejected in production).
    Rejected,
    /// Passed in service.
    Pass,
    /// Failed (or aborted) in service: the fault was found.
    Fail,
}

/// The functional test of draw `d`'s unit, commissioned on its healthy acceptance test, with
/// the run's faults in place.
pub fn functional_test_after(d: &Draw, config: Config) -> Result<Verdict, String> {
    let procedure = TestConfig::DEFAULT;
    let start = noback_twin::scene::DEFAULT_TEST.start_s;
    let mut rng = Rng::new(d.scene.noise.seed ^ 0x7e57);
    let mut accepted = test_scene(&d.scene, procedure.load_nm, &[]);
    accepted.noise.seed = rng.next_u64();
    let Some(commissioned) = accept(&scene_trace(&accepted)?, config, &procedure, start)? else {
        return Ok(Verdict::Rejected);
    };
    let load = procedure.load_nm * (1.0 + LOAD_TOLERANCE * (2.0 * rng.uniform() - 1.0));
    let mut in_service = test_scene(&d.scene, load, &d.scene.faults);
    in_service.noise.seed = rng.next_u64();
    let trace = scene_trace(&in_service)?;
    let r = run_functional_test(&trace, config, &commissioned, start)?;
    Ok(if r.result == TestResult::Pass {
        Verdict::Pass
    } else {
        Verdict::Fail
    })
}
