//! Soft-body lines: the elastic force pass against a raw-array loop of the same math, steps
//! per second of a 10,000-tet body explicit and implicit, and what the soft-body plugin costs
//! a world without soft bodies.

use std::hint::black_box;

use bevy_ecs::prelude::*;
use glam::{Mat3, Vec3, Vec3A};
use hooke::integrator::ImplicitEuler;
use hooke::prelude::*;
use hooke::soft::{CellSplit, Material, SoftBody, StrainModel, TetMesh};
use hooke::tools::scenes;

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
        let mut w = crate::quiet_world(1.0 / 60.0, substeps, Integrator::SymplecticEuler);
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
        .add_physics(hooke::particles::GravityPlugin)
        .add_physics(hooke::particles::DampingPlugin)
        .add_physics(hooke::particles::VelocityFieldPlugin)
        .add_physics(hooke::springs::SpringPlugin)
        .add_physics(hooke::rigid::RigidBodyPlugin)
        .add_physics(hooke::collision::CollisionPlugin)
        .add_physics(hooke::sleep::SleepPlugin);
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

/// rapier 0.36's own cantilever (`examples/fem_bench.rs`): a 2 m × 0.2 m × 0.2 m bar, E = 1.2e7,
/// ν = 0, 8 kg, fixed at x = 0, under its own weight; Euler–Bernoulli's tip deflection
/// q L⁴ / (8 E I) = 0.0491 m. Both engines mesh `nodes` grid points (five tets per cell, as
/// rapier does), dt = 1/60, one substep; each figure is the mean tip height after `steps` steps (1500 in rapier's bench).
pub fn cantilever_vs_rapier(cfg: &Config, steps: usize) {
    use rapier3d::prelude as rp;
    let (length, side, young) = (2.0f32, 0.2f32, 1.2e7f32);
    let exact = 8.0 * 9.81 / length * length.powi(4) / (8.0 * young * side.powi(4) / 12.0);
    for nodes in [[9usize, 3, 3], [17, 5, 5]] {
        let cells = [nodes[0] - 1, nodes[1] - 1, nodes[2] - 1];
        // hooke
        let mut w = crate::quiet_world(1.0 / 60.0, 1, Integrator::SymplecticEuler);
        let mesh = TetMesh::cuboid(Vec3::new(length, side, side), cells, CellSplit::Five).unwrap();
        let volume = length * side * side;
        let material = Material::new(young, 0.0, 8.0 / volume).unwrap();
        let (mut n, b) = SoftBody::build(
            &mesh,
            Vec3::new(0.5 * length, 0.0, 0.0),
            material,
            StrainModel::Corotated,
        )
        .unwrap();
        let tip: Vec<usize> = (0..n.len())
            .filter(|&i| n.positions()[i].x > length - 1e-4)
            .collect();
        for i in 0..n.len() {
            if n.positions()[i].x < 1e-4 {
                n.pin(i).unwrap();
            }
        }
        let e = w.spawn((n, b, ImplicitEuler::default())).id();
        // rapier
        let mut r = rp::PhysicsWorld::new();
        r.integration_parameters.num_solver_iterations = 1;
        let half = rp::Vector::new(0.5 * length, 0.5 * side, 0.5 * side);
        let builder = rp::SoftBodyBuilder::cuboid(
            rp::Vector::new(0.5 * length, 0.0, 0.0),
            half,
            nodes[0],
            nodes[1],
            nodes[2],
        )
        .cell_model(rp::SoftBodyCellModel::Corotational)
        .material(rp::SoftBodyMaterial {
            young_modulus: young,
            poisson_ratio: 0.0,
            elastic_damping_ratio: 1.0,
            ..Default::default()
        })
        .solver(rp::SoftBodySolver::Fem)
        .mass(8.0)
        .no_surface_collider()
        .can_sleep(false);
        let pinned: Vec<u32> = builder
            .particle_positions()
            .iter()
            .enumerate()
            .filter(|(_, p)| p.x < 1e-4)
            .map(|(i, _)| i as u32)
            .collect();
        let rtip: Vec<usize> = builder
            .particle_positions()
            .iter()
            .enumerate()
            .filter(|(_, p)| p.x > length - 1e-4)
            .map(|(i, _)| i)
            .collect();
        let handle = r.insert_soft_body(builder.pinned_particles(pinned));
        for _ in 0..steps {
            w.step_physics();
            r.step();
        }
        let ours_y = {
            let n = w.get::<Nodes>(e).unwrap();
            tip.iter().map(|&i| n.positions()[i].y).sum::<f32>() / tip.len() as f32
        };
        let theirs_y = {
            let sb = &r.soft_bodies[handle];
            rtip.iter().map(|&i| sb.particle_position(i).y).sum::<f32>() / rtip.len() as f32
        };
        let solve = w.get::<SoftBody>(e).unwrap().stats().implicit;
        let (t_ours, t_theirs) = compare(cfg, || w.step_physics(), || r.step());
        line(
            &format!(
                "cantilever_{}x{}x{}_vs_rapier_fem",
                nodes[0], nodes[1], nodes[2]
            ),
            t_ours,
            t_theirs,
            &format!(
                "{} tets; tip deflection hooke {:.4} m ({:+.1}%; {} Newton, {} CG per step), rapier {:.4} m ({:+.1}%), beam theory {exact:.4} m",
                mesh.tets().len(),
                -ours_y,
                100.0 * (-ours_y / exact - 1.0),
                solve.newton_iterations,
                solve.cg_iterations,
                -theirs_y,
                100.0 * (-theirs_y / exact - 1.0),
            ),
        );
    }
}

/// The stretch case of the dial: a 10,000-tet body stretched uniaxially by 1.1 (ν = 0.3), its
/// sides free. Each model's lateral stretch (where the lateral stress vanishes) and P₁₁/E,
/// against small-strain linear elasticity (lateral 1 − 0.1 ν = 0.970, P₁₁/E = 0.100), and its
/// elastic pass time on the stretched body relative to co-rotated's.
pub fn stretch_dial(cfg: &Config) {
    println!(
        "\n# strain models: uniaxial stretch 1.1, nu = 0.3; linear elasticity: lateral 0.970, P11/E 0.100"
    );
    let material = Material::new(1e6, 0.3, 1000.0).unwrap();
    let lame = material.lame();
    let lateral = |model: StrainModel| {
        let (s, p11) = model.uniaxial(1.1, lame);
        (s, p11 / material.young())
    };
    let stretched = |model: StrainModel| {
        let (mesh, mut nodes, sb) = body(model);
        let (s, _) = lateral(model);
        for (i, p) in mesh.points().iter().enumerate() {
            nodes
                .set_position(i, Vec3::new(1.1 * p.x, s * p.y, s * p.z))
                .unwrap();
        }
        (nodes, sb)
    };
    let (mut rn, mut rb) = stretched(StrainModel::Corotated);
    for model in StrainModel::ALL {
        let (s, p11) = lateral(model);
        let (mut n, mut b) = stretched(model);
        let (t, r) = compare(
            cfg,
            || {
                black_box(b.add_elastic_forces(&mut n));
            },
            || {
                black_box(rb.add_elastic_forces(&mut rn));
            },
        );
        line(
            &format!("dial_stretch_{}", model.name()),
            t,
            r,
            &format!(
                "lateral {s:.5} ({:+.2}%), P11/E {p11:.4} ({:+.1}%) against linear elasticity (time relative to co-rotated)",
                100.0 * (s / 0.97 - 1.0),
                100.0 * (p11 / 0.1 - 1.0)
            ),
        );
    }
}

/// The strain models as a dial: each model's tip deflection on the 1 m cantilever of the
/// tests (E = 1e8, ν = 0, 10 N, static solve on 30 × 6 × 6 cells) against beam theory, and its
/// time per 60 Hz implicit step (default settings) of the same bar under gravity, relative
/// to co-rotated.
pub fn strain_dial(cfg: &Config) {
    println!(
        "\n# strain models: cantilever 1 m × 0.1 m², E = 1e8, 10 N, 6,480 tets; beam theory 4.000 mm"
    );
    let exact = 10.0 / (3.0 * 1e8 * (0.1f32.powi(4) / 12.0));
    let bar = |model: StrainModel, dt: f32, g: Vec3| {
        let mut w = scenes::world_with(dt, 1, Integrator::SymplecticEuler, g).unwrap();
        w.resource_mut::<DiagnosticsSettings>().energy = false;
        let mesh = TetMesh::cuboid(Vec3::new(1.0, 0.1, 0.1), [30, 6, 6], CellSplit::Six).unwrap();
        let material = Material::new(1e8, 0.0, 1000.0).unwrap();
        let (mut n, b) = SoftBody::build(&mesh, Vec3::new(0.5, 0.0, 0.0), material, model).unwrap();
        let tip: Vec<usize> = (0..n.len())
            .filter(|&i| n.positions()[i].x > 1.0 - 1e-5)
            .collect();
        for i in 0..n.len() {
            if n.positions()[i].x < 1e-5 {
                n.pin(i).unwrap();
            }
        }
        // The static solve converged hard; the timed 60 Hz steps at the defaults a game uses.
        let settings = if dt > 1.0 {
            ImplicitEuler {
                tolerance: 1e-6,
                max_newton: 3,
                max_cg: 5000,
                ..ImplicitEuler::default()
            }
        } else {
            ImplicitEuler::default()
        };
        let e = w.spawn((n, b, settings)).id();
        (w, e, tip)
    };
    let timed = |model: StrainModel| {
        let (w, _, _) = bar(model, 1.0 / 60.0, Vec3::new(0.0, -9.81, 0.0));
        w
    };
    for model in StrainModel::ALL {
        // A fresh reference per model: both bars start falling together, so each pair of
        // timed steps meets the same phase of the motion (a settled bar takes fewer Newton
        // steps than a swinging one).
        let mut reference = timed(StrainModel::Corotated);
        // Static: one step of 100 s with the tip load as an external force on the tip nodes.
        let (mut w, e, tip) = bar(model, 100.0, Vec3::ZERO);
        let each = 10.0 / tip.len() as f32;
        w.insert_resource(Tip(e, tip.clone(), each));
        hooke::core::schedule::add_force_systems(&mut w, || {
            tip_load.in_set(hooke::core::schedule::ForceSystems::User)
        });
        w.step_physics();
        let n = w.get::<Nodes>(e).unwrap();
        let d = -tip.iter().map(|&i| n.positions()[i].y).sum::<f32>() / tip.len() as f32;
        let mut ours = timed(model);
        let (t, r) = compare(cfg, || ours.step_physics(), || reference.step_physics());
        line(
            &format!("dial_cantilever_{}", model.name()),
            t,
            r,
            &format!(
                "tip {:.4} mm, error {:+.1}% (time relative to co-rotated)",
                d * 1e3,
                100.0 * (d / exact - 1.0)
            ),
        );
    }
}

#[derive(Resource)]
struct Tip(Entity, Vec<usize>, f32);

fn tip_load(tip: Res<Tip>, mut meshes: Query<&mut Nodes>) {
    if let Ok(mut n) = meshes.get_mut(tip.0) {
        for &i in &tip.1 {
            let _ = n.add_force(i, Vec3A::new(0.0, -tip.2, 0.0));
        }
    }
}
