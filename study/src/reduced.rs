//! A reduced model of the output shaft for the braking scenes, generic over the number format
//! and the integrator: the candidates of the speed-against-accuracy study (issue 6,
//! docs/speed-accuracy.md).
//!
//! # Model
//! Only the output shaft's rotation is dynamic, `J_s·ω̇ = M − T − M_sf`, in the **load frame**
//! (positive = the load's direction, the load `M = |M|` is positive). The axial force balance is
//! quasi-static, as in the twin's `paper` reading: the pressing force is the spring preload, plus
//! the ramp force `M·tanθ/r` while the load-holding ramp face is engaged (`δ ≥ 0`, with `δ` the
//! output's angle relative to the input side); the pack capacity is
//! `T_all = μ·(2N_f − 1)·r_f·F` with μ_s stuck and `mu_sliding` slipping (μ_s too in the paper
//! reading). Stick/slip is Table 1 (`noback::table1`, the monitor's rule) with a Karnopp band:
//! inside `|ω| < band` the pack holds up to `T_all` (`T = clamp(M, ±T_all)`), outside it slips
//! (`T = T_all·sgn ω`); after each step an
//! output inside the band that the pack can hold is set to rest (`ω = 0`). The band is one
//! step's largest speed change, so a zero crossing always lands in it.
//!
//! With the drive on, the output is carried at the speed reference and `δ = 0` (along the load
//! it rides the load face's switch, the twin's tracking mode: the pack slips holding back exactly
//! the load, at the mean pressing force that gives that torque; against it the pack is at spring
//! drag); with the drive
//! off the input side stays where it stopped, except that the output ramp's far face is a stop:
//! `δ ≥ −b` with the ramp backlash `b = 2·g_p1/(r·cosθ)` (it pushes the drag-held input side).
//!
//! State: angle `θ` and relative angle `δ` in the angle format `A`, speed `ω` in the format
//! `N`; `A` may be wider than `N` (the shipped-like mixed format keeps `I16F16` speeds and
//! torques and an `I32F32` angle). See [`num`] for the formats.
//!
//! # Integrators
//! [`Method`]: explicit Euler, semi-implicit (symplectic) Euler (speed first, then the angles
//! with the new speed), Heun's RK2, classical RK4, and the implicit trapezoidal rule. The
//! trapezoidal rule is solved by functional (fixed-point) iteration from an Euler predictor with
//! [`TRAPEZOID_ITERATIONS`] corrector passes: the right-hand side is piecewise constant in the
//! state outside the stick band (Lipschitz constant · dt/2 ≪ 1), so Newton's method would buy
//! nothing, and a fixed count keeps the step's cost bounded.
//!
//! Everything is `no_std`, allocation-free and panic-free; `step` has no division.

pub mod num;

use noback::mechanism::Mechanism;
use noback::table1::{table1, Motion};
use num::{Real, Widen};

/// Corrector passes of the trapezoidal rule.
pub const TRAPEZOID_ITERATIONS: u8 = 2;

/// The integrators.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Explicit (forward) Euler, order 1.
    Euler,
    /// Semi-implicit (symplectic) Euler, order 1: speed first, angles with the new speed.
    SemiImplicitEuler,
    /// Heun's method (explicit trapezoid), order 2.
    Rk2,
    /// Classical Runge–Kutta, order 4.
    Rk4,
    /// Implicit trapezoidal rule (order 2) by functional iteration.
    Trapezoidal,
}

impl Method {
    /// Every method.
    pub const ALL: [Method; 5] = [
        Method::Euler,
        Method::SemiImplicitEuler,
        Method::Rk2,
        Method::Rk4,
        Method::Trapezoidal,
    ];

    /// Short name.
    pub fn name(self) -> &'static str {
        match self {
            Method::Euler => "euler",
            Method::SemiImplicitEuler => "symplectic",
            Method::Rk2 => "rk2",
            Method::Rk4 => "rk4",
            Method::Trapezoidal => "trapezoid",
        }
    }

    /// Right-hand-side evaluations per step.
    pub fn rhs_per_step(self) -> u32 {
        match self {
            Method::Euler | Method::SemiImplicitEuler => 1,
            Method::Rk2 => 2,
            Method::Rk4 => 4,
            Method::Trapezoidal => 1 + u32::from(TRAPEZOID_ITERATIONS),
        }
    }
}

/// The model's parameters in SI units (f64, converted once by [`Reduced::new`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params {
    /// J_s (kg·m²).
    pub inertia_kg_m2: f64,
    /// |M| (N·m), acting in the positive (load) direction.
    pub load_nm: f64,
    /// Spring preload on the pack (N).
    pub spring_n: f64,
    /// Ramp factor tanθ/r (1/m).
    pub ramp_per_m: f64,
    /// Pack torque per newton with μ_s (m).
    pub cap_static_per_n_m: f64,
    /// Pack torque per newton while slipping (m).
    pub cap_sliding_per_n_m: f64,
    /// Output-bearing Coulomb torque μ_d·m_s·g·r_ms (N·m).
    pub bearing_nm: f64,
    /// Ramp backlash `2·g_p1/(r·cosθ)` (rad).
    pub backlash_rad: f64,
    /// Step (s).
    pub dt_s: f64,
}

impl Params {
    /// The parameters of `m` under load `load_nm` at step rate `rate_hz`, in the paper's reading
    /// (μ_s while slipping too).
    pub fn from_mechanism(m: &Mechanism, load_nm: f64, rate_hz: f64) -> Params {
        let tan = m.ramp_factor_per_m() * m.socket_radius_m;
        let cos = 1.0 / sqrt(1.0 + tan * tan);
        Params {
            inertia_kg_m2: m.output_inertia_kg_m2,
            load_nm: if load_nm < 0.0 { -load_nm } else { load_nm },
            spring_n: m.spring_preload_n(),
            ramp_per_m: m.ramp_factor_per_m(),
            cap_static_per_n_m: m.pack_torque_per_newton_m(m.mu_static),
            cap_sliding_per_n_m: m.pack_torque_per_newton_m(m.mu_static),
            bearing_nm: m.mu_dynamic
                * m.output_shaft_mass_kg
                * noback::mechanism::GRAVITY_M_S2
                * m.output_friction_radius_m,
            backlash_rad: 2.0 * m.socket_clearance_m / (m.socket_radius_m * cos),
            dt_s: if rate_hz > 0.0 { 1.0 / rate_hz } else { 1e-4 },
        }
    }

    /// Largest pack capacity (engaged, μ_s) (N·m).
    pub fn max_capacity_nm(&self) -> f64 {
        self.cap_static_per_n_m * (self.spring_n + self.load_nm * self.ramp_per_m)
    }

    /// The Karnopp band: the largest speed change of one step (rad/s).
    pub fn band_rad_s(&self) -> f64 {
        (self.load_nm + self.max_capacity_nm() + self.bearing_nm) / self.inertia_kg_m2 * self.dt_s
    }
}

/// `sqrt` for configuration time (Newton from above; exact to the last bits for x in 1e-6..1e6).
fn sqrt(x: f64) -> f64 {
    if x.is_nan() || x <= 0.0 {
        return 0.0;
    }
    let mut g = if x > 1.0 { x } else { 1.0 };
    for _ in 0..80 {
        g = 0.5 * (g + x / g);
    }
    g
}

/// The state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State<N, A> {
    /// Output angle from the start (rad, load frame).
    pub theta: A,
    /// Output speed (rad/s, load frame).
    pub omega: N,
    /// Output angle relative to the input side (rad); `δ ≥ 0` engages the load-holding face.
    pub delta: A,
}

/// Derivative of a state: `(θ̇, ω̇, δ̇)`.
#[derive(Clone, Copy, Debug)]
struct Deriv<N> {
    dtheta: N,
    domega: N,
    ddelta: N,
}

/// Constants in the model's formats.
#[derive(Clone, Copy, Debug)]
struct Consts<N: Real, A: Real> {
    load: N,
    spring: N,
    ramp_force: N,
    /// Pressing force while tracking (driven along the load): the pack slips at the load minus
    /// the bearing torque, `(M − M_sf)/cap_sliding`.
    tracking_force: N,
    cap_static: N::K,
    cap_sliding: N::K,
    bearing: N,
    inv_j: N::K,
    backlash: A,
    band: N,
    dt: N::K,
    half_dt: N::K,
    sixth_dt: N::K,
    dt_a: A::K,
    half_dt_a: A::K,
    sixth_dt_a: A::K,
}

impl<N: Real, A: Real> Consts<N, A> {
    fn new(p: &Params) -> Self {
        let dt = p.dt_s;
        Consts {
            load: N::from_f64(p.load_nm),
            spring: N::from_f64(p.spring_n),
            ramp_force: N::from_f64(p.load_nm * p.ramp_per_m),
            tracking_force: N::from_f64(if p.cap_sliding_per_n_m > 0.0 {
                (p.load_nm - p.bearing_nm) / p.cap_sliding_per_n_m
            } else {
                p.spring_n + p.load_nm * p.ramp_per_m
            }),
            cap_static: N::konst(p.cap_static_per_n_m),
            cap_sliding: N::konst(p.cap_sliding_per_n_m),
            bearing: N::from_f64(p.bearing_nm),
            inv_j: N::konst(if p.inertia_kg_m2 > 0.0 {
                1.0 / p.inertia_kg_m2
            } else {
                0.0
            }),
            backlash: A::from_f64(p.backlash_rad),
            band: N::from_f64(p.band_rad_s()),
            dt: N::konst(dt),
            half_dt: N::konst(dt / 2.0),
            sixth_dt: N::konst(dt / 6.0),
            dt_a: A::konst(dt),
            half_dt_a: A::konst(dt / 2.0),
            sixth_dt_a: A::konst(dt / 6.0),
        }
    }
}

/// What the model reports about one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Output<N> {
    /// Pressing force on the pack (N).
    pub pressing_n: N,
    /// Magnitude of the pack's braking torque (N·m).
    pub braking_nm: N,
    /// The pack holds the output at rest.
    pub stuck: bool,
}

/// The reduced model with speed/torque format `N`, angle format `A` and one integrator.
#[derive(Clone, Debug)]
pub struct Reduced<N: Real, A: Real = N> {
    c: Consts<N, A>,
    params: Params,
    method: Method,
    /// The state.
    pub state: State<N, A>,
    drive_on: bool,
    speed_ref: N,
    stuck: bool,
}

impl<N: Real + Widen<A>, A: Real> Reduced<N, A> {
    /// A model at rest at angle 0, drive off, with `method`.
    pub fn new(params: Params, method: Method) -> Self {
        Reduced {
            c: Consts::new(&params),
            params,
            method,
            state: State {
                theta: A::ZERO,
                omega: N::ZERO,
                delta: A::ZERO,
            },
            drive_on: false,
            speed_ref: N::ZERO,
            stuck: false,
        }
    }

    /// The parameters.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The integrator.
    pub fn method(&self) -> Method {
        self.method
    }

    /// Changes the step (configuration-time arithmetic: converts the constants again). Used for
    /// tick jitter.
    pub fn set_dt(&mut self, dt_s: f64) {
        self.params.dt_s = dt_s;
        self.c = Consts::new(&self.params);
    }

    /// Switches the drive: on, it carries the output at `speed_ref_rad_s` (load frame) with the
    /// ramps at rest against each other (`δ = 0`).
    pub fn set_drive(&mut self, on: bool, speed_ref_rad_s: f64) {
        self.drive_on = on;
        self.speed_ref = N::from_f64(speed_ref_rad_s);
        if on {
            self.state.omega = self.speed_ref;
            self.state.delta = A::ZERO;
            self.stuck = false;
        }
    }

    /// Whether the pack holds the output at rest.
    pub fn stuck(&self) -> bool {
        self.stuck
    }

    /// Pressing force (N) at state `s`.
    #[inline(always)]
    fn pressing(&self, s: &State<N, A>) -> N {
        if self.drive_on {
            // Driven along the load the output rides the load face's switch (the twin's tracking
            // mode): the pack slips holding back exactly the load, at the mean force that gives
            // that torque; against it, the input ramp keeps the pack at spring drag.
            if self.speed_ref > N::ZERO {
                self.c.tracking_force
            } else {
                self.c.spring
            }
        } else if s.delta >= A::ZERO {
            self.c.spring.add(self.c.ramp_force)
        } else {
            self.c.spring
        }
    }

    /// The right-hand side; also the pack torque it used (signed, on the output).
    #[inline(always)]
    fn rhs(&self, s: &State<N, A>) -> (Deriv<N>, N) {
        if self.drive_on {
            return (
                Deriv {
                    dtheta: self.speed_ref,
                    domega: N::ZERO,
                    ddelta: N::ZERO,
                },
                N::ZERO,
            );
        }
        let f = self.pressing(s);
        let w = s.omega;
        let c = &self.c;
        // Table 1 gives the pack's resistance to the load's demand; on the output it acts
        // against it. Karnopp: inside the band the pack holds up to its static capacity.
        let (net, pack) = if w.abs() < c.band {
            let pack = table1(Motion::Stuck, c.load, f.mulk(c.cap_static)).neg();
            (c.load.add(pack), pack)
        } else {
            let forward = w > N::ZERO;
            let pack = table1(Motion::Slipping { forward }, c.load, f.mulk(c.cap_sliding)).neg();
            let after_bearing = if forward {
                c.load.sub(c.bearing)
            } else {
                c.load.add(c.bearing)
            };
            (after_bearing.add(pack), pack)
        };
        // The far face is a stop: δ stays at −b while the output runs against the load.
        let ddelta = if s.delta <= c.backlash.neg() && w < N::ZERO {
            N::ZERO
        } else {
            w
        };
        (
            Deriv {
                dtheta: w,
                domega: net.mulk(c.inv_j),
                ddelta,
            },
            pack,
        )
    }

    /// `s + h·d`, with `h` given in both formats.
    #[inline(always)]
    fn advance(s: &State<N, A>, d: &Deriv<N>, h: N::K, h_a: A::K) -> State<N, A> {
        State {
            theta: s.theta.add(d.dtheta.widen().mulk(h_a)),
            omega: s.omega.add(d.domega.mulk(h)),
            delta: s.delta.add(d.ddelta.widen().mulk(h_a)),
        }
    }

    fn sum2(a: &Deriv<N>, b: &Deriv<N>) -> Deriv<N> {
        Deriv {
            dtheta: a.dtheta.add(b.dtheta),
            domega: a.domega.add(b.domega),
            ddelta: a.ddelta.add(b.ddelta),
        }
    }

    /// One step of the integrator, then the stick and stop projections.
    pub fn step(&mut self) {
        let s = self.state;
        let c = self.c;
        let mut next = match self.method {
            Method::Euler => {
                let (d, _) = self.rhs(&s);
                Self::advance(&s, &d, c.dt, c.dt_a)
            }
            Method::SemiImplicitEuler => {
                let (d, _) = self.rhs(&s);
                let omega = s.omega.add(d.domega.mulk(c.dt));
                let ddelta = if self.drive_on || (s.delta <= c.backlash.neg() && omega < N::ZERO) {
                    N::ZERO
                } else {
                    omega
                };
                let dtheta = if self.drive_on { self.speed_ref } else { omega };
                State {
                    theta: s.theta.add(dtheta.widen().mulk(c.dt_a)),
                    omega,
                    delta: s.delta.add(ddelta.widen().mulk(c.dt_a)),
                }
            }
            Method::Rk2 => {
                let (k1, _) = self.rhs(&s);
                let (k2, _) = self.rhs(&Self::advance(&s, &k1, c.dt, c.dt_a));
                Self::advance(&s, &Self::sum2(&k1, &k2), c.half_dt, c.half_dt_a)
            }
            Method::Rk4 => {
                let (k1, _) = self.rhs(&s);
                let (k2, _) = self.rhs(&Self::advance(&s, &k1, c.half_dt, c.half_dt_a));
                let (k3, _) = self.rhs(&Self::advance(&s, &k2, c.half_dt, c.half_dt_a));
                let (k4, _) = self.rhs(&Self::advance(&s, &k3, c.dt, c.dt_a));
                let k23 = Self::sum2(&k2, &k3);
                let sum = Self::sum2(&Self::sum2(&k1, &k4), &Self::sum2(&k23, &k23));
                Self::advance(&s, &sum, c.sixth_dt, c.sixth_dt_a)
            }
            Method::Trapezoidal => {
                let (k1, _) = self.rhs(&s);
                let mut y = Self::advance(&s, &k1, c.dt, c.dt_a);
                for _ in 0..TRAPEZOID_ITERATIONS {
                    let (k2, _) = self.rhs(&y);
                    y = Self::advance(&s, &Self::sum2(&k1, &k2), c.half_dt, c.half_dt_a);
                }
                y
            }
        };
        if self.drive_on {
            next.omega = self.speed_ref;
            next.delta = A::ZERO;
            self.stuck = false;
        } else {
            let neg_b = c.backlash.neg();
            if next.delta < neg_b {
                next.delta = neg_b;
            }
            // Stuck when inside the band and Table 1 carries the whole load.
            let cap = self.pressing(&next).mulk(c.cap_static);
            self.stuck = next.omega.abs() < c.band && table1(Motion::Stuck, c.load, cap) == c.load;
            if self.stuck {
                next.omega = N::ZERO;
            }
        }
        self.state = next;
    }

    /// Pressing force and braking torque at the current state.
    pub fn output(&self) -> Output<N> {
        let (_, pack) = self.rhs(&self.state);
        Output {
            pressing_n: self.pressing(&self.state),
            braking_nm: if self.drive_on && self.speed_ref > N::ZERO {
                // Driven along the load: the pack holds back exactly the load.
                self.c.load.sub(self.c.bearing)
            } else if self.drive_on {
                // Driven against the load: the pack is at spring drag, slipping.
                self.c.spring.mulk(self.c.cap_sliding)
            } else {
                pack.abs()
            },
            stuck: self.stuck,
        }
    }

    /// True while every state variable is a finite number (always for fixed point).
    pub fn is_finite(&self) -> bool {
        self.state.theta.is_finite() && self.state.omega.is_finite() && self.state.delta.is_finite()
    }
}

/// The braking scenes the reduced model covers, as the twin's built-ins run them: drive on at
/// 13.78 rad/s (against the load for `reverse`, along it for `forward`), cut at 0.2 s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrakingScene {
    /// Output speed while driven (rad/s, load frame): −13.78 reverse, +13.78 forward.
    pub speed_ref_rad_s: f64,
    /// Drive cut (s).
    pub release_s: f64,
}

impl BrakingScene {
    /// The paper's reverse-load case.
    pub const REVERSE: BrakingScene = BrakingScene {
        speed_ref_rad_s: -13.78,
        release_s: 0.2,
    };
    /// The paper's forward-load case.
    pub const FORWARD: BrakingScene = BrakingScene {
        speed_ref_rad_s: 13.78,
        release_s: 0.2,
    };

    /// Ticks before the cut at `rate_hz`.
    pub fn release_tick(&self, rate_hz: u32) -> u32 {
        let t = self.release_s * f64::from(rate_hz) + 0.5;
        if t > 0.0 {
            t as u32
        } else {
            0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fixed::types::{I16F16, I32F32};
    use noback::mechanism::TABLE2;

    fn braking<N: Real + Widen<A>, A: Real>(
        method: Method,
        scene: BrakingScene,
        rate: u32,
    ) -> (f64, bool) {
        let p = Params::from_mechanism(&TABLE2, 20.3, f64::from(rate));
        let mut m = Reduced::<N, A>::new(p, method);
        m.set_drive(true, scene.speed_ref_rad_s);
        let cut = scene.release_tick(rate);
        for k in 0..rate {
            if k == cut {
                m.set_drive(false, 0.0);
            }
            m.step();
        }
        (m.state.theta.to_f64(), m.stuck())
    }

    #[test]
    fn every_format_and_method_locks_both_braking_cases() {
        for method in Method::ALL {
            for scene in [BrakingScene::REVERSE, BrakingScene::FORWARD] {
                let (a64, s64) = braking::<f64, f64>(method, scene, 10_000);
                let (a32, s32) = braking::<f32, f32>(method, scene, 10_000);
                let (aq, sq) = braking::<I16F16, I32F32>(method, scene, 10_000);
                let (aw, sw) = braking::<I32F32, I32F32>(method, scene, 10_000);
                assert!(s64 && s32 && sq && sw, "{method:?} {scene:?}");
                for a in [a32, aq, aw] {
                    assert!((a - a64).abs() < 1e-3, "{method:?} {a} vs {a64}");
                }
            }
        }
    }

    #[test]
    fn held_output_carries_the_load() {
        let p = Params::from_mechanism(&TABLE2, 20.3, 10_000.0);
        let mut m = Reduced::<f64>::new(p, Method::Rk4);
        for _ in 0..100 {
            m.step();
        }
        let o = m.output();
        assert!(o.stuck);
        assert!((o.braking_nm - 20.3).abs() < 1e-9);
        assert!((o.pressing_n - TABLE2.quasi_static_pressing_force_n(20.3)).abs() < 1e-6);
        assert_eq!(m.state.omega, 0.0);
    }
}
