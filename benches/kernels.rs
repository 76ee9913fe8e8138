//! Fine-grained kernels against hand-written raw loops, same harness as `perf_report`.
//!
//! ```text
//! cargo bench --bench kernels            # add -- --quick for a short run
//! ```

#[path = "../examples/common/timing.rs"]
mod timing;

use std::hint::black_box;

use glam::Vec3A;
use hooke::integrator::{Rk4Scratch, drift, kick};
use hooke::particles::fields::{advect_euler, advect_rk4};
use hooke::springs::spring_force;
use hooke::tools::scenes::jitter;
use timing::{Config, compare, line};

fn points(n: usize, salt: usize) -> Vec<Vec3A> {
    (0..n).map(|i| Vec3A::from(jitter(i + salt * n))).collect()
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let cfg = Config {
        samples: if quick { 11 } else { 21 },
        sample_time: if quick { 0.005 } else { 0.03 },
    };
    println!(
        "{:<48} {:>14} {:>14} {:>7}  note",
        "name", "ours_ns", "reference_ns", "ratio"
    );
    let n = 100_000;
    let (xa, xb, va, vb) = (points(n, 0), points(n, 1), points(n, 2), points(n, 3));
    let (mut out, mut out_ref) = (vec![Vec3A::ZERO; n], vec![Vec3A::ZERO; n]);

    // spring_force vs the lecture's formula written inline.
    let (ours, reference) = compare(
        &cfg,
        || {
            for i in 0..n {
                out[i] = spring_force(xa[i], xb[i], va[i], vb[i], 0.5, 100.0, 1.0);
            }
            black_box(&out);
        },
        || {
            for i in 0..n {
                let d = xb[i] - xa[i];
                let l = d.length();
                let (ks, kd, r) = (50.0f32, 0.5f32, 0.5f32);
                out_ref[i] = (ks * (l / r - 1.0) + kd * (vb[i] - va[i]).dot(d) / (r * l)) * d / l;
            }
            black_box(&out_ref);
        },
    );
    line(
        "kernel_spring_force_100k_vs_lecture_inline",
        ours,
        reference,
        &format!("{:.2} ns/spring", ours / n as f64),
    );

    // One symplectic Euler step over SoA arrays.
    let (mut x, mut v, a) = (xa.clone(), va.clone(), vb.clone());
    let (mut xr, mut vr) = (xa.clone(), va.clone());
    let h = 1.0 / 60.0;
    let (ours, reference) = compare(
        &cfg,
        || {
            for i in 0..n {
                v[i] = kick(v[i], a[i], h);
                x[i] = drift(x[i], v[i], h);
            }
            black_box(&x);
        },
        || {
            for i in 0..n {
                vr[i] += h * a[i];
                xr[i] += h * vr[i];
            }
            black_box(&xr);
        },
    );
    line(
        "kernel_symplectic_step_100k_vs_inline",
        ours,
        reference,
        "kick + drift",
    );

    // Four RK4 stages of an oscillator a(x) = −k x, vs the same arithmetic inline.
    let k = 40.0f32;
    let mut scratch = vec![Rk4Scratch::default(); n];
    let (ours, reference) = compare(
        &cfg,
        || {
            for i in 0..n {
                let mut s = Rk4Scratch::begin(x[i], v[i]);
                let (mut xs, mut vs) = (x[i], v[i]);
                for stage in 0..4 {
                    (xs, vs) = s.stage(stage, vs, -k * xs, h);
                }
                scratch[i] = s;
                (x[i], v[i]) = (xs, vs);
            }
            black_box(&x);
        },
        || {
            for i in 0..n {
                let (x0, v0) = (xr[i], vr[i]);
                let (k1x, k1v) = (v0, -k * x0);
                let (k2x, k2v) = (v0 + 0.5 * h * k1v, -k * (x0 + 0.5 * h * k1x));
                let (k3x, k3v) = (v0 + 0.5 * h * k2v, -k * (x0 + 0.5 * h * k2x));
                let (k4x, k4v) = (v0 + h * k3v, -k * (x0 + h * k3x));
                xr[i] = x0 + h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
                vr[i] = v0 + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
            }
            black_box(&xr);
        },
    );
    line(
        "kernel_rk4_oscillator_step_100k_vs_inline",
        ours,
        reference,
        "four stages with scratch",
    );

    // Vortex advection: RK4 and Euler through the same closure.
    let omega = Vec3A::new(0.0, 0.0, 2.0);
    let field = |p: Vec3A, _t: f32| omega.cross(p);
    let (ours, reference) = compare(
        &cfg,
        || {
            for p in x.iter_mut() {
                *p = advect_rk4(*p, 0.0, h, field);
            }
            black_box(&x);
        },
        || {
            for p in xr.iter_mut() {
                *p = advect_euler(*p, 0.0, h, field);
            }
            black_box(&xr);
        },
    );
    line(
        "kernel_advect_rk4_100k_vs_euler",
        ours,
        reference,
        "the price of 4 field evaluations",
    );
    rotation_kernels(&cfg);
}

/// Rotation kernels, each against a trivial quaternion product over the same data.
pub fn rotation_kernels(cfg: &Config) {
    use glam::Quat;
    use hooke::rigid::Inertia;
    use hooke::rigid::{OrientationUpdate, free_rotation_split, integrate_rotation};
    let n = 100_000;
    let inertia = Inertia::diagonal(1.0, 2.0, 3.0).unwrap();
    let l: Vec<Vec3A> = points(n, 4).iter().map(|p| *p * 3.0).collect();
    let mut q = vec![Quat::IDENTITY; n];
    let mut q_ref = vec![Quat::IDENTITY; n];
    let h = 1.0 / 60.0;
    let turn = Quat::from_rotation_y(0.01);
    let mut reference = || {
        for qi in q_ref.iter_mut() {
            *qi = (*qi * turn).normalize();
        }
        black_box(&q_ref);
    };
    let (ours, r) = compare(
        cfg,
        || {
            for i in 0..n {
                q[i] = free_rotation_split(q[i], &inertia, l[i], h, false);
            }
            black_box(&q);
        },
        &mut reference,
    );
    line(
        "kernel_rotation_split_100k_vs_quat_mul",
        ours,
        r,
        &format!("{:.1} ns/body", ours / n as f64),
    );
    let (ours, r) = compare(
        cfg,
        || {
            for i in 0..n {
                q[i] = integrate_rotation(
                    q[i],
                    inertia.angular_velocity(q[i], l[i]),
                    h,
                    OrientationUpdate::ExpMap,
                );
            }
            black_box(&q);
        },
        &mut reference,
    );
    line(
        "kernel_rotation_expmap_100k_vs_quat_mul",
        ours,
        r,
        &format!("{:.1} ns/body, with ω = I⁻¹L", ours / n as f64),
    );
    let mut w = vec![Vec3A::ZERO; n];
    let (ours, r) = compare(
        cfg,
        || {
            for i in 0..n {
                w[i] = inertia.angular_velocity(q[i], l[i]);
            }
            black_box(&w);
        },
        &mut reference,
    );
    line(
        "kernel_omega_from_l_100k_vs_quat_mul",
        ours,
        r,
        &format!("{:.1} ns/body", ours / n as f64),
    );
}
