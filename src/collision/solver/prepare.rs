//! Constraint building, once per step: the step's contact pairs become solver bodies and
//! manifold constraints (anchors, lever arms, friction bases, warm-start impulses).

use bevy_ecs::prelude::*;
use glam::{Mat3A, Quat, Vec3, Vec3A};
use parry3d::math::Pose;

use crate::collision::ContactFilter;
use crate::collision::narrow_phase::fetch::Wanted;
use crate::collision::narrow_phase::pairs::LOOK_AHEAD;
use crate::collision::narrow_phase::points::MAX_POINTS;
use crate::collision::narrow_phase::{ActivePair, Contacts, FrozenGeometry};
use crate::collision::solver::{ContactSolver, FIXED, ManifoldConstraint, PointInput, SolverBody};
use crate::collision::{Collider, ContactSettings, Friction, Restitution, RestitutionThreshold};
use crate::collision::{part_pose, shape_pose};
use crate::core::rest::Sleeping;
use crate::integrator::ConstraintsActive;
use crate::particles::{LinearVelocity, Mass, Position};
use crate::rigid::{AngularVelocity, CenterOfMass, Inertia, Rotation};

/// Constraint building's reused buffers: the bodies of the step's contacts, the contact
/// pairs with their slots among them, and the bodies' sides.
type PrepareBuffers = (Wanted, Vec<(u32, u32, u32)>, Vec<Option<Side>>);

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

/// What only some bodies have, looked up apart (see `prepare_contacts`).
type Extras<'a> = (
    Option<&'a crate::rigid::Dominance>,
    Option<&'a crate::rigid::LockedAxes>,
);
type ExtrasFilter = Or<(
    With<crate::rigid::Dominance>,
    With<crate::rigid::LockedAxes>,
)>;

/// One side of the step's contacts as constraint building needs it, fetched once per step
/// however many pairs its body is in.
pub(crate) struct Side {
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
    /// How thin its shape is (m; see `ccd::thickness`).
    thin: f32,
    /// Its bounding radius about the centre of mass (m).
    reach: f32,
    friction: f32,
    restitution: f32,
    /// The collider's own restitution threshold (m/s), if it has one.
    threshold: Option<f32>,
    /// What a solver body is made of: mass (none for static colliders), whether the body
    /// moves (has a velocity and is awake), and inertia.
    mass: Option<Mass>,
    moves: bool,
    inertia: Option<Inertia>,
    /// A material written with a bad value (through `get_mut`): the body is quarantined and
    /// this step's contacts use the defaults.
    bad_material: Option<crate::core::error::Error>,
    /// Its [`crate::rigid::Dominance`] group.
    dominance: i8,
    /// Its [`crate::rigid::LockedAxes`]' translation bits.
    translation_locks: u8,
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
        // Checked where they are used, once per body in contact: a pass over every
        // collider's `Changed` materials cost 16–36 µs a step among 10,000 idle statics.
        use crate::core::quarantine::Validate;
        // A chain, not an array of four `Option<Error>`s: moving the errors through an
        // array cost about a hundred instructions per body even when all were `None`.
        let bad_material = friction
            .validate()
            .err()
            .or_else(|| restitution.validate().err())
            .or_else(|| threshold.and_then(|t| t.validate().err()))
            .or_else(|| com.and_then(|c| c.validate().err()));
        let (friction, restitution, threshold) = if bad_material.is_some() {
            (
                crate::collision::Friction::default().0,
                crate::collision::Restitution::default().0,
                None,
            )
        } else {
            (friction.0, restitution.0, threshold.map(|t| t.0))
        };
        Side {
            entity,
            round: Roundness::of(collider.shape()),
            thin: crate::collision::narrow_phase::ccd::thickness(collider.local_bounds()),
            reach: crate::collision::radius(collider, com),
            index: Side::UNSET,
            x: x.0,
            q: q.0,
            pose: shape_pose(x.0, q.0, com),
            v: v.map_or(Vec3A::ZERO, |v| v.0),
            w: w.map_or(Vec3A::ZERO, |w| w.0),
            friction,
            restitution,
            threshold,
            mass: mass.copied(),
            moves: v.is_some() && !sleeping,
            inertia: inertia.copied(),
            bad_material,
            dominance: 0,
            translation_locks: 0,
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
#[inline]
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
    // A locked rotation: ω = (P I P)⁺ L is formed from the inertia again as the body turns.
    let locked_inertia = match side.inertia {
        Some(i) if dynamic && i.is_locked() => {
            solver.locked_inertias.push(i);
            solver.locked_inertias.len() as u32 - 1
        }
        _ => SolverBody::UNLOCKED,
    };
    solver.translation_locks |= side.translation_locks != 0;
    let i = solver.bodies.len() as u32;
    solver.bodies.push(SolverBody {
        entity: side.entity,
        inv_mass: if dynamic { mass.inverse() } else { 0.0 },
        translation_locks: side.translation_locks,
        locked_inertia,
        inv_i,
        i0,
        inv_i_start: inv_i,
        i_start: i0,
        q_axes: q,
        x0: x,
        q0: q,
        q_seen: q,
        same_turn: crate::collision::solver::exchange::same_turn(side.reach),
        w_in: side.w,
        dynamic,
        isotropic: side.inertia.as_ref().is_some_and(Inertia::is_isotropic),
        deep: false,
        speed_in: 0.0,
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
    m: &crate::collision::narrow_phase::Manifold,
    centre: Vec3A,
    (xa, va, wa): (Vec3A, Vec3A, Vec3A),
    (xb, vb, wb): (Vec3A, Vec3A, Vec3A),
    surface: Vec3A,
) -> [Vec3A; 2] {
    // Sliding is measured against the surfaces' own motion (a conveyor belt's).
    let slide = (vb + wb.cross(centre - xb)) - (va + wa.cross(centre - xa)) - surface;
    let impulse = Vec3A::from(m.data.tangent);
    let normal = crate::collision::narrow_phase::points::kept_normal_impulse(m);
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
pub(crate) fn prepare_contacts(
    mut solver: ResMut<ContactSolver>,
    mut active: ResMut<ConstraintsActive>,
    mut contacts: ResMut<Contacts>,
    settings: Res<ContactSettings>,
    bodies: Query<PreparedBody, (With<Collider>, ContactFilter)>,
    mut buffers: Local<PrepareBuffers>,
    mut commands: Commands,
    hooks: Option<Res<crate::collision::narrow_phase::decisions::HookDecisions>>,
    reporting: Query<(), With<crate::collision::ContactReporting>>,
    extras: Query<Extras, ExtrasFilter>,
) {
    let s = &mut *solver;
    s.clear();
    s.reporting = !reporting.is_empty();
    let touch = 0.25 * settings.margin;
    let (wanted, pairs, sides) = &mut *buffers;
    wanted.clear();
    pairs.clear();
    // The pairs the narrow phase went through (in the broad phase's order, by slot), then
    // those of islands woken this step.
    for &ActivePair { slot, a, b } in &contacts.active {
        pairs.push((slot, wanted.slot(a) as u32, wanted.slot(b) as u32));
    }
    for &(a, b) in &contacts.woken {
        let Some((slot, _)) = contacts.solvable(a, b) else {
            continue;
        };
        pairs.push((slot, wanted.slot(a) as u32, wanted.slot(b) as u32));
    }
    sides.clear();
    sides.resize_with(wanted.len(), || None);
    wanted.fetch(&bodies, |b| b.0, |i, b| sides[i] = Some(Side::new(b)));
    // Looked up apart, and only in a world that has groups or locks: a column more in the
    // fetch above cost every contact scene 2–3 % of its preparation.
    if !extras.is_empty() {
        for side in sides.iter_mut().flatten() {
            if let Ok((dominance, locks)) = extras.get(side.entity) {
                side.dominance = dominance.map_or(0, |d| d.0);
                side.translation_locks = locks.map_or(0, |l| l.translation_bits());
            }
        }
    }
    for side in sides.iter().flatten() {
        if let Some(err) = &side.bad_material {
            commands
                .entity(side.entity)
                .try_insert(crate::core::quarantine::Quarantined {
                    reason: crate::core::quarantine::QuarantineReason::InvalidInput(err.clone()),
                });
        }
    }
    // Freezing a manifold's geometry is bookkeeping, not a change anyone listens for.
    let contacts = contacts.bypass_change_detection();
    for (k, &(slot, sa, sb)) in pairs.iter().enumerate() {
        // A chunk's states are read in one short loop first, so that their scattered
        // memory arrives together (see `PairTable::warm`).
        if k % LOOK_AHEAD == 0 {
            contacts
                .pairs
                .warm(pairs[k..].iter().take(LOOK_AHEAD).map(|p| p.0));
        }
        let Some(state) = contacts.pairs.at_mut(slot) else {
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
        let mut friction = settings.friction_rule.combine(a.friction, b.friction);
        let mut restitution = settings
            .restitution_rule
            .combine(a.restitution, b.restitution);
        // Dominance only between two dynamic bodies: static and kinematic ones take no
        // impulse anyway, and a dominant body must still stand on the ground.
        let dynamic = |i: u32| s.bodies.get(i as usize).is_some_and(|b| b.dynamic);
        let held = if dynamic(ia) && dynamic(ib) {
            crate::rigid::dominance::held_sides(a.dominance, b.dominance)
        } else {
            0
        };
        let mut surface = Vec3A::ZERO;
        if let Some(edit) = hooks.as_ref().and_then(|h| h.edit(slot)) {
            if !edit.enabled {
                continue;
            }
            friction = edit.friction.unwrap_or(friction);
            restitution = edit.restitution.unwrap_or(restitution);
            surface = edit.surface;
        }
        // The lower of the two colliders' own thresholds, else the world's.
        let threshold = match (a.threshold, b.threshold) {
            (Some(x), Some(y)) => x.min(y),
            (Some(x), None) | (None, Some(x)) => x,
            (None, None) => settings.restitution_threshold,
        };
        for (mi, m) in state
            .manifolds
            .iter_mut()
            .chain(state.cast.as_deref_mut())
            .enumerate()
        {
            if m.points.is_empty() {
                continue;
            }
            if m.data.frozen.stale {
                m.data.frozen = m.data.frozen.refresh(freeze(m, a, b, touch));
            }
            let f = &m.data.frozen;
            let n = Vec3A::from(f.n);
            let first = s.inputs.len() as u32;
            let kept = m.data.kept();
            let t = tangent_basis(
                n,
                m,
                a.x + Vec3A::from(f.centre[0]),
                (a.x, va, wa),
                (b.x, vb, wb),
                surface,
            );
            for (&k, arms) in kept.iter().zip(&f.arms) {
                let p = &m.points[usize::from(k)];
                let (r_a, r_b) = (Vec3A::from(arms[0]), Vec3A::from(arms[1]));
                let rel = (vb + wb.cross(r_b)) - (va + wa.cross(r_a));
                s.inputs.push(PointInput {
                    r_a,
                    r_b,
                    // The separation parry measured at the turned points, less what the
                    // solver adds back from the frozen arms at the start of the step.
                    base: p.dist - n.dot(r_b - r_a),
                    n_imp: p.data.normal,
                    approach: n.dot(rel),
                    source: u32::from(k),
                });
            }
            // An overlap deeper than a quarter of the thinner shape marks both bodies (see
            // `ContactSolver::limit_deep_speed`).
            let deepest = kept
                .iter()
                .map(|&k| m.points[usize::from(k)].dist)
                .fold(f32::INFINITY, f32::min);
            if -deepest
                > 0.25
                    * crate::collision::narrow_phase::ccd::pair_thickness(
                        a.thin,
                        b.thin,
                        settings.margin,
                    )
            {
                for i in [ia, ib] {
                    if let Some(body) = s.bodies.get_mut(i as usize) {
                        body.deep = true;
                    }
                }
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
                pair: slot,
                manifold: mi as u32,
                centre_a: Vec3A::from(f.centre[0]),
                centre_b: Vec3A::from(f.centre[1]),
                radius: f.radius,
                t_imp: [tangent.dot(t[0]), tangent.dot(t[1])],
                twist: m.data.twist,
                surface: [surface.dot(t[0]), surface.dot(t[1])],
                held,
            });
            s.edited |= held != 0 || surface != Vec3A::ZERO;
        }
    }
    s.build();
    active.0 = !s.manifolds.is_empty();
}

/// The normal and lever arms of `m` at the present poses of `a` and `b` (see
/// [`FrozenGeometry`]).
fn freeze(
    m: &crate::collision::narrow_phase::Manifold,
    a: &Side,
    b: &Side,
    touch: f32,
) -> FrozenGeometry {
    // A compound's manifold is in its part's frame; the part's pose in the compound comes
    // with the manifold.
    let (pose_a, pose_b) = (
        part_pose(&a.pose, m.subshape_pos1()),
        part_pose(&b.pose, m.subshape_pos2()),
    );
    let n = Vec3A::from(pose_a.rotation * m.local_n1);
    // A round side's points are anchored at its centre of curvature (see `Roundness`).
    let (round_a, round_b) = (a.round.radius(m.subshape1), b.round.radius(m.subshape2));
    let kept = m.data.kept();
    let mut mids = [Vec3A::ZERO; MAX_POINTS];
    let mut out = FrozenGeometry {
        n: Vec3::from(n),
        count: kept.len() as u8,
        stale: false,
        ..FrozenGeometry::default()
    };
    for ((mid, arms), &k) in mids.iter_mut().zip(&mut out.arms).zip(kept) {
        let p = &m.points[usize::from(k)];
        let (w_a, w_b) = (
            Vec3A::from(pose_a * p.local_p1),
            Vec3A::from(pose_b * p.local_p2),
        );
        *mid = 0.5 * (w_a + w_b);
        // A touching point acts at the middle of its two witness points. A speculative
        // one, with a gap still open, acts on each body where that body will touch:
        // anchored in the gap, its lever arms were as long as the gap (metres for a fast
        // body), and friction on them spun the body.
        let (p_a, p_b) = if p.dist > touch {
            (w_a, w_b)
        } else {
            (*mid, *mid)
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
        *arms = [Vec3::from(p_a - a.x), Vec3::from(p_b - b.x)];
    }
    // Friction acts at the kept points' centre; the twist's arm is their mean distance
    // from it.
    let mids = &mids[..kept.len()];
    let middle = mids.iter().sum::<Vec3A>() / kept.len() as f32;
    out.centre = [Vec3::from(middle - a.x), Vec3::from(middle - b.x)];
    out.radius = mids.iter().map(|&p| (p - middle).length()).sum::<f32>() / kept.len() as f32;
    out
}
