//! The held brake (`brake_slip`): the span of the output's travel since the brake first held
//! (creep: rattling inside the lost motion keeps it bounded, a slipping pack grows it), and
//! both shafts carried the same way (`slip.rs`, sooner for a slow slip). A span travelled
//! while the output decelerates (a load turning it back until the ramps clamp) is a braking,
//! allowed twice the creep limit.
//!
//! | quantity | format | range | resolution |
//! |---|---|---|---|
//! | creep span | `i32` counts, saturating | ±2^31 | 1 count |
//! | peak speed | `i32` Q16 rad/s bits, saturating | 0 … 32 768 | 1.5e-5 rad/s |

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
    /// Highest |ω̂| since the span started (Q16 bits).
    peak_speed: i32,
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
            self.peak_speed = 0;
            self.slip.arm(out, motor);
        }
    }

    /// `reset_flags`: the span is measured afresh (a reset while holding keeps the checks armed).
    pub fn restart(&mut self, out: u32, motor: u32) {
        (self.creep, self.creep_min, self.creep_max) = (0, 0, 0);
        self.peak_speed = 0;
        self.slip.restart(out, motor);
    }

    /// Creep, every call with the drive off and a plausible output step `d_out`, with the
    /// observer's speed `w` (Q16 bits): decelerating = below ⅞ of the peak |ω̂| since the hold.
    pub fn creep(&mut self, k: &HoldSettings, d_out: i32, w: i32) -> bool {
        if !self.creep_valid {
            return false;
        }
        self.creep = self.creep.saturating_add(d_out);
        self.creep_min = self.creep_min.min(self.creep);
        self.creep_max = self.creep_max.max(self.creep);
        let span = self.creep_max.saturating_sub(self.creep_min);
        // Past the creep limit: slipped unless decelerating and within the braking span.
        let slipped = span > k.creep_counts
            && (span > k.creep_counts.saturating_mul(2)
                || w.saturating_abs() >= self.peak_speed.saturating_sub(self.peak_speed >> 3));
        if slipped {
            self.creep_valid = false;
        }
        slipped
    }

    /// The peak |ω̂| since the hold, on the slow lane's checks slot with the drive off (the
    /// creep check reads it only past its limit).
    pub fn track_speed(&mut self, w: i32) {
        self.peak_speed = self.peak_speed.max(w.saturating_abs());
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Drives the creep check with one count a tick at the speed `w(tick)` (rad/s) until it
    /// calls a slip; returns the span (rad) it called it at.
    fn slip_at(w: impl Fn(u32) -> f64) -> Option<f64> {
        let c = Config::default();
        let k = HoldSettings::new(&c).unwrap_or_else(|_| unreachable!());
        let mut h = HoldChecks::default();
        h.locked(0, 0);
        (0..4_000_u32).find_map(|t| {
            let bits = (w(t) * 65_536.0) as i32;
            h.track_speed(bits);
            h.creep(&k, 1, bits)
                .then(|| f64::from(h.creep_max - h.creep_min) * c.sensors.output_rad_per_count())
        })
    }

    #[test]
    fn a_decelerating_turn_back_is_allowed_twice_the_creep_limit() {
        let limit = Config::default().thresholds.creep_limit_rad;
        // Speeding up (a pack that cannot hold): called at the creep limit.
        let slip = slip_at(|t| 0.5 + 1e-3 * f64::from(t)).unwrap_or(0.0);
        assert!((limit..limit * 1.01).contains(&slip), "{slip}");
        // Steady travel: called at the creep limit too.
        let steady = slip_at(|_| 2.0).unwrap_or(0.0);
        assert!((limit..limit * 1.01).contains(&steady), "{steady}");
        // Up to 4 rad/s, then slowing (the ramps clamped, the load turns the output back):
        // only past twice the limit.
        let braking = slip_at(|t| if t < 300 { 4.0 } else { 3.0 }).unwrap_or(0.0);
        assert!(
            (2.0 * limit..2.0 * limit * 1.01).contains(&braking),
            "{braking}"
        );
    }
}
