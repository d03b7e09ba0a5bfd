//! Modified Rosenbrock triple of Shampine & Reichelt (MATLAB `ode23s`): second order, L-stable,
//! with a third-order error estimate, a free continuous extension for dense output and event
//! location, and a finite-difference Jacobian (the state is small).
//!
//! Steps: `W = I − h·d·J`, `k1 = W⁻¹f0`, `k2 = W⁻¹(f(y + h k1/2) − k1) + k1`,
//! `y1 = y + h·k2`, `k3 = W⁻¹(f(y1) − e32(k2 − f1) − 2(k1 − f0))`,
//! `err = h/6·(k1 − 2k2 + k3)`, with `d = 1/(2+√2)`, `e32 = 6+√2`.
//! Events: after each accepted step every event function is compared with its value at the step
//! start; a strict sign change is located by bisection on the continuous extension, the step is
//! cut there, and the system's [`OdeSystem::on_event`] may change its discrete state and the
//! state vector before integration restarts.

use super::linalg::Lu;

/// A system of ODEs with event functions and discrete state.
pub trait OdeSystem {
    /// Number of state variables.
    fn dim(&self) -> usize;
    /// Typical magnitude of each state variable (sets the absolute tolerances and the
    /// Jacobian increments).
    fn scales(&self) -> Vec<f64>;
    /// `dy = f(t, y)`.
    fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]);
    /// Number of event functions.
    fn event_count(&self) -> usize;
    /// Event functions at `(t, y)`.
    fn events(&self, t: f64, y: &[f64], g: &mut [f64]);
    /// Called at a located event with the indices that changed sign; may change `y`.
    fn on_event(&mut self, t: f64, y: &mut [f64], fired: &[usize]);
}

/// Integrator settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverOptions {
    /// Relative tolerance; absolute tolerances are this times each state's scale.
    pub tolerance: f64,
    /// Largest step (s).
    pub max_step_s: f64,
    /// Smallest step before giving up (s).
    pub min_step_s: f64,
    /// Largest number of attempted steps in one call.
    pub max_steps: u64,
}

impl Default for SolverOptions {
    fn default() -> Self {
        SolverOptions {
            tolerance: 1e-5,
            max_step_s: 1e-3,
            min_step_s: 1e-14,
            max_steps: 20_000_000,
        }
    }
}

/// Work counters.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SolverStats {
    /// Accepted steps.
    pub steps: u64,
    /// Rejected steps (error test or non-finite stage).
    pub rejected: u64,
    /// Right-hand-side evaluations (including those of the Jacobian).
    pub rhs_evals: u64,
    /// Jacobian evaluations.
    pub jacobians: u64,
    /// Located events.
    pub events: u64,
}

/// Events firing again and again at (within 1e-10 s of) one time: more than 200 is an event
/// loop, an error rather than a hang. One guard per integration, shared by both solvers.
#[derive(Clone, Copy, Debug)]
pub struct EventLoopGuard {
    last_t: f64,
    here: u32,
}

impl Default for EventLoopGuard {
    fn default() -> Self {
        EventLoopGuard {
            last_t: f64::NAN,
            here: 0,
        }
    }
}

impl EventLoopGuard {
    /// A step without an event ends any run of them.
    pub fn step(&mut self) {
        self.here = 0;
    }

    /// An event fired at `t`.
    pub fn fired(&mut self, t: f64) -> Result<(), SolverError> {
        if (t - self.last_t).abs() < 1e-10 {
            self.here += 1;
            if self.here > 200 {
                return Err(SolverError::EventLoop { t_s: t });
            }
        } else {
            self.here = 0;
        }
        self.last_t = t;
        Ok(())
    }
}

/// Why an integration failed.
#[derive(Clone, Debug, PartialEq)]
pub enum SolverError {
    /// The step size fell below the minimum at time `t_s`.
    StepSizeUnderflow {
        /// Time reached (s).
        t_s: f64,
        /// Step size tried (s).
        h_s: f64,
    },
    /// The state or its derivative became non-finite at `t_s`.
    NonFinite {
        /// Time reached (s).
        t_s: f64,
    },
    /// The iteration matrix was singular at `t_s`.
    SingularMatrix {
        /// Time reached (s).
        t_s: f64,
    },
    /// More than the allowed number of steps.
    TooManySteps {
        /// Time reached (s).
        t_s: f64,
    },
    /// Events kept firing without time advancing (a chattering discrete state).
    EventLoop {
        /// Time reached (s).
        t_s: f64,
    },
    /// A peer solver's own error (the `peer` feature), with its message.
    Peer {
        /// Time (s).
        t_s: f64,
        /// The peer's message.
        message: String,
    },
}

impl std::fmt::Display for SolverError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SolverError::StepSizeUnderflow { t_s, h_s } => {
                write!(f, "step size underflow at t = {t_s:.6} s (h = {h_s:.3e} s)")
            }
            SolverError::NonFinite { t_s } => write!(f, "non-finite state at t = {t_s:.6} s"),
            SolverError::SingularMatrix { t_s } => {
                write!(f, "singular iteration matrix at t = {t_s:.6} s")
            }
            SolverError::TooManySteps { t_s } => write!(f, "too many steps at t = {t_s:.6} s"),
            SolverError::EventLoop { t_s } => {
                write!(f, "events fire without time advancing at t = {t_s:.6} s")
            }
            SolverError::Peer { t_s, message } => write!(f, "peer at t = {t_s:.6} s: {message}"),
        }
    }
}

impl std::error::Error for SolverError {}

const D: f64 = 0.292_893_218_813_452_5; // 1/(2+√2)
const E32: f64 = 7.414_213_562_373_095; // 6+√2

/// The integrator; keeps its step size and counters between calls.
#[derive(Clone, Debug)]
pub struct Integrator {
    /// Settings.
    pub options: SolverOptions,
    /// Counters.
    pub stats: SolverStats,
    h: f64,
}

/// Output sample times: the next one and the interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sampler {
    /// Next sample time (s).
    pub next_s: f64,
    /// Interval (s).
    pub dt_s: f64,
}

impl Sampler {
    /// Samples every `dt_s` from `first_s`.
    pub fn new(first_s: f64, dt_s: f64) -> Self {
        Sampler {
            next_s: first_s,
            dt_s,
        }
    }

    /// No samples.
    pub fn none() -> Self {
        Sampler {
            next_s: f64::INFINITY,
            dt_s: 1.0,
        }
    }
}

/// Dense output of one step.
struct Step<'a> {
    t0: f64,
    h: f64,
    y0: &'a [f64],
    k1: &'a [f64],
    k2: &'a [f64],
}

impl Step<'_> {
    fn eval(&self, t: f64, out: &mut [f64]) {
        let s = if self.h > 0.0 {
            (t - self.t0) / self.h
        } else {
            0.0
        };
        let a = s * (1.0 - s) / (1.0 - 2.0 * D);
        let b = s * (s - 2.0 * D) / (1.0 - 2.0 * D);
        for (i, o) in out.iter_mut().enumerate() {
            let y = self.y0.get(i).copied().unwrap_or(0.0);
            let k1 = self.k1.get(i).copied().unwrap_or(0.0);
            let k2 = self.k2.get(i).copied().unwrap_or(0.0);
            *o = y + self.h * (a * k1 + b * k2);
        }
    }
}

fn changed(g0: f64, g1: f64) -> bool {
    (g0 > 0.0 && g1 <= 0.0) || (g0 < 0.0 && g1 >= 0.0)
}

impl Integrator {
    /// A new integrator.
    pub fn new(options: SolverOptions) -> Self {
        Integrator {
            options,
            stats: SolverStats::default(),
            h: 0.0,
        }
    }

    /// Integrate `y` from `t0` to `t1`, calling `observe(system, t, y)` at the sample times of
    /// `sampler` that fall in `(t0, t1]` (the sampler is advanced).
    pub fn integrate<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        (t0, t1): (f64, f64),
        y: &mut [f64],
        sampler: &mut Sampler,
        observe: &mut dyn FnMut(&S, f64, &[f64]),
    ) -> Result<(), SolverError> {
        let sample_dt_s = sampler.dt_s;
        let next_sample_s = &mut sampler.next_s;
        let n = sys.dim();
        let scales = sys.scales();
        let tol = self.options.tolerance;
        let atol: Vec<f64> = scales.iter().map(|s| tol * s.abs().max(1e-300)).collect();
        let ne = sys.event_count();
        let mut t = t0;
        let mut f0 = vec![0.0; n];
        let mut f1 = vec![0.0; n];
        let mut f2 = vec![0.0; n];
        let mut k1 = vec![0.0; n];
        let mut k2 = vec![0.0; n];
        let mut k3 = vec![0.0; n];
        let mut ytmp = vec![0.0; n];
        let mut y1 = vec![0.0; n];
        let mut jac = vec![0.0; n * n];
        let mut fj = vec![0.0; n];
        let mut ft = vec![0.0; n];
        let mut g0 = vec![0.0; ne];
        let mut g1 = vec![0.0; ne];
        let mut gm = vec![0.0; ne];
        let mut ym = vec![0.0; n];
        let mut fresh = true; // f0, J and g0 must be recomputed
        let mut guard = EventLoopGuard::default();
        let mut attempts = 0u64;
        if self.h <= 0.0 {
            self.h = (self.options.max_step_s * 1e-3).max(1e-9);
        }
        let span = t1 - t0;
        while t < t1 - 1e-15 * span.abs().max(1.0) {
            attempts += 1;
            if attempts > self.options.max_steps {
                return Err(SolverError::TooManySteps { t_s: t });
            }
            if fresh {
                sys.rhs(t, y, &mut f0);
                self.stats.rhs_evals += 1;
                if f0.iter().any(|v| !v.is_finite()) || y.iter().any(|v| !v.is_finite()) {
                    return Err(SolverError::NonFinite { t_s: t });
                }
                sys.events(t, y, &mut g0);
                // Finite-difference Jacobian.
                for j in 0..n {
                    let yj = y.get(j).copied().unwrap_or(0.0);
                    let sc = scales.get(j).copied().unwrap_or(1.0).abs();
                    // Absolute increments from the variable's scale: a relative increment would grow with
                    // angles that grow without bound (θ = ωt) and spoil the stiff contact derivatives.
                    let dj = 1e-7 * sc.max(1e-6 * yj.abs()).max(1e-30);
                    ytmp.copy_from_slice(y);
                    if let Some(v) = ytmp.get_mut(j) {
                        *v = yj + dj;
                    }
                    sys.rhs(t, &ytmp, &mut fj);
                    self.stats.rhs_evals += 1;
                    for i in 0..n {
                        if let Some(slot) = jac.get_mut(i * n + j) {
                            *slot = (fj.get(i).copied().unwrap_or(0.0)
                                - f0.get(i).copied().unwrap_or(0.0))
                                / dj;
                        }
                    }
                }
                // Time derivative ∂f/∂t (zero for autonomous systems, one evaluation).
                let dt = 1e-7 * t.abs().max(1e-3);
                sys.rhs(t + dt, y, &mut fj);
                self.stats.rhs_evals += 1;
                for i in 0..n {
                    if let Some(slot) = ft.get_mut(i) {
                        *slot = (fj.get(i).copied().unwrap_or(0.0)
                            - f0.get(i).copied().unwrap_or(0.0))
                            / dt;
                    }
                }
                self.stats.jacobians += 1;
                fresh = false;
            }
            let mut h = self.h.min(self.options.max_step_s).min(t1 - t);
            if t1 - t - h < 1e-3 * h {
                h = t1 - t;
            }
            if h < self.options.min_step_s {
                return Err(SolverError::StepSizeUnderflow { t_s: t, h_s: h });
            }
            // W = I − h d J.
            let mut w = vec![0.0; n * n];
            for i in 0..n {
                for j in 0..n {
                    let idx = i * n + j;
                    let v = -h * D * jac.get(idx).copied().unwrap_or(0.0)
                        + if i == j { 1.0 } else { 0.0 };
                    if let Some(slot) = w.get_mut(idx) {
                        *slot = v;
                    }
                }
            }
            let Some(lu) = Lu::factor(n, w) else {
                self.stats.rejected += 1;
                self.h = h * 0.25;
                if self.h < self.options.min_step_s {
                    return Err(SolverError::SingularMatrix { t_s: t });
                }
                continue;
            };
            for i in 0..n {
                if let (Some(o), Some(a), Some(b)) = (k1.get_mut(i), f0.get(i), ft.get(i)) {
                    *o = a + h * D * b;
                }
            }
            lu.solve(&mut k1);
            for i in 0..n {
                if let (Some(o), Some(yi), Some(ki)) = (ytmp.get_mut(i), y.get(i), k1.get(i)) {
                    *o = yi + 0.5 * h * ki;
                }
            }
            sys.rhs(t + 0.5 * h, &ytmp, &mut f1);
            for i in 0..n {
                if let (Some(o), Some(a), Some(b)) = (k2.get_mut(i), f1.get(i), k1.get(i)) {
                    *o = a - b;
                }
            }
            lu.solve(&mut k2);
            for i in 0..n {
                if let (Some(o), Some(a)) = (k2.get_mut(i), k1.get(i)) {
                    *o += a;
                }
                if let (Some(o), Some(yi), Some(ki)) = (y1.get_mut(i), y.get(i), k2.get(i)) {
                    *o = yi + h * ki;
                }
            }
            sys.rhs(t + h, &y1, &mut f2);
            self.stats.rhs_evals += 2;
            for i in 0..n {
                let v = f2.get(i).copied().unwrap_or(0.0)
                    - E32 * (k2.get(i).copied().unwrap_or(0.0) - f1.get(i).copied().unwrap_or(0.0))
                    - 2.0 * (k1.get(i).copied().unwrap_or(0.0) - f0.get(i).copied().unwrap_or(0.0))
                    + h * D * ft.get(i).copied().unwrap_or(0.0);
                if let Some(o) = k3.get_mut(i) {
                    *o = v;
                }
            }
            lu.solve(&mut k3);
            let mut err2 = 0.0;
            let mut finite = true;
            for i in 0..n {
                let e = h / 6.0
                    * (k1.get(i).copied().unwrap_or(0.0) - 2.0 * k2.get(i).copied().unwrap_or(0.0)
                        + k3.get(i).copied().unwrap_or(0.0));
                let yi = y.get(i).copied().unwrap_or(0.0);
                let yn = y1.get(i).copied().unwrap_or(0.0);
                if !yn.is_finite() || !e.is_finite() {
                    finite = false;
                }
                let sc = atol.get(i).copied().unwrap_or(tol) + tol * yi.abs().max(yn.abs());
                err2 += (e / sc) * (e / sc);
            }
            let err = (err2 / n.max(1) as f64).sqrt();
            if !finite || err > 1.0 {
                self.stats.rejected += 1;
                let shrink = if finite {
                    (0.8 * err.powf(-1.0 / 3.0)).clamp(0.1, 0.5)
                } else {
                    0.1
                };
                self.h = h * shrink;
                if self.h < self.options.min_step_s {
                    return Err(if finite {
                        SolverError::StepSizeUnderflow {
                            t_s: t,
                            h_s: self.h,
                        }
                    } else {
                        SolverError::NonFinite { t_s: t }
                    });
                }
                continue;
            }
            // Accepted: look for events.
            sys.events(t + h, &y1, &mut g1);
            let step = Step {
                t0: t,
                h,
                y0: y,
                k1: &k1,
                k2: &k2,
            };
            let mut t_end = t + h;
            let mut fired: Vec<usize> = Vec::new();
            let any = g0.iter().zip(g1.iter()).any(|(&a, &b)| changed(a, b));
            if any {
                // Bisection on the dense output for the earliest sign change.
                let (mut lo, mut hi) = (t, t + h);
                let t_tol = 1e-13_f64.max(1e-12 * t.abs());
                while hi - lo > t_tol {
                    let mid = 0.5 * (lo + hi);
                    step.eval(mid, &mut ym);
                    sys.events(mid, &ym, &mut gm);
                    if g0.iter().zip(gm.iter()).any(|(&a, &b)| changed(a, b)) {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                t_end = hi;
                step.eval(hi, &mut ym);
                sys.events(hi, &ym, &mut gm);
                for (i, (&a, &b)) in g0.iter().zip(gm.iter()).enumerate() {
                    if changed(a, b) {
                        fired.push(i);
                    }
                }
                if fired.is_empty() {
                    // Sign change did not survive the bisection (grazing); accept the step.
                    t_end = t + h;
                }
            }
            // Samples up to t_end.
            while *next_sample_s <= t_end + 1e-12 * t_end.abs().max(1.0)
                && *next_sample_s <= t1 + 1e-12
            {
                step.eval(*next_sample_s, &mut ym);
                observe(sys, *next_sample_s, &ym);
                *next_sample_s += sample_dt_s;
            }
            self.stats.steps += 1;
            let grow = if err > 0.0 {
                (0.8 * err.powf(-1.0 / 3.0)).clamp(0.2, 5.0)
            } else {
                5.0
            };
            if fired.is_empty() {
                y.copy_from_slice(&y1);
                t += h;
                f0.copy_from_slice(&f2);
                g0.copy_from_slice(&g1);
                self.h = h * grow;
                // The Jacobian is re-evaluated at every step point (Rosenbrock methods need it).
                fresh = true;
                guard.step();
            } else {
                let t_start = step.t0;
                step.eval(t_end, &mut ym);
                y.copy_from_slice(&ym);
                t = t_end;
                self.stats.events += 1;
                sys.on_event(t, y, &fired);
                if y.iter().any(|v| !v.is_finite()) {
                    return Err(SolverError::NonFinite { t_s: t });
                }
                guard.fired(t)?;
                self.h =
                    (h * grow).min((t_end - t_start).max(self.options.min_step_s * 10.0) * 2.0);
                fresh = true;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y' = −1000 (y − cos t): stiff, smooth solution ≈ cos t.
    struct Stiff;
    impl OdeSystem for Stiff {
        fn dim(&self) -> usize {
            1
        }
        fn scales(&self) -> Vec<f64> {
            vec![1.0]
        }
        fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) {
            dy[0] = -1000.0 * (y[0] - t.cos());
        }
        fn event_count(&self) -> usize {
            0
        }
        fn events(&self, _: f64, _: &[f64], _: &mut [f64]) {}
        fn on_event(&mut self, _: f64, _: &mut [f64], _: &[usize]) {}
    }

    /// A ball falling onto the floor: an event at y = 0 reverses the speed.
    struct Bounce {
        bounces: u32,
    }
    impl OdeSystem for Bounce {
        fn dim(&self) -> usize {
            2
        }
        fn scales(&self) -> Vec<f64> {
            vec![1.0, 1.0]
        }
        fn rhs(&self, _: f64, y: &[f64], dy: &mut [f64]) {
            dy[0] = y[1];
            dy[1] = -9.81;
        }
        fn event_count(&self) -> usize {
            1
        }
        fn events(&self, _: f64, y: &[f64], g: &mut [f64]) {
            g[0] = y[0];
        }
        fn on_event(&mut self, _: f64, y: &mut [f64], _: &[usize]) {
            self.bounces += 1;
            y[0] = 0.0;
            y[1] = y[1].abs();
        }
    }

    #[test]
    fn stiff_problem_in_few_steps() {
        let mut integ = Integrator::new(SolverOptions {
            tolerance: 1e-4,
            max_step_s: 1.0,
            ..SolverOptions::default()
        });
        let mut y = [0.0];
        let mut smp = Sampler::none();
        integ
            .integrate(&mut Stiff, (0.0, 2.0), &mut y, &mut smp, &mut |_, _, _| {})
            .unwrap();
        // Particular solution (the transient e^{−1000t} has died out):
        // y = (λ² cos t + λ sin t)/(λ² + 1), λ = 1000.
        let l = 1000.0_f64;
        let exact = (l * l * 2.0_f64.cos() + l * 2.0_f64.sin()) / (l * l + 1.0);
        assert!((y[0] - exact).abs() < 1e-4, "{} vs {exact}", y[0]);
        // An explicit method would need ≥ 1000 steps (|λ|·h < 2).
        assert!(integ.stats.steps < 300, "{:?}", integ.stats);
    }

    #[test]
    fn locates_an_event_precisely() {
        let mut integ = Integrator::new(SolverOptions {
            tolerance: 1e-8,
            max_step_s: 0.1,
            ..SolverOptions::default()
        });
        let mut sys = Bounce { bounces: 0 };
        let mut y = [1.0, 0.0];
        let mut smp = Sampler::none();
        let t_hit = (2.0 / 9.81_f64).sqrt();
        integ
            .integrate(
                &mut sys,
                (0.0, t_hit * 1.5),
                &mut y,
                &mut smp,
                &mut |_, _, _| {},
            )
            .unwrap();
        assert_eq!(sys.bounces, 1);
        // After the bounce the ball rises with the impact speed: check energy is kept.
        let energy = 0.5 * y[1] * y[1] + 9.81 * y[0];
        assert!((energy - 9.81).abs() < 1e-5, "{energy}");
    }

    struct Blow;
    impl OdeSystem for Blow {
        fn dim(&self) -> usize {
            1
        }
        fn scales(&self) -> Vec<f64> {
            vec![1.0]
        }
        fn rhs(&self, _: f64, y: &[f64], dy: &mut [f64]) {
            dy[0] = y[0] * y[0];
        }
        fn event_count(&self) -> usize {
            0
        }
        fn events(&self, _: f64, _: &[f64], _: &mut [f64]) {}
        fn on_event(&mut self, _: f64, _: &mut [f64], _: &[usize]) {}
    }

    #[test]
    fn blow_up_is_an_error_not_nan() {
        let mut integ = Integrator::new(SolverOptions::default());
        let mut y = [1.0];
        let mut smp = Sampler::none();
        let r = integ.integrate(&mut Blow, (0.0, 2.0), &mut y, &mut smp, &mut |_, _, _| {});
        assert!(r.is_err(), "{y:?}");
    }
}
