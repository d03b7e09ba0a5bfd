//! A commissioned unit on the firmware under QEMU (`cargo xtask test`): its configuration block
//! runs bit-exact with the host, and its functional test says what the host's says.

use crate::cores::Core;
use crate::run;
use host_tests::dormant::accept;
use noback::monitor::functional_test::{Procedure, TestConfig};
use noback::monitor::{Config, DrivingPack};

/// The paper reading's reverse_load commissioned from itself (a spring-only pack, another
/// form than the defaults') with its build record, its configuration handed to the firmware as a block: the firmware
/// must say it runs on the block and stay bit-exact with the host on the same configuration,
/// whose estimates differ from the uncommissioned ones (on the STM32F405 the block sits in its
/// configuration sector, as commissioning writes it).
pub fn block_is_bit_exact(core: Core) -> Result<(), String> {
    let scene = scene_file(
        "paper_reverse_load",
        "[scene]\nkind = \"reverse_load\"\nreading = \"paper\"\n",
    )?;
    let trace = crate::replay::twin_trace(&scene)?;
    // With a build record (as inspection measures a Table 2 unit): the block carries its model.
    let table2 = Config::default().mechanism;
    let base = host_tests::as_built::AsBuilt::inspected(&table2, 1).config();
    let c = host_tests::commission::commission_with(&[(&trace, 20.3)], base)?;
    let (report, ok) = run::replay_report_with(&scene, core, None, None, false, Some(c.config))?;
    let uncommissioned =
        crate::replay::host_run(&crate::replay::nbr1(&trace)?, &[], None, Config::default())?;
    let other = format!("{:#010x}", uncommissioned.totals.digest);
    println!(
        "configuration {} ({:?}), bit_exact {}, firmware digest {} (uncommissioned {other})",
        report["configuration"],
        c.config.driving_pack,
        report["bit_exact"],
        report["firmware_digest"]
    );
    if ok && report["configuration"] == "block" && report["firmware_digest"] != other.as_str() {
        Ok(())
    } else {
        Err("the commissioned firmware did not run on its block bit-exactly".into())
    }
}

/// The crew's functional test under QEMU, its report equal to the host's (`run` checks it):
/// a healthy unit commissioned on its own acceptance test passes, the same unit with its spring
/// half gone fails (docs/functional-test.md).
pub fn functional_test_on_firmware() -> Result<(), String> {
    let opening = crate::replay::twin_trace("reverse_load")?;
    let test = crate::replay::twin_trace("functional_test")?;
    let mut c = host_tests::commission::commission(&[(&opening, 20.3)])?.config;
    let start = noback_twin::scene::DEFAULT_TEST.start_s;
    c.functional_test = accept(&test, c, (Procedure::Loaded, &c.functional_test), start)?
        .ok_or("the healthy unit did not pass its acceptance test")?;
    let spring = scene_file(
        "functional_test_spring_half",
        "[scene]\nkind = \"functional_test\"\n[[fault]]\nkind = \"spring_broken\"\nat_s = 0.0\nseverity = 0.5\n",
    )?;
    pass_then_fail(&["functional_test".to_string(), spring], c, "loaded")
}

/// The uncoupled push under QEMU: a paper-form unit, commissioned as a spring-only pack with
/// its acceptance push uncoupled, passes healthy and fails with its pack worn by half.
pub fn uncoupled_test_on_firmware() -> Result<(), String> {
    let paper = "[scene]\nreading = \"paper\"\n";
    let opening = scene_file(
        "paper_reverse_load",
        &format!("{paper}kind = \"reverse_load\"\n"),
    )?;
    let test = format!("{paper}kind = \"functional_test\"\nload_torque_nm = 0.3\n");
    let healthy = scene_file("paper_uncoupled_test", &test)?;
    let worn = scene_file(
        "paper_uncoupled_test_worn",
        &format!("{test}[[fault]]\nkind = \"pack_wear\"\nat_s = 0.0\nseverity = 0.5\n"),
    )?;
    let mut c =
        host_tests::commission::commission(&[(&crate::replay::twin_trace(&opening)?, 20.3)])?
            .config;
    if c.driving_pack != DrivingPack::SpringOnly {
        return Err("the paper-form unit was not commissioned as a spring-only pack".into());
    }
    let start = noback_twin::scene::DEFAULT_TEST.start_s;
    let uncoupled = TestConfig::UNCOUPLED;
    let trace = crate::replay::twin_trace(&healthy)?;
    c.uncoupled_test = Some(
        accept(&trace, c, (Procedure::Uncoupled, &uncoupled), start)?
            .ok_or("the healthy unit's uncoupled push did not pass its acceptance")?,
    );
    pass_then_fail(&[healthy, worn], c, "uncoupled")
}

/// A scene file in target/replay; returns its path.
fn scene_file(stem: &str, text: &str) -> Result<String, String> {
    let dir = crate::shell::workspace_root().join("target").join("replay");
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let path = dir.join(format!("{stem}.toml"));
    std::fs::write(&path, text).map_err(|e| e.to_string())?;
    Ok(path.to_string_lossy().into_owned())
}

/// Runs `scenes` on the M3 firmware with `config`; both must run the `expected` procedure, the
/// first pass, the second fail.
fn pass_then_fail(scenes: &[String], config: Config, expected: &str) -> Result<(), String> {
    let mut verdicts = Vec::new();
    for scene in scenes {
        let (report, ok) =
            run::replay_report_with(scene, Core::M3, None, None, false, Some(config))?;
        println!("{scene}: {}", report["functional_test"]);
        if !ok {
            return Err(format!(
                "{scene}: the firmware's test differs from the host's or the run failed"
            ));
        }
        let t = &report["functional_test"];
        verdicts.push(format!(
            "{} {}",
            t["procedure"].as_str().unwrap_or(""),
            t["result"].as_str().unwrap_or("")
        ));
    }
    if verdicts == [format!("{expected} pass"), format!("{expected} fail")] {
        Ok(())
    } else {
        Err(format!(
            "functional test verdicts {verdicts:?}, expected {expected} pass then fail"
        ))
    }
}
