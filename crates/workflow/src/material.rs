//! Materials from Radiance files.

use crate::WorkflowError;
use brtf_model::Composite;
use brtf_radiance::export::klems::SolarBand;
use std::path::Path;

/// Reads the Radiance file `path` and picks the material `name` (or its
/// one top material): its identifier and the material, one Ward-type
/// primitive or a constant `mixfunc` tree of them (a lobe sum).
pub fn read_material_file(
    path: &Path,
    name: Option<&str>,
) -> Result<(String, Composite), WorkflowError> {
    let shown = path.display().to_string();
    let fail = |source| {
        WorkflowError::Io(brtf_io::IoError {
            path: path.to_path_buf(),
            what: "cannot read material file",
            source,
        })
    };
    let bytes = brtf_io::read_input(path).map_err(fail)?;
    let text = String::from_utf8(bytes)
        .map_err(|_| fail(std::io::Error::other("stream did not contain valid UTF-8")))?;
    let primitives = brtf_radiance::parse_primitives(&text, &shown)?;
    Ok(brtf_radiance::select_composite(&primitives, name, &shown)?)
}

/// The Solar band of `--solar`: `visible` (the default: the Visible values
/// again, said in the file as an assumption; WINDOW and pyWinCalc need a
/// Solar band), `none`, or the material of a Radiance file.
pub fn solar_band(arg: Option<&str>) -> Result<SolarBand, WorkflowError> {
    Ok(match arg {
        None | Some("visible") => SolarBand::ReuseVisible,
        Some("none") => SolarBand::None,
        Some(file) => SolarBand::Material {
            material: read_material_file(Path::new(file), None)
                .map_err(|e| WorkflowError::Usage(format!("--solar {file}: {e}")))?
                .1,
            source: file.to_string(),
        },
    })
}
