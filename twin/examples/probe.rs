//! Probe: run the built-in scenes and print metrics (development aid).
use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let reading = Reading::parse(args.first().map(String::as_str).unwrap_or("paper"))
        .unwrap_or(Reading::Paper);
    let dur: Option<f64> = args.get(2).and_then(|s| s.parse().ok());
    for kind in SceneKind::ALL {
        if let Some(k) = args.get(1) {
            if k != kind.name() {
                continue;
            }
        }
        let mut s = Scene::builtin(kind, reading);
        if let Some(d) = dur {
            s.duration_s = d;
            if s.release_at_s.is_some_and(|r| r > d) {
                s.release_at_s = None;
            }
        }
        match noback_twin::sim::run(&s) {
            Ok(r) => {
                let m = noback_twin::metrics::compute(&s, &r.samples, &r.stats, r.wall_s);
                println!("{}", serde_json::to_string(&m).unwrap_or_default());
            }
            Err(e) => println!("{}: {e}", kind.name()),
        }
    }
}
