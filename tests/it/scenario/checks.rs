//! Each action and each expectation kind, through the runner: every case states one
//! expectation that must hold and one that must fail, so a check that can never fail (or
//! never pass) is caught.

use hooke::tools::scenario::{Report, Scenario};

/// Runs a scenario whose entities are `entities`, with `timeline` and `expect` lists.
fn run(settings: &str, entities: &str, timeline: &str, expect: &str) -> Report {
    let text = format!(
        "(duration: 4.0, settings: ({settings}), entities: [{entities}], timeline: [{timeline}], expect: [{expect}])"
    );
    let s = Scenario::from_str(&text, "<test>").unwrap_or_else(|e| panic!("{e}\n{text}"));
    s.run().unwrap_or_else(|e| panic!("{e}"))
}

/// The outcomes must be pass, fail (in that order).
fn pass_then_fail(r: &Report) {
    assert_eq!(r.outcomes.len(), 2, "{r}");
    assert!(r.outcomes[0].passed, "{r}");
    assert!(!r.outcomes[1].passed, "{r}");
}

const BALL: &str = r#"(name: "p", spawn: Particle(at: (0, 10, 0), mass: 2.0))"#;
const FLOOR_AND_BOX: &str = r#"(name: "ground", spawn: Ground), (name: "box", spawn: Body(shape: Cuboid(0.5, 0.5, 0.5), at: (0, 0.5, 0)))"#;
const NO_G: &str = "gravity: (0, 0, 0)";

#[test]
fn impulse_changes_velocity_by_j_over_m() {
    let r = run(
        NO_G,
        BALL,
        r#"(at: 0.5, do: Impulse(entity: "p", impulse: (4, 0, 0)))"#,
        r#"(at: 1.0, check: Speed(entity: "p", min: 1.999, max: 2.001)), (at: 0.5, check: Speed(entity: "p", min: 1.0))"#,
    );
    pass_then_fail(&r);
}

#[test]
fn force_accelerates_until_cleared() {
    let r = run(
        NO_G,
        BALL,
        r#"(at: 0.0, do: Force(entity: "p", force: (2, 0, 0))), (at: 1.0, do: Force(entity: "p", force: (0, 0, 0)))"#,
        r#"(during: (1.0, 2.0), check: Speed(entity: "p", min: 0.999, max: 1.001)), (at: 2.0, check: Speed(entity: "p", min: 1.5))"#,
    );
    pass_then_fail(&r);
}

#[test]
fn torque_spins_a_body() {
    let r = run(
        NO_G,
        r#"(name: "b", spawn: Body(shape: Ball(0.5)))"#,
        r#"(at: 0.0, do: Torque(entity: "b", torque: (0, 10, 0)))"#,
        r#"(at: 1.0, check: AngularSpeed(entity: "b", min: 0.01)), (at: 1.0, check: AngularSpeed(entity: "b", max: 0.001))"#,
    );
    pass_then_fail(&r);
}

#[test]
fn set_velocity_and_angular_velocity_take_effect() {
    let r = run(
        NO_G,
        r#"(name: "b", spawn: Body(shape: Ball(0.5)))"#,
        r#"(at: 0.5, do: SetVelocity(entity: "b", velocity: (0, 3, 0))), (at: 0.5, do: SetAngularVelocity(entity: "b", angular_velocity: (0, 0, 2)))"#,
        r#"(at: 1.0, check: ClosedForm(entity: "b", quantity: Y, value: "3*(t - 0.5)", tolerance: 1e-4)), (at: 1.0, check: AngularSpeed(entity: "b", max: 1.0))"#,
    );
    pass_then_fail(&r);
}

#[test]
fn teleport_moves_a_body() {
    let r = run(
        NO_G,
        BALL,
        r#"(at: 1.0, do: Teleport(entity: "p", to: (5, 5, 5)))"#,
        r#"(at: 1.0, check: Near(entity: "p", point: (5, 5, 5), within: 1e-6)), (at: 0.5, check: Near(entity: "p", point: (5, 5, 5), within: 1.0))"#,
    );
    pass_then_fail(&r);
}

#[test]
fn spawn_and_despawn_on_the_timeline() {
    let r = run(
        NO_G,
        BALL,
        r#"(at: 0.5, do: Spawn(name: "q", spawn: Particle(at: (1, 0, 0), velocity: (1, 0, 0)))), (at: 1.0, do: Despawn(entity: "p"))"#,
        r#"(at: 1.5, check: ClosedForm(entity: "q", quantity: X, value: "1 + (t - 0.5)", tolerance: 1e-4)), (at: 0.9, check: Position(entity: "p", y: (100, 200)))"#,
    );
    pass_then_fail(&r);
    // A despawned name is gone from the world.
    let text = r#"(entities: [(name: "p", spawn: Particle(at: (0, 0, 0)))], timeline: [(at: 0.5, do: Despawn(entity: "p"))], expect: [(at: 0.6, check: Speed(entity: "p", max: 1))])"#;
    assert!(Scenario::from_str(text, "<test>").is_err());
}

#[test]
fn pin_holds_and_release_lets_go() {
    let r = run(
        "",
        &format!("{BALL}, {FLOOR_AND_BOX}"),
        r#"(at: 0.0, do: Pin(entity: "p")), (at: 1.0, do: Release(entity: "p")), (at: 0.0, do: Pin(entity: "box"))"#,
        r#"(during: (0.0, 1.0), check: Position(entity: "p", y: (9.9999, 10.0001))), (at: 1.5, check: Position(entity: "p", y: (9.9, 10.1)))"#,
    );
    pass_then_fail(&r);
}

#[test]
fn set_gravity_and_switching_gravity() {
    let r = run(
        "",
        BALL,
        r#"(at: 0.0, do: SetGravity(gravity: (0, 0, 0))), (at: 1.0, do: SetGravity(gravity: (0, 5, 0))), (at: 1.0, do: Disable(Gravity)), (at: 1.5, do: Enable(Gravity))"#,
        r#"(during: (0.0, 1.5), check: Position(entity: "p", y: (9.9999, 10.0001))), (at: 2.0, check: Position(entity: "p", y: (9.0, 10.0)))"#,
    );
    pass_then_fail(&r);
}

#[test]
fn friction_written_on_the_timeline_changes_sliding() {
    // μ = 0 on both sides: the kicked box slides on at its speed.
    let r = run(
        "",
        FLOOR_AND_BOX,
        r#"(at: 0.5, do: SetFriction(entity: "box", value: 0.0)), (at: 0.5, do: SetFriction(entity: "ground", value: 0.0)), (at: 0.5, do: SetVelocity(entity: "box", velocity: (2, 0, 0)))"#,
        r#"(at: 1.5, check: Speed(entity: "box", min: 1.99, max: 2.01)), (at: 1.5, check: Speed(entity: "box", max: 1.0))"#,
    );
    pass_then_fail(&r);
}

#[test]
fn restitution_written_on_the_timeline_makes_a_bounce() {
    let r = run(
        "",
        r#"(name: "ground", spawn: Ground), (name: "ball", spawn: Body(shape: Ball(0.1), at: (0, 1.1, 0), restitution_threshold: 0.1))"#,
        r#"(at: 0.1, do: SetRestitution(entity: "ball", value: 0.9))"#,
        r#"(during: (0.5, 1.2), check: Peak(entity: "ball", quantity: Y, min: 0.8)), (during: (0.5, 1.2), check: Peak(entity: "ball", quantity: Y, max: 0.5))"#,
    );
    pass_then_fail(&r);
}

#[test]
fn sleep_switched_off_keeps_a_box_awake() {
    let r = run(
        "",
        FLOOR_AND_BOX,
        r#"(at: 3.0, do: Disable(Sleep))"#,
        r#"(at: 2.9, check: Asleep(entity: "box")), (at: 3.5, check: Asleep(entity: "box"))"#,
    );
    pass_then_fail(&r);
    let r = run(
        "",
        FLOOR_AND_BOX,
        "",
        r#"(at: 0.1, check: Awake(entity: "box")), (at: 0.1, check: Asleep(entity: "box"))"#,
    );
    pass_then_fail(&r);
}

#[test]
fn energy_and_momentum_within_tolerance() {
    let osc = r#"(name: "a", spawn: Particle(at: (0, 0, 0), pinned: true)), (name: "m", spawn: Particle(at: (1.1, 0, 0))), (name: "s", spawn: Spring(a: "a", b: "m", stiffness: 100, rest: 1.0))"#;
    let r = run(
        NO_G,
        osc,
        "",
        r#"(check: Energy(relative: 0.03)), (check: Energy(relative: 0.001))"#,
    );
    pass_then_fail(&r);
    // A free particle keeps its momentum; a pushed one does not.
    let r = run(
        NO_G,
        r#"(name: "p", spawn: Particle(at: (0, 0, 0), velocity: (1, 2, 3))), (name: "q", spawn: Particle(at: (9, 0, 0)))"#,
        r#"(at: 1.0, do: Impulse(entity: "q", impulse: (1, 0, 0)))"#,
        r#"(check: Momentum(entity: "p", relative: 1e-6)), (check: Momentum(relative: 0.01))"#,
    );
    pass_then_fail(&r);
}

#[test]
fn contact_and_no_contact() {
    let r = run(
        "",
        r#"(name: "ground", spawn: Ground), (name: "ball", spawn: Body(shape: Ball(0.2), at: (0, 2, 0))), (name: "far", spawn: Body(shape: Ball(0.2), at: (5, 0.2, 0)))"#,
        "",
        r#"(during: (0.0, 1.0), check: Contact(a: "ball", b: "ground")), (during: (0.0, 1.0), check: NoContact(a: "ball", b: "ground"))"#,
    );
    pass_then_fail(&r);
    let r = run(
        "",
        r#"(name: "ground", spawn: Ground), (name: "ball", spawn: Body(shape: Ball(0.2), at: (0, 2, 0))), (name: "far", spawn: Body(shape: Ball(0.2), at: (5, 0.2, 0)))"#,
        "",
        r#"(check: NoContact(a: "ball", b: "far")), (check: Contact(a: "ball", b: "far"))"#,
    );
    pass_then_fail(&r);
}

#[test]
fn quarantine_expectations() {
    let r = run(
        "",
        BALL,
        r#"(at: 1.0, do: SetVelocity(entity: "p", velocity: (1e20, 0, 0)))"#,
        r#"(during: (1.0, 1.5), check: Quarantined(entity: "p")), (check: NoQuarantine)"#,
    );
    pass_then_fail(&r);
    let r = run(
        "",
        BALL,
        "",
        r#"(check: NoQuarantine), (check: Quarantined(entity: "p"))"#,
    );
    pass_then_fail(&r);
}

#[test]
fn position_speed_peak_and_closed_form_on_a_fall() {
    let r = run(
        "",
        BALL,
        "",
        r#"(at: 1.0, check: Position(entity: "p", x: (-0.001, 0.001), y: (5.0, 5.2))), (at: 1.0, check: Position(entity: "p", y: (5.2, 6.0)))"#,
    );
    pass_then_fail(&r);
    let r = run(
        "",
        BALL,
        "",
        r#"(during: (0.0, 1.0), check: Speed(entity: "p", max: 9.9)), (during: (0.0, 1.0), check: Speed(entity: "p", max: 9.0))"#,
    );
    pass_then_fail(&r);
    let r = run(
        "",
        BALL,
        "",
        r#"(during: (0.5, 1.0), check: Peak(entity: "p", quantity: Y, min: 8.7, max: 8.8)), (during: (0.5, 1.0), check: Peak(entity: "p", quantity: Vy, min: 0.0))"#,
    );
    pass_then_fail(&r);
    let r = run(
        "",
        BALL,
        "",
        r#"(check: ClosedForm(entity: "p", quantity: Vy, value: "-g*t", tolerance: 1e-3)), (check: ClosedForm(entity: "p", quantity: Y, value: "10 - g*t^2/2", tolerance: 1e-3))"#,
    );
    pass_then_fail(&r);
}

#[test]
fn a_pinned_hash_that_differs_fails_the_run() {
    let text = r#"(duration: 0.5, entities: [(name: "p", spawn: Particle(at: (0, 1, 0)))], hash: "0123456789abcdef")"#;
    let r = Scenario::from_str(text, "<test>").unwrap().run().unwrap();
    assert!(!r.passed(), "{r}");
    let pinned = text.replace("0123456789abcdef", &r.hash_hex());
    let r2 = Scenario::from_str(&pinned, "<test>")
        .unwrap()
        .run()
        .unwrap();
    assert!(r2.passed(), "{r2}");
    assert_eq!(r2.outcomes.len(), 1);
}

#[test]
fn a_group_name_checks_every_member_and_an_index_one() {
    let rope = r#"(name: "rope", spawn: Rope(from: (0, 2, 0), to: (2, 2, 0), nodes: 5))"#;
    let r = run(
        "",
        rope,
        "",
        r#"(at: 1.0, check: Position(entity: "rope[0]", y: (1.999, 2.001))), (at: 1.0, check: Position(entity: "rope", y: (1.999, 2.001)))"#,
    );
    pass_then_fail(&r);
}
