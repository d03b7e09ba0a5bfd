//! The mechanism: the paper's Table 2 and the closed-form relations built on it.
//!
//! One source of truth. The twin (host, f64) and the monitor (target, fixed point, converted once
//! in its constructor) both read these values; a parameter added here needs no second edit.
//! Values are SI and exactly as printed in Table 2 (exponent signs restored where the text lost
//! them: J_r = 1.3e-3, J_c = 1.4e-3, J_b = 1.2e-4 kg·m², g_p1 = 0.2e-3 m, g_p2 = 0.5e-3 m,
//! x0 = 2.3e-3 m). They are never tuned. What the paper leaves open (θ1, g, the cone-angle
//! convention) is named here as our decision with its reason.
//!
//! Sign and angle conventions:
//! - `socket_chamfer_rad` (θ) follows the dynamic equations (6)–(11): a ball–socket contact
//!   force `F_c` has axial component `F_c·sin θ` and tangential component `F_c·cos θ`.
//! - The *cone angle* of Figs 23–25 is measured from the shaft axis: `cone = π/2 − θ`. With
//!   that reading `F = M / (r·tan(cone))`, so a smaller cone angle gives more force, as the paper
//!   reports; at the design point (45°) the two conventions coincide.

/// Standard gravity (m/s²). The paper uses `g` in the bearing-friction terms without a value.
pub const GRAVITY_M_S2: f64 = 9.81;

/// Every parameter of Table 2 plus the two the paper leaves open (θ1 and the reading of μ in the
/// pack capacity is decided by the caller, see [`Mechanism::pack_capacity_nm`]).
#[cfg_attr(feature = "config-block", derive(serde::Serialize, serde::Deserialize))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mechanism {
    /// m_s, mass of the output shaft (kg).
    pub output_shaft_mass_kg: f64,
    /// m_r, mass of the input shaft (kg).
    pub input_shaft_mass_kg: f64,
    /// m_b, mass of one steel ball (kg).
    pub ball_mass_kg: f64,
    /// m_c, mass of the connecting shaft (kg).
    pub connecting_shaft_mass_kg: f64,
    /// J_s, equivalent moment of inertia of the output shaft, door reflected (kg·m²).
    pub output_inertia_kg_m2: f64,
    /// J_r, moment of inertia of the input shaft (kg·m²).
    pub input_inertia_kg_m2: f64,
    /// J_c, moment of inertia of the connecting shaft (kg·m²).
    pub connecting_inertia_kg_m2: f64,
    /// J_b, moment of inertia of a ball about the central axis (kg·m²). Table 2 prints 1.2e-4,
    /// about 100 × m_b·r²; kept as printed (see docs/model.md).
    pub ball_inertia_kg_m2: f64,
    /// M, the load torque of the paper's scenes (N·m).
    pub load_torque_nm: f64,
    /// k_t, stiffness of the wave spring (N/m).
    pub spring_stiffness_n_m: f64,
    /// k, Herbert–McWhannell contact stiffness (N/m^1.5).
    pub contact_stiffness: f64,
    /// x0, wave-spring preload compression (m).
    pub spring_preload_m: f64,
    /// r, radius of the ball sockets from the central axis (m).
    pub socket_radius_m: f64,
    /// r_ms, bearing friction radius of the output shaft (m).
    pub output_friction_radius_m: f64,
    /// r_md, bearing friction radius of the connecting shaft (m).
    pub connecting_friction_radius_m: f64,
    /// r_mr, bearing friction radius of the input shaft (m).
    pub input_friction_radius_m: f64,
    /// r1, inner radius of the friction-pack contact (m).
    pub pack_inner_radius_m: f64,
    /// r2, outer radius of the friction-pack contact (m).
    pub pack_outer_radius_m: f64,
    /// g_p1, clearance of a ball–socket contact (m).
    pub socket_clearance_m: f64,
    /// g_p2, clearance of the friction pack (m).
    pub pack_clearance_m: f64,
    /// θ, chamfer of the ball socket (rad), see the module doc for the convention.
    pub socket_chamfer_rad: f64,
    /// N_f, number of friction discs.
    pub friction_discs: u8,
    /// μ_f, static friction coefficient.
    pub mu_static: f64,
    /// μ_d, dynamic friction coefficient.
    pub mu_dynamic: f64,
    /// e, coefficient of restitution of the ball–socket contact.
    pub restitution: f64,
    /// θ1, centre angle of the radial grooves on a friction disc (rad). **Not in the paper**;
    /// 0 by default (no grooves), which gives the paper's 8.2 and 60 N·m levels.
    pub groove_angle_rad: f64,
}

/// Table 2 of the paper, as printed, with θ1 = 0.
pub const TABLE2: Mechanism = Mechanism {
    output_shaft_mass_kg: 0.173,
    input_shaft_mass_kg: 0.206,
    ball_mass_kg: 0.003,
    connecting_shaft_mass_kg: 0.285,
    output_inertia_kg_m2: 0.15,
    input_inertia_kg_m2: 1.3e-3,
    connecting_inertia_kg_m2: 1.4e-3,
    ball_inertia_kg_m2: 1.2e-4,
    load_torque_nm: 20.3,
    spring_stiffness_n_m: 9.4e4,
    contact_stiffness: 2.53e9,
    spring_preload_m: 2.3e-3,
    socket_radius_m: 0.02,
    output_friction_radius_m: 0.012,
    connecting_friction_radius_m: 0.01,
    input_friction_radius_m: 0.01,
    pack_inner_radius_m: 0.0285,
    pack_outer_radius_m: 0.0375,
    socket_clearance_m: 0.2e-3,
    pack_clearance_m: 0.5e-3,
    socket_chamfer_rad: core::f64::consts::FRAC_PI_4,
    friction_discs: 3,
    mu_static: 0.3,
    mu_dynamic: 0.17,
    restitution: 0.5,
    groove_angle_rad: 0.0,
};

impl Default for Mechanism {
    fn default() -> Self {
        TABLE2
    }
}

impl Mechanism {
    /// Ramp factor (1/m): axial force on the pack per newton-metre of torque carried by the three
    /// ball–socket contacts, `tan θ / r`. At Table 2 (45°, 20 mm): 50 N per N·m.
    ///
    /// ```
    /// let f = noback::mechanism::TABLE2.ramp_factor_per_m();
    /// assert!((f - 50.0).abs() < 1e-9);
    /// ```
    pub fn ramp_factor_per_m(&self) -> f64 {
        tan(self.socket_chamfer_rad) / self.socket_radius_m
    }

    /// Number of sliding surfaces in the pack, `2·N_f − 1` (Eq. 19).
    pub fn friction_surfaces(&self) -> f64 {
        f64::from(2 * u16::from(self.friction_discs)).max(1.0) - 1.0
    }

    /// Effective friction radius of one surface (m), Eq. (18) without μ and F_p:
    /// `(2π − θ1)(r2³ − r1³) / (3π(r2² − r1²))`. θ1 = 0 gives the uniform-pressure radius 33.2 mm.
    pub fn pack_friction_radius_m(&self) -> f64 {
        let (r1, r2) = (self.pack_inner_radius_m, self.pack_outer_radius_m);
        let pi = core::f64::consts::PI;
        (2.0 * pi - self.groove_angle_rad) * (r2 * r2 * r2 - r1 * r1 * r1)
            / (3.0 * pi * (r2 * r2 - r1 * r1))
    }

    /// Pack torque per newton of pressing force (m) for friction coefficient `mu`, Eqs. (18)–(19).
    /// With μ_s = 0.3 and θ1 = 0: 0.0498 m.
    pub fn pack_torque_per_newton_m(&self, mu: f64) -> f64 {
        mu * self.friction_surfaces() * self.pack_friction_radius_m()
    }

    /// Braking capacity T_all (N·m) of the pack under pressing force `pressing_force_n` (N).
    pub fn pack_capacity_nm(&self, pressing_force_n: f64, mu: f64) -> f64 {
        self.pack_torque_per_newton_m(mu) * pressing_force_n.max(0.0)
    }

    /// Wave-spring force on the pack with the pack closed (N): `k_t·(x0 − g_p2)`, 169.2 N at
    /// Table 2. The spring pushes the pack shut (a spring-applied pack, see docs/model.md).
    pub fn spring_preload_n(&self) -> f64 {
        self.spring_stiffness_n_m * (self.spring_preload_m - self.pack_clearance_m).max(0.0)
    }

    /// Quasi-static pressing force (N) for a load torque `load_torque_nm` held by the ramps:
    /// spring preload plus `|M|·tan θ / r`.
    pub fn quasi_static_pressing_force_n(&self, load_torque_nm: f64) -> f64 {
        self.spring_preload_n() + abs(load_torque_nm) * self.ramp_factor_per_m()
    }
}

/// `|x|` without std.
fn abs(x: f64) -> f64 {
    if x < 0.0 {
        -x
    } else {
        x
    }
}

/// `tan` without std: `sin/cos` by a short Taylor series after reduction to |x| ≤ π/4 is more
/// than we need; we only evaluate it at configuration time, so use the libm-free identity
/// `tan x = sin x / cos x` with series to 1e-15 on [-π/2, π/2).
fn tan(x: f64) -> f64 {
    // Reduce to [-π/2, π/2): tan has period π.
    let pi = core::f64::consts::PI;
    let mut y = x;
    while y >= pi / 2.0 {
        y -= pi;
    }
    while y < -pi / 2.0 {
        y += pi;
    }
    sin_series(y) / cos_series(y)
}

fn sin_series(x: f64) -> f64 {
    let x2 = x * x;
    let mut term = x;
    let mut sum = x;
    let mut n = 1.0;
    while n < 40.0 {
        term *= -x2 / ((n + 1.0) * (n + 2.0));
        sum += term;
        n += 2.0;
    }
    sum
}

fn cos_series(x: f64) -> f64 {
    let x2 = x * x;
    let mut term = 1.0;
    let mut sum = 1.0;
    let mut n = 0.0;
    while n < 40.0 {
        term *= -x2 / ((n + 1.0) * (n + 2.0));
        sum += term;
        n += 2.0;
    }
    sum
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    #[test]
    fn static_levels_match_the_paper() {
        let m = TABLE2;
        // Spring alone: 8.43 N·m (paper trough 8.2 N·m).
        let spring_only = m.pack_capacity_nm(m.spring_preload_n(), m.mu_static);
        assert!((spring_only - 8.43).abs() < 0.01, "{spring_only}");
        // Spring plus ramp force of the paper's load: ≈ 59 N·m (paper peak ≈ 60 N·m).
        let loaded = m.pack_capacity_nm(m.quasi_static_pressing_force_n(20.3), m.mu_static);
        assert!((loaded - 58.98).abs() < 0.05, "{loaded}");
    }

    #[test]
    fn pack_radius_is_the_uniform_pressure_radius() {
        assert!((TABLE2.pack_friction_radius_m() - 0.033_204).abs() < 1e-6);
        let grooved = Mechanism {
            groove_angle_rad: core::f64::consts::FRAC_PI_2,
            ..TABLE2
        };
        let ratio = grooved.pack_friction_radius_m() / TABLE2.pack_friction_radius_m();
        assert!((ratio - 0.75).abs() < 1e-12);
    }

    #[test]
    fn tan_series_is_exact_enough() {
        for i in -150..150 {
            let x = f64::from(i) * 0.01;
            let exact = x.sin() / x.cos(); // host std here is only the reference
            assert!(
                (tan(x) - exact).abs() <= 1e-12 * exact.abs().max(1.0),
                "{x}"
            );
        }
    }

    #[test]
    fn smaller_cone_angle_gives_more_force() {
        let force_at = |cone_deg: f64| {
            let m = Mechanism {
                socket_chamfer_rad: (90.0 - cone_deg).to_radians(),
                ..TABLE2
            };
            m.quasi_static_pressing_force_n(20.3)
        };
        assert!(force_at(30.0) > force_at(45.0));
        assert!(force_at(45.0) > force_at(60.0));
    }
}
