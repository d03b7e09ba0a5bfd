//! The twin's integrator: an [`OdeSystem`] integrated by diffsol (variable-order BDF by default,
//! or the TR-BDF2 / ESDIRK34 SDIRK methods) with diffsol's root finding; at a root the twin's
//! event rule (the functions that changed sign) and `on_event` apply, then diffsol restarts.

use super::system::{
    changed, EventLoopGuard, OdeSystem, Sampler, SolverError, SolverOptions, SolverStats,
};
use diffsol::{
    NalgebraLU, NalgebraMat, NalgebraVec, OdeBuilder, OdeEquationsImplicit, OdeSolverMethod,
    OdeSolverStopReason, Vector,
};
use std::cell::{Cell, RefCell};

type M = NalgebraMat<f64>;
type LS = NalgebraLU<f64>;

/// Which diffsol method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Variable-order BDF (like ode15s / CVODE).
    Bdf,
    /// TR-BDF2 SDIRK (like ode23tb).
    TrBdf2,
    /// ESDIRK34.
    Esdirk34,
}

impl Method {
    /// Short name used on the pages.
    pub fn name(self) -> &'static str {
        match self {
            Method::Bdf => "diffsol-bdf",
            Method::TrBdf2 => "diffsol-trbdf2",
            Method::Esdirk34 => "diffsol-esdirk34",
        }
    }
}

/// The integrator; keeps its counters between segments.
#[derive(Clone, Debug)]
pub struct Integrator {
    /// Method.
    pub method: Method,
    /// Tolerance and step limits (a step below the minimum is an error).
    pub options: SolverOptions,
    /// Work counters (steps, rejected = error-test failures, RHS evaluations, events).
    pub stats: SolverStats,
}

impl Integrator {
    /// The twin's integrator: BDF.
    pub fn new(options: SolverOptions) -> Self {
        Self::with_method(Method::Bdf, options)
    }

    /// An integrator with another of diffsol's methods.
    pub fn with_method(method: Method, options: SolverOptions) -> Self {
        Integrator {
            method,
            options,
            stats: SolverStats::default(),
        }
    }
}

fn err(t: f64) -> impl Fn(diffsol::DiffsolError) -> SolverError {
    move |e| SolverError::Diffsol {
        t_s: t,
        message: e.to_string(),
    }
}

impl Integrator {
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
        let n = sys.dim();
        let ne = sys.event_count().max(1);
        let scales = sys.scales();
        let tol = self.options.tolerance;
        let atol: Vec<f64> = scales.iter().map(|s| tol * s.abs().max(1e-300)).collect();
        let cell = RefCell::new(sys);
        let rhs_count = Cell::new(0u64);
        let start = RefCell::new(y.to_vec());
        let f = |x: &[f64], _p: &[f64], t: f64, dy: &mut [f64]| {
            rhs_count.set(rhs_count.get() + 1);
            cell.borrow().rhs(t, x, dy);
        };
        // J·v by a forward difference scaled like the twin's Jacobian columns.
        let jv = |x: &[f64], _p: &[f64], t: f64, v: &[f64], out: &mut [f64]| {
            let s = v
                .iter()
                .zip(&scales)
                .map(|(vi, si)| vi.abs() / si.abs().max(1e-30))
                .fold(0.0, f64::max);
            if s == 0.0 {
                out.iter_mut().for_each(|o| *o = 0.0);
                return;
            }
            let eps = 1e-7 / s;
            let xp: Vec<f64> = x.iter().zip(v).map(|(a, b)| a + eps * b).collect();
            let mut f0 = vec![0.0; x.len()];
            let sys = cell.borrow();
            sys.rhs(t, x, &mut f0);
            sys.rhs(t, &xp, out);
            rhs_count.set(rhs_count.get() + 2);
            for (o, a) in out.iter_mut().zip(&f0) {
                *o = (*o - a) / eps;
            }
        };
        // diffsol wants at least one root function: a constant one when the system has none.
        let real = sys_events(&cell);
        let root = |x: &[f64], _p: &[f64], t: f64, g: &mut [f64]| {
            g.iter_mut().for_each(|v| *v = 1.0);
            if let Some(head) = g.get_mut(..real) {
                cell.borrow().events(t, x, head);
            }
        };
        let mut problem = OdeBuilder::<M>::new()
            .t0(t0)
            .h0(self.options.first_step_s)
            .rtol(tol)
            .atol(atol)
            .rhs_implicit(f, jv)
            .init(
                |_p: &[f64], _t: f64, y0: &mut [f64]| y0.copy_from_slice(&start.borrow()),
                n,
            )
            .root(root, ne)
            .build()
            .map_err(err(t0))?;
        // diffsol counts Newton failures over the solver's whole life (50 by default); a contact
        // run has thousands of harmless ones, so only the minimum step stops it.
        problem.ode_options.max_nonlinear_solver_failures = usize::MAX / 2;
        problem.ode_options.min_timestep = self.options.min_step_s;
        let r = match self.method {
            Method::Bdf => run(
                problem.bdf::<LS>().map_err(err(t0))?,
                &cell,
                (t0, t1),
                y,
                sampler,
                observe,
                &self.options,
            ),
            Method::TrBdf2 => run(
                problem.tr_bdf2::<LS>().map_err(err(t0))?,
                &cell,
                (t0, t1),
                y,
                sampler,
                observe,
                &self.options,
            ),
            Method::Esdirk34 => run(
                problem.esdirk34::<LS>().map_err(err(t0))?,
                &cell,
                (t0, t1),
                y,
                sampler,
                observe,
                &self.options,
            ),
        };
        let (st, events) = r?;
        self.stats.steps += st.number_of_steps as u64;
        self.stats.rejected += st.number_of_error_test_failures as u64;
        self.stats.jacobians += st.number_of_linear_solver_setups as u64;
        self.stats.events += events;
        self.stats.rhs_evals += rhs_count.get();
        Ok(())
    }
}

fn sys_events<S: OdeSystem>(cell: &RefCell<&mut S>) -> usize {
    cell.borrow().event_count()
}

/// Step `solver` to `t1`: samples from the interpolant, events by the twin's rule at each root.
fn run<'a, S, Eqn, Sol>(
    mut solver: Sol,
    cell: &RefCell<&mut S>,
    (t0, t1): (f64, f64),
    y: &mut [f64],
    sampler: &mut Sampler,
    observe: &mut dyn FnMut(&S, f64, &[f64]),
    options: &SolverOptions,
) -> Result<(diffsol::ode_solver::OdeSolverStatistics, u64), SolverError>
where
    S: OdeSystem,
    Eqn: OdeEquationsImplicit<T = f64, V = NalgebraVec<f64>> + 'a,
    Sol: OdeSolverMethod<'a, Eqn>,
{
    let ne = cell.borrow().event_count();
    let mut g0 = vec![0.0; ne];
    let mut gm = vec![0.0; ne];
    cell.borrow().events(t0, y, &mut g0);
    let mut t = t0;
    let mut events = 0u64;
    let mut guard = EventLoopGuard::default();
    let mut steps = 0u64;
    solver.set_stop_time(t1).map_err(err(t0))?;
    let mut start = StepStart::new(y.len());
    // At the step's own end (within rounding) the state itself. A step that lands a hair past the
    // stop time gets a negative step size from diffsol, which then refuses to interpolate in it
    // (BDF also rescales its history): there, the cubic Hermite with the system's own slopes.
    let interp = |s: &Sol, start: &StepStart, tm: f64| -> Result<Vec<f64>, SolverError> {
        let st = s.state();
        if (st.t - tm).abs() <= 1e-12 * tm.abs().max(1.0) {
            return Ok(st.y.clone_as_vec());
        }
        if st.h <= 0.0 && (start.t..st.t).contains(&tm) {
            let y1 = st.y.clone_as_vec();
            let (mut dy0, mut dy1) = (vec![0.0; y1.len()], vec![0.0; y1.len()]);
            cell.borrow().rhs(start.t, &start.y, &mut dy0);
            cell.borrow().rhs(st.t, &y1, &mut dy1);
            return Ok(start.hermite(&dy0, (st.t, &y1, &dy1), tm));
        }
        s.interpolate(tm).map(|v| v.clone_as_vec()).map_err(err(tm))
    };
    loop {
        steps += 1;
        if steps > options.max_steps {
            return Err(SolverError::TooManySteps { t_s: t });
        }
        start.record(solver.state().t, solver.state().y);
        let reason = solver.step().map_err(|e| SolverError::Diffsol {
            t_s: solver.state().t,
            message: e.to_string(),
        })?;
        let t_step = solver.state().t;
        // A step after a root return is not shortened to the stop time: past it, only the part
        // up to the segment's end counts (the next segment restarts from there).
        let t_hi = t_step.min(t1);
        let (t_end, fired) = match reason {
            OdeSolverStopReason::RootFound(tr, _) if tr <= t1 => {
                // The twin's rule: the functions changed between the last restart and just
                // past the root (bisection on diffsol's interpolant up to the step end).
                let (mut lo, mut hi) = (tr.min(t_hi), t_hi);
                let first = |tm: f64, gm: &mut [f64]| -> Result<bool, SolverError> {
                    let ym = interp(&solver, &start, tm)?;
                    cell.borrow().events(tm, &ym, gm);
                    Ok(g0.iter().zip(gm.iter()).any(|(&a, &b)| changed(a, b)))
                };
                if first(lo, &mut gm)? {
                    hi = lo;
                } else {
                    let t_tol = 1e-13_f64.max(1e-12 * t.abs());
                    while hi - lo > t_tol {
                        let mid = 0.5 * (lo + hi);
                        if first(mid, &mut gm)? {
                            hi = mid;
                        } else {
                            lo = mid;
                        }
                    }
                    first(hi, &mut gm)?;
                }
                let fired: Vec<usize> = (0..ne).filter(|&i| changed(g0[i], gm[i])).collect();
                (hi, fired)
            }
            _ => (t_hi, Vec::new()),
        };
        while sampler.next_s <= t_end + 1e-12 * t_end.abs().max(1.0) && sampler.next_s <= t1 + 1e-12
        {
            let ym = interp(&solver, &start, sampler.next_s.min(t_step))?;
            observe(&**cell.borrow(), sampler.next_s, &ym);
            sampler.next_s += sampler.dt_s;
        }
        if !fired.is_empty() {
            let mut ye = interp(&solver, &start, t_end)?;
            cell.borrow_mut().on_event(t_end, &mut ye, &fired);
            if ye.iter().any(|v| !v.is_finite()) {
                return Err(SolverError::NonFinite { t_s: t_end });
            }
            events += 1;
            guard.fired(t_end)?;
            cell.borrow().events(t_end, &ye, &mut g0);
            let mut dy = vec![0.0; ye.len()];
            cell.borrow().rhs(t_end, &ye, &mut dy);
            let ctx = *solver.state().y.context();
            {
                let st = solver.state_mut();
                st.y.copy_from(&NalgebraVec::from_slice(&ye, ctx));
                st.dy.copy_from(&NalgebraVec::from_slice(&dy, ctx));
                *st.t = t_end;
            }
            t = t_end;
            y.copy_from_slice(&ye);
            if t1 - t <= 1e-15 * t1.abs().max(1.0) {
                break;
            }
            solver.set_stop_time(t1).map_err(err(t))?;
            continue;
        }
        t = t_hi;
        if matches!(reason, OdeSolverStopReason::TstopReached) || t >= t1 {
            let yl = interp(&solver, &start, t)?;
            y.copy_from_slice(&yl);
            break;
        }
        // A plain step, or a root with no sign change under the twin's rule (grazing): carry on,
        // with the next step shortened to the stop time again.
        guard.step();
        let yl = interp(&solver, &start, t)?;
        cell.borrow().events(t, &yl, &mut g0);
        if matches!(reason, OdeSolverStopReason::RootFound(..)) {
            solver.set_stop_time(t1).map_err(err(t))?;
        }
    }
    Ok((solver.get_statistics().clone(), events))
}

/// The state where the step being taken began (diffsol keeps only the step's end).
struct StepStart {
    t: f64,
    y: Vec<f64>,
}

impl StepStart {
    fn new(n: usize) -> Self {
        Self {
            t: f64::NAN,
            y: vec![0.0; n],
        }
    }

    fn record(&mut self, t: f64, y: &NalgebraVec<f64>) {
        self.t = t;
        for (i, a) in self.y.iter_mut().enumerate() {
            *a = y.get_index(i);
        }
    }

    /// The cubic Hermite through this start (slope `dy0`) and the end `(t1, y1, dy1)`, at `t`
    /// between them.
    fn hermite(&self, dy0: &[f64], (t1, y1, dy1): (f64, &[f64], &[f64]), t: f64) -> Vec<f64> {
        let h = t1 - self.t;
        let s = (t - self.t) / h;
        let (h00, h10) = ((1.0 + 2.0 * s) * (1.0 - s).powi(2), s * (1.0 - s).powi(2));
        let (h01, h11) = (s * s * (3.0 - 2.0 * s), s * s * (s - 1.0));
        (0..self.y.len())
            .map(|i| h00 * self.y[i] + h10 * h * dy0[i] + h01 * y1[i] + h11 * h * dy1[i])
            .collect()
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

    #[test]
    fn the_step_fallback_is_exact_on_a_cubic() {
        // y = t³ − 2t, y' = 3t² − 2 on [0.5, 1.5].
        let (y, dy) = (|t: f64| t * t * t - 2.0 * t, |t: f64| 3.0 * t * t - 2.0);
        let start = StepStart {
            t: 0.5,
            y: vec![y(0.5)],
        };
        for t in [0.5, 0.7, 1.0, 1.31, 1.5] {
            let v = start.hermite(&[dy(0.5)], (1.5, &[y(1.5)], &[dy(1.5)]), t)[0];
            assert!((v - y(t)).abs() < 1e-12, "{t}: {v} vs {}", y(t));
        }
    }
}
