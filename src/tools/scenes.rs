//! Scene builders shared by tests, examples and benchmarks, so that every figure is measured
//! on the same scene that is tested.

use bevy_ecs::prelude::*;
use glam::Vec3;

use crate::cloth::ClothBuilder;
use crate::core::error::Result;
use crate::core::time::PhysicsTime;
use crate::integrator::Integrator;
use crate::particles::{Gravity, ParticleBundle, Tracer, VelocityField};
use crate::plugins::PhysicsPlugins;
use crate::plugins::PhysicsWorldExt;
use crate::springs::{Chain, ChainBuilder, Spring};

/// A world with every plugin, the given step and integrator, and gravity `g`.
///
/// # Errors
/// As [`PhysicsTime::new`] and [`Gravity::new`].
pub fn world_with(dt: f32, substeps: u32, integrator: Integrator, g: Vec3) -> Result<World> {
    let mut world = World::new();
    world.insert_resource(PhysicsTime::new(dt, substeps)?);
    world.add_physics(PhysicsPlugins);
    world.insert_resource(integrator);
    world.insert_resource(Gravity::new(g)?);
    Ok(world)
}

/// A 1-D undamped or damped oscillator: a pinned anchor at the origin and a particle of mass
/// `m` (kg) at (x0, 0, 0) on a zero-length spring of stiffness `k` (N/m), damping `c`
/// (N·s/m). Returns the moving particle. Closed form for c = 0:
/// x(t) = x0 cos(ωt), ω = √(k/m).
///
/// # Errors
/// Constructor errors for bad values.
pub fn oscillator(world: &mut World, m: f32, k: f32, c: f32, x0: f32) -> Result<Entity> {
    let anchor = world.spawn(ParticleBundle::pinned(Vec3::ZERO)?).id();
    let body = world
        .spawn(ParticleBundle::new(Vec3::new(x0, 0.0, 0.0), Vec3::ZERO, m)?)
        .id();
    Spring::new(anchor, body, 0.0, k, c)?.spawn(world)?;
    Ok(body)
}

/// `n` free particles of 1 kg on a jittered cube lattice with small velocities; the same
/// values every call (a fixed integer hash, no RNG state).
///
/// # Errors
/// None in practice; constructor errors are forwarded.
pub fn particle_cloud(world: &mut World, n: usize) -> Result<()> {
    let side = (n as f32).cbrt().ceil() as usize;
    let mut batch = Vec::with_capacity(n);
    for i in 0..n {
        let (a, b, c) = (i % side, (i / side) % side, i / (side * side));
        let x = Vec3::new(a as f32, b as f32 + 10.0, c as f32) * 0.5 + jitter(i) * 0.1;
        batch.push(ParticleBundle::new(x, jitter(i + n), 1.0)?);
    }
    world.spawn_batch(batch);
    Ok(())
}

/// A deterministic value in [−1, 1]³ from an index.
#[must_use]
pub fn jitter(i: usize) -> Vec3 {
    let h = |s: u64| {
        let mut z = (i as u64)
            .wrapping_add(s)
            .wrapping_mul(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
    };
    Vec3::new(h(1), h(2), h(3))
}

/// The perf report's cloth: `n` × `n` nodes 1 cm apart, structural, shear and bend springs
/// (about 6 n² springs).
///
/// # Errors
/// As [`ClothBuilder::build`].
pub fn cloth(world: &mut World, n: usize) -> Result<Entity> {
    ClothBuilder::new(Vec3::new(-0.5, 2.0, -0.5), n, n, 1.0 / n as f32).spawn(world)
}

/// The showcase's entities.
#[derive(Debug, Clone)]
pub struct Showcase {
    /// A rope pinned at one end, starting horizontal so it swings.
    pub rope: Chain,
    /// A hair strand with bending springs.
    pub hair: Chain,
    /// Tracers in a vortex.
    pub tracers: Vec<Entity>,
    /// Free particles thrown upward.
    pub particles: Vec<Entity>,
}

/// The README demo: a swinging rope, a hair strand, tracers in a vortex and thrown particles.
///
/// # Errors
/// Constructor errors (none with these values).
pub fn showcase(world: &mut World) -> Result<Showcase> {
    let rope = ChainBuilder::rope(Vec3::new(-2.0, 3.0, 0.0), Vec3::new(0.0, 3.0, 0.0), 21)
        .stiffness(4000.0)
        .damping(2.0)
        .bending(40.0)
        .spawn(world)?;
    let hair =
        ChainBuilder::hair(Vec3::new(1.0, 3.0, 0.0), Vec3::new(1.8, 2.6, 0.0), 12).spawn(world)?;
    world.spawn(VelocityField::vortex(
        Vec3::new(3.5, 1.5, 0.0),
        Vec3::Z,
        2.0,
    )?);
    let tracers = (0..24)
        .map(|i| {
            let r = 0.2 + 0.05 * i as f32;
            let a = i as f32 * 0.7;
            let x = Vec3::new(3.5 + r * a.cos(), 1.5 + r * a.sin(), 0.0);
            Ok(world
                .spawn((crate::particles::Position::try_new(x)?, Tracer))
                .id())
        })
        .collect::<Result<Vec<_>>>()?;
    let particles = (0..8)
        .map(|i| {
            let v = Vec3::new(1.0 + 0.3 * i as f32, 6.0 + 0.2 * i as f32, 0.0);
            Ok(world
                .spawn(ParticleBundle::new(Vec3::new(-4.0, 0.0, 0.0), v, 0.5)?)
                .id())
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(Showcase {
        rope,
        hair,
        tracers,
        particles,
    })
}

/// Half extents (m) and density (kg/m³) of the tumbling-box scene.
pub const TUMBLING_BOX: (glam::Vec3, f32) = (glam::Vec3::new(0.3, 0.2, 0.1), 500.0);

/// Start position and angular velocity of box `i` of the tumbling-box scene: a 2 m lattice
/// (so no two boxes could touch) with spins up to 6 rad/s about every axis.
#[must_use]
pub fn tumbling_box_start(i: usize, n: usize) -> (Vec3, Vec3) {
    let side = (n as f32).cbrt().ceil() as usize;
    let (a, b, c) = (i % side, (i / side) % side, i / (side * side));
    let x = Vec3::new(a as f32, b as f32 + 50.0, c as f32) * 2.0;
    (x, jitter(i) * 6.0)
}

/// `n` free tumbling boxes ([`TUMBLING_BOX`]), falling under gravity with no contacts.
///
/// # Errors
/// None in practice; constructor errors are forwarded.
pub fn tumbling_boxes(world: &mut World, n: usize) -> Result<()> {
    let (half, density) = TUMBLING_BOX;
    let shape = parry3d::shape::Cuboid::new(half);
    let props = crate::rigid::MassProperties::from_shape(&shape, density)?;
    let mut batch = Vec::with_capacity(n);
    for i in 0..n {
        let (x, omega) = tumbling_box_start(i, n);
        batch.push(
            crate::rigid::RigidBodyBundle::dynamic(props)?
                .at(x)?
                .with_angular_velocity(omega)?,
        );
    }
    world.spawn_batch(batch);
    Ok(())
}

/// A static ground box whose top face is the plane y = 0, 100 m × 100 m ([`BoxSpec::ground`]).
///
/// # Errors
/// None in practice.
pub fn ground(world: &mut World) -> Result<Entity> {
    spawn_box(world, &BoxSpec::ground(), 1000.0)
}

/// Spawns `collider` at `position` and `rotation`: static when `fixed`, otherwise a dynamic
/// body of `density` (kg/m³). Every scene's bodies come through here.
fn spawn_body(
    world: &mut World,
    collider: crate::collision::Collider,
    position: Vec3,
    rotation: glam::Quat,
    fixed: bool,
    density: f32,
) -> Result<Entity> {
    if fixed {
        return Ok(world
            .spawn((
                crate::rigid::RigidBodyBundle::fixed(position, rotation)?,
                collider,
            ))
            .id());
    }
    let props = crate::rigid::MassProperties::from_shape(&**collider.shape(), density)?;
    let body = crate::rigid::RigidBodyBundle::dynamic(props)?
        .at(position)?
        .with_rotation(rotation)?;
    Ok(world.spawn((body, collider)).id())
}

fn spawn_box(world: &mut World, b: &BoxSpec, density: f32) -> Result<Entity> {
    let collider = crate::collision::Collider::cuboid(b.half.x, b.half.y, b.half.z)?;
    spawn_body(world, collider, b.position, b.rotation, b.fixed, density)
}

/// A dynamic box with half extents `half` (m) and density 1000 kg/m³ at `x`.
///
/// # Errors
/// Constructor errors for bad sizes.
pub fn dynamic_box(world: &mut World, half: Vec3, x: Vec3) -> Result<Entity> {
    spawn_box(world, &BoxSpec::dynamic(half, x), 1000.0)
}

/// A dynamic ball of radius `r` (m), density 1000 kg/m³, at `x`.
///
/// # Errors
/// Constructor errors for bad sizes.
pub fn dynamic_ball(world: &mut World, r: f32, x: Vec3) -> Result<Entity> {
    spawn_body(
        world,
        crate::collision::Collider::ball(r)?,
        x,
        glam::Quat::IDENTITY,
        false,
        1000.0,
    )
}

/// One box of a contact scene, so that hooke and a reference engine build the same bodies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoxSpec {
    /// Half extents (m).
    pub half: Vec3,
    /// Centre (m).
    pub position: Vec3,
    /// Orientation.
    pub rotation: glam::Quat,
    /// Static (true) or dynamic with density 1000 kg/m³.
    pub fixed: bool,
}

impl BoxSpec {
    fn dynamic(half: Vec3, position: Vec3) -> Self {
        Self {
            half,
            position,
            rotation: glam::Quat::IDENTITY,
            fixed: false,
        }
    }

    /// The ground of every contact scene: top face at y = 0, 100 m × 100 m.
    #[must_use]
    pub fn ground() -> Self {
        Self {
            half: Vec3::new(50.0, 0.5, 50.0),
            position: Vec3::new(0.0, -0.5, 0.0),
            rotation: glam::Quat::IDENTITY,
            fixed: true,
        }
    }
}

/// Spawns a scene; returns the dynamic boxes in order.
///
/// # Errors
/// Constructor errors for bad sizes.
pub fn spawn_boxes(world: &mut World, specs: &[BoxSpec]) -> Result<Vec<Entity>> {
    spawn_boxes_with_density(world, specs, |_| 1000.0)
}

/// [`spawn_boxes`], the dynamic box of spec `i` of density `density(i)` (kg/m³).
///
/// # Errors
/// Constructor errors for bad sizes or densities.
pub fn spawn_boxes_with_density(
    world: &mut World,
    specs: &[BoxSpec],
    density: impl Fn(usize) -> f32,
) -> Result<Vec<Entity>> {
    let mut out = Vec::new();
    for (i, b) in specs.iter().enumerate() {
        let e = spawn_box(world, b, density(i))?;
        if !b.fixed {
            out.push(e);
        }
    }
    Ok(out)
}

/// Rapier's "boxes" scene: the ground and `n` × `n` columns of `n` unit boxes, columns
/// 1.5 m apart, bottom layer first.
#[must_use]
pub fn box_stack_spec(n: usize) -> Vec<BoxSpec> {
    let mut out = vec![BoxSpec::ground()];
    let offset = (n as f32 - 1.0) * 0.75;
    for layer in 0..n {
        for i in 0..n {
            for k in 0..n {
                let x = Vec3::new(
                    i as f32 * 1.5 - offset,
                    0.5 + layer as f32,
                    k as f32 * 1.5 - offset,
                );
                out.push(BoxSpec::dynamic(Vec3::splat(0.5), x));
            }
        }
    }
    out
}

/// A pyramid of `layers` rows of unit boxes in one plane, on the ground.
#[must_use]
pub fn pyramid_spec(layers: usize) -> Vec<BoxSpec> {
    let mut out = vec![BoxSpec::ground()];
    for row in 0..layers {
        let count = layers - row;
        for i in 0..count {
            let x = (i as f32 - (count as f32 - 1.0) / 2.0) * 1.05;
            out.push(BoxSpec::dynamic(
                Vec3::splat(0.5),
                Vec3::new(x, 0.5 + row as f32, 0.0),
            ));
        }
    }
    out
}

/// `n` unit boxes in one layer 2.5 m up, 1.5 m apart, slightly turned, above the ground.
/// (Turned by up to 0.3 rad a unit box reaches 0.62 m from its centre, so 1.5 m keeps them
/// apart until they land.)
#[must_use]
pub fn falling_boxes_spec(n: usize) -> Vec<BoxSpec> {
    let side = (n as f32).sqrt().ceil() as usize;
    let mut out = vec![BoxSpec::ground()];
    for i in 0..n {
        let (a, b) = (i % side, i / side);
        let x = Vec3::new(
            (a as f32 - side as f32 / 2.0) * 1.5,
            2.5,
            (b as f32 - side as f32 / 2.0) * 1.5,
        );
        out.push(BoxSpec {
            rotation: glam::Quat::from_scaled_axis(jitter(i) * 0.3),
            ..BoxSpec::dynamic(Vec3::splat(0.5), x)
        });
    }
    out
}

/// A heap: `n` unit boxes in columns 1.1 m apart and layers 1.3 m apart (about ∛n of each),
/// each turned by up to 0.3 rad, dropped onto the ground and onto each other.
#[must_use]
pub fn box_pile_spec(n: usize) -> Vec<BoxSpec> {
    let side = (n as f32).cbrt().ceil() as usize;
    let mut out = vec![BoxSpec::ground()];
    for i in 0..n {
        let (a, b, layer) = (i % side, (i / side) % side, i / (side * side));
        let half = side as f32 / 2.0;
        let x = Vec3::new(
            (a as f32 - half) * 1.1,
            1.0 + layer as f32 * 1.3,
            (b as f32 - half) * 1.1,
        );
        out.push(BoxSpec {
            rotation: glam::Quat::from_scaled_axis(jitter(i) * 0.3),
            ..BoxSpec::dynamic(Vec3::splat(0.5), x)
        });
    }
    out
}

/// How many layers deep [`heap_spec`] lays its boxes.
pub const HEAP_LAYERS: usize = 4;

/// A heap of `n` unit boxes whose depth does not grow with `n`: [`HEAP_LAYERS`] layers on a
/// square footprint √(n / 4) boxes wide, 1.1 m apart, tilted up to 0.3 rad, dropped from
/// up to 5 m onto a ground that fits it. Each box settles among about as many neighbours at
/// 1,000 boxes as at 100,000, so the step's cost per box shows how it scales.
#[must_use]
pub fn heap_spec(n: usize) -> Vec<BoxSpec> {
    let side = ((n as f32 / HEAP_LAYERS as f32).sqrt().ceil() as usize).max(1);
    let half = side as f32 * 0.55;
    let mut out = vec![BoxSpec {
        half: Vec3::new(half + 10.0, 0.5, half + 10.0),
        ..BoxSpec::ground()
    }];
    for i in 0..n {
        let (a, b, layer) = (i % side, (i / side) % side, i / (side * side));
        let x = Vec3::new(
            a as f32 * 1.1 - half,
            1.0 + layer as f32 * 1.3,
            b as f32 * 1.1 - half,
        );
        out.push(BoxSpec {
            rotation: glam::Quat::from_scaled_axis(jitter(i) * 0.3),
            ..BoxSpec::dynamic(Vec3::splat(0.5), x)
        });
    }
    out
}

/// [`box_stack_spec`], spawned.
///
/// # Errors
/// As [`spawn_boxes`].
pub fn box_stack(world: &mut World, n: usize) -> Result<Vec<Entity>> {
    spawn_boxes(world, &box_stack_spec(n))
}

/// [`pyramid_spec`], spawned.
///
/// # Errors
/// As [`spawn_boxes`].
pub fn pyramid(world: &mut World, layers: usize) -> Result<Vec<Entity>> {
    check_boxes(layers.checked_mul(layers.saturating_add(1)).map(|n| n / 2))?;
    spawn_boxes(world, &pyramid_spec(layers))
}

/// The most boxes [`box_column`] and [`pyramid`] spawn: 2²⁰. A scenario asking for 10⁹ (or a
/// pyramid of 2³² rows, whose count overflows) aborted on allocation.
pub const MAX_SCENE_BOXES: usize = 1 << 20;

/// Refuses a box count past [`MAX_SCENE_BOXES`] (None: it overflowed) before anything is
/// allocated.
pub(crate) fn check_boxes(count: Option<usize>) -> Result<()> {
    match count {
        Some(n) if n <= MAX_SCENE_BOXES => Ok(()),
        _ => Err(crate::core::error::Error::TooMany {
            what: "boxes in a scene",
            max: MAX_SCENE_BOXES as u64,
            got: count.map_or(u64::MAX, |n| n as u64),
        }),
    }
}

/// [`falling_boxes_spec`], spawned.
///
/// # Errors
/// As [`spawn_boxes`].
pub fn falling_boxes(world: &mut World, n: usize) -> Result<Vec<Entity>> {
    spawn_boxes(world, &falling_boxes_spec(n))
}

/// [`box_pile_spec`], spawned.
///
/// # Errors
/// As [`spawn_boxes`].
pub fn box_pile(world: &mut World, n: usize) -> Result<Vec<Entity>> {
    spawn_boxes(world, &box_pile_spec(n))
}

/// The pile example's scene: a ground, a 20° ramp, and `boxes` boxes and `balls` balls
/// dropped from a lattice above the ramp. Returns (boxes, balls).
///
/// # Errors
/// Constructor errors (none with these values).
pub fn pile_scene(
    world: &mut World,
    boxes: usize,
    balls: usize,
) -> Result<(Vec<Entity>, Vec<Entity>)> {
    ground(world)?;
    let q = glam::Quat::from_rotation_z(20f32.to_radians());
    world.spawn((
        crate::rigid::RigidBodyBundle::fixed(Vec3::new(-3.0, 1.5, 0.0), q)?,
        crate::collision::Collider::cuboid(4.0, 0.2, 2.0)?,
    ));
    let mut out = (Vec::new(), Vec::new());
    for i in 0..boxes + balls {
        let x = Vec3::new(
            -5.5 + (i % 8) as f32 * 0.9,
            5.0 + (i / 8) as f32 * 0.9,
            -1.0 + (i % 3) as f32 * 0.8,
        ) + jitter(i) * 0.1;
        if i % 3 == 2 && out.1.len() < balls || out.0.len() >= boxes {
            out.1.push(dynamic_ball(world, 0.3, x)?);
        } else {
            let e = dynamic_box(world, Vec3::new(0.35, 0.25, 0.3), x)?;
            if let Some(mut r) = world.get_mut::<crate::rigid::Rotation>(e) {
                r.0 = glam::Quat::from_scaled_axis(jitter(i + 7) * 1.0);
            }
            out.0.push(e);
        }
    }
    Ok(out)
}

/// The ground and a column of `n` unit boxes resting on it, bottom first.
#[must_use]
pub fn column_spec(n: usize) -> Vec<BoxSpec> {
    let mut out = vec![BoxSpec::ground()];
    out.extend(
        (0..n).map(|i| BoxSpec::dynamic(Vec3::splat(0.5), Vec3::new(0.0, 0.5 + i as f32, 0.0))),
    );
    out
}

/// [`column_spec`] with every box moved sideways (x and z) by up to `offset` m, seeded by
/// `run`: the same run gives the same column. One straight column standing can be luck;
/// these ask how often (`examples/column_trials.rs`, `tests/it/collision/tall_stacks.rs`).
#[must_use]
pub fn perturbed_column_spec(n: usize, offset: f32, run: usize) -> Vec<BoxSpec> {
    let mut specs = column_spec(n);
    // The first spec is the ground.
    for (i, s) in specs.iter_mut().enumerate().skip(1) {
        let d = jitter(run * (n + 1) + i) * offset;
        s.position.x += d.x;
        s.position.z += d.z;
    }
    specs
}

/// [`column_spec`], spawned; returns the boxes, bottom first.
///
/// # Errors
/// As [`spawn_boxes`].
pub fn box_column(world: &mut World, n: usize) -> Result<Vec<Entity>> {
    check_boxes(Some(n))?;
    spawn_boxes(world, &column_spec(n))
}

/// The squeeze: the ground and three unit boxes stacked, bottom first (the densities are
/// [`squeeze_densities`]'s).
#[must_use]
pub fn squeeze_spec() -> Vec<BoxSpec> {
    column_spec(3)
}

/// Densities (kg/m³) for [`squeeze_spec`], ground first (unused): a light 1 t unit box
/// between two boxes `ratio` times heavier.
#[must_use]
pub fn squeeze_densities(ratio: f32) -> [f32; 4] {
    [0.0, 1000.0 * ratio, 1000.0, 1000.0 * ratio]
}

/// [`squeeze_spec`], spawned: returns the bottom, light and top boxes. A hard case for an
/// iterative contact solver: the light box must pass the top box's whole weight to the
/// bottom one.
///
/// # Errors
/// [`crate::core::error::Error::NotPositive`] or [`crate::core::error::Error::NonFinite`] for a bad `ratio`.
pub fn squeeze(world: &mut World, ratio: f32) -> Result<[Entity; 3]> {
    crate::core::error::positive("mass ratio", ratio)?;
    let rho = squeeze_densities(ratio);
    let boxes = spawn_boxes_with_density(world, &squeeze_spec(), |i| rho[i])?;
    Ok([boxes[0], boxes[1], boxes[2]])
}

/// A soft beam along x from 0 to `length` (m), square `side` (m), meshed `cells` (6 tets a
/// cell), with its nodes at x = 0 pinned: the cantilever of the FEM tests and the accuracy
/// chart.
///
/// # Errors
/// Mesh and material errors for bad sizes.
pub fn pinned_beam(
    length: f32,
    side: f32,
    cells: [usize; 3],
    material: crate::soft::Material,
    model: crate::soft::StrainModel,
) -> Result<(crate::particles::Nodes, crate::soft::SoftBody)> {
    use crate::soft::{CellSplit, SoftBody, TetMesh};
    let mesh = TetMesh::cuboid(Vec3::new(length, side, side), cells, CellSplit::Six)?;
    let (mut nodes, body) =
        SoftBody::build(&mesh, Vec3::new(0.5 * length, 0.0, 0.0), material, model)?;
    for i in 0..nodes.len() {
        if nodes.positions()[i].x.abs() < 1e-5 {
            nodes.pin(i)?;
        }
    }
    Ok((nodes, body))
}

/// A 1 kg particle on a 1 m spring of stiffness `k` (N/m) from a pin at the origin, released
/// from rest level with it (at 90°): a pendulum on a rod as stiff as `k`. At 1e6 N/m the rod's
/// own mode is 1000 rad/s, past the default substep's explicit limit. Returns the bob.
///
/// # Errors
/// As [`Spring::new`] for a bad `k`.
pub fn stiff_rod_pendulum(world: &mut World, k: f32) -> Result<Entity> {
    let pin = world.spawn(ParticleBundle::pinned(Vec3::ZERO)?).id();
    let bob = world
        .spawn(ParticleBundle::new(
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::ZERO,
            1.0,
        )?)
        .id();
    Spring::new(pin, bob, 1.0, k, 0.0)?.spawn(world)?;
    Ok(bob)
}

/// A top of 1 kg (moments 0.02, 0.01, 0.02 kg·m² about its centre; y, the 0.01 one, is its
/// symmetry axis) spinning at `spin` rad/s about that axis, tilted 0.3 rad about z, its tip
/// 0.3 m below its centre held by a pivot spring of stiffness `k` (N/m, rest length 0) to a
/// pin at the origin. At 1e6 N/m the pivot's mode, √(k (1/m + l²/I₁)) ≈ 2300 rad/s, is past
/// the default substep's explicit limit. Returns the top.
///
/// # Errors
/// As [`Spring::new`] for a bad `k`, and a non-finite `spin`.
pub fn top_on_a_pivot(world: &mut World, k: f32, spin: f32) -> Result<Entity> {
    use crate::rigid::{Inertia, MassProperties, RigidBodyBundle};
    let inertia = Inertia::diagonal(0.02, 0.01, 0.02)?;
    let tilt = glam::Quat::from_rotation_z(0.3);
    let pin = world.spawn(ParticleBundle::pinned(Vec3::ZERO)?).id();
    let top = world
        .spawn(
            RigidBodyBundle::dynamic(MassProperties::new(1.0, Vec3::ZERO, inertia)?)?
                .at(tilt * Vec3::new(0.0, 0.3, 0.0))?
                .with_rotation(tilt)?
                .with_angular_velocity(tilt * Vec3::Y * spin)?,
        )
        .id();
    Spring::new(pin, top, 0.0, k, 0.0)?
        .with_anchors(Vec3::ZERO, Vec3::new(0.0, -0.3, 0.0))?
        .spawn(world)?;
    Ok(top)
}

/// The catenary parameter a (m) of a chain of `length` hung between two pins `span` apart
/// at one height: the root of L = 2a sinh(S / 2a), by bisection (the right side falls as a
/// grows). Its sag is a (cosh(S / 2a) − 1), its support tension w a cosh(S / 2a).
#[must_use]
pub fn catenary_parameter(span: f64, length: f64) -> f64 {
    let (mut lo, mut hi) = (1e-3 * span, 1e3 * span);
    for _ in 0..200 {
        let a = 0.5 * (lo + hi);
        if 2.0 * a * (span / (2.0 * a)).sinh() > length {
            lo = a;
        } else {
            hi = a;
        }
    }
    0.5 * (lo + hi)
}

/// The DESIGN.md cantilever: a 1 m beam, 0.1 m square, E = 1e8 Pa, ν = 0 (as Euler–Bernoulli
/// theory assumes), pinned at x = 0, with a 10 N tip load shared by its end nodes and added in
/// every force evaluation. Beam theory gives a tip deflection F L³ / (3 E I) = 4.000 mm.
#[derive(Debug, Clone)]
pub struct Cantilever {
    /// The beam's entity ([`crate::particles::Nodes`] and [`crate::soft::SoftBody`]).
    pub body: Entity,
    /// The end nodes the load is shared by.
    pub tip: Vec<usize>,
}

#[derive(Resource, Clone)]
struct TipLoad(Entity, Vec<usize>, f32);

fn apply_tip_load(load: Res<TipLoad>, mut meshes: Query<&mut crate::particles::Nodes>) {
    let Ok(mut n) = meshes.get_mut(load.0) else {
        return;
    };
    let each = glam::Vec3A::new(0.0, -load.2 / load.1.len() as f32, 0.0);
    for &i in &load.1 {
        let _ = n.add_force(i, each);
    }
}

impl Cantilever {
    /// Spawns the loaded beam, meshed `cells`, with the strain `model` and the implicit
    /// solver's `settings`. Step the world once with a long dt (100 s) for a static solve.
    ///
    /// # Errors
    /// Mesh errors for bad cell counts.
    pub fn spawn(
        world: &mut World,
        cells: [usize; 3],
        model: crate::soft::StrainModel,
        settings: crate::integrator::ImplicitEuler,
    ) -> Result<Self> {
        let material = crate::soft::Material::new(1e8, 0.0, 1000.0)?;
        let (nodes, body) = pinned_beam(1.0, 0.1, cells, material, model)?;
        let tip: Vec<usize> = (0..nodes.len())
            .filter(|&i| (nodes.positions()[i].x - 1.0).abs() < 1e-5)
            .collect();
        let body = world.spawn((nodes, body, settings)).id();
        world.insert_resource(TipLoad(body, tip.clone(), 10.0));
        crate::core::schedule::add_force_systems(world, || {
            apply_tip_load.in_set(crate::core::schedule::ForceSystems::User)
        });
        Ok(Self { body, tip })
    }

    /// The mean downward deflection of the end nodes (m), if the beam is still there.
    #[must_use]
    pub fn deflection(&self, world: &World) -> Option<f32> {
        let n = world.get::<crate::particles::Nodes>(self.body)?;
        let y: f32 = self.tip.iter().map(|&i| n.positions()[i].y).sum();
        Some(-y / self.tip.len() as f32)
    }
}

/// The ground, a stiff rope (25 nodes, k = 2·10⁴ N/m) pinned at (0, 3, 0) and hanging
/// from horizontal, and a 0.6 m crate dropped onto it from 5 m. Returns the rope and the
/// crate.
///
/// # Errors
/// Constructor errors (none with these values).
pub fn rope_with_crate(world: &mut World) -> Result<(Chain, Entity)> {
    ground(world)?;
    let rope = ChainBuilder::rope(Vec3::new(0.0, 3.0, 0.0), Vec3::new(3.0, 3.0, 0.0), 25)
        .stiffness(2e4)
        .spawn(world)?;
    let crate_ = dynamic_box(world, Vec3::splat(0.3), Vec3::new(1.5, 5.0, 0.0))?;
    Ok((rope, crate_))
}

/// The ground, the perf report's `n` × `n` [`cloth`] and a static ball of radius 0.3 m at
/// (0, 1, 0) for it to fall on. Returns the cloth.
///
/// # Errors
/// Constructor errors (none for `n` ≥ 2).
pub fn cloth_on_ball(world: &mut World, n: usize) -> Result<Entity> {
    ground(world)?;
    let cloth = cloth(world, n)?;
    world.spawn((
        crate::rigid::RigidBodyBundle::fixed(Vec3::new(0.0, 1.0, 0.0), glam::Quat::IDENTITY)?,
        crate::collision::Collider::ball(0.3)?,
    ));
    Ok(cloth)
}

/// A 0.4 m jelly cube centred at `x`: 3 × 3 × 3 cells of six tetrahedra, co-rotated strain,
/// E = 200 kPa, ν = 0.3, 1000 kg/m³; on the implicit solver when `implicit`.
///
/// # Errors
/// Constructor errors (none with these values).
pub fn jelly(world: &mut World, x: Vec3, implicit: bool) -> Result<Entity> {
    use crate::soft::{CellSplit, Material, SoftBody, StrainModel, TetMesh};
    let mesh = TetMesh::cuboid(Vec3::splat(0.4), [3, 3, 3], CellSplit::Six)?;
    let material = Material::new(2e5, 0.3, 1000.0)?;
    let body = SoftBody::build(&mesh, x, material, StrainModel::Corotated)?;
    let mut e = world.spawn(body);
    if implicit {
        e.insert(crate::integrator::ImplicitEuler::default());
    }
    Ok(e.id())
}
