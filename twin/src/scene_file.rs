//! The TOML scene-file schema (docs/model.md, "Scene files"): raw `serde` structs with
//! `deny_unknown_fields`, and the checks that turn them into a [`Scene`], each error naming the
//! key (`scene.duration_s`, `mechanism.restitution`, `fault[0].severity`).

use crate::args::{num, short};
use crate::fault::{Fault, FaultKind};
use crate::reading::Reading;
use crate::scene::{Scene, SceneError, SceneKind};
use serde::Deserialize;

/// Parse the text of a scene file.
pub fn parse(name: &str, text: &str) -> Result<Scene, SceneError> {
    let raw: RawFile = toml::from_str(text).map_err(|e| toml_error(text, &e))?;
    raw.into_scene(name)
}

/// A TOML syntax or type error named by its `table.key` (found from the error's place in the
/// text), or by its line when no key is there; the message is cut to a readable length.
fn toml_error(text: &str, e: &toml::de::Error) -> SceneError {
    let message = short(e.message().lines().next().unwrap_or("").trim());
    let Some(at) = e.span().map(|s| s.start.min(text.len())) else {
        return bad("", message);
    };
    let line_no = text.get(..at).map_or(0, |t| t.matches('\n').count());
    let mut table = String::new();
    let mut faults = 0;
    for line in text.lines().take(line_no) {
        let t = line.trim();
        if t.starts_with("[[") {
            table = format!(
                "{}[{faults}]",
                t.trim_matches(|c| c == '[' || c == ']').trim()
            );
            faults += 1;
        } else if t.starts_with('[') {
            table = t.trim_matches(|c| c == '[' || c == ']').trim().to_string();
        }
    }
    let this = text.lines().nth(line_no).unwrap_or("").trim();
    let key = match this.split_once('=') {
        Some((k, _)) if !this.starts_with('[') => k.trim().trim_matches('"').to_string(),
        _ => String::new(),
    };
    let place = match (table.is_empty(), key.is_empty()) {
        (_, true) => table,
        (true, false) => key,
        (false, false) => format!("{table}.{key}"),
    };
    if place.is_empty() {
        bad("", format!("line {}: {message}", line_no + 1))
    } else {
        bad(&short(&place), format!("{message} (line {})", line_no + 1))
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFile {
    scene: RawScene,
    #[serde(default)]
    mechanism: RawMechanism,
    #[serde(default)]
    sensors: RawSensors,
    #[serde(default)]
    open: RawOpen,
    #[serde(default)]
    fault: Vec<RawFault>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScene {
    kind: String,
    reading: Option<String>,
    load_torque_nm: Option<f64>,
    initial_speed_rad_s: Option<f64>,
    release_at_s: Option<f64>,
    duration_s: Option<f64>,
    tolerance: Option<f64>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawMechanism {
    output_shaft_mass_kg: Option<f64>,
    input_shaft_mass_kg: Option<f64>,
    ball_mass_kg: Option<f64>,
    connecting_shaft_mass_kg: Option<f64>,
    output_inertia_kg_m2: Option<f64>,
    input_inertia_kg_m2: Option<f64>,
    connecting_inertia_kg_m2: Option<f64>,
    ball_inertia_kg_m2: Option<f64>,
    spring_stiffness_n_m: Option<f64>,
    contact_stiffness: Option<f64>,
    spring_preload_m: Option<f64>,
    socket_radius_m: Option<f64>,
    output_friction_radius_m: Option<f64>,
    connecting_friction_radius_m: Option<f64>,
    input_friction_radius_m: Option<f64>,
    pack_inner_radius_m: Option<f64>,
    pack_outer_radius_m: Option<f64>,
    socket_clearance_m: Option<f64>,
    pack_clearance_m: Option<f64>,
    socket_chamfer_rad: Option<f64>,
    friction_discs: Option<u8>,
    mu_static: Option<f64>,
    mu_dynamic: Option<f64>,
    restitution: Option<f64>,
    groove_angle_rad: Option<f64>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawSensors {
    motor_torque_constant_nm_a: Option<f64>,
    reducer_ratio: Option<f64>,
    reducer_efficiency: Option<f64>,
    current_adc_bits: Option<u8>,
    current_full_scale_a: Option<f64>,
    motor_encoder_counts_per_rev: Option<u32>,
    output_encoder_bits: Option<u8>,
    motor_counter_bits: Option<u8>,
    noise_seed: Option<u64>,
    current_noise_a: Option<f64>,
    current_gain: Option<f64>,
    current_offset_a: Option<f64>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawOpen {
    approach_speed_floor_m_s: Option<f64>,
    drive_gain_nm_s_rad: Option<f64>,
    drive_current_limit_a: Option<f64>,
    reflected_motor_inertia_kg_m2: Option<f64>,
    bearing_smoothing_rad_s: Option<f64>,
    axial_smoothing_m_s: Option<f64>,
    shaft_gap_m: Option<f64>,
    stop_threshold_rad_s: Option<f64>,
    paper_far_face_stop: Option<bool>,
    paper_backlash_rad: Option<f64>,
    paper_sliding_mu_static: Option<bool>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFault {
    kind: String,
    at_s: f64,
    severity: f64,
}

fn bad(key: &str, message: String) -> SceneError {
    SceneError {
        key: key.to_string(),
        message,
    }
}

/// Take `v` if set, checking `lo <= v <= hi` (and finiteness).
fn ranged(target: &mut f64, v: Option<f64>, key: &str, lo: f64, hi: f64) -> Result<(), SceneError> {
    if let Some(v) = v {
        if !(v.is_finite() && v >= lo && v <= hi) {
            return Err(bad(
                key,
                format!("{} is out of range [{}, {}]", num(v), num(lo), num(hi)),
            ));
        }
        *target = v;
    }
    Ok(())
}

fn ranged_int<T: Copy + PartialOrd + std::fmt::Display>(
    target: &mut T,
    v: Option<T>,
    key: &str,
    lo: T,
    hi: T,
) -> Result<(), SceneError> {
    if let Some(v) = v {
        if v < lo || v > hi {
            return Err(bad(key, format!("{v} is out of range [{lo}, {hi}]")));
        }
        *target = v;
    }
    Ok(())
}

/// Mechanism overrides by name: `(key, field, lo, hi)`; a macro keeps the list in one place.
macro_rules! mech_fields {
    ($raw:expr, $m:expr, $( $f:ident : $lo:expr, $hi:expr );* $(;)?) => {
        $( ranged(&mut $m.$f, $raw.$f, concat!("mechanism.", stringify!($f)), $lo, $hi)?; )*
    };
}

impl RawFile {
    fn into_scene(self, name: &str) -> Result<Scene, SceneError> {
        let kind = SceneKind::parse(&self.scene.kind).ok_or_else(|| {
            bad(
                "scene.kind",
                format!(
                    "`{}` is not one of reverse_load, forward_load, continuous_closing, hold, drive, functional_test",
                    short(&self.scene.kind)
                ),
            )
        })?;
        let reading = match &self.scene.reading {
            None => Reading::Physical,
            Some(r) => Reading::parse(r).ok_or_else(|| {
                bad(
                    "scene.reading",
                    format!("`{}` is not paper or physical", short(r)),
                )
            })?,
        };
        let mut s = Scene::builtin(kind, reading);
        s.name = name.to_string();
        ranged(
            &mut s.load_torque_nm,
            self.scene.load_torque_nm,
            "scene.load_torque_nm",
            0.0,
            500.0,
        )?;
        ranged(
            &mut s.initial_speed_rad_s,
            self.scene.initial_speed_rad_s,
            "scene.initial_speed_rad_s",
            0.0,
            200.0,
        )?;
        ranged(
            &mut s.duration_s,
            self.scene.duration_s,
            "scene.duration_s",
            1e-3,
            60.0,
        )?;
        ranged(
            &mut s.tolerance,
            self.scene.tolerance,
            "scene.tolerance",
            1e-10,
            1e-2,
        )?;
        if let Some(r) = self.scene.release_at_s {
            if !(r.is_finite() && r >= 0.0 && r <= s.duration_s) {
                return Err(bad(
                    "scene.release_at_s",
                    format!(
                        "{} is out of range [0, duration_s = {}]",
                        num(r),
                        num(s.duration_s)
                    ),
                ));
            }
            if kind == SceneKind::Hold {
                return Err(bad(
                    "scene.release_at_s",
                    "a hold scene has no drive to cut".into(),
                ));
            }
            s.release_at_s = Some(r);
        } else if s.release_at_s.is_some_and(|r| r > s.duration_s) {
            s.release_at_s = None;
        }
        let raw = self.mechanism;
        let m = &mut s.mechanism;
        mech_fields!(raw, m,
            output_shaft_mass_kg: 1e-6, 1e3;
            input_shaft_mass_kg: 1e-6, 1e3;
            ball_mass_kg: 1e-7, 10.0;
            connecting_shaft_mass_kg: 1e-6, 1e3;
            output_inertia_kg_m2: 1e-9, 1e3;
            input_inertia_kg_m2: 1e-9, 1e3;
            connecting_inertia_kg_m2: 1e-9, 1e3;
            ball_inertia_kg_m2: 1e-12, 1.0;
            spring_stiffness_n_m: 0.0, 1e9;
            contact_stiffness: 1e3, 1e13;
            spring_preload_m: 0.0, 0.1;
            socket_radius_m: 1e-4, 1.0;
            output_friction_radius_m: 0.0, 1.0;
            connecting_friction_radius_m: 0.0, 1.0;
            input_friction_radius_m: 0.0, 1.0;
            pack_inner_radius_m: 0.0, 1.0;
            pack_outer_radius_m: 1e-4, 1.0;
            socket_clearance_m: 0.0, 0.01;
            pack_clearance_m: 0.0, 0.05;
            socket_chamfer_rad: 0.05, 1.52;
            mu_static: 0.0, 2.0;
            mu_dynamic: 0.0, 2.0;
            restitution: 0.01, 1.0;
            groove_angle_rad: 0.0, 6.0;
        );
        ranged_int(
            &mut m.friction_discs,
            raw.friction_discs,
            "mechanism.friction_discs",
            1,
            20,
        )?;
        // Static friction below kinetic has no stick–slip switch the integrator can locate: the
        // run ends in a step-size underflow (docs/decisions.md, Issue 20). Named here, at once.
        if m.mu_static < m.mu_dynamic {
            return Err(bad(
                if raw.mu_static.is_some() {
                    "mechanism.mu_static"
                } else {
                    "mechanism.mu_dynamic"
                },
                format!(
                    "mu_static = {} is below mu_dynamic = {}: static friction must be ≥ kinetic",
                    num(m.mu_static),
                    num(m.mu_dynamic)
                ),
            ));
        }
        if m.pack_inner_radius_m >= m.pack_outer_radius_m {
            return Err(bad(
                "mechanism.pack_inner_radius_m",
                "must be smaller than pack_outer_radius_m".into(),
            ));
        }
        let rs = self.sensors;
        let se = &mut s.sensors;
        ranged(
            &mut se.motor_torque_constant_nm_a,
            rs.motor_torque_constant_nm_a,
            "sensors.motor_torque_constant_nm_a",
            1e-4,
            10.0,
        )?;
        ranged(
            &mut se.reducer_ratio,
            rs.reducer_ratio,
            "sensors.reducer_ratio",
            1.0,
            1e4,
        )?;
        ranged(
            &mut se.reducer_efficiency,
            rs.reducer_efficiency,
            "sensors.reducer_efficiency",
            0.01,
            1.0,
        )?;
        ranged(
            &mut se.current_full_scale_a,
            rs.current_full_scale_a,
            "sensors.current_full_scale_a",
            0.01,
            1e4,
        )?;
        ranged_int(
            &mut se.current_adc_bits,
            rs.current_adc_bits,
            "sensors.current_adc_bits",
            4,
            16,
        )?;
        ranged_int(
            &mut se.motor_encoder_counts_per_rev,
            rs.motor_encoder_counts_per_rev,
            "sensors.motor_encoder_counts_per_rev",
            4,
            1 << 24,
        )?;
        ranged_int(
            &mut se.output_encoder_bits,
            rs.output_encoder_bits,
            "sensors.output_encoder_bits",
            4,
            24,
        )?;
        ranged_int(
            &mut se.motor_counter_bits,
            rs.motor_counter_bits,
            "sensors.motor_counter_bits",
            8,
            32,
        )?;
        if let Some(seed) = rs.noise_seed {
            s.noise.seed = seed;
        }
        ranged(
            &mut s.noise.current_noise_a,
            rs.current_noise_a,
            "sensors.current_noise_a",
            0.0,
            100.0,
        )?;
        ranged(
            &mut s.noise.current_gain,
            rs.current_gain,
            "sensors.current_gain",
            0.5,
            1.5,
        )?;
        ranged(
            &mut s.noise.current_offset_a,
            rs.current_offset_a,
            "sensors.current_offset_a",
            -5.0,
            5.0,
        )?;
        let ro = self.open;
        let o = &mut s.open;
        ranged(
            &mut o.approach_speed_floor_m_s,
            ro.approach_speed_floor_m_s,
            "open.approach_speed_floor_m_s",
            1e-6,
            100.0,
        )?;
        ranged(
            &mut o.drive_gain_nm_s_rad,
            ro.drive_gain_nm_s_rad,
            "open.drive_gain_nm_s_rad",
            1e-3,
            1e5,
        )?;
        ranged(
            &mut o.drive_current_limit_a,
            ro.drive_current_limit_a,
            "open.drive_current_limit_a",
            1e-3,
            1e3,
        )?;
        ranged(
            &mut o.reflected_motor_inertia_kg_m2,
            ro.reflected_motor_inertia_kg_m2,
            "open.reflected_motor_inertia_kg_m2",
            0.0,
            10.0,
        )?;
        ranged(
            &mut o.bearing_smoothing_rad_s,
            ro.bearing_smoothing_rad_s,
            "open.bearing_smoothing_rad_s",
            1e-6,
            10.0,
        )?;
        ranged(
            &mut o.axial_smoothing_m_s,
            ro.axial_smoothing_m_s,
            "open.axial_smoothing_m_s",
            1e-6,
            1.0,
        )?;
        ranged(
            &mut o.shaft_gap_m,
            ro.shaft_gap_m,
            "open.shaft_gap_m",
            0.0,
            0.01,
        )?;
        ranged(
            &mut o.stop_threshold_rad_s,
            ro.stop_threshold_rad_s,
            "open.stop_threshold_rad_s",
            1e-6,
            10.0,
        )?;
        if let Some(b) = ro.paper_far_face_stop {
            o.paper_far_face_stop = b;
        }
        ranged(
            &mut o.paper_backlash_rad,
            ro.paper_backlash_rad,
            "open.paper_backlash_rad",
            0.0,
            1.0,
        )?;
        if let Some(b) = ro.paper_sliding_mu_static {
            o.paper_sliding_mu_static = b;
        }
        for (i, f) in self.fault.iter().enumerate() {
            let kind = FaultKind::parse(&f.kind).ok_or_else(|| {
                bad(
                    &format!("fault[{i}].kind"),
                    format!(
                        "`{}` is not one of friction_loss, spring_broken, pack_wear, ramp_jam, drag, encoder_stuck, encoder_jump, current_open",
                        short(&f.kind)
                    ),
                )
            })?;
            let mut at_s = 0.0;
            ranged(
                &mut at_s,
                Some(f.at_s),
                &format!("fault[{i}].at_s"),
                0.0,
                s.duration_s,
            )?;
            let mut severity = 0.0;
            ranged(
                &mut severity,
                Some(f.severity),
                &format!("fault[{i}].severity"),
                0.0,
                1.0,
            )?;
            s.faults.push(Fault {
                kind,
                at_s,
                severity,
            });
        }
        Ok(s)
    }
}
