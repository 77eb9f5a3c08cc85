//! The virtual gonio-photometer: a measurement's geometry, rendered.
//!
//! The sample is a flat disk (normal +z, the measurement's local frame).
//! The beam is a distant source at (θ_in, φ_in) of solid angle `ω_s`
//! (a cone), and the detector sits at each (θ_out, φ_out) with an aperture
//! of solid angle `ω_d` (a cone of directions). A detector reading is the
//! mean radiance over its aperture, `⟨L_r⟩`; the rendered BSDF is that
//! divided by the beam's irradiance on the sample,
//! `E = L ∫_{Ω_s} |cos θ_l| dω = L π sin²a_s |cos θ_in|`:
//!
//! `f_rendered(v) = (1/ω_d) ∫_{Ω_d} ∫_{Ω_s} f(l, v′) |cos θ_l| dω_l dω_v′ / ∫_{Ω_s} |cos θ_l| dω_l`.
//!
//! Each detector direction gets `samples` camera rays, each jittered over
//! the aperture and lit by one source sample through the full integrator
//! (so roughness-0 mirror and through rays find the beam as well). The
//! spread of the per-ray estimates gives a standard error. As the
//! apertures shrink, `f_rendered → f(l, v)`; [`cone_average`] computes the
//! same double integral by quadrature, for tests.

use brtf_gonio::{Channels, Incidence, Measurement, Quantity, Sample, SourceFormat};
use brtf_model::Rgb;
use glam::DVec3;
use rayon::prelude::*;

use crate::integrator::{RayCounts, Settings, Tracer};
use crate::sampling::{cone_half_angle, uniform_cone};
use crate::scene::{Ray, Scene, Shape, Source};
use crate::shader::Shader;
use brtf_model::Rng;

/// The smallest source solid angle used (a "point" source), sr.
pub(crate) const MIN_SOURCE_OMEGA: f64 = 1e-10;

/// A gonio-photometer's geometry and the sampling effort.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GonioSetup {
    /// Incident polar angle θ_in, degrees (towards the light).
    pub theta_in: f64,
    /// Incident azimuth φ_in, degrees.
    pub phi_in: f64,
    /// Solid angle of the beam (source), sr; 0 means a point.
    pub source_omega: f64,
    /// Solid angle of the detector aperture, sr; 0 means a point.
    pub detector_omega: f64,
    /// Camera rays per detector direction.
    pub samples: u32,
    /// Random seed.
    pub seed: u64,
}

impl GonioSetup {
    /// A point source and detector with 64 samples per direction.
    pub fn new(theta_in: f64, phi_in: f64) -> GonioSetup {
        GonioSetup {
            theta_in,
            phi_in,
            source_omega: 0.0,
            detector_omega: 0.0,
            samples: 64,
            seed: 1,
        }
    }

    /// Unit vector towards the light.
    pub fn light(&self) -> DVec3 {
        brtf_model::direction(self.theta_in, self.phi_in)
    }

    /// Checks the incidence (θ_in in [0, 180]°, φ_in finite) and the
    /// apertures (finite, ≥ 0 sr).
    pub fn validate(&self) -> Result<(), GonioError> {
        if !(self.theta_in.is_finite()
            && (0.0..=180.0).contains(&self.theta_in)
            && self.phi_in.is_finite())
        {
            return Err(GonioError::Incidence {
                theta_in: self.theta_in,
                phi_in: self.phi_in,
            });
        }
        for (aperture, omega) in [
            (Aperture::Source, self.source_omega),
            (Aperture::Detector, self.detector_omega),
        ] {
            if !(omega.is_finite() && omega >= 0.0) {
                return Err(GonioError::Omega(aperture));
            }
        }
        Ok(())
    }
}

/// The two apertures of the instrument.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Aperture {
    /// The beam.
    Source,
    /// The detector.
    Detector,
}

impl std::fmt::Display for Aperture {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Aperture::Source => "source",
            Aperture::Detector => "detector",
        })
    }
}

/// A gonio-photometer number that cannot make a measurement. The
/// messages name the `brtf render gonio` options the numbers come from.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GonioError {
    #[error("θ_in must be between 0 and 180 degrees")]
    Incidence { theta_in: f64, phi_in: f64 },
    #[error("give the {0} as --{0}-omega or --{0}-apex, not both")]
    OmegaAndApex(Aperture),
    #[error("--{0}-omega must be ≥ 0 sr")]
    Omega(Aperture),
    #[error("--{0}-apex must be between 0 and 180 degrees")]
    Apex(Aperture),
    #[error("grid steps must be positive")]
    GridStep { theta_step: f64, phi_step: f64 },
    #[error("grid steps too small: {directions} directions (at most {MAX_GRID_DIRECTIONS})")]
    GridSize { directions: f64 },
}

/// An aperture's solid angle in sr, given either as a solid angle `omega`
/// (sr) or as a full cone apex angle `apex` (degrees), or neither (`None`).
pub fn aperture_solid_angle(
    aperture: Aperture,
    omega: Option<f64>,
    apex: Option<f64>,
) -> Result<Option<f64>, GonioError> {
    match (omega, apex) {
        (Some(_), Some(_)) => Err(GonioError::OmegaAndApex(aperture)),
        (Some(w), None) if w.is_finite() && w >= 0.0 => Ok(Some(w)),
        (Some(_), None) => Err(GonioError::Omega(aperture)),
        (None, Some(a)) if a.is_finite() && (0.0..=180.0).contains(&a) => {
            Ok(Some(brtf_model::cone_solid_angle(a)))
        }
        (None, Some(_)) => Err(GonioError::Apex(aperture)),
        (None, None) => Ok(None),
    }
}

/// The most directions [`grid`] returns.
pub(crate) const MAX_GRID_DIRECTIONS: usize = 10_000_000;

/// A direction grid (θ_out, φ_out in degrees): θ_out from 0 to 85° (and
/// 180 − θ_out, the back hemisphere, with `back`) in `theta_step` steps,
/// φ_out over 360° in about `phi_step` steps (one φ_out at θ_out = 0).
pub fn grid(theta_step: f64, phi_step: f64, back: bool) -> Result<Vec<(f64, f64)>, GonioError> {
    let (dt, dp) = (theta_step, phi_step);
    if !(dt > 0.0 && dp > 0.0 && dt.is_finite() && dp.is_finite()) {
        return Err(GonioError::GridStep {
            theta_step,
            phi_step,
        });
    }
    let n_theta_f = (85.0 / dt).floor();
    let n_phi_f = (360.0 / dp).round().max(1.0);
    let directions = (n_theta_f * n_phi_f + 1.0) * if back { 2.0 } else { 1.0 };
    if directions > MAX_GRID_DIRECTIONS as f64 {
        return Err(GonioError::GridSize { directions });
    }
    let mut dirs = Vec::new();
    let n_theta = n_theta_f as usize;
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

/// One rendered reading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GonioValue {
    /// Rendered BSDF, 1/sr.
    pub bsdf: Rgb,
    /// Monte Carlo standard error of `bsdf`.
    pub std_err: Rgb,
}

/// A virtual gonio-photometer holding its scene.
#[derive(Debug, Clone)]
pub struct VirtualGonio {
    scene: Scene,
    setup: GonioSetup,
    detector_half_angle: f64,
    /// Beam irradiance on the sample for source radiance 1.
    irradiance: f64,
}

impl VirtualGonio {
    /// The instrument with `shader` as the sample.
    pub fn new(shader: Shader, setup: GonioSetup) -> VirtualGonio {
        let omega = setup.source_omega.max(MIN_SOURCE_OMEGA);
        let half = cone_half_angle(omega);
        let light = setup.light();
        let mut scene = Scene::new();
        let id = scene.add_shader(shader);
        scene.add(
            Shape::Disk {
                center: DVec3::ZERO,
                normal: DVec3::Z,
                radius: 1.0,
            },
            id,
        );
        scene.sources.push(Source::Distant {
            dir: light,
            half_angle: half,
            radiance: [1.0; 3],
        });
        let irradiance = cone_cosine_integral(light, half);
        VirtualGonio {
            scene,
            setup,
            detector_half_angle: cone_half_angle(setup.detector_omega.max(0.0)),
            irradiance,
        }
    }

    /// The setup.
    pub fn setup(&self) -> &GonioSetup {
        &self.setup
    }

    /// One detector reading towards `v` (unit, local frame). `stream`
    /// picks the random stream (use the direction's index).
    pub fn read(&self, v: DVec3, stream: u64, counts: &mut RayCounts) -> GonioValue {
        let settings = Settings {
            source_samples: 1,
            specular_samples: 0,
            diffuse_samples: 0,
            max_depth: 1,
        };
        let tracer = Tracer::new(&self.scene, settings);
        let mut rng = Rng::new(self.setup.seed, stream);
        let n = self.setup.samples.max(1);
        // Stratified: the detector and the source directions each take one
        // jittered cell of an m × m grid, paired at random.
        let detector_cells = stratified_cells(n as usize, &mut rng);
        let source_cells = stratified_cells(n as usize, &mut rng);
        let mut sum = [0.0; 3];
        let mut sum2 = [0.0; 3];
        for (ud, us) in detector_cells.into_iter().zip(source_cells) {
            let d = if self.detector_half_angle > 0.0 {
                uniform_cone(v, self.detector_half_angle, ud)
            } else {
                v
            };
            let ray = Ray {
                origin: d * 10.0,
                dir: -d,
            };
            let l = tracer.radiance_with(&ray, us, &mut rng, counts);
            for k in 0..3 {
                let x = l[k] / self.irradiance;
                sum[k] += x;
                sum2[k] += x * x;
            }
        }
        let nf = n as f64;
        let mean = sum.map(|s| s / nf);
        // The i.i.d. formula: an upper bound for stratified samples.
        let std_err = std::array::from_fn(|k| {
            if n < 2 {
                return 0.0;
            }
            let var = (sum2[k] - nf * mean[k] * mean[k]).max(0.0) / (nf - 1.0);
            (var / nf).sqrt()
        });
        GonioValue {
            bsdf: mean,
            std_err,
        }
    }

    /// Readings for every direction (in parallel), and the rays traced.
    pub fn render(&self, directions: &[DVec3]) -> (Vec<GonioValue>, RayCounts) {
        let results: Vec<(GonioValue, RayCounts)> = directions
            .par_iter()
            .enumerate()
            .map(|(i, &v)| {
                let mut counts = RayCounts::default();
                let value = self.read(v, i as u64, &mut counts);
                (value, counts)
            })
            .collect();
        let mut total = RayCounts::default();
        let values = results
            .into_iter()
            .map(|(v, c)| {
                total.add(&c);
                v
            })
            .collect();
        (values, total)
    }
}

/// `n` points in [0,1)², one in each of `n` distinct cells of the
/// smallest m × m grid with m² ≥ n (cells chosen at random when m² > n),
/// in random order. Each point is uniform over [0,1)², so estimates stay
/// unbiased, and the set covers the square evenly.
pub(crate) fn stratified_cells(n: usize, rng: &mut Rng) -> Vec<[f64; 2]> {
    let m = (n as f64).sqrt().ceil() as usize;
    let mut cells: Vec<usize> = (0..m * m).collect();
    // Fisher–Yates shuffle.
    for i in (1..cells.len()).rev() {
        let j = (rng.uniform() * (i + 1) as f64) as usize;
        cells.swap(i, j.min(i));
    }
    cells.truncate(n);
    cells
        .into_iter()
        .map(|c| {
            let (i, j) = (c % m, c / m);
            [
                (i as f64 + rng.uniform()) / m as f64,
                (j as f64 + rng.uniform()) / m as f64,
            ]
        })
        .collect()
}

/// Measurement slot values of a rendered RGB value: its luminance, or its
/// CIE XYZ (what the file's colorimetry header says the values are).
pub(crate) fn channel_values(c: Rgb, channels: Channels) -> [f64; 3] {
    match channels {
        Channels::Y => [brtf_model::luminance(c), 0.0, 0.0],
        Channels::Xyz => brtf_model::rgb_to_xyz(c),
    }
}

/// A measurement of `samples` directions (θ_out, φ_out in degrees) for
/// writing rendered values, in `format`.
pub fn measurement_from(
    setup: &GonioSetup,
    directions: &[(f64, f64)],
    values: &[GonioValue],
    channels: Channels,
    format: SourceFormat,
) -> Measurement {
    let samples = directions
        .iter()
        .zip(values)
        .map(|(&(t, p), v)| Sample::new(t, p, channel_values(v.bsdf, channels)))
        .collect();
    Measurement::new(
        format,
        Incidence::new(setup.theta_in, setup.phi_in),
        Quantity::Bsdf,
        channels,
        samples,
    )
}

/// `∫_cone max(0, ±cos θ) dω` over the cone of half-angle `a` around
/// `axis`, on the side of the surface the axis is on: `π sin²a |cos θ₀|`
/// when the cone does not cross the horizon, else by quadrature.
pub(crate) fn cone_cosine_integral(axis: DVec3, a: f64) -> f64 {
    let c0 = axis.z.abs();
    // The cone stays on one side when the axis is at least `a` from the horizon.
    if c0 >= a.sin() {
        let sa = a.sin();
        return std::f64::consts::PI * sa * sa * c0;
    }
    let side = axis.z.signum();
    let mut sum = 0.0;
    quadrature_cone(axis, a, 64, 128, |d, w| sum += w * (side * d.z).max(0.0));
    sum
}

/// Calls `f(direction, weight)` for the nodes of a product rule over the
/// cone of half-angle `a` around `axis` (Gauss–Legendre in the polar
/// angle, the trapezoid rule in azimuth); the weights sum to the cone's
/// solid angle.
pub(crate) fn quadrature_cone(
    axis: DVec3,
    a: f64,
    radial: usize,
    azimuthal: usize,
    mut f: impl FnMut(DVec3, f64),
) {
    if a <= 0.0 {
        f(axis, 1.0);
        return;
    }
    let frame = crate::frame::Frame::from_z(axis);
    for (x, w) in brtf_model::gauss_legendre_rule(radial) {
        let delta = 0.5 * a * (x + 1.0);
        let (sd, cd) = delta.sin_cos();
        let wr = 0.5 * a * w * sd;
        for k in 0..azimuthal {
            let phi = 2.0 * std::f64::consts::PI * (k as f64 + 0.5) / azimuthal as f64;
            let (sp, cp) = phi.sin_cos();
            let d = frame.to_world(DVec3::new(sd * cp, sd * sp, cd));
            f(d, wr * 2.0 * std::f64::consts::PI / azimuthal as f64);
        }
    }
}

/// What the virtual gonio-photometer converges to, by quadrature: the
/// BSDF averaged over the detector cone and, cosine-weighted, over the
/// source cone (see the module docs). Apertures are solid angles in sr.
pub fn cone_average(
    shader: &Shader,
    light: DVec3,
    source_omega: f64,
    view: DVec3,
    detector_omega: f64,
    nodes: (usize, usize),
) -> Rgb {
    let (radial, azimuthal) = nodes;
    let a_s = cone_half_angle(source_omega.max(0.0));
    let a_d = cone_half_angle(detector_omega.max(0.0));
    let n = DVec3::Z;
    let mut num = [0.0; 3];
    let mut den = 0.0;
    let mut wsum_v = 0.0;
    quadrature_cone(view, a_d, radial, azimuthal, |v, wv| {
        wsum_v += wv;
        // Turn the surface towards the viewer (as the tracer does).
        let (frame, degenerate) = shader.frame(if v.z >= 0.0 { n } else { -n });
        let vl = frame.to_local(v);
        let mut inner = [0.0; 3];
        let mut inner_den = 0.0;
        quadrature_cone(light, a_s, radial, azimuthal, |l, wl| {
            let ll = frame.to_local(l);
            let f = shader.eval(ll, vl, degenerate);
            let c = (l.z * light.z.signum()).max(0.0);
            for k in 0..3 {
                inner[k] += wl * c * f[k];
            }
            inner_den += wl * c;
        });
        for k in 0..3 {
            num[k] += wv * inner[k];
        }
        den = inner_den;
    });
    std::array::from_fn(|k| num[k] / (den * wsum_v))
}
