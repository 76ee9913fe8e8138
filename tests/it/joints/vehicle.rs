//! A four-wheeled car on hinge motors: it gains speed at the closed form's rate while the
//! motors give all their torque, then holds the target speed rolling without slipping,
//! straight and level.

use hooke::prelude::*;
use hooke::tools::joint_scenes::FourWheeler;

#[test]
fn a_car_on_wheel_motors_speeds_up_at_the_closed_form_rate_and_holds_its_speed() {
    let settings = super::frame_rates();
    for (name, make) in settings {
        let car = FourWheeler::default();
        let mut world = make();
        let parts = car.spawn(&mut world, 0.0).unwrap();
        let dt = world.resource::<PhysicsTime>().dt();
        let a = car.acceleration();
        let (mut t, mut gap) = (0.0_f32, 0.0_f32);
        let mut at_one = None;
        // The motors start at once, as a game's would.
        while t < 5.0 - 1e-4 {
            world.step_physics();
            t += dt;
            gap = gap.max(world.resource::<JointDiagnostics>().largest_gap);
            if at_one.is_none() && t >= 1.0 - 1e-4 {
                at_one = Some(world.get::<LinearVelocity>(parts.chassis).unwrap().0);
            }
        }
        let v1 = at_one.unwrap();
        let v = world.get::<LinearVelocity>(parts.chassis).unwrap().0;
        let x = world.get::<Position>(parts.chassis).unwrap().0;
        let q = world.get::<Rotation>(parts.chassis).unwrap().0;
        let tilt = (q * Vec3::Y).angle_between(Vec3::Y);
        let spins: Vec<f32> = parts
            .wheels
            .iter()
            .map(|&w| -world.get::<AngularVelocity>(w).unwrap().0.z)
            .collect();
        println!(
            "{name}: at 1 s {:.4} m/s (closed form {:.4}), at 5 s {:.4} m/s, wheels {spins:.3?} rad/s (v / r = {:.3}), x {:.3} m, z {:.4} m, tilt {:.3}°, gap {:.2} mm",
            v1.x,
            a * 1.0,
            v.x,
            v.x / FourWheeler::WHEEL,
            x.x,
            x.z,
            tilt.to_degrees(),
            1e3 * gap
        );
        assert!((v1.x - a).abs() < 0.02 * a, "{name}: {} m/s at 1 s", v1.x);
        // The wheels spin at the motors' target; the car goes at that spin times the
        // rolling radius, the wheel's radius less how far the contacts let it sink under
        // the car's weight (1.6 mm at the defaults, 6.5 mm at 30 Hz × 4): 0.5 % and 2.2 %
        // short of r ω.
        for s in &spins {
            let target = car.speed / FourWheeler::WHEEL;
            assert!(
                (s - target).abs() < 0.005 * target,
                "{name}: a wheel at {s} rad/s"
            );
        }
        assert!(
            (v.x - car.speed).abs() < 0.03 * car.speed,
            "{name}: {} m/s",
            v.x
        );
        assert!(
            x.z.abs() < 0.02 && v.z.abs() < 0.01,
            "{name}: drifted to z = {}",
            x.z
        );
        assert!(tilt < 0.02, "{name}: tilted {tilt} rad");
        assert!(gap < 0.01, "{name}: a hinge parted {gap} m");
        for e in parts.wheels.iter().chain([&parts.chassis]) {
            assert!(world.get::<Quarantined>(*e).is_none());
        }
    }
}
