//! `brtf render gonio|image`: brtf's own ray tracer (brtf-trace).
//!
//! * `gonio`: the virtual gonio-photometer. It reproduces a measurement's
//!   geometry (`--like FILE`) or a θ/φ grid, renders the BSDF per sample
//!   and writes it as a measurement file (`.mpc` or Mountain) or CSV.
//! * `image`: the material on a sphere and a plane under a source, as a
//!   Radiance HDR picture and a tone-mapped PNG; `--radiance` also writes
//!   the same scene and view for `rpict`.
//!
//! The material comes from a Radiance file (`--material`) or a fit folder
//! (`--fit DIR`: its θ_in-interpolated table, or `--static` for one set).

use super::material::{MaterialArgs, parse_fresnel_k, parse_variant};
use super::output::write_atomic;
use anyhow::{Context, Result, bail};
use brtf_fit::FitResult;
use brtf_gonio::{Channels, Measurement, SourceFormat};
use brtf_model::{FRESNEL_K_CLASSIC, Material, Variant, cone_solid_angle};
use brtf_trace::gonio::{GonioSetup, VirtualGonio, measurement_from};
use brtf_trace::image::{ImageOptions, auto_exposure, write_png};
use brtf_trace::{Camera, Scene, Settings, Shader, Shape, Source, hdr};
use clap::{Args, Subcommand, ValueEnum};
use glam::DVec3;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(subcommand)]
    pub what: RenderWhat,
}

#[derive(Subcommand, Debug)]
pub enum RenderWhat {
    /// Virtual gonio-photometer: the rendered BSDF at a measurement's directions.
    Gonio(GonioArgs),
    /// A picture of the material on a sphere and a plane (HDR + PNG).
    Image(ImageArgs),
}

/// Where the material comes from.
#[derive(Args, Debug, Clone)]
pub struct SampleMaterial {
    /// Radiance file holding the material primitive(s).
    #[arg(
        long,
        value_name = "M.rad",
        required_unless_present = "fit",
        conflicts_with = "fit"
    )]
    pub material: Option<PathBuf>,
    /// Which material in the file (needed when it holds several).
    #[arg(long, value_name = "N")]
    pub name: Option<String>,
    /// A fit folder (fit.json): render its θ_in-interpolated material.
    #[arg(long, value_name = "DIR")]
    pub fit: Option<PathBuf>,
    /// With --fit: the one all-incidence material instead of the θ_in table.
    #[arg(long = "static", requires = "fit")]
    pub static_material: bool,
    /// Formula set [default: radiance, or the fit's].
    #[arg(long, value_parser = parse_variant)]
    pub variant: Option<Variant>,
    /// Fresnel constant for roughness-0 surfaces: classic, pyradiance or a
    /// number [default: classic, or the fit's].
    #[arg(long, value_parser = parse_fresnel_k)]
    pub fresnel_k: Option<f64>,
}

/// A loaded material: the shader and a one-set material for exports.
pub struct Loaded {
    pub shader: Shader,
    /// The static material (the fit's all-incidence set, or the file's).
    pub material: Material,
    pub name: String,
    /// The fit, when the material came from one.
    pub fit: Option<FitResult>,
}

/// Reads `DIR/fit.json`.
pub fn read_fit(dir: &Path) -> Result<FitResult> {
    let path = dir.join("fit.json");
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("cannot read {}", path.display()))?;
    serde_json::from_str(&text)
        .with_context(|| format!("{}: not a brtf fit result", path.display()))
}

impl SampleMaterial {
    pub fn load(&self) -> Result<Loaded> {
        if let Some(dir) = &self.fit {
            let fit = read_fit(dir)?;
            let mut options = fit.options();
            if let Some(v) = self.variant {
                options.variant = v;
            }
            if let Some(k) = self.fresnel_k {
                options.fresnel_k = k;
            }
            let material = fit
                .static_material()
                .context("the fit holds no valid material")?;
            let shader = match (&fit.table, self.static_material) {
                (Some(table), false) => Shader::from_table(table, &options)?,
                _ => Shader::new(&material, &options),
            };
            return Ok(Loaded {
                shader,
                material,
                name: fit.name.clone(),
                fit: Some(fit),
            });
        }
        let file = self
            .material
            .clone()
            .expect("clap requires --material or --fit");
        let args = MaterialArgs {
            material: file,
            name: self.name.clone(),
            variant: self.variant.unwrap_or_default(),
            fresnel_k: self.fresnel_k.unwrap_or(FRESNEL_K_CLASSIC),
            source_omega: 0.0,
            curved: false,
        };
        let (name, material) = args.load()?;
        let options = args.options()?;
        Ok(Loaded {
            shader: Shader::new(&material, &options),
            material,
            name,
            fit: None,
        })
    }
}

/// A solid angle given in sr or as a full cone apex angle in degrees.
fn solid_angle(omega: Option<f64>, apex: Option<f64>, what: &str) -> Result<Option<f64>> {
    match (omega, apex) {
        (Some(_), Some(_)) => bail!("give the {what} as --{what}-omega or --{what}-apex, not both"),
        (Some(w), None) => {
            anyhow::ensure!(w.is_finite() && w >= 0.0, "--{what}-omega must be ≥ 0 sr");
            Ok(Some(w))
        }
        (None, Some(a)) => {
            anyhow::ensure!(
                a.is_finite() && (0.0..=180.0).contains(&a),
                "--{what}-apex must be between 0 and 180 degrees"
            );
            Ok(Some(cone_solid_angle(a)))
        }
        (None, None) => Ok(None),
    }
}

pub fn run(args: RenderArgs) -> Result<()> {
    match args.what {
        RenderWhat::Gonio(a) => run_gonio(a),
        RenderWhat::Image(a) => run_image(a),
    }
}

// ---------------------------------------------------------------------------
// brtf render gonio
// ---------------------------------------------------------------------------

#[derive(Args, Debug)]
pub struct GonioArgs {
    #[command(flatten)]
    pub sample: SampleMaterial,
    /// Reproduce this measurement's geometry: its incidence and every sample direction.
    #[arg(long, value_name = "FILE")]
    pub like: Option<PathBuf>,
    /// Incident polar angle θ_in in degrees (overrides the --like file's).
    #[arg(long, allow_hyphen_values = true)]
    pub theta_in: Option<f64>,
    /// Incident azimuth φ_in in degrees.
    #[arg(long, allow_hyphen_values = true)]
    pub phi_in: Option<f64>,
    /// Without --like: θ_out grid step in degrees.
    #[arg(long, default_value_t = 5.0)]
    pub theta_step: f64,
    /// Without --like: φ_out grid step in degrees.
    #[arg(long, default_value_t = 15.0)]
    pub phi_step: f64,
    /// Without --like: also the back (transmission) hemisphere [default: for trans types].
    #[arg(long)]
    pub back: bool,
    /// Beam solid angle in sr [default: the fit's source ω, else a point].
    #[arg(long, value_name = "SR")]
    pub source_omega: Option<f64>,
    /// Beam as a full cone apex angle in degrees.
    #[arg(long, value_name = "DEG")]
    pub source_apex: Option<f64>,
    /// Detector aperture solid angle in sr [default: a point].
    #[arg(long, value_name = "SR")]
    pub detector_omega: Option<f64>,
    /// Detector aperture as a full cone apex angle in degrees.
    #[arg(long, value_name = "DEG")]
    pub detector_apex: Option<f64>,
    /// Rays per detector direction.
    #[arg(long, default_value_t = 256)]
    pub samples: u32,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Values per sample in the output file: `y` (luminance) or `rgb`
    /// (the material's three channels) [default: the --like file's, else y].
    #[arg(long, value_enum)]
    pub channels: Option<ChannelsArg>,
    /// Output measurement file: `.mpc` (ISE) or anything else (Mountain).
    /// Without it, CSV goes to stdout.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Worker threads [default: all cores].
    #[arg(long)]
    pub jobs: Option<usize>,
}

#[derive(Clone, Copy, Debug, PartialEq, ValueEnum)]
pub enum ChannelsArg {
    Y,
    Rgb,
}

fn run_gonio(args: GonioArgs) -> Result<()> {
    let loaded = args.sample.load()?;
    let like: Option<Measurement> = match &args.like {
        Some(p) => {
            Some(brtf_gonio::read_path(p).with_context(|| format!("cannot read {}", p.display()))?)
        }
        None => None,
    };
    let theta_in = args
        .theta_in
        .or(like.as_ref().map(|m| m.incidence.theta_deg))
        .context("give --theta-in (and --phi-in), or --like FILE")?;
    let phi_in = args
        .phi_in
        .or(like.as_ref().map(|m| m.incidence.phi_deg))
        .unwrap_or(0.0);
    anyhow::ensure!(
        theta_in.is_finite() && (0.0..=180.0).contains(&theta_in) && phi_in.is_finite(),
        "θ_in must be between 0 and 180 degrees"
    );
    let fit_omega = loaded.fit.as_ref().map(|f| f.options().source_omega);
    let source_omega = solid_angle(args.source_omega, args.source_apex, "source")?
        .or(fit_omega)
        .unwrap_or(0.0);
    let detector_omega =
        solid_angle(args.detector_omega, args.detector_apex, "detector")?.unwrap_or(0.0);
    let setup = GonioSetup {
        theta_in,
        phi_in,
        source_omega,
        detector_omega,
        samples: args.samples.max(1),
        seed: args.seed,
    };
    let directions: Vec<(f64, f64)> = match &like {
        Some(m) => m.samples.iter().map(|s| (s.theta_deg, s.phi_deg)).collect(),
        None => grid(
            args.theta_step,
            args.phi_step,
            args.back || loaded.material.kind().is_transmitting(),
        )?,
    };
    let out_format = match &args.out {
        Some(p) if p.extension().is_some_and(|e| e.eq_ignore_ascii_case("mpc")) => {
            SourceFormat::Mpc
        }
        _ => SourceFormat::Mountain,
    };
    let mut channels = match args.channels {
        Some(ChannelsArg::Y) => Channels::Y,
        Some(ChannelsArg::Rgb) => Channels::Xyz,
        None => like.as_ref().map_or(Channels::Y, |m| m.channels),
    };
    if out_format == SourceFormat::Mpc && args.out.is_some() {
        if args.channels == Some(ChannelsArg::Rgb) {
            bail!(".mpc holds one channel; use --channels y or a Mountain file");
        }
        channels = Channels::Y;
    }

    let gonio = VirtualGonio::new(loaded.shader, setup);
    let dirs: Vec<DVec3> = directions
        .iter()
        .map(|&(t, p)| brtf_model::direction(t, p))
        .collect();
    let start = std::time::Instant::now();
    let (values, rays) = with_jobs(args.jobs, || gonio.render(&dirs))?;
    let elapsed = start.elapsed().as_secs_f64();
    eprintln!(
        "brtf render gonio: {} directions × {} rays, {:.2} M rays in {:.2} s ({:.2} M rays/s)",
        dirs.len(),
        setup.samples,
        rays.total() as f64 / 1e6,
        elapsed,
        rays.total() as f64 / 1e6 / elapsed.max(1e-9)
    );

    match &args.out {
        Some(path) => {
            let mut m = match &like {
                Some(l) => {
                    let mut m =
                        measurement_from(&setup, &directions, &values, channels, out_format);
                    for (s, src) in m.samples.iter_mut().zip(&l.samples) {
                        s.solid_angle_sr = src.solid_angle_sr;
                    }
                    m.sample_name = l.sample_name.clone();
                    m
                }
                None => measurement_from(&setup, &directions, &values, channels, out_format),
            };
            m.header.push(format!(
                "# rendered by brtf render gonio: material {}, beam {} sr, detector {} sr, {} rays per direction, seed {}",
                loaded.name, source_omega, detector_omega, setup.samples, setup.seed
            ));
            brtf_gonio::write_path(&m, path, out_format)
                .with_context(|| format!("cannot write {}", path.display()))?;
        }
        None => {
            let stdout = std::io::stdout();
            let mut out = BufWriter::new(stdout.lock());
            writeln!(out, "theta_out,phi_out,r,g,b,r_err,g_err,b_err")?;
            for (&(t, p), v) in directions.iter().zip(&values) {
                let [r, g, b] = v.bsdf;
                let [er, eg, eb] = v.std_err;
                writeln!(out, "{t},{p},{r},{g},{b},{er},{eg},{eb}")?;
            }
            out.flush()?;
        }
    }
    Ok(())
}

/// θ_out from 0 to 85° (and 95..180° with `back`) in `dt` steps, φ_out in `dp` steps.
fn grid(dt: f64, dp: f64, back: bool) -> Result<Vec<(f64, f64)>> {
    anyhow::ensure!(
        dt > 0.0 && dp > 0.0 && dt.is_finite() && dp.is_finite(),
        "grid steps must be positive"
    );
    let mut dirs = Vec::new();
    let n_theta = (85.0 / dt).floor() as usize;
    let n_phi = ((360.0 / dp).round() as usize).max(1);
    for i in 0..=n_theta {
        let t = i as f64 * dt;
        for j in 0..n_phi {
            let p = j as f64 * 360.0 / n_phi as f64;
            dirs.push((t, p));
            if back {
                dirs.push((180.0 - t, p));
            }
            if i == 0 {
                break;
            }
        }
    }
    Ok(dirs)
}

/// Runs `f` on a rayon pool of `jobs` threads (or the global pool).
pub fn with_jobs<T: Send>(jobs: Option<usize>, f: impl FnOnce() -> T + Send) -> Result<T> {
    match jobs {
        Some(n) => {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n.max(1))
                .build()
                .context("cannot start worker threads")?;
            Ok(pool.install(f))
        }
        None => Ok(f()),
    }
}

// ---------------------------------------------------------------------------
// brtf render image
// ---------------------------------------------------------------------------

#[derive(Args, Debug)]
pub struct ImageArgs {
    #[command(flatten)]
    pub sample: SampleMaterial,
    /// Output prefix: writes PREFIX.hdr (Radiance RGBE) and PREFIX.png.
    #[arg(long, value_name = "PREFIX")]
    pub out: PathBuf,
    /// Width in pixels.
    #[arg(long, default_value_t = 480)]
    pub width: usize,
    /// Height in pixels.
    #[arg(long, default_value_t = 360)]
    pub height: usize,
    /// Camera rays per pixel.
    #[arg(long, default_value_t = 16)]
    pub samples: u32,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// What to show.
    #[arg(long, value_enum, default_value_t = SceneArg::SpherePlane)]
    pub scene: SceneArg,
    /// The light source.
    #[arg(long, value_enum, default_value_t = LightArg::Distant)]
    pub light: LightArg,
    /// Polar angle of the light (from the zenith), degrees.
    #[arg(long, default_value_t = 40.0)]
    pub light_theta: f64,
    /// Azimuth of the light, degrees.
    #[arg(long, default_value_t = 210.0, allow_hyphen_values = true)]
    pub light_phi: f64,
    /// Full apex angle of the distant source, degrees (the sun: 0.53).
    #[arg(long, default_value_t = 0.53)]
    pub light_apex: f64,
    /// Sphere light: distance of its centre from the origin.
    #[arg(long, default_value_t = 6.0)]
    pub lamp_distance: f64,
    /// Sphere light: radius.
    #[arg(long, default_value_t = 0.5)]
    pub lamp_radius: f64,
    /// Irradiance the source gives at the origin, normal to it (W/m²).
    #[arg(long, default_value_t = 1.0)]
    pub irradiance: f64,
    /// Radiance of the constant background ("sky"), as a fraction of irradiance/π.
    #[arg(long, default_value_t = 0.05)]
    pub background: f64,
    /// Camera polar angle from the zenith, degrees.
    #[arg(long, default_value_t = 65.0)]
    pub view_theta: f64,
    /// Camera azimuth, degrees.
    #[arg(long, default_value_t = 300.0, allow_hyphen_values = true)]
    pub view_phi: f64,
    /// Camera distance from the sphere.
    #[arg(long, default_value_t = 8.0)]
    pub view_distance: f64,
    /// Horizontal field of view, degrees.
    #[arg(long, default_value_t = 35.0)]
    pub fov: f64,
    /// Shadow rays per source at each camera hit.
    #[arg(long, default_value_t = 1)]
    pub source_samples: u32,
    /// Specular rays per lobe at each camera hit (0: none).
    #[arg(long, default_value_t = 1)]
    pub specular_samples: u32,
    /// One-bounce diffuse rays at each camera hit (0: off).
    #[arg(long, default_value_t = 0)]
    pub diffuse_samples: u32,
    /// Longest chain of specular reflections.
    #[arg(long, default_value_t = 4)]
    pub max_depth: u32,
    /// Direct light only: no specular or diffuse rays, no background (as
    /// `rpict -ab 0 -av 0 0 0 -st 1`).
    #[arg(long)]
    pub direct_only: bool,
    /// Rays through pixel centres (as `rpict -pj 0`) instead of jittered.
    #[arg(long)]
    pub no_jitter: bool,
    /// PNG exposure multiplier [default: automatic].
    #[arg(long)]
    pub exposure: Option<f64>,
    /// Also write PREFIX.rad (scene) and PREFIX.vf (view) for rpict.
    #[arg(long)]
    pub radiance: bool,
    /// Worker threads [default: all cores].
    #[arg(long)]
    pub jobs: Option<usize>,
}

#[derive(Clone, Copy, Debug, PartialEq, ValueEnum)]
pub enum SceneArg {
    /// A unit sphere standing on a disk of radius 6.
    SpherePlane,
    /// The disk only.
    Plane,
    /// The sphere only.
    Sphere,
}

#[derive(Clone, Copy, Debug, PartialEq, ValueEnum)]
pub enum LightArg {
    /// A distant source (Radiance `source`).
    Distant,
    /// A spherical light (a `sphere` with a `light` material).
    Sphere,
}

/// Floor radius, sphere centre and radius of the picture scene.
const FLOOR_RADIUS: f64 = 6.0;
const BALL_CENTER: DVec3 = DVec3::new(0.0, 0.0, 1.0);
const BALL_RADIUS: f64 = 1.0;

fn run_image(args: ImageArgs) -> Result<()> {
    anyhow::ensure!(
        args.width > 0 && args.height > 0 && args.width * args.height <= 64_000_000,
        "image size must be between 1×1 and 64 Mpixel"
    );
    anyhow::ensure!(
        args.irradiance > 0.0 && args.irradiance.is_finite(),
        "--irradiance must be positive"
    );
    let loaded = args.sample.load()?;
    let light_dir = brtf_model::direction(args.light_theta, args.light_phi);
    let mut scene = Scene::new();
    let id = scene.add_shader(loaded.shader);
    if args.scene != SceneArg::Sphere {
        scene.add(
            Shape::Disk {
                center: DVec3::ZERO,
                normal: DVec3::Z,
                radius: FLOOR_RADIUS,
            },
            id,
        );
    }
    if args.scene != SceneArg::Plane {
        scene.add(
            Shape::Sphere {
                center: BALL_CENTER,
                radius: BALL_RADIUS,
            },
            id,
        );
    }
    let source_radiance;
    match args.light {
        LightArg::Distant => {
            let a = 0.5 * args.light_apex.to_radians();
            anyhow::ensure!(
                a > 0.0 && a < 1.5,
                "--light-apex must be in (0, 170) degrees"
            );
            // E = L π sin²a.
            source_radiance = args.irradiance / (std::f64::consts::PI * a.sin().powi(2));
            scene.sources.push(Source::distant(
                light_dir,
                args.light_apex,
                [source_radiance; 3],
            ));
        }
        LightArg::Sphere => {
            let (d, r) = (args.lamp_distance, args.lamp_radius);
            anyhow::ensure!(
                r > 0.0 && d > r + BALL_RADIUS + 1.0,
                "the lamp must clear the sphere"
            );
            source_radiance = args.irradiance / (std::f64::consts::PI * (r / d).powi(2));
            scene.sources.push(Source::Sphere {
                center: light_dir * d,
                radius: r,
                radiance: [source_radiance; 3],
            });
        }
    }
    let settings = if args.direct_only {
        Settings::direct_only()
    } else {
        scene.background = [args.background * args.irradiance / std::f64::consts::PI; 3];
        Settings {
            source_samples: args.source_samples.max(1),
            specular_samples: args.specular_samples,
            diffuse_samples: args.diffuse_samples,
            max_depth: args.max_depth,
        }
    };
    let target = match args.scene {
        SceneArg::Plane => DVec3::ZERO,
        _ => BALL_CENTER * 0.8,
    };
    let eye = target + brtf_model::direction(args.view_theta, args.view_phi) * args.view_distance;
    let camera = Camera::look_at(
        eye,
        target,
        args.fov,
        args.width as f64 / args.height as f64,
    );
    let options = ImageOptions {
        width: args.width,
        height: args.height,
        samples: args.samples.max(1),
        jitter: !args.no_jitter,
        seed: args.seed,
        settings,
    };
    let rendered = with_jobs(args.jobs, || brtf_trace::render(&scene, &camera, &options))?;
    let secs = rendered.elapsed.as_secs_f64();
    eprintln!(
        "brtf render image: {}×{} × {} samples, {:.2} M rays ({} camera, {} shadow, {} secondary) in {:.2} s ({:.2} M rays/s)",
        args.width,
        args.height,
        options.samples,
        rendered.rays.total() as f64 / 1e6,
        rendered.rays.primary,
        rendered.rays.shadow,
        rendered.rays.secondary,
        secs,
        rendered.rays.total() as f64 / 1e6 / secs.max(1e-9)
    );

    let view = camera.view_options();
    let with_ext = |ext: &str| {
        let mut p = args.out.clone().into_os_string();
        p.push(ext);
        PathBuf::from(p)
    };
    let mut hdr_bytes = Vec::new();
    hdr::write(
        &mut hdr_bytes,
        &rendered.picture,
        &[
            format!("SOFTWARE= brtf {} (brtf-trace)", env!("CARGO_PKG_VERSION")),
            format!("VIEW= {}", view.trim_start_matches("rview ")),
        ],
    )?;
    write_atomic(&with_ext(".hdr"), &hdr_bytes)?;
    let exposure = args
        .exposure
        .unwrap_or_else(|| auto_exposure(&rendered.picture));
    let mut png_bytes = Vec::new();
    write_png(&mut png_bytes, &rendered.picture, exposure)?;
    write_atomic(&with_ext(".png"), &png_bytes)?;
    if args.radiance {
        let rad = radiance_scene(
            &loaded.material,
            &args,
            light_dir,
            source_radiance,
            scene.background,
        );
        write_atomic(&with_ext(".rad"), rad.as_bytes())?;
        write_atomic(&with_ext(".vf"), format!("{view}\n").as_bytes())?;
        if scene.shaders[0].is_table() {
            eprintln!(
                "brtf render image: note: {}.rad holds the fit's static material; brtf-trace rendered its θ_in table",
                args.out.display()
            );
        }
    }
    Ok(())
}

/// The picture's scene as Radiance text (material `sample`).
fn radiance_scene(
    material: &Material,
    args: &ImageArgs,
    light_dir: DVec3,
    source_radiance: f64,
    background: [f64; 3],
) -> String {
    let prim = brtf_radiance::primitive_from_material(material, "sample");
    let mut s = format!(
        "# brtf render image --radiance: the scene brtf-trace rendered.\n\
         # rpict -vf {name}.vf -x {w} -y {h} -pa 0 -ab 0 -av 0 0 0 -st 1 -ps 1 -pj 0 {name}.oct\n\n{}\n",
        brtf_radiance::format_primitive(&prim),
        name = args
            .out
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default(),
        w = args.width,
        h = args.height,
    );
    if args.scene != SceneArg::Sphere {
        s += &format!("sample ring floor\n0\n0\n8 0 0 0  0 0 1  0 {FLOOR_RADIUS}\n\n");
    }
    if args.scene != SceneArg::Plane {
        s += &format!(
            "sample sphere ball\n0\n0\n4 {} {} {} {BALL_RADIUS}\n\n",
            BALL_CENTER.x, BALL_CENTER.y, BALL_CENTER.z
        );
    }
    let l = source_radiance;
    match args.light {
        LightArg::Distant => {
            s += &format!(
                "void light sunlight\n0\n0\n3 {l} {l} {l}\n\nsunlight source sun\n0\n0\n4 {} {} {} {}\n\n",
                light_dir.x, light_dir.y, light_dir.z, args.light_apex
            );
        }
        LightArg::Sphere => {
            let c = light_dir * args.lamp_distance;
            s += &format!(
                "void light lamplight\n0\n0\n3 {l} {l} {l}\n\nlamplight sphere lamp\n0\n0\n4 {} {} {} {}\n\n",
                c.x, c.y, c.z, args.lamp_radius
            );
        }
    }
    if background.iter().any(|&b| b > 0.0) {
        let b = background[0];
        s += &format!(
            "# The constant background (seen by specular and ambient rays only).\n\
             void glow skyglow\n0\n0\n4 {b} {b} {b} 0\n\nskyglow source sky\n0\n0\n4 0 0 1 360\n"
        );
    }
    s
}
