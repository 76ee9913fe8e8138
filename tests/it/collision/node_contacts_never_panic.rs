//! Node contacts call parry too, and are guarded as pair geometry is: parry's segment
//! projection asserts (`sqnab != 0.0`) on a NaN point against a capsule of half height 0,
//! which a soft body thrown out of a huge capsule could reach. Non-finite nodes are not
//! projected, and a mesh whose contact geometry fails anyway is quarantined, named with the
//! collider. Soft bodies and cloth below, around and inside degenerate and huge capsules end
//! finite or quarantined, never in a panic.

use crate::common;

use glam::Vec3;
use hooke::collision::Collider;
use hooke::core::quarantine::Quarantined;
use hooke::prelude::*;
use hooke::rigid::RigidBody;
use hooke::tools::scenes;

#[test]
fn soft_bodies_and_cloth_against_degenerate_and_huge_capsules_never_panic() {
    let cases = [
        (0.0f32, 0.5f32),
        (0.0, 1e5),
        (1e5, 1e5),
        (1e-7, 3e4),
        (0.0, 1e3),
    ];
    for ((half, r), inside) in cases.into_iter().flat_map(|c| [(c, false), (c, true)]) {
        for implicit in [false, true] {
            let mut w = common::default_world();
            w.spawn((
                RigidBody::Static,
                Collider::capsule_y(half, r).unwrap(),
                // Below the bodies, or around them.
                Position::from(if inside {
                    Vec3::ZERO
                } else {
                    Vec3::new(0.0, -r - half + 0.2, 0.0)
                }),
            ));
            let jelly = scenes::jelly(&mut w, Vec3::new(0.0, 0.5, 0.0), implicit).unwrap();
            let cloth = scenes::cloth(&mut w, 6).unwrap();
            for _ in 0..60 {
                w.step_physics();
            }
            for e in [jelly, cloth] {
                let ok =
                    w.get::<Quarantined>(e).is_some() || w.get::<Nodes>(e).unwrap().is_finite();
                assert!(
                    ok,
                    "capsule ({half}, {r}), implicit {implicit}: silent non-finite"
                );
            }
            println!(
                "capsule ({half}, {r}), inside {inside}, implicit {implicit}: jelly {:?}",
                w.get::<Quarantined>(jelly).map(|q| &q.reason)
            );
        }
    }
}
