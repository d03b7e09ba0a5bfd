//! The integrator: an error-controlled, L-stable linearly-implicit Rosenbrock method with event
//! location, written here because the state is small (≤ 20) and the stiff-capable crates
//! (diffsol pulls faer and nalgebra) would multiply the workspace's cold build time
//! (docs/model.md, "Integrator").

pub mod linalg;
pub mod rosenbrock;

pub use rosenbrock::{Integrator, OdeSystem, Sampler, SolverError, SolverOptions, SolverStats};
