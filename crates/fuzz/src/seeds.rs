//! The seed inputs: real and shipped files, read at run time.
//!
//! The real pgII scans in `../shared/data` have no licence and must never
//! enter the repository, so they are read from beside the checkout on
//! every run, never copied. Big files are used two ways: whole (rarely,
//! because one case then costs a full 127 000-row read and summary) and as
//! excerpts (the header plus 150 rows from the start or the middle), which
//! keep a case in the tens of microseconds.

use std::path::{Path, PathBuf};

/// Which parser a case is fed to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Target {
    /// `brtf_gonio::read_bytes_as(…, SourceFormat::Mpc)`.
    Mpc,
    /// `brtf_gonio::read_bytes_as(…, SourceFormat::Mountain)`.
    Mountain,
    /// `brtf_gonio::read_bytes`: format detection, then either reader.
    DetectedGonio,
    /// `brtf_radiance::parse_primitives` and the material reader of `brtf eval`.
    Rad,
    /// `brtf_fit::FitResult::from_json` and what `brtf export` does next.
    FitJson,
    /// `brtf_gonio::klems::read_bytes`, then `brtf info`, the conversion to
    /// measurements and brtf's Klems writer and back.
    Klems,
    /// `brtf_gonio::klems::read_any_bytes` on tensor trees, then `brtf
    /// info` and the per-incidence measurements a fit takes.
    TensorTree,
}

impl Target {
    /// Every target, in report order.
    pub const ALL: [Target; 7] = [
        Target::Mpc,
        Target::Mountain,
        Target::DetectedGonio,
        Target::Rad,
        Target::FitJson,
        Target::Klems,
        Target::TensorTree,
    ];

    /// A short name for reports.
    pub fn label(self) -> &'static str {
        match self {
            Target::Mpc => "mpc",
            Target::Mountain => "mountain",
            Target::DetectedGonio => "gonio (detected)",
            Target::Rad => "rad",
            Target::FitJson => "fit.json",
            Target::Klems => "klems xml",
            Target::TensorTree => "tensor tree",
        }
    }
}

/// One seed input.
#[derive(Clone, Debug)]
pub struct Seed {
    /// The parser it belongs to.
    pub target: Target,
    /// The display name given to the parser (the file name: `.mpc` files
    /// carry their incidence in it).
    pub name: String,
    /// Where it came from, for reports (`golden_paper.txt, rows 63000+`).
    pub origin: String,
    /// The bytes.
    pub bytes: Vec<u8>,
    /// A whole big file: picked rarely, see [`Seeds::pick`].
    pub whole_big_file: bool,
}

/// Where the seeds are read from.
#[derive(Clone, Debug)]
pub struct SeedSources {
    /// The repository root (for `data/`, `fits/`, `tests/cli/data/`, `.rad` files).
    pub repo: PathBuf,
    /// The shared real-data folder (`../shared/data` beside the checkout).
    pub shared_data: PathBuf,
}

impl SeedSources {
    /// The repository this crate was built in, and the shared data beside it.
    pub fn beside_this_checkout() -> SeedSources {
        let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        let repo = repo.canonicalize().unwrap_or(repo);
        let shared_data = repo.join("../shared/data");
        SeedSources { repo, shared_data }
    }
}

/// Files this size or larger count as big: whole-file cases are rare.
const BIG_FILE_BYTES: usize = 64 * 1024;
/// Rows kept in an excerpt of a big measurement file.
const EXCERPT_ROWS: usize = 150;
/// Lines kept from a foreign (non-brtf) file.
const FOREIGN_LINES: usize = 200;

/// All seeds, grouped by target.
#[derive(Clone, Debug, Default)]
pub struct Seeds {
    /// Every seed.
    pub all: Vec<Seed>,
}

impl Seeds {
    /// Reads every seed. Fails with a clear message when a source folder is
    /// missing: CI always has the shared data, so a silent skip would hide
    /// a broken set-up.
    pub fn load(sources: &SeedSources) -> Result<Seeds, String> {
        let mut seeds = Seeds::default();
        let repo = &sources.repo;
        let data = &sources.shared_data;
        if !data.join("rgl-epfl-pgII-raw").is_dir() {
            return Err(format!(
                "the shared real data is missing: {} has no rgl-epfl-pgII-raw/ \
                 (clone the project with `shared/data` beside it, or pass --data)",
                data.display()
            ));
        }
        for path in files_with_extension(&repo.join("data/alu-ggx"), "mpc")?
            .into_iter()
            .chain(files_with_extension(
                &repo.join("crates/gonio/tests/fixtures"),
                "mpc",
            )?)
        {
            seeds.add_measurement(Target::Mpc, &path)?;
        }
        for path in files_with_extension(&data.join("rgl-epfl-pgII-raw"), "txt")? {
            seeds.add_measurement(Target::Mountain, &path)?;
        }
        // Other formats fed to the detecting reader: what a user gets when
        // pointing `brtf info` at the wrong file.
        for (folder, extension) in [
            ("alta-retro-cea", "dat"),
            ("lbnl-frads-klems-fabrics", "xml"),
            ("bbm-ngan-fits", "fit"),
        ] {
            for path in files_with_extension(&data.join(folder), extension)? {
                let bytes = read(&path)?;
                seeds.all.push(Seed {
                    target: Target::DetectedGonio,
                    name: file_name(&path),
                    origin: format!("{folder}/{}, first {FOREIGN_LINES} lines", file_name(&path)),
                    bytes: first_lines(&bytes, FOREIGN_LINES).to_vec(),
                    whole_big_file: false,
                });
            }
        }
        // Klems BSDF XML for the detecting reader (which hands it to the
        // Klems reader, as `brtf info` does): the real Mecho fabric moved to
        // the Quarter basis (each Quarter patch takes the value of the Full
        // patch holding its centre), 41 x 41 per block, so one case costs
        // well under a millisecond; the whole files are too slow for CI.
        let mecho = data.join("lbnl-frads-klems-fabrics/klems_aniso_high.xml");
        let quarter = klems_quarter(&mecho)?;
        for target in [Target::DetectedGonio, Target::Klems] {
            seeds.all.push(Seed {
                target,
                name: "klems_quarter.xml".into(),
                origin: "klems_aniso_high.xml on the Klems Quarter basis".into(),
                bytes: quarter.clone().into_bytes(),
                whole_big_file: false,
            });
        }
        // The same data as brtf writes it (comma rows, comments, schema).
        seeds.all.push(Seed {
            target: Target::Klems,
            name: "klems_quarter_brtf.xml".into(),
            origin: "klems_aniso_high.xml on the Quarter basis, written by brtf".into(),
            bytes: rewritten(&quarter, "klems_quarter.xml")?.into_bytes(),
            whole_big_file: false,
        });
        // The whole real files, picked rarely.
        for path in files_with_extension(&data.join("lbnl-frads-klems-fabrics"), "xml")? {
            seeds.all.push(Seed {
                target: Target::Klems,
                name: file_name(&path),
                origin: format!("{}, whole", file_name(&path)),
                bytes: read(&path)?,
                whole_big_file: true,
            });
        }
        // Tensor trees written by Radiance's bsdf2ttree (the gonio tests'
        // fixtures, about 20 kB each).
        for path in files_with_extension(&repo.join("crates/gonio/tests/fixtures/ttree"), "xml")? {
            seeds.all.push(Seed {
                target: Target::TensorTree,
                name: file_name(&path),
                origin: format!("crates/gonio/tests/fixtures/ttree/{}", file_name(&path)),
                bytes: read(&path)?,
                whole_big_file: false,
            });
        }
        for path in rad_files(repo) {
            let Ok(bytes) = std::fs::read(&path) else {
                continue; // vanished since the walk
            };
            let relative = path.strip_prefix(repo).unwrap_or(&path);
            seeds.all.push(Seed {
                target: Target::Rad,
                name: file_name(&path),
                origin: relative.display().to_string(),
                bytes,
                whole_big_file: false,
            });
        }
        let fit_json = repo.join("fits/alu-ggx/fit.json");
        seeds.all.push(Seed {
            target: Target::FitJson,
            name: "fit.json".into(),
            origin: "fits/alu-ggx/fit.json".into(),
            bytes: read(&fit_json)?,
            whole_big_file: false,
        });
        for target in [
            Target::Mpc,
            Target::Mountain,
            Target::Rad,
            Target::FitJson,
            Target::Klems,
            Target::TensorTree,
        ] {
            if !seeds.all.iter().any(|s| s.target == target) {
                return Err(format!("no seed file for {}", target.label()));
            }
        }
        Ok(seeds)
    }

    /// A measurement: excerpts, plus the whole file (rare when big).
    fn add_measurement(&mut self, target: Target, path: &Path) -> Result<(), String> {
        let bytes = read(path)?;
        let name = file_name(path);
        let big = bytes.len() >= BIG_FILE_BYTES;
        if big {
            for (label, excerpt) in excerpts(&bytes) {
                self.all.push(Seed {
                    target,
                    name: name.clone(),
                    origin: format!("{name}, {label}"),
                    bytes: excerpt,
                    whole_big_file: false,
                });
            }
        }
        self.all.push(Seed {
            target,
            name: name.clone(),
            origin: format!("{name}, whole"),
            bytes,
            whole_big_file: big,
        });
        Ok(())
    }

    /// The seeds of `target` (small ones only unless `whole` is set).
    pub fn of(&self, target: Target, whole: bool) -> Vec<&Seed> {
        self.all
            .iter()
            .filter(|s| s.target == target && s.whole_big_file == whole)
            .collect()
    }
}

/// The header plus [`EXCERPT_ROWS`] rows from the start and from the
/// middle, with `#datapoints_in_file` set to the rows kept (else every
/// excerpt would fail on the count before reaching the rows).
fn excerpts(bytes: &[u8]) -> Vec<(String, Vec<u8>)> {
    let lines: Vec<&[u8]> = bytes.split_inclusive(|&b| b == b'\n').collect();
    let is_header = |l: &&&[u8]| {
        let t = l.trim_ascii_start();
        t.starts_with(b"#")
            || t.split(u8::is_ascii_whitespace)
                .filter(|w| !w.is_empty())
                .count()
                < 2
    };
    let header_len = lines.iter().take_while(is_header).count();
    let rows = lines.len() - header_len;
    let mut out = Vec::new();
    for (label, start) in [("first rows", 0), ("middle rows", rows / 2)] {
        let kept = &lines[header_len + start..(header_len + start + EXCERPT_ROWS).min(lines.len())];
        let mut excerpt = Vec::new();
        for line in &lines[..header_len] {
            if line.starts_with(b"#datapoints_in_file") {
                let end = if line.ends_with(b"\r\n") {
                    "\r\n"
                } else {
                    "\n"
                };
                excerpt.extend_from_slice(
                    format!("#datapoints_in_file\t{}{end}", kept.len()).as_bytes(),
                );
            } else {
                excerpt.extend_from_slice(line);
            }
        }
        for line in kept {
            excerpt.extend_from_slice(line);
        }
        out.push((format!("header + {} {label}", kept.len()), excerpt));
    }
    out
}

fn first_lines(bytes: &[u8], n: usize) -> &[u8] {
    let end = bytes
        .iter()
        .enumerate()
        .filter(|(_, b)| **b == b'\n')
        .nth(n - 1)
        .map_or(bytes.len(), |(i, _)| i + 1);
    &bytes[..end]
}

fn read(path: &Path) -> Result<Vec<u8>, String> {
    std::fs::read(path).map_err(|e| format!("cannot read seed {}: {e}", path.display()))
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
}

/// The files in `dir` ending in `.extension`, sorted.
fn files_with_extension(dir: &Path, extension: &str) -> Result<Vec<PathBuf>, String> {
    let entries =
        std::fs::read_dir(dir).map_err(|e| format!("cannot list {}: {e}", dir.display()))?;
    let mut files: Vec<PathBuf> = entries
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.is_file() && p.extension().is_some_and(|e| e == extension))
        .collect();
    files.sort();
    Ok(files)
}

/// Folders searched for `.rad` seeds: the shipped data, fits, docs and
/// tests. Build output and other engineers' scratch folders stay out.
const RAD_FOLDERS: [&str; 5] = ["data", "fits", "docs", "tests", "crates"];

/// Every `.rad` file under [`RAD_FOLDERS`] of `repo`, sorted.
fn rad_files(repo: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for folder in RAD_FOLDERS {
        collect_rad_files(&repo.join(folder), &mut out);
    }
    out.sort();
    out
}

/// Walks `dir`. Entries that vanish meanwhile (temporary folders of
/// tests running beside) are skipped, not errors.
fn collect_rad_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.filter_map(Result::ok) {
        let path = entry.path();
        let name = entry.file_name();
        if name.to_string_lossy().starts_with('.') || name == "target" {
            continue;
        }
        if path.is_dir() {
            collect_rad_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rad") {
            out.push(path);
        }
    }
}

/// A Klems file's text as brtf's writer writes it (its header, basis and
/// every matrix).
fn rewritten(text: &str, name: &str) -> Result<String, String> {
    let bsdf = brtf_gonio::klems::read_str(text, name).map_err(|e| e.to_string())?;
    rewrite(&bsdf, name)
}

/// `bsdf` as brtf's Klems writer writes it.
pub(crate) fn rewrite(bsdf: &brtf_gonio::klems::KlemsBsdf, name: &str) -> Result<String, String> {
    use brtf_gonio::klems::{KlemsWriteHeader, to_klems_xml};
    let header = KlemsWriteHeader {
        name: bsdf.header.name.clone().unwrap_or_default(),
        manufacturer: "brtf-fuzz".into(),
        thickness_mm: 1.0,
        device_type: "Other".into(),
        window: Default::default(),
        comment: vec![format!("rewritten from {name} -- by brtf-fuzz")],
    };
    to_klems_xml(&header, &bsdf.basis, &bsdf.write_blocks())
}

/// The Klems file at `path` resampled to the Quarter basis, as XML text.
fn klems_quarter(path: &Path) -> Result<String, String> {
    use brtf_gonio::klems::{self, KlemsBasis};
    let full = klems::read_path(path).map_err(|e| format!("seed {}: {e}", path.display()))?;
    let quarter = KlemsBasis::built_in("LBNL/Klems Quarter").expect("built in");
    let nearest: Vec<usize> = quarter
        .patches()
        .iter()
        .map(|p| full.basis.patch_index(p.theta_deg, p.phi_deg).unwrap_or(0))
        .collect();
    let mut text = String::from(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n\
         <WindowElement xmlns=\"http://windows.lbl.gov\">\n<FileType>BSDF</FileType>\n\
         <Optical>\n<Layer>\n<Material>\n<Name>fuzz seed</Name>\n\
         <Thickness unit=\"Millimeter\">1</Thickness>\n</Material>\n<DataDefinition>\n\
         <IncidentDataStructure>Columns</IncidentDataStructure>\n<AngleBasis>\n\
         <AngleBasisName>LBNL/Klems Quarter</AngleBasisName>\n</AngleBasis>\n\
         </DataDefinition>\n",
    );
    for m in &full.matrices {
        text += &format!(
            "<WavelengthData>\n<Wavelength unit=\"Integral\">{}</Wavelength>\n\
             <WavelengthDataBlock>\n<WavelengthDataDirection>{}</WavelengthDataDirection>\n\
             <ColumnAngleBasis>LBNL/Klems Quarter</ColumnAngleBasis>\n\
             <RowAngleBasis>LBNL/Klems Quarter</RowAngleBasis>\n\
             <ScatteringDataType>BTDF</ScatteringDataType>\n<ScatteringData>\n",
            m.band, m.direction
        );
        for &o in &nearest {
            let row: Vec<String> = nearest
                .iter()
                .map(|&i| format!("{:.5}", m.value(o, i)))
                .collect();
            text += &row.join(", ");
            text += "\n";
        }
        text += "</ScatteringData>\n</WavelengthDataBlock>\n</WavelengthData>\n";
    }
    text += "</Layer>\n</Optical>\n</WindowElement>\n";
    Ok(text)
}
