//! Collisions through parry: colliders, broad phase, narrow phase and a soft-step contact
//! solver.
//!
//! **Pipeline, once per step** (in [`crate::core::schedule::PrepareSystems::Collision`]):
//! 1. bounding boxes of moving colliders, grown by the distance they can travel in the step
//!    (the *speculative margin*, so fast bodies find what they would hit);
//! 2. broad phase: incremental sort-and-sweep over moving boxes and a tree of fixed ones
//!    (see the `broad_phase` module). Fixed colliders cost nothing per step: they are meant to stay
//!    put, and the broad phase hears of a change through component hooks, so move a static
//!    collider by inserting a new `Position` or `Rotation` (or make it kinematic);
//! 3. narrow phase: parry's persistent contact manifolds per pair, which carry each contact's
//!    impulses from step to step by feature id (warm starting); contact start/end messages.
//!    A pair that moved less than [`ContactSettings::recycle_distance`] relative to itself
//!    since its manifolds were found keeps them and only updates their separations;
//! 4. contact constraints with anchors, effective masses and the approach speed. A
//!    manifold's normal and lever arms are taken when its points are found and held in the
//!    world frame, riding with each body's centre of mass, until its points are found again
//!    more than 2 cm away (the separation is still measured at the turned points): arms that
//!    turned with a leaning box would swing its support against the lean and topple tall
//!    columns.
//!
//! **Solver, every substep** (Box2D v3's soft step): after the velocities are integrated,
//! the contacts are warm-started and solved with a soft position bias (spring of
//! [`ContactSettings::hertz`], damping ratio [`ContactSettings::damping_ratio`], push-out at
//! most [`ContactSettings::max_push_velocity`]); positions are integrated; then
//! [`crate::core::schedule::StepSystems::RelaxConstraints`] solves once more without bias so that the
//! push-out does not stay in the velocities. After the last substep, restitution brings the
//! normal velocity of every contact that hit faster than [`ContactSettings::restitution_threshold`]
//! to −e times its approach speed (Newton's law), but never past the impulse that ends its
//! compression plus e times the compression impulse (Poisson's law), and never giving back
//! more than e² of the kinetic energy the step's normal impulses took out: contacts never
//! create energy. An isolated impact bounces exactly; a row of touching bodies struck at one
//! end spreads the velocity over the row, as sequential impulses do, instead of passing it
//! all to the far end as a Newton's cradle would (two balls exchange their velocities
//! exactly; three keep 77 % of the energy, five 56 %). Friction is Coulomb's, one 2D constraint per manifold at
//! its centre clamped to μ times the manifold's normal impulse, plus a twist friction about
//! the normal, solved in the relax pass. Each manifold keeps at most four points, and the
//! solver takes four manifolds at a time in SIMD lanes (see the `solver` module). A
//! separated contact (s > 0) is *speculative*: it only stops the approach
//! from closing more than s in a substep, which is what keeps a fast small body from
//! tunnelling through a thin wall. A speculative point acts on each body where that body will
//! touch (its witness point), and a round shape's points (ball, capsule) are anchored at its
//! centre of curvature, so spin does not throw off the gap the solver reads. A pair fast
//! against its own thickness is also cast for its time of impact (along the bodies' arcs
//! when they spin), which adds the impact's normal when the closest features at the start
//! of the step miss it (see the `ccd` module). A body in contact turns at most
//! [`ContactSettings::max_rotation`] per substep, since contact lever arms are set at the
//! start of the step. A body that overlaps something deeply (more than a quarter of the
//! thinner shape) leaves each contact pass no faster than it entered the substep or than
//! [`ContactSettings::max_push_velocity`], and in such a step the contacts with static
//! bodies are solved once more after each pass: a heap spawned at one point spreads out on
//! the ground instead of exploding through it.
//!
//! **Bodies.** A [`Collider`] on a body with a finite [`crate::particles::Mass`] is dynamic; on a pinned
//! or massless entity it is static (a kinematic body's velocity still drives its contacts).
//! A particle with a ball collider collides like any body but never rotates.
//!
//! Units: m, s, kg; impulses in N·s.

mod attach;
pub(crate) mod broad_phase;
mod casters;
pub mod coincident;
#[cfg(feature = "collider-from-mesh")]
mod from_mesh;
pub(crate) mod hooks;
pub(crate) mod lanes;
mod layers;
pub(crate) mod narrow_phase;
pub(crate) mod nodes;
mod plugin;
pub(crate) mod prefetch;
mod query;
pub(crate) mod radii;
mod reports;
pub(crate) mod slots;
pub(crate) mod solver;
pub(crate) mod support;

pub(crate) use attach::OwnShape;
pub use attach::{ColliderDensity, ColliderOf, ColliderOffset, MAX_PART_DEPTH};
pub use hooks::{
    ActiveCollisionHooks, CollisionHookSystems, CollisionHooks, CollisionHooksPlugin, ContactEdit,
};
pub use layers::{CollisionLayers, LayerMask, PhysicsLayer};
pub(crate) use narrow_phase::ContactsRecord;
pub use narrow_phase::{ContactPair, Contacts};
pub(crate) use nodes::coupling::NodeImpulse;
pub use plugin::CollisionPlugin;
pub use reports::{ContactReport, ContactReporting, ReportedPoint};

/// Pairs of bodies that never collide, whatever their layers; each pair counts its reasons
/// (a joint between the two is one, see [`crate::joints`]), and collides again when none is
/// left.
#[derive(Resource, Debug, Default)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Resource))]
pub struct PairExclusions(bevy_platform::collections::HashMap<(Entity, Entity), u32>);

impl PairExclusions {
    fn key(a: Entity, b: Entity) -> (Entity, Entity) {
        if a <= b { (a, b) } else { (b, a) }
    }

    /// One more reason for `a` and `b` not to collide.
    pub fn add(&mut self, a: Entity, b: Entity) {
        *self.0.entry(Self::key(a, b)).or_default() += 1;
    }

    /// One reason fewer (see [`Self::add`]).
    pub fn remove(&mut self, a: Entity, b: Entity) {
        let key = Self::key(a, b);
        if let Some(n) = self.0.get_mut(&key) {
            *n -= 1;
            if *n == 0 {
                self.0.remove(&key);
            }
        }
    }

    /// True when `a` and `b` do not collide.
    #[must_use]
    pub fn contains(&self, a: Entity, b: Entity) -> bool {
        self.0.contains_key(&Self::key(a, b))
    }

    /// True when every pair may collide.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

pub(crate) use broad_phase::BroadPhaseRecord;

/// The world pose of a manifold's part: the shape's pose, then the part's pose in it.
#[inline]
pub(crate) fn part_pose(shape: &Pose, part: Option<&Pose>) -> Pose {
    part.map_or(*shape, |p| *shape * *p)
}

/// The pose of a collider's shape frame: origin x − R c.
pub(crate) fn shape_pose(x: Vec3A, q: Quat, com: Option<&CenterOfMass>) -> Pose {
    let c = com.map_or(Vec3::ZERO, |c| c.0);
    Pose::from_parts(Vec3::from(x) - q * c, q)
}

/// Bounding radius of a shape about the centre of mass (m).
pub(crate) fn radius(collider: &Collider, com: Option<&CenterOfMass>) -> f32 {
    let [min, max] = collider.local_bounds();
    let c = com.map_or(Vec3::ZERO, |c| c.0);
    let corners = (min - c).length().max((max - c).length());
    corners.min(collider.radii.0 + c.length())
}

/// The bodies the contact systems see: not quarantined, and not a part of another body (its
/// body carries it in a compound).
pub(crate) type ContactFilter = (
    Without<crate::core::quarantine::Quarantined>,
    Without<ColliderOf>,
);

/// The broad phase's kept state, for a snapshot.
pub(crate) fn broad_phase_record(world: &World) -> Option<BroadPhaseRecord> {
    world
        .get_resource::<broad_phase::BroadPhase>()
        .map(broad_phase::BroadPhase::to_record)
}

/// Restores the broad phase from a snapshot's record (or, with none, has it rebuild).
pub(crate) fn restore_broad_phase(
    world: &mut World,
    record: Option<&BroadPhaseRecord>,
    map: impl Fn(Entity) -> Option<Entity>,
) -> Result<(), Entity> {
    let Some(mut bp) = world.get_resource_mut::<broad_phase::BroadPhase>() else {
        return Ok(());
    };
    match record {
        Some(r) => bp.restore(r, map),
        None => {
            bp.fixed_dirty = true;
            bp.moving_dirty = true;
            Ok(())
        }
    }
}
pub use casters::{RayCaster, RayHits, ShapeCaster, ShapeHits};
pub use query::{Hit, Projection, QueryFilter, ShapeContact, SpatialQuery};

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3, Vec3A};
use parry3d::math::Pose;
use parry3d::shape::SharedShape;

use crate::core::error::{Error, Result, finite, finite_vec, non_negative};

use crate::core::quarantine::{Validate, validate_on_insert};
use crate::particles::Position;
use crate::rigid::{CenterOfMass, Rotation};

/// A collision shape (a parry shape) attached to a body, placed at the body's shape frame:
/// origin x − R c, where c is the [`crate::rigid::CenterOfMass`].
#[derive(serde::Serialize, serde::Deserialize, Component, Clone)]
#[serde(try_from = "ColliderRecord", into = "ColliderRecord")]
#[require(
    Position,
    Rotation,
    Friction,
    Restitution,
    CollisionLayers,
    ColliderAabb,
    crate::core::rest::SleepTimer
)]
#[cfg_attr(feature = "bevy", require(bevy_transform::components::Transform))]
#[cfg_attr(
    feature = "bevy",
    derive(bevy_reflect::Reflect),
    reflect(opaque, Component, Clone)
)]
#[component(on_insert = collider_changed, on_remove = collider_changed)]
pub struct Collider {
    shape: SharedShape,
    /// The shape's local bounding box, kept: the contact systems read it every step.
    bounds: [Vec3; 2],
    /// The farthest point from the shape's origin and the largest ball about the origin
    /// inside the shape (m; see [`radii::radii`]), kept for the same reason.
    radii: (f32, f32),
    /// A hull's vertices in columns for its support point (see [`support`]), shared by
    /// the collider's clones like the shape.
    lanes: Option<std::sync::Arc<support::HullLanes>>,
    /// Built by hooke from a body's parts (see the `attach` module), not by the user.
    composed: bool,
}

/// A collider as a snapshot holds it: the shape, checked again on the way back in (by
/// [`Collider::new`]: a shape edited by hand must still be one parry handles).
#[derive(serde::Serialize, serde::Deserialize)]
struct ColliderRecord {
    shape: SharedShape,
    composed: bool,
}

impl From<Collider> for ColliderRecord {
    fn from(c: Collider) -> Self {
        Self {
            shape: c.shape,
            composed: c.composed,
        }
    }
}

impl TryFrom<ColliderRecord> for Collider {
    type Error = Error;

    fn try_from(r: ColliderRecord) -> Result<Self> {
        // parry trusts a hull's adjacency; one index past its arrays (a hand-edited file)
        // panics in its mass properties or contacts later, outside any guard.
        let hulls = match r.shape.as_compound() {
            Some(c) => c
                .shapes()
                .iter()
                .filter_map(|(_, s)| s.as_convex_polyhedron())
                .collect(),
            None => r
                .shape
                .as_convex_polyhedron()
                .into_iter()
                .collect::<Vec<_>>(),
        };
        if !hulls.iter().all(|h| hull_is_consistent(h)) {
            return Err(Error::Restored(
                "a convex hull names a vertex, edge or face it does not have".into(),
            ));
        }
        // A malformed composite (a mesh index past its vertices) can panic inside parry.
        let built =
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| Collider::new(r.shape)))
                .map_err(|_| {
                    Error::Restored("the collider's shape made the geometry library fail".into())
                })??;
        Ok(Self {
            composed: r.composed,
            ..built
        })
    }
}

/// Every index of `h`'s adjacency lies inside the array it points into.
fn hull_is_consistent(h: &parry3d::shape::ConvexPolyhedron) -> bool {
    let (points, edges, faces) = (h.points().len(), h.edges().len(), h.faces().len());
    let within = |list: &[u32], len: usize| list.iter().all(|&i| (i as usize) < len);
    let span = |first: u32, n: u32, len: usize| (first as usize).saturating_add(n as usize) <= len;
    within(h.vertices_adj_to_face(), points)
        && within(h.edges_adj_to_face(), edges)
        && within(h.faces_adj_to_vertex(), faces)
        && h.vertices().len() == points
        && h.faces().iter().all(|f| {
            span(
                f.first_vertex_or_edge,
                f.num_vertices_or_edges,
                h.vertices_adj_to_face().len(),
            ) && span(
                f.first_vertex_or_edge,
                f.num_vertices_or_edges,
                h.edges_adj_to_face().len(),
            )
        })
        && h.vertices().iter().all(|v| {
            span(
                v.first_adj_face_or_edge,
                v.num_adj_faces_or_edge,
                h.faces_adj_to_vertex().len(),
            )
        })
        && h.edges().iter().all(|e| {
            e.vertices.iter().all(|&i| (i as usize) < points)
                && e.faces.iter().all(|&i| (i as usize) < faces)
        })
}

impl std::fmt::Debug for Collider {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Collider({:?})", self.shape.shape_type())
    }
}

fn collider_changed(
    mut world: bevy_ecs::world::DeferredWorld,
    ctx: bevy_ecs::lifecycle::HookContext,
) {
    broad_phase::mark_dirty(&mut world, ctx.entity);
    if let Some(mut changes) = world.get_resource_mut::<ColliderChanges>() {
        changes.0.push(ctx.entity);
    }
    if world
        .get::<Collider>(ctx.entity)
        .is_some_and(|c| !c.composed)
    {
        attach::queue_refresh_owner(&mut world, ctx.entity);
    }
}

/// Colliders inserted, replaced or removed (a despawn included) since the last step's
/// collision detection: what touched them must hear of it (the sleep plugin wakes their
/// islands, whose pairs the narrow phase then updates or ends).
#[derive(Resource, Debug, Default)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Resource))]
pub struct ColliderChanges(pub(crate) Vec<Entity>);

impl ColliderChanges {
    /// The entities whose collider changed or went, in the order it happened (one may
    /// appear more than once).
    #[must_use]
    pub fn entities(&self) -> &[Entity] {
        &self.0
    }
}

/// Positive sizes for the primitive shapes parry would otherwise accept.
fn check_sizes(shape: &SharedShape) -> Result<()> {
    use parry3d::shape::TypedShape;
    match shape.as_typed_shape() {
        TypedShape::Ball(b) => positive_len("ball radius", b.radius).map(|_| ()),
        TypedShape::Cuboid(c) => {
            for h in c.half_extents.to_array() {
                positive_len("half extent", h)?;
            }
            Ok(())
        }
        TypedShape::Capsule(c) => positive_len("capsule radius", c.radius).map(|_| ()),
        TypedShape::Cylinder(c) => {
            positive_len("cylinder half height", c.half_height)?;
            positive_len("cylinder radius", c.radius).map(|_| ())
        }
        TypedShape::Cone(c) => {
            positive_len("cone half height", c.half_height)?;
            positive_len("cone radius", c.radius).map(|_| ())
        }
        TypedShape::RoundCuboid(c) => {
            for h in c.inner_shape.half_extents.to_array() {
                positive_len("half extent", h)?;
            }
            non_negative("border radius", c.border_radius).map(|_| ())
        }
        _ => Ok(()),
    }
}

impl Collider {
    /// The largest distance a collider's bounds may reach from its origin (m). Beyond it f32
    /// resolves positions to worse than 6 cm, and parry's penetration search (EPA) has been
    /// seen to fail with an index panic on such shapes (a cylinder of half height 1e20, a
    /// cuboid of half extent 1e30).
    pub const MAX_EXTENT: f32 = 1e6;

    /// Wraps any parry shape after checking that it is one the collision code can handle:
    /// finite bounds no larger than [`Collider::MAX_EXTENT`], and positive sizes for the
    /// primitive shapes (a zero-radius ball or a negative cuboid is no shape).
    ///
    /// # Errors
    /// [`Error::NonFinite`] for a shape with non-finite bounds, [`Error::OutOfRange`] for one
    /// larger than [`Collider::MAX_EXTENT`] or with its bounds inverted or collapsed to a
    /// point, [`Error::NotPositive`] for a primitive with a non-positive size.
    pub fn new(shape: SharedShape) -> Result<Self> {
        check_sizes(&shape)?;
        let aabb = shape.compute_local_aabb();
        finite_vec("collider bounds", aabb.mins)?;
        finite_vec("collider bounds", aabb.maxs)?;
        let extent = aabb.mins.abs().max(aabb.maxs.abs()).max_element();
        if extent > Self::MAX_EXTENT {
            return Err(Error::OutOfRange {
                what: "collider extent from its origin (m)",
                value: extent,
                range: "at most 1e6 m (Collider::MAX_EXTENT)",
            });
        }
        let size = aabb.maxs - aabb.mins;
        if size.min_element() < 0.0 || size.max_element() <= 0.0 {
            return Err(Error::OutOfRange {
                what: "collider size (m)",
                value: size.max_element(),
                range: "bounds with a positive size",
            });
        }
        let bounds = [aabb.mins, aabb.maxs];
        Ok(Self {
            radii: radii::radii(&*shape, bounds),
            lanes: shape
                .as_convex_polyhedron()
                .and_then(support::HullLanes::new)
                .map(std::sync::Arc::new),
            shape,
            bounds,
            composed: false,
        })
    }

    /// Lower and upper corners of the shape's bounding box in its own frame (m).
    #[must_use]
    pub(crate) fn local_bounds(&self) -> [Vec3; 2] {
        self.bounds
    }

    /// The shape as a hull with its vertices in columns, if it is a hull.
    #[must_use]
    pub(crate) fn laned_hull(&self) -> Option<support::LanedHull<'_>> {
        Some(support::LanedHull {
            hull: self.shape.as_convex_polyhedron()?,
            lanes: self.lanes.as_deref()?,
        })
    }

    /// The largest ball about the shape's origin inside it (m; 0 where not known).
    #[must_use]
    pub(crate) fn inner_radius(&self) -> f32 {
        self.radii.1
    }

    /// A ball of radius `r` (m).
    ///
    /// # Errors
    /// [`Error::NotPositive`] unless `r` > 0.
    pub fn ball(r: f32) -> Result<Self> {
        Self::new(SharedShape::ball(positive_len("ball radius", r)?))
    }

    /// A box with half extents `hx`, `hy`, `hz` (m).
    ///
    /// # Errors
    /// [`Error::NotPositive`] unless every half extent is > 0.
    pub fn cuboid(hx: f32, hy: f32, hz: f32) -> Result<Self> {
        Self::new(SharedShape::cuboid(
            positive_len("half extent", hx)?,
            positive_len("half extent", hy)?,
            positive_len("half extent", hz)?,
        ))
    }

    /// A capsule along y: a segment of half length `half_height` (m) swept by radius `r`.
    ///
    /// # Errors
    /// [`Error::NotPositive`] for a non-positive radius or a negative half height.
    pub fn capsule_y(half_height: f32, r: f32) -> Result<Self> {
        non_negative("capsule half height", half_height)?;
        Self::new(SharedShape::capsule_y(
            half_height,
            positive_len("capsule radius", r)?,
        ))
    }

    /// A cylinder along y.
    ///
    /// # Errors
    /// [`Error::NotPositive`] unless both sizes are > 0.
    pub fn cylinder(half_height: f32, r: f32) -> Result<Self> {
        Self::new(SharedShape::cylinder(
            positive_len("cylinder half height", half_height)?,
            positive_len("cylinder radius", r)?,
        ))
    }

    /// The convex hull of `points` (m).
    ///
    /// # Errors
    /// [`Error::TooFew`] when no hull exists (fewer than 4 points, or all coplanar).
    pub fn convex_hull(points: &[Vec3]) -> Result<Self> {
        for p in points {
            finite_vec("hull point", *p)?;
        }
        let too_few = Error::TooFew {
            what: "non-coplanar hull points",
            min: 4,
            got: points.len(),
        };
        let shape = SharedShape::convex_hull(points).ok_or(too_few.clone())?;
        // parry builds a flat "hull" from 3 points or a coplanar set: no volume, no inertia.
        let volume = shape.mass_properties(1.0).mass();
        let aabb = shape.compute_local_aabb();
        let size = (aabb.maxs - aabb.mins).max_element();
        if volume.partial_cmp(&(1e-9 * size * size * size)) != Some(std::cmp::Ordering::Greater) {
            return Err(too_few);
        }
        Self::new(shape)
    }

    /// A triangle mesh (for static geometry; dynamic bodies should use convex parts).
    ///
    /// # Errors
    /// [`Error::TooFew`] for an empty mesh, [`Error::IndexOutOfRange`] for a bad index.
    pub fn trimesh(vertices: Vec<Vec3>, indices: Vec<[u32; 3]>) -> Result<Self> {
        if indices.is_empty() {
            return Err(Error::TooFew {
                what: "triangles",
                min: 1,
                got: 0,
            });
        }
        for i in indices.iter().flatten() {
            if *i as usize >= vertices.len() {
                return Err(Error::IndexOutOfRange {
                    what: "triangle vertex",
                    index: *i as usize,
                    len: vertices.len(),
                });
            }
        }
        for v in &vertices {
            finite_vec("mesh vertex", *v)?;
        }
        let shape = SharedShape::trimesh(vertices, indices).map_err(|_| Error::TooFew {
            what: "valid triangles",
            min: 1,
            got: 0,
        })?;
        Self::new(shape)
    }

    /// A heightfield of `nrows` × `ncols` heights (row-major) scaled by `scale` (m).
    ///
    /// # Errors
    /// [`Error::TooFew`] for fewer than 2 × 2 heights or a size mismatch.
    pub fn heightfield(nrows: usize, ncols: usize, heights: Vec<f32>, scale: Vec3) -> Result<Self> {
        // The product is checked: 2^62 × 4 wraps to 0 and matched an empty height list, then
        // overflowed parry's allocation.
        let Some(count) = nrows.checked_mul(ncols) else {
            return Err(Error::OutOfRange {
                what: "heightfield rows × columns",
                value: nrows as f32 * ncols as f32,
                range: "a count that fits in memory",
            });
        };
        if nrows < 2 || ncols < 2 || heights.len() != count {
            return Err(Error::TooFew {
                what: "heights (at least 2 × 2, rows × cols)",
                min: 4,
                got: heights.len(),
            });
        }
        for h in &heights {
            finite("height", *h)?;
        }
        finite_vec("heightfield scale", scale)?;
        let grid = parry3d::utils::Array2::new(nrows, ncols, heights);
        Self::new(SharedShape::heightfield(grid, scale))
    }

    /// Several colliders in one, each at a position and rotation in this shape's frame.
    /// (Colliders on child entities of a body are the Bevy way to do the same.)
    ///
    /// # Errors
    /// [`Error::TooFew`] for no parts, [`Error::NonFinite`] for bad poses,
    /// [`Error::CompositePart`] for a part that is itself a compound, trimesh or heightfield
    /// (parry cannot nest them).
    pub fn compound(parts: Vec<(Vec3, Quat, Collider)>) -> Result<Self> {
        if parts.is_empty() {
            return Err(Error::TooFew {
                what: "compound parts",
                min: 1,
                got: 0,
            });
        }
        let mut shapes = Vec::with_capacity(parts.len());
        for (x, q, c) in parts {
            if c.shape.as_composite_shape().is_some() {
                return Err(Error::CompositePart(format!("{:?}", c.shape.shape_type())));
            }
            let q = Rotation::try_new(q)?.0;
            shapes.push((
                Pose::from_parts(finite_vec("part position", x)?, q),
                c.shape,
            ));
        }
        Self::new(SharedShape::compound(shapes))
    }

    /// The parry shape.
    #[must_use]
    pub fn shape(&self) -> &SharedShape {
        &self.shape
    }
}

fn positive_len(what: &'static str, v: f32) -> Result<f32> {
    crate::core::error::positive(what, v)
}

/// Coulomb friction coefficient μ (dimensionless, default 0.5).
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_insert = validate_on_insert::<Self>)]
pub struct Friction(pub f32);

impl Default for Friction {
    fn default() -> Self {
        Self(0.5)
    }
}

impl Validate for Friction {
    fn validate(&self) -> Result<()> {
        non_negative("friction", self.0).map(|_| ())
    }
}

/// Coefficient of restitution e in [0, 1] (default 0: no bounce).
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_insert = validate_on_insert::<Self>)]
pub struct Restitution(pub f32);

impl Validate for Restitution {
    fn validate(&self) -> Result<()> {
        let e = non_negative("restitution", self.0)?;
        if e > 1.0 {
            return Err(Error::NotPositive {
                what: "1 - restitution (restitution above 1 adds energy)",
                value: 1.0 - e,
            });
        }
        Ok(())
    }
}

/// A collider's own restitution threshold (m/s, ≥ 0): its contacts bounce when they hit
/// faster than this, instead of [`ContactSettings::restitution_threshold`]. Of two colliders
/// with one each, the contact takes the lower. A small threshold lets slow impacts bounce
/// too (a ball's bounce series goes on longer); too small, and a resting body jitters on the
/// bounces of its own settling.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
#[component(on_insert = validate_on_insert::<Self>)]
pub struct RestitutionThreshold(pub f32);

impl Validate for RestitutionThreshold {
    fn validate(&self) -> Result<()> {
        non_negative("restitution threshold", self.0).map(|_| ())
    }
}

/// How two colliders' coefficients combine into one for their contact.
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect))]
pub enum CombineRule {
    /// √(a b): the default for friction.
    #[default]
    GeometricMean,
    /// (a + b) / 2.
    Average,
    /// min(a, b).
    Min,
    /// max(a, b): the default for restitution.
    Max,
    /// a b.
    Multiply,
}

impl CombineRule {
    /// Combines two coefficients.
    #[must_use]
    pub fn combine(self, a: f32, b: f32) -> f32 {
        match self {
            CombineRule::GeometricMean => (a * b).sqrt(),
            CombineRule::Average => 0.5 * (a + b),
            CombineRule::Min => a.min(b),
            CombineRule::Max => a.max(b),
            CombineRule::Multiply => a * b,
        }
    }
}

/// Marks a collider that reports overlaps (through [`Contacts`] and the contact messages)
/// without pushing anything.
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Eq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct Sensor;

/// The world bounding box of a collider as of the last step (m), grown by its speculative
/// margin.
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct ColliderAabb {
    /// Lower corner.
    pub min: Vec3,
    /// Upper corner.
    pub max: Vec3,
}

/// Contact solver settings (Box2D v3's, except for the stiffness cap; see [`ContactSettings::hertz`]).
#[derive(serde::Serialize, serde::Deserialize, Resource, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Resource))]
pub struct ContactSettings {
    /// Stiffness of the soft contact, as a frequency (Hz), capped at an eighth of the
    /// substep rate: 30 Hz with 4 substeps at 60 Hz, the full 60 Hz from 8 substeps. A stack
    /// compresses by about W / (m_eff (2π f)²) per contact: a 10-box stack sinks 11.3 mm at
    /// 30 Hz and 4.7 mm at 60 Hz. At a quarter of the substep rate (Box2D's cap) tall
    /// pyramids crept at 4 substeps.
    pub hertz: f32,
    /// Damping ratio of the soft contact (dimensionless; 10 is heavily overdamped).
    pub damping_ratio: f32,
    /// Fastest push-out speed for resolving penetration (m/s).
    pub max_push_velocity: f32,
    /// Approach speed below which restitution is ignored (m/s; default 1, as rapier and
    /// avian). A collider's [`RestitutionThreshold`] overrides it for its contacts.
    pub restitution_threshold: f32,
    /// Extra margin around bounding boxes and in contact prediction (m).
    pub margin: f32,
    /// How far a pair may move relative to itself before its contact manifolds are found
    /// again (m; at most [`ContactSettings::margin`], 0 finds them every step). Until then the
    /// points ride with the shapes and only their separations are updated, which is exact in
    /// depth and stale in position by at most this distance. rapier does the same with a
    /// default of 0.05 m.
    pub recycle_distance: f32,
    /// Most a body in contact may turn in one substep (rad; default 0.5, which is 120 rad/s at
    /// 60 Hz with 4 substeps; `f32::INFINITY` for no limit). The contact solver scales down
    /// the angular velocity of a body that touches anything (speculative contacts
    /// included) and spins faster; bodies in free flight are never limited. Why: a contact's
    /// lever arms are set at the start of the step, and a body that turns far within a
    /// substep brings other corners into the ground than the ones its contacts hold (a
    /// unit box spinning at 300 rad/s on the ground fell through it; at 0.5 rad per substep
    /// it stays above the ground up to 3,000 rad/s and comes to rest). More substeps raise
    /// the limit in rad/s. Box2D v3 limits every body to 0.25π per substep, Jolt to 47 rad/s
    /// and PhysX to 100 rad/s by default.
    pub max_rotation: f32,
    /// How frictions combine.
    pub friction_rule: CombineRule,
    /// How restitutions combine.
    pub restitution_rule: CombineRule,
}

impl Default for ContactSettings {
    fn default() -> Self {
        Self {
            hertz: 60.0,
            damping_ratio: 10.0,
            max_push_velocity: 3.0,
            restitution_threshold: 1.0,
            margin: 0.02,
            recycle_distance: 0.005,
            max_rotation: 0.5,
            friction_rule: CombineRule::GeometricMean,
            restitution_rule: CombineRule::Max,
        }
    }
}

/// Written when two colliders start touching (or, with a sensor, overlapping).
#[derive(Message, Debug, Clone, Copy, PartialEq, Eq)]
pub struct ContactStarted {
    /// One collider (the lower entity id).
    pub a: Entity,
    /// The other.
    pub b: Entity,
}

/// Triggered on a body with [`CollisionEventsEnabled`] when it starts touching `other`:
/// observe it with `commands.entity(body).observe(|event: On<ContactStart>| ..)`.
#[derive(EntityEvent, Debug, Clone, Copy, PartialEq, Eq)]
pub struct ContactStart {
    /// The body the event is for.
    pub entity: Entity,
    /// The one it touches.
    pub other: Entity,
}

/// Triggered on a body with [`CollisionEventsEnabled`] when it stops touching `other`.
#[derive(EntityEvent, Debug, Clone, Copy, PartialEq, Eq)]
pub struct ContactEnd {
    /// The body the event is for.
    pub entity: Entity,
    /// The one it touched.
    pub other: Entity,
}

/// Opts a body in to the [`ContactStart`] and [`ContactEnd`] entity events (messages are
/// written for every pair regardless). Opt-in, so a world that observes nothing pays nothing.
#[derive(
    serde::Serialize, serde::Deserialize, Component, Debug, Clone, Copy, PartialEq, Eq, Default,
)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct CollisionEventsEnabled;

/// Written when two colliders stop touching (or are despawned while touching).
#[derive(Message, Debug, Clone, Copy, PartialEq, Eq)]
pub struct ContactEnded {
    /// One collider (the lower entity id).
    pub a: Entity,
    /// The other.
    pub b: Entity,
}
