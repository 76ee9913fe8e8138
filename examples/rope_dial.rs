//! The accuracy dial on your own scene: how many substeps does a game's rope need to stay
//! within 1 cm of the converged answer, and what does that cost?
//!
//! ```sh
//! cargo run --release --example rope_dial
//! ```
//!
//! Copy this file and swap in your own `build` (spawn the scene) and `observe` (what must be
//! right: here the free end's position, in metres).

use bevy_ecs::prelude::*;
use hooke::prelude::*;
use hooke::tools::accuracy::{Reference, Setting, Sweep, sweep};

#[derive(Component)]
struct Tip;

fn main() -> hooke::Result<()> {
    // The scene: a 3 m rope of 31 nodes from the default builder, pinned at one end and
    // released level, under gravity, at hooke's default settings otherwise.
    let build = |world: &mut World| -> hooke::Result<()> {
        world.insert_resource(Gravity::new(Vec3::new(0.0, -9.81, 0.0))?);
        let rope = ChainBuilder::rope(Vec3::new(0.0, 3.0, 0.0), Vec3::new(3.0, 3.0, 0.0), 31)
            .spawn(world)?;
        if let Some(&tip) = rope.nodes.last() {
            world.entity_mut(tip).insert(Tip);
        }
        Ok(())
    };
    // What must be right: where the rope's free end is (m).
    let observe = |world: &mut World| -> Vec<f32> {
        let mut q = world.query_filtered::<&Position, With<Tip>>();
        q.iter(world).flat_map(|p| p.get().to_array()).collect()
    };
    let settings = Setting::grid(&Integrator::ALL, &[1, 2, 4, 8, 16]);
    let report = sweep(
        build,
        observe,
        &settings,
        // The finest setting stands in for the exact answer.
        Reference::Converged(Setting::new(Integrator::Rk4, 64)),
        Sweep::seconds(3.0),
    )?;
    println!(
        "{:<22} {:>12} {:>14}",
        "setting", "tip error", "time per step"
    );
    for m in &report.measurements {
        let err = if m.is_finite() {
            format!("{:.2} cm", m.error * 100.0)
        } else {
            "diverged".into()
        };
        println!(
            "{:<22} {err:>12} {:>11.1} µs",
            m.setting.to_string(),
            m.seconds_per_step * 1e6
        );
    }
    if let Some(d) = report.get(Setting::DEFAULT) {
        println!(
            "\nhooke's default ({}): {:.2} cm",
            d.setting,
            d.error * 100.0
        );
    }
    match report.cheapest_within(0.01) {
        Some(best) => println!(
            "cheapest within 1 cm: {} ({:.2} cm, {:.1} µs per step)",
            best.setting,
            best.error * 100.0,
            best.seconds_per_step * 1e6
        ),
        None => println!("no setting swept stays within 1 cm: sweep more substeps"),
    }
    if let Some(t) = report.reference_seconds_per_step {
        println!(
            "(the converged reference itself: {:.1} µs per step)",
            t * 1e6
        );
    }
    Ok(())
}
