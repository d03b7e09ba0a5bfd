//! The stability map of `cargo xtask bench`: explicit fixed steps on the full physical model
//! (no event location) from 0.125 µs up past their limit, one parameter scaled at a time:
//! stable, diverged or inaccurate against the twin.

use super::charts;
use super::explicit::{self, Explicit, Verdict};
use super::opt;
use noback_twin::model::physical::Physical;
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::sim::{model_config, run_model};
use std::fmt::Write as _;
use std::path::Path;

/// Stability-map row.
#[derive(Clone, Debug)]
pub struct StabRow {
    pub method: &'static str,
    /// Which parameter is scaled: `k` (contact stiffness), `Jc` (connecting-shaft inertia,
    /// i.e. the inertia ratio against the output), `mu` (both friction coefficients), or `base`.
    pub parameter: &'static str,
    pub scale: f64,
    pub h_us: f64,
    pub verdict: &'static str,
    pub diverged_at_s: Option<f64>,
    pub speed_rms: Option<f64>,
    pub rhs_evals: u64,
}

/// Threshold of "inaccurate" for the explicit runs: output-speed RMS against the twin (rad/s).
pub const STAB_INACCURATE_RAD_S: f64 = 0.1;

/// The map: explicit Euler and RK4 on the full physical model over the steps, one parameter
/// scaled at a time.
pub fn run(quick: bool) -> Result<Vec<StabRow>, String> {
    let window = if quick { 0.01 } else { 0.03 };
    let steps_us: &[f64] = if quick {
        &[0.125, 0.5, 1.0, 2.0, 2.5, 4.0, 5.0, 10.0]
    } else {
        &[0.125, 0.25, 0.5, 1.0, 2.0, 2.5, 4.0, 5.0, 10.0, 20.0]
    };
    // What makes the full model stiff or soft: contact stiffness, the light connecting shaft
    // against the output (inertia ratio), and friction. One factor at a time around Table 2.
    let variations: &[(&'static str, f64)] = if quick {
        &[("base", 1.0)]
    } else {
        &[
            ("base", 1.0),
            ("k", 0.25),
            ("k", 4.0),
            ("Jc", 0.25),
            ("Jc", 4.0),
            ("mu", 0.5),
            ("mu", 1.5),
        ]
    };
    let mut rows = Vec::new();
    for &(parameter, ks) in variations {
        let mut scene = Scene::builtin(SceneKind::ReverseLoad, Reading::Physical);
        let m = &mut scene.mechanism;
        match parameter {
            "k" => m.contact_stiffness *= ks,
            "Jc" => m.connecting_inertia_kg_m2 *= ks,
            "mu" => {
                m.mu_static *= ks;
                m.mu_dynamic *= ks;
            }
            _ => {}
        }
        scene.duration_s = window;
        scene.tolerance = 1e-8;
        let reference = run_model(&scene, Physical::new(model_config(&scene)))
            .map_err(|e| format!("twin reference: {e:?}"))?
            .samples;
        for method in [Explicit::Euler, Explicit::Rk4] {
            for &h in steps_us {
                let mut model = Physical::new(model_config(&scene));
                let r = explicit::integrate(&mut model, method, h * 1e-6, window, 1e-4);
                let (verdict, at, rms) = match r.verdict {
                    Verdict::Diverged { at_s } => ("diverged", Some(at_s), None),
                    Verdict::Finished => {
                        let (mut s, mut n) = (0.0, 0.0);
                        for (t, _, w) in &r.samples {
                            if let Some(x) = reference.get((t * 1e4).round() as usize) {
                                s += (w - x.output_speed_rad_s).powi(2);
                                n += 1.0;
                            }
                        }
                        let rms = (s / f64::max(n, 1.0)).sqrt();
                        (
                            if rms > STAB_INACCURATE_RAD_S {
                                "inaccurate"
                            } else {
                                "stable"
                            },
                            None,
                            Some(rms),
                        )
                    }
                };
                eprintln!(
                    "bench: stability {} {parameter}×{ks} h={h} µs: {verdict}",
                    method.name()
                );
                // A converging method's verdict cannot improve with a coarser step: a run under
                // the threshold whose finer neighbour is over it is error cancellation near the
                // stability limit, rated inaccurate (its RMS stays in the CSV).
                let finer_inaccurate = rows.iter().any(|r: &StabRow| {
                    r.method == method.name()
                        && r.parameter == parameter
                        && r.scale == ks
                        && r.verdict == "inaccurate"
                });
                let verdict = if verdict == "stable" && finer_inaccurate {
                    "inaccurate"
                } else {
                    verdict
                };
                rows.push(StabRow {
                    method: method.name(),
                    parameter,
                    scale: ks,
                    h_us: h,
                    verdict,
                    diverged_at_s: at,
                    speed_rms: rms,
                    rhs_evals: r.rhs_evals,
                });
            }
        }
    }
    Ok(rows)
}

/// Writes `stability.csv` and `stability.svg` into `dir`.
pub fn write(dir: &Path, stab: &[StabRow]) -> Result<(), String> {
    let mut scsv = String::from(
        "method,parameter,scale,step_us,verdict,diverged_at_s,speed_rms_rad_s,rhs_evals\n",
    );
    for r in stab {
        let _ = writeln!(
            scsv,
            "{},{},{},{},{},{},{},{}",
            r.method,
            r.parameter,
            r.scale,
            r.h_us,
            r.verdict,
            opt(r.diverged_at_s),
            opt(r.speed_rms),
            r.rhs_evals
        );
    }
    std::fs::write(dir.join("stability.csv"), &scsv).map_err(|e| e.to_string())?;
    let lanes: Vec<charts::StabCell> = stab
        .iter()
        .map(|r| (r.method, r.parameter, r.scale, r.h_us, r.verdict))
        .collect();
    charts::stability(&dir.join("stability.svg"), &lanes)?;
    Ok(())
}
