//! Fixed-step explicit integration of a twin model (`TwinModel::rhs`), for the stability map:
//! explicit Euler and classical RK4 at a fixed step, with the model's discrete events applied
//! at the end of the step in which an event function changed sign (no location: that is what a
//! fixed-step real-time integrator would do).
//!
//! A run that produces a non-finite number, or a state beyond [`BLOWUP`] times the model's
//! scale in any variable, stops and is reported as [`Verdict::Diverged`] with the time; its
//! samples end there. No NaN ever reaches a sample.
//!
//! Shared by `cargo xtask bench` and `host-tests/tests/bench_stability.rs` (included there by
//! `#[path]`, since host-tests cannot depend on the xtask).

use noback_twin::model::TwinModel;

/// A state variable beyond this many times its scale counts as a blow-up.
pub const BLOWUP: f64 = 1e6;

/// The explicit methods.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Explicit {
    /// Forward Euler.
    Euler,
    /// Classical Runge–Kutta 4.
    Rk4,
}

impl Explicit {
    /// Short name.
    pub fn name(self) -> &'static str {
        match self {
            Explicit::Euler => "euler",
            Explicit::Rk4 => "rk4",
        }
    }
}

/// How a run ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Verdict {
    /// Reached the end with every value finite and bounded.
    Finished,
    /// Stopped at this time (s): a non-finite value or a blow-up.
    Diverged {
        /// Time of the first bad step (s).
        at_s: f64,
    },
}

/// The result of a fixed-step run.
#[derive(Clone, Debug)]
pub struct FixedRun {
    /// How it ended.
    pub verdict: Verdict,
    /// `(t, output angle, output speed)` every `sample_dt`, finite by construction.
    pub samples: Vec<(f64, f64, f64)>,
    /// Right-hand-side evaluations.
    pub rhs_evals: u64,
}

/// Integrates `model` from its initial state over `[0, duration_s]` with step `h_s`, sampling
/// every `sample_dt_s` (rounded to a whole number of steps).
pub fn integrate<M: TwinModel>(
    model: &mut M,
    method: Explicit,
    h_s: f64,
    duration_s: f64,
    sample_dt_s: f64,
) -> FixedRun {
    let n = model.dim();
    let scales = model.scales();
    let mut y = model.initial_state();
    let ne = model.event_count();
    let mut g0 = vec![0.0; ne];
    let mut g1 = vec![0.0; ne];
    let mut k = [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]];
    let mut tmp = vec![0.0; n];
    let steps = (duration_s / h_s).round() as u64;
    let every = ((sample_dt_s / h_s).round() as u64).max(1);
    let mut samples = Vec::with_capacity((steps / every) as usize + 1);
    let s0 = model.sample(0.0, &y);
    samples.push((0.0, s0.output_angle_rad, s0.output_speed_rad_s));
    let mut rhs_evals = 0_u64;
    let mut fired = Vec::new();
    model.events(0.0, &y, &mut g0);
    for i in 0..steps {
        let t = i as f64 * h_s;
        match method {
            Explicit::Euler => {
                model.rhs(t, &y, &mut k[0]);
                rhs_evals += 1;
                for (yj, kj) in y.iter_mut().zip(&k[0]) {
                    *yj += h_s * kj;
                }
            }
            Explicit::Rk4 => {
                let [k1, k2, k3, k4] = &mut k;
                model.rhs(t, &y, k1);
                for ((tj, yj), kj) in tmp.iter_mut().zip(&y).zip(k1.iter()) {
                    *tj = yj + 0.5 * h_s * kj;
                }
                model.rhs(t + 0.5 * h_s, &tmp, k2);
                for ((tj, yj), kj) in tmp.iter_mut().zip(&y).zip(k2.iter()) {
                    *tj = yj + 0.5 * h_s * kj;
                }
                model.rhs(t + 0.5 * h_s, &tmp, k3);
                for ((tj, yj), kj) in tmp.iter_mut().zip(&y).zip(k3.iter()) {
                    *tj = yj + h_s * kj;
                }
                model.rhs(t + h_s, &tmp, k4);
                rhs_evals += 4;
                for (j, yj) in y.iter_mut().enumerate() {
                    let d = k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j];
                    *yj += h_s / 6.0 * d;
                }
            }
        }
        let t1 = (i + 1) as f64 * h_s;
        let bad = y
            .iter()
            .zip(&scales)
            .any(|(v, s)| !v.is_finite() || v.abs() > BLOWUP * s.max(1e-12));
        if bad {
            return FixedRun {
                verdict: Verdict::Diverged { at_s: t1 },
                samples,
                rhs_evals,
            };
        }
        model.events(t1, &y, &mut g1);
        fired.clear();
        fired.extend(
            g0.iter()
                .zip(&g1)
                .enumerate()
                .filter(|(_, (a, b))| (**a <= 0.0) != (**b <= 0.0))
                .map(|(j, _)| j),
        );
        if !fired.is_empty() {
            model.on_event(t1, &mut y, &fired);
            model.events(t1, &y, &mut g1);
        }
        std::mem::swap(&mut g0, &mut g1);
        if (i + 1) % every == 0 {
            let s = model.sample(t1, &y);
            samples.push((t1, s.output_angle_rad, s.output_speed_rad_s));
        }
    }
    FixedRun {
        verdict: Verdict::Finished,
        samples,
        rhs_evals,
    }
}
