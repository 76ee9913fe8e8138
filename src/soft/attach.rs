//! Soft-body nodes attached to rigid bodies, two-way: the body carries the nodes and feels
//! the soft body's pull.
//!
//! After both have moved in a substep, each attachment is a position constraint
//! C_k = x_k − p_k = 0 between node k and its point p_k = x_B + R (l_k − c) on the body. One
//! impulse λ_k (N·s) per node, +λ on the node and −λ on the body at p_k, closes every gap at
//! once:
//!
//! ```text
//! (W_soft + W_body) λ = −C / h
//! W_soft = H⁻¹ / h²                         (the implicit solve's response; M⁻¹ when explicit)
//! W_body(k, l) = I₃ / M − [r_k]× I⁻¹ [r_l]×   (r = p − x_B; zero for a static or kinematic body)
//! ```
//!
//! H is the backward-Euler system matrix M/h² + K + D/h of the soft body's last solve, so
//! the constraint sees the body's stiffness, not a lone node's mass: a stiff bar holding a
//! heavy box passes the box's weight through the bar in one substep instead of letting the
//! box sink while a light node absorbs the impulses. The response comes from the solve's
//! Cholesky factor (3 solves per attached node, kept until the factor is renewed); a body
//! without a factor (above `max_factor_entries`, or explicit) uses its lumped masses, which
//! couple more softly. Then the soft body moves by Δx = H⁻¹ Λ / h (v += Δx/h) and the rigid
//! body's v, L, x and q by the opposite impulses, so momentum passes exactly between them.
//!
//! Unlike contacts (see [`super::contact`]), the body moves in the same substep: a two-sided
//! constraint that leaves the body's part of the gap to the next substep overshoots (tried:
//! the bar's box hangs 16.4 mm low instead of 10.3). The price is that an attached body that
//! also rests on rigid contacts can be pushed into them within a step, which its contacts
//! then undo.

use bevy_ecs::prelude::*;
use glam::{Mat3, Vec3, Vec3A};
use nalgebra::{DMatrix, DVector};

use crate::collision::nodes::coupling::{RigidSide, move_soft, soft_response};
use crate::integrator::skyline::SkylineCholesky;

use crate::core::error::{Error, Result};
use crate::core::quarantine::Quarantined;
use crate::core::time::SubstepTime;
use crate::integrator::{ImplicitEuler, ImplicitState};
use crate::particles::{LinearVelocity, Mass, Nodes, Position};
use crate::rigid::{AngularMomentum, AngularVelocity, CenterOfMass, Inertia, Rotation};

/// The most nodes one attachment holds: its constraint is solved as one dense 3n × 3n system.
pub const MAX_ATTACHED_NODES: usize = 128;

/// Nodes of the [`Nodes`] on this entity (a [`super::SoftBody`]'s, or any mesh's) attached
/// to rigid bodies. A node keeps the place on the body it had when the attachment first ran
/// (its offset in the body's frame), and both sides exchange impulses from then on (see the
/// module docs). Pinned nodes are skipped; a missing or quarantined body leaves its nodes
/// free until it is back.
#[derive(serde::Serialize, serde::Deserialize, Component, Debug, Clone, Default)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect), reflect(Component))]
pub struct NodeAttachments {
    links: Vec<Link>,
}

#[derive(serde::Serialize, serde::Deserialize, Debug, Clone)]
#[cfg_attr(feature = "bevy", derive(bevy_reflect::Reflect))]
struct Link {
    body: Entity,
    nodes: Vec<u32>,
    /// The nodes' points in the body's frame (m), set at the first substep.
    local: Vec<Vec3>,
    /// The impulse the body got in the last substep (N·s, world) and that substep's length.
    impulse: Vec3,
    h: f32,
    /// W_soft for the nodes, kept while the factor it came from is held.
    #[cfg_attr(feature = "bevy", reflect(ignore))]
    response: Option<(u64, f32, DMatrix<f64>)>,
}

impl NodeAttachments {
    /// The bodies attached, for a snapshot to map onto its restored entities.
    pub(crate) fn bodies_mut(&mut self) -> impl Iterator<Item = &mut Entity> {
        self.links.iter_mut().map(|l| &mut l.body)
    }

    /// Whether every link indexes into a mesh of `nodes` nodes and has a local point per
    /// node once set (see [`crate::particles::Nodes`]).
    pub(crate) fn fits(&self, nodes: usize) -> bool {
        self.links.iter().all(|l| {
            l.nodes.iter().all(|&i| (i as usize) < nodes)
                && (l.local.is_empty() || l.local.len() == l.nodes.len())
        })
    }

    /// Attachments to one body: `nodes` are node indices of this entity's mesh.
    ///
    /// # Errors
    /// As [`NodeAttachments::attach`].
    pub fn new(body: Entity, nodes: impl IntoIterator<Item = usize>) -> Result<Self> {
        let mut a = Self::default();
        a.attach(body, nodes)?;
        Ok(a)
    }

    /// Attaches `nodes` to `body` where they are at the next substep (replacing an earlier
    /// attachment to the same body).
    ///
    /// # Errors
    /// [`Error::TooFew`] for no nodes; [`Error::OutOfRange`] for more than
    /// [`MAX_ATTACHED_NODES`]; [`Error::IndexOutOfRange`] for an index past `u32` (indices
    /// past the mesh's nodes are skipped when the step meets them).
    pub fn attach(&mut self, body: Entity, nodes: impl IntoIterator<Item = usize>) -> Result<()> {
        let mut list = Vec::new();
        for i in nodes {
            list.push(u32::try_from(i).map_err(|_| Error::IndexOutOfRange {
                what: "attached node",
                index: i,
                len: u32::MAX as usize,
            })?);
        }
        list.sort_unstable();
        list.dedup();
        if list.is_empty() {
            return Err(Error::TooFew {
                what: "attached nodes",
                min: 1,
                got: 0,
            });
        }
        if list.len() > MAX_ATTACHED_NODES {
            return Err(Error::OutOfRange {
                what: "attached nodes per body",
                value: list.len() as f32,
                range: "at most MAX_ATTACHED_NODES (128)",
            });
        }
        self.detach(body);
        self.links.push(Link {
            body,
            nodes: list,
            local: Vec::new(),
            impulse: Vec3::ZERO,
            h: 0.0,
            response: None,
        });
        Ok(())
    }

    /// Lets go of `body`.
    pub fn detach(&mut self, body: Entity) {
        self.links.retain(|l| l.body != body);
    }

    /// The bodies attached.
    pub fn bodies(&self) -> impl Iterator<Item = Entity> + '_ {
        self.links.iter().map(|l| l.body)
    }

    /// The force the soft body exerted on `body` over the last substep (N, world frame):
    /// its impulse over the substep's length. None if not attached or not yet run.
    #[must_use]
    pub fn force_on(&self, body: Entity) -> Option<Vec3> {
        let l = self.links.iter().find(|l| l.body == body)?;
        (l.h > 0.0).then(|| l.impulse / l.h)
    }
}

type Soft<'a> = (
    Entity,
    &'a mut Nodes,
    &'a mut NodeAttachments,
    Option<&'a ImplicitState>,
    Option<&'a ImplicitEuler>,
);

type Body<'a> = (
    &'a mut Position,
    &'a mut Rotation,
    Option<&'a mut LinearVelocity>,
    Option<&'a mut AngularMomentum>,
    Option<&'a mut AngularVelocity>,
    Option<&'a Mass>,
    Option<&'a Inertia>,
    Option<&'a CenterOfMass>,
    Option<&'a crate::rigid::LockedAxes>,
);

/// Solves every attachment once per substep, after both sides have moved.
///
/// Meshes are taken in entity order: a body held by two meshes moves with the first one's
/// link before the second's, and a query's table order is not kept by a restored snapshot
/// (see [`crate::collision::nodes::collide_nodes`]).
pub(crate) fn solve_attachments(
    time: Res<SubstepTime>,
    mut order: Local<Vec<Entity>>,
    mut meshes: Query<Soft, Without<Quarantined>>,
    mut bodies: Query<Body, (Without<Quarantined>, Without<Nodes>)>,
) {
    let h = time.h;
    if h.is_nan() || h <= 0.0 {
        return;
    }
    order.clear();
    order.extend(meshes.iter().map(|(e, ..)| e));
    order.sort_unstable();
    for &mesh in order.iter() {
        let Ok((_, mut nodes, mut attachments, state, implicit)) = meshes.get_mut(mesh) else {
            continue;
        };
        let nodes = nodes.bypass_change_detection();
        let factor = state
            .filter(|_| implicit.is_some())
            .and_then(|s| s.factor.as_ref())
            .filter(|f| f.is_factored());
        for link in &mut attachments.bypass_change_detection().links {
            link.impulse = Vec3::ZERO;
            link.h = h;
            let Ok(body) = bodies.get_mut(link.body) else {
                continue;
            };
            // A body whose state went bad this substep is quarantined by its own check;
            // the link would hand its NaN to the nodes, whose check has already run.
            let (x, q, v, _, w, ..) = &body;
            let moving_bad = v.as_ref().is_some_and(|v| !v.0.is_finite())
                || w.as_ref().is_some_and(|w| !w.0.is_finite());
            if moving_bad || !(x.0.is_finite() && q.0.is_finite()) {
                continue;
            }
            solve_link(link, nodes, body, factor, h);
        }
    }
}

fn solve_link(
    link: &mut Link,
    n: &mut Nodes,
    (mut x, mut q, v, l, w, mass, inertia, com, locks): bevy_ecs::query::QueryItem<
        '_,
        '_,
        Body<'_>,
    >,
    factor: Option<&SkylineCholesky>,
    h: f32,
) {
    let len = n.x.len();
    let com = com.map_or(Vec3::ZERO, |c| c.0);
    if link.local.len() != link.nodes.len() {
        // Not anchored before the step (the body appeared since): anchor now.
        anchor(link, n, &x, &q, com);
    }
    // The nodes that take part: in range and free.
    let active: Vec<usize> = (0..link.nodes.len())
        .filter(|&k| (link.nodes[k] as usize) < len && n.inv_mass[link.nodes[k] as usize] > 0.0)
        .collect();
    if active.is_empty() {
        return;
    }
    let a = active.len();
    let node = |k: usize| link.nodes[k] as usize;
    let rows: Vec<(usize, Vec3)> = active
        .iter()
        .flat_map(|&k| [Vec3::X, Vec3::Y, Vec3::Z].map(|d| (node(k), d)))
        .collect();
    // G_soft, kept while the factor it came from is held.
    let cached = matches!(
        (&link.response, factor),
        (Some((g, hh, m)), Some(f)) if *g == f.generation() && *hh == h && m.nrows() == 3 * a
    );
    if !cached {
        link.response = factor.map(|f| (f.generation(), h, soft_response(n, Some(f), &rows, h)));
    }
    let soft = match (&link.response, factor) {
        (Some((_, _, g)), Some(_)) => g.clone(),
        _ => soft_response(n, None, &rows, h),
    };
    let mut rigid = RigidSide {
        x: Vec3::from(x.0),
        v: v.as_ref().map_or(Vec3::ZERO, |v| Vec3::from(v.0)),
        w: w.as_ref().map_or(Vec3::ZERO, |w| Vec3::from(w.0)),
        inv_mass: crate::rigid::LockedAxes::inverse_mass_of(
            locks,
            mass.map_or(0.0, |m| m.inverse()),
        )
        .into(),
        inv_inertia: inertia.map_or(Mat3::ZERO, |i| i.world_inverse_tensor(q.0)),
        dynamic: false,
        linear: Vec3::ZERO,
        angular: Vec3::ZERO,
    };
    rigid.dynamic =
        v.is_some() && (rigid.inv_mass != Vec3::ZERO || rigid.inv_inertia != Mat3::ZERO);
    // The body feels each impulse at the node, not at its own point, so that the pair acts
    // at one place and turns nothing: the exchange keeps the angular momentum.
    let at: Vec<Vec3> = active.iter().map(|&k| Vec3::from(n.x[node(k)])).collect();
    let body_rows: Vec<(Vec3, Vec3)> = rows
        .iter()
        .enumerate()
        .map(|(r, &(_, d))| (at[r / 3], d))
        .collect();
    let system = soft + rigid.response(&body_rows);
    // The gaps to close: each node to its point on the body.
    let rot = Mat3::from_quat(q.0);
    let hd = f64::from(h);
    let rhs = DVector::<f64>::from_iterator(
        3 * a,
        active.iter().enumerate().flat_map(|(row, &k)| {
            let gap = at[row] - (Vec3::from(x.0) + rot * (link.local[k] - com));
            gap.to_array().map(|g| -f64::from(g) / hd)
        }),
    );
    let scale = system.diagonal().amax().max(f64::MIN_POSITIVE);
    let Some(lambda) = (system.clone() + DMatrix::identity(3 * a, 3 * a) * (1e-12 * scale))
        .cholesky()
        .map(|c| c.solve(&rhs))
        .or_else(|| system.lu().solve(&rhs))
    else {
        return;
    };
    if !lambda.iter().all(|v| v.is_finite()) {
        return;
    }
    let impulses: Vec<(usize, Vec3)> = (0..a)
        .map(|row| {
            let j = Vec3::new(
                lambda[3 * row] as f32,
                lambda[3 * row + 1] as f32,
                lambda[3 * row + 2] as f32,
            );
            (node(active[row]), j)
        })
        .collect();
    move_soft(n, factor, &impulses, h);
    for (row, &(_, j)) in impulses.iter().enumerate() {
        rigid.take(at[row], -j);
    }
    link.impulse = -impulses.iter().map(|&(_, j)| j).sum::<Vec3>();
    if !rigid.touched() {
        return;
    }
    let (dx, nq) = rigid.moved_pose(q.0, h);
    if let Some(mut v) = v {
        v.0 = Vec3A::from(rigid.v);
    }
    if let Some(mut l) = l {
        l.bypass_change_detection().0 += Vec3A::from(rigid.angular);
    }
    if let Some(mut w) = w {
        w.bypass_change_detection().0 = Vec3A::from(rigid.w);
    }
    x.0 += Vec3A::from(dx);
    q.0 = nq;
}

/// Each node's place in the body's frame, from where both are now.
fn anchor(link: &mut Link, n: &Nodes, x: &Position, q: &Rotation, com: Vec3) {
    let inverse = q.0.inverse();
    link.local = link
        .nodes
        .iter()
        .map(|&i| {
            let p = n.x.get(i as usize).copied().unwrap_or(Vec3A::ZERO);
            inverse * (Vec3::from(p) - Vec3::from(x.0)) + com
        })
        .collect();
    link.response = None;
}

/// Before a step: new attachments take the nodes' places on their bodies as they are, before
/// anything moves.
pub(crate) fn anchor_attachments(
    mut meshes: Query<(&Nodes, &mut NodeAttachments), Changed<NodeAttachments>>,
    bodies: Query<(&Position, &Rotation, Option<&CenterOfMass>), Without<Nodes>>,
) {
    for (n, mut attachments) in &mut meshes {
        for link in &mut attachments.bypass_change_detection().links {
            if link.local.len() == link.nodes.len() {
                continue;
            }
            if let Ok((x, q, com)) = bodies.get(link.body) {
                anchor(link, n, x, q, com.map_or(Vec3::ZERO, |c| c.0));
            }
        }
    }
}
