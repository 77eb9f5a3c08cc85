//! Renders through brtf's tracer: the virtual gonio-photometer (`brtf
//! render gonio`) and pictures (`brtf render image`), with their files.

use crate::WorkflowError;
use brtf_fit::FitResult;
use brtf_gonio::{Channels, Measurement, SourceFormat};
use brtf_model::{Composite, EvalOptions, Variant};
use brtf_trace::Shader;
use brtf_trace::{GonioSetup, GonioValue, RayCounts, SceneSpec, VirtualGonio};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

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
    /// The static material, one primitive or a lobe sum (the fit's
    /// all-incidence set, or the file's).
    pub material: Composite,
    /// Its name.
    pub name: String,
    /// The fit, when the material came from one.
    pub fit: Option<FitResult>,
    /// The files it was read from, which no output may replace: the
    /// `.rad` file, or the fit folder's ([`brtf_io::fit_folder_inputs`]).
    pub inputs: Vec<PathBuf>,
}

/// Loads `source` for the tracer: a fit folder of any shape (one
/// primitive, a lobe sum, a fitted orientation) or a `.rad` material.
/// `variant` and `fresnel_k` override the fit's (default: radiance and
/// the classic constant for a file).
pub fn load_render_material(
    source: &MaterialSource,
    variant: Option<Variant>,
    fresnel_k: Option<f64>,
) -> Result<RenderMaterial, WorkflowError> {
    let (name, material, fit, mut options) = match source {
        MaterialSource::File { path, name } => {
            let (name, material) = crate::read_material_file(path, name.as_deref())?;
            (name, material, None, EvalOptions::default())
        }
        MaterialSource::Fit { dir, .. } => {
            let fit = crate::read_fit(dir)?;
            let material = fit.static_composite().ok_or_else(|| {
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
        None => Shader::new(&material, &options)?,
    };
    let inputs = match source {
        MaterialSource::File { path, .. } => vec![path.clone()],
        MaterialSource::Fit { dir, .. } => brtf_io::fit_folder_inputs(dir, "render", &[]),
    };
    Ok(RenderMaterial {
        shader,
        material,
        name,
        fit,
        inputs,
    })
}

/// The header words of a file `brtf render gonio` wrote: `--force` is
/// needed to replace any other existing file.
const GONIO_MARKER: &str = "rendered by brtf render gonio";

/// A virtual gonio-photometer run.
#[derive(Debug, Clone)]
pub struct GonioRequest {
    /// Reproduce this measurement: its incidence and every direction.
    pub like: Option<PathBuf>,
    /// θ_in, φ_in in degrees (default: the `like` file's; φ_in 0).
    pub incidence: [Option<f64>; 2],
    /// Without `like`: θ_out and φ_out grid steps, degrees.
    pub grid_steps: [f64; 2],
    /// Without `like`: also the back hemisphere (always for transmitting types).
    pub back: bool,
    /// Beam solid angle, sr (default: the fit's source ω, else a point).
    pub source_omega: Option<f64>,
    /// Detector solid angle, sr (default: a point).
    pub detector_omega: Option<f64>,
    /// Rays per direction.
    pub samples: u32,
    /// Random seed.
    pub seed: u64,
    /// Values per sample of the written file (default: the `like` file's, else Y).
    pub channels: Option<Channels>,
    /// The measurement file written (`.mpc`, else Mountain), if any.
    pub out: Option<PathBuf>,
    /// Replace an existing `out` this command did not write (never an input).
    pub force: bool,
}

/// What a virtual gonio-photometer run rendered.
#[derive(Debug, Clone)]
pub struct GonioRun {
    /// The directions (θ_out, φ_out), degrees.
    pub directions: Vec<(f64, f64)>,
    /// The rendered BSDF per direction.
    pub values: Vec<GonioValue>,
    /// Rays traced.
    pub rays: RayCounts,
    /// Wall time of the rendering.
    pub elapsed: Duration,
}

/// Renders `material` at the request's directions; writes `out` when given.
pub fn render_gonio(
    material: RenderMaterial,
    request: &GonioRequest,
    material_file: Option<&Path>,
) -> Result<GonioRun, WorkflowError> {
    let like: Option<Measurement> = match &request.like {
        Some(p) => Some(brtf_gonio::read_path(p)?),
        None => None,
    };
    let [theta_in, phi_in] = request.incidence;
    let theta_in = theta_in
        .or(like.as_ref().map(|m| m.incidence.theta_deg))
        .ok_or_else(|| {
            WorkflowError::Usage("give --theta-in (and --phi-in), or --like FILE".into())
        })?;
    let phi_in = phi_in
        .or(like.as_ref().map(|m| m.incidence.phi_deg))
        .unwrap_or(0.0);
    brtf_model::check_incidence(theta_in, phi_in)?;
    if let Some(out) = &request.out {
        let inputs: Vec<&Path> = [request.like.as_deref(), material_file]
            .into_iter()
            .flatten()
            .chain(material.inputs.iter().map(PathBuf::as_path))
            .collect();
        brtf_io::check_overwrite(out, &inputs, Some(GONIO_MARKER), request.force)?;
    }
    let fit_omega = material.fit.as_ref().map(|f| f.options().source_omega);
    let setup = GonioSetup {
        theta_in,
        phi_in,
        source_omega: request.source_omega.or(fit_omega).unwrap_or(0.0),
        detector_omega: request.detector_omega.unwrap_or(0.0),
        samples: request.samples.max(1),
        seed: request.seed,
    };
    setup.validate()?;
    let directions: Vec<(f64, f64)> = match &like {
        Some(m) => m.samples.iter().map(|s| (s.theta_deg, s.phi_deg)).collect(),
        None => {
            let [dt, dp] = request.grid_steps;
            let back = request.back || material.shader.is_transmitting();
            brtf_trace::grid(dt, dp, back)?
        }
    };
    let format = match &request.out {
        Some(p) if p.extension().is_some_and(|e| e.eq_ignore_ascii_case("mpc")) => {
            SourceFormat::Mpc
        }
        _ => SourceFormat::Mountain,
    };
    let mut channels = request
        .channels
        .unwrap_or_else(|| like.as_ref().map_or(Channels::Y, |m| m.channels));
    if format == SourceFormat::Mpc && request.out.is_some() {
        if request.channels == Some(Channels::Xyz) {
            return Err(WorkflowError::Usage(
                ".mpc holds one channel; use --channels y or a Mountain file".into(),
            ));
        }
        channels = Channels::Y;
    }
    let name = material.name.clone();
    let gonio = VirtualGonio::new(material.shader, setup);
    let vectors: Vec<_> = directions
        .iter()
        .map(|&(t, p)| brtf_model::direction(t, p))
        .collect();
    let start = Instant::now();
    let (values, rays) = gonio.render(&vectors);
    let elapsed = start.elapsed();
    if let Some(path) = &request.out {
        let mut m = brtf_trace::measurement_from(&setup, &directions, &values, channels, format);
        if let Some(l) = &like {
            for (s, src) in m.samples.iter_mut().zip(&l.samples) {
                s.solid_angle_sr = src.solid_angle_sr;
            }
            m.sample_name = l.sample_name.clone();
        }
        let apertures = brtf_gonio::Apertures {
            source_deg: Some(brtf_model::cone_apex_deg(setup.source_omega)),
            detector_deg: Some(brtf_model::cone_apex_deg(setup.detector_omega)),
        };
        m.header.extend(apertures.header_lines());
        m.header.push(format!(
            "# {GONIO_MARKER}: material {name}, beam {} sr, detector {} sr, {} rays per direction, seed {}",
            setup.source_omega, setup.detector_omega, setup.samples, setup.seed
        ));
        brtf_gonio::write_path(&m, path, format)?;
    }
    Ok(GonioRun {
        directions,
        values,
        rays,
        elapsed,
    })
}

/// A picture rendered and written.
#[derive(Debug, Clone)]
pub struct ImageRun {
    /// Width × height.
    pub size: [usize; 2],
    /// Camera rays per pixel.
    pub samples: u32,
    /// Rays traced.
    pub rays: RayCounts,
    /// Wall time of the rendering.
    pub elapsed: Duration,
    /// The files written: `PREFIX.hdr`, `PREFIX.png` (and `.rad`, `.vf`).
    pub files: Vec<PathBuf>,
    /// Things the user should know.
    pub notes: Vec<String>,
}

/// The picture options besides the scene.
#[derive(Debug, Clone, Copy)]
pub struct ImageRequest {
    /// Camera rays per pixel.
    pub samples: u32,
    /// Jittered rays (else pixel centres).
    pub jitter: bool,
    /// Random seed.
    pub seed: u64,
    /// PNG exposure (default: automatic).
    pub exposure: Option<f64>,
    /// Also the Radiance scene and view for `rpict`.
    pub radiance: bool,
}

impl ImageRequest {
    /// Checks these options and the scene's, before any work (a front end
    /// calls it before loading the material).
    pub fn validate(&self, spec: &SceneSpec) -> Result<(), WorkflowError> {
        spec.validate()?;
        let samples = f64::from(self.samples);
        let check = brtf_model::OptionError::check;
        check(
            "--samples",
            samples,
            (1.0..=65536.0).contains(&samples),
            "1 to 65536",
        )?;
        if let Some(e) = self.exposure {
            check(
                "--exposure",
                e,
                e.is_finite() && e > 0.0,
                "a number above 0",
            )?;
        }
        Ok(())
    }
}

/// `prefix` + `ext`; a prefix given with one of the outputs' extensions
/// (`img.hdr`) loses it, so that it does not write `img.hdr.hdr`.
pub fn with_extension(prefix: &Path, ext: &str) -> PathBuf {
    let stem = match prefix.extension().and_then(|e| e.to_str()) {
        Some("hdr" | "png") => prefix.with_extension(""),
        _ => prefix.to_path_buf(),
    };
    let mut p = stem.into_os_string();
    p.push(ext);
    PathBuf::from(p)
}

/// Renders `material` in the scene `spec` and writes `PREFIX.hdr` and
/// `PREFIX.png` (with `radiance`, also `PREFIX.rad` and `PREFIX.vf`).
pub fn render_image(
    material: RenderMaterial,
    spec: &SceneSpec,
    request: &ImageRequest,
    prefix: &Path,
    material_file: Option<&Path>,
) -> Result<ImageRun, WorkflowError> {
    request.validate(spec)?;
    // The static material as Radiance text, for `--radiance`: one
    // primitive, or a lobe sum's primitives and its mixfunc tree.
    let primitive_text = request.radiance.then(|| {
        brtf_radiance::composite_primitives(&material.material, brtf_trace::MATERIAL_NAME)
            .iter()
            .map(brtf_radiance::format_primitive)
            .collect::<Vec<_>>()
            .join("\n")
    });
    let inputs: Vec<&Path> = material_file
        .into_iter()
        .chain(material.inputs.iter().map(PathBuf::as_path))
        .collect();
    for ext in [".hdr", ".png", ".rad", ".vf"] {
        brtf_io::check_overwrite(&with_extension(prefix, ext), &inputs, None, false)?;
    }
    let is_table = material.shader.is_table();
    let (scene, camera) = spec.build(material.shader)?;
    let options = spec.image_options(request.samples, request.jitter, request.seed);
    let rendered = brtf_trace::render(&scene, &camera, &options);
    let view = camera.view_options();
    let mut hdr = Vec::new();
    brtf_trace::hdr::write(
        &mut hdr,
        &rendered.picture,
        &[
            format!("SOFTWARE= brtf {} (brtf-trace)", env!("CARGO_PKG_VERSION")),
            format!("VIEW= {}", view.trim_start_matches("rview ")),
        ],
    )?;
    let exposure = request
        .exposure
        .unwrap_or_else(|| brtf_trace::auto_exposure(&rendered.picture));
    let mut png = Vec::new();
    brtf_trace::write_png(&mut png, &rendered.picture, exposure)
        .map_err(|e| WorkflowError::Usage(format!("cannot encode the PNG: {e}")))?;
    let mut written = vec![
        (with_extension(prefix, ".hdr"), hdr),
        (with_extension(prefix, ".png"), png),
    ];
    let mut notes = Vec::new();
    if let Some(primitive) = primitive_text {
        let name = prefix
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let rad = spec.radiance_text(&primitive, &name);
        written.push((with_extension(prefix, ".rad"), rad.into_bytes()));
        written.push((
            with_extension(prefix, ".vf"),
            format!("{view}\n").into_bytes(),
        ));
        if is_table {
            notes.push(format!(
                "{}.rad holds the fit's static material; brtf-trace rendered its θ_in table",
                prefix.display()
            ));
        }
    }
    for (path, bytes) in &written {
        if let Some(folder) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
            brtf_io::ensure_folder(folder)?;
        }
        brtf_io::write_atomic(path, bytes)?;
    }
    Ok(ImageRun {
        size: [spec.view.width, spec.view.height],
        samples: options.samples,
        rays: rendered.rays,
        elapsed: rendered.elapsed,
        files: written.into_iter().map(|(p, _)| p).collect(),
        notes,
    })
}

/// Writes the files of a synthetic measurement set into `out`, refusing
/// to replace files brtf synth did not write (unless `force`) or the
/// material file. Returns each file and its sample count.
pub fn write_synth_set(
    set: &brtf_gonio::synth::SynthSet,
    out: &Path,
    material_file: Option<&Path>,
    force: bool,
) -> Result<Vec<(PathBuf, usize)>, WorkflowError> {
    set.validate()?;
    let inputs: Vec<&Path> = material_file.into_iter().collect();
    let marker = Some(brtf_gonio::synth::SYNTH_MARKER);
    for &theta in &set.theta_in {
        brtf_io::check_overwrite(&out.join(set.file_name(theta)), &inputs, marker, force)?;
    }
    brtf_io::ensure_folder(out)?;
    let mut written = Vec::with_capacity(set.theta_in.len());
    for (index, &theta) in set.theta_in.iter().enumerate() {
        let (text, samples) = set.file_text(index).map_err(WorkflowError::Usage)?;
        let file = out.join(set.file_name(theta));
        brtf_io::write_atomic(&file, text.as_bytes())?;
        written.push((file, samples));
    }
    Ok(written)
}
