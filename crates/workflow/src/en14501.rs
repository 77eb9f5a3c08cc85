//! The EN 14501 shortcut: a `trans` from datasheet values at normal
//! incidence, as Radiance text.

use crate::WorkflowError;
use brtf_fit::en14501::En14501;
use brtf_model::{Bsdf, EvalOptions, Material, MaterialKind};

/// The `trans` of `values` as a Radiance material named `name` (default
/// `en14501`), with the model's own normal-incidence values as a check
/// in its header.
pub fn en14501_material(
    values: &En14501,
    name: Option<&str>,
    command_line: &[String],
) -> Result<String, WorkflowError> {
    let args = values
        .trans_args()
        .map_err(|e| WorkflowError::Usage(format!("--en14501: {e}")))?;
    let name = match name {
        Some(n) => brtf_radiance::identifier(n).ok_or_else(|| {
            WorkflowError::Usage(format!("--name {n}: not usable as a Radiance identifier"))
        })?,
        None => "en14501".to_string(),
    };
    let material = Material::new(MaterialKind::Trans, &args, None)
        .map_err(|e| WorkflowError::Usage(format!("--en14501: {e}")))?;
    let bsdf = Bsdf::new(&material, &EvalOptions::default());
    let a = brtf_model::albedo(&bsdf, glam::DVec3::Z, 1e-8);
    let numbers: Vec<String> = args.iter().map(|v| format!("{v:.6}")).collect();
    Ok(format!(
        "# brtf {}: {}\n\
         # trans from EN 14501 normal-incidence values tau_nh={} tau_nn={} rho_nh={} spec={}\n\
         # brtf-model at normal incidence: rho_nh={:.4} tau_nh={:.4} tau_nn={:.4}\n\
         void trans {name}\n0\n0\n7 {}\n",
        env!("CARGO_PKG_VERSION"),
        command_line.join(" "),
        values.tau_nh,
        values.tau_nn,
        values.rho_nh,
        values.spec,
        a.rho[1] + a.rho_spike[1],
        a.tau[1] + a.tau_spike[1],
        a.tau_spike[1],
        numbers.join(" ")
    ))
}
