//! The monitor against the twin: run the shipped monitor over a twin trace and measure how far
//! its estimates are from the twin's truth, and when its flags come.
//!
//! The twin's ball–socket contact impacts ring at hundreds of hertz; the monitor sees them only
//! through the output encoder (the inertia torque `J_s·α` of its second difference over 2 × 1.6
//! ms while the brake holds), so the twin's pressing force and braking torque are compared after
//! a centred moving average over [`COMPARE_WINDOW_S`] — the "compared" signal. Both the raw and the compared truth are kept, and the plot shows both.
//! Definitions (also in docs/monitor.md):
//! - pressing-force RMS error: over every sample, monitor − compared twin; in % of the compared
//!   twin's peak.
//! - braking-torque RMS error: |monitor| − compared twin magnitude.
//! - holding torque: mean braking torque over the last [`HOLD_WINDOW_S`] when both say locked.
//! - lock time: first sample after the drive is cut at which the brake state is locked and
//!   stays locked for [`LOCK_CONFIRM_S`].

use noback::monitor::functional_test::{Procedure, TestConfig, TestReport};
use noback::monitor::{BrakeState, Config, Estimate, Flags, Inputs, Monitor};
use noback_twin::fault::{Fault, FaultKind};
use noback_twin::trace::Trace;

/// Width of the centred moving average applied to the twin's truth (s).
pub const COMPARE_WINDOW_S: f64 = 0.010;
/// Window at the end of a run over which holding torque is averaged (s).
pub const HOLD_WINDOW_S: f64 = 0.050;
/// How long a lock must last to count (s).
pub const LOCK_CONFIRM_S: f64 = 0.020;

/// The twin's 10 kHz sensor trace of a scene (built-in name or TOML file), physical reading
/// unless the file says otherwise.
pub fn twin_trace(target: &str) -> Result<Trace, String> {
    scene_trace(&noback_twin::cli::load_scene(target, None)?)
}

/// The twin's 10 kHz sensor trace of a scene built in code.
pub fn scene_trace(scene: &noback_twin::scene::Scene) -> Result<Trace, String> {
    let run = noback_twin::sim::run(scene).map_err(|e| format!("twin: {}: {e}", scene.name))?;
    Ok(noback_twin::sensing::trace(
        &run.samples,
        &scene.sensors,
        &scene.noise,
        &scene.faults,
        noback_twin::sim::SAMPLE_RATE_HZ,
    ))
}

/// A scene built in code through the twin and the shipped monitor (default configuration): its
/// trace and the monitor's accuracy and flags against it.
pub fn monitor_on_scene(scene: &noback_twin::scene::Scene) -> Result<(Trace, Accuracy), String> {
    let trace = scene_trace(scene)?;
    let acc = compare(&trace, &run_monitor(&trace, Config::default())?);
    Ok((trace, acc))
}

/// Runs the monitor over every row of a trace, as an ECU that does not hand on the drive's
/// current command.
pub fn run_monitor(trace: &Trace, config: Config) -> Result<Vec<Estimate>, String> {
    run_monitor_with(trace, config, false)
}

/// [`run_monitor`], with the trace's current command in the inputs when `command` (and the
/// trace carries it).
pub fn run_monitor_with(
    trace: &Trace,
    config: Config,
    command: bool,
) -> Result<Vec<Estimate>, String> {
    let mut monitor = Monitor::new(config).map_err(|e| format!("monitor config: {e:?}"))?;
    Ok(trace
        .rows
        .iter()
        .map(|r| {
            let i = Inputs::new(r.current_code, r.motor_count, r.output_count, r.drive_on);
            monitor.step(&i.with_command(r.current_command_code.filter(|_| command)))
        })
        .collect())
}

/// The functional test's report after running the monitor over `trace` with `test` as the
/// procedure of its kind and the crew's request at `start_s`.
pub fn run_functional_test(
    trace: &Trace,
    mut config: Config,
    (kind, test): (Procedure, &TestConfig),
    start_s: f64,
) -> Result<TestReport, String> {
    kind.set_test(&mut config, *test);
    let mut monitor = Monitor::new(config).map_err(|e| format!("monitor config: {e:?}"))?;
    let start = (start_s * trace.sample_rate_hz).round() as usize;
    for (i, r) in trace.rows.iter().enumerate() {
        if i == start && !monitor.request_functional_test(kind) {
            return Err(format!("no {kind:?} functional test configured").to_lowercase());
        }
        monitor.step(&Inputs::new(
            r.current_code,
            r.motor_count,
            r.output_count,
            r.drive_on,
        ));
    }
    monitor
        .functional_test()
        .ok_or_else(|| format!("the test was requested at {start_s} s, after the trace's end"))
}

/// Centred moving average over `window` samples (shrinking at the ends).
pub fn smooth(x: &[f64], window: usize) -> Vec<f64> {
    let half = window / 2;
    let mut prefix = Vec::with_capacity(x.len() + 1);
    prefix.push(0.0);
    for v in x {
        prefix.push(prefix.last().copied().unwrap_or(0.0) + v);
    }
    (0..x.len())
        .map(|i| {
            let lo = i.saturating_sub(half);
            let hi = (i + half + 1).min(x.len());
            (prefix[hi] - prefix[lo]) / (hi - lo) as f64
        })
        .collect()
}

fn rms(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len()).max(1) as f64;
    (a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / n).sqrt()
}

/// One raised flag.
#[derive(Clone, Debug, PartialEq)]
pub struct FlagEvent {
    /// Flag name.
    pub flag: &'static str,
    /// Time (s).
    pub t_s: f64,
}

/// The comparison of one run.
#[derive(Clone, Debug)]
pub struct Accuracy {
    /// Time of each sample (s).
    pub t_s: Vec<f64>,
    /// Twin pressing force, raw and compared (N).
    pub twin_force_raw_n: Vec<f64>,
    /// Twin pressing force after the moving average (N).
    pub twin_force_n: Vec<f64>,
    /// Monitor pressing force (N).
    pub monitor_force_n: Vec<f64>,
    /// Twin braking torque, raw (N·m).
    pub twin_torque_raw_nm: Vec<f64>,
    /// Twin braking torque after the moving average (N·m).
    pub twin_torque_nm: Vec<f64>,
    /// Monitor braking torque magnitude (N·m).
    pub monitor_torque_nm: Vec<f64>,
    /// RMS pressing-force error (N).
    pub pressing_force_rmse_n: f64,
    /// The same in % of the compared twin's peak.
    pub pressing_force_rmse_pct: f64,
    /// RMS braking-torque error (N·m).
    pub braking_torque_rmse_nm: f64,
    /// Holding torque: twin, monitor (N·m), if both end locked.
    pub holding_torque_nm: Option<(f64, f64)>,
    /// The monitor's last estimate is marked trusted.
    pub trusted_at_end: bool,
    /// Lock time after the drive cut: twin, monitor (s), if both lock.
    pub lock_time_s: Option<(f64, Option<f64>)>,
    /// Flags as they were raised.
    pub flags: Vec<FlagEvent>,
}

impl Accuracy {
    /// The raised flags as (name, time in s) pairs, in the order they rose.
    pub fn flag_times(&self) -> Vec<(&'static str, f64)> {
        self.flags.iter().map(|f| (f.flag, f.t_s)).collect()
    }

    /// Holding-torque error in % of the twin's.
    pub fn holding_torque_err_pct(&self) -> Option<f64> {
        self.holding_torque_nm
            .map(|(twin, mon)| 100.0 * (mon - twin).abs() / twin.abs().max(1e-9))
    }

    /// Lock-time error (s); `None` when the twin does not lock, infinite when only the monitor
    /// misses it.
    pub fn lock_time_err_s(&self) -> Option<f64> {
        self.lock_time_s
            .map(|(twin, mon)| mon.map_or(f64::INFINITY, |m| (m - twin).abs()))
    }

    /// The braking figures issue 16's accuracy targets name, when both end locked.
    pub fn braking(&self) -> Option<Braking> {
        Some(Braking {
            holding_err_pct: self.holding_torque_err_pct()?,
            force_rms_pct: self.pressing_force_rmse_pct,
            lock_err_s: self.lock_time_err_s(),
            trusted: self.trusted_at_end,
        })
    }
}

/// A braking run's accuracy: holding torque, pressing force over the run, lock time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Braking {
    /// Holding-torque error (% of the twin's).
    pub holding_err_pct: f64,
    /// Pressing-force RMS error (% of the twin's compared peak).
    pub force_rms_pct: f64,
    /// Lock-time error (s; infinite when only the monitor misses the lock).
    pub lock_err_s: Option<f64>,
    /// The monitor marked its estimate trusted at the end of the run.
    pub trusted: bool,
}

/// First time after `from` at which `locked(i)` holds for [`LOCK_CONFIRM_S`].
fn lock_time(t: &[f64], from: f64, locked: impl Fn(usize) -> bool) -> Option<f64> {
    let mut start: Option<usize> = None;
    for i in 0..t.len() {
        if t[i] < from || !locked(i) {
            start = None;
            continue;
        }
        let s = *start.get_or_insert(i);
        if t[i] - t[s] >= LOCK_CONFIRM_S {
            return Some(t[s]);
        }
    }
    None
}

/// Compares the monitor's estimates with the trace's truth.
pub fn compare(trace: &Trace, estimates: &[Estimate]) -> Accuracy {
    let rows = &trace.rows;
    let window = (COMPARE_WINDOW_S * trace.sample_rate_hz).round().max(1.0) as usize;
    let t_s: Vec<f64> = rows.iter().map(|r| r.t_s).collect();
    let twin_force_raw_n: Vec<f64> = rows.iter().map(|r| r.pressing_force_n).collect();
    let twin_torque_raw_nm: Vec<f64> = rows.iter().map(|r| r.braking_torque_nm.abs()).collect();
    let twin_force_n = smooth(&twin_force_raw_n, window);
    let twin_torque_nm = smooth(&twin_torque_raw_nm, window);
    let monitor_force_n: Vec<f64> = estimates
        .iter()
        .map(|e| e.pressing_force_n.to_num::<f64>())
        .collect();
    let monitor_torque_nm: Vec<f64> = estimates
        .iter()
        .map(|e| e.braking_torque_nm.to_num::<f64>().abs())
        .collect();
    let pressing_force_rmse_n = rms(&monitor_force_n, &twin_force_n);
    let peak = twin_force_n.iter().cloned().fold(0.0, f64::max).max(1e-9);
    let braking_torque_rmse_nm = rms(&monitor_torque_nm, &twin_torque_nm);

    let hold = (HOLD_WINDOW_S * trace.sample_rate_hz) as usize;
    let n = rows.len().min(estimates.len());
    let tail = n.saturating_sub(hold)..n;
    let both_locked = n > hold
        && tail
            .clone()
            .all(|i| rows[i].brake_state == 2 && estimates[i].brake == BrakeState::Locked);
    let mean = |x: &[f64]| x[tail.clone()].iter().sum::<f64>() / hold.max(1) as f64;
    let holding_torque_nm =
        both_locked.then(|| (mean(&twin_torque_raw_nm), mean(&monitor_torque_nm)));

    let cut = rows
        .windows(2)
        .find(|w| w[0].drive_on && !w[1].drive_on)
        .map(|w| w[1].t_s)
        .or_else(|| rows.first().filter(|r| !r.drive_on).map(|r| r.t_s));
    let lock_time_s = cut.and_then(|from| {
        let twin = lock_time(&t_s, from, |i| rows[i].brake_state == 2)?;
        Some((
            twin,
            lock_time(&t_s[..n], from, |i| {
                estimates[i].brake == BrakeState::Locked
            }),
        ))
    });

    let mut flags = Vec::new();
    let mut before = Flags::default();
    for (e, r) in estimates.iter().zip(rows) {
        for ((now, name), (was, _)) in e.flags.named().into_iter().zip(before.named()) {
            if now && !was {
                flags.push(FlagEvent {
                    flag: name,
                    t_s: r.t_s,
                });
            }
        }
        before = e.flags;
    }

    Accuracy {
        t_s,
        twin_force_raw_n,
        twin_force_n,
        monitor_force_n,
        twin_torque_raw_nm,
        twin_torque_nm,
        monitor_torque_nm,
        pressing_force_rmse_n,
        pressing_force_rmse_pct: 100.0 * pressing_force_rmse_n / peak,
        braking_torque_rmse_nm,
        holding_torque_nm,
        trusted_at_end: n > 0 && estimates[n - 1].trusted,
        lock_time_s,
        flags,
    }
}

/// The flag that must answer a fault of this kind.
pub fn expected_flag(kind: FaultKind) -> &'static [&'static str] {
    match kind {
        FaultKind::FrictionLoss | FaultKind::PackWear | FaultKind::SpringBroken => {
            &["brake_weak", "brake_slip"]
        }
        FaultKind::RampJam => &["brake_weak", "brake_slip", "brake_drag"],
        FaultKind::Drag => &["brake_drag"],
        FaultKind::EncoderStuck | FaultKind::EncoderJump | FaultKind::CurrentOpen => {
            &["sensor_fault"]
        }
    }
}

/// How long the pack must fail to hold — slipping, or open (a worn pack's clearance can leave it
/// released) — with the drive off before a holding fault counts as manifest (s): a healthy pack
/// in the twin's physical reading locks within 2–11 ms of a cut (longest unlocked run with the
/// drive off in 1000 nominal Monte Carlo draws, seed 2026: 11.1 ms slipping, ≤ 1 ms open), so
/// a longer one is the brake failing to hold.
pub const FAILED_HOLD_SLIP_S: f64 = 0.020;

/// The current (A) below which a lost gain cannot be seen: twice the current sensor's offset
/// tolerance of the plant family (±0.25 A), ten times its noise (≤ 0.1 A σ, averaged). The paper
/// reading closes on less than 0.25 A (its speed-reference drive along the load takes no torque).
pub const VISIBLE_CURRENT_A: f64 = 0.5;

/// How far the output must turn for a failure to hold, or a frozen output reading, to show
/// (rad): beyond the rattle in the lost motion of a held output (≤ 0.13 rad in 1000 nominal
/// Monte Carlo draws, docs/monitor-design.md, "Common slip"). Inside it the encoders show what a
/// held output shows: a pack that opens for a while without letting the output go (a broken
/// spring's longer rattle), a worn pack whose output has only begun to creep, or a frozen
/// output reading of a shaft that rattles in its lost motion (no other sensor sees the output
/// inside its lost motion).
pub const HELD_RATTLE_RAD: f64 = 0.13;

/// When a fault first changes what the sensors can show — before that no monitor could see it
/// (a weakened pack that still self-locks is dormant, the case the periodic functional tests of
/// the field exist for). From the twin's truth columns:
/// - holding faults (friction_loss, spring_broken, pack_wear, ramp_jam): in the first run, at
///   or after the onset, in which the drive is off and the pack does not hold (slips, or is
///   open) for at least [`FAILED_HOLD_SLIP_S`] and the output turns more than
///   [`HELD_RATTLE_RAD`] from where it was when the run began, the moment it passes that
///   (before it, the output is still where a held one can be);
/// - drag: the first sample at or after the onset with the drive running;
/// - encoder_jump: at the onset; encoder_stuck: once the true output angle has left its value
///   at the onset (the frozen reading) by more than [`HELD_RATTLE_RAD`];
/// - current_open: the first sample at or after the onset with the drive running and its current
///   (the trace's command column: the true current) at least [`VISIBLE_CURRENT_A`]; on a trace
///   without it, the first with the drive running.
pub fn manifest_time(fault: &Fault, trace: &Trace) -> Option<f64> {
    let rows = &trace.rows;
    let start = rows.iter().position(|r| r.t_s >= fault.at_s)?;
    let after = || rows.iter().skip(start);
    match fault.kind {
        FaultKind::EncoderJump => Some(fault.at_s),
        FaultKind::Drag => after().find(|r| r.drive_on).map(|r| r.t_s),
        FaultKind::CurrentOpen => {
            let s = noback::sensors::DEFAULT_SENSORS;
            let mid = 1_i32 << (s.current_adc_bits - 1);
            let visible = (VISIBLE_CURRENT_A / s.amps_per_count()).round() as i32;
            after()
                .find(|r| {
                    r.drive_on
                        && r.current_command_code
                            .is_none_or(|c| (i32::from(c) - mid).abs() >= visible)
                })
                .map(|r| r.t_s)
        }
        FaultKind::EncoderStuck => {
            let angle0 = rows.get(start)?.output_angle_rad;
            after()
                .find(|r| (r.output_angle_rad - angle0).abs() > HELD_RATTLE_RAD)
                .map(|r| r.t_s)
        }
        FaultKind::FrictionLoss
        | FaultKind::SpringBroken
        | FaultKind::PackWear
        | FaultKind::RampJam => {
            // The present run without holding: its start time, the output angle then, and when
            // the output first left the held rattle in it.
            let mut run: Option<(f64, f64, Option<f64>)> = None;
            for r in after() {
                // Brake states: 0 released, 1 slipping, 2 locked (docs/trace-format.md).
                if !r.drive_on && r.brake_state != 2 {
                    let (t0, angle0, left) = run.get_or_insert((r.t_s, r.output_angle_rad, None));
                    if left.is_none() && (r.output_angle_rad - *angle0).abs() > HELD_RATTLE_RAD {
                        *left = Some(r.t_s);
                    }
                    if r.t_s - *t0 >= FAILED_HOLD_SLIP_S {
                        if let Some(t) = left {
                            return Some(*t);
                        }
                    }
                } else {
                    run = None;
                }
            }
            None
        }
    }
}

/// [`manifest_time`] beside the same run without the fault (`healthy`: same scene and noise):
/// a holding fault shows only once its output has also left the healthy output by more than
/// [`HELD_RATTLE_RAD`]; until then the encoders show what a healthy pack shows (the paper
/// reading's own braking lets its output run on, turn back and slip before it locks).
pub fn manifest_time_beside(fault: &Fault, trace: &Trace, healthy: &Trace) -> Option<f64> {
    let at = manifest_time(fault, trace)?;
    if !fault.kind.is_holding() {
        return Some(at);
    }
    trace
        .rows
        .iter()
        .zip(&healthy.rows)
        .filter(|(r, h)| r.t_s >= at && (r.t_s - h.t_s).abs() < 1e-9)
        .find(|(r, h)| (r.output_angle_rad - h.output_angle_rad).abs() > HELD_RATTLE_RAD)
        .map(|(r, _)| r.t_s)
}

/// Detection latency of a fault (s): from its manifesting to the first flag that answers its
/// kind raised at or after the onset (0 when the flag came first: detected before it could
/// harm). `None`: never flagged, or never manifest.
pub fn detection_latency_s(fault: &Fault, trace: &Trace, acc: &Accuracy) -> Option<f64> {
    latency_after(manifest_time(fault, trace)?, fault, acc)
}

/// [`detection_latency_s`] from a manifesting time found otherwise ([`manifest_time_beside`]).
pub fn latency_after(at: f64, fault: &Fault, acc: &Accuracy) -> Option<f64> {
    acc.flags
        .iter()
        .filter(|f| expected_flag(fault.kind).contains(&f.flag))
        .find(|f| f.t_s >= fault.at_s - 1e-9)
        .map(|f| (f.t_s - at).max(0.0))
}

/// Flags raised before the first fault's onset (all of them in a fault-free run), `overrun`
/// excluded (a host replay never misses a tick).
pub fn false_alarms(faults: &[Fault], acc: &Accuracy) -> usize {
    let first = faults.iter().map(|f| f.at_s).fold(f64::INFINITY, f64::min);
    acc.flags.iter().filter(|f| f.t_s < first).count()
}

#[cfg(test)]
mod tests;
