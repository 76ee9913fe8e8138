//! A snapshot from disk is checked as strictly as the constructors check their input: a
//! soft body's E or ν NaN or −1, a divergence-guard limit NaN (which turned the guard off),
//! or a NaN solver tolerance were restored without an error.

use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::prelude::*;
use hooke::snapshot::Snapshot;
use hooke::tools::scenes;

/// An implicit jelly on the ground, stepped once, as RON.
fn saved() -> String {
    let mut w = World::new();
    w.add_physics(PhysicsPlugins);
    scenes::ground(&mut w).unwrap();
    scenes::jelly(&mut w, Vec3::new(0.0, 1.0, 0.0), true).unwrap();
    w.step_physics();
    Snapshot::capture(&w).unwrap().to_ron().unwrap()
}

/// `text` with the number after the first `field: ` (after the material's `poisson`, for a
/// material field) replaced by `value`.
fn with(text: &str, field: &str, value: &str) -> String {
    let key = format!("{field}: ");
    let from = if field == "density" {
        text.find("poisson: ").unwrap()
    } else {
        0
    };
    let start = from
        + text[from..]
            .find(&key)
            .unwrap_or_else(|| panic!("no {field}"))
        + key.len();
    let end = start
        + text[start..]
            .find(|c: char| c == ',' || c == ')' || c.is_whitespace())
            .unwrap();
    format!("{}{value}{}", &text[..start], &text[end..])
}

#[test]
fn a_snapshot_with_an_invalid_material_guard_or_solver_setting_is_a_typed_error() {
    let good = saved();
    let restored = Snapshot::from_ron(&good).expect("the good one reads");
    let mut copy = World::new();
    copy.add_physics(PhysicsPlugins);
    restored.restore(&mut copy).expect("and restores");
    for (field, value) in [
        ("young", "NaN"),
        ("young", "-1.0"),
        ("poisson", "NaN"),
        ("poisson", "-1.0"),
        ("poisson", "0.5"),
        ("density", "0.0"),
        ("max_speed", "NaN"),
        ("max_spring_strain", "NaN"),
        ("max_distance", "-1.0"),
        ("tolerance", "NaN"),
        ("max_newton", "0"),
        ("max_cg", "4000000000"),
    ] {
        let bad = with(&good, field, value);
        match Snapshot::from_ron(&bad) {
            Ok(_) => panic!("{field}: {value} was accepted"),
            Err(e) => println!("{field}: {value} → {e}"),
        }
    }
}

#[test]
fn a_snapshot_whose_implicit_factor_is_one_number_short_is_refused() {
    // The jelly's kept factor: drop the last number of its `values` (the solve indexed past
    // it), or name a node past the mesh in its order.
    let good = saved();
    let at = good.find("values: [").expect("a kept factor") + "values: [".len();
    let close = at + good[at..].find(']').unwrap();
    let numbers = &good[at..close];
    let last_comma = numbers.trim_end().trim_end_matches(',').rfind(',').unwrap();
    let short = format!(
        "{}{}{}",
        &good[..at],
        &numbers[..last_comma],
        &good[close..]
    );
    let refused = |text: &str| match Snapshot::from_ron(text) {
        Ok(_) => panic!("accepted"),
        Err(e) => e.to_string(),
    };
    let e = refused(&short);
    println!("{e}");
    assert!(e.contains("implicit factor"), "{e}");
    let at = good.find("order: [").unwrap() + "order: [".len();
    let end = at + good[at..].find(',').unwrap();
    let renamed = format!("{}4294967295{}", &good[..at], &good[end..]);
    let e = refused(&renamed);
    println!("{e}");
    assert!(e.contains("implicit factor"), "{e}");
}

/// Found by the snapshot fuzz: a moving body (here asleep, so no step checks it) edited to
/// 4·10²¹ m was restored and left there, silently out of the world. No run can leave a body
/// there (the guard quarantines it past 10⁶ m), so a file that does is refused.
#[test]
fn a_moving_body_past_the_guard_distance_is_refused() {
    let mut w = World::new();
    w.add_physics(PhysicsPlugins);
    let body = scenes::dynamic_box(&mut w, Vec3::splat(0.5), Vec3::new(123.25, 5.0, 0.0)).unwrap();
    w.entity_mut(body).insert(Sleeping);
    let text = Snapshot::capture(&w).unwrap().to_ron().unwrap();
    assert!(text.contains("123.25"), "the body's x is written as given");
    let read = Snapshot::from_ron(&text.replacen("123.25", "-4.289195e21", 1)).unwrap();
    let mut copy = World::new();
    copy.add_physics(PhysicsPlugins);
    let error = read.restore(&mut copy).expect_err("refused").to_string();
    assert!(error.contains("past the divergence guard"), "{error}");
    // A static body may sit anywhere its constructor accepts.
    let mut w = World::new();
    w.add_physics(PhysicsPlugins);
    w.spawn((
        RigidBody::Static,
        Collider::cuboid(1.0, 1.0, 1.0).unwrap(),
        Position::from(Vec3::new(123.25, 0.0, 0.0)),
    ));
    let text = Snapshot::capture(&w).unwrap().to_ron().unwrap();
    let read = Snapshot::from_ron(&text.replacen("123.25", "4e21", 1)).unwrap();
    let mut copy = World::new();
    copy.add_physics(PhysicsPlugins);
    assert!(read.restore(&mut copy).is_ok());
}

/// A convex hull whose face names vertex 4294967295 in a hand-edited snapshot: parry's mass
/// properties indexed past the vertices inside the restore.
#[test]
fn a_hull_naming_a_vertex_it_lacks_is_refused() {
    let mut w = World::new();
    w.add_physics(PhysicsPlugins);
    let points = [
        Vec3::ZERO,
        Vec3::X,
        Vec3::Y,
        Vec3::Z,
        Vec3::new(0.7, 0.7, 0.7),
    ];
    w.spawn((
        RigidBody::Dynamic,
        Collider::convex_hull(&points).unwrap(),
        Position::from(Vec3::new(0.0, 2.0, 0.0)),
    ));
    w.step_physics();
    let text = Snapshot::capture(&w).unwrap().to_ron().unwrap();
    // The first face's first vertex index, in the hull's `faces` (or `vertices_adj_to_face`).
    let mut refused = 0;
    for key in ["faces_adj_to_vertex", "vertices_adj_to_face", "edges"] {
        let Some(at) = text.find(key) else { continue };
        let start = at + text[at..].find(|c: char| c.is_ascii_digit()).unwrap();
        let end = start + text[start..].find(|c: char| !c.is_ascii_digit()).unwrap();
        let edited = format!("{}4294967295{}", &text[..start], &text[end..]);
        let outcome = std::panic::catch_unwind(|| {
            let read = Snapshot::from_ron(&edited);
            let mut copy = World::new();
            copy.add_physics(PhysicsPlugins);
            let restored = read.map(|s| s.restore(&mut copy).map(|_| ()));
            if let Ok(Ok(())) = restored {
                for _ in 0..5 {
                    copy.step_physics();
                }
            }
            restored.map(|r| r.is_err()).unwrap_or(true)
        });
        println!("{key}: {outcome:?}");
        assert!(outcome.is_ok(), "{key}: a panic");
        refused += usize::from(matches!(outcome, Ok(true)));
    }
    assert!(refused > 0, "some edit reached the hull and was refused");
}
