use host_tests::dormant::{functional_test_after, Verdict};
use host_tests::family::Family;
use host_tests::mc::{commission_draw, draw_in};
use noback::monitor::DrivingPack;
use noback_twin::fault::FaultKind;
fn main() -> Result<(), String> {
    let seed: u64 = std::env::args().nth(1).unwrap().parse().unwrap();
    let n: u64 = std::env::args().nth(2).unwrap().parse().unwrap();
    let mut tally = std::collections::BTreeMap::new();
    for i in 0..n {
        let mut d = draw_in(Family::Plant, seed, i, None);
        let Ok(c) = commission_draw(&d) else { continue };
        let so = c.config.driving_pack == DrivingPack::SpringOnly;
        for (name, fault) in [
            ("healthy", None),
            ("pack_wear", Some(FaultKind::PackWear)),
            ("spring_broken", Some(FaultKind::SpringBroken)),
            ("ramp_jam", Some(FaultKind::RampJam)),
        ] {
            d.scene.faults = fault
                .map(|k| {
                    host_tests::dormant::from_start(
                        k,
                        0.5 + 0.5 * ((i * 7919 % 100) as f64 / 100.0),
                    )
                })
                .into_iter()
                .collect();
            let v = functional_test_after(&d, c.config)?;
            let e = tally
                .entry((format!("{:?}", d.scene.reading), so, name))
                .or_insert((0, 0, 0));
            match v {
                Verdict::Rejected => e.0 += 1,
                Verdict::Pass => e.1 += 1,
                Verdict::Fail => e.2 += 1,
            }
        }
    }
    for (k, v) in tally {
        println!("{k:?}: rejected {} pass {} fail {}", v.0, v.1, v.2);
    }
    Ok(())
}
