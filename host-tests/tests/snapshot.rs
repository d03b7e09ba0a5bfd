//! A monitor restored from its saved state steps on exactly as the one that saved it, from any
//! tick of a scene: what lets a trip record be replayed bit-exact on the host.

use host_tests::accuracy::scene_trace;
use noback::monitor::{AidingBraking, Config, DrivingPack, Inputs, Monitor, SnapshotError};
use noback::trip_log::record::MAGIC;
use noback_twin::scene::Scene;

fn inputs(r: &noback_twin::trace::TraceRow) -> Inputs {
    Inputs::new(r.current_code, r.motor_count, r.output_count, r.drive_on)
}

#[test]
fn a_restored_monitor_steps_on_bit_exact() {
    let text = "[scene]\nkind = \"reverse_load\"\n[[fault]]\nkind = \"friction_loss\"\nat_s = 0.2\nseverity = 0.8\n";
    let trace = scene_trace(&Scene::from_toml("snap", text).unwrap()).unwrap();
    let mut largest = 0;
    for cut in [1, 7, 1000, 2003, 2500, 4001] {
        let mut a = Monitor::new(Config::default()).unwrap();
        for r in &trace.rows[..cut] {
            a.step(&inputs(r));
        }
        let mut buf = [0_u8; 4096];
        let bytes = a.save_state(&mut buf).unwrap().to_vec();
        largest = largest.max(bytes.len());
        let mut b = Monitor::restore(Config::default(), &bytes).unwrap();
        for r in &trace.rows[cut..] {
            assert_eq!(
                a.step(&inputs(r)).to_words(),
                b.step(&inputs(r)).to_words(),
                "cut at {cut}"
            );
        }
    }
    println!("largest saved state: {largest} bytes");
    assert!(largest < 2048, "{largest} bytes");
}

/// A spring-only unit commissioned with its aiding braking (the paper form's acceptance values),
/// saved while it brakes a closing's load between the cut and the lock: the braking read so far
/// is state, restored with the rest.
#[test]
fn a_spring_only_unit_restored_mid_braking_steps_on_bit_exact() {
    let c = Config {
        driving_pack: DrivingPack::SpringOnly,
        commissioned: true,
        aiding_braking: Some(AidingBraking {
            inertia_kg_m2: 0.149,
            drag_nm: 8.37,
            load_gain: 1.49,
        }),
        ..Config::default()
    };
    let text = "[scene]\nkind = \"forward_load\"\nreading = \"paper\"\n";
    let trace = scene_trace(&Scene::from_toml("snap", text).unwrap()).unwrap();
    let cut = trace
        .rows
        .windows(2)
        .position(|w| w[0].drive_on && !w[1].drive_on)
        .expect("a cut")
        + 1;
    for at in [cut + 40, cut + 160] {
        let mut a = Monitor::new(c).unwrap();
        for r in &trace.rows[..at] {
            a.step(&inputs(r));
        }
        let mut buf = [0_u8; 4096];
        let bytes = a.save_state(&mut buf).unwrap().to_vec();
        let mut b = Monitor::restore(c, &bytes).unwrap();
        for r in &trace.rows[at..] {
            assert_eq!(
                a.step(&inputs(r)).to_words(),
                b.step(&inputs(r)).to_words(),
                "saved {} ticks after the cut",
                at - cut
            );
        }
    }
}

#[test]
fn a_short_buffer_or_corrupt_bytes_are_refused() {
    let m = Monitor::new(Config::default()).unwrap();
    let mut small = [0_u8; 16];
    assert_eq!(
        m.save_state(&mut small).unwrap_err(),
        SnapshotError::BufferFull
    );
    let mut buf = [0_u8; 4096];
    let n = m.save_state(&mut buf).unwrap().len();
    assert_eq!(
        Monitor::restore(Config::default(), &buf[..n / 2]).unwrap_err(),
        SnapshotError::Corrupt
    );
}

/// A fresh monitor's saved state, its length and FNV-1a: a change here is a change of the
/// state's layout, which must also change the trip record's magic, or a record of the old
/// layout would restore into a wrong state.
#[test]
fn the_fresh_state_is_the_one_recorded_with_the_record_magic() {
    let m = Monitor::new(Config::default()).unwrap();
    let mut buf = [0_u8; 4096];
    let bytes = m.save_state(&mut buf).unwrap();
    let mut d = noback::digest::Fnv1a::new();
    bytes.iter().for_each(|b| d.push_byte(*b));
    assert_eq!(
        (MAGIC, bytes.len(), d.value()),
        (*b"NBT7", 279, 0x2869_0853),
        "the record's magic, the fresh state's length and digest"
    );
}
