//! Scenes: the five built-ins with the paper's conditions, and TOML scene files
//! (schema in docs/model.md, "Scene files"). Unknown keys and out-of-range values are errors
//! that name the key.

use crate::fault::Fault;
use crate::reading::{OpenItems, Reading, DEFAULT_OPEN};
use noback::mechanism::{Mechanism, TABLE2};
use noback::sensors::{SensorConfig, DEFAULT_SENSORS};

/// The kind of a scene: what the drive does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneKind {
    /// Opening against the load, drive cut at `release_at_s` (paper §4.1).
    ReverseLoad,
    /// Closing along the load, drive cut at `release_at_s` (paper §4.2).
    ForwardLoad,
    /// Closing along the load with the drive on throughout (paper §4.3).
    ContinuousClosing,
    /// At rest under the load, drive off: the holding case.
    Hold,
    /// Opening against the load with the drive on throughout.
    Drive,
    /// The commanded functional test: from rest under the load, the drive creeps along the load
    /// with a torque limit that rises until the brake breaks away ([`TestProfile`]).
    FunctionalTest,
}

impl SceneKind {
    /// Parse a scene-file or CLI name.
    pub fn parse(s: &str) -> Option<SceneKind> {
        Some(match s {
            "reverse_load" => SceneKind::ReverseLoad,
            "forward_load" => SceneKind::ForwardLoad,
            "continuous_closing" => SceneKind::ContinuousClosing,
            "hold" => SceneKind::Hold,
            "drive" => SceneKind::Drive,
            "functional_test" => SceneKind::FunctionalTest,
            _ => return None,
        })
    }

    /// The name.
    pub fn name(self) -> &'static str {
        match self {
            SceneKind::ReverseLoad => "reverse_load",
            SceneKind::ForwardLoad => "forward_load",
            SceneKind::ContinuousClosing => "continuous_closing",
            SceneKind::Hold => "hold",
            SceneKind::Drive => "drive",
            SceneKind::FunctionalTest => "functional_test",
        }
    }

    /// The paper's five kinds (§4 and the holding and driving cases); the functional test apart.
    pub const ALL: [SceneKind; 5] = [
        SceneKind::ReverseLoad,
        SceneKind::ForwardLoad,
        SceneKind::ContinuousClosing,
        SceneKind::Hold,
        SceneKind::Drive,
    ];

    /// Direction of motion relative to the load: −1 against (opening), +1 along, 0 at rest.
    pub fn direction(self) -> f64 {
        match self {
            SceneKind::ReverseLoad | SceneKind::Drive => -1.0,
            SceneKind::ForwardLoad | SceneKind::ContinuousClosing | SceneKind::FunctionalTest => {
                1.0
            }
            SceneKind::Hold => 0.0,
        }
    }

    /// Whether the drive is on at t = 0.
    pub fn drive_at_start(self) -> bool {
        !matches!(self, SceneKind::Hold)
    }
}

/// The functional test's drive (scene kind `functional_test`): after `start_s` at rest under
/// the load, the drive opens against the load at `creep_speed_rad_s` for `open_s`, slows the door
/// to rest over the first third of `settle_s` and lets go for the rest of it (the brake takes
/// the load), then creeps along the load with its torque limit
/// rising at `torque_rate_nm_s` up to `torque_max_nm`; once the output has turned
/// `abort_angle_rad` along the load from where the opening ended, it holds the door at rest.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TestProfile {
    /// Rest before the ramp starts (s): the load settles on the brake.
    pub start_s: f64,
    /// Input-shaft speed of the opening and of the push (rad/s).
    pub creep_speed_rad_s: f64,
    /// Opening against the load (s).
    pub open_s: f64,
    /// Between the opening and the push (s): a third slowing to rest, the rest let go.
    pub settle_s: f64,
    /// Rise rate of the drive's torque limit (N·m/s at the input shaft).
    pub torque_rate_nm_s: f64,
    /// Largest torque limit (N·m at the input shaft).
    pub torque_max_nm: f64,
    /// Output travel from the opening's end at which the drive stops and holds (rad).
    pub abort_angle_rad: f64,
}

/// The default test: 0.2 s at rest, 0.5 s opening at 1 rad/s, 0.3 s to rest, a 1 rad/s push
/// at 20 N·m/s to 40 N·m (the motor's full scale is 40.5 N·m), stopped after 0.05 rad (2.9°)
/// of output travel.
pub const DEFAULT_TEST: TestProfile = TestProfile {
    start_s: 0.2,
    creep_speed_rad_s: 1.0,
    open_s: 0.5,
    settle_s: 0.3,
    torque_rate_nm_s: 20.0,
    torque_max_nm: 40.0,
    abort_angle_rad: 0.05,
};

/// Sensor-noise settings of the trace.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Noise {
    /// PRNG seed.
    pub seed: u64,
    /// Standard deviation of the current-measurement noise (A); 0 = noiseless.
    pub current_noise_a: f64,
    /// Current sensor's gain: measured = gain × true + offset (+ noise); 1 = ideal.
    pub current_gain: f64,
    /// Current sensor's offset (A); 0 = ideal.
    pub current_offset_a: f64,
}

/// A complete scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Name (built-in name or file stem).
    pub name: String,
    /// What the drive does.
    pub kind: SceneKind,
    /// Reading to run.
    pub reading: Reading,
    /// Load torque (N·m), positive.
    pub load_torque_nm: f64,
    /// Magnitude of the initial speed (rad/s); its sign comes from the kind.
    pub initial_speed_rad_s: f64,
    /// Drive cut time (s), if any.
    pub release_at_s: Option<f64>,
    /// Simulated time (s).
    pub duration_s: f64,
    /// Integrator tolerance.
    pub tolerance: f64,
    /// Table 2, possibly overridden.
    pub mechanism: Mechanism,
    /// Sensors, possibly overridden.
    pub sensors: SensorConfig,
    /// Trace noise.
    pub noise: Noise,
    /// Open items, possibly overridden.
    pub open: OpenItems,
    /// Faults.
    pub faults: Vec<Fault>,
    /// The functional test's drive (used by `functional_test` scenes only).
    pub test: TestProfile,
}

impl TestProfile {
    /// When the push along the load starts (s).
    pub fn push_s(&self) -> f64 {
        self.start_s + self.open_s + self.settle_s
    }
}

impl Scene {
    /// A built-in scene with the paper's conditions (§4): M = 20.3 N·m, 13.78 rad/s, drive cut
    /// at 0.2 s for the two braking cases, 3 s of continuous closing.
    pub fn builtin(kind: SceneKind, reading: Reading) -> Scene {
        let (release, duration) = match kind {
            SceneKind::ReverseLoad | SceneKind::ForwardLoad => (Some(0.2), 1.0),
            SceneKind::ContinuousClosing => (None, 3.0),
            SceneKind::Hold => (None, 0.5),
            SceneKind::Drive => (None, 0.5),
            SceneKind::FunctionalTest => (None, 3.5),
        };
        Scene {
            name: kind.name().to_string(),
            kind,
            reading,
            load_torque_nm: TABLE2.load_torque_nm,
            initial_speed_rad_s: match kind {
                SceneKind::Hold | SceneKind::FunctionalTest => 0.0,
                _ => 13.78,
            },
            release_at_s: release,
            duration_s: duration,
            tolerance: 1e-5,
            mechanism: TABLE2,
            sensors: DEFAULT_SENSORS,
            noise: Noise {
                seed: 1,
                current_noise_a: 0.0,
                current_gain: 1.0,
                current_offset_a: 0.0,
            },
            open: DEFAULT_OPEN,
            faults: Vec::new(),
            test: DEFAULT_TEST,
        }
    }

    /// Initial speed with the kind's sign (positive = load direction).
    pub fn signed_initial_speed_rad_s(&self) -> f64 {
        self.kind.direction() * self.initial_speed_rad_s
    }

    /// Parse a TOML scene file's text; `name` is used for the scene's name.
    pub fn from_toml(name: &str, text: &str) -> Result<Scene, SceneError> {
        crate::scene_file::parse(name, text)
    }

    /// Read a scene file.
    pub fn from_file(path: &std::path::Path) -> Result<Scene, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|e| SceneError {
            key: String::new(),
            message: format!("cannot read {}: {e}", path.display()),
        })?;
        let stem = path
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("scene")
            .to_string();
        Scene::from_toml(&stem, &text)
    }
}

/// A scene-file error; `key` names the offending key (`scene.duration_s`), empty for syntax
/// errors (whose message then carries the line and the key).
#[derive(Clone, Debug, PartialEq)]
pub struct SceneError {
    /// The key at fault.
    pub key: String,
    /// What is wrong.
    pub message: String,
}

impl std::fmt::Display for SceneError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.key.is_empty() {
            write!(f, "{}", self.message)
        } else {
            write!(f, "key `{}`: {}", self.key, self.message)
        }
    }
}

impl std::error::Error for SceneError {}
