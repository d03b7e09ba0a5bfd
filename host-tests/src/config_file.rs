//! The monitor's configuration as a TOML file (docs/monitor-design.md, "Configuration file"):
//! a base settings set, then any threshold or model constant by its field name. Unknown keys,
//! wrong types and values `Config` rejects are errors naming the key.
//!
//! ```toml
//! [monitor]
//! base = "uncommissioned"        # or "physical_reading"
//! sliding_mu = 0.12
//! [monitor.thresholds]
//! opposed_braking_share = 1.0
//! ```

use noback::monitor::{Config, Monitor};
use toml::{Table, Value};

/// Sets each listed `f64` field of `$target` from `$table`, removing the key.
macro_rules! take_f64 {
    ($table:expr, $prefix:expr, $target:expr, [$($field:ident),* $(,)?]) => {
        $(
            if let Some(v) = $table.remove(stringify!($field)) {
                $target.$field = number(&v, &format!("{}{}", $prefix, stringify!($field)))?;
            }
        )*
    };
}

fn number(v: &Value, key: &str) -> Result<f64, String> {
    match v {
        Value::Float(x) => Ok(*x),
        Value::Integer(i) => Ok(*i as f64),
        _ => Err(format!("{key}: expected a number")),
    }
}

fn table(v: Value, key: &str) -> Result<Table, String> {
    match v {
        Value::Table(t) => Ok(t),
        _ => Err(format!("{key}: expected a table")),
    }
}

fn no_more(t: &Table, prefix: &str) -> Result<(), String> {
    match t.keys().next() {
        Some(k) => Err(format!("{prefix}{k}: unknown key")),
        None => Ok(()),
    }
}

/// Parses a configuration file's text; the result is validated by `Monitor::new`.
pub fn parse(text: &str) -> Result<Config, String> {
    let mut root: Table = text
        .parse()
        .map_err(|e: toml::de::Error| format!("TOML: {}", e.message()))?;
    let mut m = table(
        root.remove("monitor").ok_or("[monitor]: missing")?,
        "monitor",
    )?;
    no_more(&root, "")?;
    let mut c = match m.remove("base") {
        None => Config::default(),
        Some(Value::String(s)) if s == "uncommissioned" => Config::default(),
        Some(Value::String(s)) if s == "physical_reading" => Config::physical_reading(),
        Some(_) => {
            return Err("monitor.base: expected \"uncommissioned\" or \"physical_reading\"".into())
        }
    };
    if let Some(t) = m.remove("thresholds") {
        let mut t = table(t, "monitor.thresholds")?;
        take_f64!(
            t,
            "monitor.thresholds.",
            c.thresholds,
            [
                max_load_nm,
                stick_speed_rad_s,
                lock_dwell_s,
                creep_limit_rad,
                slip_output_travel_rad,
                slip_input_travel_rad,
                slip_reversal_rad,
                braking_grace_s,
                braking_angle_factor,
                braking_angle_allowance_rad,
                undecelerated_allowance_rad,
                opposed_braking_share,
                min_capacity_margin,
                min_load_nm,
                drag_allowance_nm,
                step_allowance_nm,
                step_reference_hz,
                sync_speed_band_rad_s,
                flag_persistence_s,
                settle_time_s,
                power_on_settle_s,
                engage_settle_s,
                load_filter_hz,
                input_speed_filter_hz,
                max_output_speed_rad_s,
                max_motor_speed_rad_s,
                max_lost_motion_rad,
                current_off_max_a,
                adc_rail_time_s,
                dead_current_nm,
                dead_current_speed_rad_s,
                health_rate_per_s,
                impact_time_s,
                impact_window_s,
            ]
        );
        no_more(&t, "monitor.thresholds.")?;
    }
    take_f64!(
        m,
        "monitor.",
        c,
        [
            capacity_mu,
            sliding_mu,
            backdrive_efficiency,
            braking_model_hz
        ]
    );
    match m.remove("commissioned") {
        None => {}
        Some(Value::Boolean(b)) => c.commissioned = b,
        Some(_) => return Err("monitor.commissioned: expected true or false".into()),
    }
    no_more(&m, "monitor.")?;
    Monitor::new(c).map_err(|e| format!("{e:?}"))?;
    Ok(c)
}

/// The file's text for `c`: every threshold and model constant, so a reader sees all of it.
pub fn write(c: &Config, comment: &str) -> String {
    let t = format!("{:?}", c.thresholds);
    let fields = t
        .trim_start_matches("Thresholds { ")
        .trim_end_matches(" }")
        .split(", ")
        .map(|kv| kv.replacen(": ", " = ", 1))
        .collect::<Vec<_>>()
        .join("\n");
    format!(
        "# {comment}\n[monitor]\nbase = \"uncommissioned\"\ncommissioned = {}\ncapacity_mu = {:?}\n\
         sliding_mu = {:?}\nbackdrive_efficiency = {:?}\nbraking_model_hz = {:?}\n\n\
         [monitor.thresholds]\n{fields}\n",
        c.commissioned, c.capacity_mu, c.sliding_mu, c.backdrive_efficiency, c.braking_model_hz
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_written_file_reads_back_to_the_same_configuration() {
        for c in [Config::default(), Config::physical_reading()] {
            assert_eq!(parse(&write(&c, "test")), Ok(c));
        }
    }

    #[test]
    fn the_base_and_single_keys_set_what_they_name() {
        let c = parse("[monitor]\nbase = \"physical_reading\"\n").unwrap();
        assert_eq!(c, Config::physical_reading());
        let c = parse("[monitor]\nsliding_mu = 0.2\n[monitor.thresholds]\ndead_current_nm = 0.4\n")
            .unwrap();
        assert_eq!((c.sliding_mu, c.thresholds.dead_current_nm), (0.2, 0.4));
    }

    #[test]
    fn bad_files_name_the_key() {
        for (text, key) in [
            ("[monitor]\nslidin_mu = 0.2\n", "monitor.slidin_mu"),
            (
                "[monitor.thresholds]\nbogus = 1\n",
                "monitor.thresholds.bogus",
            ),
            (
                "[monitor.thresholds]\ncreep_limit_rad = \"x\"\n",
                "monitor.thresholds.creep_limit_rad",
            ),
            ("[monitor]\nbase = \"paper\"\n", "monitor.base"),
            (
                "[monitor.thresholds]\nopposed_braking_share = 2.0\n",
                "opposed_braking_share",
            ),
            ("[other]\n", "[monitor]"),
        ] {
            let e = parse(text).unwrap_err();
            assert!(e.contains(key), "{text:?}: {e}");
        }
    }
}
