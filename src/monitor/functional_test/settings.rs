//! The functional test's settings: each procedure's judge and the drive's timing, converted
//! once from [`TestConfig`] and checked against the configuration.

use super::super::config::{Config, ConfigError, DrivingPack};
use super::super::convert::{filter_gain, finite, positive, q16, require, ticks};
use super::super::schedule::EVERY_TICK;
use super::{Procedure, TestConfig};
use crate::fx::{Gain, Q16};

/// The test's constants, converted once.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TestSettings {
    /// The loaded push's load and band.
    pub(super) judge: TestJudge,
    /// A relieved pack's acceptance readings, or a spring-only pack's uncoupled push.
    pub(super) companion: Companion,
    /// Ticks from the request: the opening's measured half starts, the opening ends, the push
    /// starts.
    pub(super) measure_from: u32,
    pub(super) open_ticks: u32,
    pub(super) push_from: u32,
    /// Ticks of the ramp until the torque limit, plus a settling allowance.
    pub(super) limit_ticks: u32,
    pub(super) breakaway_counts: i32,
    pub(super) out_bits: u8,
    pub(super) alpha: Gain,
}

/// What a push is judged by: its load's sign and size, its lever (`Ĉ = L + lever·T_b`), the
/// expected capacity and its band. The uncoupled push keeps only this: it runs the loaded
/// push's drive and timing.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TestJudge {
    pub(super) sign: i32,
    pub(super) load: Q16,
    pub(super) lever: Q16,
    pub(super) expected_capacity: Q16,
    pub(super) min_capacity: Q16,
    pub(super) max_capacity: Q16,
}

/// What the loaded push carries beside its judge; never both (a relieved pack has no uncoupled
/// push, a spring-only pack no opening reading), so they share the room.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Companion {
    /// The breakaway alone, against the expected one.
    Alone,
    /// The acceptance readings of a relieved pack: the opening takes the load out.
    Acceptance(Acceptance),
    /// A spring-only pack's uncoupled push: its judge, on the loaded push's drive and timing.
    Uncoupled(TestJudge),
}

/// A unit's acceptance readings and `ΔĈ = k_b·ΔT_b − k_o·ΔT_o`'s weights.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Acceptance {
    pub(super) breakaway: Q16,
    pub(super) opening: Q16,
    pub(super) k_b: Q16,
    pub(super) k_o: Q16,
    /// `d`: the opening torque per N·m of `C₀`.
    pub(super) drag: Q16,
    /// Largest `|L̂ − L|` that passes (N·m).
    pub(super) load_error: Q16,
}

impl TestSettings {
    /// Checks the test's settings (`c.functional_test`, and `c.uncoupled_test` if set) against
    /// the configuration.
    pub fn new(c: &Config) -> Result<TestSettings, ConfigError> {
        let mut s = TestSettings::build(c, &c.functional_test, Procedure::Loaded)?;
        if let Some(t) = &c.uncoupled_test {
            s.companion = Companion::Uncoupled(TestSettings::uncoupled(c, t)?);
        }
        Ok(s)
    }

    /// The judge of `procedure`, if configured.
    pub(crate) fn judge(&self, procedure: Procedure) -> Option<&TestJudge> {
        match (procedure, &self.companion) {
            (Procedure::Loaded, _) => Some(&self.judge),
            (Procedure::Uncoupled, Companion::Uncoupled(j)) => Some(j),
            (Procedure::Uncoupled, _) => None,
        }
    }

    /// The uncoupled push's judge: a spring-only pack's only, on the loaded test's drive and
    /// timing, judged on its breakaway alone; errors name `uncoupled_test.*`.
    fn uncoupled(c: &Config, t: &TestConfig) -> Result<TestJudge, ConfigError> {
        require(c.driving_pack == DrivingPack::SpringOnly, "uncoupled_test")?;
        let l = &c.functional_test;
        // Every field, so that a new one is placed here: the drive's must equal the loaded's.
        let TestConfig {
            load_nm,
            torque_rate_nm_s,
            max_torque_nm,
            open_s,
            settle_s,
            breakaway_rad,
            expected_breakaway_nm: _,
            expected_opening_nm,
            min_margin: _,
            max_margin: _,
            load_tolerance: _,
            torque_filter_hz,
        } = *t;
        for (ok, key) in [
            (torque_rate_nm_s == l.torque_rate_nm_s, "torque_rate_nm_s"),
            (max_torque_nm == l.max_torque_nm, "max_torque_nm"),
            (open_s == l.open_s, "open_s"),
            (settle_s == l.settle_s, "settle_s"),
            (breakaway_rad == l.breakaway_rad, "breakaway_rad"),
            (torque_filter_hz == l.torque_filter_hz, "torque_filter_hz"),
            (load_nm * l.load_nm > 0.0, "load_nm"),
            (expected_opening_nm.is_none(), "expected_opening_nm"),
        ] {
            require(ok, uncoupled_name(key))?;
        }
        TestSettings::build(c, t, Procedure::Uncoupled)
            .map(|s| s.judge)
            .map_err(|e| match e.parameter().strip_prefix("functional_test.") {
                Some(key) => e.renamed(uncoupled_name(key)),
                None => e,
            })
    }

    fn build(
        c: &Config,
        t: &TestConfig,
        procedure: Procedure,
    ) -> Result<TestSettings, ConfigError> {
        let m = &c.mechanism;
        let load = finite(t.load_nm, "functional_test.load_nm")?;
        require(load != 0.0, "functional_test.load_nm")?;
        let rate = positive(t.torque_rate_nm_s, "functional_test.torque_rate_nm_s")?;
        let max = positive(t.max_torque_nm, "functional_test.max_torque_nm")?;
        let per_n = m.pack_torque_per_newton_m(finite(c.capacity_mu, "capacity_mu")?);
        let g = per_n * m.ramp_factor_per_m();
        require(g.is_finite() && g > 0.0, "capacity_mu")?;
        let c0 = per_n * m.spring_preload_n();
        let l = load.abs();
        // Loaded, the push relieves the pack through the ramps: `C(L) − g·T_b = L + T_b`.
        // Uncoupled, no load climbs the ramps: the spring's clamp alone, `C₀ = L + T_b`.
        let (lever, design_b) = match procedure {
            Procedure::Loaded => (1.0 + g, (c0 + (g - 1.0) * l) / (1.0 + g)),
            Procedure::Uncoupled => (1.0, c0 - l),
        };
        let expected_b = match t.expected_breakaway_nm {
            Some(b) => positive(b, "functional_test.expected_breakaway_nm")?,
            None => design_b,
        };
        require(expected_b > 0.0, "functional_test.expected_breakaway_nm")?;
        let expected = l + lever * expected_b;
        // T_b = p·L + q·C₀ and T_o = L + d·C₀ (d: the pack's drag per C₀ while driving).
        let drag = m.pack_torque_per_newton_m(finite(m.mu_dynamic, "mechanism.mu_dynamic")?);
        let d = drag / per_n / (1.0 + drag * m.ramp_factor_per_m());
        let (p, q) = ((g - 1.0) / (1.0 + g), 1.0 / (1.0 + g));
        let separation = q - p * d;
        require(separation > 0.05, "mechanism.mu_dynamic")?;
        if let Some(o) = t.expected_opening_nm {
            positive(o, "functional_test.expected_opening_nm")?;
        }
        let acceptance = match (t.expected_breakaway_nm, t.expected_opening_nm) {
            // A spring-only pack drags on its whole spring (d ≈ 0.6…1.2): its two readings move
            // alike with L and C₀, and the breakaway alone stands (docs/functional-test.md).
            (Some(b), Some(o)) if c.driving_pack == DrivingPack::Relieved => Some(Acceptance {
                breakaway: q16(b, "functional_test.expected_breakaway_nm")?,
                opening: q16(o, "functional_test.expected_opening_nm")?,
                k_b: q16(1.0 / separation, "mechanism.mu_dynamic")?,
                k_o: q16(p / separation, "mechanism.mu_dynamic")?,
                drag: q16(d, "mechanism.mu_dynamic")?,
                load_error: q16(
                    l * positive(t.load_tolerance, "functional_test.load_tolerance")?,
                    "functional_test.load_tolerance",
                )?,
            }),
            (None, Some(_)) => {
                return Err(ConfigError::OutOfRange {
                    parameter: "functional_test.expected_opening_nm",
                })
            }
            _ => None,
        };
        let open_ticks = ticks(t.open_s, tick_hz(c)?, "functional_test.open_s")?;
        let push_from =
            open_ticks.saturating_add(ticks(t.settle_s, tick_hz(c)?, "functional_test.settle_s")?);
        let margin = positive(t.min_margin, "functional_test.min_margin")?;
        require(margin <= 1.0, "functional_test.min_margin")?;
        let top = finite(t.max_margin, "functional_test.max_margin")?;
        require((1.0..=16.0).contains(&top), "functional_test.max_margin")?;
        let bits = c.sensors.output_encoder_bits;
        require((8..=24).contains(&bits), "sensors.output_encoder_bits")?;
        let counts = positive(t.breakaway_rad, "functional_test.breakaway_rad")?
            / c.sensors.output_rad_per_count();
        require(counts < 1e6, "functional_test.breakaway_rad")?;
        let hz = positive(t.torque_filter_hz, "functional_test.torque_filter_hz")?;
        let tick_hz = tick_hz(c)?;
        Ok(TestSettings {
            judge: TestJudge {
                sign: if load > 0.0 { 1 } else { -1 },
                load: q16(l, "functional_test.load_nm")?,
                lever: q16(lever, "capacity_mu")?,
                expected_capacity: q16(expected, "functional_test.expected_breakaway_nm")?,
                min_capacity: q16(expected * margin, "functional_test.min_margin")?,
                max_capacity: q16(expected * top, "functional_test.max_margin")?,
            },
            companion: acceptance.map_or(Companion::Alone, Companion::Acceptance),
            measure_from: open_ticks / 2,
            open_ticks,
            push_from,
            limit_ticks: ticks(
                max / rate + 5.0 / hz,
                tick_hz,
                "functional_test.torque_rate_nm_s",
            )?,
            // 0 < counts < 1e6 (checked above): the next whole count, at least 1.
            breakaway_counts: (counts as i32 + 1).max(1),
            out_bits: bits,
            alpha: filter_gain(hz, tick_hz, EVERY_TICK, "functional_test.torque_filter_hz")?,
        })
    }
}

/// A test parameter's name under `[monitor.uncoupled_test]`.
fn uncoupled_name(key: &'static str) -> &'static str {
    match key {
        "load_nm" => "uncoupled_test.load_nm",
        "torque_rate_nm_s" => "uncoupled_test.torque_rate_nm_s",
        "max_torque_nm" => "uncoupled_test.max_torque_nm",
        "open_s" => "uncoupled_test.open_s",
        "settle_s" => "uncoupled_test.settle_s",
        "breakaway_rad" => "uncoupled_test.breakaway_rad",
        "expected_breakaway_nm" => "uncoupled_test.expected_breakaway_nm",
        "expected_opening_nm" => "uncoupled_test.expected_opening_nm",
        "min_margin" => "uncoupled_test.min_margin",
        "max_margin" => "uncoupled_test.max_margin",
        "load_tolerance" => "uncoupled_test.load_tolerance",
        "torque_filter_hz" => "uncoupled_test.torque_filter_hz",
        _ => "uncoupled_test",
    }
}

/// The monitor's tick rate, checked.
fn tick_hz(c: &Config) -> Result<f64, ConfigError> {
    positive(c.tick_hz, "tick_hz")
}
