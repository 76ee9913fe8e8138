//! Regressions: the collider parts of a body whose state turned non-finite were moved to NaN
//! positions while not themselves quarantined; a part more than 256 levels below its body
//! was silently left out (the body kept the 1 kg default). Now the parts of a quarantined
//! body stay where it was last sound, and a part past [`MAX_PART_DEPTH`] is quarantined with
//! a typed error, whichever way the hierarchy is built.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};
use hooke::collision::MAX_PART_DEPTH;
use hooke::core::error::Error;
use hooke::prelude::*;

use crate::common;

#[test]
fn parts_of_a_quarantined_body_keep_a_finite_pose() {
    let mut w = common::contact_world(4);
    let body = w
        .spawn((RigidBody::Dynamic, Position::from(Vec3::new(0.0, 3.0, 0.0))))
        .id();
    let parts = [-1.0f32, 1.0].map(|dx| {
        w.spawn((
            Collider::cuboid(0.2, 0.2, 0.2).unwrap(),
            ColliderOffset::try_new(Vec3::new(dx, 0.0, 0.0), Quat::IDENTITY).unwrap(),
            ChildOf(body),
        ))
        .id()
    });
    for _ in 0..10 {
        w.step_physics();
    }
    w.get_mut::<LinearVelocity>(body).unwrap().0 = Vec3::NAN.into();
    for _ in 0..10 {
        w.step_physics();
    }
    assert!(
        w.get::<Quarantined>(body).is_some(),
        "the NaN body is caught"
    );
    for p in parts {
        let x = w.get::<Position>(p).unwrap().get();
        let q = w.get::<Rotation>(p).unwrap().0;
        assert!(x.is_finite() && q.is_finite(), "part {p} at {x:?} {q:?}");
        assert!(x.y > 2.5, "the part stays where the body was: {x:?}");
    }
}

/// A body, a chain of `depth` plain entities below it, and a 1 kg·m⁻³ box at the bottom:
/// built from the body down (`top_down`) or from the box up.
fn deep_part(w: &mut World, depth: usize, top_down: bool) -> (Entity, Entity) {
    let collider = || {
        (
            Collider::cuboid(0.5, 0.5, 0.5).unwrap(),
            ColliderDensity::try_new(8.0).unwrap(),
        )
    };
    if top_down {
        let body = w.spawn((RigidBody::Dynamic, Position::default())).id();
        let mut parent = body;
        for _ in 1..depth {
            parent = w.spawn(ChildOf(parent)).id();
        }
        let part = w.spawn((collider(), ChildOf(parent))).id();
        (body, part)
    } else {
        let part = w.spawn(collider()).id();
        let mut child = part;
        for _ in 1..depth {
            let parent = w.spawn_empty().id();
            w.entity_mut(child).insert(ChildOf(parent));
            child = parent;
        }
        let body = w.spawn((RigidBody::Dynamic, Position::default())).id();
        w.entity_mut(child).insert(ChildOf(body));
        (body, part)
    }
}

#[test]
fn a_part_at_the_depth_bound_is_attached_and_one_past_it_is_refused() {
    for top_down in [true, false] {
        let mut w = common::contact_world(4);
        let (body, part) = deep_part(&mut w, MAX_PART_DEPTH, top_down);
        w.step_physics();
        let mass = w.get::<Mass>(body).unwrap().value();
        assert!(
            (mass - 8.0).abs() < 1e-3 && w.get::<ColliderOf>(part).is_some(),
            "top_down {top_down}: a part {MAX_PART_DEPTH} deep is attached (mass {mass})"
        );

        let mut w = common::contact_world(4);
        let (body, part) = deep_part(&mut w, MAX_PART_DEPTH + 1, top_down);
        w.step_physics();
        let reason = w.get::<Quarantined>(part).map(|q| q.reason.clone());
        println!("top_down {top_down}: {reason:?}");
        assert!(
            matches!(
                reason,
                Some(QuarantineReason::InvalidInput(Error::TooMany { .. }))
            ),
            "top_down {top_down}: a part one level too deep is refused, not dropped: {reason:?}"
        );
        assert!(w.get::<ColliderOf>(part).is_none());
        assert!(w.get::<Quarantined>(body).is_none(), "the body itself runs");
    }
}
