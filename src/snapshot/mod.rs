//! Snapshots: the whole physics state of a `World`, saved and restored so that the restored
//! world continues **bit-identically** — for save games, rollback netcode and bug reports.
//!
//! ```
//! use bevy_ecs::prelude::*;
//! use hooke::prelude::*;
//! use hooke::snapshot::Snapshot;
//!
//! let mut world = World::new();
//! world.add_physics(PhysicsPlugins);
//! world.spawn((RigidBody::Static, Collider::cuboid(5.0, 0.5, 5.0).unwrap()));
//! let ball = world
//!     .spawn((
//!         RigidBody::Dynamic,
//!         Collider::ball(0.5).unwrap(),
//!         Position::from(Vec3::new(0.0, 2.0, 0.0)),
//!     ))
//!     .id();
//! for _ in 0..30 {
//!     world.step_physics();
//! }
//! let bytes = Snapshot::capture(&world).unwrap().to_bytes();
//!
//! let mut copy = World::new();
//! copy.add_physics(PhysicsPlugins);
//! let map = Snapshot::from_bytes(&bytes).unwrap().restore(&mut copy).unwrap();
//! for _ in 0..60 {
//!     world.step_physics();
//!     copy.step_physics();
//! }
//! let a = world.get::<Position>(ball).unwrap().0;
//! let b = copy.get::<Position>(map.get(ball).unwrap()).unwrap().0;
//! assert_eq!(a.to_array().map(f32::to_bits), b.to_array().map(f32::to_bits));
//! ```
//!
//! **What is in one.** Every hooke component of every entity that has one (bodies, springs,
//! joints with their warm-start impulses, meshes, colliders and their parts, sleep and quarantine markers, the implicit solver's
//! kept factor), the parent links of child colliders, the settings and clock resources, and
//! the contact manifolds with their warm-start impulses, and the broad phase's kept boxes (it
//! keeps a grown box while the collider stays inside it, so its candidate pairs depend on
//! history; the fixed colliders' tree is rebuilt, their pairs do not).
//! Not stored: game components, Bevy's `Transform` (re-derived from the pose), messages in
//! flight, and [`crate::particles::VelocityField::Custom`] (a closure: [`Snapshot::capture`] refuses it).
//!
//! **Formats.** [`Snapshot::to_bytes`]: `HOOKESNP`, the format version (u32, little end),
//! the payload length (u64), its CRC-32, then the payload in postcard (compact: varints,
//! no field names). [`Snapshot::to_ron`]: the same state as readable RON, for bug reports
//! and debugging. Reading either checks what it can — magic, version, checksum, every value
//! through the same checks as its constructor, indices into meshes, entities named — and
//! returns a [`SnapshotError`] rather than panicking.
//!
//! **Entities.** [`Snapshot::restore`] spawns new entities into any world with the physics
//! plugins and returns the [`EntityMap`] from the captured ids to the new ones. New ids keep
//! the captured order (pairs are keyed lower entity first) and the entities are spawned in
//! the captured storage order, so every loop of the step visits them as the original did.
//! Restoring into a world that already holds physics entities adds to them; for exact
//! continuation restore into a fresh world, or despawn the old bodies first.

mod columns;

use bevy_ecs::change_detection::DetectChangesMut;
use bevy_ecs::prelude::*;
use bevy_platform::collections::HashMap;
use serde::{Deserialize, Serialize};

use crate::collision::ColliderChanges;
use crate::collision::ContactSettings;
use crate::collision::Contacts;
use crate::collision::ContactsRecord;
use crate::core::diagnostics::DiagnosticsSettings;
use crate::core::error::Result;
use crate::core::quarantine::DivergenceGuard;
use crate::core::time::PhysicsTime;
use crate::core::time::SubstepTime;
use crate::integrator::ConstraintsActive;
use crate::integrator::Integrator;
use crate::integrator::StabilityPolicy;
use crate::particles::Advection;
use crate::particles::Gravity;
use crate::rigid::OrientationUpdate;
use crate::rigid::Renormalization;
use crate::sleep::SleepSettings;
use crate::springs::EntitySpringStability;
use columns::Columns;

/// The version [`Snapshot::to_bytes`] writes and [`Snapshot::from_bytes`] reads. It changes
/// whenever the stored state changes shape.
pub const FORMAT_VERSION: u32 = 4;

const MAGIC: [u8; 8] = *b"HOOKESNP";
const HEADER: usize = 8 + 4 + 8 + 4;

/// What is wrong with a snapshot.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SnapshotError {
    /// The data does not start with `HOOKESNP`.
    #[error("not a hooke snapshot (it does not start with HOOKESNP)")]
    NotASnapshot,
    /// Written by another format version.
    #[error("snapshot format version {found}, but this hooke reads version {expected}")]
    Version {
        /// The file's version.
        found: u32,
        /// [`FORMAT_VERSION`].
        expected: u32,
    },
    /// Shorter than its header says.
    #[error("snapshot truncated: {len} bytes, its header promises {expected}")]
    Truncated {
        /// Bytes given.
        len: usize,
        /// Bytes the header promises.
        expected: u64,
    },
    /// The payload's checksum does not match: the data was damaged.
    #[error("snapshot damaged: CRC-32 {found:08x}, its header says {expected:08x}")]
    Checksum {
        /// CRC-32 of the payload.
        found: u32,
        /// CRC-32 in the header.
        expected: u32,
    },
    /// The payload does not decode (a RON syntax error carries its line).
    #[error("snapshot does not decode: {0}")]
    Decode(String),
    /// A component value failed its checks.
    #[error("snapshot entity {slot}: invalid {component}: {error}")]
    Invalid {
        /// The entity's place in [`Snapshot::entities`].
        slot: u32,
        /// The component type.
        component: &'static str,
        /// What is wrong.
        error: String,
    },
    /// A component names an entity slot that is not there, or a slot twice.
    #[error(
        "snapshot {component} names entity slot {slot} out of order or past the {len} entities"
    )]
    BadSlot {
        /// The component type.
        component: &'static str,
        /// The slot named.
        slot: u32,
        /// Entities in the snapshot.
        len: usize,
    },
    /// A component refers to an entity the snapshot does not hold.
    #[error(
        "snapshot entity {slot}: its {component} refers to {target}, which is not in the snapshot"
    )]
    Dangling {
        /// The entity's place in [`Snapshot::entities`].
        slot: u32,
        /// The component type.
        component: &'static str,
        /// The captured id it names.
        target: Entity,
    },
    /// The same captured entity appears twice.
    #[error("snapshot lists entity {0} twice")]
    DuplicateEntity(Entity),
    /// The state holds something a snapshot cannot store.
    #[error("cannot snapshot {0}")]
    Unsupported(&'static str),
    /// The world to restore into has no physics plugins.
    #[error("restore needs a world with the physics plugins (world.add_physics(PhysicsPlugins))")]
    NoPlugins,
}

fn fail<T>(e: SnapshotError) -> Result<T, SnapshotError> {
    Err(e)
}

/// The settings and clock resources, each if the world had it.
#[derive(Clone, Default, Serialize, Deserialize)]
struct Resources {
    time: Option<PhysicsTime>,
    substep_time: Option<SubstepTime>,
    integrator: Option<Integrator>,
    gravity: Option<Gravity>,
    advection: Option<Advection>,
    contact_settings: Option<ContactSettings>,
    sleep_settings: Option<SleepSettings>,
    divergence_guard: Option<DivergenceGuard>,
    diagnostics_settings: Option<DiagnosticsSettings>,
    orientation_update: Option<OrientationUpdate>,
    renormalization: Option<Renormalization>,
    constraints_active: Option<ConstraintsActive>,
    stability_policy: Option<StabilityPolicy>,
    entity_spring_stability: Option<EntitySpringStability>,
    entity_spring_factor: Option<crate::springs::EntitySpringFactor>,
    joint_settings: Option<crate::joints::JointSettings>,
}

macro_rules! resources {
    ($($field:ident: $ty:ty),* $(,)?) => {
        impl Resources {
            fn capture(world: &World) -> Self {
                Self { $($field: world.get_resource::<$ty>().cloned(),)* }
            }

            /// Renames the entity a resource names (for the digest).
            fn rename(&mut self, f: impl Fn(Entity) -> Entity) {
                if let Some(s) = &mut self.entity_spring_stability {
                    s.spring = s.spring.map(&f);
                }
            }

            /// Inserts every resource held, with ticks old enough not to count as changed.
            fn restore(&self, world: &mut World) {
                let old = columns::ancient(world);
                $(
                    if let Some(value) = &self.$field {
                        world.insert_resource(value.clone());
                        let mut r = world.resource_mut::<$ty>();
                        r.set_last_changed(old);
                        r.set_last_added(old);
                    }
                )*
            }
        }
    };
}

resources!(
    time: PhysicsTime,
    substep_time: SubstepTime,
    integrator: Integrator,
    gravity: Gravity,
    advection: Advection,
    contact_settings: ContactSettings,
    sleep_settings: SleepSettings,
    divergence_guard: DivergenceGuard,
    diagnostics_settings: DiagnosticsSettings,
    orientation_update: OrientationUpdate,
    renormalization: Renormalization,
    constraints_active: ConstraintsActive,
    stability_policy: StabilityPolicy,
    entity_spring_stability: EntitySpringStability,
    entity_spring_factor: crate::springs::EntitySpringFactor,
    joint_settings: crate::joints::JointSettings,
);

/// The physics state of a world (see the module docs).
#[derive(Clone, Serialize, Deserialize)]
pub struct Snapshot {
    /// The captured entities, in storage order.
    entities: Vec<Entity>,
    columns: Columns,
    resources: Resources,
    contacts: Option<ContactsRecord>,
    broad_phase: Option<crate::collision::BroadPhaseRecord>,
    /// Colliders changed since the last step (the next step wakes what touched them).
    collider_changes: Vec<Entity>,
}

/// From the entities of a captured world to those [`Snapshot::restore`] spawned.
#[derive(Debug, Clone, Default)]
pub struct EntityMap(HashMap<Entity, Entity>);

impl EntityMap {
    /// The restored entity for a captured one.
    #[must_use]
    pub fn get(&self, captured: Entity) -> Option<Entity> {
        self.0.get(&captured).copied()
    }

    /// Every (captured, restored) pair, in no particular order.
    pub fn iter(&self) -> impl Iterator<Item = (Entity, Entity)> + '_ {
        self.0.iter().map(|(&a, &b)| (a, b))
    }

    /// How many entities were restored.
    #[must_use]
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// True when nothing was restored.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

impl Snapshot {
    /// Captures the physics state of `world`, between steps.
    ///
    /// # Errors
    /// [`SnapshotError::Unsupported`] for a [`VelocityField::Custom`](crate::particles::VelocityField::Custom) (a closure).
    pub fn capture(world: &World) -> Result<Self, SnapshotError> {
        let ids = Columns::component_ids(world);
        // Storage order: table by table, row by row, as a query walks them.
        let mut entities = Vec::new();
        let mut seen_tables = Vec::new();
        for archetype in world.archetypes().iter() {
            if !ids.iter().any(|&id| archetype.contains(id)) {
                continue;
            }
            let table = archetype.table_id();
            if seen_tables.contains(&table) {
                continue;
            }
            seen_tables.push(table);
            if let Some(t) = world.storages().tables.get(table) {
                entities.extend(t.entities().iter().copied().filter(|&e| {
                    world
                        .get_entity(e)
                        .is_ok_and(|r| ids.iter().any(|&id| r.contains_id(id)))
                }));
            }
        }
        let slots: HashMap<Entity, u32> = entities
            .iter()
            .enumerate()
            .map(|(i, &e)| (e, i as u32))
            .collect();
        let columns = Columns::capture(world, &slots);
        if columns.has_custom_field() {
            return fail(SnapshotError::Unsupported(
                "a VelocityField::Custom (a closure); use Uniform or Vortex, or re-add it after restoring",
            ));
        }
        Ok(Self {
            entities,
            columns,
            resources: Resources::capture(world),
            contacts: world.get_resource::<Contacts>().map(Contacts::to_record),
            broad_phase: crate::collision::broad_phase_record(world),
            collider_changes: world
                .get_resource::<ColliderChanges>()
                .map(|c| c.entities().to_vec())
                .unwrap_or_default(),
        })
    }

    /// The captured entities, in the order they are restored.
    #[must_use]
    pub fn entities(&self) -> &[Entity] {
        &self.entities
    }

    /// Restores the state into `world` (which must have the physics plugins): spawns the
    /// entities, inserts the resources and contacts, and returns where each entity went.
    /// Nothing is spawned when the snapshot fails its checks.
    ///
    /// # Errors
    /// [`SnapshotError::NoPlugins`], [`SnapshotError::DuplicateEntity`], and the value checks
    /// ([`SnapshotError::Invalid`], [`SnapshotError::BadSlot`], [`SnapshotError::Dangling`]).
    pub fn restore(&self, world: &mut World) -> Result<EntityMap, SnapshotError> {
        if !world.contains_resource::<PhysicsTime>() {
            return fail(SnapshotError::NoPlugins);
        }
        // New ids in the captured order: allocate, sort, pair off with the sorted originals.
        let mut sorted = self.entities.clone();
        sorted.sort_unstable();
        if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
            return fail(SnapshotError::DuplicateEntity(w[0]));
        }
        let mut fresh: Vec<Entity> = world
            .entity_allocator()
            .alloc_many(self.entities.len() as u32)
            .collect();
        fresh.sort_unstable();
        let map: columns::Map = sorted.iter().copied().zip(fresh.iter().copied()).collect();
        let mut columns = self.columns.clone();
        let max_distance = self
            .resources
            .divergence_guard
            .map_or(DivergenceGuard::default().max_distance, |g| g.max_distance);
        let checked = columns
            .check_and_map(self.entities.len(), &map)
            .and_then(|()| columns.check_meshes())
            .and_then(|()| match columns.body_past(max_distance) {
                Some((slot, distance)) => Err(SnapshotError::Invalid {
                    slot,
                    component: "Position",
                    error: format!(
                        "a moving body {distance} m from the origin, past the divergence guard's {max_distance} m"
                    ),
                }),
                None => Ok(()),
            });
        let contacts = match &self.contacts {
            Some(record) => Contacts::from_record(record.clone(), |e| map.get(&e).copied())
                .map(Some)
                .map_err(|e| match e {
                    Some(target) => SnapshotError::Dangling {
                        slot: 0,
                        component: "Contacts",
                        target,
                    },
                    None => SnapshotError::Invalid {
                        slot: 0,
                        component: "Contacts",
                        error: "a manifold keeps a point it does not have".into(),
                    },
                }),
            None => Ok(None),
        };
        let contacts = match (contacts, checked) {
            (Ok(c), Ok(())) => c,
            (Err(e), _) | (_, Err(e)) => {
                world.entity_allocator_mut().free_many(&fresh);
                return fail(e);
            }
        };
        let ids: Vec<Entity> = self.entities.iter().map(|e| map[e]).collect();
        for &id in &ids {
            // Allocated just above and never spawned, so this cannot fail.
            let _ = world.spawn_empty_at(id);
        }
        // One pass in slot order, so that the tables are made in the captured order: a
        // spring's check of its ends waits until every end is written.
        world.insert_resource(crate::core::restore::Restoring);
        columns.write(world, &ids);
        world.remove_resource::<crate::core::restore::Restoring>();
        for slot in columns.spring_slots() {
            let id = ids[slot as usize];
            let Some(spring) = world.get::<crate::springs::Spring>(id).copied() else {
                continue;
            };
            if world
                .get::<crate::core::quarantine::Quarantined>(id)
                .is_some()
            {
                continue;
            }
            if let Err(error) = crate::springs::ends_exist(world, &spring) {
                world
                    .entity_mut(id)
                    .insert(crate::core::quarantine::Quarantined {
                        reason: crate::core::quarantine::QuarantineReason::InvalidInput(error),
                    });
            }
        }
        // The insert hooks queued their bookkeeping (mass from colliders, compound parts).
        world.flush();
        columns.settle(world, &ids);
        self.resources.restore(world);
        if let Some(mut s) = world.get_resource_mut::<EntitySpringStability>() {
            // Informational (the stiffest spring): kept as is when it is gone.
            if let Some(e) = s.spring.and_then(|e| map.get(&e).copied()) {
                s.bypass_change_detection().spring = Some(e);
            }
        }
        if let Some(contacts) = contacts {
            world.insert_resource(contacts);
            let old = columns::ancient(world);
            world.resource_mut::<Contacts>().set_last_changed(old);
        }
        if let Some(mut changes) = world.get_resource_mut::<ColliderChanges>() {
            changes.0 = self
                .collider_changes
                .iter()
                .filter_map(|e| map.get(e).copied())
                .collect();
        }
        // Entities the checks above found in the map: the broad phase names only colliders.
        let _ = crate::collision::restore_broad_phase(world, self.broad_phase.as_ref(), |e| {
            map.get(&e).copied()
        });
        Ok(EntityMap(map))
    }

    /// A 64-bit digest of the whole state (FNV-1a over the binary payload): the same inputs
    /// give the same digest, so a pinned digest shows when a change alters results.
    ///
    /// The digest does not depend on entity ids or on how the entities sit in storage:
    /// entities are counted by their rank in id order, which a restore keeps (new ids are
    /// handed out in the captured order) and which a plugin that adds a resource (and so
    /// shifts every id after it) does not change; storage order follows the tables, and game
    /// components or relations (a `ChildOf`) that a snapshot does not hold can move an
    /// entity to another table. So a world and its restored copy have the same digest, and
    /// keep it while they step. The entities a
    /// [`crate::core::quarantine::QuarantineReason`] names are the exception (kept as ids).
    #[must_use]
    pub fn digest(&self) -> u64 {
        let mut canonical = self.clone();
        canonical.rename_by_rank();
        let payload = postcard::to_stdvec(&canonical).unwrap_or_default();
        // FNV-1a: four lines, stable across platforms and versions (a hasher crate's output
        // is not promised to be).
        payload.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
            (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
        })
    }

    /// Renames every entity to its rank in id order (index = rank, generation 0) and moves
    /// its values to that slot. An entity that names no slot keeps its id.
    fn rename_by_rank(&mut self) {
        let mut order: Vec<u32> = (0..self.entities.len() as u32).collect();
        order.sort_by_key(|&slot| self.entities[slot as usize]);
        let mut to = vec![0; order.len()];
        for (rank, &slot) in order.iter().enumerate() {
            to[slot as usize] = rank as u32;
        }
        let ranks: HashMap<Entity, Entity> = self
            .entities
            .iter()
            .zip(&to)
            .filter_map(|(&e, &rank)| Some((e, Entity::from_raw_u32(rank)?)))
            .collect();
        let f = |e: Entity| ranks.get(&e).copied().unwrap_or(e);
        self.columns.reslot(&to);
        self.entities = order
            .iter()
            .map(|&slot| f(self.entities[slot as usize]))
            .collect();
        self.columns.rename(&f);
        if let Some(c) = &mut self.contacts {
            c.rename(f);
        }
        if let Some(b) = &mut self.broad_phase {
            b.rename(f);
        }
        self.collider_changes.iter_mut().for_each(|e| *e = f(*e));
        self.collider_changes.sort_unstable();
        self.resources.rename(f);
    }

    /// The compact binary form (see the module docs).
    #[must_use]
    pub fn to_bytes(&self) -> Vec<u8> {
        // Serialising plain data into a Vec cannot fail; an empty payload would be refused
        // on reading.
        let payload = postcard::to_stdvec(self).unwrap_or_default();
        let mut out = Vec::with_capacity(HEADER + payload.len());
        out.extend_from_slice(&MAGIC);
        out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
        out.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
        out.extend_from_slice(&payload);
        out
    }

    /// Reads [`Snapshot::to_bytes`]' form.
    ///
    /// # Errors
    /// [`SnapshotError::NotASnapshot`], [`SnapshotError::Version`],
    /// [`SnapshotError::Truncated`], [`SnapshotError::Checksum`], [`SnapshotError::Decode`].
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, SnapshotError> {
        if bytes.len() < 8 || bytes[..8] != MAGIC {
            return fail(SnapshotError::NotASnapshot);
        }
        let word = |at: usize, n: usize| -> Option<u64> {
            let b = bytes.get(at..at + n)?;
            let mut v = [0u8; 8];
            v[..n].copy_from_slice(b);
            Some(u64::from_le_bytes(v))
        };
        let short = SnapshotError::Truncated {
            len: bytes.len(),
            expected: HEADER as u64,
        };
        let version = word(8, 4).ok_or(short.clone())? as u32;
        if version != FORMAT_VERSION {
            return fail(SnapshotError::Version {
                found: version,
                expected: FORMAT_VERSION,
            });
        }
        let len = word(12, 8).ok_or(short.clone())?;
        let crc = word(20, 4).ok_or(short)? as u32;
        let payload = &bytes[HEADER..];
        if (payload.len() as u64) < len {
            return fail(SnapshotError::Truncated {
                len: bytes.len(),
                expected: (HEADER as u64).saturating_add(len),
            });
        }
        let payload = &payload[..len as usize];
        let found = crc32fast::hash(payload);
        if found != crc {
            return fail(SnapshotError::Checksum {
                found,
                expected: crc,
            });
        }
        postcard::from_bytes(payload).map_err(|e| SnapshotError::Decode(e.to_string()))
    }

    /// The readable form: RON, one field per line.
    ///
    /// # Errors
    /// [`SnapshotError::Decode`] if a value cannot be written as RON.
    pub fn to_ron(&self) -> Result<String, SnapshotError> {
        let versioned = Versioned {
            version: FORMAT_VERSION,
            snapshot: self.clone(),
        };
        ron::ser::to_string_pretty(&versioned, ron::ser::PrettyConfig::default())
            .map_err(|e| SnapshotError::Decode(e.to_string()))
    }

    /// Reads [`Snapshot::to_ron`]'s form.
    ///
    /// # Errors
    /// [`SnapshotError::Version`], or [`SnapshotError::Decode`] with the line and column.
    pub fn from_ron(text: &str) -> Result<Self, SnapshotError> {
        // The version first, so that another version's layout reads as a version error.
        let options = ron::Options::default();
        if let Ok(h) = options.from_str::<HeaderOnly>(text)
            && h.version != FORMAT_VERSION
        {
            return fail(SnapshotError::Version {
                found: h.version,
                expected: FORMAT_VERSION,
            });
        }
        options
            .from_str::<Versioned>(text)
            .map(|v| v.snapshot)
            .map_err(|e| SnapshotError::Decode(e.to_string()))
    }
}

#[derive(Clone, Serialize, Deserialize)]
struct Versioned {
    version: u32,
    snapshot: Snapshot,
}

/// Reads only the version of a RON snapshot (the rest is skipped).
#[derive(Deserialize)]
struct HeaderOnly {
    version: u32,
    #[serde(rename = "snapshot")]
    _snapshot: ron::Value,
}
