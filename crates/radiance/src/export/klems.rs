//! Klems BSDF XML from a fit folder or a static material (`brtf export
//! --klems`): the file annual daylight tools (`rfluxmtx`/`dctimestep`,
//! frads, honeybee-radiance) and WINDOW-family tools (pyWinCalc,
//! EnergyPlus) read.
//!
//! Each incident patch gets the material of its own θ_in (the fit's θ_in
//! table at the patch's ring centre), and each matrix entry is the BSDF
//! averaged over the outgoing and the incident patch
//! ([`brtf_gonio::klems::model_matrix`]). A fit folder gives the front
//! components (`Reflection Back` = Radiance's rf, plus `Transmission Back`
//! = tf for the transmitting types); a folder holding `front/fit.json` and
//! `back/fit.json` (a two-sided fit, each side described as a front) gives
//! all four, the back fit's matrices written as rb and tb. A static
//! material is two-sided in Radiance, so it gives all four too, with the
//! back equal to the front.
//!
//! A lobe sum's matrices are its lobes' matrices (each computed on the same
//! sample points) added with the lobes' weights at each incident patch's
//! θ_in: exactly the patch averages of `Σ w_k f_k`.

use std::path::{Path, PathBuf};

use brtf_fit::{FitResult, azimuth_from_u};
use brtf_gonio::klems::{
    KlemsBand, KlemsBasis, KlemsDirection, KlemsWriteBlock, KlemsWriteHeader, Side, to_klems_xml,
};
use brtf_gonio::klems::{SampleOptions, SideMatrices, band_values, side_matrices};
use brtf_model::{Bsdf, Composite, EvalOptions, Material, Rgb};

/// Where the Solar band comes from.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum SolarBand {
    /// No Solar band (Radiance ignores it; WINDOW and pyWinCalc need one).
    None,
    /// The Visible values again, stated as an assumption in the header.
    #[default]
    ReuseVisible,
    /// The luminance-weighted BSDF of this static material (the user's
    /// solar properties), from the file named.
    Material {
        /// The material (one primitive or a lobe sum).
        material: Composite,
        /// Its file, for the header.
        source: String,
    },
}

/// What to write.
#[derive(Debug, Clone, PartialEq)]
pub struct KlemsOptions {
    /// The basis (`LBNL/Klems Full`, `… Half`, `… Quarter`).
    pub basis: KlemsBasis,
    /// Samples and seed of the patch averages.
    pub sampling: SampleOptions,
    /// The Solar band.
    pub solar: SolarBand,
    /// Also write `CIE-X` and `CIE-Z` (colour).
    pub colour: bool,
    /// `Name` in the file (default: the fit's or material's name).
    pub name: String,
    /// `Manufacturer`.
    pub manufacturer: String,
    /// `Thickness` in millimetres.
    pub thickness_mm: f64,
    /// `DeviceType`.
    pub device_type: String,
    /// WINDOW's thermal fields (conductivity, emissivities, …).
    pub window: brtf_gonio::klems::WindowFields,
    /// The command line that asked for the file (provenance).
    pub command_line: Vec<String>,
}

impl KlemsOptions {
    /// Defaults for the Full basis: default sampling, Visible only.
    pub fn new(name: &str) -> Self {
        KlemsOptions {
            basis: KlemsBasis::full(),
            sampling: SampleOptions::default(),
            solar: SolarBand::ReuseVisible,
            colour: false,
            name: name.to_string(),
            manufacturer: "brtf".into(),
            thickness_mm: 1.0,
            device_type: "Other".into(),
            window: Default::default(),
            command_line: Vec::new(),
        }
    }
}

/// Why the file could not be made.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum KlemsExportError {
    /// `fit.json` (or a side's) could not be read.
    #[error(transparent)]
    Read(#[from] brtf_fit::ReadFitError),
    /// The fit holds no usable parameters at some θ_in.
    #[error("{fit}: no valid material at theta_in = {theta} degrees: {why}")]
    NoMaterial {
        /// The fit file.
        fit: String,
        /// The θ_in asked for.
        theta: f64,
        /// Why.
        why: String,
    },
    /// A value is out of range.
    #[error("{0}")]
    Invalid(String),
    /// The two sides of a two-sided fit are of different types.
    #[error("front fit is {front}, back fit is {back}: both sides must have the same type")]
    MixedSides {
        /// Front type.
        front: String,
        /// Back type.
        back: String,
    },
    /// The file could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
}

/// The computed file, in memory.
#[derive(Debug, Clone)]
pub struct KlemsExport {
    /// The XML text.
    pub text: String,
    /// The matrices written, for checks: (band, direction, values).
    pub blocks: Vec<KlemsWriteBlock>,
    /// Things the user should know.
    pub notes: Vec<String>,
}

/// One lit side: a material per incident patch, as lobes: `lobes[k]` is
/// lobe k's weight and BSDF at every incident patch.
struct SideModel {
    lobes: Vec<Lobe>,
    transmitting: bool,
    /// The same model as the front's (a two-sided material): reuse the
    /// front's matrices instead of computing them again.
    same_as_front: bool,
}

/// One lobe of a side's materials over the incident patches.
struct Lobe {
    weights: Vec<f64>,
    bsdfs: Vec<Bsdf>,
}

impl SideModel {
    /// The model of the same material at every incident patch.
    fn uniform(material: &Composite, eval: &EvalOptions, patches: usize) -> SideModel {
        let lobes = material
            .components()
            .iter()
            .map(|(w, m)| Lobe {
                weights: vec![*w; patches],
                bsdfs: vec![Bsdf::new(m, eval); patches],
            })
            .collect();
        SideModel {
            lobes,
            transmitting: material
                .components()
                .iter()
                .any(|(_, m)| m.kind().is_transmitting()),
            same_as_front: false,
        }
    }

    /// The evaluation options of its BSDFs.
    fn options(&self) -> Option<EvalOptions> {
        self.lobes
            .first()
            .and_then(|l| l.bsdfs.first())
            .map(|b| *b.options())
    }

    /// The Klems matrices: each lobe's, added with its weight per incident
    /// patch (column).
    fn matrices(&self, basis: &KlemsBasis, sampling: SampleOptions) -> SideMatrices {
        let mut total: Option<SideMatrices> = None;
        for lobe in &self.lobes {
            let m = side_matrices(basis, &lobe.bsdfs, self.transmitting, sampling);
            let n = m.n;
            let sum = total.get_or_insert_with(|| SideMatrices {
                n,
                reflection: vec![[0.0; 3]; n * n],
                transmission: m.transmission.as_ref().map(|_| vec![[0.0; 3]; n * n]),
            });
            let add = |to: &mut [Rgb], from: &[Rgb]| {
                for (index, (t, f)) in to.iter_mut().zip(from).enumerate() {
                    let w = lobe.weights[index % n];
                    for c in 0..3 {
                        t[c] += w * f[c];
                    }
                }
            };
            add(&mut sum.reflection, &m.reflection);
            if let (Some(to), Some(from)) = (sum.transmission.as_mut(), m.transmission.as_ref()) {
                add(to, from);
            }
        }
        total.expect("a material has a lobe")
    }
}

/// The fit's evaluation options for export: its variant and Fresnel
/// constant, a point source (ω = 0: the material's own BSDF, without the
/// gonio source's widening).
fn export_options(result: &FitResult) -> EvalOptions {
    EvalOptions {
        source_omega: 0.0,
        ..result.options()
    }
}

/// The materials of one fit per incident patch θ_in.
fn side_from_fit(
    result: &FitResult,
    fit_path: &Path,
    basis: &KlemsBasis,
) -> Result<SideModel, KlemsExportError> {
    let options = export_options(result);
    let mut lobes: Vec<Lobe> = Vec::new();
    let mirrored = result.is_mirrored_side();
    for patch in basis.patches() {
        let theta = patch.theta_deg;
        // A patch's (θ, φ) is the direction of travel: the light is at φ + 180°.
        let phi = azimuth_from_u(result.config.orientation, mirrored, patch.phi_deg + 180.0);
        let material = match &result.table {
            Some(table) => table
                .composite_at_direction(theta, phi)
                .map(|(m, _)| m)
                .map_err(|e| e.to_string()),
            None => result
                .static_composite()
                .ok_or_else(|| "the fit holds no parameters".to_string()),
        }
        .map_err(|why| KlemsExportError::NoMaterial {
            fit: fit_path.display().to_string(),
            theta,
            why,
        })?;
        let parts = material.components();
        if lobes.is_empty() {
            lobes = parts
                .iter()
                .map(|_| Lobe {
                    weights: Vec::with_capacity(basis.len()),
                    bsdfs: Vec::with_capacity(basis.len()),
                })
                .collect();
        }
        // One shape for the whole fit, so the same lobes at every patch.
        for (lobe, (w, m)) in lobes.iter_mut().zip(parts) {
            lobe.weights.push(*w);
            lobe.bsdfs.push(Bsdf::new(m, &options));
        }
    }
    Ok(SideModel {
        lobes,
        transmitting: result.config.kind.is_transmitting(),
        same_as_front: false,
    })
}

/// A fit folder: `DIR/fit.json` (front only), or `DIR/front/fit.json` and
/// `DIR/back/fit.json` (two-sided).
pub fn klems_from_fit_dir(
    dir: &Path,
    options: &KlemsOptions,
) -> Result<KlemsExport, KlemsExportError> {
    let front_path = dir.join("front").join("fit.json");
    let back_path = dir.join("back").join("fit.json");
    let two_sided = front_path.is_file() && back_path.is_file();
    let (front_path, back_path) = if two_sided {
        (front_path, Some(back_path))
    } else {
        (dir.join("fit.json"), None)
    };
    let front = FitResult::read(&front_path)?;
    let back = back_path.as_ref().map(|p| FitResult::read(p)).transpose()?;
    if let Some(back) = &back
        && back.config.kind != front.config.kind
    {
        return Err(KlemsExportError::MixedSides {
            front: front.config.kind.to_string(),
            back: back.config.kind.to_string(),
        });
    }
    let mut sides = vec![(
        Side::Front,
        side_from_fit(&front, &front_path, &options.basis)?,
    )];
    if let (Some(back), Some(path)) = (&back, &back_path) {
        sides.push((Side::Back, side_from_fit(back, path, &options.basis)?));
    }
    let mut comment = vec![format!(
        "Klems BSDF of the fit {} ({}), written by brtf {} (brtf export --klems).",
        if two_sided {
            format!("folder {} (front/ and back/)", dir.display())
        } else {
            front_path.display().to_string()
        },
        front.config.kind,
        env!("CARGO_PKG_VERSION")
    )];
    for (label, result, path) in [("front", Some(&front), Some(&front_path))]
        .into_iter()
        .chain([("back", back.as_ref(), back_path.as_ref())])
    {
        let (Some(result), Some(path)) = (result, path) else {
            continue;
        };
        comment.extend(fit_provenance(label, result, path));
    }
    let mut notes = Vec::new();
    if !two_sided {
        notes.push(
            "front side only (Reflection Back = rf, Transmission Back = tf): the fit describes \
             light from +z; a two-sided fit (front/ and back/) gives all four components"
                .to_string(),
        );
    }
    for (label, result) in [("front", Some(&front)), ("back", back.as_ref())] {
        if let Some(result) = result
            && result.table.is_none()
        {
            notes.push(format!(
                "{label}: the fit has no theta_in table (one incidence): every incident patch \
                 gets the same parameters"
            ));
        }
    }
    comment.push(match &front.table {
        Some(t) => format!(
            "Parameters: per incident patch, the theta_in table ({:?}) at the patch's ring \
             centre, clamped to the fitted {}-{} deg.",
            t.method,
            t.range().0,
            t.range().1
        ),
        None => "Parameters: the fit's static material for every incident patch.".into(),
    });
    build(sides, options, comment, notes)
}

/// A static material: all four components (Radiance materials are
/// two-sided, so the back equals the front).
pub fn klems_from_material(
    material: &Material,
    eval: &EvalOptions,
    source: &str,
    source_sha256: &str,
    options: &KlemsOptions,
) -> Result<KlemsExport, KlemsExportError> {
    klems_from_composite(
        &Composite::from_material(material),
        eval,
        source,
        source_sha256,
        options,
    )
}

/// A static material, one primitive or a lobe sum (a constant mixfunc
/// tree): all four components, the back equal to the front.
pub fn klems_from_composite(
    material: &Composite,
    eval: &EvalOptions,
    source: &str,
    source_sha256: &str,
    options: &KlemsOptions,
) -> Result<KlemsExport, KlemsExportError> {
    // brtf-model turns the surface towards the viewer, so light from the
    // back sees exactly the front's BSDF: the back matrices are the front's.
    let side = |same_as_front| SideModel {
        same_as_front,
        ..SideModel::uniform(material, eval, options.basis.len())
    };
    let list = |args: &[f64]| {
        args.iter()
            .map(|a| a.to_string())
            .collect::<Vec<_>>()
            .join(" ")
    };
    let parts = material.components();
    let kind = material.kind();
    let mut comment = vec![
        format!(
            "Klems BSDF of the static Radiance {} in {source}, written by brtf {} (brtf export \
             --klems --material).",
            if parts.len() > 1 {
                format!("lobe sum (mixfunc of {} primitives)", parts.len())
            } else {
                kind.to_string()
            },
            env!("CARGO_PKG_VERSION")
        ),
        format!("Input: {source} sha256 {source_sha256}"),
    ];
    if let [(_, m)] = parts {
        comment.push(format!(
            "Material: {} {}; variant {}, Fresnel K {}.",
            m.kind(),
            list(m.args()),
            eval.variant,
            eval.fresnel_k
        ));
    } else {
        for (k, (w, m)) in parts.iter().enumerate() {
            comment.push(format!(
                "Lobe {}: weight {w}, {} {}.",
                k + 1,
                m.kind(),
                list(m.args())
            ));
        }
        comment.push(format!(
            "Variant {}, Fresnel K {}.",
            eval.variant, eval.fresnel_k
        ));
    }
    build(
        vec![(Side::Front, side(false)), (Side::Back, side(true))],
        options,
        comment,
        Vec::new(),
    )
}

/// Provenance lines of one side's fit: the file's hash and its inputs.
fn fit_provenance(label: &str, result: &FitResult, path: &Path) -> Vec<String> {
    let sha = std::fs::read(path)
        .map(|b| brtf_io::sha256_hex(&b))
        .unwrap_or_else(|_| "unreadable".into());
    let p = &result.provenance;
    let mut lines = vec![
        format!("{label}: {} sha256 {sha}", path.display()),
        format!(
            "  fit \"{}\" by brtf {} at {}: {}",
            result.name,
            p.brtf_version,
            p.created,
            p.command_line.join(" ")
        ),
    ];
    for input in &p.inputs {
        lines.push(format!(
            "  input {} theta_in {} phi_in {} sha256 {}",
            input.path, input.theta_in, input.phi_in, input.sha256
        ));
    }
    lines
}

/// The matrices, bands and text.
fn build(
    sides: Vec<(Side, SideModel)>,
    options: &KlemsOptions,
    mut comment: Vec<String>,
    mut notes: Vec<String>,
) -> Result<KlemsExport, KlemsExportError> {
    if options.sampling.samples == 0 {
        return Err(KlemsExportError::Invalid(
            "--klems-samples 0: out of range; allowed: at least 1".into(),
        ));
    }
    if !(options.thickness_mm.is_finite() && options.thickness_mm >= 0.0) {
        return Err(KlemsExportError::Invalid(format!(
            "--thickness {}: out of range; allowed: a finite number of millimetres >= 0",
            options.thickness_mm
        )));
    }
    options
        .window
        .validate()
        .map_err(KlemsExportError::Invalid)?;
    let basis = &options.basis;
    let mut computed: Vec<(Side, SideMatrices)> = Vec::new();
    for (side, model) in &sides {
        let matrices = match computed.first() {
            Some((_, front)) if model.same_as_front => front.clone(),
            _ => model.matrices(basis, options.sampling),
        };
        computed.push((*side, matrices));
    }
    let mut bands = vec![KlemsBand::Visible];
    if options.colour {
        bands.push(KlemsBand::CieX);
        bands.push(KlemsBand::CieZ);
    }
    let mut blocks = Vec::new();
    // WINDOW's order: band by band, transmission before reflection.
    let order = |side: Side, m: &SideMatrices| {
        let mut v: Vec<(KlemsDirection, Vec<Rgb>)> = Vec::new();
        if let Some(t) = &m.transmission {
            v.push((side.transmission(), t.clone()));
        }
        v.push((side.reflection(), m.reflection.clone()));
        v
    };
    let all: Vec<(KlemsDirection, Vec<Rgb>)> = computed
        .iter()
        .flat_map(|(side, m)| order(*side, m))
        .collect();
    for band in &bands {
        for (direction, rgb) in &all {
            blocks.push(KlemsWriteBlock {
                band: band.clone(),
                direction: *direction,
                values: band_values(rgb, band).expect("Y, X or Z"),
            });
        }
    }
    match &options.solar {
        SolarBand::None => {}
        SolarBand::ReuseVisible => {
            comment.push(
                "ASSUMPTION: the Solar band repeats the Visible values (no solar measurement \
                 was given)."
                    .into(),
            );
            for (direction, rgb) in &all {
                blocks.push(KlemsWriteBlock {
                    band: KlemsBand::Solar,
                    direction: *direction,
                    values: band_values(rgb, &KlemsBand::Visible).expect("Y"),
                });
            }
        }
        SolarBand::Material { material, source } => {
            comment.push(format!(
                "Solar band: the luminance-weighted BSDF of the static {}{} in {source} (the \
                 user's solar properties), the same for every incident patch.",
                material.kind(),
                if material.components().len() > 1 {
                    " lobe sum"
                } else {
                    ""
                }
            ));
            let eval = sides
                .first()
                .and_then(|(_, m)| m.options())
                .unwrap_or_default();
            let transmitting = sides.iter().any(|(_, m)| m.transmitting);
            let mut solar = SideModel::uniform(material, &eval, basis.len());
            if solar.transmitting != transmitting {
                notes.push(format!(
                    "the solar material {source} is a {}: its transmission does not match the \
                     visible components'",
                    material.kind()
                ));
            }
            solar.transmitting = transmitting;
            // One static material: the same matrices for both sides.
            let m = solar.matrices(basis, options.sampling);
            for (side, _) in &sides {
                for (direction, rgb) in order(*side, &m) {
                    blocks.push(KlemsWriteBlock {
                        band: KlemsBand::Solar,
                        direction,
                        values: band_values(&rgb, &KlemsBand::Visible).expect("Y"),
                    });
                }
            }
        }
    }
    comment.push(format!(
        "Values: BSDF (1/sr) averaged over the outgoing and the incident patch, {} stratified \
         samples per entry (seed {}); roughness-0 mirror and straight-through parts on the \
         diagonal as E / Lambda_i. Basis {}.",
        options.sampling.samples, options.sampling.seed, basis.name
    ));
    comment.push(
        "Visible is CIE Y of Radiance RGB; CIE-X and CIE-Z (when present) use Radiance's \
         primaries."
            .into(),
    );
    comment.push(
        "Directions: Reflection Back = Radiance rf, Transmission Back = tf (light from +z); \
         Reflection Front = rb, Transmission Front = tb."
            .into(),
    );
    if !options.command_line.is_empty() {
        comment.push(format!("Command: {}", options.command_line.join(" ")));
    }
    comment.push(format!("Created: {}", brtf_io::utc_now_rfc3339()));
    let header = KlemsWriteHeader {
        name: options.name.clone(),
        manufacturer: options.manufacturer.clone(),
        thickness_mm: options.thickness_mm,
        device_type: options.device_type.clone(),
        window: options.window,
        comment,
    };
    let text = to_klems_xml(&header, basis, &blocks).map_err(KlemsExportError::Invalid)?;
    Ok(KlemsExport {
        text,
        blocks,
        notes,
    })
}

/// Writes the export atomically to `path`.
pub fn write_klems(path: &Path, export: &KlemsExport) -> Result<(), KlemsExportError> {
    brtf_io::write_atomic(path, export.text.as_bytes()).map_err(|e| KlemsExportError::Io {
        path: e.path,
        source: e.source,
    })
}

/// The file stem of a Klems export named `name`: its last path part, with
/// every character but ASCII letters, digits, `_`, `-` and `.` made `_`
/// (`klems` for an empty name). `brtf export --klems` and the Python
/// package name their files with it.
pub fn klems_file_stem(name: &str) -> String {
    name.rsplit(['/', '\\'])
        .find(|s| !s.is_empty())
        .unwrap_or("klems")
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect()
}
