//! The deterministic pages of `cargo xtask bench`: the speed–accuracy CSV, the cheapest model per
//! scene and the cost by core (errors and instruction counts: the same bytes on every run).

use super::{opt, Variant, EQUILIBRIUM_LABEL};
use std::fmt::Write as _;

/// Instructions per step (format, integrator, mean, max) of one core.
pub type CoreCosts = [(String, String, f64, f64)];

/// `speed-accuracy.csv`: every variant, then the shipped monitor's row.
pub fn speed_accuracy_csv(
    variants: &[Variant],
    shipped_insns: f64,
    monitor_paper: f64,
    monitor_phys: f64,
) -> String {
    let mut csv = String::from("family,format,method,rate_hz,scene,angle_rms_rad,speed_rms_rad_s,force_rms_pct,torque_rms_nm,lock_err_s,hold_rel,meets_targets,m3_insns_per_step,m3_insns_per_s,rhs_evals_per_s,torque_rms_physical_nm\n");
    for v in variants {
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{:.6e},{:.6e},{:.4},{:.6e},{:.5},{:.5},{},{},{},{},{}",
            v.family,
            v.format,
            v.method,
            v.rate_hz,
            v.scene,
            v.e.angle_rms,
            v.e.speed_rms,
            v.e.force_rms_pct,
            v.e.torque_rms,
            v.e.lock_err_s,
            v.e.hold_rel,
            v.e.meets_targets(),
            opt(v.m3_insns_per_step),
            opt(v.m3_per_s()),
            v.rhs_evals,
            opt(v.e_phys.map(|e| e.torque_rms))
        );
    }
    let _ = writeln!(
        csv,
        "shipped-monitor,I16F16+Scale+u32 angle,observer,10000,reverse_load,,,,{monitor_paper:.6e},,,,{shipped_insns:.1},{:.6e},,{monitor_phys:.6e}",
        shipped_insns * 1e4
    );
    csv
}

/// The cheapest variant's label per scene.
pub type Cheapest = Vec<(&'static str, String)>;

/// `cheapest-per-scene.md` and its rows for `--json`.
pub fn cheapest(
    variants: &[Variant],
    names: &[&'static str],
    shipped_insns: f64,
) -> Result<(String, Cheapest), String> {
    let mut md = String::from("# The cheapest model per scene\n\nWritten by `cargo xtask bench`. Cheapest = fewest Cortex-M3 instructions per simulated second among the candidates that meet the monitor's accuracy targets against the twin's `paper` reading at tolerance 1e-10: output-speed RMS ≤ 0.5 rad/s, pressing-force RMS ≤ 5 % of the loaded force, lock time within 10 ms, holding torque within 5 % (targets from docs/monitor-design.md). Candidates: every format × integrator × rate of the reduced model, and the quasi-static model with no state to advance (output at the drive's speed while driven, at rest once the drive is cut; 0 instructions of model step). The monitor runs, per scene it recognises, the model named here (`Monitor::scene_model`); `host-tests/tests/monitor_scene_models.rs` fails when they differ.\n\n| scene | cheapest variant | M3 insns/step | M3 insns/s | angle RMS (rad) | speed RMS (rad/s) | force RMS % | lock error (ms) |\n|---|---|---|---|---|---|---|---|\n");
    let mut cheapest_rows = Vec::new();
    for &name in names {
        let best = variants
            .iter()
            .filter(|v| {
                v.family != "shipped" && v.rate_hz > 0.0 && v.scene == name && v.e.meets_targets()
            })
            .min_by(|a, b| {
                a.m3_per_s()
                    .unwrap_or(f64::MAX)
                    .total_cmp(&b.m3_per_s().unwrap_or(f64::MAX))
            });
        match best {
            Some(v) => {
                let _ = writeln!(
                    md,
                    "| {name} | {} | {:.0} | {:.3e} | {:.2e} | {:.3} | {:.3} | {:.1} |",
                    v.label(),
                    v.m3_insns_per_step.unwrap_or(f64::NAN),
                    v.m3_per_s().unwrap_or(f64::NAN),
                    v.e.angle_rms,
                    v.e.speed_rms,
                    v.e.force_rms_pct,
                    v.e.lock_err_s * 1e3
                );
                cheapest_rows.push((name, v.label()));
            }
            None => {
                let _ = writeln!(md, "| {name} | none meets the targets | | | | | | |");
            }
        }
    }
    // Continuous closing: the reduced model has no drive-on engagement cycle (the paper
    // reading's 0.444 s limit cycle); the monitor's overrunning equilibrium is the only
    // candidate, measured through the monitor against the physical reading (its ground truth).
    let closing = crate::replay::twin_trace("continuous_closing")?;
    let closing_acc = host_tests::accuracy::compare(
        &closing,
        &host_tests::accuracy::run_monitor(&closing, noback::monitor::Config::default())?,
    );
    let _ = writeln!(
        md,
        "| continuous_closing | {EQUILIBRIUM_LABEL} | 0 | 0 | | | {:.3} | |",
        closing_acc.pressing_force_rmse_pct
    );
    cheapest_rows.push(("continuous_closing", EQUILIBRIUM_LABEL.to_string()));
    md.push_str("\nContinuous closing: the reduced model has no drive-on engagement cycle, so the only candidate is the monitor's overrunning equilibrium (`T = g₁·v − g₀` from the drive torque, no state); its force RMS above is the whole monitor against the twin's `physical` reading (% of the peak, the monitor's 10 % target, `cargo xtask monitor continuous_closing`).\n");
    let _ = writeln!(
        md,
        "\nThe shipped monitor (whole estimator: observer, model, flags) costs {shipped_insns:.1} M3 instructions per 10 kHz tick, its interrupt's part and its background call together ({:.3e} per simulated second).",
        shipped_insns * 1e4
    );
    Ok((md, cheapest_rows))
}

/// `cost-by-core.md`: the format that is cheap on an M3 (single-cycle 32×32→64 multiply) is not
/// necessarily cheap on an M0 (no long multiply, no FPU).
pub fn cost_by_core(m3: &CoreCosts, m0: &CoreCosts) -> String {
    let mut cores_md = String::from(
        "# Instructions per step by core\n\nWritten by `cargo xtask bench`; do not edit. \
         `noback-bench` under QEMU `-icount` (reverse-load braking, 3000 steps each).\n\n\
         | format | integrator | M3 mean | M3 max | M0 mean | M0 max | M0 / M3 |\n|---|---|---|---|---|---|---|\n",
    );
    for (f, m, mean3, max3) in m3 {
        if let Some((_, _, mean0, max0)) = m0.iter().find(|(a, b, _, _)| a == f && b == m) {
            let _ = writeln!(
                cores_md,
                "| {f} | {m} | {mean3:.0} | {max3:.0} | {mean0:.0} | {max0:.0} | {:.1} |",
                mean0 / mean3.max(1.0)
            );
        }
    }
    cores_md
}
