//! The narrow phase's systems: contact manifolds for the broad phase's pairs, and contact
//! messages.

use bevy_ecs::prelude::*;
use glam::{Vec3, Vec3A};
use parry3d::math::Pose;
use parry3d::query::{DefaultQueryDispatcher, PersistentQueryDispatcher};

use crate::collision::ContactFilter;
use crate::collision::broad_phase::BroadPhase;
use crate::collision::narrow_phase::fetch::Wanted;
use crate::collision::narrow_phase::pairs::LOOK_AHEAD;
use crate::collision::narrow_phase::points::{PointsKey, choose_changed_points};
use crate::collision::narrow_phase::{ActivePair, Contacts, Manifold, PairState, Recycle};
use crate::collision::{Collider, ContactEnded, ContactSettings, ContactStarted, Sensor};
use crate::collision::{radius, shape_pose};
use crate::core::rest::Sleeping;
use crate::core::time::PhysicsTime;
use crate::particles::{LinearVelocity, Position};
use crate::rigid::{AngularVelocity, CenterOfMass, Rotation};

/// The second part's pose in the first part's frame, from the second shape's pose in the
/// first's.
#[inline]
fn part_pose12(m: &crate::collision::narrow_phase::Manifold, pos12: &Pose) -> Pose {
    match (m.subshape_pos1(), m.subshape_pos2()) {
        (None, None) => *pos12,
        (p1, p2) => {
            let p1 = p1.copied().unwrap_or_default();
            let p2 = p2.copied().unwrap_or_default();
            p1.inverse() * *pos12 * p2
        }
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
    /// Farthest any point of the shape is from its centre of mass (m).
    reach: f32,
    /// How thin the shape is (m; see [`crate::collision::narrow_phase::ccd::thickness`]).
    thin: f32,
    /// Fastest speed of any point of the shape (m/s): |v| + |ω| r.
    speed: f32,
    /// The fastest its spin moves its surface along any direction (m/s; see
    /// [`crate::collision::radii::surface_swing`]).
    surface: f32,
    /// Farthest any point of the shape is from the shape's origin (m).
    extent: f32,
    /// The collider was replaced or changed since the last step.
    changed: bool,
    sensor: bool,
    /// It has a velocity (a dynamic or kinematic body's collider, or a particle's).
    moving: bool,
}

impl<'a> NarrowBody<'a> {
    fn cast_side(&self) -> crate::collision::narrow_phase::ccd::CastSide<'a> {
        crate::collision::narrow_phase::ccd::CastSide {
            shape: &**self.collider.shape(),
            pose: self.pose,
            velocity: self.velocity,
            spin: self.spin,
            centre: self.centre,
            swing: self.swing,
            reach: self.reach,
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
        reach,
        thin: crate::collision::narrow_phase::ccd::thickness([lo, hi]),
        speed,
        surface: w.map_or(0.0, |w| {
            crate::collision::radii::surface_swing(
                w.0.length(),
                reach,
                collider.inner_radius(),
                com.map_or(Vec3::ZERO, |c| c.0),
            )
        }),
        extent: lo.abs().max(hi.abs()).length(),
        changed,
        sensor,
        moving: v.is_some(),
    }
}

/// The fastest any point of the smaller side moves against the other (m/s): the relative
/// velocity at its centre of mass, with the larger side's spin taken about the larger
/// side's own centre, plus the two spins' difference over the smaller side's reach. Contact
/// points lie within the smaller side, so this bounds how fast they close.
///
/// Why: a large turning body (Box3D's washer drum, 20 m across at 25°/s) swings its far
/// points at 9 m/s, and taking that as the pair's speed cast every cube in it every step,
/// though the drum's wall near a cube moves with it.
fn local_sweep(a: &NarrowBody, b: &NarrowBody) -> f32 {
    let (sa, sb) = (a.cast_side(), b.cast_side());
    let (a_small, there) = crate::collision::narrow_phase::ccd::at_smaller(&sa, &sb);
    let small = if a_small { &sa } else { &sb };
    (small.velocity - there).length() + (sa.spin - sb.spin).length() * small.reach
}

/// The normal of the pair's manifold and the gap along it, if it is a separating axis
/// (parry keeps the separating axis its search found, with or without points). `n1` is in
/// `a`'s shape frame; the gap (m) is how far `b` lies beyond `a` along it, at least 0.
///
/// Why it is tested rather than trusted: an overlap's normal can point out of the far side
/// of a thin wall, and box against box keeps the normal of a contact long gone while the
/// two are apart (measured: a spinning plank trusted such a normal and went through a 1 cm
/// wall). Why only the normal parry found: the points are measured along it, and along
/// another axis (the line between the centres of mass) a leaning box's far corner lost its
/// speculative point, and a column of 200 boxes strayed 0.74 m where it stands.
fn separating_axis(
    a: &NarrowBody,
    b: &NarrowBody,
    pos12: &Pose,
    manifolds: &[Manifold],
) -> Option<Separation> {
    // A compound's manifolds are in its parts' frames.
    let [m] = manifolds else { return None };
    // A point that overlapped in the last step all but rules the normal out, and a resting
    // pair's is such: the support points are not worth asking (asked, they took 8 % of the
    // full 100-row pyramid's profile samples). Going without only keeps the whole speeds.
    if m.points.iter().any(|p| p.dist < 0.0) {
        return None;
    }
    let n1 = m.local_n1.try_normalize()?;
    let gap = gap_along(a.collider, b.collider, pos12, n1)?;
    (gap >= 0.0).then_some(Separation { n1, gap })
}

/// The gap between the two sides' bounding spheres (m; negative where they overlap): each
/// side's [`NarrowBody::reach`] about its centre of mass. No two points of the shapes are
/// closer.
fn spheres_gap(a: &NarrowBody, b: &NarrowBody) -> f32 {
    (b.pose * b.centre - a.pose * a.centre).length() - a.reach - b.reach
}

/// A separating axis of a pair (see [`separating_axis`]).
#[derive(Clone, Copy)]
struct Separation {
    /// The axis, from the first side to the second, in the first side's shape frame.
    n1: Vec3,
    /// How far apart the two are along it (m).
    gap: f32,
}

/// How far `b` lies beyond `a` along the unit `n1` (in `a`'s frame; m, negative where
/// they overlap along it), by the shapes' support points; `None` unless both shapes have
/// one (compounds, meshes and planes do not).
#[must_use]
fn gap_along(a: &Collider, b: &Collider, pos12: &Pose, n1: Vec3) -> Option<f32> {
    let n2 = pos12.rotation.inverse() * -n1;
    Some(pos12.translation.dot(n1) - support_along(a, n1)? - support_along(b, n2)?)
}

/// The farthest any point of `c` reaches along `dir` in its own frame (m).
#[inline]
fn support_along(c: &Collider, dir: Vec3) -> Option<f32> {
    use parry3d::shape::SupportMap;
    match c.laned_hull() {
        Some(hull) => Some(hull.local_support_point(dir).dot(dir)),
        None => Some(
            c.shape()
                .as_support_map()?
                .local_support_point(dir)
                .dot(dir),
        ),
    }
}

/// How fast the pair can close within the step (m/s), for the prediction distance.
///
/// Each side may keep its velocity or be stopped by a third body mid-step, so the bound is
/// each side's speed toward the other, summed, plus how fast each one's spin moves its
/// surface ([`crate::collision::radii::surface_swing`]; none for a ball about its centre).
/// "Toward" is along a separating axis (see [`separating_axis`]): to touch, the two must
/// close the gap along it. Without one it is each side's whole speed.
///
/// Why: Box3D's pile drops 5,120 hulls side by side. Counting the whole speed of each gave
/// neighbours falling together a prediction of metres, and parry then found speculative
/// points between every pair of them, three times rapier's points, that could never close.
/// A hull above another that lands still sees the full speed along their normal.
fn approach_speed(a: &NarrowBody, b: &NarrowBody, separation: Option<Separation>) -> f32 {
    match separation {
        Some(Separation { n1, .. }) => {
            let n = a.pose.rotation * n1;
            a.velocity.dot(n).max(0.0) + (-b.velocity.dot(n)).max(0.0) + a.surface + b.surface
        }
        None => a.speed + b.speed,
    }
}

/// parry's manifolds for a pair; two hulls go straight to parry's hull-against-hull
/// manifold with their vertices in columns (see [`crate::collision::support`]), which is
/// what parry's dispatcher calls for them, with a faster support point.
fn contact_manifolds(
    a: &Collider,
    b: &Collider,
    pos12: &Pose,
    reach: f32,
    state: &mut PairState,
) -> Result<(), parry3d::query::Unsupported> {
    if let (Some(ha), Some(hb)) = (a.laned_hull(), b.laned_hull()) {
        if state.manifolds.is_empty() {
            state.manifolds.push(Manifold::new());
        }
        parry3d::query::details::contact_manifold_pfm_pfm(
            pos12,
            &ha,
            0.0,
            None,
            &hb,
            0.0,
            None,
            reach,
            &mut state.manifolds[0],
        );
        return Ok(());
    }
    DefaultQueryDispatcher.contact_manifolds(
        pos12,
        &**a.shape(),
        &**b.shape(),
        reach,
        &mut state.manifolds,
        &mut state.workspace,
    )
}

/// Runs a parry call; a panic inside it sets `failed` and gives `None`.
#[inline]
fn guarded<T>(failed: &mut bool, f: impl FnOnce() -> T) -> Option<T> {
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).ok();
    *failed |= r.is_none();
    r
}

/// What every pair's update reads of the step.
struct StepFrame {
    /// [`ContactSettings::margin`] (m).
    margin: f32,
    /// The step (s).
    dt: f32,
    /// How far a pair may move and keep its points (m; see [`Recycle`]).
    window: f32,
    /// The separation under which a pair touches (m).
    touch: f32,
}

/// Brings a pair's manifolds (and its impact cast) up to date; returns whether the two
/// touch. Sets `failed` when parry failed on them and `updated` when the manifolds were
/// found again rather than reused.
fn update_manifolds(
    ca: &NarrowBody,
    cb: &NarrowBody,
    state: &mut PairState,
    frame: &StepFrame,
    scratch: &mut Vec<(Vec3A, f32, bool)>,
    failed: &mut bool,
    updated: &mut bool,
) -> bool {
    let (pose_a, pose_b) = (&ca.pose, &cb.pose);
    let pos12 = pose_a.inverse() * *pose_b;
    let separation = separating_axis(ca, cb, &pos12, &state.manifolds);
    let prediction = frame.margin + approach_speed(ca, cb, separation) * frame.dt;
    let changed = ca.changed || cb.changed;
    match state.recycle {
        Some(r) if !changed && r.holds(&pos12, cb.extent, prediction, frame.window) => {
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
            *updated = true;
            let reach = prediction + frame.window;
            let before = PointsKey::of(&state.manifolds);
            // Two sides farther apart than the reach along an axis have no points, and
            // parry's search would cost as much as for a contact to find none. Boxes overlap
            // where the shapes in them do not (a pile of hulls falling side by side, their
            // boxes stretched by the fall): their bounding spheres tell most such pairs.
            // Their normals stay, to start parry's next search.
            let result =
                match separation.is_some_and(|s| s.gap > reach) || spheres_gap(ca, cb) > reach {
                    true => {
                        for m in &mut state.manifolds {
                            m.points.clear();
                        }
                        Ok(())
                    }
                    false => guarded(&mut *failed, || {
                        contact_manifolds(ca.collider, cb.collider, &pos12, reach, state)
                    })
                    .unwrap_or(Err(parry3d::query::Unsupported)),
                };
            // Two shapes cannot overlap by more than the narrower one's width,
            // at most twice its reach. A deeper point is parry's GJK and EPA
            // failing on a degenerate simplex (Box3D's pile: a hull 5.5 m "into"
            // the ground along (−1, 1, −1)/√3), and pushing it out would kick the
            // body sideways at the push-out speed: the pair starts afresh.
            let deepest = 2.0 * ca.reach.min(cb.reach) + frame.margin;
            let impossible =
                (state.manifolds.iter().flat_map(|m| &m.points)).any(|p| p.dist < -deepest);
            let result = match impossible {
                true => Err(parry3d::query::Unsupported),
                false => result,
            };
            if result.is_err() {
                state.manifolds.clear();
                state.workspace = None;
            }
            // parry keeps a manifold's points while the pose holds still (two
            // hulls falling together), whatever today's reach: past it they
            // cannot close within the step.
            for m in &mut state.manifolds {
                m.points.retain(|p| p.dist <= reach);
            }
            state.recycle =
                (frame.window > 0.0 && result.is_ok()).then_some(Recycle { pos12, reach });
            choose_changed_points(&mut state.manifolds, before, scratch);
        }
    }
    let thin = crate::collision::narrow_phase::ccd::pair_thickness(ca.thin, cb.thin, frame.margin);
    let fast = |sweep| crate::collision::narrow_phase::ccd::is_fast(sweep, frame.dt, thin);
    // The local sweep is the finer bound and costs more: it is only asked of
    // pairs the whole relative speed would cast.
    let whole = (cb.velocity - ca.velocity).length() + ca.swing.max(cb.swing);
    if fast(whole) && fast(whole.min(local_sweep(ca, cb))) {
        let manifolds = &state.manifolds;
        state.cast = guarded(&mut *failed, || {
            crate::collision::narrow_phase::ccd::impact_manifold(
                &ca.cast_side(),
                &cb.cast_side(),
                frame.dt,
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
        .any(|p| p.dist < frame.touch)
}

/// A slot no pair holds.
const NO_SLOT: u32 = u32::MAX;

/// How often (steps) the pair table is put back in the broad phase's order.
const REORDER_EVERY: u64 = 16;

/// The narrow phase's reused buffers: the bodies of the step's pairs, the pairs' slots
/// among them, the point list of the point choice, and the pairs' slots in the table.
type NarrowBuffers = (Wanted, Vec<(u32, u32)>, Vec<(Vec3A, f32, bool)>, TableSlots);

/// Each broad-phase pair's slot in the pair table ([`NO_SLOT`]: not looked up), for the
/// versions of both lists it was made from.
///
/// Why: a scene at rest has the same pairs in the same slots step after step, and finding
/// each in the table's index was a hash probe per pair (2–3 % of Box3D's pyramids' samples).
#[derive(Default)]
pub(crate) struct TableSlots {
    pairs: Option<crate::collision::slots::Stamp>,
    table: Option<crate::collision::slots::Stamp>,
    slots: Vec<u32>,
}

/// Persistent manifolds for every candidate pair; start/end messages.
#[allow(clippy::too_many_arguments)] // two message writers and the queries of one pass
pub(crate) fn update_contacts(
    mut contacts: ResMut<Contacts>,
    bp: Res<BroadPhase>,
    time: Res<PhysicsTime>,
    settings: Res<ContactSettings>,
    colliders: Query<NarrowCollider, ContactFilter>,
    mut started: MessageWriter<ContactStarted>,
    mut ended: MessageWriter<ContactEnded>,
    sleeping: Query<(), With<Sleeping>>,
    mut buffers: Local<NarrowBuffers>,
    mut commands: Commands,
    hooks: Option<Res<crate::collision::narrow_phase::decisions::HookDecisions>>,
) {
    let (wanted, pair_slots, scratch, known) = &mut *buffers;
    if known.pairs != Some(bp.pairs_stamp())
        || known.table != Some(contacts.pairs.stamp())
        || known.slots.len() != bp.pairs.len()
    {
        known.slots.clear();
        known.slots.resize(bp.pairs.len(), NO_SLOT);
    }
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
    contacts.active.clear();
    let step = contacts.step;
    let touch = 0.25 * settings.margin;
    let window = match settings.recycle_distance {
        r if r > 0.0 => r.min(settings.margin),
        // Zero, negative or not a number: no reuse.
        _ => 0.0,
    };
    let frame = StepFrame {
        margin: settings.margin,
        dt,
        window,
        touch,
    };
    let mut updated = 0;
    let mut slots = [NO_SLOT; LOOK_AHEAD];
    for ((chunk, chunk_slots), chunk_known) in bp
        .pairs
        .chunks(LOOK_AHEAD)
        .zip(pair_slots.chunks(LOOK_AHEAD))
        .zip(known.slots.chunks_mut(LOOK_AHEAD))
    {
        // A chunk's pairs are found in the index, then their states read, each in a short
        // loop of its own whose cache misses overlap (see `PairTable::warm`).
        for (((&key, &(sa, sb)), slot), known) in chunk
            .iter()
            .zip(chunk_slots)
            .zip(&mut slots)
            .zip(chunk_known)
        {
            *slot = match bodies[sa as usize].is_some() && bodies[sb as usize].is_some() {
                true if *known != NO_SLOT => {
                    contacts.pairs.mark_seen(*known, step);
                    *known
                }
                true => {
                    *known = contacts.pairs.see(key, step);
                    *known
                }
                false => NO_SLOT,
            };
        }
        contacts.pairs.warm(slots[..chunk.len()].iter().copied());
        for ((&(a, b), &(sa, sb)), &slot) in chunk.iter().zip(chunk_slots).zip(&slots) {
            let (Some(ca), Some(cb)) = (&bodies[sa as usize], &bodies[sb as usize]) else {
                continue;
            };
            let (pose_a, pose_b) = (&ca.pose, &cb.pose);
            let sensor = ca.sensor || cb.sensor;
            let Some(state) = contacts.pairs.at_mut(slot) else {
                continue;
            };
            state.sensor = sensor;
            state.cast = None;
            if hooks.as_ref().is_some_and(|h| h.rejects(a, b)) {
                turn_away(state, a, b, &mut ended);
                continue;
            }
            // parry can still panic on shapes at the edge of its domain (EPA's index panic was
            // seen on huge or badly turned shapes): each parry call is guarded, and one bad pair
            // loses its contact and its moving sides are quarantined while the step goes on.
            let (mut failed, mut renewed) = (false, false);
            let touching = {
                if sensor {
                    let (sa, sb) = (&**ca.collider.shape(), &**cb.collider.shape());
                    guarded(&mut failed, || {
                        parry3d::query::intersection_test(pose_a, sa, pose_b, sb)
                    })
                    .is_some_and(|r| r.is_ok_and(|i| i.intersecting))
                } else {
                    update_manifolds(ca, cb, state, &frame, scratch, &mut failed, &mut renewed)
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
            updated += usize::from(renewed);
            // The solver takes the pairs with points, by slot, without reading them again.
            if !sensor && state.solved().any(|m| !m.points.is_empty()) {
                contacts.active.push(ActivePair { slot, a, b });
            }
        }
    }
    contacts.updated = updated;
    // What `known` holds is true of the lists as they are now; removing or reordering
    // pairs below gives the table a new version, and the next step looks them up again.
    (known.pairs, known.table) = (Some(bp.pairs_stamp()), Some(contacts.pairs.stamp()));
    let mut gone: Vec<_> = contacts
        .pairs
        .unseen(step)
        // A pair with a sleeping side is not re-formed while it sleeps, but it still
        // touches: keep it (and its warm-start impulses) until the island wakes.
        .filter(|((a, b), _)| !(sleeping.contains(*a) || sleeping.contains(*b)))
        .collect();
    gone.sort_unstable_by_key(|g| g.0);
    for ((a, b), touching) in gone {
        contacts.pairs.remove(&(a, b));
        if touching {
            ended.write(ContactEnded { a, b });
        }
    }
    if step.is_multiple_of(REORDER_EVERY) {
        // Only when the pairs are out of order: a resting scene keeps the order it was
        // found in, and copying its manifolds would only cost.
        let contacts = &mut *contacts;
        let jumps = contacts
            .active
            .windows(2)
            .filter(|w| w[1].slot != w[0].slot.wrapping_add(1))
            .count();
        if 4 * jumps > contacts.active.len() {
            contacts
                .pairs
                .reorder(contacts.active.iter_mut().map(|p| &mut p.slot));
        }
    }
}

/// A filter hook turned the pair away: no contact, and the next contact it is allowed
/// starts cold. Out of line: the narrow phase's loop stays as small as without hooks.
#[cold]
#[inline(never)]
fn turn_away(state: &mut PairState, a: Entity, b: Entity, ended: &mut MessageWriter<ContactEnded>) {
    state.manifolds.clear();
    state.workspace = None;
    state.recycle = None;
    if state.touching {
        state.touching = false;
        ended.write(ContactEnded { a, b });
    }
}

/// Triggers [`crate::collision::ContactStart`] / [`crate::collision::ContactEnd`] on opted-in bodies, for the
/// messages written since this system last ran (each message once).
pub(crate) fn trigger_contact_events(
    mut commands: Commands,
    mut started: MessageReader<ContactStarted>,
    mut ended: MessageReader<ContactEnded>,
    enabled: Query<(), With<crate::collision::CollisionEventsEnabled>>,
) {
    for m in started.read() {
        for (entity, other) in [(m.a, m.b), (m.b, m.a)] {
            if enabled.contains(entity) {
                commands.trigger(crate::collision::ContactStart { entity, other });
            }
        }
    }
    for m in ended.read() {
        for (entity, other) in [(m.a, m.b), (m.b, m.a)] {
            if enabled.contains(entity) {
                commands.trigger(crate::collision::ContactEnd { entity, other });
            }
        }
    }
}
