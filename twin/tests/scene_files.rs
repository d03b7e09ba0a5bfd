//! Scene-file errors, one per class: each names the offending key.

use noback_twin::reading::Reading;
use noback_twin::scene::{Scene, SceneKind};

fn err(text: &str) -> String {
    Scene::from_toml("t", text).unwrap_err().to_string()
}

const BASE: &str = "[scene]\nkind = \"forward_load\"\n";

#[test]
fn a_valid_file_overrides_what_it_names() {
    let s = Scene::from_toml(
        "t",
        "[scene]\nkind = \"forward_load\"\nreading = \"paper\"\nload_torque_nm = 15.0\nrelease_at_s = 0.1\nduration_s = 0.5\n\
         [mechanism]\nmu_static = 0.25\n[sensors]\ncurrent_noise_a = 0.1\nnoise_seed = 9\n[open]\napproach_speed_floor_m_s = 0.1\n\
         [[fault]]\nkind = \"friction_loss\"\nat_s = 0.3\nseverity = 0.7\n",
    )
    .unwrap();
    assert_eq!(s.kind, SceneKind::ForwardLoad);
    assert_eq!(s.reading, Reading::Paper);
    assert_eq!(s.load_torque_nm, 15.0);
    assert_eq!(s.release_at_s, Some(0.1));
    assert_eq!(s.mechanism.mu_static, 0.25);
    assert_eq!(
        s.mechanism.mu_dynamic, 0.17,
        "untouched values stay Table 2"
    );
    assert_eq!(s.noise.seed, 9);
    assert_eq!(s.open.approach_speed_floor_m_s, 0.1);
    assert_eq!(s.faults.len(), 1);
}

#[test]
fn unknown_key_is_named() {
    assert!(err(&format!("{BASE}durations = 1.0\n")).contains("durations"));
    assert!(err(&format!("{BASE}[mechanism]\ncone_angle = 0.5\n")).contains("cone_angle"));
    assert!(err(&format!("{BASE}[extra]\n")).contains("extra"));
}

#[test]
fn out_of_range_value_is_named() {
    assert!(err(&format!("{BASE}duration_s = -1.0\n")).contains("scene.duration_s"));
    assert!(
        err(&format!("{BASE}[mechanism]\nrestitution = 1.5\n")).contains("mechanism.restitution")
    );
    assert!(err(&format!("{BASE}release_at_s = 5.0\n")).contains("scene.release_at_s"));
    assert!(err(&format!(
        "{BASE}[[fault]]\nkind = \"drag\"\nat_s = 0.1\nseverity = 2.0\n"
    ))
    .contains("fault[0].severity"));
}

#[test]
fn bad_enumeration_is_named() {
    assert!(err("[scene]\nkind = \"closing\"\n").contains("scene.kind"));
    assert!(err(&format!("{BASE}reading = \"exact\"\n")).contains("scene.reading"));
    assert!(err(&format!(
        "{BASE}[[fault]]\nkind = \"rust\"\nat_s = 0.1\nseverity = 0.5\n"
    ))
    .contains("fault[0].kind"));
}

#[test]
fn syntax_and_type_errors_name_the_place() {
    let e = err(&format!("{BASE}duration_s = \"long\"\n"));
    assert!(e.contains("duration_s"), "{e}");
    let e = err("[scene\nkind = 1\n");
    assert!(e.contains("line 1") || e.contains("1 |"), "{e}");
    let e = err("[mechanism]\nmu_static = 0.3\n");
    assert!(e.contains("scene"), "missing [scene]: {e}");
}

#[test]
fn hold_has_no_release() {
    assert!(err("[scene]\nkind = \"hold\"\nrelease_at_s = 0.1\n").contains("scene.release_at_s"));
}

#[test]
fn nan_infinite_zero_and_negative_parameters_are_named() {
    let mech = |line: &str| err(&format!("[scene]\nkind = \"hold\"\n[mechanism]\n{line}\n"));
    assert!(mech("output_inertia_kg_m2 = 0.0").contains("mechanism.output_inertia_kg_m2"));
    assert!(mech("output_inertia_kg_m2 = -0.15").contains("mechanism.output_inertia_kg_m2"));
    assert!(mech("mu_static = nan").contains("mechanism.mu_static"));
    assert!(mech("contact_stiffness = inf").contains("mechanism.contact_stiffness"));
}
