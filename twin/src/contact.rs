//! Herbert–McWhannell contact (paper Eqs. 1–5): the force law of every ball–socket contact and
//! of the friction pack, shared by both readings.
//!
//! `F_N = k·δ^1.5·(1 + c_e·δ̇/δ̇₀)` for penetration `δ > 0`, zero otherwise, and never pulling
//! (the damping term may not make the force negative). `c_e = 6(1−e)/((2e−1)² + 3)` is exactly 1
//! at the paper's e = 0.5. `δ̇₀` is the approach speed recorded when the contact closed; for a
//! contact that closes slowly (a seated ball) it tends to zero and the damping becomes unbounded,
//! so the twin floors it at [`ContactLaw::approach_speed_floor_m_s`] (default 0.01 m/s, an open
//! item: see docs/model.md, "Contact damping floor").

/// The force law of one contact type.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactLaw {
    /// k, contact stiffness (N/m^1.5).
    pub stiffness: f64,
    /// e, coefficient of restitution.
    pub restitution: f64,
    /// Floor on the recorded approach speed δ̇₀ (m/s).
    pub approach_speed_floor_m_s: f64,
}

impl ContactLaw {
    /// The damping factor `c_e = 6(1−e)/((2e−1)² + 3)`.
    pub fn damping_factor(&self) -> f64 {
        let e = self.restitution;
        6.0 * (1.0 - e) / ((2.0 * e - 1.0).powi(2) + 3.0)
    }

    /// Approach speed to record at contact onset: `max(|δ̇|, floor)`.
    pub fn approach_speed_m_s(&self, penetration_rate_m_s: f64) -> f64 {
        penetration_rate_m_s
            .abs()
            .max(self.approach_speed_floor_m_s)
            .max(1e-12)
    }

    /// Normal force (N) for penetration `penetration_m` (δ), its rate (δ̇) and the recorded
    /// approach speed `approach_m_s` (δ̇₀, already floored).
    pub fn force_n(&self, penetration_m: f64, rate_m_s: f64, approach_m_s: f64) -> f64 {
        if penetration_m <= 0.0 {
            return 0.0;
        }
        let elastic = self.stiffness * penetration_m * penetration_m.sqrt();
        let factor = 1.0 + self.damping_factor() * rate_m_s / approach_m_s.max(1e-12);
        (elastic * factor).max(0.0)
    }

    /// Potential energy (J) stored at penetration δ: `k·δ^2.5 / 2.5`.
    pub fn energy_j(&self, penetration_m: f64) -> f64 {
        if penetration_m <= 0.0 {
            0.0
        } else {
            self.stiffness * penetration_m.powf(2.5) / 2.5
        }
    }

    /// The same law with no damping (for energy checks).
    pub fn undamped(&self) -> Self {
        ContactLaw {
            restitution: 1.0,
            ..*self
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn law() -> ContactLaw {
        ContactLaw {
            stiffness: 2.53e9,
            restitution: 0.5,
            approach_speed_floor_m_s: 0.05,
        }
    }

    #[test]
    fn factor_is_one_at_half_restitution_and_zero_at_one() {
        assert!((law().damping_factor() - 1.0).abs() < 1e-15);
        assert!(law().undamped().damping_factor().abs() < 1e-15);
    }

    #[test]
    fn never_pulls_and_is_zero_when_open() {
        let l = law();
        assert_eq!(l.force_n(-1e-6, 1.0, 0.1), 0.0);
        // Fast separation would make the damped force negative: it is clamped to zero.
        assert_eq!(l.force_n(1e-6, -10.0, 0.1), 0.0);
        let f = l.force_n(1e-5, 0.0, 0.1);
        assert!((f - 2.53e9 * 1e-5_f64.powf(1.5)).abs() < 1e-9 * f);
    }

    #[test]
    fn floor_applies_to_slow_approach() {
        assert_eq!(law().approach_speed_m_s(1e-6), 0.05);
        assert_eq!(law().approach_speed_m_s(-0.3), 0.3);
    }
}
