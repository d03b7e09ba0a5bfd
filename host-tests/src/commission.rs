//! Commissioning (docs/commissioning.md): the plant
//! facts the uncommissioned monitor cannot know, identified from the unit's acceptance runs —
//! each: the drive turns the door against (opening) or with (closing) a known load at a steady
//! speed, is cut, and the brake holds the door; two opening runs at different loads also give
//! the current's gain. The first run opens and sets the direction an opening turns the output.
//!
//! | identified | from | sets |
//! |---|---|---|
//! | current offset | the current reading over the final hold, drive off | `current_offset_a` |
//! | current gain (two runs or more, loads ≥ 5 N·m apart) | slope of the steady drive torque over the load | `sensors.motor_torque_constant_nm_a` |
//! | pack drag while driving | steady drive torque / gain − the load | `driving_drag_nm`; `sliding_mu` (spring-only, or no closing run) |
//! | overrunning equilibrium (a closing run) | `y = L + v` against `g₁(μ)·v − g₀(μ)` | `sliding_mu` (relieved) |
//! | overrunning line (closings at loads ≥ 5 N·m apart, relieved) | `y = L + v` against `g₁·v − g₀`, least squares | `overrun_line` |
//! | braking against the load | the output's deceleration to its turning point: `J·α − M` | `braking_share` (0.8 × its share of the capacity) |
//! | a spring-only pack's braking (two opening loads and a closing) | the decelerations `ω₀²/(2θ)`: openings `J·α = M + D`, the closing `J·α = D + g·M` | `aiding_braking` |
//! | form | that braking over the drag: the ramps clamp from the cut (> 3) or it is the drag alone (≈ 1) | `driving_pack`, braking-angle allowance, dead-current check |
//!
//! The pack's static capacity is not identified: it needs the brake made to slip (a functional
//! test, issue 17); `capacity_mu` stays at Table 2's μ_s.

mod lock_times;

use crate::accuracy::{run_monitor, scene_trace};
use noback::fx::{adc_centered, counter_delta};
use noback::mechanism::Mechanism;
use noback::monitor::{
    AidingBraking, Config, DrivingPack, OverrunLine, Thresholds, MARGINAL_SELF_LOCKING,
};
use noback_twin::scene::{Scene, SceneKind};
use noback_twin::trace::Trace;

/// Steady drive averaged before the cut (s), ending [`CUT_GUARD_S`] before it.
pub const STEADY_WINDOW_S: f64 = 0.1;
/// Gap between the steady window and the cut (s).
pub const CUT_GUARD_S: f64 = 0.005;
/// Shortest drive before the cut (s): the steady window then starts after the drive's start-up.
pub const MIN_DRIVE_S: f64 = 0.2;
/// Shortest hold at the end of the run (s): the output still within [`HOLD_CREEP_RAD`].
pub const MIN_HOLD_S: f64 = 0.1;
/// Output travel allowed over the final hold (rad): a few encoder counts of rattle.
pub const HOLD_CREEP_RAD: f64 = 0.005;
/// Slowest steady drive (rad/s at the output).
pub const MIN_SPEED_RAD_S: f64 = 1.0;
/// Largest speed ripple over the window, as a share of the mean speed.
pub const MAX_RIPPLE: f64 = 0.05;
/// Braking against the load, over the drag while driving, above which the ramps clamp from the
/// cut (`DrivingPack::Relieved`: 55–67 × on the physical reading from 35 to 20 N·m); a pack
/// they leave open brakes with its drag alone (≈ 1 ×).
pub const CLAMPS_AT_ONCE: f64 = 3.0;
/// Share of the measured opposed braking the commissioned envelope counts on: margin for the
/// inertia (Table 2 ± 10 %) and the load the crew applied.
pub const BRAKING_SHARE_MARGIN: f64 = 0.8;

/// Two acceptance runs' loads must differ by this much (N·m) to identify the current's gain.
pub const MIN_LOAD_SPAN_NM: f64 = 5.0;
/// Plausible range of the identified gain (measured drive torque over true).
pub const GAIN_RANGE: (f64, f64) = (0.5, 2.0);

/// What one acceptance run showed.
#[derive(Clone, Debug, PartialEq)]
pub struct RunFigures {
    /// The run's place in the acceptance runs given (from 0).
    pub run: usize,
    pub load_nm: f64,
    pub cut_s: f64,
    pub drive_speed_rad_s: f64,
    /// Mean drive torque over the steady window (N·m, signed as the current reads).
    pub drive_torque_nm: f64,
    /// Whether the drive turned the output with the load (closing: the other way than the
    /// first run, which opens) rather than against it.
    pub closing: bool,
    /// Mean current reading over the final hold, drive off (A).
    pub hold_current_a: f64,
    pub braking_time_s: f64,
    pub braking_nm: f64,
    pub braking_share: f64,
    /// The output's mean deceleration to its turning point, `ω₀²/(2θ)` (rad/s²).
    pub decel_rad_s2: f64,
}

/// What the acceptance runs showed, and the configuration set from them.
#[derive(Clone, Debug, PartialEq)]
pub struct Commissioning {
    pub runs: Vec<RunFigures>,
    /// Measured over true drive torque (1 unless two loads were run).
    pub gain: f64,
    pub current_offset_a: f64,
    pub drive_drag_nm: f64,
    pub braking_share: f64,
    /// A spring-only pack's braking of an aiding load, where the runs identify it.
    pub aiding: Option<AidingBraking>,
    pub config: Config,
}

fn mean(x: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = x.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    s / n.max(1) as f64
}

/// The output angle (rad) of every row, unwrapped from the encoder's counts.
fn output_angles(trace: &Trace, c: &Config) -> Vec<f64> {
    let bits = c.sensors.output_encoder_bits;
    let rad = c.sensors.output_rad_per_count();
    let mut prev = trace.rows.first().map_or(0, |r| r.output_count);
    let mut n = 0_i64;
    trace
        .rows
        .iter()
        .map(|r| {
            n += i64::from(counter_delta(prev, r.output_count, bits));
            prev = r.output_count;
            n as f64 * rad
        })
        .collect()
}

/// The sign of the output's travel while the drive runs, as its encoder reads it.
fn driven_sign(trace: &Trace, c: &Config) -> f64 {
    let theta = output_angles(trace, c);
    let cut = trace
        .rows
        .iter()
        .position(|r| !r.drive_on)
        .unwrap_or(theta.len());
    let end = theta.get(cut.saturating_sub(1)).copied().unwrap_or(0.0);
    (end - theta.first().copied().unwrap_or(0.0)).signum()
}

/// Mean current reading over the last [`MIN_HOLD_S`] of a run (A), drive off there.
fn hold_current_a(trace: &Trace, c: &Config) -> f64 {
    let s = &c.sensors;
    let hold = (MIN_HOLD_S / (1.0 / trace.sample_rate_hz)) as usize;
    let tail = &trace.rows[trace.rows.len().saturating_sub(hold + 1)..];
    mean(
        tail.iter().map(|r| {
            f64::from(adc_centered(r.current_code, s.current_adc_bits)) * s.amps_per_count()
        }),
    )
}

impl RunFigures {
    /// The drive torque along the output's motion (N·m): the load and the drag opening, the
    /// overrunning equilibrium's drive share closing.
    pub fn along_nm(&self) -> f64 {
        self.drive_torque_nm * self.drive_speed_rad_s.signum()
    }
}

/// One run's figures, the monitor set with `base`; refuses a run that cannot give them.
/// `opening`: the direction (±1) an opening turns the output, `None` for the first run, which
/// opens and sets it (the sensors' mounting, not a convention, says which way that is).
fn measure(
    trace: &Trace,
    load_nm: f64,
    base: Config,
    opening: Option<f64>,
) -> Result<RunFigures, String> {
    if !(load_nm.is_finite() && load_nm >= base.thresholds.min_load_nm * 2.0) {
        return Err(format!(
            "the load {load_nm} N·m is below the {} N·m the identification needs",
            base.thresholds.min_load_nm * 2.0
        ));
    }
    // Health is judged by the uncommissioned monitor, on the design's pack: a build record's
    // pack with the design's friction may be one `Monitor::new` refuses.
    let design = Config {
        mechanism: Config::default().mechanism,
        ..base
    };
    let estimates = run_monitor(trace, design)?;
    let dt = 1.0 / trace.sample_rate_hz;
    if let Some((i, e)) = estimates
        .iter()
        .enumerate()
        .find(|(_, e)| e.flags.bits() != 0)
    {
        return Err(format!(
            "the uncommissioned monitor raised {:?} at {:.4} s: not a healthy run",
            e.flags,
            i as f64 * dt
        ));
    }
    let rows = &trace.rows;
    let cut = rows
        .windows(2)
        .position(|w| w[0].drive_on && !w[1].drive_on)
        .map(|i| i + 1)
        .ok_or("no drive cut: the run must drive, then cut the drive")?;
    if rows[..cut].iter().any(|r| !r.drive_on) || (cut as f64) * dt < MIN_DRIVE_S {
        return Err(format!(
            "the drive must run from the start for at least {MIN_DRIVE_S} s before the cut"
        ));
    }
    if rows[cut..].iter().any(|r| r.drive_on) {
        return Err("the drive comes back on after the cut".into());
    }
    let theta = output_angles(trace, &base);
    let hold = (MIN_HOLD_S / dt) as usize;
    let end = rows.len() - 1;
    if end < cut + hold
        || theta[end - hold..]
            .iter()
            .any(|t| (t - theta[end]).abs() > HOLD_CREEP_RAD)
    {
        return Err(format!(
            "no hold: the output must stay still for the last {MIN_HOLD_S} s"
        ));
    }
    let (w1, w0) = (
        cut - (CUT_GUARD_S / dt) as usize,
        cut - ((CUT_GUARD_S + STEADY_WINDOW_S) / dt) as usize,
    );
    let speed = (theta[w1] - theta[w0]) / ((w1 - w0) as f64 * dt);
    let tenth = (w1 - w0) / 10;
    let ripple = (0..10)
        .map(|k| {
            let (a, b) = (w0 + k * tenth, w0 + (k + 1) * tenth);
            ((theta[b] - theta[a]) / (tenth as f64 * dt) - speed).abs()
        })
        .fold(0.0, f64::max);
    if speed.abs() < MIN_SPEED_RAD_S {
        return Err(format!(
            "the output must turn at {MIN_SPEED_RAD_S} rad/s or more before the cut; it turned at {speed:.3} rad/s"
        ));
    }
    if ripple > MAX_RIPPLE * speed.abs() {
        return Err(format!(
            "the drive is not steady over the {STEADY_WINDOW_S} s before the cut (speed ripple {ripple:.3} rad/s)"
        ));
    }
    let drive_torque = mean(
        estimates[w0..w1]
            .iter()
            .map(|e| e.drive_torque_nm.to_num::<f64>()),
    );
    // Braking: from the cut to the output's turning point (the first sample at the far end of
    // its travel).
    let dir = speed.signum();
    let stop = cut
        + theta[cut..]
            .iter()
            .enumerate()
            .min_by(|a, b| (-dir * a.1).total_cmp(&(-dir * b.1)))
            .map_or(0, |(i, _)| i);
    let braking_time = (stop - cut) as f64 * dt;
    let braking_angle = (theta[stop] - theta[cut]).abs();
    if braking_time <= 2.0 * dt {
        return Err("the output did not move after the cut".into());
    }
    let m: &Mechanism = &base.mechanism;
    // The pack's torque from the deceleration: J·|α| − M opening (the load helps stop the
    // output), J·|α| + M closing.
    let closing = opening.is_some_and(|o| dir != o);
    let load_along = if closing { load_nm } else { -load_nm };
    let opposed = m.output_inertia_kg_m2 * (speed.abs() / braking_time) + load_along;
    let capacity = m.pack_capacity_nm(m.quasi_static_pressing_force_n(load_nm), base.capacity_mu);
    Ok(RunFigures {
        run: 0,
        load_nm,
        cut_s: cut as f64 * dt,
        drive_speed_rad_s: speed,
        drive_torque_nm: drive_torque,
        closing,
        hold_current_a: hold_current_a(trace, &base),
        braking_time_s: braking_time,
        braking_nm: opposed,
        braking_share: opposed / capacity,
        decel_rad_s2: speed * speed / (2.0 * braking_angle),
    })
}

/// Identifies the unit's settings from its acceptance runs, each `(trace, load the crew
/// applied)`. One run: the current's gain is taken as nominal. Two or more at loads
/// [`MIN_LOAD_SPAN_NM`] apart: the gain is the slope of drive torque over load. A run that cannot
/// identify them is refused with the reason (naming the run when there are several).
pub fn commission(runs: &[(&Trace, f64)]) -> Result<Commissioning, String> {
    commission_with(runs, Config::default())
}

/// [`commission`] from `base` (the unit's as-built mechanism in place of the design's).
pub fn commission_with(runs: &[(&Trace, f64)], base: Config) -> Result<Commissioning, String> {
    let name = |i: usize| {
        if runs.len() > 1 {
            format!("run {}: ", i + 1)
        } else {
            String::new()
        }
    };
    let first = runs.first().ok_or("no acceptance run")?;
    // The offset first (drive off in the hold, once the run checked out), so the drive torques
    // are read without it.
    let mut base = base;
    let first = measure(first.0, first.1, base, None).map_err(|e| name(0) + &e)?;
    base.current_offset_a = first.hold_current_a;
    let dir = Some(first.drive_speed_rad_s.signum());
    // A closing after the first serves a relieved pack's overrunning line alone: a refusal of
    // it waits until the openings show the pack's form.
    let (mut figures, mut later_closing_refused) = (Vec::<RunFigures>::new(), None);
    for (i, (t, load)) in runs.iter().enumerate() {
        match measure(t, *load, base, dir.filter(|_| i > 0)) {
            Ok(f) => figures.push(RunFigures { run: i, ..f }),
            Err(e) if figures.iter().any(|f| f.closing) && Some(driven_sign(t, &base)) != dir => {
                later_closing_refused.get_or_insert(name(i) + &e);
            }
            Err(e) => return Err(name(i) + &e),
        }
    }
    // The first run opens: never empty.
    let opening: Vec<&RunFigures> = figures.iter().filter(|f| !f.closing).collect();
    // Drive torque against the load: −D̂ = g·(M + drag), one line through the opening runs.
    let gain = if load_span(&opening) >= MIN_LOAD_SPAN_NM {
        line(opening.iter().map(|f| (f.load_nm, f.along_nm()))).0
    } else if opening.len() > 1 {
        return Err(format!(
            "the opening runs' loads must span at least {MIN_LOAD_SPAN_NM} N·m to identify the current's gain"
        ));
    } else {
        1.0
    };
    if !(GAIN_RANGE.0..=GAIN_RANGE.1).contains(&gain) {
        return Err(format!(
            "the drive torque grows {gain:.3} times the load: not a healthy drive (are the loads right?)"
        ));
    }
    let drag = mean(opening.iter().map(|f| f.along_nm() / gain - f.load_nm));
    if drag <= 0.0 {
        return Err(format!(
            "the drive took {:.3} N·m against a load of {} N·m: no drag left for the pack (is the load right, and does the first run open against it?)",
            opening[0].along_nm(), opening[0].load_nm
        ));
    }
    let heaviest = opening
        .iter()
        .max_by(|a, b| a.load_nm.total_cmp(&b.load_nm))
        .ok_or("no acceptance run")?;
    let relieved = heaviest.braking_nm > CLAMPS_AT_ONCE * drag;
    let m = &base.mechanism;
    let (spring, k) = (m.spring_preload_n(), m.ramp_factor_per_m());
    // a = μ·c: from a closing run's overrunning equilibrium y = L + v = g₁(a)·v − g₀(a) where
    // there is one (what the closing estimate rests on), else from the drag, drag = a·F.
    let closing = figures.iter().find(|f| f.closing);
    let a = match (relieved, closing) {
        (true, Some(f)) => {
            let v = f.along_nm() / gain;
            let y = f.load_nm + v;
            let den = y * k - 2.0 * k * v + spring;
            if !(v > 0.0 && den > 0.0) {
                return Err(format!(
                    "the closing run's drive torque {v:.3} N·m at {} N·m is no overrunning equilibrium",
                    f.load_nm
                ));
            }
            y / den
        }
        (true, None) => {
            let room = spring - drag * k;
            if room <= 0.0 {
                return Err(format!(
                    "a drag of {drag:.3} N·m is more than a pack the drive relieves can give (≤ {:.3} N·m)",
                    spring / k
                ));
            }
            drag / room
        }
        (false, _) => drag / spring,
    };
    let closings: Vec<&RunFigures> = figures.iter().filter(|f| f.closing).collect();
    let overrun = match (relieved, later_closing_refused) {
        (true, Some(e)) => return Err(e),
        (true, None) => overrun_line(&closings, gain)?,
        (false, _) => None,
    };
    // The closing estimate reads the load off `1/(a·k − 1)`: a relieved pack that barely
    // self-locks while slipping, or does not, is refused (the top of Monitor::new's band).
    let a_k = overrun.map_or(a * k, |l| l.self_locking_ratio());
    let least = MARGINAL_SELF_LOCKING.1;
    if relieved && a_k < least {
        return Err(format!(
            "the runs give a·k = {a_k:.3}: a pack that self-locks too little while slipping for its closings to be read (a·k ≥ {least})"
        ));
    }
    let braking_share = heaviest.braking_share;
    let aiding = (!relieved)
        .then(|| aiding_braking(&opening, closing?, base.mechanism.output_inertia_kg_m2))
        .flatten();
    let mut config = configured(base, a, drag, braking_share, relieved);
    config.aiding_braking = aiding;
    config.overrun_line = overrun;
    // The monitor's torque per amp, so that its drive torque reads true.
    config.sensors.motor_torque_constant_nm_a /= gain;
    config.commissioned = true;
    if relieved {
        config.lock_times = lock_times::lock_times(&figures, runs, config)?;
    }
    noback::monitor::Monitor::new(config).map_err(|e| format!("the identified settings: {e}"))?;
    Ok(Commissioning {
        runs: figures,
        gain,
        current_offset_a: config.current_offset_a,
        drive_drag_nm: drag,
        braking_share,
        aiding,
        config,
    })
}

/// How far apart the runs' loads lie (N·m; −∞ for none).
fn load_span(runs: &[&RunFigures]) -> f64 {
    let loads = runs.iter().map(|f| f.load_nm);
    loads.clone().fold(f64::NEG_INFINITY, f64::max) - loads.fold(f64::INFINITY, f64::min)
}

/// The least-squares line `y = slope·x + intercept` through `points` (two or more, not all at
/// one `x`): (slope, intercept).
fn line(points: impl Iterator<Item = (f64, f64)> + Clone) -> (f64, f64) {
    let xm = mean(points.clone().map(|p| p.0));
    let ym = mean(points.clone().map(|p| p.1));
    let sxy: f64 = points.clone().map(|(x, y)| (x - xm) * (y - ym)).sum();
    let sxx: f64 = points.map(|(x, _)| (x - xm).powi(2)).sum();
    let slope = sxy / sxx;
    (slope, ym - slope * xm)
}

/// A relieved pack's overrunning line `y = L + v = g₁·v − g₀` through closings at loads
/// [`MIN_LOAD_SPAN_NM`] apart or more (`v`: drive torque along the motion over `gain`); `None`
/// with one closing or none, or where the line is no self-locking pack's (`g₁ > 2`, `g₀ > 0`):
/// then `sliding_mu`'s line stands.
fn overrun_line(closings: &[&RunFigures], gain: f64) -> Result<Option<OverrunLine>, String> {
    if closings.len() < 2 {
        return Ok(None);
    }
    if load_span(closings) < MIN_LOAD_SPAN_NM {
        return Err(format!(
            "the closing runs' loads must span at least {MIN_LOAD_SPAN_NM} N·m to identify the overrunning line"
        ));
    }
    let points = closings.iter().map(|f| {
        let v = f.along_nm() / gain;
        (v, f.load_nm + v)
    });
    let (g1, minus_g0) = line(points);
    Ok((g1 > 2.0 && minus_g0 < 0.0).then_some(OverrunLine {
        gain: g1,
        offset_nm: -minus_g0,
    }))
}

/// A spring-only pack's braking, `J·α = D + g·M` along an aiding load, from the openings' (ramps
/// open: `J·α = M + D`, two loads give `J` and `D`) and a closing's deceleration. `None` without
/// two opening loads [`MIN_LOAD_SPAN_NM`] apart, or where the figures are implausible.
fn aiding_braking(opening: &[&RunFigures], closing: &RunFigures, j: f64) -> Option<AidingBraking> {
    let (lo, hi) = (
        opening
            .iter()
            .min_by(|a, b| a.load_nm.total_cmp(&b.load_nm))?,
        opening
            .iter()
            .max_by(|a, b| a.load_nm.total_cmp(&b.load_nm))?,
    );
    if hi.load_nm - lo.load_nm < MIN_LOAD_SPAN_NM {
        return None;
    }
    let inertia = (hi.load_nm - lo.load_nm) / (hi.decel_rad_s2 - lo.decel_rad_s2);
    let drag = inertia * hi.decel_rad_s2 - hi.load_nm;
    let gain = (inertia * closing.decel_rad_s2 - drag) / closing.load_nm;
    let plausible =
        (GAIN_RANGE.0..=GAIN_RANGE.1).contains(&(inertia / j)) && drag > 0.0 && gain > 0.0;
    plausible.then_some(AidingBraking {
        inertia_kg_m2: inertia,
        drag_nm: drag,
        load_gain: gain,
    })
}

/// The configuration for a pack with `a = μ·c` while slipping, whose measured braking against the
/// load is `share` of its capacity, and which the ramps clamp from the cut (`relieved`) or not.
fn configured(base: Config, a: f64, drag: f64, share: f64, relieved: bool) -> Config {
    let mut cfg = base;
    cfg.sliding_mu = a / base.mechanism.pack_torque_per_newton_m(1.0);
    // The drag the openings measured, not `a`'s: a closing run's `a` gives another drag.
    cfg.driving_drag_nm = Some(drag);
    cfg.driving_pack = if relieved {
        DrivingPack::Relieved
    } else {
        DrivingPack::SpringOnly
    };
    let t = if relieved {
        Thresholds::PHYSICAL_READING
    } else {
        Thresholds::DEFAULT
    };
    cfg.thresholds.braking_angle_allowance_rad = t.braking_angle_allowance_rad;
    cfg.thresholds.braking_angle_factor = t.braking_angle_factor;
    cfg.thresholds.opposed_braking_share = (share * BRAKING_SHARE_MARGIN).clamp(0.0, 1.0);
    // The dead-reading check needs a drive torque that never falls near zero while the output
    // turns: a relieved pack's drag; a spring-only pack closes on almost none.
    cfg.thresholds.dead_current_nm = if relieved {
        (drag / 4.0).min(t.dead_current_nm)
    } else {
        0.0
    };
    cfg
}

/// The documented acceptance procedure (docs/commissioning.md), as `(kind, load N·m)`: two
/// openings against the door's load and a test weight 12 N·m apart, and two closings with the
/// door's load and with a counterweight leaving the family's lightest load, 5 N·m;
/// each at [`ACCEPTANCE_SPEED_RAD_S`], cut at [`ACCEPTANCE_CUT_S`], run for
/// [`ACCEPTANCE_RUN_S`].
pub const ACCEPTANCE: [(SceneKind, f64); 4] = [
    (SceneKind::ReverseLoad, 20.3),
    (SceneKind::ReverseLoad, 8.0),
    (SceneKind::ForwardLoad, 20.3),
    (SceneKind::ForwardLoad, 5.0),
];
/// The acceptance runs' steady input speed (rad/s): Table 2's opening speed.
pub const ACCEPTANCE_SPEED_RAD_S: f64 = 13.78;
/// The acceptance runs' drive cut (s): [`MIN_DRIVE_S`] of steady drive.
pub const ACCEPTANCE_CUT_S: f64 = 0.2;
/// The acceptance runs' length (s): the cut, the braking and a hold well past [`MIN_HOLD_S`].
pub const ACCEPTANCE_RUN_S: f64 = 1.0;

/// The unit `scene` runs on (its plant, sensors and noise; its faults left out: acceptance
/// finds it healthy) taken through the acceptance `plan` (as [`ACCEPTANCE`]) on the twin, each
/// trace passed through `installed` (how the unit's sensors are mounted), and commissioned.
pub fn commission_unit(
    scene: &Scene,
    plan: &[(SceneKind, f64)],
    installed: impl Fn(&mut Trace),
) -> Result<Commissioning, String> {
    commission_unit_with(scene, plan, installed, Config::default())
}

/// [`commission_unit`] from `base` ([`commission_with`]).
pub fn commission_unit_with(
    scene: &Scene,
    plan: &[(SceneKind, f64)],
    installed: impl Fn(&mut Trace),
    base: Config,
) -> Result<Commissioning, String> {
    let mut traces = Vec::new();
    for &(kind, load) in plan {
        let mut run = scene.clone();
        run.kind = kind;
        run.load_torque_nm = load;
        run.initial_speed_rad_s = ACCEPTANCE_SPEED_RAD_S;
        run.release_at_s = Some(ACCEPTANCE_CUT_S);
        run.duration_s = ACCEPTANCE_RUN_S;
        run.faults.clear();
        let mut trace = scene_trace(&run)?;
        installed(&mut trace);
        traces.push((trace, load));
    }
    let runs: Vec<_> = traces.iter().map(|(t, l)| (t, *l)).collect();
    commission_with(&runs, base)
}
