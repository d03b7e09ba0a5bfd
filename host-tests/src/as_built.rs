//! A unit's build record (docs/commissioning.md, "The build record"): what its assembly and
//! inspection measured of the pack — the spring's preload force and the ramps' and discs'
//! geometry — which commissioning sets the monitor's mechanism from in place of Table 2's.

use noback::mechanism::Mechanism;
use noback::monitor::Config;
use noback_twin::sensing::Rng;
use toml::{Table, Value};

/// The measured quantities, in the record file's keys.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AsBuilt {
    /// The spring's preload force as shimmed at assembly (N): `k_t·(x₀ − g_p2)`.
    pub spring_preload_n: f64,
    /// `r`, the ball sockets' radius (m).
    pub socket_radius_m: f64,
    /// `θ`, the sockets' chamfer (rad).
    pub socket_chamfer_rad: f64,
    /// `r1`, `r2`, the friction contact's radii (m).
    pub pack_inner_radius_m: f64,
    pub pack_outer_radius_m: f64,
}

/// The inspection's tolerances the Monte Carlo draws a record within (uniform, ±): the preload
/// on the shimming fixture's load cell 2 %, the chamfer on a CMM 0.25°, the radii 0.5 %.
pub const PRELOAD_TOLERANCE: f64 = 0.02;
pub const CHAMFER_TOLERANCE_RAD: f64 = 0.25 * core::f64::consts::PI / 180.0;
pub const RADIUS_TOLERANCE: f64 = 0.005;

/// The monitor's mechanism fields a record sets, in the configuration file's keys.
pub(crate) fn fields(m: &mut Mechanism) -> [(&'static str, &mut f64); 5] {
    [
        ("spring_preload_m", &mut m.spring_preload_m),
        ("socket_radius_m", &mut m.socket_radius_m),
        ("socket_chamfer_rad", &mut m.socket_chamfer_rad),
        ("pack_inner_radius_m", &mut m.pack_inner_radius_m),
        ("pack_outer_radius_m", &mut m.pack_outer_radius_m),
    ]
}

impl AsBuilt {
    /// The record of a mechanism measured exactly.
    pub fn of(m: &Mechanism) -> AsBuilt {
        AsBuilt {
            spring_preload_n: m.spring_preload_n(),
            socket_radius_m: m.socket_radius_m,
            socket_chamfer_rad: m.socket_chamfer_rad,
            pack_inner_radius_m: m.pack_inner_radius_m,
            pack_outer_radius_m: m.pack_outer_radius_m,
        }
    }

    /// The record of `m` as inspection measures it: each quantity within its tolerance, drawn
    /// from `seed` alone (a draw's other quantities are not moved).
    pub fn inspected(m: &Mechanism, seed: u64) -> AsBuilt {
        let mut rng = Rng::new(seed);
        let mut within = |x: f64, tol: f64| x + tol * (2.0 * rng.uniform() - 1.0);
        let exact = AsBuilt::of(m);
        AsBuilt {
            spring_preload_n: exact.spring_preload_n * within(1.0, PRELOAD_TOLERANCE),
            socket_radius_m: exact.socket_radius_m * within(1.0, RADIUS_TOLERANCE),
            socket_chamfer_rad: within(exact.socket_chamfer_rad, CHAMFER_TOLERANCE_RAD),
            pack_inner_radius_m: exact.pack_inner_radius_m * within(1.0, RADIUS_TOLERANCE),
            pack_outer_radius_m: exact.pack_outer_radius_m * within(1.0, RADIUS_TOLERANCE),
        }
    }

    /// The uncommissioned configuration with the record's pack: where commissioning starts.
    pub fn config(&self) -> Config {
        let mut c = Config::default();
        c.mechanism = self.applied_to(&c.mechanism);
        c
    }

    /// `design` with the record's quantities: the preload force through the design's spring
    /// stiffness and pack clearance.
    pub fn applied_to(&self, design: &Mechanism) -> Mechanism {
        let mut m = *design;
        m.spring_preload_m = m.pack_clearance_m + self.spring_preload_n / m.spring_stiffness_n_m;
        m.socket_radius_m = self.socket_radius_m;
        m.socket_chamfer_rad = self.socket_chamfer_rad;
        m.pack_inner_radius_m = self.pack_inner_radius_m;
        m.pack_outer_radius_m = self.pack_outer_radius_m;
        m
    }

    /// Reads a record file: `[as_built]` with every key of [`AsBuilt`]; a missing, unknown or
    /// non-positive key, a chamfer not below π/2 (radians, not degrees) or discs whose inner
    /// radius is not below the outer are errors naming the key.
    pub fn parse(text: &str) -> Result<AsBuilt, String> {
        let mut root: Table = text
            .parse()
            .map_err(|e: toml::de::Error| format!("TOML: {}", e.message()))?;
        let mut t = match root.remove("as_built") {
            Some(Value::Table(t)) => t,
            Some(_) => return Err("as_built: expected a table".into()),
            None => return Err("[as_built]: missing".into()),
        };
        if let Some(k) = root.keys().next() {
            return Err(format!("{k}: unknown key"));
        }
        let mut take = |key: &str| -> Result<f64, String> {
            match t.remove(key) {
                Some(Value::Float(x)) if x.is_finite() && x > 0.0 => Ok(x),
                Some(Value::Integer(i)) if i > 0 => Ok(i as f64),
                Some(_) => Err(format!("as_built.{key}: expected a positive number")),
                None => Err(format!("as_built.{key}: missing")),
            }
        };
        let record = AsBuilt {
            spring_preload_n: take("spring_preload_n")?,
            socket_radius_m: take("socket_radius_m")?,
            socket_chamfer_rad: take("socket_chamfer_rad")?,
            pack_inner_radius_m: take("pack_inner_radius_m")?,
            pack_outer_radius_m: take("pack_outer_radius_m")?,
        };
        if let Some(k) = t.keys().next() {
            return Err(format!("as_built.{k}: unknown key"));
        }
        if record.socket_chamfer_rad >= core::f64::consts::FRAC_PI_2 {
            return Err("as_built.socket_chamfer_rad: expected radians below π/2".into());
        }
        if record.pack_inner_radius_m >= record.pack_outer_radius_m {
            return Err("as_built.pack_inner_radius_m: expected below pack_outer_radius_m".into());
        }
        Ok(record)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use noback::mechanism::TABLE2;

    /// The record of a unit off the design, applied to the design, is that unit's pack; an
    /// inspected one spreads over most of each tolerance, and no further.
    #[test]
    fn a_record_applied_gives_the_units_pack_and_inspection_spreads_within_tolerance() {
        let mut unit = TABLE2;
        unit.spring_preload_m *= 1.07;
        unit.socket_chamfer_rad *= 0.93;
        unit.pack_outer_radius_m *= 1.05;
        let exact = AsBuilt::of(&unit);
        let m = exact.applied_to(&TABLE2);
        assert!((m.spring_preload_n() / unit.spring_preload_n() - 1.0).abs() < 1e-12);
        assert_eq!(m.socket_chamfer_rad, unit.socket_chamfer_rad);
        assert_eq!(m.pack_outer_radius_m, unit.pack_outer_radius_m);
        assert_eq!(m.mu_static, TABLE2.mu_static);
        // Each quantity's largest deviation over 400 draws (relative; the chamfer's in rad).
        let mut most = [0.0_f64; 5];
        for seed in 0..400 {
            let r = AsBuilt::inspected(&unit, seed);
            let dev = [
                r.spring_preload_n / exact.spring_preload_n - 1.0,
                r.socket_radius_m / exact.socket_radius_m - 1.0,
                r.socket_chamfer_rad - exact.socket_chamfer_rad,
                r.pack_inner_radius_m / exact.pack_inner_radius_m - 1.0,
                r.pack_outer_radius_m / exact.pack_outer_radius_m - 1.0,
            ];
            for (m, d) in most.iter_mut().zip(dev) {
                *m = m.max(d.abs());
            }
        }
        let tol = [
            PRELOAD_TOLERANCE,
            RADIUS_TOLERANCE,
            CHAMFER_TOLERANCE_RAD,
            RADIUS_TOLERANCE,
            RADIUS_TOLERANCE,
        ];
        for (m, t) in most.iter().zip(tol) {
            assert!(*m <= t && *m > 0.9 * t, "spread {m} against tolerance {t}");
        }
    }

    #[test]
    fn a_record_file_reads_every_key_and_names_a_bad_one() {
        let good = "[as_built]\nspring_preload_n = 180.0\nsocket_radius_m = 0.0201\n\
                    socket_chamfer_rad = 0.80\npack_inner_radius_m = 0.0285\npack_outer_radius_m = 0.0375\n";
        let r = AsBuilt::parse(good).expect("a whole record");
        assert_eq!(r.spring_preload_n, 180.0);
        assert_eq!(r.socket_chamfer_rad, 0.80);
        for (bad, error) in [
            (
                good.replace("socket_radius_m = 0.0201\n", ""),
                "as_built.socket_radius_m: missing",
            ),
            (
                format!("{good}mu_static = 0.3\n"),
                "as_built.mu_static: unknown key",
            ),
            (
                good.replace("180.0", "-180.0"),
                "as_built.spring_preload_n: expected a positive number",
            ),
            (
                good.replace("0.80", "45.0"),
                "as_built.socket_chamfer_rad: expected radians below π/2",
            ),
            (
                good.replace("0.0375", "0.0200"),
                "as_built.pack_inner_radius_m: expected below pack_outer_radius_m",
            ),
        ] {
            assert_eq!(AsBuilt::parse(&bad), Err(error.to_string()), "{bad}");
        }
    }
}
