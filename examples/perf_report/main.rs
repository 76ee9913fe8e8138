//! One run, one line per comparison: `name ours_ns reference_ns ratio`.
//!
//! Every figure is the median of at least 11 samples; ours and the reference are sampled
//! alternately in the same run so that machine noise hits both alike. `--quick` keeps the
//! whole report under a minute. Release build:
//!
//! ```text
//! cargo run --release --example perf_report -- --quick
//! cargo run --release --example perf_report -- --only contacts
//! cargo run --release --features bevy --example perf_report -- --only bevy
//! ```

#[cfg(feature = "bevy")]
mod bevy_layer;
mod box3d;
mod contacts;
mod joints;
#[path = "../common/rapier_box3d.rs"]
mod rapier_box3d;
#[path = "../common/rapier_boxes.rs"]
mod rapier_boxes;
#[path = "../common/rapier_joints.rs"]
mod rapier_joints;
mod rigid;
mod scaling;
mod scenario;
mod snapshot;
mod soft;
mod springs;
#[path = "../common/timing.rs"]
mod timing;

use std::hint::black_box;
use std::time::Instant;

use bevy_ecs::prelude::*;
use glam::Vec3A;
use hooke::prelude::*;
use hooke::tools::scenes;
use timing::{Config, compare, line};

/// A world with every plugin and gravity, without the energy pass: the setup of every
/// timed scene.
pub(crate) fn quiet_world(dt: f32, substeps: u32, integrator: Integrator) -> World {
    let mut world =
        scenes::world_with(dt, substeps, integrator, Vec3::new(0.0, -9.81, 0.0)).unwrap();
    // The energy pass reads every body once more per step; the references don't do it.
    world.resource_mut::<DiagnosticsSettings>().energy = false;
    world
}

/// Raw SoA particles: the physical limit of a particle step.
struct RawParticles {
    x: Vec<Vec3A>,
    v: Vec<Vec3A>,
    f: Vec<Vec3A>,
    m: Vec<f32>,
    inv_m: Vec<f32>,
}

impl RawParticles {
    fn from_world(world: &mut World) -> Self {
        let mut q = world.query::<(&Position, &LinearVelocity, &Mass)>();
        let mut r = RawParticles {
            x: vec![],
            v: vec![],
            f: vec![],
            m: vec![],
            inv_m: vec![],
        };
        for (p, v, m) in q.iter(world) {
            r.x.push(p.0);
            r.v.push(v.0);
            r.f.push(Vec3A::ZERO);
            r.m.push(m.value());
            r.inv_m.push(m.inverse());
        }
        r
    }

    /// Clear, gravity, symplectic Euler and the finite check, fused in one pass.
    fn step(&mut self, g: Vec3A, h: f32) -> bool {
        let mut finite = true;
        for i in 0..self.x.len() {
            let f = self.m[i] * g;
            self.f[i] = f;
            let v = self.v[i] + h * (f * self.inv_m[i]);
            self.v[i] = v;
            self.x[i] += h * v;
            finite &= self.x[i].is_finite();
        }
        finite
    }
}

fn particles_vs_raw(cfg: &Config, n: usize) {
    let mut world = quiet_world(1.0 / 60.0, 1, Integrator::SymplecticEuler);
    scenes::particle_cloud(&mut world, n).unwrap();
    let mut raw = RawParticles::from_world(&mut world);
    let g = Vec3A::new(0.0, -9.81, 0.0);
    let (ours, reference) = compare(
        cfg,
        || world.step_physics(),
        || {
            black_box(raw.step(g, 1.0 / 60.0));
        },
    );
    let label = if n >= 1_000_000 {
        format!("{}M", n / 1_000_000)
    } else {
        format!("{}k", n / 1000)
    };
    line(
        &format!("particles_{label}_step_vs_raw"),
        ours,
        reference,
        &format!("{:.2} ns/particle", ours / n as f64),
    );
}

/// Raw cloth arrays and the lecture's spring loop, written out by hand.
struct RawCloth {
    x: Vec<Vec3A>,
    v: Vec<Vec3A>,
    f: Vec<Vec3A>,
    m: Vec<f32>,
    ends: Vec<[u32; 2]>,
    rest: Vec<f32>,
    k: Vec<f32>,
    c: Vec<f32>,
}

impl RawCloth {
    fn force_pass(&mut self, g: Vec3A) {
        for (f, m) in self.f.iter_mut().zip(&self.m) {
            *f = *m * g;
        }
        for (s, &[a, b]) in self.ends.iter().enumerate() {
            let (a, b) = (a as usize, b as usize);
            let d = self.x[b] - self.x[a];
            let l = d.length();
            if l > 1e-15 {
                let dir = d / l;
                let f = (self.k[s] * (l - self.rest[s])
                    + self.c[s] * (self.v[b] - self.v[a]).dot(dir))
                    * dir;
                self.f[a] += f;
                self.f[b] -= f;
            }
        }
    }
}

fn cloth_springs(cfg: &Config, n: usize) {
    let g = Vec3A::new(0.0, -9.81, 0.0);
    // Mesh representation: one Nodes + SpringNetwork component.
    let mut world = quiet_world(1.0 / 60.0, 1, Integrator::SymplecticEuler);
    let cloth = scenes::cloth(&mut world, n).unwrap();
    // Let it sag a little so springs are stretched and moving.
    for _ in 0..3 {
        world.step_physics();
    }
    let (nodes, net) = {
        let e = world.entity(cloth);
        (
            e.get::<Nodes>().unwrap().clone(),
            e.get::<SpringNetwork>().unwrap().clone(),
        )
    };
    let springs = net.len();
    let mut raw = RawCloth {
        x: nodes.positions().to_vec(),
        v: nodes.velocities().to_vec(),
        f: vec![Vec3A::ZERO; nodes.len()],
        m: (0..nodes.len())
            .map(|i| {
                nodes
                    .mass(i)
                    .map_or(0.0, |m| if m.is_finite() { m } else { 0.0 })
            })
            .collect(),
        ends: net.ends().to_vec(),
        rest: vec![0.0; springs],
        k: vec![0.0; springs],
        c: vec![0.0; springs],
    };
    // Same coefficients as the mesh (the builder's structural/shear/bend values).
    for (i, &[a, b]) in raw.ends.clone().iter().enumerate() {
        let d = (raw.x[b as usize] - raw.x[a as usize]).length();
        raw.rest[i] = d;
        raw.k[i] = 8.0;
        raw.c[i] = 0.01;
    }
    let (ours, reference) = compare(
        cfg,
        || world.run_schedule(hooke::core::schedule::ForceSchedule),
        || raw.force_pass(g),
    );
    line(
        &format!("springs_cloth{n}_mesh_force_pass_vs_raw"),
        ours,
        reference,
        &format!(
            "{springs} springs, {:.2} ns/spring, Nodes+SpringNetwork",
            ours / springs as f64
        ),
    );

    // Entity representation: one entity per node and per spring.
    let mut world = quiet_world(1.0 / 60.0, 1, Integrator::SymplecticEuler);
    let ids: Vec<Entity> = (0..nodes.len())
        .map(|i| {
            let x = Vec3::from(nodes.positions()[i]);
            let b = match nodes.mass(i) {
                Some(m) if m.is_finite() => ParticleBundle::new(x, Vec3::ZERO, m).unwrap(),
                _ => ParticleBundle::pinned(x).unwrap(),
            };
            world.spawn(b).id()
        })
        .collect();
    let batch: Vec<Spring> = net
        .ends()
        .iter()
        .map(|&[a, b]| {
            let r = (nodes.positions()[b as usize] - nodes.positions()[a as usize]).length();
            Spring::new(ids[a as usize], ids[b as usize], r, 8.0, 0.01).unwrap()
        })
        .collect();
    world.spawn_batch(batch);
    let (ours, reference) = compare(
        cfg,
        || world.run_schedule(hooke::core::schedule::ForceSchedule),
        || raw.force_pass(g),
    );
    line(
        &format!("springs_cloth{n}_entities_force_pass_vs_raw"),
        ours,
        reference,
        &format!(
            "{:.2} ns/spring, one entity per spring",
            ours / springs as f64
        ),
    );
}

fn empty_world(cfg: &Config) {
    let mut world = World::new();
    world.add_physics(PhysicsPlugins);
    let mut bare_world = World::new();
    let mut bare = Schedule::default();
    bare.add_systems(|| {});
    let (ours, reference) = compare(cfg, || world.step_physics(), || bare.run(&mut bare_world));
    line(
        "empty_world_step_vs_bare_schedule",
        ours,
        reference,
        "goal: ours <= 2000 ns",
    );
    // The fixed cost of a step that has work: one particle, every plugin, default settings.
    let mut one = World::new();
    one.add_physics(PhysicsPlugins);
    one.spawn(ParticleBundle::new(Vec3::ZERO, Vec3::ZERO, 1.0).unwrap());
    let (ours, reference) = compare(cfg, || one.step_physics(), || bare.run(&mut bare_world));
    line(
        "one_particle_world_step_vs_bare_schedule",
        ours,
        reference,
        "fixed cost of a step with work",
    );
    one.resource_mut::<DiagnosticsSettings>().timings = false;
    one.resource_mut::<DiagnosticsSettings>().energy = false;
    let (ours, reference) = compare(cfg, || one.step_physics(), || bare.run(&mut bare_world));
    line(
        "one_particle_world_step_quiet_vs_bare_schedule",
        ours,
        reference,
        "timings and energy off",
    );
}

fn all_plugins_vs_needed(cfg: &Config, n: usize) {
    let mut all = quiet_world(1.0 / 60.0, 1, Integrator::SymplecticEuler);
    scenes::particle_cloud(&mut all, n).unwrap();
    let mut needed = World::new();
    needed.insert_resource(PhysicsTime::new(1.0 / 60.0, 1).unwrap());
    needed.add_physics(hooke::particles::GravityPlugin);
    needed.resource_mut::<DiagnosticsSettings>().energy = false;
    scenes::particle_cloud(&mut needed, n).unwrap();
    let (ours, reference) = compare(cfg, || all.step_physics(), || needed.step_physics());
    line(
        &format!("particles_{}k_all_plugins_vs_needed", n / 1000),
        ours,
        reference,
        "goal <= 1.03",
    );
}

/// The accuracy dial: 1,000 unit oscillators (period 1 s) as one mesh; each setting's largest
/// error against x = cos(2πt) over 10.3 s, sampled every step, and its time per 1/60 s step
/// relative to the default (symplectic Euler, one substep). Errors below about 1e-5 are at the
/// floor set by f32 rounding over 618 steps, not by the integrator.
fn accuracy_dial(cfg: &Config) {
    println!("\n# accuracy dial: 1k oscillators (k = 4π², m = 1), dt = 1/60 s; f32 floor ≈ 1e-5");
    println!(
        "{:<48} {:>14} {:>14} {:>7}  max |error| over 10.3 s",
        "name", "ours_ns", "default_ns", "ratio"
    );
    let build = |integrator: Integrator, substeps: u32| {
        let mut world = scenes::world_with(1.0 / 60.0, substeps, integrator, Vec3::ZERO).unwrap();
        world.resource_mut::<DiagnosticsSettings>().energy = false;
        let mut nodes = Nodes::new();
        let mut net = SpringNetwork::new();
        for i in 0..1000 {
            let anchor = nodes.push_pinned(Vec3::new(0.0, i as f32, 0.0)).unwrap();
            let body = nodes
                .push(Vec3::new(1.0, i as f32, 0.0), Vec3::ZERO, 1.0)
                .unwrap();
            net.push(anchor, body, 0.0, std::f32::consts::TAU.powi(2), 0.0)
                .unwrap();
        }
        let e = world.spawn((nodes, net)).id();
        (world, e)
    };
    let error = |integrator, substeps| {
        let (mut world, e) = build(integrator, substeps);
        let mut worst = 0.0f64;
        for step in 1..=618 {
            world.step_physics();
            let exact = (std::f64::consts::TAU * f64::from(step) / 60.0).cos();
            let err = (f64::from(world.get::<Nodes>(e).unwrap().positions()[1].x) - exact).abs();
            worst = if err.is_finite() {
                worst.max(err)
            } else {
                f64::INFINITY
            };
        }
        worst
    };
    // Timing runs thousands of steps; explicit Euler would blow up and be quarantined, and a
    // quarantined mesh costs nothing. Both sides restore the start state every 60 steps.
    let restoring = |(mut world, e): (World, Entity)| {
        let start = world.get::<Nodes>(e).unwrap().clone();
        let mut count = 0u32;
        move || {
            count += 1;
            if count.is_multiple_of(60) {
                world.get_mut::<Nodes>(e).unwrap().clone_from(&start);
            }
            world.step_physics();
        }
    };
    let mut default = restoring(build(Integrator::SymplecticEuler, 1));
    for integrator in Integrator::ALL {
        for substeps in [1, 2, 4, 8] {
            let mut ours = restoring(build(integrator, substeps));
            let (ours, reference) = compare(cfg, &mut ours, &mut default);
            let err = error(integrator, substeps);
            let shown = if err.is_finite() {
                format!("{err:.2e}")
            } else {
                "diverged".into()
            };
            line(
                &format!("dial_osc1k_{}_x{substeps}", integrator.name()),
                ours,
                reference,
                &format!("error {shown}"),
            );
        }
    }
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let cfg = if quick {
        Config {
            samples: 11,
            sample_time: 0.01,
        }
    } else {
        Config {
            samples: 21,
            sample_time: 0.05,
        }
    };
    let start = Instant::now();
    println!(
        "# hooke perf report ({} mode, release, single thread)",
        if quick { "quick" } else { "full" }
    );
    println!(
        "{:<48} {:>14} {:>14} {:>7}  note",
        "name", "ours_ns", "reference_ns", "ratio"
    );
    // `--only particles|rigid|contacts|box3d|joints|scaling|springs|scenario|snapshot|soft|bevy|dial` runs one group (bevy with `--features bevy`).
    let only = std::env::args()
        .skip_while(|a| a != "--only")
        .nth(1)
        .unwrap_or_default();
    let run = |group: &str| only.is_empty() || only == group;
    if run("particles") {
        particles_vs_raw(&cfg, 100_000);
        particles_vs_raw(&cfg, 1_000_000);
        cloth_springs(&cfg, 316);
        empty_world(&cfg);
        all_plugins_vs_needed(&cfg, 100_000);
    }
    if run("rigid") {
        rigid::rigid_free(&cfg, 1_000);
        rigid::rigid_free(&cfg, 100_000);
    }
    if run("contacts") {
        contacts::contact_scenes(&cfg, quick);
    }
    // `--scene NAME` runs one scene of the box3d or joints group.
    let scene = std::env::args()
        .skip_while(|a| a != "--scene")
        .nth(1)
        .unwrap_or_default();
    if run("box3d") {
        // large_pyramid|many_pyramids|convex_pile|joint_grid|washer
        box3d::box3d_suite(quick, &scene);
    }
    if run("joints") {
        let (runs, steps) = if quick { (3, 60) } else { (5, 300) };
        if scene.is_empty() || scene == "chain" {
            joints::chain_vs_rapier(runs, steps, !quick);
        }
        if scene.is_empty() || scene == "ragdolls" {
            joints::ragdolls_vs_rapier(runs, steps, !quick);
        }
        if !quick && (scene.is_empty() || scene == "joint_grid") {
            joints::joint_grid_at_equal_gap(3);
        }
    }
    if run("scaling") {
        scaling::scaling_lines(&cfg, quick);
    }
    if run("springs") {
        springs::implicit_springs(&cfg);
        springs::rescue_costs(&cfg);
        springs::cloth_vs_rapier(&cfg, if quick { 120 } else { 600 });
    }
    if run("scenario") {
        scenario::scenario_lines(&cfg);
    }
    if run("snapshot") {
        snapshot::snapshot_lines(&cfg);
    }
    if run("soft") {
        soft::soft_lines(&cfg);
        soft::cantilever_vs_rapier(&cfg, if quick { 150 } else { 1500 });
    }
    #[cfg(feature = "bevy")]
    if run("bevy") {
        bevy_layer::bevy_layer(&cfg);
    }
    if run("dial") {
        accuracy_dial(&cfg);
        soft::stretch_dial(&cfg);
        soft::strain_dial(&cfg);
    }
    println!("\n# total {:.1} s", start.elapsed().as_secs_f64());
}
