//! Shared helpers: materials, statistics.

#![allow(dead_code)]

use brtf_model::{Composite, EvalOptions, Material, MaterialKind, Shape};
use brtf_trace::Shader;
use glam::DVec3;

/// A material from its kind and arguments (orientation +x for `*2`).
pub(crate) fn mat(kind: MaterialKind, args: &[f64]) -> Material {
    Material::new(kind, args, Some(DVec3::new(1.0, 0.3, 0.0))).expect("valid material")
}

/// The shader of one primitive.
pub(crate) fn shader_of(material: &Material, options: &EvalOptions) -> Shader {
    Shader::new(&Composite::from_material(material), options).expect("one primitive")
}

/// Default options (radiance variant, ω = 0).
pub(crate) fn opts() -> EvalOptions {
    EvalOptions::default()
}

/// A set of materials covering every type.
pub(crate) fn zoo() -> Vec<(&'static str, Material)> {
    use MaterialKind::*;
    vec![
        ("plastic", mat(Plastic, &[0.6, 0.5, 0.4, 0.05, 0.1])),
        ("plastic rough", mat(Plastic, &[0.2, 0.3, 0.8, 0.3, 0.35])),
        ("metal", mat(Metal, &[0.9, 0.7, 0.5, 0.9, 0.15])),
        ("trans", mat(Trans, &[0.8, 0.8, 0.7, 0.04, 0.12, 0.6, 0.5])),
        ("plastic2", mat(Plastic2, &[0.5, 0.5, 0.5, 0.1, 0.08, 0.25])),
        ("metal2", mat(Metal2, &[0.8, 0.8, 0.9, 0.8, 0.3, 0.1])),
        (
            "trans2",
            mat(Trans2, &[0.7, 0.7, 0.7, 0.05, 0.15, 0.2, 0.5, 0.6]),
        ),
    ]
}

/// A lobe sum of `lobes` lobes of `kind` (orientation fitted when
/// `oriented`, else +x turned a little) from its flat arguments.
pub(crate) fn lobe_sum(
    kind: MaterialKind,
    lobes: usize,
    oriented: bool,
    args: &[f64],
) -> Composite {
    let shape = Shape::new(kind, lobes, oriented).expect("a shape");
    Composite::new(shape, args, Some(DVec3::new(1.0, 0.3, 0.0))).expect("valid lobe sum")
}

/// Lobe sums of every plastic and metal type, and a mixture of types as
/// a `.rad` file's constant `mixfunc` tree can give (no roughness 0).
pub(crate) fn lobe_sums() -> Vec<(&'static str, Composite)> {
    use MaterialKind::*;
    vec![
        // red green blue spec split1 rough1 rough2
        (
            "metal ×2",
            lobe_sum(Metal, 2, false, &[0.9, 0.85, 0.8, 0.9, 0.35, 0.05, 0.25]),
        ),
        // … split1 split2 rough1 rough2 rough3
        (
            "plastic ×3",
            lobe_sum(
                Plastic,
                3,
                false,
                &[0.6, 0.5, 0.4, 0.08, 0.3, 0.5, 0.04, 0.12, 0.3],
            ),
        ),
        // … split1 rough_u1 rough_v1 rough_u2 rough_v2 orient
        (
            "plastic2 ×2 oriented",
            lobe_sum(
                Plastic2,
                2,
                true,
                &[0.5, 0.5, 0.5, 0.1, 0.4, 0.05, 0.2, 0.3, 0.1, 30.0],
            ),
        ),
        (
            "metal2 ×2",
            lobe_sum(
                Metal2,
                2,
                false,
                &[0.8, 0.8, 0.9, 0.8, 0.6, 0.3, 0.1, 0.08, 0.15],
            ),
        ),
        (
            "plastic + metal2 + trans mixture",
            Composite::mixture(vec![
                (0.3, mat(Plastic, &[0.6, 0.5, 0.4, 0.05, 0.1])),
                (0.5, mat(Metal2, &[0.8, 0.8, 0.9, 0.8, 0.3, 0.1])),
                (0.2, mat(Trans, &[0.8, 0.8, 0.7, 0.04, 0.12, 0.6, 0.5])),
            ])
            .expect("valid mixture"),
        ),
    ]
}

/// A mixture with a roughness-0 primitive (mirror deltas).
pub(crate) fn mirror_mixture() -> Composite {
    use MaterialKind::*;
    Composite::mixture(vec![
        (0.6, mat(Metal, &[0.9, 0.8, 0.6, 0.9, 0.2])),
        (0.4, mat(Plastic, &[0.5, 0.5, 0.5, 0.05, 0.0])),
    ])
    .expect("valid mixture")
}

/// Regularised upper incomplete gamma Q(a, x) (Numerical Recipes: series
/// for x < a + 1, continued fraction otherwise).
pub(crate) fn gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let gln = ln_gamma(a);
    if x < a + 1.0 {
        let mut sum = 1.0 / a;
        let mut del = sum;
        let mut ap = a;
        for _ in 0..10_000 {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        1.0 - sum * (-x + a * x.ln() - gln).exp()
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-15 {
                break;
            }
        }
        (-x + a * x.ln() - gln).exp() * h
    }
}

/// ln Γ(x), Lanczos approximation (g = 7, n = 9).
pub(crate) fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + 7.5;
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// p-value of a chi² statistic with `dof` degrees of freedom.
pub(crate) fn chi2_p_value(chi2: f64, dof: usize) -> f64 {
    gamma_q(0.5 * dof as f64, 0.5 * chi2)
}

#[test]
fn chi2_p_values_are_right() {
    // scipy.stats.chi2.sf(x, k)
    assert!((chi2_p_value(3.84146, 1) - 0.05).abs() < 1e-5);
    assert!((chi2_p_value(18.307, 10) - 0.05).abs() < 1e-4);
    assert!((chi2_p_value(124.342, 100) - 0.05).abs() < 1e-4);
}
