//! The joint systems: a biased pass after the contacts' biased pass, a relax pass after the
//! contacts' relax pass, each substep.

use bevy_ecs::prelude::*;
use glam::{Mat3A, Vec3, Vec3A};

use bevy_ecs::entity::EntityHashMap;
use bevy_platform::collections::HashMap;

use super::axial;
use super::block::{self, Row};
use super::envelope::{self, Envelope};
use super::graph::{self, Forest, Ordering};
use super::kinds::{self, Kinds};
use super::solve::{self, Accumulated, Angular, Linear, Mode, Rows, Side};
use super::{
    DistanceJoint, FixedJoint, JointImpulse, JointSettings, PrismaticJoint, RevoluteJoint,
    SphericalJoint,
};
use crate::core::diagnostics::energy_on;
use crate::core::plugin::WorldPlugin;
use crate::core::quarantine::Quarantined;
use crate::core::rest::Sleeping;
use crate::core::schedule::{
    CollisionSystems, FinishSystems, MeasureSystems, PhysicsSchedule, PhysicsSystems,
    PrepareSystems, RelaxSystems, StepSystems, SubstepSchedule, add_own_systems,
};
use crate::core::time::SubstepTime;
use crate::integrator::ConstraintsActive;
use crate::particles::{LinearVelocity, Mass, Position};
use crate::rigid::{AngularMomentum, AngularVelocity, CenterOfMass, Inertia, Rotation};

/// Solves [`SphericalJoint`], [`RevoluteJoint`], [`PrismaticJoint`], [`DistanceJoint`] and
/// [`FixedJoint`] entities in the substeps,
/// after the contacts in each pass. Its systems run only while a joint exists.
#[derive(Debug, Default, Clone, Copy)]
pub struct JointPlugin;

impl WorldPlugin for JointPlugin {
    fn build(&self, world: &mut World) {
        add_own_systems(
            world,
            PhysicsSchedule,
            MeasureSystems::configure(
                super::diagnostics::measure_joints
                    .run_if(any_with_component::<JointImpulse>)
                    .run_if(energy_on),
            ),
        );
        crate::core::restore::init::<JointSettings>(world);
        crate::core::plugin::add_message::<super::JointBroken>(world);
        add_own_systems(
            world,
            PhysicsSchedule,
            super::breaking::break_joints
                .run_if(any_with_component::<super::JointBreakForce>)
                .in_set(PhysicsSystems::Finish)
                .before(FinishSystems::Diagnostics),
        );
        crate::core::restore::init::<super::JointDiagnostics>(world);
        world.init_resource::<Scratch>();
        // The whole-step path knows no joints: worlds with one take the schedule.
        crate::core::whole_step::block_on::<SphericalJoint>(world);
        crate::core::whole_step::block_on::<RevoluteJoint>(world);
        crate::core::whole_step::block_on::<FixedJoint>(world);
        crate::core::whole_step::block_on::<PrismaticJoint>(world);
        crate::core::whole_step::block_on::<DistanceJoint>(world);
        let any = any_with_component::<JointImpulse>;
        add_own_systems(
            world,
            PhysicsSchedule,
            mark_constraints_active
                .run_if(any)
                .in_set(PrepareSystems::Collision)
                .after(CollisionSystems::Constraints),
        );
        add_own_systems(
            world,
            SubstepSchedule,
            (
                solve_joints
                    .run_if(any)
                    .in_set(StepSystems::SolveConstraints)
                    .after(crate::collision::solver::plugin::solve_contacts),
                relax_joints
                    .run_if(any)
                    .in_set(RelaxSystems::Rigid)
                    .after(crate::collision::solver::plugin::relax_contacts),
            ),
        );
    }
}

type JointItem<'a> = (Entity, Kinds<'a>, &'a mut JointImpulse);

type BodyItem<'a> = (
    &'a Position,
    &'a Rotation,
    Option<&'a CenterOfMass>,
    Option<&'a Mass>,
    Option<&'a Inertia>,
    Option<&'a mut LinearVelocity>,
    Option<&'a mut AngularMomentum>,
    Option<&'a mut AngularVelocity>,
    Has<Sleeping>,
    Option<&'a crate::rigid::LockedAxes>,
);

type Joints<'w, 's> = Query<'w, 's, JointItem<'static>, Without<Quarantined>>;
type Bodies<'w, 's> = Query<'w, 's, BodyItem<'static>, Without<Quarantined>>;

/// Joints act between the velocity and the position half of the substep, so the integrators
/// must not fuse the two (the contacts' preparation sets the flag for contacts; this runs
/// after it).
fn mark_constraints_active(mut active: ResMut<ConstraintsActive>) {
    active.0 = true;
}

/// Warm start, then one biased pass over every joint.
fn solve_joints(
    time: Res<SubstepTime>,
    settings: Res<JointSettings>,
    mut joints: Joints,
    mut bodies: Bodies,
    mut scratch: ResMut<Scratch>,
) {
    let hertz = settings.hertz.min(0.25 / time.h);
    let soft = crate::collision::solver::Softness::new(hertz, settings.damping_ratio, time.h);
    pass(
        &mut joints,
        &mut bodies,
        Mode::soft(soft),
        true,
        time.h,
        &mut scratch,
    );
}

/// One rigid pass over every joint.
fn relax_joints(
    time: Res<SubstepTime>,
    mut joints: Joints,
    mut bodies: Bodies,
    mut scratch: ResMut<Scratch>,
) {
    pass(
        &mut joints,
        &mut bodies,
        Mode::RIGID,
        false,
        time.h,
        &mut scratch,
    );
}

/// A body's side: immovable when it has no mass, is asleep or is not a body at all (the
/// world), with its anchor measured from its centre of mass.
fn load(bodies: &Bodies, e: Option<Entity>, anchor: Vec3) -> (Side, Vec3A) {
    let Some((x, q, com, mass, inertia, v, l, w, asleep, locks)) =
        e.and_then(|e| bodies.get(e).ok())
    else {
        return (Side::WORLD, Vec3A::from(anchor));
    };
    let local = Vec3A::from(anchor - com.map_or(Vec3::ZERO, |c| c.0));
    let mut side = Side {
        x: x.0,
        q: q.0,
        ..Side::WORLD
    };
    if asleep {
        return (side, local);
    }
    side.moves = mass.is_some_and(|m| m.inverse() > 0.0);
    side.v = v.map_or(Vec3A::ZERO, |v| v.0);
    side.inv_m = crate::rigid::LockedAxes::inverse_mass_of(locks, mass.map_or(0.0, Mass::inverse));
    match (inertia, l) {
        (Some(i), Some(l)) if !i.is_infinite() => {
            side.w = i.angular_velocity(q.0, l.0);
            side.inv_i = i.world_inverse_tensor(q.0).into();
        }
        _ => side.w = w.map_or(Vec3A::ZERO, |w| w.0),
    }
    (side, local)
}

/// Writes a moving side's velocities back: v, and L += the pass's angular impulse with ω
/// following it.
fn store(bodies: &mut Bodies, e: Option<Entity>, side: &Side) {
    if !side.moves {
        return;
    }
    let Some((_, q, _, _, inertia, v, l, w, ..)) = e.and_then(|e| bodies.get_mut(e).ok()) else {
        return;
    };
    if let Some(mut v) = v {
        v.0 = side.v;
    }
    if let (Some(mut l), Some(i)) = (l, inertia) {
        let l = l.bypass_change_detection();
        l.0 += side.momentum.map_or(side.dl, |m| m * side.dl);
        if let Some(mut w) = w {
            w.bypass_change_detection().0 = i.angular_velocity(q.0, l.0);
        }
    }
}

/// Empties `list` and hands back its memory as a list of another element type of the same
/// size and alignment (the standard library collects such a map in place): the joints'
/// descriptions borrow from the pass's query, and a fresh list each pass of a 20,000-joint
/// net cost fresh pages from the system.
fn recycle<T, U>(mut list: Vec<T>) -> Vec<U> {
    list.clear();
    list.into_iter().map(|_| unreachable!()).collect()
}

/// The passes' working set, kept to reuse its memory, the plan and the groups' layouts (both
/// passes share them).
#[derive(Default, Resource)]
struct Scratch {
    /// Every side the pass reads: each moving body once, then immovable sides per joint.
    sides: Vec<Side>,
    /// Per side: its centre of mass in its shape frame (m).
    coms: Vec<Vec3>,
    entities: Vec<Option<Entity>>,
    index: EntityHashMap<usize>,
    /// Per joint: its geometry and its sides' places in `sides`.
    joints: Vec<(Rows, usize, usize)>,
    acc: Vec<Accumulated>,
    /// Per joint: whether its group is solved as one system (and takes its limits).
    in_block: Vec<bool>,
    /// Union–find over `sides`: the groups of bodies joints connect.
    parent: Vec<usize>,
    /// Per joint, its group's root; then the joints in group order.
    order: Vec<(usize, usize)>,
    rows: Vec<Row>,
    system: Envelope,
    /// Per group solved as one system, its system.
    systems: Vec<Envelope>,
    ordering: Ordering,
    forest: Forest,
    /// A group's joints while it is planned, and where its trees end.
    group: Vec<usize>,
    tree_ends: Vec<usize>,
    /// Per group root, its first joint (groups are solved in that order).
    first: HashMap<usize, usize>,
    /// The groups: their span in `order` and how each is solved.
    groups: Vec<(usize, usize, GroupSolve)>,
    /// The joints' entities in the order the query visited them, this pass and when the
    /// order was last worked out, and per place in that order its joint's slot (the joints
    /// are solved in the order of their entities).
    visited: Vec<Entity>,
    visited_before: Vec<Entity>,
    slot_of: Vec<usize>,
    /// The memory of the pass's list of joint descriptions ([`recycle`]).
    described: Vec<[usize; 2]>,
    /// Per joint: the substep length of its last impulse (s), NaN before its first.
    h: Vec<f32>,
    /// Per joint, what the plan was made for (see [`topology_key`]).
    topology: Vec<(usize, usize, usize)>,
    /// Per side, the geometric stiffness of its joints' pull (N·m per rad).
    stiffness: Vec<Mat3A>,
    /// The joints whose free axis has a motor or limits, in order.
    axial: Vec<usize>,
}

fn root(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// The place of `e`'s side in `s.sides`, loading it the first time; immovable sides get a
/// place of their own each time.
fn place(s: &mut Scratch, bodies: &Bodies, e: Option<Entity>, anchor: Vec3) -> (usize, Vec3A) {
    if let Some(&i) = e.and_then(|e| s.index.get(&e)) {
        return (i, Vec3A::from(anchor - s.coms[i]));
    }
    let (side, local) = load(bodies, e, anchor);
    let i = s.sides.len();
    s.coms.push(anchor - Vec3::from(local));
    if side.moves
        && let Some(e) = e
    {
        s.index.insert(e, i);
    }
    s.sides.push(side);
    s.entities.push(e);
    s.stiffness.push(Mat3A::ZERO);
    (i, local)
}

/// One pass over every joint: the warm start first when `warm`; then each group of joints
/// connected through moving bodies is solved as one system (when
/// [`graph::affordable`]), or joint after joint (a net).
fn pass(joints: &mut Joints, bodies: &mut Bodies, mode: Mode, warm: bool, h: f32, s: &mut Scratch) {
    s.sides.clear();
    s.coms.clear();
    s.entities.clear();
    s.index.clear();
    s.joints.clear();
    s.stiffness.clear();
    s.axial.clear();
    let (mut stiffened, mut replan) = (false, false);
    // The joints in the order of their entities, whatever order the query visits them in: a
    // restored snapshot builds its archetypes in an order of its own, and the solve's order
    // (its rounding, its plan) must not depend on it.
    s.visited.clear();
    s.visited.extend(joints.iter().map(|(e, ..)| e));
    if s.visited != s.visited_before {
        s.visited_before.clone_from(&s.visited);
        let mut by_entity: Vec<usize> = (0..s.visited.len()).collect();
        by_entity.sort_unstable_by_key(|&k| s.visited[k]);
        s.slot_of.clear();
        s.slot_of.resize(by_entity.len(), 0);
        for (slot, &k) in by_entity.iter().enumerate() {
            s.slot_of[k] = slot;
        }
    }
    let n = s.visited.len();
    let mut described = recycle(std::mem::take(&mut s.described));
    described.resize(n, None);
    s.acc.clear();
    s.acc.resize(n, Accumulated::default());
    s.h.clear();
    s.h.resize(n, f32::NAN);
    for (k, (_, joint, impulse)) in joints.iter().enumerate() {
        let slot = s.slot_of[k];
        described[slot] = kinds::describe(joint);
        s.h[slot] = impulse.h;
        s.acc[slot] = Accumulated {
            linear: impulse.linear.into(),
            angular: impulse.angular.into(),
            motor: impulse.motor,
            lower: impulse.lower,
            upper: impulse.upper,
            swing: impulse.swing,
            friction: impulse.friction.into(),
        };
    }
    for (slot, described) in described.drain(..).enumerate() {
        // A body that is gone or quarantined leaves the joint inert: its partner runs free
        // (and the joint exerts nothing) until it is back.
        let gone = |e: Entity| !s.index.contains_key(&e) && bodies.get(e).is_err();
        let described =
            described.filter(|j| !(j.bodies().a.is_some_and(gone) || gone(j.bodies().b)));
        let Some(described) = described else {
            let inert = s.sides.len();
            s.sides.push(Side::WORLD);
            s.coms.push(Vec3::ZERO);
            s.entities.push(None);
            s.stiffness.push(Mat3A::ZERO);
            let rows = Rows {
                linear: Linear::Free,
                ..Rows::ball(Vec3A::ZERO, Vec3A::ZERO)
            };
            s.joints.push((rows, inert, inert));
            s.acc[slot] = Accumulated::default();
            replan |= note_topology(s, slot);
            continue;
        };
        let ends = described.bodies();
        let (ia, local_a) = place(s, bodies, ends.a, ends.anchor_a);
        let (ib, local_b) = place(s, bodies, Some(ends.b), ends.anchor_b);
        let rows = described.rows_at(local_a, local_b);
        stiffened |= add_stiffness(s, &rows, (ia, ib), slot);
        if rows.axial.active() {
            s.axial.push(slot);
        }
        s.joints.push((rows, ia, ib));
        replan |= note_topology(s, slot);
    }
    s.described = recycle(described);
    replan |= s.topology.len() != s.joints.len();
    s.topology.truncate(s.joints.len());
    if stiffened {
        stiffen_sides(s, h);
    }
    if warm {
        for (j, (rows, ia, ib)) in s.joints.iter().enumerate() {
            let (ia, ib) = (*ia, *ib);
            if let Ok([a, b]) = s.sides.get_disjoint_mut([ia, ib]) {
                solve::warm_start(rows, &mut s.acc[j], a, b);
                axial::warm_start(rows, &s.acc[j], a, b);
            }
        }
    }
    if replan {
        plan(s);
    }
    // Motors (and the limits no group takes) first, each on its own (Box2D's order): the
    // rows after them keep what they leave free, the free axis.
    free_axes(s, mode, h, warm);
    if s.systems.len() < s.groups.len() {
        s.systems.resize_with(s.groups.len(), Envelope::default);
    }
    for g in 0..s.groups.len() {
        let (k, end, how) = s.groups[g];
        if how == GroupSolve::Whole {
            s.rows.clear();
            for i in k..end {
                let j = s.order[i].1;
                push_rows(s, j, h);
            }
            let system = &mut s.systems[g];
            envelope::solve(&s.rows, &mut s.sides, &mut s.acc, mode.exact(), system);
        } else {
            // A mesh of loops (a net, a grid): the tree would leave most joints to be solved
            // after it anyway, so each joint is solved on its own, as Box2D solves them.
            for i in k..end {
                let (rows, ia, ib) = &s.joints[s.order[i].1];
                let (ia, ib) = (*ia, *ib);
                let j = s.order[i].1;
                if let (Angular::Free, Linear::Point, Ok([a, b])) = (
                    rows.angular,
                    rows.linear,
                    s.sides.get_disjoint_mut([ia, ib]),
                ) {
                    solve::solve_ball(rows, a, b, &mut s.acc[j], mode);
                    continue;
                }
                s.rows.clear();
                push_rows(s, j, h);
                let system = &mut s.system;
                envelope::solve(&s.rows, &mut s.sides, &mut s.acc, mode, system);
            }
        }
    }
    for (side, &e) in s.sides.iter().zip(&s.entities) {
        store(bodies, e, side);
    }
    for (k, (_, _, mut impulse)) in joints.iter_mut().enumerate() {
        let slot = s.slot_of[k];
        let (acc, (rows, ia, ib)) = (&s.acc[slot], &s.joints[slot]);
        let (ia, ib) = (*ia, *ib);
        // Bookkeeping, not a change anyone listens for.
        let impulse = impulse.bypass_change_detection();
        impulse.linear = acc.linear.into();
        impulse.angular = acc.angular.into();
        impulse.motor = acc.motor;
        impulse.lower = acc.lower;
        impulse.upper = acc.upper;
        impulse.swing = acc.swing;
        impulse.friction = acc.friction.into();
        (impulse.axial_linear, impulse.axial_angular) =
            axial::world_impulse(rows, acc, &s.sides[ia], &s.sides[ib]);
        impulse.h = h;
    }
}

/// What the plan was made for at joint `j`: its sides' places, which of them move, and the
/// rows it locks (see [`plan`]).
fn topology_key(s: &Scratch, j: usize) -> (usize, usize, usize) {
    let (rows, ia, ib) = &s.joints[j];
    let rod = rows.axial.limits.is_some_and(|(min, max)| min >= max);
    let flags = usize::from(s.sides[*ia].moves)
        | usize::from(s.sides[*ib].moves) << 1
        | usize::from(rod) << 2
        | rows.count() << 3;
    (*ia, *ib, flags)
}

/// Notes joint `j`'s [`topology_key`] as it is gathered; returns whether it differs from the
/// one the plan was made for.
fn note_topology(s: &mut Scratch, j: usize) -> bool {
    let key = topology_key(s, j);
    if s.topology.get(j) == Some(&key) {
        return false;
    }
    s.topology.truncate(j);
    s.topology.push(key);
    true
}

/// Plans the groups: bodies joined through moving bodies (an immovable side joins nothing),
/// each solved as [`plan_group`] decides, and which joints' limits their group takes.
fn plan(s: &mut Scratch) {
    // Groups: bodies joined through moving bodies (an immovable side joins nothing).
    s.parent.clear();
    s.parent.extend(0..s.sides.len());
    for &(_, ia, ib) in &s.joints {
        if s.sides[ia].moves && s.sides[ib].moves {
            let (ra, rb) = (root(&mut s.parent, ia), root(&mut s.parent, ib));
            s.parent[ra.max(rb)] = ra.min(rb);
        }
    }
    s.order.clear();
    for (j, &(_, ia, ib)) in s.joints.iter().enumerate() {
        let moving = if s.sides[ib].moves { ib } else { ia };
        if s.sides[moving].moves {
            s.order.push((root(&mut s.parent, moving), j));
        }
    }
    // Groups in the order of their first joint, joints in their own order within a group.
    s.first.clear();
    for &(g, j) in &s.order {
        s.first.entry(g).or_insert(j);
    }
    for o in &mut s.order {
        o.0 = s.first[&o.0];
    }
    // Keys are unique (a joint is in one group), so an unstable sort orders them fully.
    s.order.sort_unstable();
    // A group solved as one system takes its joints' limits with its other rows (a door
    // stopped at its limit stops about its hinge); elsewhere they are solved on their own.
    s.groups.clear();
    let mut k = 0;
    while k < s.order.len() {
        let end = group_end(s, k);
        plan_group(s, k, end);
        k = end;
    }
    s.in_block.clear();
    s.in_block.resize(s.joints.len(), false);
    for &(k, end, how) in &s.groups {
        if how == GroupSolve::Whole {
            for i in k..end {
                let j = s.order[i].1;
                // A rod (min = max) keeps its two-sided pair of rows apart: as rows of one
                // system they would be one row twice.
                s.in_block[j] = s.joints[j]
                    .0
                    .axial
                    .limits
                    .is_none_or(|(min, max)| min < max);
            }
        }
    }
}

/// Adds to the geometric stiffness of joint `j`'s moving sides `(ia, ib)` that of the force
/// it exerted in the last substep; returns whether it did.
fn add_stiffness(s: &mut Scratch, rows: &Rows, (ia, ib): (usize, usize), j: usize) -> bool {
    let last = s.h[j];
    if last.is_nan() || last <= 0.0 {
        return false;
    }
    let f = s.acc[j].linear / last;
    let mut any = false;
    for (i, local) in [(ia, rows.local_a), (ib, rows.local_b)] {
        let side = &s.sides[i];
        if side.moves {
            s.stiffness[i] += solve::geometric_stiffness(f, side.q * local);
            any = true;
        }
    }
    any
}

/// Stiffens the inertia of every moving side by the geometric stiffness of the forces its
/// joints exerted in the last substep ([`add_stiffness`], [`solve::stiffen`]).
fn stiffen_sides(s: &mut Scratch, h: f32) {
    for (side, &k) in s.sides.iter_mut().zip(&s.stiffness) {
        if side.moves && k != Mat3A::ZERO {
            solve::stiffen(side, k, h);
        }
    }
}

/// Solves every free axis's motor, and its limits unless its group takes them, each joint
/// on its own.
fn free_axes(s: &mut Scratch, mode: Mode, h: f32, first: bool) {
    for &j in &s.axial {
        let (rows, ia, ib) = &s.joints[j];
        let (ia, ib) = (*ia, *ib);
        if let Ok(sides) = s.sides.get_disjoint_mut([ia, ib]) {
            let [a, b] = sides;
            axial::solve(
                rows,
                (a, b),
                &mut s.acc[j],
                (mode, h, first),
                !s.in_block[j],
            );
        }
    }
}

/// How a run of joints is solved.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum GroupSolve {
    /// As one system ([`envelope::solve`]), its joints in the order that keeps the
    /// factorisation sparse.
    Whole,
    /// Joint after joint (the loops of a net of joints).
    JointByJoint,
}

/// Plans how the group `s.order[k..end]` is solved and puts its joints in that order: as one
/// system when that is [`graph::affordable`], else as the trees of
/// [`graph::split_forest`] (each as one system when affordable) and then its loops' joints
/// one after another.
fn plan_group(s: &mut Scratch, k: usize, end: usize) {
    let mut group = std::mem::take(&mut s.group);
    group.clear();
    group.extend(s.order[k..end].iter().map(|o| o.1));
    let sides = &s.sides;
    let joints = &s.joints;
    let ends = |j: usize| {
        let (_, ia, ib) = joints[j];
        (sides[ia].moves.then_some(ia), sides[ib].moves.then_some(ib))
    };
    let rows = |j: usize| joints[j].0.count();
    let plan = |span: &mut [usize], from: usize, groups: &mut Vec<_>, o: &mut _| {
        let cost = graph::order_joints(span, ends, rows, o);
        let how = if graph::affordable(cost, span.iter().map(|&j| rows(j)).sum()) {
            GroupSolve::Whole
        } else {
            GroupSolve::JointByJoint
        };
        groups.push((k + from, k + from + span.len(), how));
    };
    let cost = graph::order_joints(&mut group, ends, rows, &mut s.ordering);
    if graph::affordable(cost, group.iter().map(|&j| rows(j)).sum()) {
        s.groups.push((k, end, GroupSolve::Whole));
    } else {
        graph::split_forest(&mut group, ends, &mut s.forest, &mut s.tree_ends);
        let mut from = 0;
        for &to in &s.tree_ends {
            plan(&mut group[from..to], from, &mut s.groups, &mut s.ordering);
            from = to;
        }
        if from < group.len() {
            // The loops' joints in their own order: their sides then come in about the order
            // they were gathered in, so a net of 10,000 bodies streams through memory
            // instead of jumping across it.
            group[from..].sort_unstable();
            s.groups.push((k + from, end, GroupSolve::JointByJoint));
        }
    }
    for (o, &j) in s.order[k..end].iter_mut().zip(&group) {
        o.1 = j;
    }
    s.group = group;
}

/// The end of the group that starts at `s.order[k]`.
fn group_end(s: &Scratch, k: usize) -> usize {
    let group = s.order[k].0;
    k + s.order[k..].iter().take_while(|o| o.0 == group).count()
}

/// Appends joint `j`'s rows to `s.rows`, each side named only if it moves; its limits'
/// rows too when its group is solved as one system.
fn push_rows(s: &mut Scratch, j: usize, h: f32) {
    let (rows, ia, ib) = &s.joints[j];
    let (ia, ib) = (*ia, *ib);
    let moving = |i: usize| s.sides[i].moves.then_some(i);
    let limits = s.in_block[j].then_some((h, &s.acc[j]));
    block::joint_rows(
        j,
        rows,
        (moving(ia), &s.sides[ia]),
        (moving(ib), &s.sides[ib]),
        limits,
        &mut s.rows,
    );
}
