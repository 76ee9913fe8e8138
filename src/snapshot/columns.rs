//! The component columns of a snapshot: one list of `(entity slot, value)` per component
//! type, in slot order, generated for every type a step reads.

use bevy_ecs::bundle::BundleScratch;
use bevy_ecs::change_detection::{DetectChangesMut, MAX_CHANGE_AGE, Tick};
use bevy_ecs::component::{Component, ComponentId, Mutable};
use bevy_ecs::prelude::*;
use bevy_platform::collections::HashMap;
use serde::{Deserialize, Serialize};

use super::SnapshotError;
use crate::core::error::Error;
use crate::core::quarantine::Validate;

/// What a snapshot does with each component type beyond storing it: check a value read
/// back (a file may be edited by hand), and map the entities it names onto the restored
/// ones.
pub(crate) trait Column: Component + Clone + Serialize + for<'de> Deserialize<'de> {
    /// Checks a value read from a snapshot.
    fn check(&self) -> Result<(), Error> {
        Ok(())
    }

    /// The entities the value names.
    fn entities_mut(&mut self) -> Vec<&mut Entity> {
        Vec::new()
    }

    /// Writes `value` over `id`'s, unmarked, with change ticks as old as `old`. (Nothing for
    /// an immutable component: inserted once, no hook recomputes it.)
    fn settle(_world: &mut World, _id: Entity, _value: &Self, _old: Tick) {}
}

fn settle_mut<T: Component<Mutability = Mutable> + Clone>(
    world: &mut World,
    id: Entity,
    value: &T,
    old: Tick,
) {
    if let Some(mut c) = world.get_mut::<T>(id) {
        *c.bypass_change_detection() = value.clone();
        c.set_last_changed(old);
        c.set_last_added(old);
    }
}

macro_rules! settled {
    () => {
        fn settle(world: &mut World, id: Entity, value: &Self, old: Tick) {
            settle_mut(world, id, value, old);
        }
    };
}

macro_rules! plain {
    ($($ty:ty),* $(,)?) => { $(impl Column for $ty { settled!(); })* };
}

macro_rules! validated {
    ($($ty:ty),* $(,)?) => {
        $(impl Column for $ty {
            fn check(&self) -> Result<(), Error> {
                Validate::validate(self)
            }
            settled!();
        })*
    };
}

use crate::cloth::Cloth;
use crate::collision::ActiveCollisionHooks;
use crate::collision::Collider;
use crate::collision::ColliderAabb;
use crate::collision::ColliderDensity;
use crate::collision::ColliderOf;
use crate::collision::ColliderOffset;
use crate::collision::CollisionEventsEnabled;
use crate::collision::CollisionLayers;
use crate::collision::ContactReporting;
use crate::collision::Friction;
use crate::collision::Restitution;
use crate::collision::RestitutionThreshold;
use crate::collision::Sensor;
use crate::collision::{NodeImpulse, OwnShape};
use crate::core::quarantine::Quarantined;
use crate::core::rest::{SleepTimer, Sleeping, SleepingDisabled};
use crate::integrator::ImplicitByDial;
use crate::integrator::ImplicitEuler;
use crate::integrator::ImplicitState;
use crate::integrator::IntegratorOverride;
use crate::integrator::LocalSubsteps;
use crate::joints::{
    DistanceJoint, FixedJoint, JointBreakForce, JointImpulse, PrismaticJoint, RevoluteJoint,
    SphericalJoint,
};
use crate::particles::ExternalForce;
use crate::particles::ExternalImpulse;
use crate::particles::Force;
use crate::particles::GravityScale;
use crate::particles::LinearDamping;
use crate::particles::LinearVelocity;
use crate::particles::Mass;
use crate::particles::Nodes;
use crate::particles::Position;
use crate::particles::Tracer;
use crate::particles::VelocityField;
use crate::rigid::AngularDamping;
use crate::rigid::AngularMomentum;
use crate::rigid::AngularVelocity;
use crate::rigid::CenterOfMass;
use crate::rigid::ComputedMass;
use crate::rigid::Dominance;
use crate::rigid::ExternalForceAtPoint;
use crate::rigid::ExternalImpulseAtPoint;
use crate::rigid::ExternalTorque;
use crate::rigid::Inertia;
use crate::rigid::KinematicTarget;
use crate::rigid::LockedAxes;
use crate::rigid::MaxAngularSpeed;
use crate::rigid::MaxLinearSpeed;
use crate::rigid::RigidBody;
use crate::rigid::Rotation;
use crate::rigid::SkipRenormalization;
use crate::rigid::Torque;
use crate::soft::SoftStability;
use crate::soft::{NodeAttachments, NodeTargets, SoftBody};
use crate::springs::Spring;
use crate::springs::SpringNetwork;
use crate::springs::SpringStability;
use core::result::Result;

validated!(
    Position,
    LinearVelocity,
    ExternalForce,
    ExternalImpulse,
    GravityScale,
    LinearDamping,
    Friction,
    Restitution,
    RestitutionThreshold,
    ColliderDensity,
    ColliderOffset,
    Rotation,
    AngularVelocity,
    AngularMomentum,
    ExternalTorque,
    ExternalForceAtPoint,
    ExternalImpulseAtPoint,
    AngularDamping,
    KinematicTarget,
    CenterOfMass,
    JointBreakForce,
    MaxLinearSpeed,
    MaxAngularSpeed,
    ContactReporting,
);
plain!(
    Force,
    Tracer,
    VelocityField,
    SpringNetwork,
    SpringStability,
    SoftStability,
    Collider,
    CollisionLayers,
    Sensor,
    ColliderAabb,
    CollisionEventsEnabled,
    OwnShape,
    NodeImpulse,
    Sleeping,
    SleepingDisabled,
    SleepTimer,
    ImplicitEuler,
    ImplicitState,
    ImplicitByDial,
    IntegratorOverride,
    LocalSubsteps,
    Cloth,
    SoftBody,
    NodeTargets,
    ComputedMass,
    Torque,
    Inertia,
    SkipRenormalization,
    RigidBody,
    JointImpulse,
    LockedAxes,
    Dominance,
    ActiveCollisionHooks,
);

impl Column for Mass {
    settled!();

    fn check(&self) -> Result<(), Error> {
        if self.is_pinned() {
            Ok(())
        } else {
            Mass::new(self.value()).map(|_| ())
        }
    }
}

impl Column for Nodes {
    settled!();

    fn check(&self) -> Result<(), Error> {
        if self.consistent() {
            Ok(())
        } else {
            Err(Error::Restored(
                "mesh node arrays of different lengths".into(),
            ))
        }
    }
}

impl Column for Spring {
    settled!();

    fn entities_mut(&mut self) -> Vec<&mut Entity> {
        self.ends_mut().into()
    }
}

impl Column for ColliderOf {
    settled!();

    fn entities_mut(&mut self) -> Vec<&mut Entity> {
        vec![&mut self.body]
    }
}

impl Column for ChildOf {
    fn entities_mut(&mut self) -> Vec<&mut Entity> {
        vec![&mut self.0]
    }
}

impl Column for NodeAttachments {
    settled!();

    fn entities_mut(&mut self) -> Vec<&mut Entity> {
        self.bodies_mut().collect()
    }
}

/// A joint kind: checked as on insert, its bodies mapped.
macro_rules! jointed {
    ($($ty:ty),* $(,)?) => {
        $(impl Column for $ty {
            settled!();

            fn check(&self) -> Result<(), Error> {
                Validate::validate(self)
            }

            fn entities_mut(&mut self) -> Vec<&mut Entity> {
                self.bodies.a.iter_mut().chain([&mut self.bodies.b]).collect()
            }
        })*
    };
}

jointed!(
    SphericalJoint,
    RevoluteJoint,
    FixedJoint,
    PrismaticJoint,
    DistanceJoint
);

impl Column for Quarantined {
    // The entities a reason names are for reading only: one that is gone stays as it was.
    settled!();
}

/// Maps an entity of the captured world onto the restored one.
pub(crate) type Map = HashMap<Entity, Entity>;

/// Ticks older than any system's last run: restored values are not "changed" (a step would
/// otherwise take every restored value for a write by game code, and wake sleepers, resync
/// ω from L, recompute manifolds).
pub(crate) fn ancient(world: &World) -> Tick {
    Tick::new(world.read_change_tick().get().wrapping_sub(MAX_CHANGE_AGE))
}

fn map_all<T: Column>(value: &mut T, map: &Map) -> Result<(), Entity> {
    for e in value.entities_mut() {
        *e = *map.get(e).ok_or(*e)?;
    }
    Ok(())
}

fn map_leniently<T: Column>(value: &mut T, map: &Map) {
    for e in value.entities_mut() {
        *e = map.get(e).copied().unwrap_or(Entity::PLACEHOLDER);
    }
}

macro_rules! columns {
    ($($field:ident: $ty:ty),* $(,)?) => {
        /// One column per component type.
        #[derive(Clone, Default, Serialize, Deserialize)]
        pub(crate) struct Columns {
            $(
                #[serde(default)]
                $field: Vec<(u32, $ty)>,
            )*
        }

        impl Columns {
            /// The component ids of every type in the columns that `world` knows.
            pub(crate) fn component_ids(world: &World) -> Vec<ComponentId> {
                [$(world.component_id::<$ty>()),*].into_iter().flatten().collect()
            }

            /// Every value of every column type on the entities of `slots`.
            pub(crate) fn capture(world: &World, slots: &HashMap<Entity, u32>) -> Self {
                let mut columns = Self::default();
                $(
                    if let Some(mut q) = world.try_query::<(Entity, &$ty)>() {
                        columns.$field.extend(
                            q.iter(world).filter_map(|(e, v)| Some((*slots.get(&e)?, v.clone()))),
                        );
                        columns.$field.sort_by_key(|(slot, _)| *slot);
                    }
                )*
                columns
            }

            /// Checks every value, that every slot is one of `len` and holds a type once, and
            /// maps the entities the values name.
            pub(crate) fn check_and_map(&mut self, len: usize, map: &Map) -> Result<(), SnapshotError> {
                // A quarantined body keeps the bad value that put it there; it is restored
                // quarantined, and no system reads it.
                let quarantined: Vec<u32> = self.quarantined.iter().map(|(slot, _)| *slot).collect();
                $(
                    let mut last = None;
                    for (slot, value) in &mut self.$field {
                        let component = stringify!($ty);
                        if *slot as usize >= len || last.is_some_and(|l| l >= *slot) {
                            return Err(SnapshotError::BadSlot { component, slot: *slot, len });
                        }
                        last = Some(*slot);
                        if quarantined.binary_search(slot).is_err() {
                            value.check().map_err(|e| SnapshotError::Invalid {
                                slot: *slot,
                                component,
                                error: e.to_string(),
                            })?;
                        }
                        if quarantined.binary_search(slot).is_ok() {
                            // A quarantined spring may name an end that was despawned (the
                            // reason it was quarantined); no system reads it.
                            map_leniently(value, map);
                        } else {
                            map_all(value, map).map_err(|target| SnapshotError::Dangling {
                                slot: *slot,
                                component,
                                target,
                            })?;
                        }
                    }
                )*
                Ok(())
            }

            /// Renames every entity a value names through `f` (for the digest).
            pub(crate) fn rename(&mut self, f: &impl Fn(Entity) -> Entity) {
                $(
                    for (_, value) in &mut self.$field {
                        for e in value.entities_mut() {
                            *e = f(*e);
                        }
                    }
                )*
            }

            /// Moves every value from slot `s` to `to[s]` (a permutation), keeping each
            /// column in slot order (for the digest).
            pub(crate) fn reslot(&mut self, to: &[u32]) {
                $(
                    for (slot, _) in &mut self.$field {
                        *slot = to[*slot as usize];
                    }
                    self.$field.sort_by_key(|(slot, _)| *slot);
                )*
            }

            /// The node count of every slot that has nodes, for the mesh checks across components.
            pub(crate) fn nodes_of(&self) -> HashMap<u32, usize> {
                self.nodes.iter().map(|(slot, n)| (*slot, n.len())).collect()
            }

            /// Spawns the components of every slot on `ids[slot]` as one bundle each, in slot
            /// order, so that the restored entities sit in the captured storage order (tables
            /// made in the order their first entity comes).
            #[allow(unsafe_code)]
            pub(crate) fn write(&self, world: &mut World, ids: &[Entity]) {
                let mut scratch = BundleScratch::default();
                $(let mut $field = self.$field.iter().peekable();)*
                for (slot, &id) in ids.iter().enumerate() {
                    let slot = slot as u32;
                    let mut writer = scratch.writer();
                    $(
                        if let Some((_, value)) = $field.next_if(|(s, _)| *s == slot) {
                            // SAFETY: every component is registered with and written to this
                            // one world.
                            unsafe { writer.push_component(&mut world.components_registrator(), value.clone()) };
                        }
                    )*
                    let mut entity = world.entity_mut(id);
                    // SAFETY: as above, `entity` is of the world the components came from.
                    unsafe { writer.write(&mut entity) };
                }
            }

            /// Writes every value again, unmarked, over what the insert hooks' commands may
            /// have recomputed (in a different rounding), and ages every restored value's
            /// change ticks (see [`ancient`]).
            pub(crate) fn settle(&self, world: &mut World, ids: &[Entity]) {
                let old = ancient(world);
                $(
                    for (slot, value) in &self.$field {
                        <$ty as Column>::settle(world, ids[*slot as usize], value, old);
                    }
                )*
            }
        }
    };
}

columns!(
    position: Position,
    linear_velocity: LinearVelocity,
    external_force: ExternalForce,
    external_impulse: ExternalImpulse,
    force: Force,
    mass: Mass,
    gravity_scale: GravityScale,
    linear_damping: LinearDamping,
    tracer: Tracer,
    velocity_field: VelocityField,
    nodes: Nodes,
    spring: Spring,
    spring_network: SpringNetwork,
    spring_stability: SpringStability,
    soft_stability: SoftStability,
    rigid_body: RigidBody,
    rotation: Rotation,
    angular_velocity: AngularVelocity,
    angular_momentum: AngularMomentum,
    external_torque: ExternalTorque,
    torque: Torque,
    center_of_mass: CenterOfMass,
    inertia: Inertia,
    computed_mass: ComputedMass,
    skip_renormalization: SkipRenormalization,
    external_force_at_point: ExternalForceAtPoint,
    external_impulse_at_point: ExternalImpulseAtPoint,
    angular_damping: AngularDamping,
    kinematic_target: KinematicTarget,
    collider: Collider,
    friction: Friction,
    restitution: Restitution,
    restitution_threshold: RestitutionThreshold,
    collision_layers: CollisionLayers,
    sensor: Sensor,
    collider_aabb: ColliderAabb,
    collision_events_enabled: CollisionEventsEnabled,
    collider_density: ColliderDensity,
    collider_offset: ColliderOffset,
    collider_of: ColliderOf,
    own_shape: OwnShape,
    node_impulse: NodeImpulse,
    child_of: ChildOf,
    sleeping: Sleeping,
    sleeping_disabled: SleepingDisabled,
    sleep_timer: SleepTimer,
    implicit_euler: ImplicitEuler,
    implicit_state: ImplicitState,
    implicit_by_dial: ImplicitByDial,
    integrator_override: IntegratorOverride,
    local_substeps: LocalSubsteps,
    cloth: Cloth,
    soft_body: SoftBody,
    node_targets: NodeTargets,
    node_attachments: NodeAttachments,
    spherical_joint: SphericalJoint,
    revolute_joint: RevoluteJoint,
    fixed_joint: FixedJoint,
    prismatic_joint: PrismaticJoint,
    distance_joint: DistanceJoint,
    joint_impulse: JointImpulse,
    joint_break_force: JointBreakForce,
    locked_axes: LockedAxes,
    dominance: Dominance,
    max_linear_speed: MaxLinearSpeed,
    max_angular_speed: MaxAngularSpeed,
    contact_reporting: ContactReporting,
    active_collision_hooks: ActiveCollisionHooks,
    quarantined: Quarantined,
);

impl Columns {
    /// The checks that span components of one entity: a mesh's elements, springs and
    /// attachments must index into its nodes.
    pub(crate) fn check_meshes(&self) -> Result<(), SnapshotError> {
        let nodes = self.nodes_of();
        // A quarantined mesh may be the misfit that put it there; no system reads it.
        let quarantined: Vec<u32> = self.quarantined.iter().map(|(slot, _)| *slot).collect();
        let len = |slot: &u32| {
            if quarantined.binary_search(slot).is_ok() {
                usize::MAX
            } else {
                nodes.get(slot).copied().unwrap_or(0)
            }
        };
        let bad = |slot: u32, component: &'static str| SnapshotError::Invalid {
            slot,
            component,
            error: "indexes past the entity's mesh nodes".into(),
        };
        for (slot, s) in &self.spring_network {
            if !s.consistent() || !(s.is_empty() || (s.max_index as usize) < len(slot)) {
                return Err(bad(*slot, "SpringNetwork"));
            }
        }
        for (slot, c) in &self.cloth {
            if !c.consistent(len(slot)) {
                return Err(bad(*slot, "Cloth"));
            }
        }
        for (slot, s) in &self.soft_body {
            if !s.fits(len(slot)) {
                return Err(bad(*slot, "SoftBody"));
            }
        }
        for (slot, t) in &self.node_targets {
            if !t.fits(len(slot)) {
                return Err(bad(*slot, "NodeTargets"));
            }
        }
        for (slot, a) in &self.node_attachments {
            if !a.fits(len(slot)) {
                return Err(bad(*slot, "NodeAttachments"));
            }
        }
        Ok(())
    }

    /// The first body with a mass (so one that moves) placed farther from the origin than
    /// `max` (m) on some axis, unless it is quarantined: no run can leave a sleeping or
    /// awake body there (the guard quarantines it), so only an edited file can.
    pub(crate) fn body_past(&self, max: f32) -> Option<(u32, f32)> {
        let quarantined: Vec<u32> = self.quarantined.iter().map(|(slot, _)| *slot).collect();
        let mass: Vec<u32> = self.mass.iter().map(|(slot, _)| *slot).collect();
        self.position
            .iter()
            .filter(|(slot, _)| mass.binary_search(slot).is_ok())
            .filter(|(slot, _)| quarantined.binary_search(slot).is_err())
            .map(|(slot, x)| (*slot, x.0.abs().max_element()))
            .find(|&(_, d)| d > max)
    }

    /// The slots that hold a spring (their ends are checked once every entity is written).
    pub(crate) fn spring_slots(&self) -> Vec<u32> {
        self.spring.iter().map(|(slot, _)| *slot).collect()
    }

    /// Whether any velocity field is a closure (which cannot be saved).
    pub(crate) fn has_custom_field(&self) -> bool {
        self.velocity_field
            .iter()
            .any(|(_, f)| matches!(f, VelocityField::Custom(_)))
    }
}
