//! Stick/slip state machine of the friction pack (paper Table 1), after Modelica's
//! `PartialFriction`: the pack is Free (no pressing force), sliding Forward or Backward, or
//! Stuck. While Stuck the body's speed is held at exactly zero and the friction torque is
//! whatever holds it (Table 1: `T = M`); it breaks loose only when the torque it must hold
//! exceeds the static capacity (Table 1: `T = T_all`). A sliding body that reaches zero speed
//! is re-decided once, at the located event, so the machine never chatters at zero speed:
//! the integrator locates the zero crossing, [`settle`] picks Stuck or the opposite direction,
//! and the state is reset to exactly zero speed.

use crate::pack::PackCapacity;

/// Mode of a friction contact.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrictionMode {
    /// No pressing force: no torque.
    Free,
    /// Sliding with positive speed: torque `−T_sliding`.
    Forward,
    /// Held at zero speed by up to the static capacity.
    Stuck,
    /// Sliding with negative speed: torque `+T_sliding`.
    Backward,
}

impl FrictionMode {
    /// Brake-state code used in traces: 0 released, 1 slipping, 2 locked.
    pub fn brake_state(self) -> u8 {
        match self {
            FrictionMode::Free => 0,
            FrictionMode::Forward | FrictionMode::Backward => 1,
            FrictionMode::Stuck => 2,
        }
    }
}

/// Speed band (rad/s) inside which a body is treated as at rest when a mode is decided.
pub const SPEED_BAND_RAD_S: f64 = 1e-6;

/// Decide the mode from the body speed, the torque the friction would have to hold
/// (`required_nm`: everything else acting on the body, positive = accelerating forward) and the
/// pack capacities.
pub fn settle(speed_rad_s: f64, required_nm: f64, cap: PackCapacity) -> FrictionMode {
    if cap.static_nm <= 0.0 && cap.sliding_nm <= 0.0 {
        return FrictionMode::Free;
    }
    if speed_rad_s > SPEED_BAND_RAD_S {
        FrictionMode::Forward
    } else if speed_rad_s < -SPEED_BAND_RAD_S {
        FrictionMode::Backward
    } else if required_nm.abs() <= cap.static_nm {
        FrictionMode::Stuck
    } else if required_nm > 0.0 {
        FrictionMode::Forward
    } else {
        FrictionMode::Backward
    }
}

/// Friction torque (N·m) on the body in `mode`; for Stuck it is `−required_nm` (the holding
/// torque), clamped to the static capacity.
pub fn torque_nm(mode: FrictionMode, required_nm: f64, cap: PackCapacity) -> f64 {
    match mode {
        FrictionMode::Free => 0.0,
        FrictionMode::Forward => -cap.sliding_nm,
        FrictionMode::Backward => cap.sliding_nm,
        FrictionMode::Stuck => (-required_nm).clamp(-cap.static_nm, cap.static_nm),
    }
}

/// Event function of the mode: the integrator stops where it changes sign.
/// Sliding: the speed (zero crossing). Stuck: static capacity minus |required| (breakaway).
/// Free: the static capacity (becomes positive when the pack closes).
pub fn event_value(
    mode: FrictionMode,
    speed_rad_s: f64,
    required_nm: f64,
    cap: PackCapacity,
) -> f64 {
    match mode {
        FrictionMode::Forward | FrictionMode::Backward => speed_rad_s,
        FrictionMode::Stuck => cap.static_nm - required_nm.abs(),
        FrictionMode::Free => {
            if cap.static_nm > 0.0 {
                1.0
            } else {
                -1.0
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CAP: PackCapacity = PackCapacity {
        static_nm: 59.0,
        sliding_nm: 33.4,
    };

    #[test]
    fn transitions() {
        assert_eq!(settle(1.0, 0.0, CAP), FrictionMode::Forward);
        assert_eq!(settle(-1.0, 100.0, CAP), FrictionMode::Backward);
        // At rest: holds what it can (Table 1, T = M).
        assert_eq!(settle(0.0, 20.3, CAP), FrictionMode::Stuck);
        assert_eq!(torque_nm(FrictionMode::Stuck, 20.3, CAP), -20.3);
        // Breakaway: the required torque exceeds the static capacity (Table 1, T = T_all).
        assert_eq!(settle(0.0, 60.0, CAP), FrictionMode::Forward);
        assert_eq!(settle(0.0, -60.0, CAP), FrictionMode::Backward);
        assert_eq!(torque_nm(FrictionMode::Forward, 60.0, CAP), -33.4);
        // No pressing force: free.
        let none = PackCapacity {
            static_nm: 0.0,
            sliding_nm: 0.0,
        };
        assert_eq!(settle(0.0, 1.0, none), FrictionMode::Free);
        assert_eq!(torque_nm(FrictionMode::Free, 1.0, none), 0.0);
    }

    #[test]
    fn stuck_breaks_loose_where_the_event_changes_sign() {
        assert!(event_value(FrictionMode::Stuck, 0.0, 58.0, CAP) > 0.0);
        assert!(event_value(FrictionMode::Stuck, 0.0, -59.5, CAP) < 0.0);
        assert!(event_value(FrictionMode::Forward, 0.1, 0.0, CAP) > 0.0);
        assert!(event_value(FrictionMode::Forward, -0.1, 0.0, CAP) < 0.0);
    }

    #[test]
    fn the_pack_only_dissipates() {
        // Sliding torque always opposes the speed; a stuck pack does no work (speed zero).
        for &w in &[-3.0, -1e-3, 1e-3, 3.0] {
            let mode = settle(w, 10.0, CAP);
            assert!(torque_nm(mode, 10.0, CAP) * w <= 0.0);
        }
    }
}
