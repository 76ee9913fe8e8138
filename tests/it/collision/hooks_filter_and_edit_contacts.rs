//! Collision hooks at the defaults (`PhysicsPlugins` and the hooks plugin): a filter turns
//! pairs away (and a pair that stops being allowed ends with its message); the shared scene's
//! one-way platform lets a ball rise through it on its free-flight arc and then holds it;
//! its conveyor belt carries a crate at the belt's speed after μ g of acceleration; an edit
//! of friction and restitution takes effect. Each in both spawn orders where order decides
//! which collider is `a`.

use crate::common;
use bevy_ecs::prelude::*;
use bevy_ecs::system::SystemParam;
use hooke::prelude::*;
use hooke::tools::hook_scenes::{BELT_TOP, HooksCourse, PlatformHooks, SLAB};

#[derive(Component)]
struct Ghost;

/// Lets things drop through every `Ghost` floor while it is set.
#[derive(Resource, Default)]
struct DropThrough(bool);

#[derive(SystemParam)]
struct GhostHooks<'w, 's> {
    ghosts: Query<'w, 's, (), With<Ghost>>,
    drop: Option<Res<'w, DropThrough>>,
}

impl CollisionHooks for GhostHooks<'_, '_> {
    fn filter_pair(&self, a: Entity, b: Entity, _: &mut Commands) -> bool {
        let open = self.drop.as_ref().is_some_and(|d| d.0);
        !(open && (self.ghosts.contains(a) || self.ghosts.contains(b)))
    }
}

fn ghost_world(floor_first: bool) -> (World, Entity, Entity) {
    let mut w = common::default_world();
    w.add_physics(CollisionHooksPlugin::<GhostHooks>::default());
    w.init_resource::<DropThrough>();
    w.spawn((
        RigidBody::Static,
        Collider::cuboid(5.0, 0.5, 5.0).unwrap(),
        Position::from(Vec3::new(0.0, -0.5, 0.0)),
    ));
    let floor = |w: &mut World| {
        w.spawn((
            RigidBody::Static,
            Collider::cuboid(2.0, 0.1, 2.0).unwrap(),
            Position::from(Vec3::new(0.0, 1.9, 0.0)),
            Ghost,
            ActiveCollisionHooks::FILTER_PAIRS,
        ))
        .id()
    };
    let body = |w: &mut World| {
        common::dynamic(
            w,
            Collider::cuboid(0.25, 0.25, 0.25).unwrap(),
            Vec3::new(0.0, 3.0, 0.0),
        )
    };
    let (f, b) = if floor_first {
        let f = floor(&mut w);
        (f, body(&mut w))
    } else {
        let b = body(&mut w);
        (floor(&mut w), b)
    };
    (w, f, b)
}

#[test]
fn a_filter_drops_a_body_through_a_floor_and_ends_the_contact_once() {
    for floor_first in [true, false] {
        let (mut w, floor, body) = ghost_world(floor_first);
        for _ in 0..90 {
            w.step_physics();
        }
        let y = common::x(&w, body).y;
        assert!(
            (y - 2.25).abs() < 0.02,
            "held by the floor while closed: {y}"
        );
        assert!(w.resource::<Contacts>().are_touching(floor, body));
        let mut ended = w.resource::<Messages<ContactEnded>>().get_cursor();
        w.resource_mut::<DropThrough>().0 = true;
        // Asleep by now, and a sleeping body's pairs are not asked again: a game that
        // changes its rule wakes the body, as it would to move it.
        w.entity_mut(body).remove::<Sleeping>();
        let mut ends = 0;
        for _ in 0..90 {
            w.step_physics();
            ends += ended
                .read(w.resource::<Messages<ContactEnded>>())
                .filter(|m| (m.a, m.b) == (floor.min(body), floor.max(body)))
                .count();
        }
        let y = common::x(&w, body).y;
        assert!((y - 0.25).abs() < 0.02, "on the ground once open: {y}");
        assert_eq!(ends, 1, "the floor's contact ended once");
    }
}

#[test]
fn hooks_leave_pairs_without_the_component_alone() {
    // The same scene without `ActiveCollisionHooks` on the floor: the filter is never asked.
    let mut w = common::default_world();
    w.add_physics(CollisionHooksPlugin::<GhostHooks>::default());
    w.insert_resource(DropThrough(true));
    let floor = w
        .spawn((
            RigidBody::Static,
            Collider::cuboid(2.0, 0.1, 2.0).unwrap(),
            Position::from(Vec3::new(0.0, 1.9, 0.0)),
            Ghost,
        ))
        .id();
    let body = common::dynamic(
        &mut w,
        Collider::ball(0.25).unwrap(),
        Vec3::new(0.0, 3.0, 0.0),
    );
    for _ in 0..90 {
        w.step_physics();
    }
    assert!(w.resource::<Contacts>().are_touching(floor, body));
}

fn course_world(course: &HooksCourse) -> (World, hooke::tools::hook_scenes::HooksParts) {
    let mut w = common::default_world();
    w.add_physics(CollisionHooksPlugin::<PlatformHooks>::default());
    let parts = course.spawn(&mut w).unwrap();
    (w, parts)
}

#[test]
fn a_one_way_platform_lets_a_ball_up_on_its_free_arc_and_then_holds_it() {
    let course = HooksCourse::default();
    let (mut w, parts) = course_world(&course);
    let g = 9.81;
    let mut apex = f32::MIN;
    for _ in 0..240 {
        w.step_physics();
        apex = apex.max(common::x(&w, parts.ball).y);
    }
    // Through the platform untouched: the apex of free flight (the discrete one is within
    // v dt of v²/2g).
    let free = course.free_apex(g);
    let dt = w.resource::<PhysicsTime>().dt();
    assert!(
        (apex - free).abs() < course.launch * dt,
        "apex {apex} vs free flight {free}"
    );
    // Then it lands on top and stays.
    let y = common::x(&w, parts.ball).y;
    let top = course.platform_top + course.ball_radius;
    assert!(
        (y - top).abs() < 0.02,
        "resting on the platform: {y} vs {top}"
    );
    assert!(common::v(&w, parts.ball).length() < 0.05);
    // Without the hooks the same launch stops under the platform.
    let mut plain = common::default_world();
    let parts = course.spawn(&mut plain).unwrap();
    let mut apex = f32::MIN;
    for _ in 0..120 {
        plain.step_physics();
        apex = apex.max(common::x(&plain, parts.ball).y);
    }
    assert!(
        apex < course.platform_top - 2.0 * SLAB,
        "blocked from below: {apex}"
    );
}

#[test]
fn a_conveyor_belt_carries_a_crate_at_its_speed() {
    let course = HooksCourse::default();
    let (mut w, parts) = course_world(&course);
    let dt = w.resource::<PhysicsTime>().dt();
    // Let the crate settle onto the belt (it starts resting on it).
    let mut speeds = Vec::new();
    for _ in 0..90 {
        w.step_physics();
        speeds.push(common::v(&w, parts.crate_).x);
    }
    // Friction accelerates it at μ g (μ = 0.5 from the default materials) up to the belt's
    // speed, which it then keeps.
    let mu = w.get::<Friction>(parts.crate_).unwrap().0;
    let t_reach = course.belt_speed / (mu * 9.81);
    let early = (0.5 * t_reach / dt) as usize;
    let expected = mu * 9.81 * (early + 1) as f32 * dt;
    assert!(
        (speeds[early] - expected).abs() < 0.1 * expected,
        "at {:.2} s: {} vs μ g t = {expected}",
        (early + 1) as f32 * dt,
        speeds[early]
    );
    let settled = &speeds[((t_reach + 0.3) / dt) as usize..];
    for &v in settled {
        assert!(
            (v - course.belt_speed).abs() < 0.01 * course.belt_speed,
            "carried at {v}"
        );
    }
    let y = common::x(&w, parts.crate_).y;
    assert!((y - (BELT_TOP + 0.25)).abs() < 0.01, "on the belt: {y}");
}

#[derive(Resource, Clone, Copy)]
struct Material {
    friction: f32,
    restitution: f32,
}

#[derive(SystemParam)]
struct MaterialHooks<'w> {
    material: Res<'w, Material>,
}

impl CollisionHooks for MaterialHooks<'_> {
    fn modify_contacts(&self, contact: &mut ContactEdit, _: &mut Commands) -> bool {
        contact.friction = self.material.friction;
        contact.restitution = self.material.restitution;
        true
    }
}

#[test]
fn edited_restitution_and_friction_take_effect() {
    // A ball dropped from 1 m bounces to e² of its height with restitution e set by the
    // hook; a box sliding at 3 m/s stops after v²/(2 μ g) with μ set by the hook.
    for (e, mu) in [(0.8f32, 0.2f32), (0.5, 0.4)] {
        let mut w = common::default_world();
        w.add_physics(CollisionHooksPlugin::<MaterialHooks>::default());
        w.insert_resource(Material {
            friction: mu,
            restitution: e,
        });
        w.spawn((
            RigidBody::Static,
            Collider::cuboid(20.0, 0.5, 5.0).unwrap(),
            Position::from(Vec3::new(0.0, -0.5, 0.0)),
            ActiveCollisionHooks::MODIFY_CONTACTS,
        ));
        let ball = common::dynamic(
            &mut w,
            Collider::ball(0.2).unwrap(),
            Vec3::new(-5.0, 1.2, 0.0),
        );
        let slider = w
            .spawn((
                RigidBody::Dynamic,
                Collider::cuboid(0.25, 0.25, 0.25).unwrap(),
                Position::from(Vec3::new(5.0, 0.25, 0.0)),
                LinearVelocity::from(Vec3::new(3.0, 0.0, 0.0)),
            ))
            .id();
        let (mut rebound, mut landed) = (f32::MIN, false);
        for _ in 0..150 {
            let v0 = common::v(&w, ball).y;
            w.step_physics();
            let (y, v) = (common::x(&w, ball).y, common::v(&w, ball).y);
            landed |= v0 < 0.0 && v > 0.0;
            if landed {
                // The first rebound is the highest after the landing.
                rebound = rebound.max(y);
            }
        }
        let bounce = rebound - 0.2;
        assert!(
            (bounce - e * e).abs() < 0.05 * e * e,
            "rebound {bounce} vs e² h = {}",
            e * e
        );
        let slid = common::x(&w, slider).x - 5.0;
        let expected = 9.0 / (2.0 * mu * 9.81);
        assert!(
            (slid - expected).abs() < 0.03 * expected,
            "slid {slid} vs {expected}"
        );
    }
}
