//! Box3D's benchmark scenes (`shared/benchmarks.c` in erincatto/box3d), rebuilt through
//! hooke's public API so that tests, `examples/perf_report` and `benches/` measure the
//! scenes the field compares engines on, not scenes hooke chose for itself.
//!
//! Box3D runs every scene at 1/60 s with 4 substeps, gravity −10 m/s², friction 0.6,
//! contact stiffness 30 Hz at damping ratio 10 and a push-out of at most 3 m/s (hooke's
//! defaults for the last three), times the steps after one untimed step, and keeps the
//! fastest of 4 runs. Its boxes are hulls (`b3MakeBoxHull`); here they are cuboids, as
//! rapier's users and hooke's would build them (parry's box–box manifold). Sleeping is off
//! where Box3D turns it off (the pyramids) and at its default, on, for the convex pile.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};

use crate::collision::{Collider, ColliderDensity, CollisionLayers, Friction};
use crate::core::error::Result;
use crate::core::time::PhysicsTime;
use crate::joints::SphericalJoint;
use crate::particles::Gravity;
use crate::particles::{LinearVelocity, Position};
use crate::plugins::{PhysicsPlugins, PhysicsWorldExt};
use crate::rigid::{AngularVelocity, RigidBody};
use crate::sleep::SleepSettings;
use crate::tools::scenes::BoxSpec;

/// Box3D's friction on every shape of its benchmark scenes.
pub const FRICTION: f32 = 0.6;

/// One scene of the suite.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scene {
    /// `large_pyramid`: a 2-D pyramid of 1 m cubes, 100 at its base (5,050 cubes, density
    /// 100 kg/m³), on a 800 m × 800 m ground; 200 steps.
    LargePyramid,
    /// `many_pyramids`: 14 × 14 pyramids of base 10 (55 cubes each, 10,780 in all, density
    /// 100 kg/m³); 100 steps.
    ManyPyramids,
    /// `convex_pile`: 8 × 8 × 80 = 5,120 copies of one hull of 32 random points on a
    /// sphere of radius 2 m (density 1000 kg/m³), dropped in a grid that collapses into a
    /// pile; 500 steps.
    ConvexPile,
    /// `joint_grid`: 100 × 100 spheres of radius 0.4 m (density 1 kg/m³) 1 m apart in a
    /// vertical plane, each joined by ball joints to the one above and the one beside it
    /// (19,800 joints), the top row static; the spheres do not collide. 100 steps.
    JointGrid,
    /// `washer`: 20 × 20 × 20 = 8,000 cubes of 0.4 m (density 1000 kg/m³) tumbling in a
    /// kinematic drum of 40 hulls turning at 25°/s about z; 1,000 steps.
    Washer,
}

impl Scene {
    /// The suite, in Box3D's order.
    pub const ALL: [Scene; 5] = [
        Scene::JointGrid,
        Scene::ConvexPile,
        Scene::LargePyramid,
        Scene::ManyPyramids,
        Scene::Washer,
    ];

    /// Box3D's name for it.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Scene::LargePyramid => "large_pyramid",
            Scene::ManyPyramids => "many_pyramids",
            Scene::ConvexPile => "convex_pile",
            Scene::JointGrid => "joint_grid",
            Scene::Washer => "washer",
        }
    }

    /// The steps Box3D times (after one untimed step).
    #[must_use]
    pub fn steps(self) -> usize {
        match self {
            Scene::LargePyramid => 200,
            Scene::ManyPyramids | Scene::JointGrid => 100,
            Scene::ConvexPile => 500,
            Scene::Washer => 1000,
        }
    }

    /// Whether bodies may sleep (Box3D turns sleeping off for the pyramids).
    #[must_use]
    pub fn sleeping(self) -> bool {
        matches!(self, Scene::ConvexPile | Scene::Washer)
    }

    /// The scene's size: Box3D's full size, or its `BENCHMARK_DEBUG` size (a pyramid of base
    /// 20, 3 × 3 pyramids, 10 layers of hulls, 10 × 10 spheres, 8 × 8 × 8 cubes in the drum)
    /// when `small`.
    #[must_use]
    pub fn bodies(self, small: bool) -> SceneBodies {
        match (self, small) {
            (Scene::LargePyramid, false) => SceneBodies::Boxes(large_pyramid(100)),
            (Scene::LargePyramid, true) => SceneBodies::Boxes(large_pyramid(20)),
            (Scene::ManyPyramids, false) => SceneBodies::Boxes(many_pyramids(14, 14, 10)),
            (Scene::ManyPyramids, true) => SceneBodies::Boxes(many_pyramids(3, 3, 10)),
            (Scene::ConvexPile, false) => SceneBodies::Hulls(convex_pile(80)),
            (Scene::ConvexPile, true) => SceneBodies::Hulls(convex_pile(10)),
            (Scene::JointGrid, false) => SceneBodies::JointGrid(JointGridSpec { side: 100 }),
            (Scene::JointGrid, true) => SceneBodies::JointGrid(JointGridSpec { side: 10 }),
            (Scene::Washer, false) => SceneBodies::Washer(washer(20)),
            (Scene::Washer, true) => SceneBodies::Washer(washer(8)),
        }
    }

    /// Density of the dynamic bodies (kg/m³).
    #[must_use]
    pub fn density(self) -> f32 {
        match self {
            Scene::LargePyramid | Scene::ManyPyramids => 100.0,
            Scene::JointGrid => 1.0,
            Scene::ConvexPile | Scene::Washer => 1000.0,
        }
    }
}

/// What a scene is made of, for any engine to build.
#[derive(Debug, Clone, PartialEq)]
pub enum SceneBodies {
    /// Boxes (the first is the static ground).
    Boxes(Vec<BoxSpec>),
    /// A static ground box and copies of one convex hull.
    Hulls(HullPile),
    /// A static ground, a turning kinematic drum and cubes inside it.
    Washer(WasherSpec),
    /// Spheres on ball joints in a square grid.
    JointGrid(JointGridSpec),
}

/// Box3D's joint grid: `side` × `side` spheres, column k at x = k m, row i at y = −i m.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct JointGridSpec {
    /// Spheres along each side.
    pub side: usize,
}

impl JointGridSpec {
    /// The spheres' radius (m).
    pub const RADIUS: f32 = 0.4;

    /// The joints, as (body a, body b, anchor on a, anchor on b) over the spheres indexed
    /// column after column (`k * side + i`), in Box3D's order: to the sphere above, then to
    /// the one in the column before. The top row's joints to each other join two static
    /// bodies; they are kept, as Box3D keeps them.
    #[must_use]
    pub fn joints(&self) -> Vec<(usize, usize, Vec3, Vec3)> {
        let n = self.side;
        let mut out = Vec::with_capacity(2 * n * n);
        for k in 0..n {
            for i in 0..n {
                let index = k * n + i;
                if i > 0 {
                    out.push((
                        index - 1,
                        index,
                        Vec3::new(0.0, -0.5, 0.0),
                        Vec3::new(0.0, 0.5, 0.0),
                    ));
                }
                if k > 0 {
                    out.push((
                        index - n,
                        index,
                        Vec3::new(0.5, 0.0, 0.0),
                        Vec3::new(-0.5, 0.0, 0.0),
                    ));
                }
            }
        }
        out
    }

    /// Sphere `index`'s place (m) and whether it is static (the top row).
    #[must_use]
    pub fn sphere(&self, index: usize) -> (Vec3, bool) {
        let (k, i) = (index / self.side, index % self.side);
        (Vec3::new(k as f32, -(i as f32), 0.0), i == 0)
    }
}

/// The washer: a ground, a drum of hulls and the cubes tumbling in it.
#[derive(Debug, Clone, PartialEq)]
pub struct WasherSpec {
    /// The static ground.
    pub ground: BoxSpec,
    /// The drum's centre at the start (m).
    pub centre: Vec3,
    /// The drum's velocity (m/s): Box3D gives it a slight drift.
    pub velocity: Vec3,
    /// The drum's angular velocity (rad/s).
    pub spin: Vec3,
    /// The drum's parts, each a hull's points in the drum's frame (m).
    pub parts: Vec<Vec<Vec3>>,
    /// The cubes' half side (m).
    pub cube_half: f32,
    /// The cubes' starting centres (m).
    pub cubes: Vec<Vec3>,
}

/// The convex pile: a ground box, one hull's points and where its copies start.
#[derive(Debug, Clone, PartialEq)]
pub struct HullPile {
    /// The static ground.
    pub ground: BoxSpec,
    /// The hull's points (m, in its own frame).
    pub points: Vec<Vec3>,
    /// The copies' starting centres (m).
    pub positions: Vec<Vec3>,
}

fn ground(half_x: f32, half_z: f32) -> BoxSpec {
    BoxSpec {
        half: Vec3::new(half_x, 1.0, half_z),
        position: Vec3::new(0.0, -1.0, 0.0),
        rotation: Quat::IDENTITY,
        fixed: true,
    }
}

fn cube(half: f32, position: Vec3) -> BoxSpec {
    BoxSpec {
        half: Vec3::splat(half),
        position,
        rotation: Quat::IDENTITY,
        fixed: false,
    }
}

/// `CreateLargePyramid`: rows of 1 m cubes in the x–y plane, `base` in the bottom row.
#[must_use]
fn large_pyramid(base: usize) -> Vec<BoxSpec> {
    let h = 0.5f32;
    let mut out = vec![ground(400.0, 400.0)];
    for i in 0..base {
        let y = (2.0 * i as f32 + 1.0) * h;
        for j in i..base {
            let x = (i as f32 + 1.0) * h + 2.0 * (j - i) as f32 * h - h * base as f32;
            out.push(cube(h, Vec3::new(x, y, 0.0)));
        }
    }
    out
}

/// `CreateManyPyramids`: `rows` × `columns` pyramids of `base` cubes of 1 m, spread over a
/// ground sized to hold them.
#[must_use]
fn many_pyramids(rows: usize, columns: usize, base: usize) -> Vec<BoxSpec> {
    let extent = 0.5f32;
    let ground_extent = extent * columns as f32 * (base as f32 + 1.0);
    let mut out = vec![ground(ground_extent, ground_extent)];
    let base_width = 2.0 * extent * base as f32;
    let base_z = -ground_extent + 2.0 * extent;
    let delta_z = 2.0 * (ground_extent - 2.0 * extent) / (rows as f32 - 1.0).max(1.0);
    for i in 0..rows {
        let z = base_z + i as f32 * delta_z;
        for j in 0..columns {
            let centre_x = -ground_extent + j as f32 * (base_width + 2.0 * extent) + 2.0 * extent;
            for r in 0..base {
                let y = (2.0 * r as f32 + 1.0) * extent;
                for c in r..base {
                    let x =
                        (r as f32 + 1.0) * extent + 2.0 * (c - r) as f32 * extent + centre_x - 0.5;
                    out.push(cube(extent, Vec3::new(x, y, z)));
                }
            }
        }
    }
    out
}

/// The linear congruential generator Box3D's convex pile uses (PEEL's `BasicRandom`), so the
/// hull is the same point set: the state times 2147001325 plus 715136305, modulo 2³².
struct PileRandom(u32);

impl PileRandom {
    /// A float in [−0.5, 0.5] from the low 16 bits of the next state.
    fn float(&mut self) -> f32 {
        self.0 = self.0.wrapping_mul(2_147_001_325).wrapping_add(715_136_305);
        (self.0 & 0xffff) as f32 / 65535.0 - 0.5
    }

    /// A unit vector: rejection-sampled inside the sphere of radius 0.5, then normalised.
    fn unit(&mut self) -> Vec3 {
        loop {
            let p = Vec3::new(self.float(), self.float(), self.float());
            if p.length_squared() <= 0.25 {
                return p.normalize();
            }
        }
    }
}

/// `CreateConvexPile`: one hull of 32 random points on a sphere of radius 2 m (seed 42),
/// copied over an 8 × 8 grid 4 m apart, `layers` high, on a 500 m × 500 m ground.
#[must_use]
fn convex_pile(layers: usize) -> HullPile {
    let amplitude = 2.0f32;
    let mut rng = PileRandom(42);
    let points = (0..32).map(|_| amplitude * rng.unit()).collect();
    let scatter = 2.0 * amplitude;
    let mut positions = Vec::new();
    for layer in 0..layers {
        for z in 0..8 {
            for x in 0..8 {
                positions.push(Vec3::new(
                    (x as f32 - 4.0) * scatter,
                    amplitude + 2.0 * amplitude * layer as f32,
                    (z as f32 - 4.0) * scatter,
                ));
            }
        }
    }
    HullPile {
        ground: ground(250.0, 250.0),
        points,
        positions,
    }
}

/// `CreateWasher`: a drum of 36 rim segments between radii 16 and 18 m (each spanning 10°
/// and a tenth of that more on both sides, so they overlap) and 4 paddles between 14 and
/// 16 m every 90°, all 20 m deep along z, centred at (0, 21, 0) and turning at 25°/s about z;
/// `grid`³ cubes of 0.4 m, 0.8 m apart, inside it; a ground 120 m × 120 m, top at y = 0.
#[must_use]
fn washer(grid: usize) -> WasherSpec {
    let (r0, r1, r2) = (14.0f32, 16.0f32, 18.0f32);
    let (back, front) = (Vec3::new(0.0, 0.0, -10.0), Vec3::new(0.0, 0.0, 10.0));
    let angle = std::f32::consts::PI / 18.0;
    let turn = Quat::from_rotation_z(angle);
    let overlap = Quat::from_rotation_z(0.1 * angle);
    let slab = |inner: f32, outer: f32, a: Vec3, b: Vec3| {
        vec![
            back + inner * a,
            back + outer * a,
            back + inner * b,
            back + outer * b,
            front + inner * a,
            front + outer * a,
            front + inner * b,
            front + outer * b,
        ]
    };
    let mut parts = Vec::new();
    let mut u1 = Vec3::X;
    for i in 0..36 {
        let u2 = if i == 35 { Vec3::X } else { turn * u1 };
        parts.push(slab(r1, r2, overlap.inverse() * u1, overlap * u2));
        if i % 9 == 0 {
            parts.push(slab(r0, r1, u1, u2));
        }
        u1 = u2;
    }
    let a = 0.2f32;
    let start = -2.0 * a * grid as f32;
    let mut cubes = Vec::with_capacity(grid * grid * grid);
    for i in 0..grid {
        for j in 0..grid {
            for k in 0..grid {
                cubes.push(Vec3::new(
                    start + 4.0 * a * i as f32,
                    start + 21.0 + 4.0 * a * j as f32,
                    start + 4.0 * a * k as f32,
                ));
            }
        }
    }
    WasherSpec {
        ground: ground(60.0, 60.0),
        centre: Vec3::new(0.0, 21.0, 0.0),
        velocity: Vec3::new(0.001, -0.002, 0.0),
        spin: Vec3::new(0.0, 0.0, 25.0f32.to_radians()),
        parts,
        cube_half: a,
        cubes,
    }
}

/// A world set as Box3D's benchmark sets its own, at hooke's defaults otherwise:
/// [`PhysicsPlugins`], 1/60 s with 4 substeps, gravity −10 m/s², sleeping as the scene says.
///
/// # Errors
/// Never for the suite's constants; as [`PhysicsTime::new`] otherwise.
pub fn world(scene: Scene) -> Result<World> {
    let mut world = World::new();
    world.insert_resource(PhysicsTime::new(1.0 / 60.0, 4)?);
    world.add_physics(PhysicsPlugins);
    world.insert_resource(Gravity::new(Vec3::new(0.0, -10.0, 0.0))?);
    world.resource_mut::<SleepSettings>().enabled = scene.sleeping();
    Ok(world)
}

/// Spawns `bodies` the way a game would (`RigidBody`, `Collider`, `Position`, a density
/// and Box3D's friction on each); returns the dynamic bodies in order.
///
/// # Errors
/// [`crate::core::error::Error::TooMany`] past [`crate::tools::scenes::MAX_SCENE_BOXES`]; constructor errors for
/// a degenerate hull.
pub fn spawn(world: &mut World, bodies: &SceneBodies, density: f32) -> Result<Vec<Entity>> {
    let mut out = Vec::new();
    let mut put = |world: &mut World, collider: Collider, at: Vec3, fixed: bool| {
        let kind = if fixed {
            RigidBody::Static
        } else {
            RigidBody::Dynamic
        };
        let e = world
            .spawn((
                kind,
                collider,
                Position::from(at),
                ColliderDensity(density),
                Friction(FRICTION),
            ))
            .id();
        if !fixed {
            out.push(e);
        }
        e
    };
    match bodies {
        SceneBodies::Boxes(specs) => {
            crate::tools::scenes::check_boxes(Some(specs.len()))?;
            for b in specs {
                put(world, cuboid(b)?, b.position, b.fixed);
            }
        }
        SceneBodies::Hulls(pile) => {
            crate::tools::scenes::check_boxes(Some(pile.positions.len()))?;
            put(world, cuboid(&pile.ground)?, pile.ground.position, true);
            let hull = Collider::convex_hull(&pile.points)?;
            for &at in &pile.positions {
                put(world, hull.clone(), at, false);
            }
        }
        SceneBodies::JointGrid(grid) => {
            crate::tools::scenes::check_boxes(Some(grid.side * grid.side))?;
            let ball = Collider::ball(JointGridSpec::RADIUS)?;
            let spheres: Vec<Entity> = (0..grid.side * grid.side)
                .map(|index| {
                    let (at, fixed) = grid.sphere(index);
                    let e = put(world, ball.clone(), at, fixed);
                    // Box3D's filter: category 2, colliding with everything but category 2.
                    world.entity_mut(e).insert(CollisionLayers {
                        memberships: 2,
                        filters: !2,
                    });
                    e
                })
                .collect();
            for (a, b, anchor_a, anchor_b) in grid.joints() {
                world.spawn(
                    SphericalJoint::new(spheres[a], spheres[b]).with_anchors(anchor_a, anchor_b),
                );
            }
        }
        SceneBodies::Washer(washer) => {
            crate::tools::scenes::check_boxes(Some(washer.cubes.len()))?;
            put(world, cuboid(&washer.ground)?, washer.ground.position, true);
            let parts = washer
                .parts
                .iter()
                .map(|p| Ok((Vec3::ZERO, Quat::IDENTITY, Collider::convex_hull(p)?)))
                .collect::<Result<Vec<_>>>()?;
            world.spawn((
                RigidBody::Kinematic,
                Collider::compound(parts)?,
                Position::from(washer.centre),
                LinearVelocity::from(washer.velocity),
                AngularVelocity::from(washer.spin),
                Friction(FRICTION),
            ));
            let h = washer.cube_half;
            let cube = Collider::cuboid(h, h, h)?;
            for &at in &washer.cubes {
                put(world, cube.clone(), at, false);
            }
        }
    }
    Ok(out)
}

/// The collider of a box spec (its orientation is the body's).
fn cuboid(b: &BoxSpec) -> Result<Collider> {
    Collider::cuboid(b.half.x, b.half.y, b.half.z)
}

/// A world holding `scene` at its full size (or Box3D's debug size when `small`), ready for
/// its untimed first step; returns it and the dynamic bodies.
///
/// # Errors
/// As [`world`] and [`spawn`].
pub fn build(scene: Scene, small: bool) -> Result<(World, Vec<Entity>)> {
    let mut w = world(scene)?;
    let bodies = spawn(&mut w, &scene.bodies(small), scene.density())?;
    Ok((w, bodies))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_suite_has_box3ds_body_counts() {
        let count = |s: Scene| match s.bodies(false) {
            SceneBodies::Boxes(b) => b.len() - 1,
            SceneBodies::Hulls(h) => h.positions.len(),
            SceneBodies::Washer(w) => w.cubes.len(),
            SceneBodies::JointGrid(g) => g.side * g.side,
        };
        assert_eq!(count(Scene::LargePyramid), 5050);
        assert_eq!(count(Scene::ManyPyramids), 10_780);
        assert_eq!(count(Scene::ConvexPile), 5120);
        assert_eq!(count(Scene::Washer), 8000);
        assert_eq!(count(Scene::JointGrid), 10_000);
        assert_eq!(JointGridSpec { side: 100 }.joints().len(), 19_800);
    }

    #[test]
    fn the_washer_drum_closes_and_holds_its_cubes() {
        let w = washer(20);
        assert_eq!(w.parts.len(), 40);
        // The rim's segments overlap: each starts before the last one ended.
        let angle = |p: &Vec3| p.y.atan2(p.x);
        let ends: Vec<(f32, f32)> = w
            .parts
            .iter()
            .filter(|p| (p[1].truncate().length() - 18.0).abs() < 1e-3)
            .map(|p| (angle(&p[0]), angle(&p[2])))
            .collect();
        assert_eq!(ends.len(), 36);
        for pair in ends.windows(2) {
            let gap = (pair[1].0 - pair[0].1 + std::f32::consts::PI)
                .rem_euclid(std::f32::consts::TAU)
                - std::f32::consts::PI;
            assert!(gap < 0.0, "{pair:?}");
        }
        // Every cube starts inside the paddles' radius and the drum's depth.
        for c in &w.cubes {
            let r = (c.truncate() - w.centre.truncate()).length() + w.cube_half * 2f32.sqrt();
            assert!(r < 14.0 && c.z.abs() + w.cube_half < 10.0, "{c}");
        }
    }

    #[test]
    fn the_pile_hull_points_lie_on_the_sphere() {
        let pile = convex_pile(1);
        assert_eq!(pile.points.len(), 32);
        for p in &pile.points {
            assert!((p.length() - 2.0).abs() < 1e-5);
        }
        // Deterministic: the same points each time.
        assert_eq!(pile.points, convex_pile(1).points);
    }
}
