//! Materials from Radiance files.

use crate::WorkflowError;
use brtf_model::Composite;
use std::path::Path;

/// Reads the Radiance file `path` and picks the material `name` (or its
/// one top material): its identifier and the material, one Ward-type
/// primitive or a constant `mixfunc` tree of them (a lobe sum).
pub fn read_material_file(
    path: &Path,
    name: Option<&str>,
) -> Result<(String, Composite), WorkflowError> {
    let shown = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| {
        WorkflowError::Io(brtf_io::IoError {
            path: path.to_path_buf(),
            what: "cannot read material file",
            source,
        })
    })?;
    let primitives = brtf_radiance::parse_primitives(&text, &shown)?;
    Ok(brtf_radiance::select_composite(&primitives, name, &shown)?)
}
