//! The jointed problems: a hinged rod's large swing against its ODE, and how far a long
//! chain's joints part, each over every integrator × substeps.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};
use hooke::prelude::*;
use hooke::tools::accuracy::{Reference, Sweep, sweep};
use hooke::tools::joint_scenes::HangingChain;

use crate::problems::{G, Problem, runs, settings};

/// Marks the body whose position is compared.
#[derive(Component)]
struct Swinging;

/// The rod's half extents (m): 0.1 × 1 × 0.1, hinged at its top end.
const HALF: Vec3 = Vec3::new(0.05, 0.5, 0.05);

/// θ'' = −(g d / (I_p / m)) sin θ for the rod hinged at its end, θ from hanging straight
/// down, integrated by RK4 in f64 at 1,000 steps a frame of `dt`: the angle at the end of
/// each of `frames` frames, from rest at `start`.
fn rod_angles(start: f64, dt: f64, frames: u32) -> Vec<f64> {
    let (a, l, d) = (
        2.0 * f64::from(HALF.x),
        2.0 * f64::from(HALF.y),
        f64::from(HALF.y),
    );
    let w2 = f64::from(G) * d / ((l * l + a * a) / 12.0 + d * d);
    let f = |(th, om): (f64, f64)| (om, -w2 * th.sin());
    let (mut s, h) = ((start, 0.0), dt / 1000.0);
    let mut out = Vec::with_capacity(frames as usize);
    for _ in 0..frames {
        for _ in 0..1000 {
            let k1 = f(s);
            let k2 = f((s.0 + 0.5 * h * k1.0, s.1 + 0.5 * h * k1.1));
            let k3 = f((s.0 + 0.5 * h * k2.0, s.1 + 0.5 * h * k2.1));
            let k4 = f((s.0 + h * k3.0, s.1 + h * k3.1));
            s.0 += h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
            s.1 += h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
        }
        out.push(s.0);
    }
    out
}

/// A rod on a [`RevoluteJoint`] released level: the error of its centre over 4 s.
pub fn hinged_rod(quick: bool) -> hooke::Result<Problem> {
    let pivot = Vec3::new(0.0, 2.0, 0.0);
    let cfg = Sweep::seconds(4.0).with_timing_runs(runs(quick));
    let angles = rod_angles(std::f64::consts::FRAC_PI_2, f64::from(cfg.dt), cfg.steps);
    let dt = f64::from(cfg.dt);
    let report = sweep(
        move |w: &mut World| {
            w.insert_resource(Gravity::new(Vec3::new(0.0, -G, 0.0))?);
            w.resource_mut::<hooke::sleep::SleepSettings>().enabled = false;
            let turn = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
            let rod = w
                .spawn((
                    RigidBody::Dynamic,
                    Collider::cuboid(HALF.x, HALF.y, HALF.z)?,
                    Position((pivot + turn * Vec3::new(0.0, -HALF.y, 0.0)).into()),
                    Rotation(turn),
                    Swinging,
                ))
                .id();
            w.spawn(
                RevoluteJoint::to_world(rod, Vec3::Z)
                    .with_anchors(pivot, Vec3::new(0.0, HALF.y, 0.0)),
            );
            Ok(())
        },
        |w: &mut World| {
            let mut q = w.query_filtered::<&Position, With<Swinging>>();
            q.iter(w).flat_map(|p| p.get().to_array()).collect()
        },
        &settings(),
        Reference::exact(move |t| {
            let i = ((t / dt).round() as usize).clamp(1, angles.len());
            let (th, d) = (angles[i - 1], f64::from(HALF.y));
            let p = pivot.as_dvec3();
            vec![p.x + d * th.sin(), p.y - d * th.cos(), p.z]
        }),
        cfg,
    )?;
    Ok(Problem::new(
        "hinged rod swinging (90°, revolute joint)",
        "max error of the rod's centre over 4 s, per its 1 m length",
        "f64 RK4 of θ'' = −(m g d / I_p) sin θ (the rigid rod's own ODE)",
        1.0,
        report,
    ))
}

/// The 100-link chain hanging an 8 kg load kicked at 3 m/s ([`HangingChain`]): how far its
/// joints part over 5 s (2 s quick).
pub fn chain_gap(quick: bool) -> hooke::Result<Problem> {
    let seconds = if quick { 2.0 } else { 5.0 };
    let report = sweep(
        |w: &mut World| {
            HangingChain { links: 100 }.build(w)?;
            Ok(())
        },
        |w: &mut World| vec![w.resource::<JointDiagnostics>().largest_gap],
        &settings(),
        Reference::exact(|_| vec![0.0]),
        Sweep::seconds(seconds).with_timing_runs(runs(quick)),
    )?;
    Ok(Problem::new(
        "100-link chain, 8 kg load kicked (ball joints)",
        "widest gap between any joint's anchors over the run, per the 0.2 m link",
        "the joints held exactly (no gap)",
        0.2,
        report,
    ))
}
