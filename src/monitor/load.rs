//! The load and the pack's health: the load learned where it is well conditioned (driving,
//! where the pack torque follows from the current alone) and held elsewhere; the capacity and
//! margin that follow from it; the pack health learned while the pack slips with the drive off.
//!
//! | quantity | format | range | resolution |
//! |---|---|---|---|
//! | load, capacity, available | [`Q16`] N·m, saturating | ±32 768 | 1.5e-5 N·m |
//! | margins | [`Q16`], at most [`MARGIN_MAX`] | 0 … 1000 | 1.5e-5 |
//! | health | [`Q16`], clamped | 0 … 2 | 1.5e-5 |

use super::checks::Decel;
use super::config::{Config, ConfigError};
use super::convert::{filter_gain, finite, positive, q16, require, scale, ticks, Q16_ONE};
use super::scale::Scale;
use super::schedule::SLOW;
use super::{mul_q16, MARGIN_MAX};
use crate::fx::{lowpass, Gain, Q16};

/// Pack health is kept within [0, 2].
const HEALTH_MAX: i32 = 2 << 16;

/// The load stage's constants.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct LoadSettings {
    /// Gain of the load filter, run in the slow lane.
    alpha: Gain,
    /// Learning ticks before the load counts as known (three time constants).
    known_ticks: u32,
    min_margin: Scale<26>,
    /// A healthy pack's modelled capacity over the largest expected load (`max_load_nm`), and
    /// its lower bound (`× (1 − capacity_uncertainty)`), each at most [`MARGIN_MAX`] / 2.
    service_margin: Q16,
    service_margin_low: Q16,
    /// Health change per slow-lane update (Q16 bits).
    health_step: i32,
    /// Health is learned against an opposing load too: only where the envelope counts on the
    /// whole capacity there (`opposed_braking_share` = 1, both socket faces clamp).
    pub learn_opposed: bool,
}

impl LoadSettings {
    pub fn new(c: &Config) -> Result<LoadSettings, ConfigError> {
        let (t, tick_hz) = (&c.thresholds, c.tick_hz);
        let hz = positive(t.load_filter_hz, "thresholds.load_filter_hz")?;
        let health_step = positive(t.health_rate_per_s, "thresholds.health_rate_per_s")?
            * f64::from(SLOW.ticks)
            * (1.0 / tick_hz);
        require(health_step < 0.5, "thresholds.health_rate_per_s")?;
        let max_load = positive(t.max_load_nm, "thresholds.max_load_nm")?;
        let (m, mu) = (&c.mechanism, finite(c.capacity_mu, "capacity_mu")?);
        let service = m.pack_capacity_nm(m.quasi_static_pressing_force_n(max_load), mu) / max_load;
        // Health ≤ 2 keeps `h · service` within MARGIN_MAX.
        let most = f64::from(MARGIN_MAX.to_bits() >> 17);
        require(service > 0.0 && service < most, "capacity_mu")?;
        let u = finite(t.capacity_uncertainty, "thresholds.capacity_uncertainty")?;
        require((0.0..1.0).contains(&u), "thresholds.capacity_uncertainty")?;
        Ok(LoadSettings {
            alpha: filter_gain(hz, tick_hz, SLOW, "thresholds.load_filter_hz")?,
            known_ticks: ticks(
                3.0 / (core::f64::consts::TAU * hz),
                tick_hz,
                "thresholds.load_filter_hz",
            )?,
            min_margin: scale(
                positive(t.min_capacity_margin, "thresholds.min_capacity_margin")?,
                "thresholds.min_capacity_margin",
            )?,
            service_margin: q16(service, "capacity_mu")?,
            service_margin_low: q16(service * (1.0 - u), "thresholds.capacity_uncertainty")?,
            health_step: ((health_step * Q16_ONE + 0.5) as i32).max(1),
            learn_opposed: t.opposed_braking_share >= 1.0,
        })
    }

    /// The load filter's gain after `learned` ticks of learning: the running mean's `1/k` over
    /// its first `k` slow-lane slots while that exceeds `alpha`, so the estimate starts from its
    /// first sample instead of zero and carries no start-up bias when it becomes known.
    fn gain(&self, learned: u32) -> Gain {
        let k = learned / SLOW.ticks + 1;
        let mean = (1u32 << 16).checked_div(k).unwrap_or(0);
        Gain::from_bits(u16::try_from(mean).unwrap_or(u16::MAX)).max(self.alpha)
    }

    /// The capacity margin at the largest expected load for pack health `h`, and its lower
    /// bound, which never credits the pack with more than its model (`min(h, 1)`).
    pub fn margins(&self, h: Q16) -> (Q16, Q16) {
        (
            mul_q16(h, self.service_margin),
            mul_q16(h.min(Q16::ONE), self.service_margin_low),
        )
    }
}

/// The load estimate: learning (a running mean of its first samples, then the filter) until
/// the filter has run three time constants, then known; held with the drive off. Known but
/// *unseen* when last learned aiding the motion of a spring-only pack, which overruns on almost
/// no drive torque whatever the load: no estimate resting on it is trusted. *Settled*: known,
/// its sign read from the first lock's time (`lock_times`), untrusted until a drive learns it
/// on a decided reading.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum LoadEstimate {
    Learning(Q16),
    Known(Q16),
    Unseen(Q16),
    Settled(Q16),
}

impl LoadEstimate {
    #[inline]
    pub fn value(self) -> Q16 {
        match self {
            LoadEstimate::Learning(x)
            | LoadEstimate::Known(x)
            | LoadEstimate::Unseen(x)
            | LoadEstimate::Settled(x) => x,
        }
    }

    #[inline]
    pub fn known(self) -> Option<Q16> {
        match self {
            LoadEstimate::Known(x) | LoadEstimate::Unseen(x) | LoadEstimate::Settled(x) => Some(x),
            LoadEstimate::Learning(_) => None,
        }
    }
}

/// Capacity and margin floor for one load value, recomputed when it changes; `available` for
/// one health value.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug)]
pub(crate) struct LoadCache {
    load: Q16,
    alt: Option<Q16>,
    /// Static capacity `μ_s·c·(F_s + k·|M̂|)` of the pack clamped by the load (drive off).
    pub capacity: Q16,
    /// The braking envelope's deceleration torques.
    pub decel: Decel,
    /// `min_capacity_margin · |M̂|`.
    pub margin_floor: Q16,
    health: Q16,
    /// `health · capacity`.
    pub available: Q16,
}

/// The load stage's state.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug)]
pub(crate) struct Load {
    pub estimate: LoadEstimate,
    learn_ticks: u32,
    /// The known load at the drive's start (the drag check's reference).
    pub reference: Option<Q16>,
    pub health: Q16,
    pub cache: LoadCache,
    /// The driving reading's load, learned beside the estimate while the overrunning reading
    /// is a power-on guess (`Classified::guessed`): the estimate's sign is not known.
    pub alt: Option<Q16>,
}

impl Load {
    pub const fn new() -> Load {
        Load {
            estimate: LoadEstimate::Learning(Q16::ZERO),
            learn_ticks: 0,
            reference: None,
            health: Q16::ONE,
            cache: LoadCache {
                load: Q16::ZERO,
                alt: None,
                capacity: Q16::ZERO,
                decel: Decel {
                    along: Q16::ZERO,
                    opposed: Q16::ZERO,
                },
                margin_floor: Q16::ZERO,
                health: Q16::ONE,
                available: Q16::ZERO,
            },
            alt: None,
        }
    }

    /// At the drive's start the known load becomes the drag check's reference.
    pub fn drive_started(&mut self) {
        self.reference = self.estimate.known();
    }

    /// The driving reading changed before the load was known: what was learned under the
    /// abandoned reading is dropped and learning starts again.
    pub fn reading_changed(&mut self) {
        if let LoadEstimate::Learning(_) = self.estimate {
            (self.estimate, self.learn_ticks) = (LoadEstimate::Learning(Q16::ZERO), 0);
            self.alt = None;
        }
    }

    /// One slow-lane learning step with the load this call implies (`n` ticks elapsed) and, on
    /// a guessed reading, the other reading's; learning on a decided reading drops `alt`.
    /// `unseen`: the reading does not show the load ([`LoadEstimate::Unseen`]).
    pub fn learn(
        &mut self,
        k: &LoadSettings,
        implied: Q16,
        other: Option<Q16>,
        unseen: bool,
        n: u32,
    ) {
        let gain = k.gain(self.learn_ticks);
        self.alt = other.map(|y| lowpass(self.alt.unwrap_or(self.estimate.value()), y, gain));
        let value = lowpass(self.estimate.value(), implied, gain);
        self.learn_ticks = self.learn_ticks.saturating_add(SLOW.covered(n));
        let known = match self.estimate {
            LoadEstimate::Learning(_) if self.learn_ticks >= k.known_ticks => {
                // First known load of a drive that started without one (power-on while
                // driving): the drag check's reference from here on.
                if self.reference.is_none() {
                    self.reference = Some(value);
                }
                true
            }
            LoadEstimate::Learning(_) => false,
            LoadEstimate::Known(_) | LoadEstimate::Unseen(_) | LoadEstimate::Settled(_) => true,
        };
        self.estimate = match (known, unseen) {
            (false, _) => LoadEstimate::Learning(value),
            (true, false) => LoadEstimate::Known(value),
            (true, true) => LoadEstimate::Unseen(value),
        };
    }

    /// Refreshes the cache for `load` with its engaged `capacity` and the braking model's
    /// decelerations.
    pub fn refresh(&mut self, k: &LoadSettings, load: Q16, capacity: Q16, decel: Decel) {
        let load_abs = load.saturating_abs();
        self.cache = LoadCache {
            load,
            alt: self.alt,
            capacity,
            decel,
            margin_floor: Q16::from_bits(k.min_margin.apply(load_abs.to_bits())),
            health: self.health,
            available: Q16::ZERO,
        };
        self.cache_health();
    }

    /// The load is known and its sign is not a power-on guess (`alt`) (trust also needs the
    /// load seen, [`Load::trusted`]; the pack-health learning too).
    pub fn decided(&self) -> bool {
        self.estimate.known().is_some() && self.alt.is_none()
    }

    /// The first lock after a cut put a guessed load against the motion (`lock_times`): the
    /// driving reading's load stands, settled, its sign no longer a guess. Its size carries the
    /// drag's error, large beside a light load: untrusted.
    pub fn settle_against(&mut self) {
        if let Some(alt) = self.alt.take() {
            self.estimate = match self.estimate {
                LoadEstimate::Learning(_) => LoadEstimate::Learning(alt),
                _ => LoadEstimate::Settled(alt),
            };
        }
    }

    /// The load is known but unseen ([`LoadEstimate::Unseen`]).
    pub fn unseen(&self) -> bool {
        matches!(self.estimate, LoadEstimate::Unseen(_))
    }

    /// An unseen load read another way (`aiding`): known and seen from here on.
    pub fn seen(&mut self, value: Q16) {
        self.estimate = LoadEstimate::Known(value);
    }

    /// [`Load::decided`] and seen: an estimate resting on the load may be trusted.
    pub fn trusted(&self) -> bool {
        matches!(self.estimate, LoadEstimate::Known(_)) && self.alt.is_none()
    }

    /// Whether the cache was formed for another load.
    pub fn cache_stale(&self) -> bool {
        self.cache.load != self.estimate.value() || self.cache.alt != self.alt
    }

    /// One slow-lane health step (sign-LMS, no division): the measured braking torque along
    /// the motion against the healthy pack's.
    pub fn learn_health(&mut self, k: &LoadSettings, measured_along: Q16) {
        let predicted = mul_q16(self.health, self.cache.capacity);
        let step = if measured_along > predicted {
            k.health_step
        } else {
            -k.health_step
        };
        self.health = Q16::from_bits(
            self.health
                .to_bits()
                .saturating_add(step)
                .clamp(0, HEALTH_MAX),
        );
        if self.cache.health != self.health {
            self.cache_health();
        }
    }

    /// `available` for the present health.
    fn cache_health(&mut self) {
        let c = &mut self.cache;
        c.health = self.health;
        c.available = mul_q16(self.health, c.capacity);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_change_of_reading_before_the_load_is_known_restarts_learning() {
        let k = LoadSettings::new(&Config::default()).expect("default configuration");
        let mut load = Load::new();
        // Learned under the overrunning reading (one call per slow-lane slot): 60 N·m, not known.
        for _ in 0..k.known_ticks / SLOW.ticks / 2 {
            load.learn(&k, Q16::from_num(60), None, false, 1);
        }
        assert!(load.estimate.known().is_none() && load.estimate.value() > Q16::from_num(10));
        load.reading_changed();
        assert_eq!(load.estimate, LoadEstimate::Learning(Q16::ZERO));
        // Under the new reading the load is known after the full learning time, near −10 N·m.
        let mut calls = 0;
        while load.estimate.known().is_none() {
            load.learn(&k, Q16::from_num(-10), None, false, 1);
            calls += 1;
        }
        assert!(calls * SLOW.ticks >= k.known_ticks);
        let v = load.estimate.value().to_num::<f64>();
        assert!((-10.0..-9.0).contains(&v), "{v}");
        assert_eq!(load.reference, Some(load.estimate.value()));
        // A known load is kept through a change of reading.
        load.reading_changed();
        assert!(load.estimate.known().is_some());
    }

    #[test]
    fn a_steady_load_is_known_without_a_start_up_bias() {
        let k = LoadSettings::new(&Config::default()).expect("default configuration");
        let mut load = Load::new();
        // The first sample is taken whole; a filter started from zero would stand 5 % short
        // after its three time constants.
        load.learn(&k, Q16::from_num(12), None, false, 1);
        assert!((load.estimate.value() - Q16::from_num(12)).abs() < Q16::from_num(0.001));
        while load.estimate.known().is_none() {
            load.learn(&k, Q16::from_num(12), None, false, 1);
        }
        let v = load.estimate.value().to_num::<f64>();
        assert!((v - 12.0).abs() < 0.01, "{v}");
        // Once known, a new load is followed at the filter's own gain, not restarted.
        let before = load.estimate.value();
        load.learn(&k, Q16::from_num(20), None, false, 1);
        let step = (load.estimate.value() - before).to_num::<f64>();
        assert!(
            (step - 8.0 * k.alpha.to_num::<f64>()).abs() < 0.001,
            "{step}"
        );
    }
}
