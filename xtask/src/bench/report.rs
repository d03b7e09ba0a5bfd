//! What `cargo xtask bench` prints: one JSON line (`--json`) or the tables.

use super::stability_map::StabRow;
use super::{pages, Fronts, MonitorPoint, Variant};
use std::time::Instant;

/// Everything the bench measured, as it prints it.
pub(super) struct Report<'a> {
    pub variants: &'a [Variant],
    pub fronts: &'a Fronts,
    pub monitor: &'a MonitorPoint,
    pub cheapest: &'a pages::Cheapest,
    pub stab: &'a [StabRow],
    pub t0: Instant,
}

impl Report<'_> {
    /// `--json`: everything on one line.
    pub(super) fn print_json(&self) {
        let vs: Vec<_> = self.variants
        .iter()
        .map(|v| {
            serde_json::json!({
                "family": v.family, "format": v.format, "method": v.method,
                "rate_hz": v.rate_hz, "scene": v.scene,
                "angle_rms_rad": v.e.angle_rms, "speed_rms_rad_s": v.e.speed_rms,
                "force_rms_pct": v.e.force_rms_pct, "torque_rms_nm": v.e.torque_rms,
                "lock_err_s": v.e.lock_err_s, "meets_targets": v.e.meets_targets(),
                "m3_insns_per_step": v.m3_insns_per_step, "host_ns_per_step": v.host_ns_per_step,
            })
        })
        .collect();
        let labels = |front: &[usize], pts: &[(f64, f64, String)]| -> Vec<String> {
            front
                .iter()
                .filter_map(|&i| pts.get(i).map(|p| p.2.clone()))
                .collect()
        };
        println!(
            "{}",
            serde_json::json!({
                "variants": vs,
                "pareto_reverse_load": labels(&self.fronts.front, &self.fronts.pts),
                "pareto_reverse_load_physical": labels(&self.fronts.front_phys, &self.fronts.pts_phys),
                "monitor": {"m3_insns_per_s": self.monitor.insns * 1e4, "torque_rms_paper_nm": self.monitor.err_paper, "torque_rms_physical_nm": self.monitor.err_phys},
                "cheapest": self.cheapest, "shipped_insns_per_step": self.monitor.insns,
                "stability": self.stab.iter().map(|r| serde_json::json!({"method": r.method, "parameter": r.parameter, "scale": r.scale, "h_us": r.h_us, "verdict": r.verdict})).collect::<Vec<_>>(),
                "seconds": self.t0.elapsed().as_secs_f64(),
            })
        );
    }

    /// Without `--json`: the tables on the terminal.
    pub(super) fn print_table(&self) {
        println!("format         method      rate   scene         angle RMS  speed RMS  force%  lock ms  M3 insn/step  host ns  targets");
        for v in self.variants.iter().filter(|v| v.family == "reduced") {
            println!(
            "{:<14} {:<11} {:>3}k  {:<12} {:>9.2e}  {:>9.2e}  {:>6.3}  {:>7.2}  {:>12.0}  {:>7.1}  {}",
            v.format,
            v.method,
            v.rate_hz / 1e3,
            v.scene,
            v.e.angle_rms,
            v.e.speed_rms,
            v.e.force_rms_pct,
            v.e.lock_err_s * 1e3,
            v.m3_insns_per_step.unwrap_or(f64::NAN),
            v.host_ns_per_step,
            if v.e.meets_targets() { "yes" } else { "no" }
        );
        }
        println!("\ntwin against its tightest run (paper 1e-10, physical 1e-9):");
        for v in self.variants.iter().filter(|v| v.family != "reduced") {
            println!(
            "{:<15} {:<24} {:<12} angle RMS {:.2e}  speed RMS {:.2e}  lock err {:.2} ms  rhs evals {:.0}  host ns/step {:.0}",
            v.family, v.method, v.scene, v.e.angle_rms, v.e.speed_rms, v.e.lock_err_s * 1e3, v.rhs_evals, v.host_ns_per_step
        );
        }
        println!("\nPareto front (reverse_load, braking-torque RMS vs M3 insns/s, paper reading):");
        for &i in &self.fronts.front {
            if let Some(p) = self.fronts.pts.get(i) {
                println!("  {:<40} {:.3e} insns/s  {:.2e} N·m", p.2, p.0, p.1);
            }
        }
        println!("\nstability (full physical model, explicit fixed steps):");
        for r in self.stab {
            println!(
                "  {:<5} {:>4}×{:<5} h={:>5} µs  {}",
                r.method, r.parameter, r.scale, r.h_us, r.verdict
            );
        }
        println!("\ncheapest per scene:");
        for (s, l) in self.cheapest {
            println!("  {s}: {l}");
        }
        println!("shipped monitor: {:.1} M3 insns/step", self.monitor.insns);
        println!(
        "\nwrote docs/results/speed-accuracy.{{csv,svg}}, stability.{{csv,svg}}, cheapest-per-scene.md, cost-by-core.md, host-speed.md in {:.0} s",
        self.t0.elapsed().as_secs_f64()
    );
    }
}
