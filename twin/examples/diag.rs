//! Diagnostic dump of a short physical run (development aid).
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let kind = SceneKind::parse(args.first().map(String::as_str).unwrap_or("drive"))
        .unwrap_or(SceneKind::Drive);
    let dur: f64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(0.01);
    let every: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(10);
    let mut s = Scene::builtin(kind, Reading::Physical);
    s.duration_s = dur;
    if s.release_at_s.is_some_and(|r| r > dur) {
        s.release_at_s = None;
    }
    for a in args.iter().skip(3) {
        let (k, v) = a.split_once('=').unwrap_or(("", "0"));
        let v: f64 = v.parse().unwrap_or(0.0);
        match k {
            "axial" => s.open.axial_smoothing_m_s = v,
            "bearing" => s.open.bearing_smoothing_rad_s = v,
            "tol" => s.tolerance = v,
            "floor" => s.open.approach_speed_floor_m_s = v,
            "gain" => s.open.drive_gain_nm_s_rad = v,
            _ => {}
        }
    }
    match noback_twin::sim::run(&s) {
        Ok(r) => {
            for x in r.samples.iter().step_by(every) {
                println!("{:.4} ws={:8.3} wi={:8.3} Tdrv={:7.2} Fp={:8.1} Tb={:7.2} st={} Fc={:8.1} Fin={:8.1} xo={:.3e} xb={:.3e}",
                  x.t_s, x.output_speed_rad_s, x.input_speed_rad_s, x.drive_torque_nm, x.pressing_force_n, x.braking_torque_nm, x.brake_state, x.contact_force_n, x.input_contact_force_n, x.ball_axial_m, x.shaft_axial_m);
                if std::env::var_os("FULL").is_some() {
                    println!(
                        "   xb={:.9e} Fp={:.6} ws={:.9}",
                        x.shaft_axial_m, x.pressing_force_n, x.output_speed_rad_s
                    );
                }
            }
            println!("{:?} wall {:.2}", r.stats, r.wall_s);
        }
        Err(e) => println!("{e}"),
    }
}
