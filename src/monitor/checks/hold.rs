//! The held brake (`brake_slip`): the span of the output's travel since the brake first held
//! (creep: rattling inside the lost motion keeps it bounded, a slipping pack grows it), and
//! both shafts carried the same way (`slip.rs`, sooner for a slow slip).
//!
//! | quantity | format | range | resolution |
//! |---|---|---|---|
//! | creep span | `i32` counts, saturating | ±2^31 | 1 count |

use super::slip::{SlipCheck, SlipLimits};
use crate::monitor::config::{Config, ConfigError};
use crate::monitor::convert::{counts, positive};

/// The held brake's constants.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct HoldSettings {
    creep_counts: i32,
    slip: SlipLimits,
}

impl HoldSettings {
    pub fn new(c: &Config) -> Result<HoldSettings, ConfigError> {
        let out_rad = c.sensors.output_rad_per_count();
        Ok(HoldSettings {
            creep_counts: counts(
                positive(c.thresholds.creep_limit_rad, "thresholds.creep_limit_rad")? / out_rad,
                "thresholds.creep_limit_rad",
            )?,
            slip: SlipLimits::new(c)?,
        })
    }
}

/// The held brake's checks.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct HoldChecks {
    /// The creep span is measured (from the brake's first hold since the drive's cut).
    creep_valid: bool,
    creep: i32,
    creep_min: i32,
    creep_max: i32,
    slip: SlipCheck,
}

impl HoldChecks {
    /// The drive's cut: the next hold starts a new span.
    pub fn drive_cut(&mut self) {
        self.creep_valid = false;
        self.creep = 0;
    }

    /// An implausible reading or a drive edge: the common-slip check stops (a jump is no travel).
    pub fn disarm_slip(&mut self) {
        self.slip.disarm();
    }

    /// The brake locked: arm both checks unless a span is already measured.
    pub fn locked(&mut self, out: u32, motor: u32) {
        if !self.creep_valid {
            self.creep_valid = true;
            (self.creep, self.creep_min, self.creep_max) = (0, 0, 0);
            self.slip.arm(out, motor);
        }
    }

    /// `reset_flags`: the span is measured afresh (a reset while holding keeps the checks armed).
    pub fn restart(&mut self, out: u32, motor: u32) {
        (self.creep, self.creep_min, self.creep_max) = (0, 0, 0);
        self.slip.restart(out, motor);
    }

    /// Creep, every call with the drive off and a plausible output step.
    pub fn creep(&mut self, k: &HoldSettings, d_out: i32) -> bool {
        if !self.creep_valid {
            return false;
        }
        self.creep = self.creep.saturating_add(d_out);
        self.creep_min = self.creep_min.min(self.creep);
        self.creep_max = self.creep_max.max(self.creep);
        let slipped = self.creep_max.saturating_sub(self.creep_min) > k.creep_counts;
        if slipped {
            self.creep_valid = false;
        }
        slipped
    }

    /// The common-slip check, on its slow-lane slot with the drive off.
    pub fn common_slip(&mut self, k: &HoldSettings, out: u32, motor: u32) -> bool {
        let slipped = self.slip.slipping(&k.slip, out, motor);
        if slipped {
            self.creep_valid = false;
            self.slip.disarm();
        }
        slipped
    }
}
