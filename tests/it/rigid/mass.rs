//! Mass properties from parry shapes against closed forms.

use glam::{Mat3, Quat, Vec3};
use hooke::Error;
use hooke::rigid::Inertia;
use hooke::rigid::MassProperties;
use hooke::rigid::parallel_axis;
use parry3d::math::Pose;
use parry3d::shape::SharedShape;
use std::f32::consts::PI;

const RHO: f32 = 700.0;

fn close(a: f32, b: f32, tol: f32) -> bool {
    (a - b).abs() <= tol * b.abs().max(1e-6)
}

/// Principal moments sorted, so the frame parry picked does not matter.
fn sorted(p: Vec3) -> [f32; 3] {
    let mut a = p.to_array();
    a.sort_by(f32::total_cmp);
    a
}

fn assert_moments(props: &MassProperties, expected: [f32; 3], what: &str) {
    let got = sorted(props.inertia.principal());
    let mut want = expected;
    want.sort_by(f32::total_cmp);
    for i in 0..3 {
        assert!(
            close(got[i], want[i], 2e-3),
            "{what}: moments {got:?} vs {want:?}"
        );
    }
}

#[test]
fn ball() {
    let r = 0.3;
    let p = MassProperties::from_shape(&*SharedShape::ball(r), RHO).unwrap();
    let m = 4.0 / 3.0 * PI * r * r * r * RHO;
    assert!(close(p.mass, m, 1e-4));
    assert_moments(&p, [0.4 * m * r * r; 3], "ball");
    assert!(p.center_of_mass.length() < 1e-6);
}

#[test]
fn cuboid() {
    let (a, b, c) = (0.5, 0.25, 0.1); // half extents
    let p = MassProperties::from_shape(&*SharedShape::cuboid(a, b, c), RHO).unwrap();
    let m = 8.0 * a * b * c * RHO;
    assert!(close(p.mass, m, 1e-4));
    let third = m / 3.0;
    assert_moments(
        &p,
        [
            third * (b * b + c * c),
            third * (a * a + c * c),
            third * (a * a + b * b),
        ],
        "cuboid",
    );
}

#[test]
fn cylinder() {
    let (hh, r) = (0.4, 0.2);
    let p = MassProperties::from_shape(&*SharedShape::cylinder(hh, r), RHO).unwrap();
    let h = 2.0 * hh;
    let m = PI * r * r * h * RHO;
    assert!(close(p.mass, m, 1e-4));
    let side = m / 12.0 * (3.0 * r * r + h * h);
    assert_moments(&p, [side, 0.5 * m * r * r, side], "cylinder");
}

#[test]
fn capsule() {
    let (hh, r) = (0.3, 0.1);
    let p = MassProperties::from_shape(&*SharedShape::capsule_y(hh, r), RHO).unwrap();
    let h = 2.0 * hh;
    let m_cyl = PI * r * r * h * RHO;
    let m_caps = 4.0 / 3.0 * PI * r * r * r * RHO; // both hemispheres
    assert!(close(p.mass, m_cyl + m_caps, 1e-4));
    let axial = m_cyl * r * r / 2.0 + m_caps * 0.4 * r * r;
    let side = m_cyl * (h * h / 12.0 + r * r / 4.0)
        + m_caps * (0.4 * r * r + h * h / 4.0 + 3.0 * h * r / 8.0);
    assert_moments(&p, [side, axial, side], "capsule");
}

#[test]
fn cone() {
    let (hh, r) = (0.5, 0.3);
    let p = MassProperties::from_shape(&*SharedShape::cone(hh, r), RHO).unwrap();
    let h = 2.0 * hh;
    let m = PI * r * r * h / 3.0 * RHO;
    assert!(close(p.mass, m, 1e-3));
    // About the centre of mass, a quarter of the height above the base.
    let side = 3.0 / 20.0 * m * r * r + 3.0 / 80.0 * m * h * h;
    assert_moments(&p, [side, 0.3 * m * r * r, side], "cone");
    assert!(
        (p.center_of_mass.y - (-hh + h / 4.0)).abs() < 1e-3,
        "{}",
        p.center_of_mass
    );
}

fn cube_corners(a: f32) -> Vec<Vec3> {
    let mut v = Vec::new();
    for i in 0..8 {
        v.push(Vec3::new(
            if i & 1 == 0 { -a } else { a },
            if i & 2 == 0 { -a } else { a },
            if i & 4 == 0 { -a } else { a },
        ));
    }
    v
}

#[test]
fn convex_hull_and_closed_trimesh_of_a_cube_match_the_cuboid() {
    let a = 0.2;
    let cuboid = MassProperties::from_shape(&*SharedShape::cuboid(a, a, a), RHO).unwrap();
    let hull =
        MassProperties::from_shape(&*SharedShape::convex_hull(&cube_corners(a)).unwrap(), RHO)
            .unwrap();
    assert!(close(hull.mass, cuboid.mass, 1e-4));
    assert_moments(&hull, sorted(cuboid.inertia.principal()), "hull");

    // Closed cube mesh, outward-facing triangles.
    let v = cube_corners(a);
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let mut idx = Vec::new();
    for q in quads {
        idx.push([q[0], q[1], q[2]]);
        idx.push([q[0], q[2], q[3]]);
    }
    let mesh = SharedShape::trimesh(v, idx).unwrap();
    let tri = MassProperties::from_shape(&*mesh, RHO).unwrap();
    assert!(
        close(tri.mass, cuboid.mass, 1e-4),
        "{} vs {}",
        tri.mass,
        cuboid.mass
    );
    assert_moments(&tri, sorted(cuboid.inertia.principal()), "trimesh");
}

#[test]
fn compound_uses_the_parallel_axis_theorem() {
    let (r, d) = (0.1, 0.5);
    let ball = SharedShape::ball(r);
    let shape = SharedShape::compound(vec![
        (
            Pose::from_translation(Vec3::new(-d, 0.0, 0.0)),
            ball.clone(),
        ),
        (Pose::from_translation(Vec3::new(d, 0.0, 0.0)), ball),
    ]);
    let p = MassProperties::from_shape(&*shape, RHO).unwrap();
    let mb = 4.0 / 3.0 * PI * r * r * r * RHO;
    let own = 0.4 * mb * r * r;
    assert!(close(p.mass, 2.0 * mb, 1e-4));
    assert_moments(
        &p,
        [
            2.0 * own,
            2.0 * (own + mb * d * d),
            2.0 * (own + mb * d * d),
        ],
        "compound",
    );

    // And our own parallel-axis function gives the same tensor.
    let i_ball = Mat3::from_diagonal(Vec3::splat(own));
    let total = parallel_axis(i_ball, mb, Vec3::new(d, 0.0, 0.0))
        + parallel_axis(i_ball, mb, Vec3::new(-d, 0.0, 0.0));
    assert!(close(total.x_axis.x, 2.0 * own, 1e-5));
    assert!(close(total.y_axis.y, 2.0 * (own + mb * d * d), 1e-5));
    assert!(total.x_axis.y.abs() < 1e-7);
}

#[test]
fn parallel_axis_off_diagonal_terms() {
    // Point mass at d: I = m (|d|² E − d dᵀ).
    let d = Vec3::new(1.0, 2.0, 0.0);
    let i = parallel_axis(Mat3::ZERO, 2.0, d);
    assert_eq!(i.x_axis, Vec3::new(2.0 * 4.0, -2.0 * 2.0, 0.0));
    assert_eq!(i.y_axis, Vec3::new(-4.0, 2.0 * 1.0, 0.0));
    assert_eq!(i.z_axis, Vec3::new(0.0, 0.0, 2.0 * 5.0));
}

#[test]
fn full_tensors_are_diagonalised_and_bad_ones_rejected() {
    // diag(1, 2, 3) turned by 30° about z.
    let r = Mat3::from_quat(Quat::from_rotation_z(std::f32::consts::FRAC_PI_6));
    let tensor = r * Mat3::from_diagonal(Vec3::new(1.0, 2.0, 3.0)) * r.transpose();
    let p = MassProperties::from_tensor(1.0, Vec3::ZERO, tensor).unwrap();
    assert_moments(&p, [1.0, 2.0, 3.0], "rotated tensor");
    let back = p.inertia.tensor();
    assert!(back.abs_diff_eq(tensor, 1e-4), "{back} vs {tensor}");
    // Not positive definite.
    let bad = Mat3::from_diagonal(Vec3::new(1.0, -1.0, 1.0));
    assert!(matches!(
        MassProperties::from_tensor(1.0, Vec3::ZERO, bad),
        Err(Error::NotPositive { .. })
    ));
    assert!(
        MassProperties::from_tensor(
            1.0,
            Vec3::ZERO,
            Mat3::from_diagonal(Vec3::new(1.0, 0.0, 1.0))
        )
        .is_err()
    );
    assert!(MassProperties::from_tensor(f32::NAN, Vec3::ZERO, Mat3::IDENTITY).is_err());
    assert!(MassProperties::from_tensor(1.0, Vec3::ZERO, Mat3::from_diagonal(Vec3::NAN)).is_err());
}

#[test]
fn shapes_without_volume_and_bad_densities_are_errors() {
    assert!(matches!(
        MassProperties::from_shape(&*SharedShape::cuboid(1.0, 0.0, 1.0), RHO),
        Err(Error::ZeroVolume(_))
    ));
    assert!(matches!(
        MassProperties::from_shape(&*SharedShape::ball(0.0), RHO),
        Err(Error::ZeroVolume(_))
    ));
    let hf = SharedShape::heightfield(parry3d::utils::Array2::new(3, 3, vec![0.0; 9]), Vec3::ONE);
    assert!(matches!(
        MassProperties::from_shape(&*hf, RHO),
        Err(Error::ZeroVolume(_))
    ));
    for density in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        assert!(
            MassProperties::from_shape(&*SharedShape::ball(1.0), density).is_err(),
            "{density}"
        );
    }
    assert!(matches!(
        Inertia::diagonal(1.0, 0.0, 1.0),
        Err(Error::NotPositive { .. })
    ));
    let p = MassProperties::from_shape(&*SharedShape::ball(1.0), 1.0).unwrap();
    assert!(p.with_mass(0.0).is_err());
    let scaled = p.with_mass(2.0 * p.mass).unwrap();
    assert!(close(
        scaled.inertia.principal().x,
        2.0 * p.inertia.principal().x,
        1e-6
    ));
}
