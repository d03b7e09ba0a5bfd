//! The integrator: diffsol's BDF (or its SDIRK methods) with the twin's event rule, behind the
//! twin's segment interface ([`Integrator::integrate`]); what it integrates is an [`OdeSystem`].

pub mod integrator;
pub mod system;

pub use integrator::{Integrator, Method};
pub use system::{EventLoopGuard, OdeSystem, Sampler, SolverError, SolverOptions, SolverStats};
