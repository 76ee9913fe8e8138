//! The `hooke` command (feature `cli`): exit status 0 when everything held, 1 when an
//! expectation failed, 2 for a bad file or command line; CSV traces and a plot on request.
#![cfg(feature = "cli")]

use std::process::Command;

fn hooke(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_hooke"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the hooke binary runs")
}

#[test]
fn a_passing_file_exits_zero_and_prints_each_expectation() {
    let out = hooke(&["run", "scenarios/kick_crate.ron"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    // Five expectations and the pinned hash.
    assert_eq!(text.matches("  pass line").count(), 6, "{text}");
    assert!(text.contains("scenarios: 1 passed, 0 failed"), "{text}");
}

#[test]
fn a_failed_expectation_exits_one() {
    let out = hooke(&[
        "run",
        "scenarios/kick_crate.ron",
        "tests/scenarios/fails.ron",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{text}");
    assert!(text.contains("FAIL line   7"), "{text}");
    assert!(text.contains("scenarios: 1 passed, 1 failed"), "{text}");
}

#[test]
fn a_bad_file_or_command_exits_two_with_its_line() {
    let out = hooke(&["run", "tests/scenarios/unknown_entity.ron"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("unknown_entity.ron:7:"), "{err}");
    assert_eq!(hooke(&["frobnicate"]).status.code(), Some(2));
    assert_eq!(hooke(&["run"]).status.code(), Some(2));
    assert_eq!(
        hooke(&["check", "scenarios/stack.ron"]).status.code(),
        Some(0)
    );
}

#[test]
fn traces_and_a_plot_are_written_on_request() {
    let dir = std::env::temp_dir().join(format!("hooke_cli_{}", std::process::id()));
    let (csv, png) = (dir.join("csv"), dir.join("png"));
    let out = hooke(&[
        "run",
        "--quiet",
        "--csv",
        csv.to_str().unwrap(),
        "--plot",
        png.to_str().unwrap(),
        "scenarios/bounce.ron",
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    let trace = std::fs::read_to_string(csv.join("bounce_ball.csv")).unwrap();
    let mut lines = trace.lines();
    assert_eq!(lines.next(), Some(hooke::tools::scenario::Trace::HEADER));
    // One row per step, 0 to 180.
    assert_eq!(lines.count(), 181);
    let bytes = std::fs::read(png.join("bounce.png")).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    let _ = std::fs::remove_dir_all(dir);
}
