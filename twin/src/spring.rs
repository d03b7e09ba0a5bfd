//! The wave spring: it pushes the big connecting shaft towards the friction pack
//! (a spring-applied pack), `F_k = k_t·(x0 − x)` with `x` the shaft's travel from the spring's
//! installed position; the pack closes at `x = g_p2`, where the force is the 169 N preload of
//! [`noback::mechanism::Mechanism::spring_preload_n`]. The sign of `F_k` is an open item of
//! MODEL.md; this direction is the one that makes the no-back self-actuating (docs/model.md).

use noback::mechanism::Mechanism;

/// Spring force (N) on the big connecting shaft at axial travel `x_m`, positive towards the pack.
/// A broken spring (fault) scales the stiffness by `1 − severity`.
pub fn spring_force_n(mech: &Mechanism, x_m: f64, stiffness_scale: f64) -> f64 {
    (mech.spring_stiffness_n_m * stiffness_scale * (mech.spring_preload_m - x_m)).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use noback::mechanism::TABLE2;

    #[test]
    fn preload_at_pack_closure_matches_the_library() {
        let f = spring_force_n(&TABLE2, TABLE2.pack_clearance_m, 1.0);
        assert!((f - TABLE2.spring_preload_n()).abs() < 1e-9);
    }
}
