//! Materials from Radiance files.

use crate::WorkflowError;
use brtf_model::Material;
use std::path::Path;

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
