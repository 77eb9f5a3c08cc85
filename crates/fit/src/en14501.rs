//! Radiance `trans` parameters from the normal-incidence values that
//! glazing and shading datasheets list (EN 14501 / EN 410): the
//! normal-hemispherical transmittance τ_nh, the normal-normal (direct)
//! transmittance τ_nn and the normal-hemispherical reflectance ρ_nh, with
//! an optional specular reflectance.
//!
//! `trans` with colour C, specularity S, roughness α, transmissivity T and
//! transmitted specularity Ts splits light at normal incidence into
//! (Radiance's `trans` definition; `docs/fitting.md` gives the derivation):
//!
//! - specular reflection S,
//! - diffuse reflection C (1 − S)(1 − T),
//! - transmission C T (1 − S), of which the fraction Ts leaves straight
//!   through (a delta with α = 0) and the rest diffusely.
//!
//! So τ_nh = C T (1 − S), τ_nn = τ_nh Ts and ρ_nh = S + C (1 − S)(1 − T),
//! which give C = (ρ_nh − S + τ_nh)/(1 − S), T = τ_nh/(ρ_nh − S + τ_nh) and
//! Ts = τ_nn/τ_nh, with α = 0: the direct part is a true straight-through
//! delta, as the openness of a fabric is. With S ≥ 0.018, Radiance's
//! roughness-0 Fresnel factor also scales the diffuse parts; the factors
//! are read off brtf-model and divided out, so the material's own ρ_dh and
//! τ_dh at normal incidence are the datasheet's.

use std::collections::BTreeMap;

/// The datasheet values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct En14501 {
    /// Normal-hemispherical transmittance τ_nh (total).
    pub tau_nh: f64,
    /// Normal-normal transmittance τ_nn (direct, the openness of a fabric).
    pub tau_nn: f64,
    /// Normal-hemispherical reflectance ρ_nh (total).
    pub rho_nh: f64,
    /// The specular part of ρ_nh (0 for matte fabrics).
    pub spec: f64,
}

impl std::str::FromStr for En14501 {
    type Err = String;

    /// `tau_nh=0.12,tau_nn=0.05,rho_nh=0.6[,spec=0.01]`.
    fn from_str(text: &str) -> Result<Self, String> {
        let mut values = BTreeMap::new();
        for part in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            let (key, value) = part
                .split_once('=')
                .ok_or_else(|| format!("`{part}`: expected key=value"))?;
            let key = key.trim();
            if !["tau_nh", "tau_nn", "rho_nh", "spec"].contains(&key) {
                return Err(format!(
                    "`{key}`: unknown value (expected tau_nh, tau_nn, rho_nh, spec)"
                ));
            }
            let number: f64 = value
                .trim()
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite())
                .ok_or_else(|| format!("{key}: `{}` is not a number", value.trim()))?;
            if !(0.0..=1.0).contains(&number) {
                return Err(format!("{key} = {number} is outside 0-1"));
            }
            values.insert(key.to_string(), number);
        }
        let get = |k: &str| {
            values
                .get(k)
                .copied()
                .ok_or_else(|| format!("{k} is missing (give tau_nh, tau_nn and rho_nh)"))
        };
        Ok(En14501 {
            tau_nh: get("tau_nh")?,
            tau_nn: get("tau_nn")?,
            rho_nh: get("rho_nh")?,
            spec: values.get("spec").copied().unwrap_or(0.0),
        })
    }
}

impl En14501 {
    /// The grey `trans` arguments (C, C, C, S, α = 0, T, Ts), or why the
    /// values cannot be a `trans` material.
    pub fn trans_args(&self) -> Result<[f64; 7], String> {
        let En14501 {
            tau_nh,
            tau_nn,
            rho_nh,
            spec,
        } = *self;
        if tau_nn > tau_nh {
            return Err(format!(
                "tau_nn = {tau_nn} exceeds tau_nh = {tau_nh}: the direct part is part of the total"
            ));
        }
        if spec > rho_nh {
            return Err(format!(
                "spec = {spec} exceeds rho_nh = {rho_nh}: the specular part is part of the total"
            ));
        }
        if rho_nh + tau_nh > 1.0 {
            return Err(format!(
                "rho_nh + tau_nh = {} exceeds 1: the sample would create light",
                rho_nh + tau_nh
            ));
        }
        if spec >= 1.0 {
            return Err("spec = 1: nothing is left to scatter".into());
        }
        // Radiance's roughness-0 Fresnel factor (on only for spec ≥ 0.018)
        // lowers the diffuse parts by its cosine-weighted mean, and can
        // scale the straight-through part: read all three factors off the
        // model itself with probe materials of the same specularity.
        let [g_reflect, g_transmit, g_through] = fresnel_factors(spec)?;
        let direct = tau_nn / ((1.0 - spec) * g_through);
        let diffuse_through = (tau_nh - tau_nn) / ((1.0 - spec) * g_transmit);
        let diffuse_back = (rho_nh - spec) / ((1.0 - spec) * g_reflect);
        let transmitted = direct + diffuse_through;
        let colour = transmitted + diffuse_back;
        if colour <= 0.0 {
            return Err("nothing is scattered: there is no trans material for these values".into());
        }
        if colour > 1.0 + 1e-9 {
            return Err(format!(
                "the values need a colour of {colour:.4} > 1 (Radiance's roughness-0 Fresnel \
                 factor absorbs part of the diffuse light when spec ≥ 0.018)"
            ));
        }
        let trans = transmitted / colour;
        let tspec = if transmitted > 0.0 {
            direct / transmitted
        } else {
            0.0
        };
        Ok([colour, colour, colour, spec, 0.0, trans, tspec])
    }
}

/// The model's factors on diffuse reflection, diffuse transmission and
/// straight-through transmission of a roughness-0 `trans` with
/// specularity `spec` at normal incidence, relative to the plain
/// (1 − S)(1 − T), (1 − S) T (1 − Ts) and (1 − S) T Ts.
fn fresnel_factors(spec: f64) -> Result<[f64; 3], String> {
    let albedo = |tspec: f64| -> Result<brtf_model::Albedo, String> {
        let m = brtf_model::Material::new(
            brtf_model::MaterialKind::Trans,
            &[1.0, 1.0, 1.0, spec, 0.0, 0.5, tspec],
            None,
        )
        .map_err(|e| e.to_string())?;
        let bsdf = brtf_model::Bsdf::new(&m, &brtf_model::EvalOptions::default());
        Ok(brtf_model::albedo(&bsdf, glam::DVec3::Z, 1e-8))
    };
    let plain = 0.5 * (1.0 - spec);
    let diffuse = albedo(0.0)?;
    let through = albedo(1.0)?;
    let factors = [
        diffuse.rho[1] / plain,
        diffuse.tau[1] / plain,
        through.tau_spike[1] / plain,
    ];
    if factors.iter().all(|f| f.is_finite() && *f > 0.0) {
        Ok(factors)
    } else {
        Err(format!(
            "spec = {spec}: the model scatters nothing to match"
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_parse_and_refuse_what_is_not_physical() {
        let v: En14501 = "tau_nh=0.12, tau_nn=0.05, rho_nh=0.6".parse().unwrap();
        assert_eq!(v.spec, 0.0);
        assert!(v.trans_args().is_ok());
        for bad in [
            "tau_nh=0.1,rho_nh=0.5",
            "tau_nh=x,tau_nn=0,rho_nh=0",
            "tau_nh=1.5,tau_nn=0,rho_nh=0",
            "foo=1",
        ] {
            assert!(bad.parse::<En14501>().is_err(), "{bad}");
        }
        let over: En14501 = "tau_nh=0.5,tau_nn=0.1,rho_nh=0.6".parse().unwrap();
        assert!(over.trans_args().unwrap_err().contains("exceeds 1"));
        let direct: En14501 = "tau_nh=0.1,tau_nn=0.2,rho_nh=0.6".parse().unwrap();
        assert!(direct.trans_args().is_err());
    }

    /// brtf-model's own ρ_dh, τ_dh and straight-through spike of the
    /// derived material at normal incidence give back the datasheet values.
    #[test]
    fn the_material_has_the_datasheet_values() {
        for text in [
            "tau_nh=0.12,tau_nn=0.05,rho_nh=0.6",
            "tau_nh=0.3,tau_nn=0.0,rho_nh=0.45,spec=0.03",
            "tau_nh=0.05,tau_nn=0.049,rho_nh=0.7",
        ] {
            let v: En14501 = text.parse().unwrap();
            let args = v.trans_args().unwrap();
            let m =
                brtf_model::Material::new(brtf_model::MaterialKind::Trans, &args, None).unwrap();
            let bsdf = brtf_model::Bsdf::new(&m, &brtf_model::EvalOptions::default());
            let a = brtf_model::albedo(&bsdf, glam::DVec3::Z, 1e-7);
            let rho = a.rho[1] + a.rho_spike[1];
            let tau = a.tau[1] + a.tau_spike[1];
            assert!(
                (rho - v.rho_nh).abs() < 1e-4,
                "{text}: ρ_nh {rho} = {:?} + {:?}",
                a.rho,
                a.rho_spike
            );
            assert!((tau - v.tau_nh).abs() < 1e-4, "{text}: τ_nh {tau}");
            assert!(
                (a.tau_spike[1] - v.tau_nn).abs() < 1e-4,
                "{text}: τ_nn {}",
                a.tau_spike[1]
            );
        }
    }
}
