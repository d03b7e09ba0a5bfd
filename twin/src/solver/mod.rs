//! The integrator: an error-controlled, L-stable linearly-implicit Rosenbrock method with event
//! location (the default), and the diffsol peer (`peer` feature) behind the same
//! [`SegmentSolver`]; the peer is faster at matched accuracy but stays opt-in until the goldens
//! move with it (docs/model.md "Speed", docs/decisions.md issue 18).

pub mod linalg;
#[cfg(feature = "peer")]
pub mod peer;
pub mod rosenbrock;

pub use rosenbrock::{
    EventLoopGuard, Integrator, OdeSystem, Sampler, SolverError, SolverOptions, SolverStats,
};

/// Anything that integrates an [`OdeSystem`] over one segment with samples and events.
pub trait SegmentSolver {
    /// Integrate `y` over `(t0, t1)`, calling `observe` at the sampler's times in `(t0, t1]`.
    fn integrate<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        span: (f64, f64),
        y: &mut [f64],
        sampler: &mut Sampler,
        observe: &mut dyn FnMut(&S, f64, &[f64]),
    ) -> Result<(), SolverError>;
    /// Work counters so far.
    fn stats(&self) -> SolverStats;
}

impl SegmentSolver for Integrator {
    fn integrate<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        span: (f64, f64),
        y: &mut [f64],
        sampler: &mut Sampler,
        observe: &mut dyn FnMut(&S, f64, &[f64]),
    ) -> Result<(), SolverError> {
        Integrator::integrate(self, sys, span, y, sampler, observe)
    }
    fn stats(&self) -> SolverStats {
        self.stats
    }
}
