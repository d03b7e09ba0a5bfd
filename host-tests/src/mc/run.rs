//! Running a campaign: the configuration each draw's monitor runs on (commissioned on the
//! draw's own acceptance runs, or not), one draw through the twin and the monitor, and every
//! draw over the machine's cores.

use super::{draw_trace_after, not_driven, Context, Draw, Outcome, PRE_ROLL_S};
use crate::accuracy::{
    compare, latency_after, manifest_time, manifest_time_beside, run_monitor, run_monitor_with,
};
use crate::dormant::functional_test_after;
use crate::family::Family;
use noback::digest::Fnv1a;
use noback::monitor::Config;
use noback_twin::scene::SceneKind;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// What a campaign runs the draws with: the monitor's configuration and the pre-roll (the
/// defaults are the shipped monitor and [`PRE_ROLL_S`]; others serve the ablations in
/// docs/decisions.md, `cargo xtask monitor-mc --power-on-settle S --pre-roll S`).
#[derive(Clone, Copy, Debug)]
pub struct Campaign {
    /// The monitor's configuration.
    pub config: Config,
    /// How long the twin runs before the monitor is powered on (s).
    pub pre_roll_s: f64,
    /// The functional test also runs after one nominal run in this many (by the run's noise
    /// seed; 0: none) — and after every fault run whose fault stayed dormant (unless 0).
    pub test_every: u64,
    /// Each draw's unit is commissioned on its healthy plant ([`commission_draw`]) and runs
    /// on that configuration (on `config` if acceptance refuses it).
    pub commissioned: bool,
}

impl Campaign {
    /// The campaign of a plant family, with the monitor [`Family::config`] gives it.
    pub fn for_family(family: Family) -> Campaign {
        Campaign {
            config: family.config(),
            pre_roll_s: PRE_ROLL_S,
            test_every: TEST_EVERY,
            commissioned: false,
        }
    }

    /// The configuration draw `d`'s monitor runs on, and whether acceptance refused its unit.
    /// It is configured with the nominal Table 2, not the drawn mechanism: it must cope with a
    /// ±10 % real part (commissioned: with what its acceptance runs identified).
    pub fn config_for(&self, d: &Draw) -> (Config, bool) {
        match self.commissioned.then(|| commission_draw(d)) {
            Some(Ok(c)) => (c.config, false),
            Some(Err(_)) => (self.config, true),
            None => (self.config, false),
        }
    }
}

/// Nominal draws [`behaviour_digest`] runs: the first 128 of the plant family hold every
/// (form, scene kind, load direction) class at seeds 2718, 3141 and 4242.
pub const BEHAVIOUR_RUNS: u64 = 128;

/// The monitor's behaviour in a campaign: FNV-1a over every estimate's words, without and
/// with the current command, on `draws` run as [`evaluate`] runs them; a run that fails folds
/// in its error's text, as `evaluate` counts it. Unlike a configuration digest, this changes
/// with the monitor's code, on any draw the code treats otherwise.
pub fn behaviour_digest(draws: &[Draw], campaign: &Campaign) -> u32 {
    let mut digest = Fnv1a::new();
    for d in draws {
        let (config, _) = campaign.config_for(d);
        let runs = draw_trace_after(d, campaign.pre_roll_s).and_then(|trace| {
            [false, true]
                .map(|command| run_monitor_with(&trace, config, command))
                .into_iter()
                .collect::<Result<Vec<_>, _>>()
        });
        match runs {
            Ok(runs) => runs
                .iter()
                .flatten()
                .flat_map(|e| e.to_words())
                .for_each(|w| digest.push(w)),
            Err(e) => e.bytes().for_each(|b| digest.push_byte(b)),
        }
    }
    digest.value()
}

impl Default for Campaign {
    /// The default family's campaign.
    fn default() -> Self {
        Campaign::for_family(Family::PhysicalDefault)
    }
}

/// The share of nominal runs the functional test follows by default (one in this many).
pub const TEST_EVERY: u64 = 10;

/// Runs one draw through the twin and the monitor, then the functional test if it is due.
pub fn evaluate(d: &Draw, campaign: &Campaign) -> Outcome {
    let fault = d.scene.faults.first().copied();
    let fail = |e: String| Outcome {
        error: Some(e),
        ..Outcome::quiet(fault.map(|f| f.kind))
    };
    let trace = match draw_trace_after(d, campaign.pre_roll_s) {
        Ok(trace) => trace,
        Err(e) => return fail(e),
    };
    let (config, refused) = campaign.config_for(d);
    let estimates = match run_monitor(&trace, config) {
        Ok(e) => e,
        Err(e) => return fail(e),
    };
    let acc = compare(&trace, &estimates);
    let with_command = match run_monitor_with(&trace, config, true) {
        Ok(e) => compare(&trace, &e),
        Err(e) => return fail(e),
    };
    let onset = fault.map_or(f64::INFINITY, |f| f.at_s);
    // The same draw without its fault: where a holding fault shows, and whether the plant
    // itself came apart (counted apart, as a nominal run is).
    let healthy = match fault {
        Some(_) => {
            let mut healthy = d.clone();
            healthy.scene.faults.clear();
            match draw_trace_after(&healthy, campaign.pre_roll_s) {
                Ok(same) => Some(same),
                Err(e) => return fail(e),
            }
        }
        None => None,
    };
    let same = healthy.as_ref().unwrap_or(&trace);
    let manifest = match fault {
        Some(f) if f.kind.is_holding() => manifest_time_beside(&f, &trace, same),
        Some(f) => manifest_time(&f, &trace),
        None => None,
    };
    let manifested = manifest.is_some();
    let not_driven = not_driven(same, &d.scene.sensors);
    let every = campaign.test_every;
    let tested = every > 0
        && match fault {
            Some(_) => !manifested && !not_driven,
            None => !not_driven && d.scene.noise.seed.is_multiple_of(every),
        };
    let test = if tested {
        match functional_test_after(d, config) {
            Ok(v) => Some(v),
            Err(e) => return fail(e),
        }
    } else {
        None
    };
    Outcome {
        fault: fault.map(|f| f.kind),
        latency_s: fault
            .zip(manifest)
            .and_then(|(f, at)| latency_after(at, &f, &acc)),
        latency_with_command_s: fault
            .zip(manifest)
            .and_then(|(f, at)| latency_after(at, &f, &with_command)),
        manifested,
        context: fault.map(|f| Context::of(f.at_s, &trace, d.scene.kind, &config)),
        false_flags: acc.flags.iter().filter(|f| f.t_s < onset).count(),
        false_flags_with_command: with_command.flags.iter().filter(|f| f.t_s < onset).count(),
        error: None,
        not_driven,
        test,
        warned: fault.is_some()
            && acc
                .flags
                .iter()
                .any(|f| f.flag == "brake_degraded" && f.t_s >= onset),
        refused,
        braking: match (fault, d.scene.kind) {
            (None, SceneKind::ReverseLoad | SceneKind::ForwardLoad) => acc.braking(),
            _ => None,
        },
    }
}

/// A draw's unit commissioned on the acceptance procedure ([`crate::commission::ACCEPTANCE`])
/// of its healthy plant, its sensors mounted as the draw's, from its build record as inspection
/// measured it ([`crate::as_built::AsBuilt::inspected`], drawn apart from the run's draws).
pub fn commission_draw(d: &Draw) -> Result<crate::commission::Commissioning, String> {
    let seed = d.scene.noise.seed ^ RECORD_STREAM;
    let base = crate::as_built::AsBuilt::inspected(&d.scene.mechanism, seed).config();
    let plan = &crate::commission::ACCEPTANCE;
    crate::commission::commission_unit_with(&d.scene, plan, |t| d.mount(t), base)
}

/// Mixed into a draw's noise seed to draw its build record's inspection errors.
const RECORD_STREAM: u64 = 0x6275_696c_7420_7265;

/// Runs every draw on `threads` workers, calling `progress(done, total)` as runs finish.
pub fn run_all(
    draws: &[Draw],
    campaign: &Campaign,
    threads: usize,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Vec<Outcome> {
    let next = AtomicUsize::new(0);
    let results = Mutex::new(vec![None; draws.len()]);
    std::thread::scope(|scope| {
        for _ in 0..threads.max(1) {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(d) = draws.get(i) else { break };
                let outcome = evaluate(d, campaign);
                let done = {
                    let mut r = results.lock().unwrap_or_else(|p| p.into_inner());
                    r[i] = Some(outcome);
                    r.iter().filter(|o| o.is_some()).count()
                };
                progress(done, draws.len());
            });
        }
    });
    results
        .into_inner()
        .unwrap_or_else(|p| p.into_inner())
        .into_iter()
        .flatten()
        .collect()
}
