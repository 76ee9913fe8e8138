//! Sleeping: bodies at rest stop being simulated until something disturbs them.
//!
//! Every step, dynamic bodies with a [`Collider`] are grouped into islands by the contacts
//! that touch (union–find over [`Contacts`]). A body's [`SleepTimer`] counts how long its
//! speed has stayed below [`SleepSettings::linear`] and [`SleepSettings::angular`]; when every
//! body of an island has been still for [`SleepSettings::time`], the whole island gets
//! [`Sleeping`], its velocities are zeroed, and no integrating system visits it again (an
//! archetype filter: a sleeping body costs nothing per substep). Sleeping bodies stay solid:
//! awake bodies collide with them as with static ones.
//!
//! **Waking.** An island with a sleeping and a moving member wakes whole, within the step in
//! which an awake body touches it or could reach it (so whatever hits a sleeping stack
//! pushes it in the step of impact, not as a wall). Game code wakes a body by writing its
//! position, rotation or velocity, or by adding an external force, torque or impulse; or by
//! removing [`Sleeping`] directly.
//!
//! **Joints** join islands as contacts do: a jointed chain sleeps whole and wakes whole, a
//! body jointed to a moving kinematic body (or to a body that never sleeps) stays awake, and
//! putting a joint on or taking one off (breaking it included) wakes its bodies.
//!
//! Particles, meshes and bodies attached to springs never sleep: springs act only between
//! awake bodies, and a spring's pull is not a contact that the islands could see.

use bevy_platform::collections::HashMap;

use bevy_ecs::prelude::*;

use crate::collision::{Collider, ContactSettings, Contacts};
use crate::core::plugin::WorldPlugin;
use crate::core::quarantine::Quarantined;
use crate::core::schedule::{CollisionSystems, PhysicsSchedule, PrepareSystems, add_own_systems};
use crate::core::time::PhysicsTime;
use crate::joints::{self, Kinds};
use crate::particles::{ExternalForce, ExternalImpulse, LinearVelocity, Mass, Position};
use crate::rigid::{
    AngularMomentum, AngularVelocity, ExternalForceAtPoint, ExternalImpulseAtPoint, ExternalTorque,
    Rotation,
};
use crate::springs::Spring;

pub use crate::core::rest::{SleepTimer, Sleeping, SleepingDisabled};

/// When islands fall asleep.
#[derive(serde::Serialize, serde::Deserialize, Resource, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Resource))]
pub struct SleepSettings {
    /// Whether bodies may sleep at all.
    pub enabled: bool,
    /// Speed below which a body counts as still (m/s).
    pub linear: f32,
    /// Spin below which a body counts as still (rad/s).
    pub angular: f32,
    /// How long a whole island must stay still before it sleeps (s).
    pub time: f32,
}

impl Default for SleepSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            linear: 0.05,
            angular: 0.05,
            time: 0.5,
        }
    }
}

/// Island sleeping for bodies with colliders.
#[derive(Debug, Default, Clone, Copy)]
pub struct SleepPlugin;

impl WorldPlugin for SleepPlugin {
    fn build(&self, world: &mut World) {
        crate::core::restore::init::<SleepSettings>(world);
        add_own_systems(
            world,
            PhysicsSchedule,
            (
                wake_on_user_change,
                wake_on_joint_change,
                wake_on_structural_change,
                update_islands,
            )
                .chain()
                .run_if(any_with_component::<Collider>)
                .in_set(PrepareSystems::Sleep),
        );
        add_own_systems(
            world,
            PhysicsSchedule,
            wake_hit_islands
                .run_if(any_with_component::<Sleeping>)
                .in_set(CollisionSystems::Wake),
        );
        world.add_observer(restart_stillness);
    }
}

/// However a body wakes (game code removing [`Sleeping`] included), it counts its stillness
/// afresh: with the old count it fell straight back asleep in the next step.
fn restart_stillness(woken: On<Remove<Sleeping>>, mut timers: Query<&mut SleepTimer>) {
    if let Ok(mut timer) = timers.get_mut(woken.entity) {
        timer.0 = 0.0;
    }
}

type Disturbed = (
    With<Sleeping>,
    Or<(
        Changed<Position>,
        Changed<Rotation>,
        Changed<LinearVelocity>,
        Changed<AngularVelocity>,
        Changed<AngularMomentum>,
        Changed<ExternalForce>,
        Changed<ExternalImpulse>,
        Changed<ExternalTorque>,
        Changed<ExternalForceAtPoint>,
        Changed<ExternalImpulseAtPoint>,
    )>,
);

/// Game code touched a sleeping body: wake it. (hooke never writes a sleeping body, so any
/// change is the game's.)
fn wake_on_user_change(
    mut commands: Commands,
    mut disturbed: Query<(Entity, &mut SleepTimer), Disturbed>,
) {
    for (e, mut timer) in &mut disturbed {
        // A woken body starts its stillness count afresh, or it would fall straight back asleep.
        timer.0 = 0.0;
        commands.entity(e).remove::<Sleeping>();
    }
}

/// Game code changed a joint (a motor set, a limit moved): wake what it holds. (hooke never
/// writes a joint's kind, so any change is the game's.)
fn wake_on_joint_change(
    mut commands: Commands,
    changed: Query<Kinds, (Without<Quarantined>, ChangedJoint)>,
    mut sleepers: Query<&mut SleepTimer, With<Sleeping>>,
) {
    for j in &changed {
        let Some(ends) = joints::bodies(j) else {
            continue;
        };
        for e in ends.a.into_iter().chain([ends.b]) {
            if let Ok(mut timer) = sleepers.get_mut(e) {
                timer.0 = 0.0;
                commands.entity(e).remove::<Sleeping>();
            }
        }
    }
}

/// A joint of any kind changed.
type ChangedJoint = Or<(
    Changed<joints::SphericalJoint>,
    Changed<joints::RevoluteJoint>,
    Changed<joints::FixedJoint>,
    Changed<joints::PrismaticJoint>,
    Changed<joints::DistanceJoint>,
)>;

/// A collider was removed, despawned, replaced or resized: every sleeping island that touched
/// it wakes, so that a stack whose middle box or ground went falls (it floated before).
fn wake_on_structural_change(
    mut commands: Commands,
    changes: Option<Res<crate::collision::ColliderChanges>>,
    contacts: Res<Contacts>,
    mut sleepers: Query<&mut SleepTimer, With<Sleeping>>,
) {
    let Some(changes) = changes.filter(|c| !c.entities().is_empty()) else {
        return;
    };
    if sleepers.is_empty() {
        return;
    }
    let changed: bevy_platform::collections::HashSet<Entity> =
        changes.entities().iter().copied().collect();
    let touching = contacts.touching();
    let mut stack: Vec<Entity> = touching
        .iter()
        .filter_map(|&(a, b)| {
            if changed.contains(&a) {
                Some(b)
            } else if changed.contains(&b) {
                Some(a)
            } else {
                None
            }
        })
        .chain(changed.iter().copied())
        .filter(|&e| sleepers.contains(e))
        .collect();
    // The islands: through the touching pairs of sleepers.
    let mut woken = bevy_platform::collections::HashSet::new();
    while let Some(e) = stack.pop() {
        if !woken.insert(e) {
            continue;
        }
        for &(a, b) in &touching {
            let other = if a == e {
                b
            } else if b == e {
                a
            } else {
                continue;
            };
            if !woken.contains(&other) && sleepers.contains(other) {
                stack.push(other);
            }
        }
    }
    let mut woken: Vec<Entity> = woken.into_iter().collect();
    woken.sort_unstable();
    for e in woken {
        if let Ok(mut timer) = sleepers.get_mut(e) {
            timer.0 = 0.0;
        }
        commands.entity(e).remove::<Sleeping>();
    }
}

/// Wakes, within the step, every sleeping island that an awake body is about to hit: one
/// that touches it, or that could close the gap in this step at its current speed. (Waiting
/// for the next step's islands would let the sleeper stand like a wall for the step of
/// impact: a ball fired at a sleeping box stopped dead and the box never moved.) Runs
/// between the narrow phase and the contact constraints; its removals of [`Sleeping`] are
/// applied before the constraints are built.
#[allow(clippy::too_many_arguments)] // system parameters: queries and resources
fn wake_hit_islands(
    mut commands: Commands,
    time: Res<PhysicsTime>,
    settings: Res<ContactSettings>,
    mut contacts: ResMut<Contacts>,
    sleepers: Query<(), With<Sleeping>>,
    movers: Query<(&LinearVelocity, Option<&Mass>), Without<Sleeping>>,
    mut timers: Query<&mut SleepTimer>,
    jointed: Query<Kinds, Without<Quarantined>>,
) {
    let (dt, touch) = (time.dt(), 0.25 * settings.margin);
    let mut woken = Vec::new();
    let mut asleep_pairs = Vec::new();
    // A joint between two sleepers carries the waking as a touching contact does.
    let mut asleep_joints = Vec::new();
    for j in &jointed {
        if let Some(&joints::JointBodies { a: Some(a), b, .. }) = joints::bodies(j)
            && sleepers.contains(a)
            && sleepers.contains(b)
        {
            asleep_joints.push((a.min(b), a.max(b)));
        }
    }
    // The broad phase pairs a sleeper with nothing static either: (sleeper, pair).
    let mut grounded = Vec::new();
    for (&(a, b), state) in contacts.pairs.iter() {
        if state.sensor {
            continue;
        }
        let (sa, sb) = (sleepers.contains(a), sleepers.contains(b));
        if sa && sb {
            if state.touching {
                asleep_pairs.push((a, b));
            }
            continue;
        }
        let (sleeper, other) = match (sa, sb) {
            (true, false) => (a, b),
            (false, true) => (b, a),
            _ => continue,
        };
        // Static colliders (no velocity) and resting pinned bodies wake nothing.
        let Ok((v, mass)) = movers.get(other) else {
            if state.touching {
                grounded.push((sleeper, (a, b)));
            }
            continue;
        };
        let speed = v.0.length();
        if mass.is_none_or(|m| m.is_pinned()) && speed == 0.0 {
            continue;
        }
        let reach = touch + speed * dt;
        let points = state.manifolds.iter().flat_map(|m| &m.points);
        if points.into_iter().any(|p| p.dist < reach) {
            woken.push(sleeper);
        }
    }
    if woken.is_empty() {
        return;
    }
    // The whole island wakes: spread over the touching pairs and the joints of sleepers.
    woken.sort_unstable();
    woken.dedup();
    asleep_pairs.sort_unstable();
    asleep_joints.sort_unstable();
    let mut grew = true;
    while grew {
        grew = false;
        for &(a, b) in asleep_pairs.iter().chain(&asleep_joints) {
            let (ia, ib) = (woken.binary_search(&a), woken.binary_search(&b));
            let new = match (ia, ib) {
                (Ok(_), Err(at)) => Some((b, at)),
                (Err(at), Ok(_)) => Some((a, at)),
                _ => None,
            };
            if let Some((e, at)) = new {
                woken.insert(at, e);
                grew = true;
            }
        }
    }
    for &e in &woken {
        if let Ok(mut timer) = timers.get_mut(e) {
            timer.0 = 0.0;
        }
        commands.entity(e).remove::<Sleeping>();
    }
    let is_woken = |e: &Entity| woken.binary_search(e).is_ok();
    contacts.woken.extend(
        asleep_pairs
            .into_iter()
            .filter(|(a, b)| is_woken(a) && is_woken(b)),
    );
    grounded.sort_unstable();
    contacts.woken.extend(
        grounded
            .into_iter()
            .filter(|(s, _)| is_woken(s))
            .map(|(_, p)| p),
    );
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

type SleepBody<'a> = (
    Entity,
    &'a Mass,
    &'a mut LinearVelocity,
    Option<&'a mut AngularVelocity>,
    Option<&'a mut AngularMomentum>,
    &'a mut SleepTimer,
    Has<Sleeping>,
    Has<SleepingDisabled>,
);

/// Buffers of [`update_islands`], kept so the per-step pass does not allocate.
#[derive(Default)]
struct IslandScratch {
    index: HashMap<Entity, usize>,
    still: Vec<bool>,
    asleep: Vec<bool>,
    entities: Vec<Entity>,
    parent: Vec<usize>,
    island_still: Vec<bool>,
    moving_pinned: Vec<Entity>,
}

/// What holds one side of a joint, as the islands see it.
enum JointSide {
    /// A body of the islands.
    Island(usize),
    /// The world, a pinned body at rest, or a body gone or quarantined (the joint is inert).
    Still,
    /// A moving kinematic body, or a dynamic body that never sleeps (one without a collider of
    /// its own): its partner stays awake.
    Moving,
}

/// Bodies outside the islands, read for the joints they hold (disjoint from [`SleepFilter`]).
type Outsiders<'w, 's> = Query<
    'w,
    's,
    (
        Option<&'static Mass>,
        Option<&'static LinearVelocity>,
        Option<&'static AngularVelocity>,
        Has<Quarantined>,
    ),
    Or<(
        Without<Collider>,
        With<Quarantined>,
        With<crate::collision::ColliderOf>,
    )>,
>;

/// Colliders that sleep on their own: not quarantined, not a part of another body.
type SleepFilter = (
    With<Collider>,
    Without<Quarantined>,
    Without<crate::collision::ColliderOf>,
);

/// Timers, islands, and the sleep/wake decisions.
#[allow(clippy::too_many_arguments)] // system parameters: queries, resources and a Local
fn update_islands(
    mut commands: Commands,
    settings: Res<SleepSettings>,
    time: Res<PhysicsTime>,
    contacts: Res<Contacts>,
    springs: Query<&Spring>,
    jointed: Query<Kinds, Without<Quarantined>>,
    outsiders: Outsiders,
    sleepers: Query<Entity, With<Sleeping>>,
    mut bodies: Query<SleepBody, SleepFilter>,
    mut scratch: Local<IslandScratch>,
) {
    if !settings.enabled {
        // No islands to build; just make sure nothing stays asleep.
        for e in &sleepers {
            commands.entity(e).remove::<Sleeping>();
        }
        return;
    }
    let dt = time.dt();
    let IslandScratch {
        index,
        still,
        asleep,
        entities,
        parent,
        island_still,
        moving_pinned,
    } = &mut *scratch;
    index.clear();
    still.clear();
    asleep.clear();
    entities.clear();
    moving_pinned.clear();
    for (e, m, v, w, _, mut timer, sleeping, disabled) in &mut bodies {
        if m.is_pinned() {
            if v.0 != glam::Vec3A::ZERO || w.is_some_and(|w| w.0 != glam::Vec3A::ZERO) {
                moving_pinned.push(e);
            }
            continue;
        }
        let slow =
            v.0.length() < settings.linear && w.is_none_or(|w| w.0.length() < settings.angular);
        timer.0 = if slow && !disabled && settings.enabled {
            timer.0 + dt
        } else {
            0.0
        };
        index.insert(e, entities.len());
        entities.push(e);
        still.push(sleeping || timer.0 >= settings.time);
        asleep.push(sleeping);
    }
    if entities.is_empty() {
        return;
    }
    // Spring endpoints never sleep.
    for s in &springs {
        for e in [s.a(), s.b()] {
            if let Some(&i) = index.get(&e) {
                still[i] = false;
            }
        }
    }
    moving_pinned.sort_unstable();
    parent.clear();
    parent.extend(0..entities.len());
    let union = |parent: &mut Vec<usize>, i: usize, j: usize| {
        let (ri, rj) = (find(parent, i), find(parent, j));
        if ri != rj {
            parent[ri.max(rj)] = ri.min(rj);
        }
    };
    for (a, b) in contacts.touching() {
        if let (Some(&i), Some(&j)) = (index.get(&a), index.get(&b)) {
            union(parent, i, j);
        }
    }
    let side = |e: Option<Entity>| -> JointSide {
        let Some(e) = e else {
            return JointSide::Still;
        };
        if let Some(&i) = index.get(&e) {
            return JointSide::Island(i);
        }
        if moving_pinned.binary_search(&e).is_ok() {
            return JointSide::Moving;
        }
        match outsiders.get(e) {
            Ok((_, _, _, true)) | Err(_) => JointSide::Still,
            Ok((mass, v, w, false)) => {
                let moves = v.is_some_and(|v| v.0 != glam::Vec3A::ZERO)
                    || w.is_some_and(|w| w.0 != glam::Vec3A::ZERO);
                if moves || mass.is_some_and(|m| !m.is_pinned()) {
                    JointSide::Moving
                } else {
                    JointSide::Still
                }
            }
        }
    };
    for j in &jointed {
        let Some(bodies) = joints::bodies(j) else {
            continue;
        };
        match (side(bodies.a), side(Some(bodies.b))) {
            (JointSide::Island(i), JointSide::Island(k)) => union(parent, i, k),
            (JointSide::Island(i), JointSide::Moving)
            | (JointSide::Moving, JointSide::Island(i)) => {
                still[i] = false;
            }
            _ => {}
        }
    }
    island_still.clear();
    island_still.resize(entities.len(), true);
    for (i, &s) in still.iter().enumerate() {
        let r = find(parent, i);
        island_still[r] &= s;
    }
    for i in 0..entities.len() {
        let r = find(parent, i);
        let e = entities[i];
        if island_still[r] && !asleep[i] {
            if let Ok((_, _, mut v, w, l, ..)) = bodies.get_mut(e) {
                // Without change ticks: a tick here would read as the game waking it.
                v.bypass_change_detection().0 = glam::Vec3A::ZERO;
                if let Some(mut w) = w {
                    w.bypass_change_detection().0 = glam::Vec3A::ZERO;
                }
                if let Some(mut l) = l {
                    l.bypass_change_detection().0 = glam::Vec3A::ZERO;
                }
            }
            commands.entity(e).insert(Sleeping);
        } else if !island_still[r] && asleep[i] {
            if let Ok((.., mut timer, _, _)) = bodies.get_mut(e) {
                timer.0 = 0.0;
            }
            commands.entity(e).remove::<Sleeping>();
        }
    }
}
