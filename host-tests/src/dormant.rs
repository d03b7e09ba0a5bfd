//! The commanded functional test on the host (docs/functional-test.md): a scene's procedure, a
//! unit's acceptance, and the test at the end of a Monte Carlo run that finds dormant faults
//! (docs/monitor.md). There the unit is commissioned by its healthy acceptance test at the
//! procedure's load (and a spring-only unit by its uncoupled push too); in service the tests run
//! with the run's faults in place, at a load within ±5 % of the procedure's (the uncoupled push's
//! within ±0.05 N·m) and with fresh sensor noise, on the draw's own reading.

use crate::accuracy::{run_functional_test, scene_trace};
use crate::mc::Draw;
use noback::fx::Q16;
use noback::monitor::functional_test::{Procedure, TestConfig, TestResult};
use noback::monitor::{Config, DrivingPack};
use noback_twin::fault::{Fault, FaultKind};
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::sensing::Rng;
use noback_twin::trace::Trace;

/// How far the in-service test's load may lie from the procedure's (fraction).
pub const LOAD_TOLERANCE: f64 = 0.05;

/// How far the uncoupled push's set torque may lie from the procedure's (N·m): a weight on a
/// lever, not a door.
pub const UNCOUPLED_LOAD_TOLERANCE_NM: f64 = 0.05;

/// A `functional_test` scene at a load this small (N·m) is the uncoupled push.
pub const UNCOUPLED_MAX_LOAD_NM: f64 = 1.0;

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

/// The procedure a `functional_test` scene runs: uncoupled at a load within
/// [`UNCOUPLED_MAX_LOAD_NM`], else loaded; its load and its drive's ramp.
pub fn procedure_of(scene: &Scene) -> (Procedure, TestConfig) {
    let (procedure, base) = if scene.load_torque_nm.abs() <= UNCOUPLED_MAX_LOAD_NM {
        (Procedure::Uncoupled, TestConfig::UNCOUPLED)
    } else {
        (Procedure::Loaded, TestConfig::DEFAULT)
    };
    let test = TestConfig {
        load_nm: scene.load_torque_nm,
        torque_rate_nm_s: scene.test.torque_rate_nm_s,
        max_torque_nm: scene.test.torque_max_nm,
        open_s: scene.test.open_s,
        settle_s: scene.test.settle_s,
        ..base
    };
    (procedure, test)
}

/// The acceptance test on a healthy unit's `trace`: the procedure commissioned on its readings
/// if the unit passed against the design (the uncoupled push: at or above its floor), else
/// `None`.
pub fn accept(
    trace: &Trace,
    config: Config,
    (kind, procedure): (Procedure, &TestConfig),
    start_s: f64,
) -> Result<Option<TestConfig>, String> {
    let r = run_functional_test(trace, config, (kind, procedure), start_s)?;
    let accepted = match kind {
        Procedure::Loaded => r.result == TestResult::Pass,
        // Its floor only: the design reads the paper reading's clamp ~10 % low (a healthy unit
        // may lie above the band), and a dragging pack fails the loaded push.
        Procedure::Uncoupled => {
            r.result != TestResult::Aborted && r.margin >= Q16::from_num(procedure.min_margin)
        }
    };
    // Only the loaded push has a door to open against.
    let opening = (kind == Procedure::Loaded).then(|| r.opening_torque_nm.to_num());
    Ok(accepted.then(|| procedure.commissioned(r.breakaway_torque_nm.to_num(), opening)))
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
/// the run's faults in place; a unit commissioned as a spring-only pack is also pushed
/// uncoupled, and fails if either test fails.
pub fn functional_test_after(d: &Draw, config: Config) -> Result<Verdict, String> {
    let start = noback_twin::scene::DEFAULT_TEST.start_s;
    let seed = d.scene.noise.seed ^ 0x7e57;
    // Each procedure draws its noise and load from its own stream.
    let mut procedures = vec![(
        Procedure::Loaded,
        TestConfig::DEFAULT,
        LOAD_TOLERANCE,
        Rng::new(seed),
    )];
    if config.driving_pack == DrivingPack::SpringOnly {
        let tolerance = UNCOUPLED_LOAD_TOLERANCE_NM / TestConfig::UNCOUPLED.load_nm;
        let rng = Rng::new(seed ^ 0x0c0_1ed);
        procedures.push((Procedure::Uncoupled, TestConfig::UNCOUPLED, tolerance, rng));
    }
    // Acceptance: every procedure on the healthy unit.
    let mut unit = config;
    for (kind, procedure, _, rng) in &mut procedures {
        let mut accepted = test_scene(&d.scene, procedure.load_nm, &[]);
        accepted.noise.seed = rng.next_u64();
        let trace = scene_trace(&accepted)?;
        let Some(commissioned) = accept(&trace, unit, (*kind, procedure), start)? else {
            return Ok(Verdict::Rejected);
        };
        kind.set_test(&mut unit, commissioned);
    }
    // In service: each procedure at a load within its tolerance, with the run's faults.
    for (kind, procedure, tolerance, rng) in &mut procedures {
        let load = procedure.load_nm * (1.0 + *tolerance * (2.0 * rng.uniform() - 1.0));
        let mut in_service = test_scene(&d.scene, load, &d.scene.faults);
        in_service.noise.seed = rng.next_u64();
        let trace = scene_trace(&in_service)?;
        let test = kind
            .test(&unit)
            .ok_or("the uncoupled push was not accepted")?;
        if run_functional_test(&trace, unit, (*kind, &test), start)?.result != TestResult::Pass {
            return Ok(Verdict::Fail);
        }
    }
    Ok(Verdict::Pass)
}
