//! The monitor's configuration as a TOML file (docs/commissioning.md):
//! a base settings set, then any threshold (by its `Thresholds` field name, through serde) or
//! model constant. Unknown keys, wrong types and values `Config` rejects are errors naming
//! the key.
//!
//! ```toml
//! [monitor]
//! base = "uncommissioned"        # or "physical_reading"
//! sliding_mu = 0.12
//! driving_pack = "spring_only"   # or "relieved" (the default)
//! current_offset_a = 0.05        # the current reading at zero current
//! driving_drag_nm = 1.4          # the pack's drag while driving (absent: the model's)
//! motor_torque_constant_nm_a = 0.066
//! [monitor.thresholds]
//! opposed_braking_share = 1.0
//! [monitor.mechanism]            # the unit's build record (host_tests::as_built), over Table 2
//! spring_preload_m = 2.41e-3
//! socket_chamfer_rad = 0.80
//! [monitor.functional_test]      # the commanded test's procedure (TestConfig's fields)
//! load_nm = 20.3
//! expected_breakaway_nm = 11.0   # the unit's acceptance test (absent: the design's)
//! expected_opening_nm = 24.8     # and its opening torque (needs the breakaway)
//! min_margin = 0.95
//! [monitor.uncoupled_test]       # a spring-only pack's push with the output uncoupled (its
//! expected_breakaway_nm = 8.2    # fields as above but no opening; drive and timing the loaded's)
//! [monitor.aiding_braking]       # a spring-only pack's braking (AidingBraking), all three
//! inertia_kg_m2 = 0.15
//! drag_nm = 8.4
//! load_gain = 1.5
//! [monitor.overrun_line]         # a relieved pack's overrunning equilibrium (OverrunLine), both
//! gain = 6.9
//! offset_nm = 11.6
//! [monitor.lock_times]           # a relieved pack's cut-to-lock times (LockTimes), both
//! along_s = 0.0124
//! against_s = 0.0164
//! ```

use crate::as_built::fields;
use noback::monitor::functional_test::TestConfig;
use noback::monitor::{
    AidingBraking, Config, DrivingPack, LockTimes, Monitor, OverrunLine, Thresholds,
};
use toml::{Table, Value};

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

/// `base` with the thresholds `given` names set: only `Thresholds`' own fields, as numbers.
fn thresholds(base: Thresholds, given: Table) -> Result<Thresholds, String> {
    let mut all = table(
        Value::try_from(base).map_err(|e| e.to_string())?,
        "monitor.thresholds",
    )?;
    for (key, v) in given {
        let path = format!("monitor.thresholds.{key}");
        if !all.contains_key(&key) {
            return Err(format!("{path}: unknown key"));
        }
        all.insert(key, Value::Float(number(&v, &path)?));
    }
    Value::Table(all)
        .try_into()
        .map_err(|e: toml::de::Error| e.to_string())
}

/// The functional test's keys and fields, in `TestConfig`'s order.
fn test_fields(t: &mut TestConfig) -> [(&'static str, &mut f64); 10] {
    [
        ("load_nm", &mut t.load_nm),
        ("torque_rate_nm_s", &mut t.torque_rate_nm_s),
        ("max_torque_nm", &mut t.max_torque_nm),
        ("open_s", &mut t.open_s),
        ("settle_s", &mut t.settle_s),
        ("breakaway_rad", &mut t.breakaway_rad),
        ("min_margin", &mut t.min_margin),
        ("max_margin", &mut t.max_margin),
        ("load_tolerance", &mut t.load_tolerance),
        ("torque_filter_hz", &mut t.torque_filter_hz),
    ]
}

/// The functional test's optional keys (the unit's acceptance readings) and fields.
fn acceptance_fields(t: &mut TestConfig) -> [(&'static str, &mut Option<f64>); 2] {
    [
        ("expected_breakaway_nm", &mut t.expected_breakaway_nm),
        ("expected_opening_nm", &mut t.expected_opening_nm),
    ]
}

/// A functional test's table (`path`: `monitor.functional_test` or `monitor.uncoupled_test`)
/// over its procedure's defaults `base`.
fn test_table(mut given: Table, base: TestConfig, path: &str) -> Result<TestConfig, String> {
    let mut t = base;
    for (key, field) in test_fields(&mut t) {
        if let Some(v) = given.remove(key) {
            *field = number(&v, &format!("{path}.{key}"))?;
        }
    }
    for (key, field) in acceptance_fields(&mut t) {
        if let Some(v) = given.remove(key) {
            *field = Some(number(&v, &format!("{path}.{key}"))?);
        }
    }
    no_more(&given, &format!("{path}."))?;
    Ok(t)
}

/// A functional test's lines: the fields that differ from `base`, then the acceptance readings.
fn test_lines(mut base: TestConfig, mut now: TestConfig) -> String {
    let mut test = String::new();
    for ((key, b), (_, v)) in test_fields(&mut base)
        .into_iter()
        .zip(test_fields(&mut now))
    {
        if *b != *v {
            test.push_str(&format!("{key} = {v:?}\n"));
        }
    }
    for (key, v) in acceptance_fields(&mut now) {
        if let Some(v) = v {
            test.push_str(&format!("{key} = {v:?}\n"));
        }
    }
    test
}

/// A table whose every one of `keys` is given (and nothing else), in `keys`' order.
fn all_of<const N: usize>(
    mut given: Table,
    path: &str,
    keys: [&str; N],
) -> Result<[f64; N], String> {
    let mut out = [0.0; N];
    for (v, key) in out.iter_mut().zip(keys) {
        let at = format!("{path}.{key}");
        *v = number(&given.remove(key).ok_or(format!("{at}: missing"))?, &at)?;
    }
    no_more(&given, &format!("{path}."))?;
    Ok(out)
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
        c.thresholds = thresholds(c.thresholds, table(t, "monitor.thresholds")?)?;
    }
    if let Some(t) = m.remove("mechanism") {
        let mut given = table(t, "monitor.mechanism")?;
        for (key, field) in fields(&mut c.mechanism) {
            if let Some(v) = given.remove(key) {
                *field = number(&v, &format!("monitor.mechanism.{key}"))?;
            }
        }
        no_more(&given, "monitor.mechanism.")?;
    }
    if let Some(t) = m.remove("functional_test") {
        let path = "monitor.functional_test";
        c.functional_test = test_table(table(t, path)?, TestConfig::DEFAULT, path)?;
    }
    if let Some(t) = m.remove("uncoupled_test") {
        let path = "monitor.uncoupled_test";
        let base = c.functional_test.uncoupled_beside();
        c.uncoupled_test = Some(test_table(table(t, path)?, base, path)?);
    }
    if let Some(t) = m.remove("aiding_braking") {
        let path = "monitor.aiding_braking";
        let [inertia_kg_m2, drag_nm, load_gain] = all_of(
            table(t, path)?,
            path,
            ["inertia_kg_m2", "drag_nm", "load_gain"],
        )?;
        c.aiding_braking = Some(AidingBraking {
            inertia_kg_m2,
            drag_nm,
            load_gain,
        });
    }
    if let Some(t) = m.remove("overrun_line") {
        let path = "monitor.overrun_line";
        let [gain, offset_nm] = all_of(table(t, path)?, path, ["gain", "offset_nm"])?;
        c.overrun_line = Some(OverrunLine { gain, offset_nm });
    }
    if let Some(t) = m.remove("lock_times") {
        let path = "monitor.lock_times";
        let [along_s, against_s] = all_of(table(t, path)?, path, ["along_s", "against_s"])?;
        c.lock_times = Some(LockTimes { along_s, against_s });
    }
    for (key, field) in [
        ("capacity_mu", &mut c.capacity_mu),
        ("sliding_mu", &mut c.sliding_mu),
        ("backdrive_efficiency", &mut c.backdrive_efficiency),
        ("braking_model_hz", &mut c.braking_model_hz),
        ("current_offset_a", &mut c.current_offset_a),
        (
            "motor_torque_constant_nm_a",
            &mut c.sensors.motor_torque_constant_nm_a,
        ),
    ] {
        if let Some(v) = m.remove(key) {
            *field = number(&v, &format!("monitor.{key}"))?;
        }
    }
    if let Some(v) = m.remove("driving_drag_nm") {
        c.driving_drag_nm = Some(number(&v, "monitor.driving_drag_nm")?);
    }
    match m.remove("driving_pack") {
        None => {}
        Some(Value::String(s)) if s == "relieved" => c.driving_pack = DrivingPack::Relieved,
        Some(Value::String(s)) if s == "spring_only" => c.driving_pack = DrivingPack::SpringOnly,
        Some(_) => {
            return Err("monitor.driving_pack: expected \"relieved\" or \"spring_only\"".into())
        }
    }
    match m.remove("commissioned") {
        None => {}
        Some(Value::Boolean(b)) => c.commissioned = b,
        Some(_) => return Err("monitor.commissioned: expected true or false".into()),
    }
    no_more(&m, "monitor.")?;
    Monitor::new(c).map_err(|e| format!("{e:?}"))?;
    Ok(c)
}

/// The file of `c` over the uncommissioned base: every model constant the file carries and the
/// thresholds that differ from the base. Refuses a `Config` the file cannot carry whole.
pub fn write(c: &Config, comment: &str) -> Result<String, String> {
    let mut out = String::new();
    for line in comment.lines() {
        out.push_str(&format!("# {line}\n"));
    }
    out.push_str("[monitor]\nbase = \"uncommissioned\"\n");
    for (key, v) in [
        ("capacity_mu", c.capacity_mu),
        ("sliding_mu", c.sliding_mu),
        ("backdrive_efficiency", c.backdrive_efficiency),
        ("braking_model_hz", c.braking_model_hz),
        ("current_offset_a", c.current_offset_a),
        (
            "motor_torque_constant_nm_a",
            c.sensors.motor_torque_constant_nm_a,
        ),
    ] {
        out.push_str(&format!("{key} = {v:?}\n"));
    }
    if let Some(d) = c.driving_drag_nm {
        out.push_str(&format!("driving_drag_nm = {d:?}\n"));
    }
    let pack = match c.driving_pack {
        DrivingPack::Relieved => "relieved",
        DrivingPack::SpringOnly => "spring_only",
    };
    out.push_str(&format!(
        "driving_pack = \"{pack}\"\ncommissioned = {}\n[monitor.thresholds]\n",
        c.commissioned
    ));
    let base = Value::try_from(Thresholds::DEFAULT).map_err(|e| e.to_string())?;
    let now = Value::try_from(c.thresholds).map_err(|e| e.to_string())?;
    if let (Value::Table(base), Value::Table(now)) = (base, now) {
        for (key, v) in now {
            if base.get(&key) != Some(&v) {
                out.push_str(&format!("{key} = {:?}\n", number(&v, &key)?));
            }
        }
    }
    // The record's fields that differ from Table 2's.
    let (mut design, mut built) = (Config::default().mechanism, c.mechanism);
    let mechanism: String = fields(&mut design)
        .into_iter()
        .zip(fields(&mut built))
        .filter(|((_, d), (_, v))| d != v)
        .map(|((key, _), (_, v))| format!("{key} = {:?}\n", *v))
        .collect();
    if !mechanism.is_empty() {
        out.push_str("[monitor.mechanism]\n");
        out.push_str(&mechanism);
    }
    let test = test_lines(TestConfig::DEFAULT, c.functional_test);
    if !test.is_empty() {
        out.push_str("[monitor.functional_test]\n");
        out.push_str(&test);
    }
    if let Some(t) = c.uncoupled_test {
        out.push_str("[monitor.uncoupled_test]\n");
        out.push_str(&test_lines(c.functional_test.uncoupled_beside(), t));
    }
    if let Some(a) = c.aiding_braking {
        out.push_str(&format!(
            "[monitor.aiding_braking]\ninertia_kg_m2 = {:?}\ndrag_nm = {:?}\nload_gain = {:?}\n",
            a.inertia_kg_m2, a.drag_nm, a.load_gain
        ));
    }
    if let Some(l) = c.overrun_line {
        out.push_str(&format!(
            "[monitor.overrun_line]\ngain = {:?}\noffset_nm = {:?}\n",
            l.gain, l.offset_nm
        ));
    }
    if let Some(l) = c.lock_times {
        out.push_str(&format!(
            "[monitor.lock_times]\nalong_s = {:?}\nagainst_s = {:?}\n",
            l.along_s, l.against_s
        ));
    }
    match parse(&out) {
        Ok(back) if back == *c => Ok(out),
        Ok(_) => Err("the configuration sets a field the file does not carry".into()),
        Err(e) => Err(e),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_base_and_single_keys_set_what_they_name() {
        let c = parse("[monitor]\nbase = \"physical_reading\"\n").unwrap();
        assert_eq!(c, Config::physical_reading());
        let c = parse("[monitor]\nsliding_mu = 0.2\n[monitor.thresholds]\ndead_current_nm = 0.4\n")
            .unwrap();
        assert_eq!((c.sliding_mu, c.thresholds.dead_current_nm), (0.2, 0.4));
        let c = parse(
            "[monitor]\ncommissioned = true\n[monitor.thresholds]\nopposed_braking_share = 1\n",
        )
        .unwrap();
        assert!(c.commissioned && c.thresholds.opposed_braking_share == 1.0);
    }

    #[test]
    fn a_written_file_reads_back_the_same_configuration() {
        let mut c = Config::physical_reading();
        c.sliding_mu = 0.2345678901;
        c.driving_pack = DrivingPack::SpringOnly;
        c.thresholds.creep_limit_rad = 0.125;
        c.mechanism = crate::as_built::AsBuilt::inspected(&c.mechanism, 7).applied_to(&c.mechanism);
        c.functional_test = TestConfig {
            load_nm: 18.5,
            ..TestConfig::DEFAULT
        }
        .commissioned(10.25, Some(24.5));
        c.uncoupled_test = Some(TestConfig::UNCOUPLED.commissioned(8.125, None));
        c.aiding_braking = Some(AidingBraking {
            inertia_kg_m2: 0.1512345,
            drag_nm: 8.25,
            load_gain: 1.625,
        });
        c.overrun_line = Some(OverrunLine {
            gain: 6.125,
            offset_nm: 11.375,
        });
        c.lock_times = Some(LockTimes {
            along_s: 0.0125,
            against_s: 0.0165,
        });
        let text = write(&c, "test").unwrap();
        assert_eq!(parse(&text), Ok(c), "{text}");
        let mut other = c;
        other.tick_hz = 5_000.0;
        assert!(write(&other, "").is_err());
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
            (
                "[monitor.mechanism]\nmu_static = 0.3\n",
                "monitor.mechanism.mu_static",
            ),
            (
                "[monitor.mechanism]\npack_inner_radius_m = 0.04\n",
                "mechanism.pack_outer_radius_m",
            ),
            (
                "[monitor.functional_test]\nload = 1\n",
                "monitor.functional_test.load",
            ),
            (
                "[monitor.functional_test]\nmin_margin = 2\n",
                "functional_test.min_margin",
            ),
            (
                "[monitor]\ndriving_pack = \"spring_only\"\n[monitor.uncoupled_test]\nmin_margin = 2\n",
                "uncoupled_test.min_margin",
            ),
            // The uncoupled push is a spring-only pack's.
            ("[monitor.uncoupled_test]\n", "uncoupled_test"),
        ] {
            let e = parse(text).unwrap_err();
            assert!(e.contains(key), "{text:?}: {e}");
        }
    }
}
