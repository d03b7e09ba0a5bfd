//! The two readings of the paper and the open-item choices both share.
//!
//! `Paper` reproduces the paper's Simulink platform as MODEL.md's quasi-static reading
//! describes; `Physical` is our coherent contact mechanics and the monitor's ground truth. The
//! differences are listed side by side in docs/model.md ("Two readings").

/// Which reading of the paper the twin runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Reading {
    /// The paper's platform: quasi-static pressing force from the load torque, Table 1 torque
    /// with μ_s on the output inertia, input as an ideal speed reference.
    Paper,
    /// Full contact mechanics of every body (default).
    #[default]
    Physical,
}

impl Reading {
    /// Parse `paper` or `physical`.
    pub fn parse(s: &str) -> Option<Reading> {
        match s {
            "paper" => Some(Reading::Paper),
            "physical" => Some(Reading::Physical),
            _ => None,
        }
    }

    /// The name used on the command line and in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Reading::Paper => "paper",
            Reading::Physical => "physical",
        }
    }
}

/// Choices on what the paper leaves open (never a Table 2 value). Defaults and reasons are in
/// docs/model.md; every field can be overridden in a scene file's `[open]` table and swept.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OpenItems {
    /// Floor on the Herbert–McWhannell approach speed δ̇₀ (m/s).
    pub approach_speed_floor_m_s: f64,
    /// Proportional gain of the physical reading's motor speed servo, at the input shaft
    /// (N·m per rad/s).
    pub drive_gain_nm_s_rad: f64,
    /// The physical reading's drive current limit (A); below the current sensor's full scale,
    /// as drives size their sensing, so a drive at its limit reads below the ADC's rail.
    pub drive_current_limit_a: f64,
    /// Motor inertia reflected to the input shaft (kg·m²); not in Table 2.
    pub reflected_motor_inertia_kg_m2: f64,
    /// Speed (rad/s) over which bearing friction torques reach their Coulomb value (tanh).
    pub bearing_smoothing_rad_s: f64,
    /// Speed (m/s) over which axial friction forces reach their Coulomb value (tanh).
    pub axial_smoothing_m_s: f64,
    /// Clearance between the small and the big connecting shaft (m); not in Table 2.
    pub shaft_gap_m: f64,
    /// Output speed (rad/s) below which the output counts as stopped (metrics).
    pub stop_threshold_rad_s: f64,
    /// Paper reading: after the drive is cut, the output ramp's far face is a stop that pushes
    /// the drag-held connecting shaft (true), or the input side stays where it stopped (false).
    pub paper_far_face_stop: bool,
    /// Paper reading: angular backlash of the output ramp between its two faces (rad); 0 (the
    /// default) derives it from Table 2 as `2·g_p1/(r·cosθ)` = 0.028 rad.
    pub paper_backlash_rad: f64,
    /// Paper reading: the pack uses μ_s while slipping as well as stuck (true, the paper's
    /// 60 / 8.2 N·m levels), or μ_d while slipping (false).
    pub paper_sliding_mu_static: bool,
}

/// Defaults of the open items (docs/model.md gives the reasons).
pub const DEFAULT_OPEN: OpenItems = OpenItems {
    approach_speed_floor_m_s: 0.01,
    drive_gain_nm_s_rad: 50.0,
    drive_current_limit_a: 25.0,
    reflected_motor_inertia_kg_m2: 0.0,
    bearing_smoothing_rad_s: 0.01,
    axial_smoothing_m_s: 1e-4,
    shaft_gap_m: 0.0,
    stop_threshold_rad_s: 0.05,
    paper_far_face_stop: true,
    paper_backlash_rad: 0.0,
    paper_sliding_mu_static: true,
};

impl Default for OpenItems {
    fn default() -> Self {
        DEFAULT_OPEN
    }
}
