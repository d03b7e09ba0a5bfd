//! The benchmark page of host wall times (`docs/results/host-speed.md`): ns per step of every
//! variant `cargo xtask bench` times, with the machine. Apart from `speed-accuracy.csv`, whose
//! errors and instruction counts are the same on every run.

use std::fmt::Write as _;

/// One variant's host time.
pub struct Row<'a> {
    pub family: &'a str,
    pub format: &'a str,
    pub method: &'a str,
    pub scene: &'a str,
    pub ns_per_step: f64,
}

/// The page. A reduced variant is timed once per format × integrator (criterion, not per scene
/// or rate); the twin per tolerance and scene (median wall of the bench's repetitions).
pub fn page(rows: &[Row], quick: bool) -> String {
    let mut s = format!(
        "# Host time per step (benchmark: machine-dependent)\n\n\
         Written by `cargo xtask bench{}`; do not edit. Wall times change from run to run and \
         machine to machine; the errors and instruction counts beside them are in \
         `speed-accuracy.csv`, the same on every run. Machine: {}.\n\n\
         | family | format | method | scene | host ns per step |\n|---|---|---|---|---|\n",
        if quick { " --quick" } else { "" },
        crate::machine::this()
    );
    let mut seen: Vec<(&str, &str, &str, &str)> = Vec::new();
    for r in rows.iter().filter(|r| r.ns_per_step > 0.0) {
        let scene = if r.family == "reduced" {
            "all"
        } else {
            r.scene
        };
        let key = (r.family, r.format, r.method, scene);
        if !seen.contains(&key) {
            seen.push(key);
            let _ = writeln!(
                s,
                "| {} | {} | {} | {scene} | {:.1} |",
                r.family, r.format, r.method, r.ns_per_step
            );
        }
    }
    s
}
