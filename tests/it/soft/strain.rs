//! The soft-body material models against closed forms (numbers in `shared/DESIGN.md`):
//! uniaxial stretch, rotation invariance and Cauchy's ghost energy, derivatives against
//! finite differences (inverted elements included), and recovery from inversion.

use glam::{Mat3, Quat, Vec3};
use hooke::Error;
use hooke::soft::strain::{cauchy_strain, green_strain, polar_decomposition};
use hooke::soft::{Lame, Material, StrainModel};

fn unit(nu: f32) -> Lame {
    Material::new(1.0, nu, 1000.0).unwrap().lame()
}

#[test]
fn lame_parameters_and_bad_materials() {
    let l = unit(0.3);
    assert!((l.mu - 1.0 / 2.6).abs() < 1e-6 && (l.lambda - 0.3 / (1.3 * 0.4)).abs() < 1e-6);
    assert!(matches!(
        Material::new(1.0, 0.5, 1.0),
        Err(Error::OutOfRange { .. })
    ));
    assert!(matches!(
        Material::new(1.0, -1.0, 1.0),
        Err(Error::OutOfRange { .. })
    ));
    assert!(matches!(
        Material::new(1.0, f32::NAN, 1.0),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        Material::new(0.0, 0.3, 1.0),
        Err(Error::NotPositive { .. })
    ));
    assert!(matches!(
        Material::new(1e6, 0.3, -1.0),
        Err(Error::NotPositive { .. })
    ));
    let m = Material::new(1e6, 0.3, 1.0).unwrap();
    assert!(m.with_damping(-1.0, 0.0).is_err());
    assert_eq!(m.with_damping(0.5, 0.01).unwrap().damping(), (0.5, 0.01));
}

#[test]
fn rest_is_stress_free_for_every_model() {
    for model in StrainModel::ALL {
        let s = model.stress(Mat3::IDENTITY, unit(0.3));
        assert!(s.energy.abs() < 1e-7, "{model:?} Ψ {}", s.energy);
        assert!(
            s.piola.abs_diff_eq(Mat3::ZERO, 1e-6),
            "{model:?} P {}",
            s.piola
        );
    }
}

/// The lateral stretch s at which a bar stretched 1.1 along x carries no lateral stress:
/// P₂₂(diag(1.1, s, s)) = 0, by bisection.
fn lateral_stretch(model: StrainModel, lame: Lame) -> (f32, f32) {
    model.uniaxial(1.1, lame)
}

#[test]
fn uniaxial_stretch_matches_the_closed_forms() {
    let lame = unit(0.3);
    // St. Venant–Kirchhoff: s² = 1 − 2ν E₁₁ with E₁₁ = 0.105; P₁₁ = 1.1 E E₁₁.
    let (s, p11) = lateral_stretch(StrainModel::Green, lame);
    assert!((s - 0.96799).abs() < 2e-5, "Green lateral {s}");
    assert!((p11 - 0.1155).abs() < 1e-4, "Green P11/E {p11}");
    // Co-rotated (no rotation here, so linear): s = 1 − 0.1 ν, P₁₁ = 0.1 E.
    let (s, p11) = lateral_stretch(StrainModel::Corotated, lame);
    assert!((s - 0.970).abs() < 2e-5, "co-rotated lateral {s}");
    assert!((p11 - 0.100).abs() < 1e-4, "co-rotated P11/E {p11}");
    let (s, p11) = lateral_stretch(StrainModel::Cauchy, lame);
    assert!((s - 0.970).abs() < 2e-5 && (p11 - 0.100).abs() < 1e-4);
    // Neo-Hookean: no closed form quoted; it lies between the linear and St. Venant–Kirchhoff
    // answers (nonlinear, softer in stretch than StVK).
    let (s, p11) = lateral_stretch(StrainModel::StableNeoHookean, lame);
    println!("stable Neo-Hookean at stretch 1.1, ν = 0.3: lateral {s:.5}, P11/E {p11:.4}");
    assert!(s > 0.96 && s < 0.975, "{s}");
    assert!(p11 > 0.09 && p11 < 0.12, "{p11}");
}

#[test]
fn a_rigid_rotation_is_stress_free_except_for_cauchy_whose_ghost_energy_is_the_closed_form() {
    let lame = unit(0.3);
    for (axis, theta) in [
        (Vec3::Z, 90f32.to_radians()),
        (Vec3::new(1.0, 2.0, -0.5), 0.6),
    ] {
        let r = Mat3::from_quat(Quat::from_axis_angle(axis.normalize(), theta));
        for model in [
            StrainModel::Green,
            StrainModel::Corotated,
            StrainModel::StableNeoHookean,
        ] {
            let s = model.stress(r, lame);
            assert!(
                s.energy.abs() < 1e-5,
                "{model:?} Ψ {} at θ {theta}",
                s.energy
            );
            assert!(
                s.piola.abs_diff_eq(Mat3::ZERO, 1e-5),
                "{model:?} P {}",
                s.piola
            );
        }
        let ghost = StrainModel::Cauchy.energy_density(r, lame);
        let expected = 2.0 * (lame.mu + lame.lambda) * (1.0 - theta.cos()).powi(2);
        assert!(
            (ghost - expected).abs() < 1e-5 * expected.max(1.0),
            "{ghost} vs {expected}"
        );
    }
    // The figure of DESIGN.md: 1.923 E at 90° and ν = 0.3.
    let r = Mat3::from_rotation_z(90f32.to_radians());
    let ghost = StrainModel::Cauchy.energy_density(r, lame);
    assert!((ghost - 1.923).abs() < 1e-3, "{ghost}");
    assert!(green_strain(r).abs_diff_eq(Mat3::ZERO, 1e-6));
    assert!(!cauchy_strain(r).abs_diff_eq(Mat3::ZERO, 1e-3));
}

/// A small deterministic generator (xorshift), so the random matrices are the same each run.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
    }

    fn mat(&mut self, scale: f32) -> Mat3 {
        Mat3::from_cols_array(&std::array::from_fn(|_| scale * self.next()))
    }
}

/// Random deformation gradients: near rest, large, and (for the models that allow it)
/// inverted.
fn samples(inverted: bool) -> Vec<Mat3> {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let mut out = Vec::new();
    while out.len() < 40 {
        let f = Mat3::IDENTITY + rng.mat(0.5);
        let f = if inverted && out.len() % 2 == 1 {
            f * Mat3::from_diagonal(Vec3::new(1.0, 1.0, -0.7))
        } else {
            f
        };
        let j = f.determinant();
        // Away from flat elements, where the derivatives themselves are ill-conditioned.
        if j.abs() > 0.15 && (inverted || j > 0.0) {
            out.push(f);
        }
    }
    out
}

fn relative_gap(a: Mat3, b: Mat3) -> f32 {
    (a - b)
        .abs()
        .to_cols_array()
        .into_iter()
        .fold(0.0, f32::max)
        / b.abs().to_cols_array().into_iter().fold(1.0, f32::max)
}

#[test]
fn stress_is_the_derivative_of_energy_and_the_differential_that_of_stress() {
    let lame = unit(0.3);
    let mut rng = Rng(12345);
    let h = 1e-3f32;
    for model in StrainModel::ALL {
        let inverted = matches!(
            model,
            StrainModel::Corotated | StrainModel::StableNeoHookean
        );
        let (mut worst_p, mut worst_dp) = (0.0f32, 0.0f32);
        let mut negative = 0;
        for f in samples(inverted) {
            negative += usize::from(f.determinant() < 0.0);
            // P against central differences of Ψ, entry by entry.
            let mut fd = [0.0f32; 9];
            for (k, slot) in fd.iter_mut().enumerate() {
                let mut e = [0.0f32; 9];
                e[k] = h;
                let e = Mat3::from_cols_array(&e);
                *slot = (model.energy_density(f + e, lame) - model.energy_density(f - e, lame))
                    / (2.0 * h);
            }
            worst_p = worst_p.max(relative_gap(
                Mat3::from_cols_array(&fd),
                model.first_piola(f, lame),
            ));
            // dP[dF] against central differences of P along a random direction.
            let df = rng.mat(1.0);
            let fd = (model.first_piola(f + h * df, lame) - model.first_piola(f - h * df, lame))
                / (2.0 * h);
            worst_dp = worst_dp.max(relative_gap(fd, model.differential(f, df, lame)));
        }
        println!(
            "{model:?}: worst relative gap P {worst_p:.1e}, dP {worst_dp:.1e}, {negative} of 40 with det F < 0"
        );
        assert!(worst_p < 1e-3, "{model:?} P vs dΨ/dF: {worst_p}");
        assert!(worst_dp < 1e-3, "{model:?} dP vs dP/dF: {worst_dp}");
        if inverted {
            assert!(negative >= 15);
        }
    }
}

#[test]
fn polar_decomposition_is_a_rotation_times_a_symmetric_stretch_even_inverted() {
    for f in samples(true) {
        let (r, s) = polar_decomposition(f);
        assert!((r.transpose() * r).abs_diff_eq(Mat3::IDENTITY, 1e-5), "{r}");
        assert!((r.determinant() - 1.0).abs() < 1e-5);
        assert!(s.abs_diff_eq(s.transpose(), 1e-5));
        assert!((r * s).abs_diff_eq(f, 1e-5), "{} vs {f}", r * s);
        // The inversion lives in S.
        assert_eq!(s.determinant() < 0.0, f.determinant() < 0.0);
    }
}

/// Regression (issue 37): an element collapsed onto a point, a line or a plane (a jelly
/// thrown at the ground at 150 m/s crushes some) still has a rotation and a symmetric S
/// with F = R S. The SVD it used went through the eigenvectors of FᵀF and gave a NaN R for
/// F of rank 1, so the body went non-finite and was quarantined.
#[test]
fn polar_decomposition_holds_on_collapsed_elements() {
    let a = Vec3::new(0.3, 0.2, 0.1);
    let b = Vec3::new(-0.4, 0.9, 0.2);
    let collapsed = [
        Mat3::ZERO,
        Mat3::from_cols(Vec3::X, Vec3::ZERO, Vec3::ZERO),
        Mat3::from_cols(Vec3::X, Vec3::X, Vec3::ZERO),
        Mat3::from_cols(a, 2.0 * a, -a),
        Mat3::from_cols(a, b, a + b),
        Mat3::from_cols(Vec3::X, Vec3::Y, Vec3::ZERO),
        Mat3::from_cols(Vec3::X, Vec3::X * (1.0 + 1e-7), Vec3::Y),
    ];
    for f in collapsed {
        let (r, s) = polar_decomposition(f);
        assert!(r.is_finite() && s.is_finite(), "{f}: R {r}, S {s}");
        assert!(
            (r.transpose() * r).abs_diff_eq(Mat3::IDENTITY, 1e-5),
            "{f}: R {r}"
        );
        assert!(
            (r.determinant() - 1.0).abs() < 1e-5,
            "{f}: det R {}",
            r.determinant()
        );
        assert!(s.abs_diff_eq(s.transpose(), 1e-5), "{f}: S {s}");
        assert!((r * s).abs_diff_eq(f, 1e-5), "{f}: R S = {}", r * s);
        let lame = unit(0.3);
        for model in [StrainModel::Corotated, StrainModel::StableNeoHookean] {
            assert!(model.first_piola(f, lame).is_finite(), "{model:?} at {f}");
        }
    }
}

/// F = R₀ S with S symmetric positive definite has the polar factor R₀, whichever path
/// computes it: a mild stretch takes the fast (Newton) path, a very anisotropic one the SVD.
#[test]
fn polar_decomposition_returns_the_known_rotation_on_both_of_its_paths() {
    let r0 = Mat3::from_quat(glam::Quat::from_axis_angle(
        Vec3::new(1.0, 2.0, -0.5).normalize(),
        2.1,
    ));
    let q = Mat3::from_quat(glam::Quat::from_axis_angle(
        Vec3::new(-0.3, 0.4, 1.0).normalize(),
        0.7,
    ));
    for sigma in [
        Vec3::new(1.0, 1.0, 1.0),
        Vec3::new(1.0001, 0.9999, 1.0),
        Vec3::new(1.2, 0.9, 1.05),
        Vec3::new(3.0, 0.5, 1.0),
        Vec3::new(10.0, 0.1, 0.05),
        Vec3::new(2.0, 2.0, 0.01),
    ] {
        let stretch = q * Mat3::from_diagonal(sigma) * q.transpose();
        let (r, s) = polar_decomposition(r0 * stretch);
        assert!(r.abs_diff_eq(r0, 2e-5), "{sigma}: {r} vs {r0}");
        assert!(
            s.abs_diff_eq(stretch, 1e-4 * sigma.max_element()),
            "{sigma}: {s}"
        );
    }
}

/// Gradient descent on Ψ from an element flattened through itself (F₃₃ = −0.5).
fn relax(model: StrainModel, lame: Lame) -> Mat3 {
    relax_from(model, lame, Mat3::from_diagonal(Vec3::new(1.0, 1.0, -0.5)))
}

/// Gradient descent on Ψ from `f`.
fn relax_from(model: StrainModel, lame: Lame, mut f: Mat3) -> Mat3 {
    for _ in 0..4000 {
        f -= 0.05 * model.first_piola(f, lame);
    }
    f
}

#[test]
fn inverted_elements_recover_with_corotated_and_neo_hookean_not_with_green() {
    let lame = unit(0.3);
    for model in [StrainModel::Corotated, StrainModel::StableNeoHookean] {
        let f = relax(model, lame);
        assert!(
            f.determinant() > 0.99,
            "{model:?} ends at det {}",
            f.determinant()
        );
        assert!(
            model.energy_density(f, lame) < 1e-6,
            "{model:?} back at rest"
        );
    }
    // St. Venant–Kirchhoff cannot tell an element from its mirror image: it settles
    // inverted, at F₃₃ = −1, with zero energy. That is why it is no default.
    let f = relax(StrainModel::Green, lame);
    assert!(
        (f.determinant() + 1.0).abs() < 1e-3,
        "Green ends at det {}",
        f.determinant()
    );
}

#[test]
fn a_crushed_element_recovers_with_corotated_and_neo_hookean() {
    // Issue 37: stable Neo-Hookean without its log term has a local minimum at F = 0
    // (P(0) = 0, Hessian μ I), and an element crushed below J ≈ 0.024 collapsed to a point.
    // With −½ μ′ log(I_C + 1), the Hessian at F = 0 vanishes and J > 0 is downhill.
    let lame = unit(0.3);
    for model in [StrainModel::Corotated, StrainModel::StableNeoHookean] {
        for (scale, skew) in [(0.2154, 0.0), (0.05, 0.0), (0.1, 0.03), (0.01, 0.002)] {
            let mut start = Mat3::from_diagonal(Vec3::splat(scale));
            start.x_axis.y = skew;
            let f = relax_from(model, lame, start);
            println!(
                "{model:?} from {scale} I (J = {:.1e}): ends at det {:.4}",
                start.determinant(),
                f.determinant()
            );
            assert!(
                f.determinant() > 0.99 && model.energy_density(f, lame) < 1e-6,
                "{model:?} from {scale}: det {}",
                f.determinant()
            );
        }
    }
    // F = 0 itself stays a stationary point of stable Neo-Hookean (P(0) = 0), now a saddle:
    // only a crush to exactly a point is left there.
    let snh = StrainModel::StableNeoHookean;
    assert!(
        snh.first_piola(Mat3::ZERO, lame)
            .abs_diff_eq(Mat3::ZERO, 1e-6)
    );
    let rest_of_a_point = snh.energy_density(Mat3::ZERO, lame);
    assert!(snh.energy_density(Mat3::from_diagonal(Vec3::splat(0.05)), lame) < rest_of_a_point);
}
