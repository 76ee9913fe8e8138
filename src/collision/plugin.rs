//! Collision systems: bounding boxes, broad phase, narrow phase, contact solver.

use bevy_ecs::prelude::*;
use glam::{Mat3A, Quat, Vec3, Vec3A};
use parry3d::math::Pose;
use parry3d::query::{DefaultQueryDispatcher, PersistentQueryDispatcher};

use super::broad::{BroadPhase, Entry};
use super::exchange::{Live, SolvedBody, gather, scatter};
use super::fetch::Wanted;
use super::narrow::{ContactImpulse, Contacts, PairState, Recycle, choose_points};
use super::solver::{ContactSolver, FIXED, ManifoldConstraint, PointInput, Softness, SolverBody};
use super::{
    Collider, ColliderAabb, CollisionLayers, ContactEnded, ContactSettings, ContactStarted,
    Friction, Restitution, RestitutionThreshold, Sensor,
};
use crate::WorldPlugin;
use crate::integrator::ConstraintsActive;
use crate::particles::{LinearVelocity, Mass, Position};
use crate::rest::Sleeping;
use crate::rigid::{AngularVelocity, CenterOfMass, Inertia, Rotation};
use crate::schedule::{
    CollisionSystems, PhysicsSchedule, StepSystems, SubstepSchedule, add_systems,
};
use crate::time::{PhysicsTime, SubstepTime};

/// Colliders, contacts and the contact solver. Every system runs only while a collider
/// exists; the solver only while some contact does.
#[derive(Debug, Default, Clone, Copy)]
pub struct CollisionPlugin;

impl WorldPlugin for CollisionPlugin {
    fn build(&self, world: &mut World) {
        world.init_resource::<ContactSettings>();
        world.init_resource::<super::ColliderChanges>();
        world.init_resource::<BroadPhase>();
        world.init_resource::<Contacts>();
        world.init_resource::<ContactSolver>();
        world.init_resource::<bevy_ecs::message::Messages<ContactStarted>>();
        world.init_resource::<bevy_ecs::message::Messages<ContactEnded>>();
        // Impulses from mesh nodes (soft bodies, cloth) reach their bodies at the start of the
        // next substep, before the bodies' own integrators.
        add_systems(
            world,
            crate::schedule::SubstepSchedule,
            super::coupling::apply_node_impulses
                .run_if(any_with_component::<super::coupling::NodeImpulse>)
                .in_set(crate::schedule::StepSystems::AccumulateTorque),
        );
        world.add_observer(super::broad::on_body_inserted);
        world.add_observer(super::broad::on_body_removed);
        world.add_observer(super::attach::on_body_inserted);
        world.add_observer(super::attach::on_child_of_discarded);
        world.add_observer(super::attach::on_child_of_inserted);
        add_systems(
            world,
            PhysicsSchedule,
            super::attach::place_attached_colliders
                .run_if(any_with_component::<super::ColliderOf>)
                .in_set(crate::schedule::FinishSystems::Writeback),
        );
        add_systems(
            world,
            PhysicsSchedule,
            (
                (
                    clear_collider_changes,
                    update_moving_aabbs,
                    update_fixed_aabbs.run_if(fixed_dirty),
                    run_broad_phase,
                    update_contacts,
                    trigger_contact_events
                        .run_if(any_with_component::<super::CollisionEventsEnabled>),
                )
                    .chain()
                    .in_set(CollisionSystems::Detect),
                prepare_contacts.in_set(CollisionSystems::Constraints),
            )
                .run_if(any_with_component::<Collider>.or_else(has_contacts)),
        );
        add_systems(
            world,
            SubstepSchedule,
            (
                solve_contacts
                    .run_if(contacts_active)
                    .in_set(StepSystems::SolveConstraints),
                relax_contacts
                    .run_if(contacts_active)
                    .in_set(crate::schedule::RelaxSystems::Rigid),
            ),
        );
    }
}

/// Empties [`super::ColliderChanges`] once the step's inputs have read it (the sleep plugin
/// wakes the islands that touched a changed collider; their pairs then end through the
/// narrow phase like any other, with their messages).
fn clear_collider_changes(mut changes: ResMut<super::ColliderChanges>) {
    if !changes.0.is_empty() {
        changes.0.clear();
    }
}

fn contacts_active(solver: Res<ContactSolver>) -> bool {
    !solver.manifolds.is_empty()
}

/// Contacts or constraints are left from a step that had colliders: the collision systems
/// run once more after the last collider goes, so that its pairs end (with their events)
/// and the solver drops their constraints.
fn has_contacts(solver: Res<ContactSolver>, contacts: Res<Contacts>) -> bool {
    !solver.manifolds.is_empty() || !contacts.pairs.is_empty()
}

/// The second part's pose in the first part's frame, from the second shape's pose in the
/// first's.
#[inline]
fn part_pose12(m: &super::narrow::Manifold, pos12: &Pose) -> Pose {
    match (m.subshape_pos1(), m.subshape_pos2()) {
        (None, None) => *pos12,
        (p1, p2) => {
            let p1 = p1.copied().unwrap_or_default();
            let p2 = p2.copied().unwrap_or_default();
            p1.inverse() * *pos12 * p2
        }
    }
}

/// The world pose of a manifold's part: the shape's pose, then the part's pose in it.
#[inline]
fn part_pose(shape: &Pose, part: Option<&Pose>) -> Pose {
    part.map_or(*shape, |p| *shape * *p)
}

/// The pose of a collider's shape frame: origin x − R c.
pub(crate) fn shape_pose(x: Vec3A, q: Quat, com: Option<&CenterOfMass>) -> Pose {
    let c = com.map_or(Vec3::ZERO, |c| c.0);
    Pose::from_parts(Vec3::from(x) - q * c, q)
}

/// Bounding radius of a shape about the centre of mass (m).
fn radius(collider: &Collider, com: Option<&CenterOfMass>) -> f32 {
    let [min, max] = collider.local_bounds();
    let c = com.map_or(Vec3::ZERO, |c| c.0);
    (min - c).length().max((max - c).length())
}

type MovingCollider<'a> = (
    &'a Collider,
    &'a Position,
    &'a Rotation,
    Option<&'a CenterOfMass>,
    &'a LinearVelocity,
    Option<&'a AngularVelocity>,
    &'a mut ColliderAabb,
);

/// Boxes of moving colliders, grown by how far they can travel in a step.
fn update_moving_aabbs(
    time: Res<PhysicsTime>,
    settings: Res<ContactSettings>,
    mut colliders: Query<MovingCollider, (Live, Without<Sleeping>)>,
) {
    let dt = time.dt();
    for (c, x, q, com, v, w, mut aabb) in &mut colliders {
        let b = c.shape().compute_aabb(&shape_pose(x.0, q.0, com));
        let spin = w.map_or(0.0, |w| w.0.length() * radius(c, com));
        let grow = settings.margin + (v.0.length() + spin) * dt;
        *aabb = ColliderAabb {
            min: b.mins - Vec3::splat(grow),
            max: b.maxs + Vec3::splat(grow),
        };
    }
}

type Fixed = (Without<LinearVelocity>, Live);

fn fixed_dirty(bp: Res<BroadPhase>) -> bool {
    bp.fixed_dirty
}

type FixedBox<'a> = (
    &'a Collider,
    &'a Position,
    &'a Rotation,
    Option<&'a CenterOfMass>,
    &'a mut ColliderAabb,
);

/// Boxes of fixed colliders: recomputed only after a collider was inserted or removed or a
/// pose was inserted (the hooks set the flag), so idle static geometry costs nothing.
fn update_fixed_aabbs(settings: Res<ContactSettings>, mut colliders: Query<FixedBox, Fixed>) {
    for (c, x, q, com, mut aabb) in &mut colliders {
        let b = c.shape().compute_aabb(&shape_pose(x.0, q.0, com));
        *aabb = ColliderAabb {
            min: b.mins - Vec3::splat(settings.margin),
            max: b.maxs + Vec3::splat(settings.margin),
        };
    }
}

type BroadCollider<'a> = (Entity, &'a ColliderAabb, &'a CollisionLayers, Has<Sleeping>);

fn entry(
    (entity, aabb, layers, sleeping): (Entity, &ColliderAabb, &CollisionLayers, bool),
) -> Entry {
    Entry {
        entity,
        min: aabb.min,
        max: aabb.max,
        awake: !sleeping,
        layers: *layers,
        cell: 0,
    }
}

/// Keeps the broad phase's lists current: moving boxes in place, rebuilding a list only
/// when colliders were added, removed or quarantined.
///
/// The broad phase holds each moving box grown by a tenth of the margin, and keeps it while
/// the collider's box stays inside and no face is twice that far in: a resting body then
/// changes nothing, and when no box changed the last step's pairs still hold and the sweep
/// is skipped. The pairs are those of the grown boxes, a superset of the exact ones that the
/// narrow phase sorts out.
fn run_broad_phase(
    mut bp: ResMut<BroadPhase>,
    settings: Res<ContactSettings>,
    moving: Query<BroadCollider, (With<Collider>, With<LinearVelocity>, Live)>,
    fixed: Query<BroadCollider, (With<Collider>, Without<LinearVelocity>, Live)>,
) {
    let bp = &mut *bp;
    let fat = Vec3::splat(0.1 * settings.margin.max(0.0));
    let grown = |mut e: Entry| {
        (e.min, e.max) = (e.min - fat, e.max + fat);
        e
    };
    let mut changed = bp.moving_dirty || bp.fixed_dirty;
    if !bp.moving_dirty {
        for e in &mut bp.moving {
            match moving.get(e.entity) {
                Ok(c) => {
                    let now = entry(c);
                    // Inside, and not so far inside that the box was grown for a speed
                    // the body no longer has.
                    let (below, above) = (now.min - e.min, e.max - now.max);
                    let fits = below.cmpge(Vec3::ZERO).all()
                        && above.cmpge(Vec3::ZERO).all()
                        && below.max(above).cmple(2.0 * fat).all();
                    if !(fits && now.awake == e.awake && now.layers == e.layers) {
                        *e = grown(now);
                        changed = true;
                    }
                }
                Err(_) => {
                    bp.moving_dirty = true;
                    changed = true;
                    break;
                }
            }
        }
    }
    if bp.moving_dirty {
        bp.moving.clear();
        bp.moving.extend(moving.iter().map(|c| grown(entry(c))));
    }
    if bp.fixed_dirty {
        bp.fixed.clear();
        bp.fixed.extend(fixed.iter().map(entry));
    }
    if changed {
        bp.find_pairs();
    }
}

type NarrowCollider<'a> = (
    Entity,
    Ref<'a, Collider>,
    &'a Position,
    &'a Rotation,
    Option<&'a CenterOfMass>,
    Option<&'a LinearVelocity>,
    Option<&'a AngularVelocity>,
    Has<Sensor>,
);

/// What the narrow phase needs of one collider, fetched once per step however many pairs
/// it is in.
struct NarrowBody<'a> {
    collider: &'a Collider,
    pose: Pose,
    /// Velocity of the centre of mass (m/s; zero for static colliders).
    velocity: Vec3,
    /// Angular velocity (rad/s; zero for static colliders).
    spin: Vec3,
    /// Centre of mass in the shape's frame (m) and how far the shape reaches from it.
    centre: Vec3,
    radius: f32,
    /// The fastest speed its spin gives any of its points, |ω| r (m/s).
    swing: f32,
    /// How thin the shape is (m; see [`super::ccd::thickness`]).
    thin: f32,
    /// Fastest speed of any point of the shape (m/s): |v| + |ω| r.
    speed: f32,
    /// Farthest any point of the shape is from the shape's origin (m).
    extent: f32,
    /// The collider was replaced or changed since the last step.
    changed: bool,
    sensor: bool,
}

impl<'a> NarrowBody<'a> {
    fn cast_side(&self) -> super::ccd::CastSide<'a> {
        super::ccd::CastSide {
            shape: &**self.collider.shape(),
            pose: self.pose,
            velocity: self.velocity,
            spin: self.spin,
            centre: self.centre,
            radius: self.radius,
        }
    }
}

fn narrow_body<'a>(
    (_, collider, x, q, com, v, w, sensor): bevy_ecs::query::ROQueryItem<'a, '_, NarrowCollider>,
) -> NarrowBody<'a> {
    let changed = collider.is_changed();
    let collider = collider.into_inner();
    let [lo, hi] = collider.local_bounds();
    let reach = radius(collider, com);
    let swing = w.map_or(0.0, |w| w.0.length() * reach);
    let speed = v.map_or(0.0, |v| v.0.length()) + swing;
    NarrowBody {
        collider,
        pose: shape_pose(x.0, q.0, com),
        velocity: v.map_or(Vec3::ZERO, |v| v.0.into()),
        spin: w.map_or(Vec3::ZERO, |w| w.0.into()),
        centre: com.map_or(Vec3::ZERO, |c| c.0),
        radius: reach,
        swing,
        thin: super::ccd::thickness([lo, hi]),
        speed,
        extent: lo.abs().max(hi.abs()).length(),
        changed,
        sensor,
    }
}

/// Constraint building's reused buffers: the bodies of the step's contacts, the contact
/// pairs with their slots among them, and the bodies' sides.
type PrepareBuffers = (Wanted, Vec<(Entity, Entity, u32, u32)>, Vec<Option<Side>>);

/// The narrow phase's reused buffers: the bodies of the step's pairs, the pairs' slots
/// among them, and the point list of the point choice.
type NarrowBuffers = (Wanted, Vec<(u32, u32)>, Vec<(Vec3A, f32, bool)>);

/// Persistent manifolds for every candidate pair; start/end messages.
#[allow(clippy::too_many_arguments)] // two message writers and the queries of one pass
fn update_contacts(
    mut contacts: ResMut<Contacts>,
    bp: Res<BroadPhase>,
    time: Res<PhysicsTime>,
    settings: Res<ContactSettings>,
    colliders: Query<NarrowCollider, Live>,
    mut started: MessageWriter<ContactStarted>,
    mut ended: MessageWriter<ContactEnded>,
    sleeping: Query<(), With<Sleeping>>,
    mut buffers: Local<NarrowBuffers>,
) {
    let (wanted, pair_slots, scratch) = &mut *buffers;
    wanted.clear();
    pair_slots.clear();
    pair_slots.extend(
        bp.pairs
            .iter()
            .map(|&(a, b)| (wanted.slot(a) as u32, wanted.slot(b) as u32)),
    );
    let mut bodies: Vec<Option<NarrowBody>> = Vec::new();
    bodies.resize_with(wanted.len(), || None);
    wanted.fetch(&colliders, |c| c.0, |i, c| bodies[i] = Some(narrow_body(c)));
    let dt = time.dt();
    contacts.step += 1;
    contacts.woken.clear();
    let step = contacts.step;
    let touch = 0.25 * settings.margin;
    let window = match settings.recycle_distance {
        r if r > 0.0 => r.min(settings.margin),
        // Zero, negative or not a number: no reuse.
        _ => 0.0,
    };
    for (&(a, b), &(sa, sb)) in bp.pairs.iter().zip(pair_slots.iter()) {
        let (Some(ca), Some(cb)) = (&bodies[sa as usize], &bodies[sb as usize]) else {
            continue;
        };
        let (pose_a, pose_b) = (&ca.pose, &cb.pose);
        let sensor = ca.sensor || cb.sensor;
        let state = contacts.pairs.entry((a, b)).or_insert_with(PairState::new);
        state.seen = step;
        state.sensor = sensor;
        state.cast = None;
        let touching = if sensor {
            let (sa, sb) = (&**ca.collider.shape(), &**cb.collider.shape());
            parry3d::query::intersection_test(pose_a, sa, pose_b, sb).is_ok_and(|i| i.intersecting)
        } else {
            let prediction = settings.margin + (ca.speed + cb.speed) * dt;
            let pos12 = pose_a.inverse() * *pose_b;
            let changed = ca.changed || cb.changed;
            match state.recycle {
                Some(r) if !changed && r.holds(&pos12, cb.extent, prediction, window) => {
                    for m in &mut state.manifolds {
                        m.update_separations(&part_pose12(m, &pos12));
                    }
                }
                _ => {
                    if changed {
                        // parry reuses points itself while a pose holds still, and cannot tell
                        // that a shape changed: start from nothing.
                        state.manifolds.clear();
                        state.workspace = None;
                    }
                    let reach = prediction + window;
                    let result = DefaultQueryDispatcher.contact_manifolds(
                        &pos12,
                        &**ca.collider.shape(),
                        &**cb.collider.shape(),
                        reach,
                        &mut state.manifolds,
                        &mut state.workspace,
                    );
                    if result.is_err() {
                        state.manifolds.clear();
                    }
                    state.recycle =
                        (window > 0.0 && result.is_ok()).then_some(Recycle { pos12, reach });
                    for m in &mut state.manifolds {
                        choose_points(m, scratch);
                    }
                }
            }
            // A triangle mesh or heightfield is zero thick: without the margin as a floor,
            // every pair moving on one at all would be cast every step.
            let thin = ca.thin.min(cb.thin).max(settings.margin);
            let sweep = (cb.velocity - ca.velocity).length() + ca.swing.max(cb.swing);
            if super::ccd::is_fast(sweep, dt, thin) {
                state.cast = super::ccd::impact_manifold(
                    &ca.cast_side(),
                    &cb.cast_side(),
                    dt,
                    thin,
                    &state.manifolds,
                    scratch,
                );
            }
            state
                .manifolds
                .iter()
                .flat_map(|m| &m.points)
                .any(|p| p.dist < touch)
        };
        if touching != state.touching {
            state.touching = touching;
            if touching {
                started.write(ContactStarted { a, b });
            } else {
                ended.write(ContactEnded { a, b });
            }
        }
    }
    let mut gone: Vec<_> = contacts
        .pairs
        .iter()
        // A pair with a sleeping side is not re-formed while it sleeps, but it still
        // touches: keep it (and its warm-start impulses) until the island wakes.
        .filter(|((a, b), s)| s.seen != step && !(sleeping.contains(*a) || sleeping.contains(*b)))
        .map(|(k, s)| (*k, s.touching))
        .collect();
    gone.sort_unstable_by_key(|g| g.0);
    for ((a, b), touching) in gone {
        contacts.pairs.remove(&(a, b));
        if touching {
            ended.write(ContactEnded { a, b });
        }
    }
}

/// Triggers [`super::ContactStart`] / [`super::ContactEnd`] on opted-in bodies, for the
/// messages written since this system last ran (each message once).
fn trigger_contact_events(
    mut commands: Commands,
    mut started: MessageReader<ContactStarted>,
    mut ended: MessageReader<ContactEnded>,
    enabled: Query<(), With<super::CollisionEventsEnabled>>,
) {
    for m in started.read() {
        for (entity, other) in [(m.a, m.b), (m.b, m.a)] {
            if enabled.contains(entity) {
                commands.trigger(super::ContactStart { entity, other });
            }
        }
    }
    for m in ended.read() {
        for (entity, other) in [(m.a, m.b), (m.b, m.a)] {
            if enabled.contains(entity) {
                commands.trigger(super::ContactEnd { entity, other });
            }
        }
    }
}

type PreparedBody<'a> = (
    Entity,
    &'a Collider,
    &'a Position,
    &'a Rotation,
    Option<&'a CenterOfMass>,
    Option<&'a Mass>,
    Option<&'a LinearVelocity>,
    Option<&'a Inertia>,
    Option<&'a AngularVelocity>,
    &'a Friction,
    &'a Restitution,
    Option<&'a RestitutionThreshold>,
    Has<Sleeping>,
);

/// One side of the step's contacts as constraint building needs it, fetched once per step
/// however many pairs its body is in.
struct Side {
    entity: Entity,
    /// Solver index, [`FIXED`], or [`Side::UNSET`] until a contact first needs it.
    index: u32,
    x: Vec3A,
    q: Quat,
    pose: Pose,
    /// Velocity and angular velocity (zero for a [`FIXED`] side).
    v: Vec3A,
    w: Vec3A,
    /// What the anchors of its contact points need of its shape.
    round: Roundness,
    friction: f32,
    restitution: f32,
    /// The collider's own restitution threshold (m/s), if it has one.
    threshold: Option<f32>,
    /// What a solver body is made of: mass (none for static colliders), whether the body
    /// moves (has a velocity and is awake), and inertia.
    mass: Option<Mass>,
    moves: bool,
    inertia: Option<Inertia>,
}

impl Side {
    const UNSET: u32 = u32::MAX - 1;

    fn new(body: bevy_ecs::query::ROQueryItem<'_, '_, PreparedBody>) -> Self {
        let (
            entity,
            collider,
            x,
            q,
            com,
            mass,
            v,
            inertia,
            w,
            friction,
            restitution,
            threshold,
            sleeping,
        ) = body;
        Side {
            entity,
            round: Roundness::of(collider.shape()),
            index: Side::UNSET,
            x: x.0,
            q: q.0,
            pose: shape_pose(x.0, q.0, com),
            v: v.map_or(Vec3A::ZERO, |v| v.0),
            w: w.map_or(Vec3A::ZERO, |w| w.0),
            friction: friction.0,
            restitution: restitution.0,
            threshold: threshold.map(|t| t.0),
            mass: mass.copied(),
            moves: v.is_some() && !sleeping,
            inertia: inertia.copied(),
        }
    }
}

/// How far a collider's contact points may be anchored inside it: the radius of a round
/// shape (a ball, a capsule).
///
/// A round shape's support point in a direction does not turn with it: it is the centre of
/// the ball (or of the capsule's cap) plus r times the direction. So its contact point is
/// anchored there, r inside its surface along the normal: the normal passes through it, so
/// the normal's effective mass and velocity are the same, and the separation the solver
/// updates from the anchors (n·(Δx + ΔR r)) is not thrown off by the body's spin. Anchored
/// on its surface, a ball spun by friction (a ball glancing off a wall at 70 m/s spins at
/// 170 rad/s) read its gap as wider than it was and went through a thin wall.
enum Roundness {
    Round(f32),
    /// A compound: its parts are looked up per manifold.
    Parts(parry3d::shape::SharedShape),
}

impl Roundness {
    fn of(shape: &parry3d::shape::SharedShape) -> Self {
        if shape.shape_type() == parry3d::shape::ShapeType::Compound {
            Roundness::Parts(shape.clone())
        } else {
            Roundness::Round(round_radius(&**shape))
        }
    }

    /// The radius of the manifold's part (0 when it is not round).
    fn radius(&self, part: u32) -> f32 {
        match self {
            Roundness::Round(r) => *r,
            Roundness::Parts(shape) => shape
                .as_compound()
                .and_then(|c| c.shapes().get(part as usize))
                .map_or(0.0, |(_, s)| round_radius(&**s)),
        }
    }
}

fn round_radius(shape: &dyn parry3d::shape::Shape) -> f32 {
    use parry3d::shape::ShapeType;
    // One virtual call for the common shapes; a downcast only for the round ones.
    match shape.shape_type() {
        ShapeType::Ball => shape.as_ball().map_or(0.0, |b| b.radius),
        ShapeType::Capsule => shape.as_capsule().map_or(0.0, |c| c.radius),
        _ => 0.0,
    }
}

/// Solver index of a side's body, made on first use: a new [`SolverBody`] for anything
/// with a velocity, [`FIXED`] for static colliders (whose velocities then read zero).
fn body_index(solver: &mut ContactSolver, side: &mut Side) -> u32 {
    if side.index == Side::UNSET {
        side.index = new_body(solver, side);
        if side.index == FIXED {
            (side.v, side.w) = (Vec3A::ZERO, Vec3A::ZERO);
        }
    }
    side.index
}

fn new_body(solver: &mut ContactSolver, side: &Side) -> u32 {
    // A sleeping body holds still like a static one until its island wakes; a non-finite
    // one (about to be quarantined) is kept out of the solver altogether.
    let (Some(mass), true) = (side.mass, side.moves) else {
        return FIXED;
    };
    let (x, q, v) = (side.x, side.q, side.v);
    if !(x.is_finite() && v.is_finite() && q.is_finite()) {
        return FIXED;
    }
    // A kinematic body drives its contacts but takes no impulse: zero inverse mass and
    // inertia make every push on it exactly nothing.
    let dynamic = !mass.is_pinned();
    let (inv_i, i0) = match side.inertia {
        Some(i) if dynamic && !i.is_infinite() => {
            let (tensor, inverse) = i.world_tensors(q);
            (inverse, tensor)
        }
        _ => (Mat3A::ZERO, Mat3A::ZERO),
    };
    let i = solver.bodies.len() as u32;
    solver.bodies.push(SolverBody {
        entity: side.entity,
        inv_mass: if dynamic { mass.inverse() } else { 0.0 },
        inv_i,
        i0,
        x0: x,
        q0: q,
        q_seen: q,
        w_in: side.w,
        dynamic,
        isotropic: side.inertia.as_ref().is_some_and(Inertia::is_isotropic),
    });
    solver.index.insert(side.entity, i);
    i
}

/// Friction directions for a manifold: the first along the sliding direction (the mean
/// relative tangential velocity), or at rest along last step's friction impulse. With an
/// arbitrary basis the per-point friction impulses of a face contact twist against each
/// other through the body's rotation and their sum falls short of μN (measured: a box
/// crept down a 30° slope at μ = 0.6).
///
/// `centre` is the mean of the solved points, where friction acts: the mean relative
/// velocity of the points is the relative velocity at their mean (velocity is affine in
/// position).
fn tangent_basis(
    n: Vec3A,
    m: &super::narrow::Manifold,
    centre: Vec3A,
    (xa, va, wa): (Vec3A, Vec3A, Vec3A),
    (xb, vb, wb): (Vec3A, Vec3A, Vec3A),
) -> [Vec3A; 2] {
    let slide = (vb + wb.cross(centre - xb)) - (va + wa.cross(centre - xa));
    let impulse = Vec3A::from(m.data.tangent);
    let normal: f32 = m.points.iter().map(|p| p.data.normal).sum();
    let along = |v: Vec3A| (v - n * n.dot(v)).try_normalize();
    // Only a clear signal picks the direction: below it (a body at rest under a small
    // sideways load) a noisy direction would turn the basis from step to step, and a fixed
    // basis is steadier.
    let t0 = along(slide)
        .filter(|_| slide.length() > 1e-2)
        .or_else(|| along(impulse).filter(|_| impulse.length() > 0.05 * normal))
        .unwrap_or_else(|| Vec3A::from(Vec3::from(n).any_orthonormal_pair().0));
    [t0, n.cross(t0)]
}

#[allow(clippy::too_many_arguments)] // the step's inputs and its reused buffers
fn prepare_contacts(
    mut solver: ResMut<ContactSolver>,
    mut active: ResMut<ConstraintsActive>,
    contacts: Res<Contacts>,
    bp: Res<BroadPhase>,
    settings: Res<ContactSettings>,
    bodies: Query<PreparedBody, (With<Collider>, Live)>,
    mut buffers: Local<PrepareBuffers>,
) {
    let s = &mut *solver;
    s.clear();
    let touch = 0.25 * settings.margin;
    let (wanted, pairs, sides) = &mut *buffers;
    wanted.clear();
    pairs.clear();
    for &(ea, eb) in bp.pairs.iter().chain(&contacts.woken) {
        let Some(state) = contacts.pairs.get(&(ea, eb)) else {
            continue;
        };
        if state.sensor || state.solved().all(|m| m.points.is_empty()) {
            continue;
        }
        pairs.push((ea, eb, wanted.slot(ea) as u32, wanted.slot(eb) as u32));
    }
    sides.clear();
    sides.resize_with(wanted.len(), || None);
    wanted.fetch(&bodies, |b| b.0, |i, b| sides[i] = Some(Side::new(b)));
    for &(ea, eb, sa, sb) in pairs.iter() {
        let Some(state) = contacts.pairs.get(&(ea, eb)) else {
            continue;
        };
        let (sa, sb) = (sa as usize, sb as usize);
        if sides[sa].is_none() || sides[sb].is_none() {
            continue;
        }
        // Solver bodies are numbered in the order contacts first need them.
        let ia = sides[sa].as_mut().map_or(FIXED, |a| body_index(s, a));
        let ib = sides[sb].as_mut().map_or(FIXED, |b| body_index(s, b));
        if ia == FIXED && ib == FIXED {
            continue;
        }
        let (Some(a), Some(b)) = (&sides[sa], &sides[sb]) else {
            continue;
        };
        let ((va, wa), (vb, wb)) = ((a.v, a.w), (b.v, b.w));
        let (pose_a, pose_b) = (&a.pose, &b.pose);
        let friction = settings.friction_rule.combine(a.friction, b.friction);
        let restitution = settings
            .restitution_rule
            .combine(a.restitution, b.restitution);
        // The lower of the two colliders' own thresholds, else the world's.
        let threshold = match (a.threshold, b.threshold) {
            (Some(x), Some(y)) => x.min(y),
            (Some(x), None) | (None, Some(x)) => x,
            (None, None) => settings.restitution_threshold,
        };
        for (mi, m) in state.solved().enumerate() {
            if m.points.is_empty() {
                continue;
            }
            // A compound's manifold is in its part's frame; the part's pose in the compound
            // comes with the manifold.
            let (pose_a, pose_b) = (
                part_pose(pose_a, m.subshape_pos1()),
                part_pose(pose_b, m.subshape_pos2()),
            );
            let n = Vec3A::from(pose_a.rotation * m.local_n1);
            let first = s.inputs.len() as u32;
            let kept = m.data.kept();
            let count = kept.len();
            let mut mids = [Vec3A::ZERO; super::narrow::MAX_POINTS];
            let mut witness = [(Vec3A::ZERO, Vec3A::ZERO); super::narrow::MAX_POINTS];
            for ((mid, w), &k) in mids.iter_mut().zip(&mut witness).zip(kept) {
                let p = &m.points[usize::from(k)];
                *w = (
                    Vec3A::from(pose_a * p.local_p1),
                    Vec3A::from(pose_b * p.local_p2),
                );
                *mid = 0.5 * (w.0 + w.1);
            }
            // A round side's points are anchored at its centre of curvature (see
            // `Roundness`).
            let (round_a, round_b) = (a.round.radius(m.subshape1), b.round.radius(m.subshape2));
            let mids = &mids[..count];
            // Friction acts at the kept points' centre; the twist's arm is their mean
            // distance from it.
            let middle = mids.iter().sum::<Vec3A>() / count as f32;
            let t = tangent_basis(n, m, middle, (a.x, va, wa), (b.x, vb, wb));
            let radius = mids.iter().map(|&p| (p - middle).length()).sum::<f32>() / count as f32;
            for ((&k, &mid), &(w_a, w_b)) in kept.iter().zip(mids).zip(&witness) {
                let p = &m.points[usize::from(k)];
                // A touching point acts at the middle of its two witness points. A
                // speculative one, with a gap still open, acts on each body where that body
                // will touch: anchored in the gap, its lever arms were as long as the gap
                // (metres for a fast body), and friction on them spun the body.
                let (p_a, p_b) = if p.dist > touch {
                    (w_a, w_b)
                } else {
                    (mid, mid)
                };
                let p_a = if round_a > 0.0 {
                    w_a - n * round_a
                } else {
                    p_a
                };
                let p_b = if round_b > 0.0 {
                    w_b + n * round_b
                } else {
                    p_b
                };
                let (r_a, r_b) = (p_a - a.x, p_b - b.x);
                let rel = (vb + wb.cross(r_b)) - (va + wa.cross(r_a));
                s.inputs.push(PointInput {
                    r_a,
                    r_b,
                    base: p.dist - n.dot(r_b - r_a),
                    n_imp: p.data.normal,
                    approach: n.dot(rel),
                    source: u32::from(k),
                });
            }
            let tangent = Vec3A::from(m.data.tangent);
            s.manifolds.push(ManifoldConstraint {
                a: ia,
                b: ib,
                n,
                t,
                friction,
                restitution,
                threshold,
                first,
                count: s.inputs.len() as u32 - first,
                pair: (ea, eb),
                manifold: mi as u32,
                centre_a: middle - a.x,
                centre_b: middle - b.x,
                radius,
                t_imp: [tangent.dot(t[0]), tangent.dot(t[1])],
                twist: m.data.twist,
            });
        }
    }
    s.build();
    active.0 = !s.manifolds.is_empty();
}

fn softness(settings: &ContactSettings, h: f32) -> (Softness, Softness) {
    // An eighth of the substep rate, not Box2D's quarter: at a quarter (60 Hz with 4 substeps
    // of 60 Hz) a 20-row pyramid crept 8–16 cm in 10 s; at an eighth it holds (measured).
    let hertz = settings.hertz.min(0.125 / h);
    (
        Softness::new(hertz, settings.damping_ratio, h),
        Softness::new(2.0 * hertz, settings.damping_ratio, h),
    )
}

/// Warm start, then one biased pass.
fn solve_contacts(
    mut solver: ResMut<ContactSolver>,
    time: Res<SubstepTime>,
    settings: Res<ContactSettings>,
    mut bodies: Query<SolvedBody, Live>,
) {
    gather(&mut solver, &bodies);
    solver.limit_rotation(settings.max_rotation / time.h);
    let (soft, fixed) = softness(&settings, time.h);
    solver.warm_start();
    solver.solve(time.h, soft, fixed, true, settings.max_push_velocity);
    scatter(&mut solver, &mut bodies);
}

/// One pass without bias; after the last substep, restitution and the impulses kept for
/// the next step's warm start.
fn relax_contacts(
    mut solver: ResMut<ContactSolver>,
    mut contacts: ResMut<Contacts>,
    time: Res<SubstepTime>,
    settings: Res<ContactSettings>,
    mut bodies: Query<SolvedBody, Live>,
) {
    gather(&mut solver, &bodies);
    let (soft, fixed) = softness(&settings, time.h);
    solver.solve(time.h, soft, fixed, false, settings.max_push_velocity);
    if time.is_last() {
        solver.restitution();
        for solved in solver.manifold_impulses() {
            let m = solved.constraint;
            let Some(tracked) = contacts
                .pairs
                .get_mut(&m.pair)
                .and_then(|s| s.manifolds.get_mut(m.manifold as usize))
            else {
                continue;
            };
            // (The time-of-impact manifold, after parry's, is not found here: it is not
            // warm-started.)
            // Points the solver left out (beyond four) start from zero if kept later.
            for p in &mut tracked.points {
                p.data = ContactImpulse::default();
            }
            for &(k, normal) in &solved.normals[..solved.count] {
                if let Some(p) = tracked.points.get_mut(k as usize) {
                    p.data = ContactImpulse { normal };
                }
            }
            tracked.data.tangent = solved.tangent.into();
            tracked.data.twist = solved.twist;
        }
    }
    scatter(&mut solver, &mut bodies);
}
