//! `brtf render image`: the material on a sphere and a plane, as HDR + PNG.

use super::SampleMaterial;
use crate::cmd::output::write_atomic;
use crate::cmd::shared::{with_jobs, words};
use anyhow::Result;
use brtf_trace::MATERIAL_NAME;
use brtf_trace::{LightKind, LightSpec, SceneKind, SceneSpec, Settings, ViewSpec, hdr};
use brtf_trace::{auto_exposure, write_png};
use clap::Args;
use std::path::PathBuf;

/// The defaults (shown by `--help`) are [`SceneSpec::DEFAULT`]'s.
const D: SceneSpec = SceneSpec::DEFAULT;

#[derive(Args, Debug)]
pub(crate) struct ImageArgs {
    #[command(flatten)]
    pub sample: SampleMaterial,
    /// Output prefix: writes PREFIX.hdr (Radiance RGBE) and PREFIX.png
    /// (a trailing .hdr or .png on PREFIX is dropped).
    #[arg(long, value_name = "PREFIX")]
    pub out: PathBuf,
    /// Width in pixels.
    #[arg(long, default_value_t = D.view.width)]
    pub width: usize,
    /// Height in pixels.
    #[arg(long, default_value_t = D.view.height)]
    pub height: usize,
    /// Camera rays per pixel.
    #[arg(long, default_value_t = 16)]
    pub samples: u32,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// What to show: sphere-plane (a unit sphere on a disk of radius 6), plane or sphere.
    #[arg(long, value_parser = words::<SceneKind>(), default_value_t = SceneKind::SpherePlane)]
    pub scene: SceneKind,
    /// The light source: distant (a Radiance `source`) or sphere (a lamp).
    #[arg(long, value_parser = words::<LightKind>(), default_value_t = LightKind::Distant)]
    pub light: LightKind,
    /// Polar angle of the light (from the zenith), degrees.
    #[arg(long, default_value_t = D.light.theta)]
    pub light_theta: f64,
    /// Azimuth of the light, degrees.
    #[arg(long, default_value_t = D.light.phi, allow_hyphen_values = true)]
    pub light_phi: f64,
    /// Full apex angle of the distant source, degrees (the sun: 0.53).
    #[arg(long, default_value_t = D.light.apex)]
    pub light_apex: f64,
    /// Sphere light: distance of its centre from the origin.
    #[arg(long, default_value_t = D.light.lamp_distance)]
    pub lamp_distance: f64,
    /// Sphere light: radius.
    #[arg(long, default_value_t = D.light.lamp_radius)]
    pub lamp_radius: f64,
    /// Irradiance the source gives at the origin, normal to it (W/m²).
    #[arg(long, default_value_t = D.light.irradiance)]
    pub irradiance: f64,
    /// Radiance of the constant background ("sky"), as a fraction of irradiance/π.
    #[arg(long, default_value_t = D.light.background)]
    pub background: f64,
    /// Camera polar angle from the zenith, degrees.
    #[arg(long, default_value_t = D.view.theta)]
    pub view_theta: f64,
    /// Camera azimuth, degrees.
    #[arg(long, default_value_t = D.view.phi, allow_hyphen_values = true)]
    pub view_phi: f64,
    /// Camera distance from the sphere.
    #[arg(long, default_value_t = D.view.distance)]
    pub view_distance: f64,
    /// Horizontal field of view, degrees.
    #[arg(long, default_value_t = D.view.fov)]
    pub fov: f64,
    /// Shadow rays per source at each camera hit.
    #[arg(long, default_value_t = D.settings.source_samples)]
    pub source_samples: u32,
    /// Specular rays per lobe at each camera hit (0: none).
    #[arg(long, default_value_t = D.settings.specular_samples)]
    pub specular_samples: u32,
    /// One-bounce diffuse rays at each camera hit (0: off).
    #[arg(long, default_value_t = D.settings.diffuse_samples)]
    pub diffuse_samples: u32,
    /// Longest chain of specular reflections.
    #[arg(long, default_value_t = D.settings.max_depth)]
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

impl ImageArgs {
    /// The picture scene these options describe.
    fn spec(&self) -> SceneSpec {
        SceneSpec {
            scene: self.scene,
            light: LightSpec {
                kind: self.light,
                theta: self.light_theta,
                phi: self.light_phi,
                apex: self.light_apex,
                lamp_distance: self.lamp_distance,
                lamp_radius: self.lamp_radius,
                irradiance: self.irradiance,
                background: self.background,
            },
            view: ViewSpec {
                theta: self.view_theta,
                phi: self.view_phi,
                distance: self.view_distance,
                fov: self.fov,
                width: self.width,
                height: self.height,
            },
            settings: Settings {
                source_samples: self.source_samples,
                specular_samples: self.specular_samples,
                diffuse_samples: self.diffuse_samples,
                max_depth: self.max_depth,
            },
            direct_only: self.direct_only,
        }
    }

    /// `PREFIX` + `ext`. A prefix given with one of the outputs'
    /// extensions (`--out img.hdr`) loses it, so it does not write
    /// `img.hdr.hdr`.
    fn with_ext(&self, ext: &str) -> PathBuf {
        let prefix = match self.out.extension().and_then(|e| e.to_str()) {
            Some("hdr" | "png") => self.out.with_extension(""),
            _ => self.out.clone(),
        };
        let mut p = prefix.into_os_string();
        p.push(ext);
        PathBuf::from(p)
    }
}

pub(crate) fn run(args: ImageArgs) -> Result<()> {
    let spec = args.spec();
    spec.validate()?;
    let samples = f64::from(args.samples);
    let check = brtf_model::OptionError::check;
    check(
        "--samples",
        samples,
        (1.0..=65536.0).contains(&samples),
        "1 to 65536",
    )?;
    if let Some(e) = args.exposure {
        check(
            "--exposure",
            e,
            e.is_finite() && e > 0.0,
            "a number above 0",
        )?;
    }
    for ext in [".hdr", ".png", ".rad", ".vf"] {
        let inputs: Vec<&std::path::Path> =
            args.sample.material.iter().map(|m| m.as_path()).collect();
        brtf_io::check_overwrite(&args.with_ext(ext), &inputs, None, false)?;
    }
    let loaded = args.sample.load()?;
    let is_table = loaded.shader.is_table();
    let (scene, camera) = spec.build(loaded.shader)?;
    let options = spec.image_options(args.samples, !args.no_jitter, args.seed);
    let rendered = with_jobs(args.jobs, || brtf_trace::render(&scene, &camera, &options))?;
    let secs = rendered.elapsed.as_secs_f64();
    say!(
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
    let mut hdr_bytes = Vec::new();
    hdr::write(
        &mut hdr_bytes,
        &rendered.picture,
        &[
            format!("SOFTWARE= brtf {} (brtf-trace)", env!("CARGO_PKG_VERSION")),
            format!("VIEW= {}", view.trim_start_matches("rview ")),
        ],
    )?;
    write_atomic(&args.with_ext(".hdr"), &hdr_bytes)?;
    let exposure = args
        .exposure
        .unwrap_or_else(|| auto_exposure(&rendered.picture));
    let mut png_bytes = Vec::new();
    write_png(&mut png_bytes, &rendered.picture, exposure)?;
    write_atomic(&args.with_ext(".png"), &png_bytes)?;
    if args.radiance {
        let prim = brtf_radiance::primitive_from_material(&loaded.material, MATERIAL_NAME);
        let name = args
            .out
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let rad = spec.radiance_text(&brtf_radiance::format_primitive(&prim), &name);
        write_atomic(&args.with_ext(".rad"), rad.as_bytes())?;
        write_atomic(&args.with_ext(".vf"), format!("{view}\n").as_bytes())?;
        if is_table {
            say!(
                "brtf render image: note: {}.rad holds the fit's static material; brtf-trace rendered its θ_in table",
                args.out.display()
            );
        }
    }
    Ok(())
}
