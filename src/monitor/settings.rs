//! The monitor's settings: every stage's constants, built once from a [`Config`] by each
//! stage's builder (in data order), apart from the state the step changes.

use super::aiding::AidingSettings;
use super::checks::CheckSettings;
use super::config::{Config, ConfigError};
use super::convert::{positive, require};
use super::estimate::EstimateSettings;
use super::functional_test::TestSettings;
use super::load::{Load, LoadSettings};
use super::observe::ObserveSettings;
use super::pack::PackSettings;
use super::scene::SceneSettings;
use super::sense::SenseSettings;

/// Every stage's settings, converted from a [`Config`] (or read from a configuration block).
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    pub(crate) sense: SenseSettings,
    pub(crate) observe: ObserveSettings,
    pub(crate) pack: PackSettings,
    pub(crate) scene: SceneSettings,
    pub(crate) load: LoadSettings,
    pub(crate) estimate: EstimateSettings,
    pub(crate) checks: CheckSettings,
    pub(crate) functional_test: TestSettings,
    /// A spring-only pack's aiding load from its braking, once commissioning identified it.
    pub(crate) aiding: Option<AidingSettings>,
    /// No estimate is trusted unless the monitor was set for its plant.
    pub(crate) commissioned: bool,
}

impl Settings {
    pub(crate) fn new(c: &Config) -> Result<Settings, ConfigError> {
        let tick_hz = positive(c.tick_hz, "tick_hz")?;
        require((100.0..=1.0e6).contains(&tick_hz), "tick_hz")?;
        let max_load = positive(c.thresholds.max_load_nm, "thresholds.max_load_nm")?;
        let (pack, ratios) = PackSettings::new(c, max_load)?;
        let sense = SenseSettings::new(c)?;
        let observe = ObserveSettings::new(c, &sense)?;
        Ok(Settings {
            sense,
            observe,
            pack,
            scene: SceneSettings::new(c, observe.settle_ticks)?,
            load: LoadSettings::new(c)?,
            estimate: EstimateSettings::new(c)?,
            checks: CheckSettings::new(c, &pack, &ratios)?,
            functional_test: TestSettings::new(c)?,
            aiding: AidingSettings::new(c)?,
            commissioned: c.commissioned,
        })
    }
}

impl Settings {
    /// `load`'s cache for its present load (capacity, margin floor, decelerations).
    pub(crate) fn refresh_load(&self, load: &mut Load) {
        let value = load.estimate.value();
        let capacity = self.pack.capacity(self.pack.clamped_force(value));
        let decel = self
            .checks
            .envelope
            .decelerations(capacity, value, load.alt);
        load.refresh(&self.load, value, capacity, decel);
    }
}
