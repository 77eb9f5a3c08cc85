//! Materials from files: one primitive of a Radiance file, or a fit
//! folder's material as brtf's tracer renders it.

use crate::WorkflowError;
use brtf_fit::FitResult;
use brtf_model::{EvalOptions, Material, Variant};
use brtf_trace::Shader;
use std::path::{Path, PathBuf};

/// Reads the Radiance file `path` and picks the material `name` (or its
/// only Ward-type material): its identifier and the material.
pub fn read_material_file(
    path: &Path,
    name: Option<&str>,
) -> Result<(String, Material), WorkflowError> {
    let shown = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| {
        WorkflowError::Io(brtf_io::IoError {
            path: path.to_path_buf(),
            what: "cannot read material file",
            source,
        })
    })?;
    let primitives = brtf_radiance::parse_primitives(&text, &shown)?;
    Ok(brtf_radiance::select_material(&primitives, name, &shown)?)
}

/// Where a material to render comes from.
#[derive(Debug, Clone)]
pub enum MaterialSource {
    /// A material of a Radiance file (`name` picks one of several).
    File {
        /// The `.rad` file.
        path: PathBuf,
        /// Which material.
        name: Option<String>,
    },
    /// A fit folder: its θ_in table, or (`fixed`) its all-incidence material.
    Fit {
        /// The folder.
        dir: PathBuf,
        /// The one all-incidence material instead of the θ_in table.
        fixed: bool,
    },
}

/// A material ready to render.
pub struct RenderMaterial {
    /// What the tracer evaluates.
    pub shader: Shader,
    /// The one static material (the fit's all-incidence set, or the file's).
    pub material: Material,
    /// Its name.
    pub name: String,
    /// The fit, when the material came from one.
    pub fit: Option<FitResult>,
}

/// Loads `source` for the tracer. `variant` and `fresnel_k` override the
/// fit's (default: radiance and the classic constant for a file).
pub fn load_render_material(
    source: &MaterialSource,
    variant: Option<Variant>,
    fresnel_k: Option<f64>,
) -> Result<RenderMaterial, WorkflowError> {
    let (name, material, fit, mut options) = match source {
        MaterialSource::File { path, name } => {
            let (name, material) = read_material_file(path, name.as_deref())?;
            (name, material, None, EvalOptions::default())
        }
        MaterialSource::Fit { dir, .. } => {
            let fit = crate::read_fit(dir)?;
            let material = fit.static_material().ok_or_else(|| {
                WorkflowError::Usage(format!(
                    "{}: the fit holds no valid material",
                    dir.display()
                ))
            })?;
            let options = fit.options();
            (fit.name.clone(), material, Some(fit), options)
        }
    };
    options.variant = variant.unwrap_or(options.variant);
    options.fresnel_k = fresnel_k.unwrap_or(options.fresnel_k);
    options.validate()?;
    let table = match (source, &fit) {
        (MaterialSource::Fit { fixed: false, .. }, Some(fit)) => fit.table.as_ref(),
        _ => None,
    };
    let shader = match table {
        Some(table) => Shader::from_table(table, &options)?,
        None => Shader::new(&material, &options),
    };
    Ok(RenderMaterial {
        shader,
        material,
        name,
        fit,
    })
}
