//! Properties of the BSDF: analytic gradients, reciprocity, variants.

use approx::assert_relative_eq;
use brtf_model::{Bsdf, EvalOptions, Gradient, Material, MaterialKind, Variant, direction};
use glam::DVec3;
use proptest::prelude::*;

/// A material of `kind` from unit-interval draws, kept away from the
/// roughness-0 switch and the 1e-6 cut-offs so central differences are
/// meaningful.
fn material_from(kind: MaterialKind, u: &[f64]) -> Material {
    let mut args: Vec<f64> = (0..kind.n_args()).map(|i| 0.05 + 0.9 * u[i]).collect();
    args[3] = 0.02 + 0.6 * u[3];
    args[4] = 0.03 + 0.3 * u[4];
    if kind.is_anisotropic() {
        args[5] = 0.03 + 0.3 * u[5];
    }
    if kind == MaterialKind::Trans {
        args[5] = 0.1 + 0.8 * u[5];
    }
    let orient = DVec3::new(u[6] - 0.5, u[7] - 0.5, 0.3).normalize();
    Material::new(kind, &args, Some(orient)).unwrap()
}

fn kinds() -> impl Strategy<Value = MaterialKind> {
    prop::sample::select(MaterialKind::ALL.to_vec())
}

fn variants() -> impl Strategy<Value = Variant> {
    prop::sample::select(Variant::ALL.to_vec())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// ∂f/∂a from `eval_with_gradient` equals a central difference of `eval`.
    #[test]
    fn gradient_matches_central_differences(
        kind in kinds(),
        variant in variants(),
        u in prop::array::uniform8(0.0f64..1.0),
        theta_in in 0.0f64..80.0, phi_in in 0.0f64..360.0,
        theta_out in 0.0f64..179.0, phi_out in 0.0f64..360.0,
        omega in prop::sample::select(vec![0.0, 1e-4, 6.8e-5]),
    ) {
        prop_assume!((theta_out - 90.0).abs() > 1.0);
        let material = material_from(kind, &u);
        let options = EvalOptions { variant, source_omega: omega, ..EvalOptions::default() };
        let (l, v) = (direction(theta_in, phi_in), direction(theta_out, phi_out));
        let bsdf = Bsdf::new(&material, &options);
        let mut grad = Gradient::default();
        let value = bsdf.eval_with_gradient(l, v, &mut grad);
        prop_assert_eq!(value, bsdf.eval(l, v));
        let args = material.args().to_vec();
        for j in 0..args.len() {
            let h = 1e-6 * args[j].abs().max(1e-2);
            let mut plus = args.clone();
            plus[j] += h;
            let mut minus = args.clone();
            minus[j] -= h;
            let fp = Bsdf::new(&material.with_args(&plus).unwrap(), &options).eval(l, v);
            let fm = Bsdf::new(&material.with_args(&minus).unwrap(), &options).eval(l, v);
            for ch in 0..3 {
                // Skip points sitting on a cut-off (1e-6) or switch, where f jumps.
                let jump = (fp[ch] - value[ch]).abs().max((value[ch] - fm[ch]).abs());
                if jump > 1e-7 && ((fp[ch] - value[ch]) - (value[ch] - fm[ch])).abs() > 0.5 * jump {
                    continue;
                }
                let numeric = (fp[ch] - fm[ch]) / (2.0 * h);
                let analytic = grad.d[j][ch];
                let scale = analytic.abs().max(numeric.abs()).max(1.0);
                prop_assert!(
                    (numeric - analytic).abs() <= 1e-5 * scale,
                    "{kind} {variant} arg {j} ch {ch}: analytic {analytic} numeric {numeric}"
                );
            }
        }
    }

    /// A geometry prepared by one `Bsdf` serves any other of the same type,
    /// orientation and options: `eval_geometry` equals `eval` bit for bit,
    /// with and without the gradient.
    #[test]
    fn prepared_geometry_serves_other_arguments(
        kind in kinds(),
        variant in variants(),
        u in prop::array::uniform8(0.0f64..1.0),
        w in prop::array::uniform8(0.0f64..1.0),
        theta_in in 0.0f64..89.0, phi_in in 0.0f64..360.0,
        theta_out in 0.0f64..180.0, phi_out in 0.0f64..360.0,
        omega in prop::sample::select(vec![0.0, 6.8e-5]),
    ) {
        let options = EvalOptions { variant, source_omega: omega, ..EvalOptions::default() };
        let first = material_from(kind, &u);
        let second = first.with_args(material_from(kind, &w).args()).unwrap();
        let (l, v) = (direction(theta_in, phi_in), direction(theta_out, phi_out));
        let geometry = Bsdf::new(&first, &options).geometry(l, v);
        let bsdf = Bsdf::new(&second, &options);
        prop_assert_eq!(bsdf.eval_geometry(&geometry), bsdf.eval(l, v));
        let (mut g1, mut g2) = (Gradient::default(), Gradient::default());
        let a = bsdf.eval_geometry_with_gradient(&geometry, &mut g1);
        let b = bsdf.eval_with_gradient(l, v, &mut g2);
        prop_assert_eq!(a, b);
        prop_assert_eq!(g1, g2);
        let mut g0 = Gradient::default();
        let first = bsdf.eval_geometry_channels_with_gradient::<1>(&geometry, &mut g0);
        prop_assert_eq!(first, [b[0], 0.0, 0.0]);
        for (d0, d2) in g0.d.iter().zip(&g2.d) {
            prop_assert_eq!(d0[0], d2[0]);
        }
    }

    /// The diffuse part never exceeds the whole, and is the whole when the
    /// material has no specular lobe: spec 0 (and tspec 0) on a rough
    /// surface, except in
    /// the Ward 1992 variant, whose Fresnel-like term gives a non-metal a
    /// lobe even then.
    #[test]
    fn diffuse_part_is_part_of_the_whole(
        kind in kinds(),
        variant in variants(),
        u in prop::array::uniform8(0.0f64..1.0),
        theta_in in 0.0f64..89.0, phi_in in 0.0f64..360.0,
        theta_out in 0.0f64..180.0, phi_out in 0.0f64..360.0,
    ) {
        let options = EvalOptions { variant, ..EvalOptions::default() };
        let material = material_from(kind, &u);
        let (l, v) = (direction(theta_in, phi_in), direction(theta_out, phi_out));
        let bsdf = Bsdf::new(&material, &options);
        let (whole, diffuse) = (bsdf.eval(l, v), bsdf.eval_diffuse(l, v));
        for ch in 0..3 {
            prop_assert!(diffuse[ch] >= 0.0 && diffuse[ch] <= whole[ch] * (1.0 + 1e-12));
        }
        if variant != Variant::Ward1992 {
            // No reflected lobe (spec 0), no transmitted one (tspec 0).
            let mut args = material.args().to_vec();
            args[3] = 0.0;
            if kind.is_transmitting() {
                let last = args.len() - 1;
                args[last] = 0.0;
            }
            let matte = Bsdf::new(&material.with_args(&args).unwrap(), &options);
            prop_assert_eq!(matte.eval_diffuse(l, v), matte.eval(l, v));
        }
    }

    /// The reflection part of the radiance variant is reciprocal: f(l,v) = f(v,l).
    /// (Except where rtrace's Fresnel estimate is on, which is symmetric too.)
    #[test]
    fn radiance_reflection_is_reciprocal(
        kind in kinds(),
        u in prop::array::uniform8(0.0f64..1.0),
        theta_in in 0.0f64..89.0, phi_in in 0.0f64..360.0,
        theta_out in 0.0f64..89.0, phi_out in 0.0f64..360.0,
    ) {
        let material = material_from(kind, &u);
        let bsdf = Bsdf::new(&material, &EvalOptions::default());
        let (l, v) = (direction(theta_in, phi_in), direction(theta_out, phi_out));
        let a = bsdf.eval(l, v);
        let b = bsdf.eval(v, l);
        for ch in 0..3 {
            // The 1e-6 lobe cut-off is not symmetric in floating point.
            prop_assert!((a[ch] - b[ch]).abs() <= 1e-9 + 1e-9 * a[ch].abs(),
                "{kind}: f(l,v)={} f(v,l)={}", a[ch], b[ch]);
        }
    }
}

#[test]
fn roughness_zero_reflection_is_reciprocal_with_fresnel() {
    let m = Material::new(MaterialKind::Plastic, &[0.5, 0.4, 0.3, 0.05, 0.0], None).unwrap();
    let bsdf = Bsdf::new(&m, &EvalOptions::default());
    let (l, v) = (direction(20.0, 0.0), direction(70.0, 120.0));
    let (a, b) = (bsdf.eval(l, v), bsdf.eval(v, l));
    for ch in 0..3 {
        assert_relative_eq!(a[ch], b[ch], max_relative = 1e-12);
    }
}

#[test]
fn lambertian_is_rho_over_pi_on_both_sides_only_for_trans() {
    let plastic = Material::new(MaterialKind::Plastic, &[0.2, 0.5, 0.8, 0.0, 0.0], None).unwrap();
    let bsdf = Bsdf::new(&plastic, &EvalOptions::default());
    let front = bsdf.eval(direction(30.0, 0.0), direction(60.0, 90.0));
    assert_relative_eq!(front[1], 0.5 / std::f64::consts::PI, max_relative = 1e-12);
    let back = bsdf.eval(direction(30.0, 0.0), direction(120.0, 90.0));
    assert_eq!(back, [0.0; 3]);
}

#[test]
fn variants_agree_at_the_mirror_peak_and_differ_elsewhere() {
    // At θ_h = 0 the W-G-M-D and the 2004 manual lobes coincide.
    let m = Material::new(MaterialKind::Metal, &[0.9, 0.9, 0.9, 0.8, 0.1], None).unwrap();
    let radiance = Bsdf::new(&m, &EvalOptions::with_variant(Variant::Radiance));
    let manual = Bsdf::new(&m, &EvalOptions::with_variant(Variant::Manual2004));
    let l = direction(45.0, 0.0);
    let mirror = direction(45.0, 180.0);
    assert_relative_eq!(
        radiance.eval(l, mirror)[0],
        manual.eval(l, mirror)[0],
        max_relative = 1e-12
    );
    let off = direction(55.0, 170.0);
    let (a, b) = (radiance.eval(l, off)[0], manual.eval(l, off)[0]);
    assert!(
        (a - b).abs() > 1e-3 * a,
        "variants should differ off-peak: {a} vs {b}"
    );
}

#[test]
fn bad_materials_are_rejected() {
    assert!(Material::new(MaterialKind::Metal, &[0.5; 4], None).is_err());
    assert!(Material::new(MaterialKind::Metal, &[0.5, 0.5, f64::NAN, 0.5, 0.1], None).is_err());
    let err = Material::new(MaterialKind::Metal2, &[0.5, 0.5, 0.5, 0.5, 0.0, 0.1], None);
    assert!(err.unwrap_err().to_string().contains("roughness too small"));
}
