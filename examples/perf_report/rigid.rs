//! Rigid-body lines: free tumbling boxes against a raw-array loop and against rapier 0.36.

use std::hint::black_box;

use glam::{Quat, Vec3A};
use hooke::prelude::*;
use hooke::rigid::Inertia;
use hooke::rigid::MassProperties;
use hooke::rigid::free_rotation_split;
use hooke::tools::scenes;
use parry3d::shape::Cuboid;
use rapier3d::prelude as rp;

use crate::timing::{Config, compare, line};

/// The same bodies as flat arrays, stepped with the same arithmetic as hooke's default
/// (symplectic Euler, free-rotation splitting, renormalisation, ω = I⁻¹L): the physical limit.
struct RawBodies {
    x: Vec<Vec3A>,
    v: Vec<Vec3A>,
    q: Vec<Quat>,
    l: Vec<Vec3A>,
    w: Vec<Vec3A>,
    inertia: Inertia,
}

impl RawBodies {
    fn new(n: usize, inertia: Inertia) -> Self {
        let mut r = RawBodies {
            x: vec![],
            v: vec![],
            q: vec![],
            l: vec![],
            w: vec![],
            inertia,
        };
        for i in 0..n {
            let (x, omega) = scenes::tumbling_box_start(i, n);
            r.x.push(x.into());
            r.v.push(Vec3A::ZERO);
            r.q.push(Quat::IDENTITY);
            r.l.push(inertia.angular_momentum(Quat::IDENTITY, omega.into()));
            r.w.push(omega.into());
        }
        r
    }

    fn step(&mut self, g: Vec3A, h: f32) {
        for i in 0..self.x.len() {
            // Torque-free: τ = 0, so L keeps its value (the kick adds h·0).
            self.v[i] += h * g;
            self.x[i] += h * self.v[i];
            let q = free_rotation_split(self.q[i], &self.inertia, self.l[i], h, false).normalize();
            self.q[i] = q;
            self.w[i] = self.inertia.angular_velocity(q, self.l[i]);
        }
    }
}

fn rapier_world(n: usize, props: &MassProperties) -> rp::PhysicsWorld {
    let (half, density) = scenes::TUMBLING_BOX;
    let mut world = rp::PhysicsWorld::new();
    world.integration_parameters.dt = 1.0 / 60.0;
    let mprops = parry3d::shape::Shape::mass_properties(&Cuboid::new(half), density);
    assert!((mprops.mass() - props.mass).abs() < 1e-3);
    for i in 0..n {
        let (x, omega) = scenes::tumbling_box_start(i, n);
        // No collider: both engines only integrate (hooke has no colliders yet).
        world.insert_body(
            rp::RigidBodyBuilder::dynamic()
                .translation(x)
                .angvel(omega)
                .additional_mass_properties(mprops),
        );
    }
    world
}

pub fn rigid_free(cfg: &Config, n: usize) {
    let (half, density) = scenes::TUMBLING_BOX;
    let props = MassProperties::from_shape(&Cuboid::new(half), density).unwrap();
    let mut world = crate::quiet_world(1.0 / 60.0, 1, Integrator::SymplecticEuler);
    scenes::tumbling_boxes(&mut world, n).unwrap();
    world.step_physics();
    let mut raw = RawBodies::new(n, props.inertia);
    let g = Vec3A::new(0.0, -9.81, 0.0);
    let label = if n >= 1000 {
        format!("{}k", n / 1000)
    } else {
        n.to_string()
    };
    let (ours, reference) = compare(
        cfg,
        || world.step_physics(),
        || {
            raw.step(g, 1.0 / 60.0);
            black_box(&raw.q);
        },
    );
    line(
        &format!("rigid_free_{label}_vs_raw"),
        ours,
        reference,
        &format!("{:.1} ns/body, goal <= 1.3", ours / n as f64),
    );
    let mut rapier = rapier_world(n, &props);
    let (ours, reference) = compare(cfg, || world.step_physics(), || rapier.step());
    line(
        &format!("rigid_free_{label}_vs_rapier"),
        ours,
        reference,
        "no colliders on either side, goal <= 0.5",
    );
}
