//! The monitor's model per scene follows the cheapest-per-scene table (issue 6): each row of
//! `docs/results/cheapest-per-scene.md` (written by `cargo xtask bench`, never by hand) names
//! the cheapest candidate that meets the accuracy targets in one of the twin's scenes, and the
//! monitor must run exactly that model in the scene it recognises there. When a rerun of the
//! bench changes a row, this test fails until the monitor's configuration follows.

use noback::monitor::{Config, Monitor, Scene};

/// The scene the monitor recognises in each of the twin's scenes (after the drive cut for the
/// two braking scenes).
fn monitor_scene(twin_scene: &str) -> Option<Scene> {
    match twin_scene {
        "reverse_load" | "forward_load" => Some(Scene::FaultBraking),
        "hold" => Some(Scene::Holding),
        "drive" => Some(Scene::Driving),
        "continuous_closing" => Some(Scene::Overrunning),
        _ => None,
    }
}

#[test]
fn every_scene_runs_the_tables_cheapest_model() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../docs/results/cheapest-per-scene.md"
    );
    let text = std::fs::read_to_string(path).expect("cargo xtask bench writes the table");
    let monitor = Monitor::new(Config::default()).expect("defaults are valid");
    let mut seen = Vec::new();
    for line in text.lines().filter(|l| l.starts_with("| ")) {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        let (Some(&scene), Some(&model)) = (cells.get(1), cells.get(2)) else {
            continue;
        };
        let Some(recognised) = monitor_scene(scene) else {
            continue; // the header row
        };
        assert_eq!(
            monitor.scene_model(recognised).to_string(),
            model,
            "{scene}: the table's cheapest model is `{model}`, the monitor runs `{}` in {recognised:?}",
            monitor.scene_model(recognised)
        );
        seen.push(scene);
    }
    for scene in [
        "reverse_load",
        "forward_load",
        "hold",
        "drive",
        "continuous_closing",
    ] {
        assert!(seen.contains(&scene), "no row for {scene} in {path}");
    }
}

#[test]
fn the_braking_model_rate_is_configurable_and_validated() {
    let mut c = Config {
        braking_model_hz: 2_000.0,
        ..Config::default()
    };
    let m = Monitor::new(c).expect("2 kHz divides 10 kHz");
    assert_eq!(
        m.scene_model(Scene::FaultBraking).to_string(),
        "reduced I16F16 euler 2 kHz"
    );
    for bad in [0.0, -1.0, f64::NAN, 3_000.0, 20_000.0, 5.0] {
        c.braking_model_hz = bad;
        assert!(Monitor::new(c).is_err(), "{bad} Hz must be rejected");
    }
}
