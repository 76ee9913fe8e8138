//! Every kind of bad scenario file is a typed error with its line, never a panic: one file
//! per case in `tests/scenarios/`.

use hooke::tools::scenario::{Scenario, ScenarioError, ScenarioErrorKind};

fn load(name: &str) -> Result<Scenario, ScenarioError> {
    Scenario::from_file(format!(
        "{}/tests/scenarios/{name}",
        env!("CARGO_MANIFEST_DIR")
    ))
}

fn error(name: &str) -> ScenarioError {
    match load(name) {
        Ok(_) => panic!("{name} loaded"),
        Err(e) => {
            // The message names the file and line as an editor wants them.
            assert!(
                e.to_string().contains(&format!("{name}:{}:", e.line)),
                "{e}"
            );
            e
        }
    }
}

#[test]
fn an_unknown_entity_is_named_with_its_line() {
    let e = error("unknown_entity.ron");
    assert_eq!(e.kind, ScenarioErrorKind::UnknownEntity("krate".into()));
    assert_eq!(e.line, 7);
}

#[test]
fn an_unknown_field_is_a_syntax_error_at_its_line() {
    let e = error("unknown_field.ron");
    assert!(
        matches!(&e.kind, ScenarioErrorKind::Syntax(m) if m.contains("velocty")),
        "{e}"
    );
    assert_eq!(e.line, 3);
}

#[test]
fn a_negative_time_is_refused() {
    let e = error("negative_time.ron");
    assert!(
        matches!(&e.kind, ScenarioErrorKind::BadTime(m) if m.contains("-1")),
        "{e}"
    );
    assert_eq!(e.line, 6);
}

#[test]
fn an_expectation_on_a_despawned_entity_is_refused() {
    let e = error("missing_entity.ron");
    assert_eq!(
        e.kind,
        ScenarioErrorKind::MissingEntity {
            name: "crate".into(),
            born: 0,
            died: Some(60)
        }
    );
    // The check at 0.5 s (line 10) is fine; the one at 2 s is not.
    assert_eq!(e.line, 11);
}

#[test]
fn a_duplicate_name_points_at_both_lines() {
    let e = error("duplicate_name.ron");
    assert_eq!(
        e.kind,
        ScenarioErrorKind::DuplicateName {
            name: "crate".into(),
            first_line: 3
        }
    );
    assert_eq!(e.line, 4);
}

#[test]
fn broken_ron_is_a_syntax_error() {
    let e = error("bad_syntax.ron");
    assert!(matches!(e.kind, ScenarioErrorKind::Syntax(_)), "{e}");
    assert!((3..=5).contains(&e.line), "{e}");
}

#[test]
fn a_moment_past_the_duration_is_refused() {
    let e = error("past_duration.ron");
    assert!(
        matches!(&e.kind, ScenarioErrorKind::BadTime(m) if m.contains("duration")),
        "{e}"
    );
    assert_eq!(e.line, 7);
}

#[test]
fn a_bad_closed_form_names_its_column() {
    let e = error("bad_closed_form.ron");
    assert!(
        matches!(&e.kind, ScenarioErrorKind::BadValue(m) if m.contains("unexpected end at column 14")),
        "{e}"
    );
    assert_eq!(e.line, 6);
}

#[test]
fn an_index_past_a_group_is_refused() {
    let e = error("group_index.ron");
    assert!(
        matches!(&e.kind, ScenarioErrorKind::BadValue(m) if m.contains("has 5 entities")),
        "{e}"
    );
    assert_eq!(e.line, 6);
}

#[test]
fn a_value_a_constructor_refuses_is_found_when_the_scene_is_built() {
    let s = load("bad_value.ron").expect("the file itself is well formed");
    let e = s.run().expect_err("a negative radius");
    assert!(
        matches!(
            e.kind,
            ScenarioErrorKind::Build(hooke::Error::NotPositive { .. })
        ),
        "{e}"
    );
    assert_eq!(e.line, 6);
}

#[test]
fn an_unreadable_file_is_an_io_error() {
    let e = error("no_such_file.ron");
    assert!(matches!(e.kind, ScenarioErrorKind::Io(_)), "{e}");
}

#[test]
fn a_failing_expectation_is_reported_with_its_time_and_value() {
    let report = load("fails.ron").unwrap().run().unwrap();
    assert!(!report.passed());
    let f = report.first_failure().unwrap();
    assert_eq!(f.line, 7);
    assert!((f.time - 1.0).abs() < 1e-6, "{f}");
    // 1 s of free fall from 10 m: about 5.1 m (symplectic Euler at 240 Hz).
    assert!(
        f.measured.contains("y = 5.0") || f.measured.contains("y = 5.1"),
        "{f}"
    );
}

#[test]
fn scenario_errors_carry_hooke_errors_and_both_pass_through_question_marks() {
    fn user_test() -> Result<(), Box<dyn std::error::Error>> {
        let _ball = hooke::prelude::Collider::ball(0.5)?;
        load("unknown_entity.ron")?;
        Ok(())
    }
    let e = user_test().unwrap_err();
    assert!(e.downcast_ref::<ScenarioError>().is_some(), "{e}");
    let bad = load("bad_value.ron").unwrap().run().unwrap_err();
    assert!(
        matches!(
            bad.kind,
            ScenarioErrorKind::Build(hooke::Error::NotPositive { .. })
        ),
        "{bad}"
    );
}

#[test]
fn a_motor_on_a_joint_that_takes_none_is_refused_with_its_line() {
    let e = error("motor_on_ball_joint.ron");
    assert!(
        matches!(&e.kind, ScenarioErrorKind::BadValue(m) if m.contains("not a hinge or a slider")),
        "{e}"
    );
    assert_eq!(e.line, 9);
}

#[test]
fn a_joint_with_a_bad_axis_or_cone_is_a_build_error_with_its_line() {
    // A hinge about no axis; a ball joint's cone of 200°.
    for file in ["bad_joint_axis.ron", "cone_past_half_a_turn.ron"] {
        let s = load(file).expect("the file itself is well formed");
        let e = s.run().expect_err(file);
        assert!(
            matches!(
                e.kind,
                ScenarioErrorKind::Build(hooke::Error::OutOfRange { .. })
            ),
            "{file}: {e}"
        );
        assert_eq!(e.line, 6, "{file}");
    }
}

#[test]
fn a_servo_on_a_joint_without_an_axis_is_refused_with_its_line() {
    let e = error("servo_on_a_ball_joint.ron");
    assert!(
        matches!(&e.kind, ScenarioErrorKind::BadValue(m) if m.contains("only they take a motor")),
        "{e}"
    );
    assert_eq!(e.line, 9);
}
