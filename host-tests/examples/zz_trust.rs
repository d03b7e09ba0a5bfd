use host_tests::family::{form, Family};
use host_tests::mc::{draw_in, evaluate, Campaign};
fn main() {
    let a: Vec<u64> = std::env::args()
        .skip(1)
        .map(|s| s.parse().unwrap())
        .collect();
    let mut c = Campaign::for_family(Family::Plant);
    c.commissioned = true;
    for i in 0..a[1] {
        let d = draw_in(Family::Plant, a[0], i, None);
        let o = evaluate(&d, &c);
        if let Some(b) = o.braking {
            if b.trusted && b.holding_err_pct > 2.0 {
                println!(
                    "{i} {} {:?} load {:.1} speed {:.1} err {:.1} % refused {}",
                    form(&d.scene),
                    d.scene.kind,
                    d.scene.load_torque_nm,
                    d.scene.initial_speed_rad_s,
                    b.holding_err_pct,
                    o.refused
                );
            }
        }
    }
}
