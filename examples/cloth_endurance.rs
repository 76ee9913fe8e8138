//! A stiff 64 × 64 cloth pinned at two corners, integrated by backward Euler at 60 Hz with one
//! substep for 10⁴ steps (2 min 47 s of simulated time): it must stay finite and bounded.
//! Symplectic Euler needs the substeps its stability limit asks for, printed at the start.
//!
//! ```text
//! cargo run --release --example cloth_endurance -- [--steps 10000] [--newton 8]
//! ```
//!
//! Too slow for the test suite (about 70 ms per step on a 2-core machine at the default
//! eight Newton iterations, 12 minutes in all): CI runs it (`.ci/run`), and it exits with an
//! error if the cloth is quarantined or a node gets farther than 2.6 m from the pins.

use bevy_ecs::prelude::*;
use glam::Vec3;
use hooke::cloth::ClothBuilder;
use hooke::core::quarantine::Quarantined;
use hooke::integrator::ImplicitEuler;
use hooke::integrator::ImplicitState;
use hooke::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let value = |flag: &str, default: u32| -> Result<u32, String> {
        match args.iter().position(|a| a == flag) {
            Some(i) => args
                .get(i + 1)
                .ok_or(format!("{flag} needs a value"))?
                .parse()
                .map_err(|e| format!("{flag}: {e}")),
            None => Ok(default),
        }
    };
    let (steps, newton) = (value("--steps", 10_000)?, value("--newton", 8)?);
    let mut w = hooke::tools::scenes::world_with(
        1.0 / 60.0,
        1,
        Integrator::SymplecticEuler,
        Vec3::new(0.0, -9.81, 0.0),
    )?;
    w.resource_mut::<hooke::sleep::SleepSettings>().enabled = false;
    let (nodes, net) = ClothBuilder::new(Vec3::new(0.0, 2.0, 0.0), 64, 64, 0.03)
        .stiffness(5e3, 1e3, 1e2)
        .build()?;
    let limit = net.critical_step(&nodes);
    println!(
        "64 x 64 cloth, {} springs: explicit limit {limit:.2e} s, symplectic Euler needs {} substeps at 60 Hz",
        net.len(),
        ((1.0 / 60.0) / (0.9 * limit)).ceil()
    );
    let settings = ImplicitEuler {
        max_newton: newton,
        ..Default::default()
    };
    let e = w.spawn((nodes, net, settings)).id();
    let start = std::time::Instant::now();
    let (mut farthest, mut fastest, mut cg) = (0.0f32, 0.0f32, 0u64);
    for step in 1..=steps {
        w.step_physics();
        let n = w.get::<Nodes>(e).ok_or("cloth gone")?;
        // Pinned at (0, 2, 0) and (1.89, 2, 0): no node can be farther than 1.9 m + stretch.
        for p in n.positions() {
            farthest = farthest.max((p.x - 0.945).hypot(p.y - 2.0).hypot(p.z));
        }
        fastest = fastest.max(n.max_speed());
        cg += u64::from(
            w.get::<ImplicitState>(e)
                .ok_or("state gone")?
                .last_solve()
                .cg_iterations,
        );
        if w.get::<Quarantined>(e).is_some() {
            return Err(format!("quarantined at step {step}").into());
        }
        if step % 1000 == 0 {
            println!(
                "step {step}: farthest node {farthest:.3} m from the pins' midpoint, fastest {fastest:.2} m/s, now {:.3} m/s; {:.1} ms and {:.0} CG per step so far",
                n.max_speed(),
                start.elapsed().as_secs_f64() * 1e3 / f64::from(step),
                cg as f64 / f64::from(step)
            );
        }
    }
    // The far corners hang 2.11 m from the pins' midpoint unstretched; 2.6 m would be a 23 %
    // stretch, far past the 12 % the springs settle at.
    if !(farthest.is_finite() && farthest < 2.6) {
        return Err(format!("unbounded: a node {farthest} m from the pins").into());
    }
    println!("{steps} steps: finite, bounded (farthest {farthest:.3} m), fastest {fastest:.2} m/s");
    Ok(())
}
