//! Table 1 of the paper, the pack's stick/slip rule, once for every fixed-point and float user
//! (the monitor in `Q16`, the study crate's reduced models in each format it compares).
//!
//! ```
//! use noback::fx::Q16;
//! use noback::table1::{table1, Motion};
//! let (demand, cap) = (Q16::from_num(30), Q16::from_num(20));
//! assert_eq!(table1(Motion::Stuck, demand, cap), cap);
//! assert_eq!(table1(Motion::Stuck, -demand, cap), -cap);
//! assert_eq!(table1(Motion::Stuck, Q16::from_num(5), cap), Q16::from_num(5));
//! assert_eq!(table1(Motion::Slipping { forward: false }, demand, cap), -cap);
//! ```

use crate::fx::Q16;

/// A torque in some number format: what Table 1 needs of it.
pub trait Torque: Copy + PartialOrd {
    /// Zero.
    const ZERO: Self;
    /// `−self`, saturating where the format can overflow.
    fn negated(self) -> Self;
}

impl Torque for Q16 {
    const ZERO: Q16 = Q16::ZERO;
    #[inline]
    fn negated(self) -> Q16 {
        self.saturating_neg()
    }
}

/// The study crate's wide format (`noback_study`); here because of the orphan rule.
impl Torque for fixed::types::I32F32 {
    const ZERO: Self = Self::ZERO;
    #[inline]
    fn negated(self) -> Self {
        self.saturating_neg()
    }
}

impl Torque for f64 {
    const ZERO: f64 = 0.0;
    #[inline]
    fn negated(self) -> f64 {
        -self
    }
}

impl Torque for f32 {
    const ZERO: f32 = 0.0;
    #[inline]
    fn negated(self) -> f32 {
        -self
    }
}

/// The output's motion relative to the pack.
#[cfg_attr(
    feature = "config-block",
    derive(serde::Serialize, serde::Deserialize, Hash)
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Motion {
    /// Within the stick band (or held): the pack carries the demand.
    Stuck,
    /// Slipping: `forward` is the positive direction of motion.
    Slipping {
        /// The output turns the positive way.
        forward: bool,
    },
}

/// Table 1: stuck, the pack carries the demand up to its capacity `±cap`; slipping, its
/// capacity in the direction of the motion (the sign convention of the caller's demand).
#[inline]
pub fn table1<T: Torque>(motion: Motion, demand: T, capacity: T) -> T {
    match motion {
        Motion::Stuck => {
            // max/min, not `clamp`, which asserts min ≤ max: a negative capacity must bound.
            let cap = if capacity > T::ZERO {
                capacity
            } else {
                T::ZERO
            };
            let neg = cap.negated();
            if demand > cap {
                cap
            } else if demand < neg {
                neg
            } else {
                demand
            }
        }
        Motion::Slipping { forward: true } => capacity,
        Motion::Slipping { forward: false } => capacity.negated(),
    }
}
