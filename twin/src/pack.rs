//! Friction pack, paper Eqs. (18)–(19), through `noback::mechanism` (one source of truth).
//!
//! The pack converts a pressing force into a torque capacity `T_all = μ·R_eff·(2N_f−1)·F_p`.
//! Which μ applies while slipping is the main difference of the two readings (docs/model.md):
//! the `physical` reading uses μ_d when slipping and μ_s for breakaway; the `paper` reading
//! uses μ_s for both (the paper's 8.2 / 60 N·m levels require it).

use noback::mechanism::Mechanism;

/// Torque capacities of the pack at one pressing force.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PackCapacity {
    /// Largest torque the pack can hold while stuck (N·m).
    pub static_nm: f64,
    /// Torque while slipping (N·m).
    pub sliding_nm: f64,
}

/// Capacities at pressing force `pressing_force_n` (N); `mu_scale` models friction loss / wear
/// (1 = healthy); `sliding_uses_static_mu` selects the paper's reading.
pub fn capacity(
    mech: &Mechanism,
    pressing_force_n: f64,
    mu_scale: f64,
    sliding_uses_static_mu: bool,
) -> PackCapacity {
    let mu_s = mech.mu_static * mu_scale;
    let mu_d = if sliding_uses_static_mu {
        mu_s
    } else {
        mech.mu_dynamic * mu_scale
    };
    PackCapacity {
        static_nm: mech.pack_capacity_nm(pressing_force_n, mu_s),
        sliding_nm: mech.pack_capacity_nm(pressing_force_n, mu_d),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use noback::mechanism::TABLE2;

    #[test]
    fn spring_only_and_loaded_capacities() {
        let m = TABLE2;
        let spring = capacity(&m, m.spring_preload_n(), 1.0, true);
        assert!((spring.static_nm - 8.43).abs() < 0.01);
        let loaded = capacity(&m, m.quasi_static_pressing_force_n(20.3), 1.0, false);
        assert!((loaded.static_nm - 58.98).abs() < 0.05);
        assert!((loaded.sliding_nm / loaded.static_nm - 0.17 / 0.3).abs() < 1e-12);
    }
}
