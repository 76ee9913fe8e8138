//! The integrators' measurement of motion for the diagnostics: kinetic energy, momentum and
//! the gravitational potential of every body they move.

use bevy_ecs::prelude::*;
use glam::{DVec3, Vec3};

use crate::core::diagnostics::PhysicsDiagnostics;
use crate::core::quarantine::Quarantined;
use crate::particles::{Gravity, LinearVelocity, Mass, Nodes, Position, Tracer};
use crate::rigid::{AngularMomentum, AngularVelocity, Inertia, rotational_energy};

/// T = Σ ½ m |v|² + Σ ½ ω·L, U_g = −Σ m g·x, P = Σ m v, L = Σ x × m v + Σ L, in f64, and the
/// counts of particles, meshes, rigid bodies and tracers.
pub(super) fn measure_motion(
    mut diag: ResMut<PhysicsDiagnostics>,
    gravity: Option<Res<Gravity>>,
    bodies: Query<(&Position, &LinearVelocity, &Mass), Without<Quarantined>>,
    meshes: Query<&Nodes, Without<Quarantined>>,
    rotating: Query<(&AngularVelocity, &AngularMomentum, &Inertia), Without<Quarantined>>,
    tracers: Query<(), (With<Tracer>, Without<Quarantined>)>,
) {
    let g = gravity.map_or(DVec3::ZERO, |g| g.get().as_dvec3());
    let (mut t, mut u, mut p) = (0.0f64, 0.0f64, DVec3::ZERO);
    let counts = &mut diag.counts;
    counts.particles = 0;
    counts.meshes = 0;
    counts.mesh_nodes = 0;
    for (x, v, m) in &bodies {
        counts.particles += 1;
        if m.is_pinned() {
            continue;
        }
        let (mass, v) = (f64::from(m.value()), v.0.as_dvec3());
        t += 0.5 * mass * v.length_squared();
        u -= mass * g.dot(x.0.as_dvec3());
        p += mass * v;
    }
    for nodes in &meshes {
        counts.meshes += 1;
        counts.mesh_nodes += nodes.len();
        for i in 0..nodes.len() {
            let mass = f64::from(nodes.mass[i]);
            let v = Vec3::from(nodes.v[i]).as_dvec3();
            t += 0.5 * mass * v.length_squared();
            u -= mass * g.dot(Vec3::from(nodes.x[i]).as_dvec3());
            p += mass * v;
        }
    }
    // Rotation: T_rot = ½ ω·L; angular momentum about the origin Σ (x × m v) + L.
    let mut t_rot = 0.0f64;
    let mut l_total = DVec3::ZERO;
    for (x, v, m) in &bodies {
        if !m.is_pinned() {
            l_total += Vec3::from(x.0)
                .as_dvec3()
                .cross(f64::from(m.value()) * Vec3::from(v.0).as_dvec3());
        }
    }
    for (w, l, inertia) in &rotating {
        if !inertia.is_infinite() {
            t_rot += rotational_energy(w.0, l.0);
            l_total += Vec3::from(l.0).as_dvec3();
        }
    }
    counts.rigid_bodies = rotating.iter().count();
    counts.tracers = tracers.iter().count();
    diag.kinetic_energy = t + t_rot;
    diag.rotational_energy = t_rot;
    diag.angular_momentum = l_total.as_vec3();
    diag.gravitational_energy = u;
    diag.linear_momentum = p.as_vec3();
}
