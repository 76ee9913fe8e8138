//! Moving body state between the ECS and the contact solver: a gather before and a scatter
//! after each of the two solver passes of a substep. (On the whole-step path the solver's
//! bodies stay in arrays for the step, and [`read_values`] / [`write_values`] serve it.)
//!
//! A gather reads x, q, v and L and forms ω = ΔR I₀⁻¹ ΔRᵀ L (I(q)⁻¹ = ΔR I₀⁻¹ ΔRᵀ: three
//! matrix products instead of the quaternion round trip through the principal frame). A
//! scatter writes v and L += I₀ Δω, the angular impulse of the pass (the solver moved ω by
//! I₀⁻¹ Σ r × P with the step's start inertia I₀).
//!
//! **Storage order.** Looking each body up by entity costs about as much as the solver's
//! arithmetic for it. So the first gather of a step records at which position of the
//! query's storage-order walk each solver body sits, and every pass walks the query once,
//! checking each entity against the record. A body whose position changed (a structural
//! change between substeps, such as a quarantine) fails the check and is looked up by
//! entity instead, and the record is rebuilt at the next gather. A world where the solver's
//! bodies are a small part of the query keeps the lookups, so a few contacts among many
//! free bodies do not pay for a walk over all of them.

use bevy_ecs::prelude::*;
use glam::{Mat3A, Vec3A};

use crate::collision::ContactFilter;
use crate::collision::solver::{BodyState, ContactSolver, SolverBody};
use crate::particles::{LinearVelocity, Position};
use crate::rigid::{AngularMomentum, AngularVelocity, Rotation};

/// A query position that holds no solver body.
const NONE: u32 = u32::MAX;

/// How far a contact anchor may lag its body's turn when a pass reuses ΔR (m): about f32's
/// resolution of a position 100 m from the origin.
const ANCHOR_LAG: f32 = 1e-5;

/// The smallest reuse limit (squared quaternion distance): a renormalisation's rounding.
pub(crate) const ROUNDING_TURN: f32 = 1e-12;

/// The squared quaternion distance within which a body of bounding radius `reach` (m)
/// reuses its ΔR: a turn by θ moves a point r out by θ r, and θ ≈ 2 |Δq|. At least
/// [`ROUNDING_TURN`] (the floor of f32 rounding), which sets it past a reach of
/// 0.87 m: there the lag is up to 2e-6 rad times the reach.
#[must_use]
pub(crate) fn same_turn(reach: f32) -> f32 {
    let d = ANCHOR_LAG / (2.0 * reach);
    if d.is_finite() {
        (d * d).max(ROUNDING_TURN)
    } else {
        ROUNDING_TURN
    }
}

/// How far (1 − |q·q_axes|, about θ²/8) a body may turn before its contact axes take its
/// current inertia: 0.02 rad, which leaves the tensor within 2 % of its spread.
const AXES_TURN: f32 = 5e-5;

/// A walk pays while at least this share of the query's bodies are in the solver.
const WALK_SHARE: usize = 4;

pub(crate) type SolvedBody<'a> = (
    Entity,
    &'a Position,
    &'a Rotation,
    &'a mut LinearVelocity,
    Option<&'a mut AngularMomentum>,
    Option<&'a AngularVelocity>,
);

/// Where each solver body sits in the query's storage order, for one step.
#[derive(Debug, Default)]
pub(crate) struct StorageOrder {
    /// Per query position, the solver body there, or [`NONE`].
    slots: Vec<u32>,
    /// Per solver body, the pass that last reached it.
    reached: Vec<u32>,
    pass: u32,
    /// False until the step's first gather, and after a walk missed a body.
    ready: bool,
    /// Whether passes walk the query (else they look bodies up).
    walk: bool,
}

impl StorageOrder {
    /// Forgets the record: the solver's bodies changed.
    pub fn reset(&mut self) {
        self.ready = false;
        self.reached.clear();
    }

    fn begin(&mut self, solver_bodies: usize) -> u32 {
        self.pass = self.pass.wrapping_add(1);
        if self.pass == 0 {
            // Never equal to a stamp of an old pass after wrapping.
            self.reached.fill(0);
            self.pass = 1;
        }
        self.reached.resize(solver_bodies, 0);
        self.pass
    }
}

fn record(solver: &mut ContactSolver, bodies: &Query<SolvedBody, ContactFilter>) {
    let order = &mut solver.order;
    order.ready = true;
    order.slots.clear();
    let len = bodies.iter().len();
    order.walk = len <= WALK_SHARE * solver.bodies.len();
    if order.walk {
        order.slots.extend(
            bodies
                .iter()
                .map(|item| solver.index.get(item.0, &solver.bodies).unwrap_or(NONE)),
        );
    }
}

/// Visits each solver body found at its recorded position of the storage-order walk
/// `items` and marks it reached in `pass`; bodies not found are left for lookups.
/// Returns how many bodies it reached.
fn walk<Q>(
    solver: &mut ContactSolver,
    items: impl Iterator<Item = Q>,
    entity: impl Fn(&Q) -> Entity,
    pass: u32,
    mut visit: impl FnMut(&mut ContactSolver, usize, Q),
) -> usize {
    let slots = std::mem::take(&mut solver.order.slots);
    let mut hits = 0;
    // `for_each` takes the query's table-at-a-time fold; a `zip` would not.
    items.enumerate().for_each(|(k, item)| {
        let slot = slots.get(k).copied().unwrap_or(NONE) as usize;
        if solver
            .bodies
            .get(slot)
            .is_some_and(|b| b.entity == entity(&item))
        {
            visit(solver, slot, item);
            solver.order.reached[slot] = pass;
            hits += 1;
        }
    });
    solver.order.slots = slots;
    hits
}

/// Reads the current state of every body in contact into the solver.
pub(crate) fn gather(solver: &mut ContactSolver, bodies: &Query<SolvedBody, ContactFilter>) {
    if !solver.order.ready {
        record(solver, bodies);
    }
    let pass = solver.order.begin(solver.bodies.len());
    let mut frozen = Vec::new();
    let mut hits = 0;
    if solver.order.walk {
        hits = walk(
            solver,
            bodies.iter(),
            |item| item.0,
            pass,
            |solver, i, item| {
                read(solver, i, item, &mut frozen);
            },
        );
    }
    // A walk that reached every body leaves nothing to look up (the test over all bodies
    // cost 1 % of a resting stack's step).
    if hits < solver.bodies.len() {
        for i in 0..solver.bodies.len() {
            if solver.order.reached[i] != pass
                && let Ok(item) = bodies.get(solver.bodies[i].entity)
            {
                // Present but elsewhere: the storage changed, record it again next time.
                solver.order.ready &= !solver.order.walk;
                read(solver, i, item, &mut frozen);
            }
        }
    }
    solver.after_gather(&frozen);
}

#[inline(always)]
fn read(
    solver: &mut ContactSolver,
    i: usize,
    (_, x, q, v, l, w): bevy_ecs::query::ROQueryItem<'_, '_, SolvedBody<'_>>,
    frozen: &mut Vec<u32>,
) {
    read_values(
        solver,
        i,
        x.0,
        q.0,
        v.0,
        l.map(|l| &l.0),
        w.map(|w| &w.0),
        frozen,
    );
}

/// [`read`] from plain values: solver body `i` at position `x`, rotation `q`, velocity `v`,
/// angular momentum `l` (none for a body without inertia) and stored ω `w`.
#[inline(always)]
#[allow(clippy::too_many_arguments)] // one body's state, field by field
pub(crate) fn read_values(
    solver: &mut ContactSolver,
    i: usize,
    x: Vec3A,
    q: glam::Quat,
    v: Vec3A,
    l: Option<&Vec3A>,
    w: Option<&Vec3A>,
    frozen: &mut Vec<u32>,
) {
    let b = &mut solver.bodies[i];
    // ΔR formed at a rotation this close still holds: always compared with the rotation it
    // was formed at, it lags by at most `ANCHOR_LAG` at the body's reach. Between a relax
    // pass and the next substep's biased pass only renormalisation turns a body, by a
    // rounding; a body at rest turns by less than that lag for many substeps (in a 50-row
    // pyramid three reads in four formed ΔR again at a rounding's tolerance).
    let dq = if (q - b.q_seen).length_squared() <= b.same_turn {
        solver.states[i].dq
    } else {
        b.q_seen = q;
        q * b.q0.inverse()
    };
    let mut turned = false;
    let w = match l {
        Some(&l) if b.dynamic && b.isotropic => b.inv_i.x_axis.x * l,
        Some(&l) if b.dynamic && b.locked_inertia != SolverBody::UNLOCKED => {
            let w;
            (w, turned) = locked_omega(solver, i, q, l);
            w
        }
        Some(&l) if b.dynamic => {
            let dr = Mat3A::from_quat(dq);
            // Turned more than the axes allow since they were formed: the contact axes take
            // the current inertia (see `ContactSolver::after_gather`).
            if 1.0 - q.dot(b.q_axes).abs() > AXES_TURN && q.is_finite() {
                b.inv_i = dr * b.inv_i_start * dr.transpose();
                b.i0 = dr * b.i_start * dr.transpose();
                b.q_axes = q;
                turned = true;
            }
            dr * (b.inv_i_start * (dr.transpose() * l))
        }
        _ => w.copied().unwrap_or(Vec3A::ZERO),
    };
    if turned {
        solver.turned.push(i as u32);
    }
    let b = &mut solver.bodies[i];
    let state = BodyState {
        v,
        w,
        dx: x - b.x0,
        dq,
    };
    b.w_in = w;
    // One test of three lane masks, not three branches.
    let finite = (state.v.is_finite_mask() & w.is_finite_mask() & state.dx.is_finite_mask()).all()
        && q.is_finite();
    if finite || !b.dynamic {
        solver.states[i] = if finite { state } else { BodyState::REST };
    } else {
        // A body that turned non-finite inside the step (it is quarantined at the next
        // position pass) must not pass NaN through its contacts: for the rest of the step
        // it is an immovable, motionless obstacle and is never written back.
        solver.states[i] = BodyState::REST;
        frozen.push(i as u32);
    }
}

/// Writes the solved velocities back.
pub(crate) fn scatter(solver: &mut ContactSolver, bodies: &mut Query<SolvedBody, ContactFilter>) {
    let pass = solver.order.begin(solver.bodies.len());
    let mut hits = 0;
    if solver.order.walk && solver.order.ready {
        hits = walk(
            solver,
            bodies.iter_mut(),
            |item| item.0,
            pass,
            |solver, i, item| {
                write(solver, i, item);
            },
        );
    }
    if hits < solver.bodies.len() {
        for i in 0..solver.bodies.len() {
            if solver.order.reached[i] != pass
                && let Ok(item) = bodies.get_mut(solver.bodies[i].entity)
            {
                solver.order.ready &= !solver.order.walk;
                write(solver, i, item);
            }
        }
    }
}

#[inline]
fn write(
    solver: &ContactSolver,
    i: usize,
    (_, _, _, mut v, l, _): bevy_ecs::query::QueryItem<'_, '_, SolvedBody<'_>>,
) {
    let (b, state) = (&solver.bodies[i], &solver.states[i]);
    if !b.dynamic {
        return;
    }
    v.0 = state.v;
    if let Some(mut l) = l {
        l.bypass_change_detection().0 += angular_impulse(b, state);
    }
}

/// I₀ Δω, the angular impulse of a pass.
#[inline(always)]
fn angular_impulse(b: &crate::collision::solver::SolverBody, state: &BodyState) -> Vec3A {
    let dw = state.w - b.w_in;
    // An isotropic body's tensor is an exact diagonal (see `Inertia::world_tensors`): the
    // scalar product is the matrix product without its added zeros.
    if b.isotropic {
        b.i0.x_axis.x * dw
    } else {
        b.i0 * dw
    }
}

/// ω = (P I P)⁺ L of solver body `i`, whose rotation is locked about some axis (see
/// [`crate::rigid::LockedAxes`]), at rotation `q`; its contact axes take the inertia at `q`
/// once it has turned past [`AXES_TURN`] (true then). The restricted inverse does not
/// follow a turn as R I⁻¹ Rᵀ does (the locked axes stay put in the world), so it is formed
/// again.
#[inline(never)]
fn locked_omega(solver: &mut ContactSolver, i: usize, q: glam::Quat, l: Vec3A) -> (Vec3A, bool) {
    let b = &mut solver.bodies[i];
    let Some(inertia) = solver.locked_inertias.get(b.locked_inertia as usize) else {
        return (Vec3A::ZERO, false);
    };
    let mut turned = false;
    if 1.0 - q.dot(b.q_axes).abs() > AXES_TURN && q.is_finite() {
        (b.i0, b.inv_i) = inertia.world_tensors(q);
        b.q_axes = q;
        turned = true;
    }
    (inertia.angular_velocity(q, l), turned)
}

/// [`write()`] to plain values: v ← the solved v, L += I₀ Δω. Nothing for a body that is not
/// dynamic.
#[inline(always)]
pub(crate) fn write_values(solver: &ContactSolver, i: usize, v: &mut Vec3A, l: Option<&mut Vec3A>) {
    let (b, state) = (&solver.bodies[i], &solver.states[i]);
    if !b.dynamic {
        return;
    }
    *v = state.v;
    if let Some(l) = l {
        *l += angular_impulse(b, state);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collision::solver::SolverBody;
    use bevy_ecs::system::SystemState;
    use glam::{Quat, Vec3};

    type Params = (
        ResMut<'static, ContactSolver>,
        Query<'static, 'static, SolvedBody<'static>, ContactFilter>,
    );

    fn body(world: &mut World, i: usize) -> Entity {
        world
            .spawn((
                Position::from(Vec3::new(i as f32, 0.0, 0.0)),
                Rotation(Quat::IDENTITY),
                LinearVelocity::from(Vec3::new(i as f32, 0.0, 0.0)),
                AngularMomentum::from(Vec3::ZERO),
                AngularVelocity::from(Vec3::ZERO),
            ))
            .id()
    }

    /// A world of six bodies; the solver holds the last four (unit mass and inertia).
    fn setup() -> (World, Vec<Entity>) {
        let mut world = World::new();
        let entities: Vec<Entity> = (0..6).map(|i| body(&mut world, i)).collect();
        let mut solver = ContactSolver::default();
        for &e in &entities[2..] {
            let i = solver.bodies.len() as u32;
            solver
                .bodies
                .push(SolverBody::at_origin(e, 1.0, Mat3A::IDENTITY));
            solver.index.insert(e, i);
        }
        solver.states = vec![BodyState::REST; solver.bodies.len() + 1];
        world.insert_resource(solver);
        (world, entities)
    }

    fn gather_in(world: &mut World, state: &mut SystemState<Params>) {
        let (mut solver, bodies) = state.get_mut(world).expect("the test world has the solver");
        gather(&mut solver, &bodies);
    }

    fn scatter_in(world: &mut World, state: &mut SystemState<Params>) {
        let (mut solver, mut bodies) = state.get_mut(world).expect("the test world has the solver");
        scatter(&mut solver, &mut bodies);
    }

    fn velocities(world: &World) -> Vec<f32> {
        let solver = world.resource::<ContactSolver>();
        solver.states[..solver.bodies.len()]
            .iter()
            .map(|s| s.v.x)
            .collect()
    }

    #[test]
    fn passes_follow_the_bodies_when_the_storage_order_changes_between_them() {
        let (mut world, e) = setup();
        let mut state = SystemState::<Params>::new(&mut world);
        gather_in(&mut world, &mut state);
        assert!(world.resource::<ContactSolver>().order.walk);
        assert_eq!(velocities(&world), [2.0, 3.0, 4.0, 5.0]);

        // Removing the first body moves the last one into its row: every solver body but
        // one now sits elsewhere in the walk.
        world.despawn(e[0]);
        for (k, &b) in e[2..].iter().enumerate() {
            world.get_mut::<LinearVelocity>(b).unwrap().0 = Vec3A::splat(10.0 * k as f32);
        }
        gather_in(&mut world, &mut state);
        assert_eq!(velocities(&world), [0.0, 10.0, 20.0, 30.0]);
        assert!(!world.resource::<ContactSolver>().order.ready);

        // The scatter after a missed walk writes each body exactly once: L += I₀ Δω.
        {
            let mut solver = world.resource_mut::<ContactSolver>();
            for s in &mut solver.states[..4] {
                s.v = Vec3A::new(-1.0, 0.0, 0.0);
                s.w = Vec3A::new(0.0, 2.0, 0.0);
            }
        }
        scatter_in(&mut world, &mut state);
        for &b in &e[2..] {
            assert_eq!(world.get::<LinearVelocity>(b).unwrap().0.x, -1.0);
            assert_eq!(world.get::<AngularMomentum>(b).unwrap().0.y, 2.0);
        }

        // The next gather records the new order and walks it again.
        gather_in(&mut world, &mut state);
        assert!(world.resource::<ContactSolver>().order.ready);
        assert_eq!(velocities(&world), [-1.0; 4]);
        scatter_in(&mut world, &mut state);
        for &b in &e[2..] {
            // ω read back as 2 (unit inertia), written unchanged: L stays 2.
            assert_eq!(world.get::<AngularMomentum>(b).unwrap().0.y, 2.0);
        }
    }

    #[test]
    fn a_few_solver_bodies_among_many_are_looked_up_not_walked() {
        let mut world = World::new();
        for i in 0..40 {
            body(&mut world, i);
        }
        let e = body(&mut world, 99);
        let mut solver = ContactSolver::default();
        solver
            .bodies
            .push(SolverBody::at_origin(e, 1.0, Mat3A::IDENTITY));
        solver.index.insert(e, 0);
        solver.states = vec![BodyState::REST; 2];
        world.insert_resource(solver);
        let mut state = SystemState::<Params>::new(&mut world);
        gather_in(&mut world, &mut state);
        let solver = world.resource::<ContactSolver>();
        assert!(!solver.order.walk);
        assert_eq!(solver.states[0].v.x, 99.0);
    }

    /// A turn just within `same_turn(reach)` moves a point `reach` out from the centre by
    /// at most `ANCHOR_LAG`, about any axis; twice that turn is past it. Past a reach of
    /// 0.87 m the rounding floor (1e-12) sets the limit.
    #[test]
    fn a_reused_turn_lags_an_anchor_by_at_most_the_tolerance() {
        for reach in [0.05f32, 0.5, 0.866] {
            let limit = same_turn(reach);
            assert!(limit > 1e-12);
            for axis in [Vec3::X, Vec3::new(1.0, 2.0, -0.5).normalize()] {
                // |q − 1|² = 4 sin²(θ/4), solved for the turn θ at the limit.
                let theta = 4.0 * (0.5 * f64::from(limit).sqrt()).asin();
                let q = glam::DQuat::from_axis_angle(axis.as_dvec3(), theta);
                let distance = (q - glam::DQuat::IDENTITY).length_squared();
                assert!((distance / f64::from(limit) - 1.0).abs() < 1e-6);
                let p = axis.any_orthonormal_vector().as_dvec3() * f64::from(reach);
                let moved = (q * p - p).length();
                assert!(
                    moved <= f64::from(ANCHOR_LAG) * 1.001,
                    "{reach} m: {moved} m"
                );
                let q2 = glam::DQuat::from_axis_angle(axis.as_dvec3(), 2.0 * theta);
                assert!((q2 * p - p).length() > f64::from(ANCHOR_LAG) * 1.9);
            }
        }
        assert_eq!(same_turn(10.0), 1e-12);
        assert_eq!(same_turn(0.0), 1e-12);
    }
}
