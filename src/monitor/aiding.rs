//! A load that aids a spring-only pack's motion, read from its braking (a commissioned unit,
//! docs/monitor-design.md, "Aiding load"). While the drive runs, such a pack overruns on
//! almost no drive torque whatever the load, so the load is unseen (`LoadEstimate::Unseen`).
//! Cut, the load clamps the ramps and the pack brakes it: `J·α = D + g·M`, the output
//! decelerating from `ω₀` over the angle `θ` to the lock, `α = ω₀²/(2θ)`. Commissioning
//! identifies `J`, `D` and `g` (`AidingBraking`); at the lock the load is `(J·α − D)/g`.
//!
//! | step | when | does |
//! |---|---|---|
//! | [`Cut::at`] | the drive is cut (a unit with `AidingBraking`) | keeps the observer's speed |
//! | [`Cut::travel`] | every tick after | sums the output's travel (a braking may pass half a turn) and the ticks |
//! | [`Cut::read_so_far`] | once per window after it | `M̂` so far, `α = 2(ω₀·t − θ)/t²`: the pressing force's load until the lock |
//! | [`Cut::load_at_lock`] | the first lock after it, the load unseen | `M̂` along the motion, known if `M̂ ≥ D` and `g·M̂ ≥` [`CONDITIONING`]`·D` |
//!
//! Below `D` the ramps need not clamp (the seated pack brakes a lighter load alone), and the
//! reading is not taken: the load stays unseen and untrusted. Nor where the load's share of the
//! braking is small: the reading divides the error of `J·α` by `g·M̂/(J·α)`.
//!
//! | quantity | format | range | resolution |
//! |---|---|---|---|
//! | `ω₀²` | [`Q16`] rad²/s², saturating | 0 … 32 768 | 1.5e-5 |
//! | `ω₀²/θ` | `i32` Q24 rad²/s² per count, saturating | 0 … 128 | 6e-8 |
//! | braking angle | `i32` counts, saturating sum of the ticks' travel | ±2^31 counts | 1 count |
//! | ticks since the cut | `u32`, saturating | 5 days at 10 kHz | 1 tick |
//! | `ω₀·t − θ` | `i64` Q16 counts (`ω₀·h` in Q16 counts per tick, saturating) | ±2^31 counts (its Q32 product saturates beyond) | 1.5e-5 count |
//! | `α·h²/2` | `i32` Q32 counts per tick², saturating | ±0.5 (±38 000 rad/s² at 10 kHz) | 2.3e-10 |
//! | `J·α`, `M̂` | [`Q16`] N·m, saturating | ±32 768 | 1.5e-5 N·m |

use super::config::{Config, ConfigError};
use super::convert::{positive, q16, scale};
use super::load::Load;
use super::scale::{sat_i32, Scale};
use super::sense::Sensed;
use super::{mul_q16, observe::Observed};
use crate::fx::Q16;

/// The least `g·M̂/D` at which the reading is trusted, as a ratio (0.4): `J·α`'s error (≤ 0.6 %
/// on tuning seed 1616's forward loads) times `1 + D/(g·M̂)` stays within 2 %. Compared exactly,
/// `5·J·α ≥ (5 + 2)·D` in `i64`, no setting held for it (the part's RAM budget).
pub const CONDITIONING: (i64, i64) = (2, 5);

/// The least lag behind the cut's speed (`ω₀·t − θ`, counts) the braking so far is read from:
/// the encoder's count is then at most a quarter of it.
const SO_FAR_MIN_COUNTS: i64 = 4;

/// The reading's constants (present once commissioning identified them).
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct AidingSettings {
    /// `J/(2·rad per count)/256`: `ω₀²/θ` (Q24, per count) → `J·α` (Q16 N·m).
    torque_per: Scale<27>,
    /// `D`: the seated pack's braking torque.
    drag: Q16,
    /// `1/g`.
    per_gain: Scale<24>,
    /// `h/(rad per count)`: `ω₀` (Q16 rad/s) → Q16 counts per tick.
    counts_per_tick: Scale<29>,
    /// `2J·(rad per count)·tick_hz²·2^-16`: `α·h²/2` (Q32 counts per tick²) → `J·α` (Q16 N·m).
    so_far_torque_per: Scale<29>,
}

impl AidingSettings {
    /// `None` unless `c.aiding_braking` was identified.
    pub fn new(c: &Config) -> Result<Option<AidingSettings>, ConfigError> {
        let Some(a) = c.aiding_braking else {
            return Ok(None);
        };
        let inertia = positive(a.inertia_kg_m2, "aiding_braking.inertia_kg_m2")?;
        let gain = positive(a.load_gain, "aiding_braking.load_gain")?;
        let drag = positive(a.drag_nm, "aiding_braking.drag_nm")?;
        Ok(Some(AidingSettings {
            torque_per: scale(
                inertia / (2.0 * c.sensors.output_rad_per_count()) / 256.0,
                "aiding_braking.inertia_kg_m2",
            )?,
            drag: q16(drag, "aiding_braking.drag_nm")?,
            per_gain: scale(1.0 / gain, "aiding_braking.load_gain")?,
            counts_per_tick: scale(
                1.0 / (c.tick_hz * c.sensors.output_rad_per_count()),
                "tick_hz",
            )?,
            so_far_torque_per: scale(
                2.0 * inertia * c.sensors.output_rad_per_count() * c.tick_hz * c.tick_hz / 65_536.0,
                "aiding_braking.inertia_kg_m2",
            )?,
        }))
    }
}

/// Where the drive was cut.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Cut {
    w: Q16,
    /// Output counts since the cut.
    travel: i32,
    /// The load the braking so far implies (magnitude); [`NOT_READ`] before it is read.
    so_far: Q16,
    /// Ticks since the cut (saturating: 6.5 s at 10 kHz, past any braking).
    ticks: u16,
    /// A cut awaits its first lock (packed, no `Option`: the part's RAM budget).
    armed: bool,
}

/// [`Cut::so_far`] not yet read (a reading is floored at 0).
const NOT_READ: Q16 = Q16::from_bits(-1);

impl Cut {
    /// No cut awaiting a lock.
    pub const NONE: Cut = Cut {
        w: Q16::ZERO,
        travel: 0,
        so_far: NOT_READ,
        ticks: 0,
        armed: false,
    };

    /// At the cut: the observer's speed.
    pub fn at(o: &Observed) -> Cut {
        Cut {
            w: o.w,
            armed: true,
            ..Cut::NONE
        }
    }

    /// A cut awaits its first lock.
    pub fn armed(&self) -> bool {
        self.armed
    }

    /// At the lock: the cut it ends, if one was armed.
    pub fn take(&mut self) -> Option<Cut> {
        let c = core::mem::replace(self, Cut::NONE);
        c.armed.then_some(c)
    }

    /// Each tick after the cut: the output's travel and the ticks it took.
    #[inline]
    pub fn travel(&mut self, x: &Sensed) {
        self.travel = self.travel.saturating_add(x.d_out);
        let n = u16::try_from(x.n).unwrap_or(u16::MAX);
        self.ticks = self.ticks.saturating_add(n);
    }

    /// Once per window: the load (magnitude) that braked the output so far at a constant
    /// deceleration, `J·α = D + g·M̂`, `α = 2(ω₀·t − θ)/t²`, once the output lags the cut's
    /// speed by [`SO_FAR_MIN_COUNTS`]; floored at 0.
    pub fn read_so_far(&mut self, k: &AidingSettings) {
        let speed = i64::from(k.counts_per_tick.apply(self.w.saturating_abs().to_bits()));
        let along = i64::from(if self.w < Q16::ZERO {
            self.travel.saturating_neg()
        } else {
            self.travel
        });
        let ticks = i64::from(self.ticks);
        let lag = speed
            .saturating_mul(ticks)
            .saturating_sub(along.saturating_mul(1 << 16));
        if lag < SO_FAR_MIN_COUNTS << 16 {
            return;
        }
        let Some(decel) = lag
            .saturating_mul(1 << 16)
            .checked_div(ticks.saturating_mul(ticks))
        else {
            return;
        };
        let decel_torque = Q16::from_bits(k.so_far_torque_per.apply(sat_i32(decel)));
        let load = k
            .per_gain
            .apply(decel_torque.saturating_sub(k.drag).to_bits());
        self.so_far = Q16::from_bits(load.max(0));
    }

    /// The load the braking so far implies, once read.
    pub fn so_far(&self) -> Option<Q16> {
        (self.armed && self.so_far >= Q16::ZERO).then_some(self.so_far)
    }

    /// The load along the motion (signed as the speed at the cut) that braked the output from
    /// the cut to the lock, if it clamped the ramps (`M̂ ≥ D`) and the output ended past the
    /// cut along its motion; and whether the reading is conditioned well enough to trust.
    pub fn load_at_lock(self, k: &AidingSettings) -> Option<(Q16, bool)> {
        let back = self.w < Q16::ZERO;
        let angle = if back {
            self.travel.saturating_neg()
        } else {
            self.travel
        };
        if angle <= 0 {
            return None;
        }
        let w2 = i64::from(mul_q16(self.w, self.w).to_bits()) << 8;
        let per_count = sat_i32(w2.checked_div(i64::from(angle))?);
        let decel_torque = Q16::from_bits(k.torque_per.apply(per_count));
        let load = Q16::from_bits(
            k.per_gain
                .apply(decel_torque.saturating_sub(k.drag).to_bits()),
        );
        let along = if back { load.saturating_neg() } else { load };
        let (num, den) = CONDITIONING;
        let trusted =
            i64::from(decel_torque.to_bits()) * den >= i64::from(k.drag.to_bits()) * (den + num);
        (load >= k.drag).then_some((along, trusted))
    }
}

/// At a lock: a load `load` holds unseen, read from the braking since `cut` (`k` identified)
/// and conditioned, becomes known. Returns whether it did.
pub(crate) fn read_at_lock(cut: Option<Cut>, k: Option<&AidingSettings>, load: &mut Load) -> bool {
    match cut.zip(k).and_then(|(c, k)| c.load_at_lock(k)) {
        Some((m, true)) if load.unseen() => {
            load.seen(m);
            true
        }
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::monitor::config::AidingBraking;

    /// A unit with `J = 0.05`, `D = 8`, `g = 1.5`: an aiding 20 N·m braked from 10 rad/s needs
    /// `α = (8 + 30)/0.05 = 760` rad/s², over `θ = ω₀²/(2α)`.
    fn unit() -> (Config, AidingSettings) {
        let c = Config {
            aiding_braking: Some(AidingBraking {
                inertia_kg_m2: 0.05,
                drag_nm: 8.0,
                load_gain: 1.5,
            }),
            ..Config::default()
        };
        let k = AidingSettings::new(&c).ok().flatten().expect("identified");
        (c, k)
    }

    /// The load read after braking from `w` over `theta` in steps of at most 0.01 rad.
    fn lock_after(c: &Config, k: &AidingSettings, w: f64, theta: f64) -> Option<f64> {
        let counts = (theta / c.sensors.output_rad_per_count()).round() as i32;
        let mut cut = Cut::at(&Observed {
            w: Q16::from_num(w),
            ..Observed::NONE
        });
        let (mut left, step) = (counts, 26 * counts.signum());
        while left != 0 {
            let d_out = if left.abs() < step.abs() { left } else { step };
            cut.travel(&Sensed {
                d_out,
                ..Sensed::NONE
            });
            left -= d_out;
        }
        cut.load_at_lock(k).map(|(m, trusted)| {
            assert!(trusted, "a well-conditioned reading");
            m.to_num::<f64>()
        })
    }

    #[test]
    fn the_braking_angle_gives_the_load_along_the_motion() {
        let (c, k) = unit();
        let theta = 10.0_f64 * 10.0 / (2.0 * 760.0);
        let m = lock_after(&c, &k, 10.0, theta).expect("clamped");
        assert!((m - 20.0).abs() < 0.1, "{m}");
        // Turning the other way: the load is negative.
        let m = lock_after(&c, &k, -10.0, -theta).expect("clamped");
        assert!((m + 20.0).abs() < 0.1, "{m}");
        // A slow braking past half a turn (the counter's aliasing limit): 10 N·m at
        // J·α = 8 + 1.5·10 = 23 N·m from 20 rad/s takes 1.30 rad; at J = 0.5, 4.35 rad.
        let mut slow = c;
        slow.aiding_braking = slow.aiding_braking.map(|a| AidingBraking {
            inertia_kg_m2: 0.5,
            ..a
        });
        let ks = AidingSettings::new(&slow)
            .ok()
            .flatten()
            .expect("identified");
        let m = lock_after(&slow, &ks, 20.0, 400.0 / (2.0 * 23.0 / 0.5)).expect("clamped");
        assert!((m - 10.0).abs() < 0.05, "{m}");
    }

    /// The load read so far while braking at `J·α = D + g·M` from `w`, after `ms`.
    fn so_far_after(k: &AidingSettings, c: &Config, w: f64, load: f64, ms: u32) -> Option<f64> {
        let alpha = (8.0 + 1.5 * load) / 0.05 * w.signum();
        let mut cut = Cut::at(&Observed {
            w: Q16::from_num(w),
            ..Observed::NONE
        });
        let (h, per) = (1.0 / c.tick_hz, c.sensors.output_rad_per_count());
        let count = |t: f64| ((w * t - alpha * t * t / 2.0) / per).floor() as i32;
        for i in 1..=ms * 10 {
            let t = f64::from(i) * h;
            cut.travel(&Sensed {
                d_out: count(t) - count(t - h),
                n: 1,
                ..Sensed::NONE
            });
        }
        cut.read_so_far(k);
        cut.so_far().map(|m| m.to_num::<f64>())
    }

    #[test]
    fn the_braking_so_far_gives_the_load_before_the_lock() {
        let (c, k) = unit();
        // 20 N·m from 10 rad/s: α = 760 rad/s²; 4 ms in, the output lags the cut's speed by
        // 6.1e-3 rad (16 counts), the count within 1 of it: 6 % of J·α = 38 N·m, 1.6 N·m of M̂
        // (at 10 ms, 99 counts: 0.26 N·m).
        for (w, ms, within) in [(10.0, 4, 1.7), (10.0, 10, 0.3), (-10.0, 10, 0.3)] {
            let m = so_far_after(&k, &c, w, 20.0, ms).expect("read");
            assert!((m - 20.0).abs() < within, "{w} rad/s, {ms} ms: {m}");
        }
        // Too early to read (a lag under 4 counts), and a load below the drag floors at 0.
        assert_eq!(so_far_after(&k, &c, 10.0, 20.0, 1), None);
        assert_eq!(so_far_after(&k, &c, 10.0, -4.0, 20), Some(0.0));
    }

    #[test]
    fn a_load_small_beside_the_drag_is_not_conditioned() {
        let (c, k) = unit();
        // g = 1.5: J·α = 14 N·m reads 4 N·m, below D: not read. g = 0.1: J·α = 8.9 reads 9 N·m
        // at g·M̂/D = 0.11, not conditioned; J·α = 12 reads 40 N·m (0.5), conditioned.
        let theta = |j: f64, ja: f64| 100.0 / (2.0 * ja / j) / c.sensors.output_rad_per_count();
        let read = |k: &AidingSettings, counts: f64| {
            let mut cut = Cut::at(&Observed {
                w: Q16::from_num(10.0),
                ..Observed::NONE
            });
            cut.travel(&Sensed {
                d_out: counts.round() as i32,
                ..Sensed::NONE
            });
            cut.load_at_lock(k)
                .map(|(m, t)| (m.to_num::<f64>().round(), t))
        };
        assert_eq!(read(&k, theta(0.05, 14.0)), None);
        let mut weak = c;
        weak.aiding_braking = weak.aiding_braking.map(|a| AidingBraking {
            load_gain: 0.1,
            ..a
        });
        let kw = AidingSettings::new(&weak)
            .ok()
            .flatten()
            .expect("identified");
        assert_eq!(read(&kw, theta(0.05, 8.9)), Some((9.0, false)));
        assert_eq!(read(&kw, theta(0.05, 12.0)), Some((40.0, true)));
    }

    #[test]
    fn a_load_below_the_drag_or_no_braking_angle_is_not_read() {
        let (c, k) = unit();
        // 6 N·m would need J·α = 17 < D + g·D: left unseen.
        let theta = 10.0_f64 * 10.0 / (2.0 * (8.0 + 1.5 * 6.0) / 0.05);
        assert_eq!(lock_after(&c, &k, 10.0, theta), None);
        assert_eq!(lock_after(&c, &k, 10.0, 0.0), None);
        // Back past the cut: no braking along the motion to read.
        assert_eq!(lock_after(&c, &k, 10.0, -0.05), None);
        assert!(AidingSettings::new(&Config::default()) == Ok(None));
    }
}
