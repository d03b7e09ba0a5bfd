//! The models of the two readings behind one interface: each is an [`OdeSystem`] with discrete
//! state (friction mode, contact approach speeds), a drive command the scene switches, and a
//! [`Sample`] of the quantities the traces and metrics need.

pub mod paper;
pub mod physical;

use crate::fault::PhysicsFaults;
use crate::reading::OpenItems;
use crate::solver::OdeSystem;
use noback::mechanism::Mechanism;
use noback::sensors::SensorConfig;

/// What the drive does: on or off, and the speed it holds the input shaft at (rad/s, positive
/// along the load).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drive {
    /// Drive commanded on.
    pub on: bool,
    /// Input-shaft speed reference (rad/s).
    pub speed_ref_rad_s: f64,
    /// Torque limit below the motor's (N·m), as the functional test ramps it; `None` = the
    /// motor's full-scale limit.
    pub torque_limit_nm: Option<f64>,
}

/// Everything a model needs to be built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelConfig {
    /// Table 2 (possibly overridden by a scene).
    pub mechanism: Mechanism,
    /// Motor and sensors (for the drive torque limit).
    pub sensors: SensorConfig,
    /// Open-item choices.
    pub open: OpenItems,
    /// Load torque on the output shaft (N·m), positive direction = load direction.
    pub load_torque_nm: f64,
    /// Initial speed of the input and connecting shafts (rad/s).
    pub initial_speed_rad_s: f64,
    /// Initial speed of the output shaft (rad/s).
    pub output_initial_speed_rad_s: f64,
    /// Initial drive command.
    pub drive: Drive,
}

/// The load's direction on the output (±1; no load counts as positive): where its face rests
/// and which way the functional test's push and abort count.
pub fn load_sign(load_torque_nm: f64) -> f64 {
    if load_torque_nm >= 0.0 {
        1.0
    } else {
        -1.0
    }
}

impl ModelConfig {
    /// Largest input-shaft torque the motor can give: its current limit through the reducer.
    pub fn drive_torque_limit_nm(&self) -> f64 {
        self.sensors
            .input_torque_nm(self.open.drive_current_limit_a)
            .abs()
    }
}

/// Quantities of one instant, in the twin's sign convention (positive = load direction).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample {
    /// Time (s).
    pub t_s: f64,
    /// Output-shaft angle (rad).
    pub output_angle_rad: f64,
    /// Output-shaft speed (rad/s).
    pub output_speed_rad_s: f64,
    /// Input-shaft angle (rad).
    pub input_angle_rad: f64,
    /// Input-shaft speed (rad/s).
    pub input_speed_rad_s: f64,
    /// Torque the motor applies at the input shaft (N·m).
    pub drive_torque_nm: f64,
    /// Drive commanded on.
    pub drive_on: bool,
    /// Pressing force on the friction pack (N).
    pub pressing_force_n: f64,
    /// Magnitude of the pack's braking torque (N·m).
    pub braking_torque_nm: f64,
    /// 0 released, 1 slipping, 2 locked.
    pub brake_state: u8,
    /// Contact force of one output-end ball on the load face (N).
    pub contact_force_n: f64,
    /// Contact force of one input-end ball (N).
    pub input_contact_force_n: f64,
    /// Axial position of the output-end balls (m).
    pub ball_axial_m: f64,
    /// Axial position of the big connecting shaft (m).
    pub shaft_axial_m: f64,
}

/// A model of one reading.
pub trait TwinModel: OdeSystem {
    /// Initial state vector.
    fn initial_state(&self) -> Vec<f64>;
    /// Switch the drive (at a segment boundary); may adjust the state.
    fn set_drive(&mut self, drive: Drive, y: &mut [f64]);
    /// Apply the physics faults in force (at a segment boundary).
    fn set_faults(&mut self, faults: PhysicsFaults, y: &mut [f64]);
    /// The derived quantities at `(t, y)`.
    fn sample(&self, t: f64, y: &[f64]) -> Sample;
    /// Total mechanical energy (J): kinetic + contact + spring − work potential of the load.
    fn energy_j(&self, y: &[f64]) -> f64;
}

/// `tanh(v/scale)`: the smoothed sign used by small Coulomb frictions (bearings, axial guides).
pub fn smooth_sign(v: f64, scale: f64) -> f64 {
    (v / scale.max(1e-300)).tanh()
}

/// Value of `y[i]`, 0 if out of range.
pub(crate) fn at(y: &[f64], i: usize) -> f64 {
    y.get(i).copied().unwrap_or(0.0)
}

/// Set `y[i]` if in range.
pub(crate) fn put(y: &mut [f64], i: usize, v: f64) {
    if let Some(s) = y.get_mut(i) {
        *s = v;
    }
}
