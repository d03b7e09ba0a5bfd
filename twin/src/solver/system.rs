//! What the integrator integrates and how it reports: the [`OdeSystem`] with its event functions
//! and discrete state, the settings, the work counters, the sample clock and the errors.

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
    /// First step tried after each (re)start (s).
    pub first_step_s: f64,
    /// Smallest step before giving up (s).
    pub min_step_s: f64,
    /// Largest number of attempted steps in one call.
    pub max_steps: u64,
}

impl Default for SolverOptions {
    fn default() -> Self {
        SolverOptions {
            tolerance: 1e-5,
            first_step_s: 1e-6,
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
    /// Rejected steps (error-test failures).
    pub rejected: u64,
    /// Right-hand-side evaluations (including those of the Jacobian).
    pub rhs_evals: u64,
    /// Iteration-matrix factorisations (linear solver setups).
    pub jacobians: u64,
    /// Located events.
    pub events: u64,
}

/// Events firing again and again at (within 1e-10 s of) one time: more than 200 is an event
/// loop, an error rather than a hang. One guard per integration.
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
    /// The state or its derivative became non-finite at `t_s`.
    NonFinite {
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
    /// diffsol's own error (a step below the minimum, a failed factorisation…), with its message.
    Diffsol {
        /// Time (s).
        t_s: f64,
        /// diffsol's message.
        message: String,
    },
}

impl std::fmt::Display for SolverError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SolverError::NonFinite { t_s } => write!(f, "non-finite state at t = {t_s:.6} s"),
            SolverError::TooManySteps { t_s } => write!(f, "too many steps at t = {t_s:.6} s"),
            SolverError::EventLoop { t_s } => {
                write!(f, "events fire without time advancing at t = {t_s:.6} s")
            }
            SolverError::Diffsol { t_s, message } => {
                write!(f, "diffsol at t = {t_s:.6} s: {message}")
            }
        }
    }
}

impl std::error::Error for SolverError {}

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

/// A strict sign change of an event function, the rule by which an event fires.
pub fn changed(g0: f64, g1: f64) -> bool {
    (g0 > 0.0 && g1 <= 0.0) || (g0 < 0.0 && g1 >= 0.0)
}
