//! The trip log: records replay bit-exact, refuse corruption, and survive power cuts.

use host_tests::power_fail::{run, sample_records};
use noback::monitor::Config;
use noback::trip_log::record::{decode, RecordError};

#[test]
fn every_record_replays_to_its_estimate_bit_exact() {
    for bytes in sample_records(6).unwrap() {
        let r = decode(&bytes).unwrap();
        let last = r.replay(Config::default()).unwrap();
        assert_eq!(last.to_words(), r.estimate, "tick {}", r.tick);
        assert_eq!(last.tick, r.tick);
        assert_eq!(last.flags, r.now);
        assert!(
            r.window_len() > 8 && r.window_len() <= 16,
            "{}",
            r.window_len()
        );
    }
}

#[test]
fn a_torn_or_flipped_record_is_refused() {
    let bytes = sample_records(1).unwrap().remove(0);
    assert_eq!(
        decode(&bytes[..bytes.len() - 1]).unwrap_err(),
        RecordError::NotARecord
    );
    for at in [0, 9, 40, bytes.len() / 2, bytes.len() - 2] {
        let mut flipped = bytes.clone();
        flipped[at] ^= 0x10;
        assert!(decode(&flipped).is_err(), "a flip at byte {at} was read");
    }
}

#[test]
fn power_cut_at_every_step_loses_nothing_but_the_record_in_flight() {
    let records = sample_records(14).unwrap();
    let f = run(&records).unwrap();
    println!("{f:?}");
    assert!(f.cuts > 1000, "{} cuts", f.cuts);
    assert_eq!(
        (f.records_lost, f.corrupt_reads, f.stopped_working),
        (0, 0, 0)
    );
    // The queue commits an item with its last write: a record cut short is always absent.
    assert_eq!(f.in_flight_whole + f.in_flight_absent, f.cuts);
    assert!(
        f.dropped > 0 && f.kept > 2,
        "the overflow run must drop the oldest: {f:?}"
    );
    assert!(f.erases_per_record > 0.0);
}
