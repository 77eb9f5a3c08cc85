//! `brtf render image`: the material on a sphere and a plane, as HDR + PNG.

use super::SampleMaterial;
use crate::cmd::shared::{with_jobs, words};
use anyhow::Result;
use brtf_trace::{LightKind, LightSpec, SceneKind, SceneSpec, Settings, ViewSpec};
use brtf_workflow::{ImageRequest, render_image};
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
    /// Also write PREFIX.rad (scene, with the static material: a lobe sum
    /// as its primitives and mixfunc tree) and PREFIX.vf (view) for rpict.
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
}

pub(crate) fn run(args: ImageArgs) -> Result<()> {
    let spec = args.spec();
    let request = ImageRequest {
        samples: args.samples,
        jitter: !args.no_jitter,
        seed: args.seed,
        exposure: args.exposure,
        radiance: args.radiance,
    };
    request.validate(&spec)?;
    let material = args.sample.load()?;
    let file = args.sample.material.as_deref();
    let run = with_jobs(args.jobs, || {
        render_image(material, &spec, &request, &args.out, file)
    })??;
    let secs = run.elapsed.as_secs_f64();
    let rays = run.rays.total() as f64 / 1e6;
    say!(
        "brtf render image: {}×{} × {} samples, {rays:.2} M rays ({} camera, {} shadow, {} secondary) in {secs:.2} s ({:.2} M rays/s)",
        run.size[0],
        run.size[1],
        run.samples,
        run.rays.primary,
        run.rays.shadow,
        run.rays.secondary,
        rays / secs.max(1e-9)
    );
    for note in &run.notes {
        say!("brtf render image: note: {note}");
    }
    Ok(())
}
