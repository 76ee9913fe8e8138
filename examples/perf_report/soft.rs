//! Soft-body lines: the elastic force pass against a raw-array loop of the same math, steps
//! per second of a 10,000-tet body explicit and implicit, and what the soft-body plugin costs
//! a world without soft bodies.

use std::hint::black_box;

use bevy_ecs::prelude::*;
use glam::{Mat3, Vec3, Vec3A};
use hooke::prelude::*;
use hooke::soft::{CellSplit, Material, SoftBody, StrainModel, TetMesh};
use hooke::{ImplicitEuler, scenes};

use crate::timing::{Config, compare, line};

/// The same elements as flat arrays: corners, Dm⁻¹, volumes; the same per-element math
/// (F = Ds Dm⁻¹, P from the strain model, f = −V P Dm⁻ᵀ), with energy and volume tallied as
/// the component does (its stats: energy, volume ratio, inverted count).
struct RawElements {
    tets: Vec<[u32; 4]>,
    dm_inv: Vec<Mat3>,
    volume: Vec<f32>,
}

impl RawElements {
    fn new(mesh: &TetMesh) -> Self {
        let p = mesh.points();
        let mut r = RawElements {
            tets: mesh.tets().to_vec(),
            dm_inv: vec![],
            volume: vec![],
        };
        for t in mesh.tets() {
            let c = |i: usize| p[t[i] as usize];
            let dm = Mat3::from_cols(c(1) - c(0), c(2) - c(0), c(3) - c(0));
            r.dm_inv.push(dm.inverse());
            r.volume.push(dm.determinant() / 6.0);
        }
        r
    }

    fn forces(
        &self,
        model: StrainModel,
        lame: hooke::soft::Lame,
        x: &[Vec3A],
        f: &mut [Vec3A],
    ) -> (f32, f32, usize) {
        let (mut energy, mut volume, mut inverted) = (0.0, 0.0, 0);
        for k in 0..self.tets.len() {
            let t = self.tets[k];
            let c = |i: usize| Vec3::from(x[t[i] as usize]);
            let def = Mat3::from_cols(c(1) - c(0), c(2) - c(0), c(3) - c(0)) * self.dm_inv[k];
            let s = model.stress(def, lame);
            let h = -self.volume[k] * s.piola * self.dm_inv[k].transpose();
            let (a, b, d) = (
                Vec3A::from(h.x_axis),
                Vec3A::from(h.y_axis),
                Vec3A::from(h.z_axis),
            );
            f[t[1] as usize] += a;
            f[t[2] as usize] += b;
            f[t[3] as usize] += d;
            f[t[0] as usize] -= a + b + d;
            let j = def.determinant();
            energy += self.volume[k] * s.energy;
            volume += self.volume[k] * j;
            inverted += usize::from(j <= 0.0);
        }
        (energy, volume, inverted)
    }
}

fn body(model: StrainModel) -> (TetMesh, Nodes, SoftBody) {
    // 20 × 10 × 10 cells of five tets: 10,000 tetrahedra.
    let mesh = TetMesh::cuboid(Vec3::new(2.0, 1.0, 1.0), [20, 10, 10], CellSplit::Five).unwrap();
    let material = Material::new(1e6, 0.3, 1000.0).unwrap();
    let (mut nodes, body) = SoftBody::build(&mesh, Vec3::ZERO, material, model).unwrap();
    // A little shear so every element carries stress.
    for (i, p) in mesh.points().iter().enumerate() {
        nodes
            .set_position(i, *p + Vec3::new(0.05 * p.y, 0.0, 0.0))
            .unwrap();
    }
    (mesh, nodes, body)
}

pub fn soft_lines(cfg: &Config) {
    for model in StrainModel::ALL {
        let (mesh, mut nodes, mut sb) = body(model);
        let raw = RawElements::new(&mesh);
        let x: Vec<Vec3A> = nodes.positions().to_vec();
        let mut f = vec![Vec3A::ZERO; x.len()];
        let lame = sb.material().lame();
        let (ours, reference) = compare(
            cfg,
            || {
                black_box(sb.add_elastic_forces(&mut nodes));
            },
            || {
                black_box(raw.forces(model, lame, &x, &mut f));
            },
        );
        line(
            &format!("soft_elastic_pass_10k_{}_vs_raw", model.name()),
            ours,
            reference,
            &format!("{:.1} M tets/s; goal <= 1.2", 10_000.0 / ours * 1e3),
        );
    }
    // Whole steps of a falling 10k-tet body at 60 Hz: implicit with one substep against
    // symplectic Euler at the substeps its stability needs (E = 1e6 here).
    let step_world = |implicit: bool, substeps: u32| {
        let mut w = scenes::world_with(
            1.0 / 60.0,
            substeps,
            Integrator::SymplecticEuler,
            Vec3::new(0.0, -9.81, 0.0),
        )
        .unwrap();
        w.resource_mut::<DiagnosticsSettings>().energy = false;
        let (_, nodes, sb) = body(StrainModel::Corotated);
        let e = if implicit {
            w.spawn((nodes, sb, ImplicitEuler::default())).id()
        } else {
            w.spawn((nodes, sb)).id()
        };
        (w, e)
    };
    let (mut implicit, ie) = step_world(true, 1);
    let (mut explicit, ee) = step_world(false, 40);
    let (ours, reference) = compare(cfg, || implicit.step_physics(), || explicit.step_physics());
    let stats = implicit.get::<SoftBody>(ie).unwrap().stats().implicit;
    let exploded = explicit.get::<Quarantined>(ee).is_some();
    line(
        "soft_step_10k_implicit_x1_vs_symplectic_x40",
        ours,
        reference,
        &format!(
            "implicit {:.2} M tet-steps/s ({} Newton, {} CG in its last substep); explicit {}",
            10_000.0 / ours * 1e3,
            stats.newton_iterations,
            stats.cg_iterations,
            if exploded {
                "quarantined (unstable)"
            } else {
                "stable"
            }
        ),
    );
    // A world without soft bodies: every plugin against every plugin but soft bodies.
    let mut all = crate::quiet_world(1.0 / 60.0, 4, Integrator::SymplecticEuler);
    scenes::particle_cloud(&mut all, 100_000).unwrap();
    let mut without = World::new();
    without.insert_resource(PhysicsTime::new(1.0 / 60.0, 4).unwrap());
    without
        .add_physics(hooke::GravityPlugin)
        .add_physics(hooke::DampingPlugin)
        .add_physics(hooke::VelocityFieldPlugin)
        .add_physics(hooke::SpringPlugin)
        .add_physics(hooke::RigidBodyPlugin)
        .add_physics(hooke::CollisionPlugin)
        .add_physics(hooke::SleepPlugin);
    without.insert_resource(Gravity::new(Vec3::new(0.0, -9.81, 0.0)).unwrap());
    without.resource_mut::<DiagnosticsSettings>().energy = false;
    scenes::particle_cloud(&mut without, 100_000).unwrap();
    let (ours, reference) = compare(cfg, || all.step_physics(), || without.step_physics());
    line(
        "particles_100k_with_vs_without_soft_plugin",
        ours,
        reference,
        "no soft body in the world; goal <= 1.03",
    );
}
