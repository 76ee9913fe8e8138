//! Spring meshes under backward Euler (one substep at 60 Hz) against symplectic Euler at the
//! substeps their stability needs: the price of stability, both ways.

use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::cloth::ClothBuilder;
use hooke::integrator::ImplicitEuler;
use hooke::integrator::ImplicitState;
use hooke::prelude::*;

use crate::timing::{Config, compare, line};

fn world(substeps: u32) -> World {
    let mut w = crate::quiet_world(1.0 / 60.0, substeps, Integrator::SymplecticEuler);
    w.resource_mut::<hooke::sleep::SleepSettings>().enabled = false;
    w
}

/// `nodes` and `springs` of a mesh, stepped implicitly at 60 Hz × 1 and explicitly at the
/// substeps its limit asks for, each after 60 warm-up steps.
fn pair(cfg: &Config, name: &str, mesh: impl Fn() -> (Nodes, SpringNetwork)) {
    let (nodes, net) = mesh();
    let limit = net.critical_step(&nodes);
    let needed = ((1.0 / 60.0) / (0.9 * limit)).ceil() as u32;
    let springs = net.len();
    let mut implicit = world(1);
    let e = implicit.spawn((nodes, net, ImplicitEuler::default())).id();
    let (nodes, net) = mesh();
    let mut explicit = world(needed);
    explicit.spawn((nodes, net));
    for _ in 0..60 {
        implicit.step_physics();
        explicit.step_physics();
    }
    let (ours, reference) = compare(cfg, || implicit.step_physics(), || explicit.step_physics());
    let r = implicit.get::<ImplicitState>(e).unwrap().last_solve();
    line(
        name,
        ours,
        reference,
        &format!(
            "{springs} springs; implicit x1 ({} Newton, {} CG) vs symplectic x{needed} (its limit {limit:.1e} s)",
            r.newton_iterations, r.cg_iterations
        ),
    );
}

pub fn implicit_springs(cfg: &Config) {
    for n in [32usize, 64, 128] {
        pair(
            cfg,
            &format!("springs_cloth{n}_implicit_x1_vs_symplectic_needed"),
            || {
                ClothBuilder::new(Vec3::new(0.0, 2.0, 0.0), n, n, 0.03)
                    .stiffness(5e3, 1e3, 1e2)
                    .build()
                    .unwrap()
            },
        );
    }
    pair(
        cfg,
        "springs_rope100_implicit_x1_vs_symplectic_needed",
        || {
            // 100 links of 1 cm, 10 g nodes, k = 1e4 N/m: stretches 1 % under its weight.
            let mut nodes = Nodes::new();
            nodes.push_pinned(Vec3::new(0.0, 2.0, 0.0)).unwrap();
            for i in 1..=100 {
                nodes
                    .push(Vec3::new(0.01 * i as f32, 2.0, 0.0), Vec3::ZERO, 0.01)
                    .unwrap();
            }
            let mut net = SpringNetwork::new();
            for i in 0..100 {
                net.push(i, i + 1, 0.01, 1e4, 0.1).unwrap();
            }
            (nodes, net)
        },
    );
}

/// Rapier 0.36's cloth (`SoftBodyBuilder::cloth`, constraint solver, its defaults: 60 Hz, 4
/// substeps) and hooke's on the same grid: 30 × 30 particles 0.1 m apart, 0.02 kg each,
/// hung by two corners. Each one's largest stretch of a grid edge after `steps` steps is
/// printed beside the time ratio.
pub fn cloth_vs_rapier(cfg: &Config, steps: usize) {
    use rapier3d::prelude as rp;
    let (n, s, m) = (30usize, 0.1f32, 0.02f32);
    let mut r = rp::PhysicsWorld::new();
    let builder = rp::SoftBodyBuilder::cloth(
        rp::Vector::new(0.0, 3.0, 0.0),
        rp::Vector::new(s, 0.0, 0.0),
        rp::Vector::new(0.0, 0.0, s),
        n,
        n,
    )
    .pinned_particles([0, (n - 1) as u32])
    .softness(rp::SpringCoefficients::new(100.0, 1.0))
    .can_sleep(false)
    .particle_mass(m);
    let handle = r.insert_soft_body(builder);
    for _ in 0..steps {
        r.step();
    }
    let theirs = {
        let sb = &r.soft_bodies[handle];
        sb.edges()
            .iter()
            .filter(|e| (e.rest_length - s).abs() < 1e-4)
            .map(|e| {
                let [a, b] = e.vertices.map(|i| sb.particle_position(i as usize));
                (b - a).length() / e.rest_length - 1.0
            })
            .fold(0.0f32, f32::max)
    };
    // hooke on the same grid: explicit at the substeps its springs need (None), with and
    // without strain limiting, and implicit at one substep.
    for (name, substeps, k, limit) in [
        (
            "springs_cloth30_symplectic_k400_vs_rapier",
            None,
            400.0f32,
            None,
        ),
        (
            "springs_cloth30_symplectic_k400_limit10_vs_rapier",
            None,
            400.0,
            Some(0.1),
        ),
        (
            "springs_cloth30_symplectic_k3000_vs_rapier",
            None,
            3000.0,
            None,
        ),
        (
            "springs_cloth30_symplectic_k6000_vs_rapier",
            None,
            6000.0,
            None,
        ),
        (
            "springs_cloth30_implicit_x1_k3000_vs_rapier",
            Some(1u32),
            3000.0,
            None,
        ),
    ] {
        let (nodes, net, cloth) = ClothBuilder::new(Vec3::new(0.0, 3.0, 0.0), n, n, s)
            .node_mass(m)
            .stiffness(k, k / 4.0, k / 40.0)
            .damping(0.05)
            .build_cloth()
            .unwrap();
        let implicit = substeps.is_some();
        let substeps = substeps
            .unwrap_or_else(|| ((1.0 / 60.0) / (0.9 * net.critical_step(&nodes))).ceil() as u32);
        let mut w = world(substeps);
        let cloth = cloth.with_strain_limit(limit).unwrap();
        let e = w.spawn((nodes, net, cloth)).id();
        if implicit {
            w.entity_mut(e).insert(ImplicitEuler::default());
        }
        for _ in 0..steps {
            w.step_physics();
        }
        let ours = {
            let (nodes, net, cloth) = (
                w.get::<Nodes>(e).unwrap(),
                w.get::<SpringNetwork>(e).unwrap(),
                w.get::<hooke::cloth::Cloth>(e).unwrap(),
            );
            cloth.max_strain(nodes, net)
        };
        let (t_ours, t_theirs) = compare(cfg, || w.step_physics(), || r.step());
        line(
            name,
            t_ours,
            t_theirs,
            &format!(
                "largest grid-edge stretch after {:.0} s: hooke {:.2} % (k = {k} N/m, x{substeps}), rapier {:.2} % (x4)",
                steps as f32 / 60.0,
                100.0 * ours,
                100.0 * theirs
            ),
        );
    }
}

/// One case of the stability policy's price: `spawn` builds the scene; it runs at the
/// defaults (60 Hz × 4) under `policy` against explicit symplectic Euler at the substeps the
/// policy's warning says the scene needs (`StabilityPolicy::Warn`), each after 30 warm-up
/// steps.
fn rescue_case(
    cfg: &Config,
    name: &str,
    policy: hooke::integrator::StabilityPolicy,
    spawn: impl Fn(&mut World),
) {
    use hooke::integrator::StabilityPolicy;
    let mut rescued = world(4);
    rescued.insert_resource(policy);
    spawn(&mut rescued);
    rescued.step_physics();
    let (needed, chosen) = {
        let m =
            rescued.resource::<bevy_ecs::message::Messages<hooke::integrator::StabilityWarning>>();
        let told: Vec<_> = m.get_cursor().read(m).cloned().collect();
        let needed = told.iter().map(|w| w.substeps_needed).max().unwrap_or(4);
        let chosen = match told.first().and_then(|w| w.rescue) {
            Some(hooke::integrator::Rescue::LocalSubsteps(n)) => format!("{n} local substeps"),
            Some(r) => r.name().to_string(),
            None => "nothing".into(),
        };
        (needed, chosen)
    };
    let mut explicit = world(needed);
    explicit.insert_resource(StabilityPolicy::Warn);
    spawn(&mut explicit);
    for _ in 0..30 {
        rescued.step_physics();
        explicit.step_physics();
    }
    let (ours, reference) = compare(cfg, || rescued.step_physics(), || explicit.step_physics());
    line(
        name,
        ours,
        reference,
        &format!(
            "defaults under {policy:?} ({chosen} past the limit) vs symplectic x{needed} (the substeps it needs)"
        ),
    );
}

/// The stiff rope of the tests: 20 beads of 0.1 kg, its top segment stretched 0.1 % by the
/// weight below (k = 3.7e5 N/m; 36 substeps at 60 Hz keep it explicit).
fn stiff_rope20(w: &mut World) {
    hooke::springs::ChainBuilder::rope(Vec3::new(0.0, 2.0, 0.0), Vec3::new(1.0, 2.0, 0.0), 20)
        .stiffness(20.0 * 0.1 * 9.81 / (1e-3 / 19.0))
        .spawn(w)
        .unwrap();
}

/// A soft bar of E = 1e6 Pa, 1 m long, 480 tets, hanging from pins.
fn soft_bar480(w: &mut World) {
    use hooke::soft::{CellSplit, Material, SoftBody, StrainModel, TetMesh};
    let mesh = TetMesh::cuboid(Vec3::new(0.1, 1.0, 0.1), [2, 20, 2], CellSplit::Six).unwrap();
    let material = Material::new(1e6, 0.3, 1000.0).unwrap();
    let (mut nodes, body) = SoftBody::build(
        &mesh,
        Vec3::new(0.0, -0.5, 0.0),
        material,
        StrainModel::Corotated,
    )
    .unwrap();
    for i in 0..nodes.len() {
        if nodes.positions()[i].y.abs() < 1e-5 {
            nodes.pin(i).unwrap();
        }
    }
    w.spawn((nodes, body));
}

/// What the stability policy's rescue costs against explicit integration at the substeps
/// that would keep each case explicit: the stiff-rod pendulum and the stiff rope of the
/// tests, and a soft bar of E = 1e6 Pa (480 tets); under the default policy (its own
/// choice), BDF2 and backward Euler. Then where local substeps stop being cheaper than BDF2:
/// the rope stepped n times per substep on its own against the rope under BDF2.
pub fn rescue_costs(cfg: &Config) {
    use hooke::integrator::{ImplicitScheme, StabilityPolicy};
    for policy in [
        StabilityPolicy::Automatic,
        StabilityPolicy::SwitchToImplicit(ImplicitScheme::Bdf2),
        StabilityPolicy::SwitchToImplicit(ImplicitScheme::BackwardEuler),
    ] {
        let tag = match policy {
            StabilityPolicy::SwitchToImplicit(s) => s.name(),
            _ => "automatic",
        };
        rescue_case(
            cfg,
            &format!("rescue_pendulum_{tag}_vs_symplectic_needed"),
            policy,
            |w| {
                hooke::tools::scenes::stiff_rod_pendulum(w, 1e6).unwrap();
            },
        );
        rescue_case(
            cfg,
            &format!("rescue_rope20_{tag}_vs_symplectic_needed"),
            policy,
            stiff_rope20,
        );
        rescue_case(
            cfg,
            &format!("rescue_softbar480_{tag}_vs_symplectic_needed"),
            policy,
            soft_bar480,
        );
    }
    local_vs_bdf2(cfg, "softbar480", &[12, 16, 24, 32], soft_bar480, || {
        hooke::soft::stability::LOCAL_SUBSTEPS_CHEAPER_UP_TO
    });
    local_vs_bdf2(cfg, "rope20", &[9, 16, 32, 64], stiff_rope20, || {
        hooke::springs::stability::LOCAL_SUBSTEPS_CHEAPER_UP_TO
    });
}

/// A scene's systems (its meshes and springs) stepped n times per substep on their own (each n of `counts`) against
/// the same scene solved by BDF2, at the defaults' 60 Hz × 4.
fn local_vs_bdf2(
    cfg: &Config,
    tag: &str,
    counts: &[u32],
    spawn: impl Fn(&mut World),
    crossover: impl Fn() -> u32,
) {
    use hooke::integrator::{ImplicitScheme, LocalSubsteps, StabilityPolicy};
    for &n in counts {
        let mut local = world(4);
        local.insert_resource(StabilityPolicy::Warn);
        spawn(&mut local);
        let systems: Vec<_> = local
            .query_filtered::<Entity, Or<(With<Nodes>, With<hooke::springs::Spring>)>>()
            .iter(&local)
            .collect();
        for e in systems {
            local
                .entity_mut(e)
                .insert(LocalSubsteps::try_new(n).unwrap());
        }
        let mut bdf2 = world(4);
        bdf2.insert_resource(StabilityPolicy::SwitchToImplicit(ImplicitScheme::Bdf2));
        spawn(&mut bdf2);
        for _ in 0..30 {
            local.step_physics();
            bdf2.step_physics();
        }
        let (ours, reference) = compare(cfg, || local.step_physics(), || bdf2.step_physics());
        line(
            &format!("local_substeps_{n}_vs_bdf2_{tag}"),
            ours,
            reference,
            &format!(
                "stepped {n} times per substep on its own vs solved by BDF2 (the automatic policy's crossover is {})",
                crossover()
            ),
        );
    }
}
