//! A relieved pack's cut-to-lock times from the acceptance runs (`Config::lock_times`): the
//! monitor, set as commissioned, is run on each run and its first lock after the cut timed.

use super::RunFigures;
use crate::accuracy::run_monitor;
use noback::monitor::{Config, LockTimes, Scene};
use noback_twin::trace::Trace;

/// Seconds from the drive's cut to the monitor's first lock after it, as the monitor counts
/// them: to the classification that locked, one tick before its estimate shows it.
fn cut_to_lock_s(trace: &Trace, config: Config) -> Result<f64, String> {
    let estimates = run_monitor(trace, config)?;
    let cut = trace
        .rows
        .iter()
        .position(|r| !r.drive_on)
        .ok_or("no drive cut")?;
    let lock = estimates[cut..]
        .iter()
        .position(|e| e.scene == Scene::Holding)
        .ok_or("the monitor saw no lock after the cut")?;
    Ok(lock.saturating_sub(1) as f64 / config.tick_hz)
}

/// The closings' longest and the openings' shortest cut-to-lock time, where both were run and
/// they lie [`LockTimes::MIN_GAP_S`] apart or more; else `None` (the power-on guess stands).
pub fn lock_times(
    figures: &[RunFigures],
    traces: &[(&Trace, f64)],
    config: Config,
) -> Result<Option<LockTimes>, String> {
    let (mut along_s, mut against_s) = (f64::NEG_INFINITY, f64::INFINITY);
    for f in figures {
        let t = cut_to_lock_s(traces[f.run].0, config)
            .map_err(|e| format!("run {}: {e}", f.run + 1))?;
        if f.closing {
            along_s = along_s.max(t);
        } else {
            against_s = against_s.min(t);
        }
    }
    let apart = against_s - along_s >= LockTimes::MIN_GAP_S;
    Ok((along_s.is_finite() && against_s.is_finite() && apart)
        .then_some(LockTimes { along_s, against_s }))
}
