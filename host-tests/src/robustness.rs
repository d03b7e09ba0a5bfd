//! Input classes the monitor is driven through, each with the outcome it must give: the table a
//! reviewer asks for ("what inputs were tried and what happened"). The test
//! `host-tests/tests/robustness.rs` asserts every class; `cargo xtask reliability` writes the same
//! results into `docs/reliability.md`.
//!
//! Every class starts from a monitor that has settled at rest (drive off, ADC mid-scale), so a
//! flag can be blamed on the class's input. Across all classes every estimate is also checked
//! against the invariants of [`crate::fuzz::check_estimate`] (bounded, latched, ticks counted).

use crate::fuzz::check_estimate;
use noback::monitor::{Config, Estimate, Flags, Inputs, Monitor};

/// ADC mid-scale (0 A) for the default 12-bit converter.
const MID: u16 = 2048;
/// Output encoder counts per turn (14 bits).
const OUT_COUNTS: u32 = 1 << 14;
/// Motor counter modulus (16 bits).
const MOTOR_COUNTS: u32 = 1 << 16;

/// The result of one class.
#[derive(Clone, Debug, PartialEq)]
pub struct ClassResult {
    /// What was fed.
    pub class: &'static str,
    /// What must happen.
    pub expected: &'static str,
    /// Separate input streams tried.
    pub streams: usize,
    /// Monitor steps taken.
    pub steps: usize,
    /// Streams whose outcome was not the expected one (described).
    pub failures: Vec<String>,
}

struct Run {
    monitor: Monitor,
    prev: Option<Estimate>,
    steps: usize,
    error: Option<String>,
}

impl Run {
    fn settled() -> Run {
        let mut r = Run {
            monitor: Monitor::new(Config::default()).unwrap_or_else(unreachable_config),
            prev: None,
            steps: 0,
            error: None,
        };
        r.settle_at(0, 0);
        r
    }

    /// A fresh monitor that has settled at rest at these counter values.
    fn settle_at(&mut self, out: u32, motor: u32) {
        self.monitor = Monitor::new(Config::default()).unwrap_or_else(unreachable_config);
        self.prev = None;
        for _ in 0..300 {
            self.step(Inputs::new(MID, motor, out, false));
        }
    }

    fn step(&mut self, inputs: Inputs) -> Estimate {
        let e = self.monitor.step(&inputs);
        if self.error.is_none() {
            if let Err(msg) = check_estimate(
                &e,
                self.prev.as_ref(),
                u32::from(inputs.ticks_elapsed.max(1)),
                false,
            ) {
                self.error = Some(msg);
            }
        }
        self.prev = Some(e);
        self.steps += 1;
        e
    }

    fn flags(&self) -> Flags {
        self.monitor.flags()
    }
}

fn unreachable_config(e: noback::monitor::ConfigError) -> Monitor {
    // The default configuration is valid (tested elsewhere); report rather than panic.
    panic!("the default monitor configuration was rejected: {e:?}")
}

fn class(
    class: &'static str,
    expected: &'static str,
    streams: impl Iterator<Item = (String, Box<dyn FnOnce(&mut Run) -> Result<(), String>>)>,
) -> ClassResult {
    let mut r = ClassResult {
        class,
        expected,
        streams: 0,
        steps: 0,
        failures: Vec::new(),
    };
    for (name, body) in streams {
        let mut run = Run::settled();
        let before = run.steps;
        let outcome = body(&mut run);
        r.streams += 1;
        r.steps += run.steps - before;
        if let Some(e) = run.error.take() {
            r.failures.push(format!("{name}: invariant broken: {e}"));
        } else if let Err(e) = outcome {
            r.failures.push(format!("{name}: {e}"));
        }
    }
    r
}

type Body = Box<dyn FnOnce(&mut Run) -> Result<(), String>>;

/// Runs every class.
pub fn all_classes() -> Vec<ClassResult> {
    vec![
        class(
            "every ADC code 0..=65535, held 8 ticks, drive off",
            "codes above 4095 raise sensor_fault at once and mark the estimate untrusted; the rest stay bounded",
            (0..=u16::MAX).step_by(1).map(|code| {
                let body: Body = Box::new(move |r: &mut Run| {
                    let mut last = r.step(Inputs::new(code, 0, 0, false));
                    for _ in 1..8 {
                        last = r.step(Inputs::new(code, 0, 0, false));
                    }
                    if code > 4095 && (!last.flags.sensor_fault || last.trusted) {
                        return Err("out-of-range code not flagged".into());
                    }
                    Ok(())
                });
                (format!("code {code}"), body)
            }),
        ),
        class(
            "output encoder crossing its wrap at every 64th start count, 2 counts/tick, drive off",
            "wrap is motion, never a sensor fault",
            (0..OUT_COUNTS).step_by(64).map(|start| {
                let body: Body = Box::new(move |r: &mut Run| {
                    // Settle at `start`, then creep forward across the wrap.
                    r.settle_at(start, 0);
                    for i in 0..400_u32 {
                        let out = (start + 2 * i) % OUT_COUNTS;
                        r.step(Inputs::new(MID, 0, out, false));
                    }
                    if r.flags().sensor_fault {
                        return Err("wrap flagged as a sensor fault".into());
                    }
                    Ok(())
                });
                (format!("start {start}"), body)
            }),
        ),
        class(
            "motor counter crossing its 16-bit wrap while driving with matching output motion",
            "wrap is motion, never a sensor fault",
            (0..MOTOR_COUNTS).step_by(4096).map(|start| {
                let body: Body = Box::new(move |r: &mut Run| {
                    // Both shafts turn together at about 3 rad/s at the input.
                    r.settle_at(0, start);
                    for i in 0..2000_u32 {
                        let motor = (start + 6 * i) % MOTOR_COUNTS;
                        // 6 motor counts = 6·2π/(4096·30) rad at the input = 0.8 output counts.
                        let out = (i * 4 / 5) % OUT_COUNTS;
                        r.step(Inputs::new(MID + 60, motor, out, true));
                    }
                    if r.flags().sensor_fault {
                        return Err(format!("flags {:?}", r.flags()));
                    }
                    Ok(())
                });
                (format!("start {start}"), body)
            }),
        ),
        class(
            "one-sample output encoder jump of 200..=8000 counts at rest",
            "sensor_fault raised; no brake flag from the glitch",
            (200..=8000_u32).step_by(200).map(|jump| {
                let body: Body = Box::new(move |r: &mut Run| {
                    r.step(Inputs::new(MID, 0, jump % OUT_COUNTS, false));
                    for _ in 0..3000 {
                        r.step(Inputs::new(MID, 0, 0, false));
                    }
                    let f = r.flags();
                    if !f.sensor_fault {
                        return Err("jump not flagged".into());
                    }
                    if f.brake_slip || f.brake_weak || f.brake_drag {
                        return Err(format!("glitch raised a brake flag: {f:?}"));
                    }
                    Ok(())
                });
                (format!("jump {jump}"), body)
            }),
        ),
        class(
            "counter values beyond the register width (bits above 14 / 16 set)",
            "sensor_fault raised",
            (0..32_u32).map(|bit| {
                let body: Body = Box::new(move |r: &mut Run| {
                    let v = 1_u32 << bit;
                    let e = if bit < 16 {
                        r.step(Inputs::new(MID, 0, v, false))
                    } else {
                        r.step(Inputs::new(MID, v, 0, false))
                    };
                    let beyond = bit >= 14;
                    if beyond && !e.flags.sensor_fault {
                        return Err("value beyond the register not flagged".into());
                    }
                    Ok(())
                });
                (format!("bit {bit}"), body)
            }),
        ),
        class(
            "drive-commanded flag toggling every tick for 1 s, shafts at rest",
            "bounded; no brake flag",
            std::iter::once({
                let body: Body = Box::new(|r: &mut Run| {
                    for i in 0..10_000_u32 {
                        r.step(Inputs::new(MID, 0, 0, i % 2 == 0));
                    }
                    let f = r.flags();
                    if f.brake_slip || f.brake_weak || f.brake_drag {
                        return Err(format!("{f:?}"));
                    }
                    Ok(())
                });
                ("toggle".to_string(), body)
            }),
        ),
        class(
            "a late step after 2..=255 ticks (missed deadlines), at rest",
            "overrun raised, ticks counted, bounded",
            (2..=255_u8).map(|n| {
                let body: Body = Box::new(move |r: &mut Run| {
                    let e = r.step(Inputs {
                        ticks_elapsed: n,
                        ..Inputs::new(MID, 0, 0, false)
                    });
                    if !e.flags.overrun {
                        return Err("overrun not raised".into());
                    }
                    Ok(())
                });
                (format!("late by {n}"), body)
            }),
        ),
    ]
}
