//! What a fit is given: measurement files, Klems BSDF XML files, or sample
//! folders; and the material name they imply.

use crate::WorkflowError;
use std::path::{Path, PathBuf};

/// The inputs of one `brtf fit`, by kind.
#[derive(Debug, Clone, PartialEq)]
pub enum FitInputs {
    /// Gonio-photometer files (`.mpc`, Mountain), one incidence each: one sample.
    Measurements(Vec<PathBuf>),
    /// Klems BSDF XML files: each incident patch of a side is an incidence.
    Klems(Vec<PathBuf>),
    /// Sample folders, one sample each (their `.mpc` and `.txt` files).
    Samples(Vec<PathBuf>),
}

impl FitInputs {
    /// Sorts `paths` into one kind; mixing kinds is refused.
    pub fn classify(paths: &[PathBuf]) -> Result<FitInputs, WorkflowError> {
        if paths.is_empty() {
            return Err(WorkflowError::Usage("no measurement files given".into()));
        }
        if paths.iter().any(|p| p.is_dir()) {
            if let Some(file) = paths.iter().find(|p| !p.is_dir()) {
                return Err(WorkflowError::Usage(format!(
                    "{} is a file, but other inputs are folders: give either measurement files \
                     (one sample) or sample folders (one sample each), not both",
                    file.display()
                )));
            }
            return Ok(FitInputs::Samples(paths.to_vec()));
        }
        let klems = paths.iter().filter(|p| is_klems(p)).count();
        match klems {
            0 => Ok(FitInputs::Measurements(paths.to_vec())),
            n if n == paths.len() => Ok(FitInputs::Klems(paths.to_vec())),
            _ => Err(WorkflowError::Usage(
                "Klems BSDF XML files are fitted on their own, not with gonio-photometer files"
                    .into(),
            )),
        }
    }

    /// The files (or folders) given.
    pub fn paths(&self) -> &[PathBuf] {
        match self {
            FitInputs::Measurements(p) | FitInputs::Klems(p) | FitInputs::Samples(p) => p,
        }
    }

    /// True for Klems BSDF XML inputs.
    pub fn is_klems(&self) -> bool {
        matches!(self, FitInputs::Klems(_))
    }
}

/// True when `path` is a Klems BSDF XML file (by its extension or its
/// first bytes), as [`brtf_gonio::detect_format`] decides.
pub fn is_klems(path: &Path) -> bool {
    use std::io::Read;
    let mut head = Vec::new();
    if let Ok(file) = std::fs::File::open(path) {
        let _ = file.take(512).read_to_end(&mut head);
    }
    brtf_gonio::detect_format(&head, path) == brtf_gonio::SourceFormat::KlemsXml
}

/// The material name of one sample's files: their `#sample_name` (or the
/// Klems header's name) when they agree, else the longest common start of
/// their file names ([`brtf_radiance::default_fit_name`]).
pub fn default_name(files: &[PathBuf], klems: bool) -> Result<String, WorkflowError> {
    let mut sample_names = Vec::new();
    for file in files {
        let name = if klems {
            // genBSDF writes `<Name>Name</Name>` when given none.
            let name = brtf_gonio::klems::read_any_path(file)?
                .header()
                .name
                .clone();
            name.filter(|n| {
                let n = n.trim().to_ascii_lowercase();
                !["", "name", "unnamed", "untitled"].contains(&n.as_str())
            })
        } else {
            // The header alone: the fit reads and checks the whole file.
            brtf_gonio::read_sample_name_at(file).map_err(|source| {
                WorkflowError::Io(brtf_io::IoError {
                    path: file.clone(),
                    what: "cannot read",
                    source,
                })
            })?
        };
        sample_names.push(name);
    }
    let stems: Vec<String> = files
        .iter()
        .map(|f| {
            f.file_stem()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    Ok(brtf_radiance::default_fit_name(&sample_names, &stems))
}

/// The sides of a Klems fit's files that hold data (front first).
pub(crate) fn klems_sides(
    files: &[PathBuf],
) -> Result<Vec<brtf_gonio::klems::Side>, WorkflowError> {
    let mut sides = Vec::new();
    for file in files {
        for side in brtf_gonio::klems::read_any_path(file)?.sides_present() {
            if !sides.contains(&side) {
                sides.push(side);
            }
        }
    }
    sides.sort_by_key(|s| *s != brtf_gonio::klems::Side::Front);
    Ok(sides)
}

/// The measurement files of a sample folder: `.mpc` and `.txt`, sorted.
pub fn sample_files(folder: &Path) -> Result<Vec<PathBuf>, WorkflowError> {
    let listing = |source| {
        WorkflowError::Io(brtf_io::IoError {
            path: folder.to_path_buf(),
            what: "cannot list",
            source,
        })
    };
    let mut files = Vec::new();
    for entry in std::fs::read_dir(folder).map_err(listing)? {
        let path = entry.map_err(listing)?.path();
        let measured = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("mpc") || e.eq_ignore_ascii_case("txt"));
        if measured && path.is_file() {
            files.push(path);
        }
    }
    if files.is_empty() {
        return Err(WorkflowError::Usage(format!(
            "{} holds no measurement files (.mpc or .txt)",
            folder.display()
        )));
    }
    files.sort();
    Ok(files)
}
