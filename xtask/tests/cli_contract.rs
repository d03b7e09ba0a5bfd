//! The command-line contract of every command, table-driven on the built `xtask` binary:
//! `--help` exits 0; an unknown flag, a bad value (NaN, infinity, negative, not a number, an
//! unknown core or scene), an extra positional, a missing or bad scene file, a bad trace → exit
//! 2 with ONE line on stderr naming the input.

use std::path::{Path, PathBuf};
use std::process::Command;

fn xtask(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_xtask"))
        .args(args)
        .output()
        .expect("the xtask binary runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Exit 2, one line, naming `named`.
fn refused(args: &[&str], named: &str) {
    let (code, err) = xtask(args);
    assert_eq!(code, 2, "{args:?} exited {code}: {err}");
    assert_eq!(
        err.lines().count(),
        1,
        "{args:?} printed more than one line: {err}"
    );
    assert!(
        err.contains(named),
        "{args:?}: `{named}` not named in: {err}"
    );
    assert!(
        err.len() < 400,
        "{args:?}: message too long ({} bytes)",
        err.len()
    );
}

fn scratch() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("noback-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn file(name: &str, text: &str) -> String {
    let path = scratch().join(name);
    std::fs::write(&path, text).unwrap();
    path.to_string_lossy().into_owned()
}

/// Every command with its options (but no positional), as `cargo xtask CMD --help` lists them.
const COMMANDS: &[&str] = &[
    "run",
    "test",
    "qemu",
    "twin",
    "twin-bench",
    "paper",
    "sweep",
    "monitor",
    "commission",
    "monitor-mc",
    "fuzz",
    "golden",
    "opt-level",
    "reliability",
    "bench",
    "log",
    "power-fail",
    "profile",
    "bootstrap",
];

#[test]
fn help_exits_zero_everywhere() {
    assert_eq!(xtask(&["--help"]).0, 0);
    for cmd in COMMANDS {
        let (code, err) = xtask(&[cmd, "--help"]);
        assert_eq!(code, 0, "{cmd} --help exited {code}: {err}");
    }
}

#[test]
fn an_unknown_flag_is_refused_by_every_command() {
    refused(&["--bogus"], "--bogus");
    refused(&["no-such-command"], "no-such-command");
    refused(&[], "command");
    for cmd in COMMANDS {
        refused(&[cmd, "--bogus"], "--bogus");
    }
}

#[test]
fn bad_values_are_refused_naming_them() {
    // (command line, what the message must name)
    let cases: &[(&[&str], &str)] = &[
        (&["run", "--core", "m9"], "m9"),
        (&["test", "--core", "m9"], "m9"),
        (&["qemu", "x.elf", "--core", "m9"], "m9"),
        (&["run", "--overrun-at", "-1"], "-1"),
        (&["profile", "--core", "m9"], "m9"),
        (&["profile", "--scene", "no_such_scene"], "no_such_scene"),
        (&["run", "--overrun-at", "abc"], "abc"),
        (&["qemu", "x.elf", "--timeout", "NaN"], "NaN"),
        (&["qemu", "x.elf", "--timeout", "inf"], "inf"),
        (&["qemu", "x.elf", "--timeout", "-3"], "-3"),
        (&["qemu", "x.elf", "--icount", "11"], "11"),
        (&["twin", "hold", "--tolerance", "NaN"], "NaN"),
        (&["twin", "hold", "--reading", "exact"], "exact"),
        (&["monitor-mc", "--test-every", "-1"], "-1"),
        (&["twin-bench", "--tolerance", "inf"], "inf"),
        (&["paper", "--tolerance", "-1"], "-1"),
        (&["paper", "--tolerance", "abc"], "abc"),
        (&["sweep", "mu_static=0.1..0.2", "--steps", "-5"], "-5"),
        (
            &["sweep", "mu_static=0.1..0.2", "--scene", "closing"],
            "closing",
        ),
        (&["sweep", "mu_static=a..0.2"], "`a`"),
        (&["sweep", "cone=0.1..0.2"], "cone"),
        (&["fuzz", "--seconds", "-1"], "-1"),
        (&["fuzz", "no_target"], "no_target"),
        (&["run", "--scene", "closing"], "closing"),
        (&["twin", "closing"], "closing"),
        (&["monitor", "closing"], "closing"),
        (&["monitor-mc", "--runs", "-1"], "-1"),
        (&["monitor-mc", "--seed", "abc"], "abc"),
        (&["monitor-mc", "--pre-roll", "inf"], "inf"),
        (&["monitor-mc", "--shard", "3/2", "--out", "p.json"], "3/2"),
        (&["monitor-mc", "family", "--runs", "-1"], "-1"),
    ];
    for (args, named) in cases {
        refused(args, named);
    }
}

#[test]
fn an_extra_positional_is_refused() {
    let cases: &[(&[&str], &str)] = &[
        (&["monitor", "hold", "forward_load"], "forward_load"),
        (&["monitor-mc", "extra"], "extra"),
        (&["monitor-mc", "family", "extra"], "extra"),
        (&["twin", "hold", "drive"], "drive"),
        (&["run", "hold"], "hold"),
        (&["paper", "extra"], "extra"),
        (&["reliability", "extra"], "extra"),
        (&["golden", "extra"], "extra"),
        (&["opt-level", "extra"], "extra"),
        (&["bench", "extra"], "extra"),
        (&["bootstrap", "extra"], "extra"),
        (&["test", "extra"], "extra"),
        (&["fuzz", "scene_file", "trace_files"], "trace_files"),
        (&["sweep", "pressing-force", "extra"], "extra"),
    ];
    for (args, named) in cases {
        refused(args, named);
    }
}

#[test]
fn a_long_value_is_cut() {
    let long = "x".repeat(100_000);
    refused(&["run", "--core", &long], "xxx…");
    refused(&["twin", &long], "xxx…");
}

#[test]
fn bad_scene_files_are_refused_by_every_command_that_reads_one() {
    let missing = scratch()
        .join("missing.toml")
        .to_string_lossy()
        .into_owned();
    let nan = file(
        "nan.toml",
        "[scene]\nkind = \"hold\"\nload_torque_nm = nan\n",
    );
    let typed = file(
        "typed.toml",
        "[scene]\nkind = \"hold\"\n[mechanism]\nfriction_discs = 300\n",
    );
    let huge = file(
        "huge.toml",
        "[scene]\nkind = \"hold\"\nload_torque_nm = 1e308\n",
    );
    let long_kind = file(
        "kind.toml",
        &format!("[scene]\nkind = \"{}\"\n", "k".repeat(50_000)),
    );
    let syntax = file(
        "syntax.toml",
        "[scene]\nkind = \"hold\"\n[mechanism]\nmu_static = = 3\n",
    );
    let fault = file(
        "fault.toml",
        "[scene]\nkind = \"hold\"\n[[fault]]\nkind = \"drag\"\nat_s = \"x\"\nseverity = 0.5\n",
    );
    for (path, named) in [
        (missing.as_str(), "missing.toml"),
        (&nan, "scene.load_torque_nm"),
        (&typed, "mechanism.friction_discs"),
        (&huge, "1e308"),
        (&long_kind, "scene.kind"),
        (&syntax, "mechanism.mu_static"),
        (&fault, "fault[0].at_s"),
    ] {
        refused(&["run", "--scene", path], named);
        refused(&["monitor", path], named);
        refused(&["twin", path], named);
    }
}

#[test]
fn parameters_the_twin_cannot_integrate_are_refused_at_once() {
    let cases = [
        ("mu_static = 0.0", "mechanism.mu_static"),
        ("mu_static = 0.1\nmu_dynamic = 0.17", "mechanism.mu_static"),
        ("mu_dynamic = 2.0", "mechanism.mu_dynamic"),
    ];
    for (i, (mechanism, named)) in cases.iter().enumerate() {
        let path = file(
            &format!("mu{i}.toml"),
            &format!("[scene]\nkind = \"reverse_load\"\n[mechanism]\n{mechanism}\n"),
        );
        let started = std::time::Instant::now();
        refused(&["twin", &path], named);
        refused(&["monitor", &path], named);
        refused(&["run", "--scene", &path], named);
        assert!(
            started.elapsed().as_secs() < 10,
            "{mechanism}: not refused at once"
        );
    }
    let smooth = file(
        "smooth.toml",
        "[scene]\nkind = \"reverse_load\"\n[open]\naxial_smoothing_m_s = 1e-9\n",
    );
    refused(&["twin", &smooth], "open.axial_smoothing_m_s");
}

#[test]
fn bad_traces_are_refused_by_monitor() {
    let head = "# noback-trace v1\n";
    let rate = "# sample_rate_hz=10000\n";
    let cols = "t_s,current_code,motor_count,output_count,drive_on,pressing_force_n,braking_torque_nm,output_speed_rad_s,input_speed_rad_s,output_angle_rad,brake_state\n";
    let row = |t: &str| format!("{t},2048,0,0,0,0,0,0,0,0,0\n");
    let cases = [
        ("empty.csv", String::new(), "empty file"),
        ("header.csv", format!("{head}{rate}{cols}"), "no samples"),
        (
            "one.csv",
            format!("{head}{rate}{cols}{}", row("0.0")),
            "one sample",
        ),
        (
            "backwards.csv",
            format!(
                "{head}{rate}{cols}{}{}{}",
                row("0.0"),
                row("0.0002"),
                row("0.0001")
            ),
            "time does not increase",
        ),
        (
            "rate0.csv",
            format!(
                "{head}# sample_rate_hz=0\n{cols}{}{}",
                row("0.0"),
                row("0.0001")
            ),
            "sample_rate_hz must be a positive number",
        ),
        (
            "norate.csv",
            format!("{head}{cols}{}{}", row("0.0"), row("0.0001")),
            "sample_rate_hz",
        ),
    ];
    for (name, text, named) in cases {
        let path = file(name, &text);
        refused(&["monitor", &path], named);
        refused(&["monitor", &path], name);
    }
}

#[test]
fn commission_refuses_runs_that_cannot_identify_the_settings() {
    // No drive cut; a flag raised (a stuck output encoder); too short a drive.
    refused(&["commission", "drive"], "no drive cut");
    let stuck = file(
        "stuck.toml",
        "[scene]\nkind = \"reverse_load\"\n[[fault]]\nkind = \"encoder_stuck\"\nat_s = 0.15\nseverity = 1.0\n",
    );
    refused(&["commission", &stuck], "not a healthy run");
    let short = file(
        "short.toml",
        "[scene]\nkind = \"reverse_load\"\nrelease_at_s = 0.1\n",
    );
    refused(&["commission", &short], "at least 0.2 s");
    refused(&["commission", "reverse_load", "--load-nm", "nan"], "NaN");
    let trace = file(
        "acceptance.csv",
        "# noback-trace v1\n# sample_rate_hz=10000\nt_s,current_code,motor_count,output_count,drive_on,pressing_force_n,braking_torque_nm,output_speed_rad_s,input_speed_rad_s,output_angle_rad,brake_state\n0.0,2048,0,0,1,0,0,0,0,0,0\n0.0001,2048,0,0,1,0,0,0,0,0,0\n",
    );
    refused(&["commission", &trace], "--load-nm");
    refused(
        &[
            "commission",
            "reverse_load",
            "forward_load",
            "--load-nm",
            "20",
        ],
        "one per run",
    );
    let record = file("record.toml", "[as_built]\nspring_preload_n = 170.0\n");
    refused(
        &["commission", "reverse_load", "--as-built", &record],
        "as_built.socket_radius_m: missing",
    );
    refused(
        &["run", "--config", "/nonexistent.toml"],
        "nonexistent.toml",
    );
}

#[test]
fn reliability_with_a_bad_argument_leaves_its_page_alone() {
    let page = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/reliability.md");
    let before = std::fs::metadata(&page).and_then(|m| m.modified()).ok();
    refused(&["reliability", "--bogus"], "--bogus");
    let after = std::fs::metadata(&page).and_then(|m| m.modified()).ok();
    assert_eq!(
        before, after,
        "reliability --bogus touched docs/reliability.md"
    );
}

#[test]
fn the_table_lists_every_command() {
    let (code, _) = xtask(&["--help"]);
    assert_eq!(code, 0);
    let out = Command::new(env!("CARGO_BIN_EXE_xtask"))
        .arg("--help")
        .output()
        .unwrap();
    let help = String::from_utf8_lossy(&out.stdout);
    for line in help
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
    {
        let Some(name) = line.split_whitespace().next() else {
            break;
        };
        assert!(
            COMMANDS.contains(&name),
            "`{name}` is missing from this test's table"
        );
    }
}
