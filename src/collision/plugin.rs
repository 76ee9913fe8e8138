//! Collision systems: bounding boxes, broad phase, narrow phase, contact solver.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3, Vec3A};
use parry3d::math::Pose;
use parry3d::query::{DefaultQueryDispatcher, PersistentQueryDispatcher};

use super::broad::{BroadPhase, Entry};
use super::exchange::{Live, SolvedBody, gather, scatter};
use super::fetch::Wanted;
use super::narrow::{ContactImpulse, Contacts, PairState, Recycle};
use super::points::{PointsKey, choose_changed_points};
use super::solver::{ContactSolver, Softness};
use super::{
    Collider, ColliderAabb, CollisionLayers, ContactEnded, ContactSettings, ContactStarted, Sensor,
};
use crate::core::plugin::WorldPlugin;
use crate::core::rest::Sleeping;
use crate::core::schedule::{
    CollisionSystems, PhysicsSchedule, StepSystems, SubstepSchedule, add_own_systems,
};
use crate::core::time::{PhysicsTime, SubstepTime};
use crate::particles::{LinearVelocity, Position};
use crate::rigid::{AngularVelocity, CenterOfMass, Rotation};

/// Colliders, contacts and the contact solver. Every system runs only while a collider
/// exists; the solver only while some contact does.
#[derive(Debug, Default, Clone, Copy)]
pub struct CollisionPlugin;

impl WorldPlugin for CollisionPlugin {
    fn build(&self, world: &mut World) {
        crate::core::restore::init::<ContactSettings>(world);
        super::fused::install(world);
        add_own_systems(
            world,
            PhysicsSchedule,
            (
                correct_contact_settings,
                super::attach::refresh_written_parts,
            )
                .in_set(crate::core::schedule::PrepareSystems::Inputs),
        );
        crate::core::restore::init::<super::ColliderChanges>(world);
        crate::core::restore::init::<BroadPhase>(world);
        crate::core::restore::init::<Contacts>(world);
        crate::core::restore::init::<ContactSolver>(world);
        crate::core::plugin::add_message::<ContactStarted>(world);
        crate::core::plugin::add_message::<ContactEnded>(world);
        // Impulses from mesh nodes (soft bodies, cloth) reach their bodies at the start of the
        // next substep, before the bodies' own integrators.
        add_own_systems(
            world,
            crate::core::schedule::SubstepSchedule,
            super::coupling::apply_node_impulses
                .run_if(any_with_component::<super::coupling::NodeImpulse>)
                .in_set(crate::core::schedule::StepSystems::AccumulateTorque),
        );
        world.add_observer(super::broad::on_body_inserted);
        world.add_observer(super::broad::on_body_removed);
        world.add_observer(super::attach::on_body_inserted);
        world.add_observer(super::attach::on_child_of_discarded);
        world.add_observer(super::attach::on_child_of_inserted);
        add_own_systems(
            world,
            PhysicsSchedule,
            super::attach::place_attached_colliders
                .run_if(any_with_component::<super::ColliderOf>)
                .in_set(crate::core::schedule::FinishSystems::Writeback),
        );
        add_own_systems(
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
                super::prepare::prepare_contacts.in_set(CollisionSystems::Constraints),
            )
                .run_if(any_with_component::<Collider>.or_else(has_contacts)),
        );
        add_own_systems(
            world,
            SubstepSchedule,
            (
                solve_contacts
                    .run_if(contacts_active)
                    .in_set(StepSystems::SolveConstraints),
                relax_contacts
                    .run_if(contacts_active)
                    .in_set(crate::core::schedule::RelaxSystems::Rigid),
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
pub(super) fn part_pose(shape: &Pose, part: Option<&Pose>) -> Pose {
    part.map_or(*shape, |p| *shape * *p)
}

/// The pose of a collider's shape frame: origin x − R c.
pub(crate) fn shape_pose(x: Vec3A, q: Quat, com: Option<&CenterOfMass>) -> Pose {
    let c = com.map_or(Vec3::ZERO, |c| c.0);
    Pose::from_parts(Vec3::from(x) - q * c, q)
}

/// Bounding radius of a shape about the centre of mass (m).
pub(super) fn radius(collider: &Collider, com: Option<&CenterOfMass>) -> f32 {
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
    /// Centre of mass in the shape's frame (m).
    centre: Vec3,
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
    /// It has a velocity (a dynamic or kinematic body's collider, or a particle's).
    moving: bool,
}

impl<'a> NarrowBody<'a> {
    fn cast_side(&self) -> super::ccd::CastSide<'a> {
        super::ccd::CastSide {
            shape: &**self.collider.shape(),
            pose: self.pose,
            velocity: self.velocity,
            spin: self.spin,
            centre: self.centre,
            swing: self.swing,
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
        swing,
        thin: super::ccd::thickness([lo, hi]),
        speed,
        extent: lo.abs().max(hi.abs()).length(),
        changed,
        sensor,
        moving: v.is_some(),
    }
}

/// Runs a parry call; a panic inside it sets `failed` and gives `None`.
#[inline]
fn guarded<T>(failed: &mut bool, f: impl FnOnce() -> T) -> Option<T> {
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).ok();
    *failed |= r.is_none();
    r
}

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
    mut commands: Commands,
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
        // parry can still panic on shapes at the edge of its domain (EPA's index panic was
        // seen on huge or badly turned shapes): each parry call is guarded, and one bad pair
        // loses its contact and its moving sides are quarantined while the step goes on.
        let mut failed = false;
        let touching = {
            if sensor {
                let (sa, sb) = (&**ca.collider.shape(), &**cb.collider.shape());
                guarded(&mut failed, || {
                    parry3d::query::intersection_test(pose_a, sa, pose_b, sb)
                })
                .is_some_and(|r| r.is_ok_and(|i| i.intersecting))
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
                        let before = PointsKey::of(&state.manifolds);
                        let result = guarded(&mut failed, || {
                            DefaultQueryDispatcher.contact_manifolds(
                                &pos12,
                                &**ca.collider.shape(),
                                &**cb.collider.shape(),
                                reach,
                                &mut state.manifolds,
                                &mut state.workspace,
                            )
                        })
                        .unwrap_or(Err(parry3d::query::Unsupported));
                        if result.is_err() {
                            state.manifolds.clear();
                        }
                        state.recycle =
                            (window > 0.0 && result.is_ok()).then_some(Recycle { pos12, reach });
                        choose_changed_points(&mut state.manifolds, before, scratch);
                    }
                }
                let thin = super::ccd::pair_thickness(ca.thin, cb.thin, settings.margin);
                let sweep = (cb.velocity - ca.velocity).length() + ca.swing.max(cb.swing);
                if super::ccd::is_fast(sweep, dt, thin) {
                    let manifolds = &state.manifolds;
                    state.cast = guarded(&mut failed, || {
                        super::ccd::impact_manifold(
                            &ca.cast_side(),
                            &cb.cast_side(),
                            dt,
                            thin,
                            manifolds,
                            scratch,
                        )
                    })
                    .flatten()
                    .map(Box::new);
                }
                state
                    .manifolds
                    .iter()
                    .flat_map(|m| &m.points)
                    .any(|p| p.dist < touch)
            }
        };
        let touching = if failed {
            state.manifolds.clear();
            state.workspace = None;
            state.recycle = None;
            state.cast = None;
            for (side, body, other) in [(a, ca, b), (b, cb, a)] {
                if body.moving {
                    commands
                        .entity(side)
                        .try_insert(crate::core::quarantine::Quarantined {
                            reason: crate::core::quarantine::QuarantineReason::GeometryFailed {
                                other,
                            },
                        });
                }
            }
            false
        } else {
            touching
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
    biased_pass(&mut solver, &time, &settings);
    scatter(&mut solver, &mut bodies);
}

/// The solver's work in [`solve_contacts`], between its gather and its scatter.
pub(super) fn biased_pass(
    solver: &mut ContactSolver,
    time: &SubstepTime,
    settings: &ContactSettings,
) {
    solver.limit_rotation(settings.max_rotation / time.h);
    solver.record_speeds();
    let (soft, fixed) = softness(settings, time.h);
    solver.warm_start();
    solver.solve(time.h, soft, fixed, true, settings.max_push_velocity);
    solver.solve_grounded(time.h, soft, fixed, true, settings.max_push_velocity);
    solver.limit_deep_speed(settings.max_push_velocity);
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
    relax_pass(&mut solver, &mut contacts, &time, &settings);
    scatter(&mut solver, &mut bodies);
}

/// The solver's work in [`relax_contacts`], between its gather and its scatter.
pub(super) fn relax_pass(
    solver: &mut ContactSolver,
    contacts: &mut Contacts,
    time: &SubstepTime,
    settings: &ContactSettings,
) {
    let (soft, fixed) = softness(settings, time.h);
    solver.solve(time.h, soft, fixed, false, settings.max_push_velocity);
    solver.solve_grounded(time.h, soft, fixed, false, settings.max_push_velocity);
    if time.is_last() {
        solver.restitution();
    }
    solver.limit_deep_speed(settings.max_push_velocity);
    if time.is_last() {
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
}

/// Settings written with bad values (NaN, negative) are put back to their defaults, field by
/// field, each with an [`InvalidSetting`](crate::core::restore::InvalidSetting) message: a NaN
/// `max_push_velocity` or a negative `margin` dropped bodies through the ground, a negative
/// damping ratio exploded a stack. Runs only in a step after the resource changed.
fn correct_contact_settings(
    mut settings: ResMut<ContactSettings>,
    mut invalid: MessageWriter<crate::core::restore::InvalidSetting>,
    mut bp: ResMut<BroadPhase>,
) {
    if !settings.is_changed() {
        return;
    }
    // The boxes are grown by the margin: fixed colliders' boxes are only recomputed when
    // the lists are rebuilt (a new margin left them at the old one).
    bp.fixed_dirty = true;
    bp.moving_dirty = true;
    let d = ContactSettings::default();
    let current = *settings;
    // (`recycle_distance` and `max_rotation` are left alone: negative or NaN documentedly
    // means "no reuse" and "no limit". A hertz of zero or less means rigid contacts.)
    let ok = |v: f32, finite: bool| v >= 0.0 && (!finite || v.is_finite());
    let fields: [(&'static str, f32, f32, bool); 5] = [
        ("hertz", current.hertz.abs(), d.hertz, true),
        (
            "damping_ratio",
            current.damping_ratio,
            d.damping_ratio,
            true,
        ),
        (
            "max_push_velocity",
            current.max_push_velocity,
            d.max_push_velocity,
            false,
        ),
        (
            "restitution_threshold",
            current.restitution_threshold,
            d.restitution_threshold,
            false,
        ),
        ("margin", current.margin, d.margin, true),
    ];
    let mut fixed = current;
    let mut any = false;
    for (field, value, default, finite) in fields {
        if ok(value, finite) {
            continue;
        }
        any = true;
        invalid.write(crate::core::restore::InvalidSetting {
            resource: "ContactSettings",
            field,
            value,
        });
        match field {
            "hertz" => fixed.hertz = default,
            "damping_ratio" => fixed.damping_ratio = default,
            "max_push_velocity" => fixed.max_push_velocity = default,
            "restitution_threshold" => fixed.restitution_threshold = default,
            _ => fixed.margin = default,
        }
    }
    if any {
        *settings = fixed;
    }
}
