//! The scene classifier's unit tests.

#![cfg(test)]

use super::*;

/// Runs `windows` synchronism windows of a drive, the output and the input turning at
/// `speeds` (rad/s) from the angles `at` (rad); returns where they end.
fn drive(cl: &mut Classify, speeds: (f64, f64), windows: u32, at: (f64, f64)) -> (f64, f64) {
    let c = Config::default();
    let k = SceneSettings::new(&c, 1).expect("default configuration");
    let (out_rad, in_rad) = (
        c.sensors.output_rad_per_count(),
        c.sensors.input_rad_per_motor_count(),
    );
    let h = f64::from(WINDOW.ticks) / c.tick_hz;
    let mut pos = at;
    for _ in 0..windows {
        pos = (pos.0 + speeds.0 * h, pos.1 + speeds.1 * h);
        let x = Sensed {
            n: 1,
            drive: true,
            out: (pos.0 / out_rad).round() as u32 & ((1 << k.out_bits) - 1),
            motor: (pos.1 / in_rad).round() as u32 & (u32::MAX >> (32 - u32::from(k.motor_bits))),
            ..Sensed::NONE
        };
        cl.sync_window(&k, &x, Q16::from_num(speeds.0));
    }
    pos
}

#[test]
fn an_input_gaining_on_the_output_faster_than_the_stick_speed_ran_ahead() {
    let k = SceneSettings::new(&Config::default(), 1).expect("default configuration");
    let start = Sensed {
        n: 1,
        drive: true,
        drive_edge: true,
        first: true,
        ..Sensed::NONE
    };
    let mut cl = Classify::new();
    cl.tick(&start, &Observed::NONE);
    // Together at 5 rad/s for 0.1 s: not ahead.
    let at = drive(&mut cl, (5.0, 5.0), 64, (0.0, 0.0));
    assert!(!cl.input_ran_ahead(&k));
    // The input 0.5 rad/s faster (18198 and 57429 at seed 4242: 0.55–0.64): ahead.
    let at = drive(&mut cl, (5.0, 5.5), 64, at);
    assert!(cl.input_ran_ahead(&k));
    // The drive off keeps the verdict; a new drive starts its own.
    cl.tick(
        &Sensed {
            drive: false,
            ..start
        },
        &Observed::NONE,
    );
    assert!(cl.input_ran_ahead(&k));
    cl.tick(
        &Sensed {
            first: false,
            ..start
        },
        &Observed::NONE,
    );
    assert!(!cl.input_ran_ahead(&k));
    // Below the stick speed, or the output gaining: not ahead.
    let at = drive(&mut cl, (5.0, 5.2), 128, at);
    assert!(!cl.input_ran_ahead(&k));
    drive(&mut cl, (5.5, 5.0), 128, at);
    assert!(!cl.input_ran_ahead(&k));
}

#[test]
fn lock_times_give_a_late_lock_a_quarter_of_the_gap_short_of_the_openings() {
    let set = |along_s, against_s| {
        SceneSettings::new(
            &Config {
                lock_times: Some(LockTimes { along_s, against_s }),
                ..Config::default()
            },
            1,
        )
        .map(|k| k.lock_against_ticks)
    };
    // 12 and 16 ms at 10 kHz: against from 15 ms.
    assert_eq!(set(0.012, 0.016), Ok(150));
    let refused = Err(ConfigError::OutOfRange {
        parameter: "lock_times",
    });
    assert_eq!(set(0.012, 0.0135), refused, "closer than MIN_GAP_S");
    assert_eq!(set(0.0, 0.016), refused);
    assert_eq!(set(f64::NAN, 0.016), refused);
    assert_eq!(
        SceneSettings::new(&Config::default(), 1).map(|k| k.lock_against_ticks),
        Ok(0)
    );
}
