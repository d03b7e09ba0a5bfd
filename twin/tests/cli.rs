//! The command-line entry points: outputs, the trace round trip and exit codes.

use noback_twin::cli;
use noback_twin::trace::Trace;

fn args(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

#[test]
fn twin_writes_history_trace_and_plot() {
    let dir = std::env::temp_dir().join(format!("noback-twin-cli-{}", std::process::id()));
    let out = dir.to_string_lossy().to_string();
    assert_eq!(
        cli::twin_main(&args(&[
            "hold",
            "--reading",
            "paper",
            "--out",
            &out,
            "--json"
        ])),
        0
    );
    let trace = Trace::read(&dir.join("hold-paper.trace.csv")).unwrap();
    assert_eq!(trace.sample_rate_hz, 10_000.0);
    // 0.5 s at 10 kHz, both ends included.
    assert_eq!(trace.rows.len(), 5001);
    let last = trace.rows.last().unwrap();
    assert_eq!(last.brake_state, 2);
    assert!((last.braking_torque_nm - 20.3).abs() < 1e-3);
    // Drive off: no current, mid-scale code.
    assert_eq!(last.current_code, 2048);
    assert!(dir.join("hold-paper.csv").exists());
    let svg = std::fs::read_to_string(dir.join("hold-paper.svg")).unwrap();
    assert!(svg.contains("<svg") && svg.contains("polyline"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn errors_exit_with_code_2() {
    assert_eq!(cli::twin_main(&args(&[])), 2);
    assert_eq!(cli::twin_main(&args(&["no_such_scene"])), 2);
    assert_eq!(cli::twin_main(&args(&["hold", "--reading", "exact"])), 2);
    assert_eq!(cli::twin_main(&args(&["hold", "--frobnicate"])), 2);
    assert_eq!(cli::paper_main(&args(&["--bogus"])), 2);
    let dir = std::env::temp_dir().join(format!("noback-twin-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("bad.toml");
    std::fs::write(&f, "[scene]\nkind = \"hold\"\nwhat = 1\n").unwrap();
    assert_eq!(cli::twin_main(&args(&[f.to_str().unwrap()])), 2);
    let _ = std::fs::remove_dir_all(&dir);
}
