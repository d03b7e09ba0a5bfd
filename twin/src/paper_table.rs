//! The paper's table (MODEL.md, "Reported results"): every figure of §4–§5 beside each
//! reading's value and deviation, the qualitative findings, and the Markdown/JSON renderings
//! that `paper` writes to docs/paper-comparison.md.

use crate::metrics::{self, Metrics};
use crate::reading::Reading;
use crate::scene::{Scene, SceneKind};
use crate::sim;
use crate::solver::SolverError;
use noback::mechanism::{Mechanism, TABLE2};
use serde::Serialize;

/// One quantitative figure.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Figure {
    /// Scene it belongs to.
    pub scene: &'static str,
    /// What it is, with unit.
    pub figure: &'static str,
    /// The paper's value.
    pub paper: f64,
    /// One of the eight figures the paper protocol scores (`paper_protocol`).
    pub dynamic: bool,
    /// Value under the paper reading.
    pub paper_reading: Option<f64>,
    /// Value under the physical reading.
    pub physical_reading: Option<f64>,
}

/// One qualitative finding.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Finding {
    /// The finding.
    pub finding: &'static str,
    /// Holds under the paper reading.
    pub paper_reading: bool,
    /// Holds under the physical reading.
    pub physical_reading: bool,
}

/// The whole comparison.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct PaperTable {
    /// Quantitative figures.
    pub figures: Vec<Figure>,
    /// Qualitative findings.
    pub findings: Vec<Finding>,
    /// Metrics of every run, paper reading first.
    pub runs: Vec<Metrics>,
}

/// Relative deviation `(value − paper)/paper`.
pub fn deviation(value: f64, paper: f64) -> f64 {
    (value - paper) / paper
}

/// The scenes the table runs.
pub const SCENES: [SceneKind; 4] = [
    SceneKind::ReverseLoad,
    SceneKind::ForwardLoad,
    SceneKind::ContinuousClosing,
    SceneKind::Hold,
];

/// Run every scene under both readings (with `tolerance`) and build the table.
pub fn build(tolerance: f64) -> Result<PaperTable, SolverError> {
    let mut runs = Vec::new();
    for reading in [Reading::Paper, Reading::Physical] {
        for kind in SCENES {
            let mut scene = Scene::builtin(kind, reading);
            scene.tolerance = tolerance;
            let run = sim::run(&scene)?;
            runs.push(metrics::compute(
                &scene,
                &run.samples,
                &run.stats,
                run.wall_s,
            ));
        }
    }
    Ok(table_from(&runs, &TABLE2))
}

fn find(runs: &[Metrics], reading: Reading, kind: SceneKind) -> Option<&Metrics> {
    runs.iter()
        .find(|m| m.reading == reading.name() && m.scene == kind.name())
}

/// Build the table from the metrics of the runs.
pub fn table_from(runs: &[Metrics], mech: &Mechanism) -> PaperTable {
    type Get = fn(&Metrics) -> Option<f64>;
    let rows: [(SceneKind, &'static str, f64, bool, Get); 13] = [
        (
            SceneKind::ReverseLoad,
            "contact-force lag after release (s)",
            0.13,
            true,
            |m| m.contact_lag_s,
        ),
        (
            SceneKind::ReverseLoad,
            "stable braking torque (N·m)",
            20.3,
            false,
            |m| m.holding_torque_nm,
        ),
        (
            SceneKind::ReverseLoad,
            "braking time (s)",
            0.44,
            true,
            |m| m.braking_time_s,
        ),
        (
            SceneKind::ReverseLoad,
            "output angle during braking (rad)",
            0.376,
            true,
            |m| m.braking_angle_rad,
        ),
        (
            SceneKind::ForwardLoad,
            "contact-force lag after release (s)",
            0.03,
            true,
            |m| m.contact_lag_s,
        ),
        (
            SceneKind::ForwardLoad,
            "stable braking torque (N·m)",
            20.3,
            false,
            |m| m.holding_torque_nm,
        ),
        (
            SceneKind::ForwardLoad,
            "braking time (s)",
            0.335,
            true,
            |m| m.braking_time_s,
        ),
        (
            SceneKind::ForwardLoad,
            "output angle during braking (rad)",
            0.886,
            true,
            |m| m.braking_angle_rad,
        ),
        (
            SceneKind::ContinuousClosing,
            "axial travel before 1.2 s (mm)",
            1.73,
            false,
            |m| m.axial_travel_mm,
        ),
        (
            SceneKind::ContinuousClosing,
            "period after 1.2 s (s)",
            0.444,
            true,
            |m| m.period_s,
        ),
        (
            SceneKind::ContinuousClosing,
            "braking torque peaks (N·m)",
            60.0,
            false,
            |m| Some(m.peak_braking_torque_nm),
        ),
        (
            SceneKind::ContinuousClosing,
            "braking torque troughs (N·m)",
            8.2,
            false,
            |m| Some(m.trough_braking_torque_nm),
        ),
        (
            SceneKind::ContinuousClosing,
            "max output speed (rad/s)",
            29.0,
            true,
            |m| Some(m.max_output_speed_rad_s),
        ),
    ];
    let mut figures: Vec<Figure> = rows
        .iter()
        .map(|(kind, figure, paper, dynamic, get)| Figure {
            scene: kind.name(),
            figure,
            paper: *paper,
            dynamic: *dynamic,
            paper_reading: find(runs, Reading::Paper, *kind).and_then(get),
            physical_reading: find(runs, Reading::Physical, *kind).and_then(get),
        })
        .collect();
    // Static identities (the same in both readings: they use μ_s and the quasi-static force).
    let spring = mech.pack_capacity_nm(mech.spring_preload_n(), mech.mu_static);
    let loaded = mech.pack_capacity_nm(
        mech.quasi_static_pressing_force_n(mech.load_torque_nm),
        mech.mu_static,
    );
    figures.push(Figure {
        scene: "static",
        figure: "pack capacity, spring only (N·m)",
        paper: 8.2,
        dynamic: false,
        paper_reading: Some(spring),
        physical_reading: Some(spring),
    });
    figures.push(Figure {
        scene: "static",
        figure: "pack capacity, spring + load (N·m)",
        paper: 60.0,
        dynamic: false,
        paper_reading: Some(loaded),
        physical_reading: Some(loaded),
    });
    let hold = |r| find(runs, r, SceneKind::Hold).and_then(|m| m.holding_torque_nm);
    figures.push(Figure {
        scene: "hold",
        figure: "holding torque (N·m)",
        paper: 20.3,
        dynamic: false,
        paper_reading: hold(Reading::Paper),
        physical_reading: hold(Reading::Physical),
    });
    let findings = [Reading::Paper, Reading::Physical].map(|r| {
        let rev = find(runs, r, SceneKind::ReverseLoad);
        let fwd = find(runs, r, SceneKind::ForwardLoad);
        let cc = find(runs, r, SceneKind::ContinuousClosing);
        let cmp = |a: Option<f64>, b: Option<f64>, f: fn(f64, f64) -> bool| match (a, b) {
            (Some(a), Some(b)) => f(a, b),
            _ => false,
        };
        [
            cmp(
                rev.and_then(|m| m.braking_time_s),
                fwd.and_then(|m| m.braking_time_s),
                |a, b| a > b,
            ),
            cmp(
                rev.and_then(|m| m.braking_angle_rad),
                fwd.and_then(|m| m.braking_angle_rad),
                |a, b| a < b,
            ),
            cmp(
                fwd.and_then(|m| m.contact_lag_s),
                rev.and_then(|m| m.contact_lag_s),
                |a, b| a < b,
            ),
            fwd.is_some_and(|m| m.output_reversals == 0 && m.braking_time_s.is_some()),
            rev.is_some_and(|m| m.output_reversals >= 1 && m.holding_torque_nm.is_some()),
            cc.is_some_and(|m| {
                m.period_s.is_some() && m.peak_braking_torque_nm > m.trough_braking_torque_nm + 10.0
            }),
        ]
    });
    let names = [
        "reverse braking time longer than forward",
        "reverse braking angle smaller than forward",
        "forward contact lag shorter than reverse",
        "forward load: output never reverses",
        "reverse load: output reverses, then locks",
        "continuous closing is periodic with brake/unlock phases",
    ];
    let findings = names
        .iter()
        .enumerate()
        .map(|(i, finding)| Finding {
            finding,
            paper_reading: findings[0].get(i).copied().unwrap_or(false),
            physical_reading: findings[1].get(i).copied().unwrap_or(false),
        })
        .collect();
    PaperTable {
        figures,
        findings,
        runs: runs.to_vec(),
    }
}

fn cell(v: Option<f64>, paper: f64) -> (String, String) {
    match v {
        Some(v) => {
            let d = (100.0 * deviation(v, paper)).round();
            let d = if d == 0.0 {
                "0 %".to_string()
            } else {
                format!("{d:+.0} %")
            };
            (sig(v), d)
        }
        None => ("—".to_string(), "—".to_string()),
    }
}

/// Three significant digits.
pub fn sig(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let digits = (2 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.digits$}")
}

impl PaperTable {
    /// Every figure at the base tolerance, both readings, with the findings and the solver
    /// work (counts only: wall times live on the benchmark pages).
    pub fn markdown(&self) -> String {
        let mut s = String::new();
        s.push_str("| scene | figure | paper | `paper` reading | dev. | `physical` reading | dev. |\n|---|---|---|---|---|---|---|\n");
        for f in &self.figures {
            let (pv, pd) = cell(f.paper_reading, f.paper);
            let (hv, hd) = cell(f.physical_reading, f.paper);
            s.push_str(&format!(
                "| {} | {}{} | {} | {} | {} | {} | {} |\n",
                f.scene,
                f.figure,
                if f.dynamic { " *" } else { "" },
                sig(f.paper),
                pv,
                pd,
                hv,
                hd
            ));
        }
        s.push_str(
            "\n| qualitative finding | `paper` reading | `physical` reading |\n|---|---|---|\n",
        );
        for f in &self.findings {
            let yn = |b: bool| if b { "holds" } else { "fails" };
            s.push_str(&format!(
                "| {} | {} | {} |\n",
                f.finding,
                yn(f.paper_reading),
                yn(f.physical_reading)
            ));
        }
        s.push_str("\n### Solver work per run\n\n| scene | reading | steps | rejected | RHS evaluations | events |\n|---|---|---|---|---|---|\n");
        for m in &self.runs {
            s.push_str(&format!(
                "| {} | {} | {} | {} | {} | {} |\n",
                m.scene, m.reading, m.steps, m.rejected_steps, m.rhs_evals, m.events
            ));
        }
        s
    }

    /// The figures only (no timings): the snapshot the tests hold fixed.
    pub fn snapshot(&self) -> String {
        let mut s = String::new();
        for f in &self.figures {
            let v = |x: Option<f64>| x.map_or("—".to_string(), sig);
            s.push_str(&format!(
                "{} | {} | {} | {}\n",
                f.scene,
                f.figure,
                v(f.paper_reading),
                v(f.physical_reading)
            ));
        }
        for f in &self.findings {
            s.push_str(&format!(
                "{} | {} | {}\n",
                f.finding, f.paper_reading, f.physical_reading
            ));
        }
        s
    }
}
