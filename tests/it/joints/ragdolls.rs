//! A pile of ragdolls (ball joints with cones, twists and friction, hinges with limits,
//! contacts between all of them) at the defaults: nothing comes apart, nothing is
//! quarantined, no limb stays past its limits and the pile comes to rest.

use bevy_ecs::prelude::*;
use hooke::prelude::*;
use hooke::tools::joint_scenes::{Ragdoll, RagdollPile};

use crate::common::default_world;

/// What a pile of ragdolls did in 6 s: the widest any joint's anchors parted (m), the
/// widest any joint stood past its limits (rad), the same over the last second, and the
/// parts' mean and largest speed at the end (m/s).
struct Dropped {
    gap: f32,
    angle: f32,
    settled_angle: f32,
    mean_speed: f32,
    fastest: f32,
    /// How many parts are asleep at the end.
    asleep: usize,
}

fn drop_pile(mut world: World, ragdolls: usize, reversed: bool) -> Dropped {
    let (parts, joints) = if reversed {
        // The same scene, the ragdolls spawned last first and the ground last.
        let (mut parts, mut joints) = (Vec::new(), Vec::new());
        for k in (0..ragdolls).rev() {
            let (origin, turn) = RagdollPile::placement(k);
            let (p, j) = Ragdoll::spawn(&mut world, origin, turn).unwrap();
            parts.extend(p);
            joints.extend(j);
        }
        RagdollPile { ragdolls: 0 }.spawn(&mut world).unwrap();
        (parts, joints)
    } else {
        RagdollPile { ragdolls }.spawn(&mut world).unwrap()
    };
    assert_eq!(parts.len(), ragdolls * Ragdoll::PARTS.len());
    let dt = world.resource::<PhysicsTime>().dt();
    let steps = (6.0 / dt).round() as usize;
    let (mut gap, mut angle, mut settled_angle) = (0.0_f32, 0.0_f32, 0.0_f32);
    for step in 0..steps {
        world.step_physics();
        let d = *world.resource::<JointDiagnostics>();
        assert_eq!(d.joints, joints.len());
        gap = gap.max(d.largest_gap);
        angle = angle.max(d.largest_angle);
        if (step as f32) * dt >= 5.0 {
            settled_angle = settled_angle.max(d.largest_angle);
        }
    }
    let (mut total, mut fastest) = (0.0_f32, 0.0_f32);
    let asleep = parts
        .iter()
        .filter(|&&e| world.get::<Sleeping>(e).is_some())
        .count();
    for &e in &parts {
        assert!(world.get::<Quarantined>(e).is_none(), "{e} quarantined");
        let x = world.get::<Position>(e).unwrap().0;
        assert!(x.is_finite() && x.y > -0.05, "{e} at {x}");
        let v = world.get::<LinearVelocity>(e).unwrap().0.length();
        total += v;
        fastest = fastest.max(v);
    }
    Dropped {
        gap,
        angle,
        settled_angle,
        mean_speed: total / parts.len() as f32,
        fastest,
        asleep,
    }
}

#[test]
fn a_pile_of_twenty_ragdolls_holds_together_and_comes_to_rest() {
    // Measured at the defaults, spawned in order / reversed: anchors parted by 7.8 / 8.4 mm
    // at most (in the impacts), 3.0 / 3.7° past a limit at most and 0.03 / 0.07° in the last
    // second, mean speed 0.015 / 0.023 m/s at 6 s. With each ragdoll's joints solved as soft
    // springs (the soft step's scales) the same pile parted by 10.2 / 11.8 mm (7.7 held
    // under the settled pile), its limits pressed 2.5 / 4.8° past their stops at rest.
    for reversed in [false, true] {
        let d = drop_pile(default_world(), 20, reversed);
        println!(
            "20 ragdolls (reversed {reversed}): anchors parted by {:.2} mm at most, {:.2}° past a limit at most ({:.2}° in the last second), speed at 6 s: mean {:.4} m/s, largest {:.4} m/s",
            d.gap * 1e3,
            d.angle.to_degrees(),
            d.settled_angle.to_degrees(),
            d.mean_speed,
            d.fastest
        );
        assert!(d.gap < 0.01, "anchors parted by {} m", d.gap);
        assert!(
            d.angle < 6f32.to_radians() && d.settled_angle < 0.5f32.to_radians(),
            "{}° past a limit ({}° in the last second)",
            d.angle.to_degrees(),
            d.settled_angle.to_degrees()
        );
        assert!(
            d.mean_speed < 0.03 && d.fastest < 0.3,
            "still moving: mean {} m/s, largest {} m/s",
            d.mean_speed,
            d.fastest
        );
    }
}

#[test]
fn a_lone_ragdoll_dropped_on_the_ground_lies_still() {
    // One ragdoll falls 0.4 m onto its back. Measured: anchors 0.34 mm apart at most (as it
    // lands), no limit passed, all 11 parts asleep at 6 s. Solved as soft springs its joints
    // and the ground's contacts undid a little of each other every substep: 1.8 mm, and it
    // never slept (its parts at 0.02 m/s).
    let d = drop_pile(default_world(), 1, false);
    println!(
        "1 ragdoll: anchors parted by {:.2} mm, {:.3}° past a limit, largest speed at 6 s {:.4} m/s",
        d.gap * 1e3,
        d.angle.to_degrees(),
        d.fastest
    );
    assert!(d.gap < 1e-3, "anchors parted by {} m", d.gap);
    assert!(d.angle < 0.5f32.to_radians());
    assert!(d.fastest < 0.005, "still moving at {} m/s", d.fastest);
    assert_eq!(d.asleep, Ragdoll::PARTS.len(), "not all asleep");
}
