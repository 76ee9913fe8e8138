//! The whole step of a world of rigid bodies under constant forces, in the contact solver's
//! own arrays (see [`crate::core::whole_step`] for when it runs).
//!
//! Per substep of length h, for every live body, exactly as [`crate::core::schedule::SubstepSchedule`] does:
//!
//! ```text
//! v ← v + h f/m,  L ← L + h τ              f = f_ext + m g s, τ = τ_ext (constant)
//! biased contact pass                       (solver reads v, ω = I⁻¹L, x − x₀, ΔR)
//! x ← x + h v,  q ← exp(½ h ω) ⊗ q          (free-rotation splitting)
//! checks: non-finite q or L, spin; in the last substep also distance and speed
//! relax pass, then q ← q/|q|, ω ← I(q)⁻¹ L
//! ```
//!
//! The bodies are loaded once and stored once; solver bodies come first, in the solver's
//! order, so the passes read and write them without a lookup. A body that a check
//! quarantines stops after its substep, as the schedule's deferred quarantine does.

use bevy_ecs::prelude::*;
use bevy_ecs::system::SystemState;
use glam::{Quat, Vec3A};

use crate::collision::ContactSettings;
use crate::collision::narrow_phase::Contacts;
use crate::collision::solver::ContactSolver;
use crate::collision::solver::exchange::{read_values, write_values};
use crate::collision::solver::plugin::{biased_pass, relax_pass};
use crate::core::quarantine::{DivergenceGuard, QuarantineReason, Quarantined};
use crate::core::time::{PhysicsTime, SubstepTime};
use crate::integrator::{Integrator, constant_force, drift, kick};
use crate::particles::{
    ExternalForce, Force, Gravity, GravityScale, LinearVelocity, Mass, Position,
};
use crate::rigid::{
    AngularMomentum, AngularVelocity, ExternalTorque, Inertia, LockedAxes, OrientationUpdate,
    Renormalization, Rotation, Torque, free_rotation_split, turn,
};

/// Registers the path; called by the collision plugin.
pub(crate) fn install(world: &mut World) {
    let state = SystemState::<Params>::new(world);
    world.insert_resource(Cache(Some(state)));
    world.insert_resource(crate::core::whole_step::WholeStepRunner(run));
    crate::core::whole_step::block_on::<crate::collision::nodes::coupling::NodeImpulse>(world);
}

type Body<'a> = (
    &'a mut Position,
    &'a mut Rotation,
    &'a mut LinearVelocity,
    &'a mut AngularMomentum,
    &'a mut AngularVelocity,
    &'a Mass,
    &'a Inertia,
    Option<&'a ExternalForce>,
    Option<&'a GravityScale>,
    Option<&'a ExternalTorque>,
    &'a mut Force,
    &'a mut Torque,
    Option<&'a LockedAxes>,
);

/// What the schedule's integrators move: not quarantined, not asleep.
type Moving = (Without<Quarantined>, Without<crate::core::rest::Sleeping>);

type Params = (
    Commands<'static, 'static>,
    Res<'static, PhysicsTime>,
    Res<'static, ContactSettings>,
    Res<'static, DivergenceGuard>,
    Option<Res<'static, Gravity>>,
    ResMut<'static, ContactSolver>,
    ResMut<'static, Contacts>,
    Query<'static, 'static, (Entity, Body<'static>), Moving>,
    Query<'static, 'static, (), (With<Mass>, Moving)>,
    Query<'static, 'static, (), (With<Inertia>, Moving)>,
    Local<'static, Scratch>,
);

#[derive(Resource)]
struct Cache(Option<SystemState<Params>>);

/// One body's state for the step, in one place: the passes touch all of it together.
#[derive(Clone, Copy)]
struct Hot {
    x: Vec3A,
    v: Vec3A,
    l: Vec3A,
    /// ω as the renormalise set last stored it (the spin check and kinematic turns read it).
    w: Vec3A,
    /// f / m, constant over the step.
    a: Vec3A,
    torque: Vec3A,
    q: Quat,
    inertia: Inertia,
    /// False once a check quarantined the body: it stays where that substep left it.
    live: bool,
    /// The body's place in query order.
    order: u32,
}

/// The step's bodies: solver bodies at their solver index, then the rest.
#[derive(Default)]
struct Scratch {
    hot: Vec<Hot>,
    entity: Vec<Entity>,
    /// Per body in query order, its place in `hot`.
    slot: Vec<u32>,
    frozen: Vec<u32>,
}

/// The registered runner: declines unless the world uses the default integration and
/// takes two or more substeps a step.
fn run(world: &mut World) -> bool {
    let defaults = world
        .get_resource::<Integrator>()
        .is_some_and(|i| *i == Integrator::SymplecticEuler)
        && world
            .get_resource::<OrientationUpdate>()
            .is_some_and(|u| *u == OrientationUpdate::Splitting)
        && world.get_resource::<Renormalization>().is_some_and(|r| r.0);
    // Loading and storing cost a free body about 1.7 of the schedule's substeps' worth of
    // savings (1,000 tumbling boxes: 889 k instructions a step against 784 k at one substep,
    // 1.40 M against 1.46 M at two): with one substep the schedule is the cheaper path.
    let substeps = world
        .get_resource::<PhysicsTime>()
        .map_or(0, PhysicsTime::substeps);
    if !defaults || substeps < 2 {
        return false;
    }
    let Some(mut state) = world
        .get_resource_mut::<Cache>()
        .and_then(|mut c| c.0.take())
    else {
        return false;
    };
    let ran = match state.get_mut(world) {
        Ok(params) => step(params),
        Err(_) => false,
    };
    state.apply(world);
    if let Some(mut cache) = world.get_resource_mut::<Cache>() {
        cache.0 = Some(state);
    }
    ran
}

/// Loads the bodies; false if some solver body is outside what this path integrates.
fn load(
    s: &mut Scratch,
    solver: &ContactSolver,
    bodies: &Query<(Entity, Body), Moving>,
    g: Vec3A,
) -> bool {
    let n = bodies.iter().len();
    let solved = solver.bodies.len();
    if n < solved {
        return false;
    }
    // Every place below n is written exactly once when every solver body is found, which
    // is checked before anything reads them.
    let blank = Hot {
        x: Vec3A::ZERO,
        v: Vec3A::ZERO,
        l: Vec3A::ZERO,
        w: Vec3A::ZERO,
        a: Vec3A::ZERO,
        torque: Vec3A::ZERO,
        q: Quat::IDENTITY,
        inertia: Inertia::INFINITE,
        live: true,
        order: 0,
    };
    s.hot.resize(n, blank);
    s.entity.resize(n, Entity::PLACEHOLDER);
    s.slot.clear();
    let mut next = solved;
    let mut found = 0;
    for (e, (x, q, v, l, w, m, inertia, ext, scale, torque, _, _, locks)) in bodies {
        let at = if let Some(j) = solver.index.get(e, &solver.bodies) {
            found += 1;
            j as usize
        } else {
            next += 1;
            next - 1
        };
        let (Some(hot), Some(entity)) = (s.hot.get_mut(at), s.entity.get_mut(at)) else {
            return false;
        };
        // As `hold_locked_translations` leaves them: nothing along a locked axis.
        let free = locks.map(|l| l.translation_mask());
        let f = constant_force(m, ext, scale, g);
        let f = free.map_or(f, |k| f * k);
        *hot = Hot {
            x: x.0,
            v: free.map_or(v.0, |k| v.0 * k),
            l: l.0,
            w: w.0,
            a: f * m.inverse(),
            torque: torque.map_or(Vec3A::ZERO, |t| t.0),
            q: q.0,
            inertia: *inertia,
            live: true,
            order: s.slot.len() as u32,
        };
        *entity = e;
        s.slot.push(at as u32);
    }
    found == solved
}

/// Loads solver body `j` into the solver's state (a quarantined body is no longer in the
/// schedule's queries: its solver state stays as the last pass left it).
#[inline(always)]
fn read_body(solver: &mut ContactSolver, j: usize, b: &Hot, frozen: &mut Vec<u32>) {
    read_values(solver, j, b.x, b.q, b.v, Some(&b.l), Some(&b.w), frozen);
}

/// A check that quarantined a body: in which of the two checks, the body's place in query
/// order, its place in the arrays, why.
type Trip = (u8, u32, usize, QuarantineReason);

/// The per-substep constants of the position phase's checks.
#[derive(Clone, Copy)]
struct Limits {
    last: bool,
    speed_scale: f32,
    reach_scale: f32,
    spin: f32,
}

/// The velocity phase.
#[inline(always)]
fn kick_body(b: &mut Hot, h: f32) {
    b.v = kick(b.v, b.a, h);
    if !b.inertia.is_infinite() {
        b.l += h * b.torque;
    }
}

/// The position phase: x ← x + h v and q turned, then the schedule's checks on the result:
/// in the last substep the linear integrator's (x and v finite, within the guard's distance
/// and speed), in every substep the angular integrator's (q and L finite, ω within the spin
/// limit).
#[inline(always)]
fn drift_and_turn(
    b: &mut Hot,
    k: usize,
    h: f32,
    limits: Limits,
    guard: &DivergenceGuard,
    trips: &mut Vec<Trip>,
) {
    b.x = drift(b.x, b.v, h);
    // `turn` with the update fixed to splitting; the split called in place, as `turn` out of
    // line cost a fifth of the turn (50-row pyramid: 80 k instructions a step).
    b.q = if b.inertia.is_infinite() {
        turn(
            b.q,
            b.l,
            b.w,
            &b.inertia,
            h,
            OrientationUpdate::Splitting,
            false,
        )
    } else {
        free_rotation_split(b.q, &b.inertia, b.l, h, false)
    };
    let (x, v) = (b.x, b.v);
    if limits.last && (x * limits.reach_scale + v * limits.speed_scale) * 0.0 != Vec3A::ZERO {
        let reason = if !(x.is_finite() && v.is_finite()) {
            Some(QuarantineReason::NonFiniteState)
        } else {
            guard.check(x, v, None)
        };
        if let Some(reason) = reason {
            trips.push((0, b.order, k, reason));
        }
    }
    if !(b.q.is_finite() && b.l.is_finite()) {
        trips.push((1, b.order, k, QuarantineReason::NonFiniteState));
    } else if b.w.length_squared() > limits.spin {
        let angular_speed = b.w.length();
        trips.push((1, b.order, k, QuarantineReason::SpunOut { angular_speed }));
    }
}

/// q ← q/|q| and ω ← I(q)⁻¹ L, as the renormalise set does.
#[inline(always)]
fn renormalize(b: &mut Hot) {
    let unit = b.q.normalize();
    if unit.is_finite() {
        b.q = unit;
    }
    if !b.inertia.is_infinite() {
        b.w = b.inertia.angular_velocity(b.q, b.l);
    }
}

#[allow(clippy::type_complexity)] // the system's parameters, as one tuple
fn step(
    (
        mut commands,
        time,
        settings,
        guard,
        gravity,
        mut solver,
        mut contacts,
        mut bodies,
        massive,
        turning,
        mut scratch,
    ): bevy_ecs::system::SystemParamItem<Params>,
) -> bool {
    let g = gravity.map_or(Vec3A::ZERO, |g| g.get().into());
    let s = &mut *scratch;
    // Every body the integrators would move must be one this path moves.
    let n = bodies.iter().len();
    if massive.iter().len() != n || turning.iter().len() != n || !load(s, &solver, &bodies, g) {
        return false;
    }
    let guard = *guard;
    let (count, h, t0) = (time.substeps(), time.substep_dt(), time.elapsed());
    let solved = solver.bodies.len();
    let solving = !solver.manifolds.is_empty();
    let mut last = SubstepTime::default();
    let mut trips: Vec<Trip> = Vec::new();
    for index in 0..count {
        let t = SubstepTime {
            h,
            t: (t0 + f64::from(h) * f64::from(index)) as f32,
            index,
            count,
        };
        last = t;
        let limits = Limits {
            last: t.is_last(),
            speed_scale: guard.overflow_scale(),
            reach_scale: guard.distance_scale(),
            spin: guard.max_angular_speed * guard.max_angular_speed,
        };
        // Bodies outside the solver, and every body when nothing is solved: the whole
        // substep in one pass.
        let first_free = if solving { solved } else { 0 };
        let (in_solver, free) = s.hot.split_at_mut(first_free);
        for (k, b) in free.iter_mut().enumerate() {
            if b.live {
                kick_body(b, h);
                drift_and_turn(b, first_free + k, h, limits, &guard, &mut trips);
                renormalize(b);
            }
        }
        // Three sweeps over the solver bodies a substep, each doing for one body what the
        // schedule does for all of them between two passes: the bodies' arrays are read
        // once per pass, not once per stage.
        if solving {
            s.frozen.clear();
            for (j, b) in in_solver.iter_mut().enumerate() {
                if b.live {
                    kick_body(b, h);
                    read_body(&mut solver, j, b, &mut s.frozen);
                }
            }
            solver.after_gather(&s.frozen);
            biased_pass(&mut solver, &t, &settings);
            s.frozen.clear();
            for (j, b) in in_solver.iter_mut().enumerate() {
                if b.live {
                    write_values(&solver, j, &mut b.v, Some(&mut b.l));
                    drift_and_turn(b, j, h, limits, &guard, &mut trips);
                    read_body(&mut solver, j, b, &mut s.frozen);
                }
            }
            solver.after_gather(&s.frozen);
            relax_pass(&mut solver, &mut contacts, &t, &settings);
            for (j, b) in in_solver.iter_mut().enumerate() {
                if b.live {
                    write_values(&solver, j, &mut b.v, Some(&mut b.l));
                    renormalize(b);
                }
            }
        }
        // The schedule quarantines after the substep: one system's bodies, then the other's,
        // each in query order.
        trips.sort_by_key(|trip| (trip.0, trip.1));
        for (_, _, k, reason) in trips.drain(..) {
            commands.entity(s.entity[k]).insert(Quarantined { reason });
            s.hot[k].live = false;
        }
    }
    commands.insert_resource(last);
    let bodies = bodies.iter_mut().zip(&s.slot);
    for ((_, body), &at) in bodies {
        let (mut x, mut q, mut v, mut l, mut w, m, _, ext, scale, torque, mut f, mut t, locks) =
            body;
        let b = &s.hot[at as usize];
        // The accumulators as the schedule leaves them: nothing adds to them in a world on
        // this path, so they hold the constant force and torque (without what a lock takes).
        let force = constant_force(m, ext, scale, g);
        f.bypass_change_detection().0 = locks.map_or(force, |l| force * l.translation_mask());
        t.bypass_change_detection().0 = torque.map_or(Vec3A::ZERO, |t| t.0);
        x.0 = b.x;
        q.0 = b.q;
        v.0 = b.v;
        l.bypass_change_detection().0 = b.l;
        w.bypass_change_detection().0 = b.w;
    }
    true
}
