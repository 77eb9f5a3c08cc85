//! Synthetic measurements with realistic instrument effects.
//!
//! This module owns `brtf synth`'s physics-free part of the instrument:
//! where the detector samples (a coarse hemisphere grid plus a dense patch
//! around the specular peak, as adaptive gonio-photometers do), averaging
//! over the source and detector apertures, noise (multiplicative plus a
//! floor), the blind spot around the incident beam, a holder-shadow gap,
//! and noise-only back rows for opaque samples. The ground truth is any
//! brtf-model material or lobe sum, or a GGX (Cook-Torrance) conductor that Radiance's
//! Gaussian lobe cannot fit exactly, for honest model-mismatch tests.
//! Everything is seeded and deterministic.

use crate::measurement::{
    Channels, Incidence, IncidenceOrigin, Measurement, Quantity, Sample, SourceFormat,
};
use crate::solid_angle::compute_solid_angles;
use brtf_model::{Bsdf, CompositeBsdf, Rng, direction};
use glam::DVec3;
use std::f64::consts::PI;

/// What the synthetic sample really is.
#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant)] // built once per file, never stored in bulk
pub enum GroundTruth {
    /// A brtf-model material, evaluated with its options.
    Model(Bsdf),
    /// A lobe sum (primitives mixed with constant weights, as a `mixfunc`
    /// tree renders), evaluated with its options.
    Lobes(CompositeBsdf),
    /// A GGX conductor: Trowbridge-Reitz microfacets, Schlick Fresnel,
    /// separable Smith shadowing, plus a Lambertian base.
    Ggx {
        /// Normal-incidence Fresnel reflectance per channel.
        f0: [f64; 3],
        /// GGX roughness α (the slope-distribution width).
        alpha: f64,
        /// Lambertian reflectance per channel.
        diffuse: [f64; 3],
    },
}

impl GroundTruth {
    /// A material file's ground truth: one primitive as itself, a lobe sum
    /// as the weighted sum of its lobes.
    pub fn material(bsdf: CompositeBsdf) -> GroundTruth {
        match bsdf.parts() {
            [(_, one)] => GroundTruth::Model(*one),
            _ => GroundTruth::Lobes(bsdf),
        }
    }

    /// The GGX ground truth of `--ggx R,G,B --ggx-alpha A --ggx-diffuse R,G,B`,
    /// checked: three numbers each, 0 < α ≤ 1.
    pub fn ggx(f0: &[f64], alpha: f64, diffuse: &[f64]) -> Result<GroundTruth, String> {
        let (Ok(f0), Ok(diffuse)) = (<[f64; 3]>::try_from(f0), <[f64; 3]>::try_from(diffuse))
        else {
            return Err("--ggx and --ggx-diffuse take three numbers r,g,b".into());
        };
        if !(alpha > 0.0 && alpha <= 1.0) {
            return Err("--ggx-alpha must be in (0, 1]".into());
        }
        Ok(GroundTruth::Ggx { f0, alpha, diffuse })
    }

    /// BSDF (1/sr, no cosine) for light `l` and view `v`.
    pub fn eval(&self, l: DVec3, v: DVec3) -> [f64; 3] {
        match self {
            GroundTruth::Model(bsdf) => bsdf.eval(l, v),
            GroundTruth::Lobes(bsdf) => bsdf.eval(l, v),
            GroundTruth::Ggx { f0, alpha, diffuse } => ggx(*f0, *alpha, *diffuse, l, v),
        }
    }

    /// The lobe's angular width in radians, to size the dense patch.
    pub fn lobe_width(&self) -> f64 {
        match self {
            GroundTruth::Model(bsdf) => 2.0 * widest_roughness(bsdf).max(0.005),
            // The widest lobe: the dense patch must cover it.
            GroundTruth::Lobes(bsdf) => {
                let alpha = bsdf
                    .parts()
                    .iter()
                    .map(|(_, b)| widest_roughness(b))
                    .fold(0.0, f64::max);
                2.0 * alpha.max(0.005)
            }
            GroundTruth::Ggx { alpha, .. } => 2.0 * alpha.max(0.005),
        }
    }

    /// True when the truth transmits light.
    pub fn transmits(&self) -> bool {
        match self {
            GroundTruth::Model(bsdf) => bsdf.kind().is_transmitting(),
            GroundTruth::Lobes(bsdf) => bsdf.is_transmitting(),
            GroundTruth::Ggx { .. } => false,
        }
    }
}

/// The larger roughness of one primitive (its only one, if isotropic).
fn widest_roughness(bsdf: &Bsdf) -> f64 {
    let a = bsdf.material().args();
    if bsdf.kind().is_anisotropic() {
        a[4].max(a[5])
    } else {
        a[4]
    }
}

fn ggx(f0: [f64; 3], alpha: f64, diffuse: [f64; 3], l: DVec3, v: DVec3) -> [f64; 3] {
    if l.z <= 0.0 || v.z <= 0.0 {
        return [0.0; 3];
    }
    let h = (l + v).normalize();
    let a2 = alpha * alpha;
    let cos_h = h.z;
    let tan2_h = (1.0 - cos_h * cos_h) / (cos_h * cos_h);
    let d = a2 / (PI * cos_h.powi(4) * (a2 + tan2_h).powi(2));
    let smith = |c: f64| {
        let tan2 = (1.0 - c * c) / (c * c);
        2.0 / (1.0 + (1.0 + a2 * tan2).sqrt())
    };
    let g = smith(l.z) * smith(v.z);
    let schlick = (1.0 - v.dot(h)).clamp(0.0, 1.0).powi(5);
    let mut f = [0.0; 3];
    for c in 0..3 {
        let fresnel = f0[c] + (1.0 - f0[c]) * schlick;
        f[c] = diffuse[c] / PI + fresnel * d * g / (4.0 * l.z * v.z);
    }
    f
}

/// The instrument's imperfections.
#[derive(Debug, Clone, PartialEq)]
pub struct Instrument {
    /// Full apex angle of the source (beam) cone, degrees.
    pub source_aperture_deg: f64,
    /// Full apex angle of the detector cone, degrees.
    pub detector_aperture_deg: f64,
    /// Relative (multiplicative) noise, 1σ.
    pub noise_relative: f64,
    /// Additive noise floor, 1σ, in 1/sr.
    pub noise_floor: f64,
    /// Half-angle of the blind spot around the incident beam, degrees.
    pub blind_spot_deg: f64,
    /// Remove a holder-shadow gap: near-grazing directions (θ > 80°)
    /// within ±10° of φ_in + 90°, where the sample holder's arm stands.
    pub holder_gap: bool,
    /// Darken the pgII holder's shadow 100×: φ_out − φ_in in 270 ± 45° at
    /// θ_out ≥ 73.5°, where the real pgII scans read far below their
    /// mirror azimuth ([`crate::PGII_HOLDER_BAND`]).
    pub holder_shadow: bool,
    /// Add noise-only rows on the back hemisphere of an opaque sample.
    pub back_rows: bool,
    /// Aperture-averaging rays per cone (per axis: n × n).
    pub aperture_rays: usize,
}

impl Default for Instrument {
    fn default() -> Self {
        Instrument {
            source_aperture_deg: 0.5,
            detector_aperture_deg: 0.75,
            noise_relative: 0.02,
            noise_floor: 1e-3,
            blind_spot_deg: 3.0,
            holder_gap: true,
            holder_shadow: false,
            back_rows: true,
            aperture_rays: 3,
        }
    }
}

/// Where the detector samples.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// Spacing of the coarse grid, degrees.
    pub coarse_step_deg: f64,
    /// Spacing of the dense patch around the peak, degrees.
    pub fine_step_deg: f64,
    /// Largest θ_out sampled, degrees.
    pub max_theta_deg: f64,
}

impl Default for Layout {
    fn default() -> Self {
        Layout {
            coarse_step_deg: 2.5,
            fine_step_deg: 0.5,
            max_theta_deg: 88.0,
        }
    }
}

/// Everything that defines one synthetic file.
#[derive(Debug, Clone)]
pub struct SynthSpec {
    /// The truth.
    pub truth: GroundTruth,
    /// Incident direction.
    pub incidence: Incidence,
    /// Instrument effects.
    pub instrument: Instrument,
    /// Sampling layout.
    pub layout: Layout,
    /// 1 (CIE-Y, the luminance) or 3 (CIE X, Y, Z) values per row, of
    /// the material's Radiance RGB.
    pub channels: Channels,
    /// Seed of the noise (the layout itself is deterministic).
    pub seed: u64,
    /// `#sample_name`.
    pub sample_name: String,
}

/// Unit vectors perpendicular to `d`.
fn frame(d: DVec3) -> (DVec3, DVec3) {
    let helper = if d.z.abs() < 0.9 { DVec3::Z } else { DVec3::X };
    let e1 = helper.cross(d).normalize();
    (e1, d.cross(e1))
}

/// Deterministic stratified directions filling a cone of full apex angle
/// `aperture_deg` around `d` (uniform in solid angle), n × n of them.
fn cone_directions(d: DVec3, aperture_deg: f64, n: usize) -> Vec<DVec3> {
    if aperture_deg <= 0.0 || n <= 1 {
        return vec![d];
    }
    let cos_max = (0.5 * aperture_deg.to_radians()).cos();
    let (e1, e2) = frame(d);
    let mut out = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            let u = (i as f64 + 0.5) / n as f64;
            // Offset rows so the pattern has no radial alignment.
            let w = (j as f64 + 0.5 + 0.5 * (i % 2) as f64) / n as f64;
            let cos_t = 1.0 - u * (1.0 - cos_max);
            let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
            let psi = 2.0 * PI * w;
            out.push((d * cos_t + (e1 * psi.cos() + e2 * psi.sin()) * sin_t).normalize());
        }
    }
    out
}

/// The sample directions (θ, φ in degrees) for `spec`: coarse rings over
/// the front hemisphere, a dense polar patch around the mirror direction,
/// and for transmitting truths the same mirrored to the back.
fn layout_directions(spec: &SynthSpec) -> Vec<(f64, f64)> {
    let layout = &spec.layout;
    let mut dirs = Vec::new();
    let mut ring = |theta: f64, step: f64, back: bool| {
        let n = ((360.0 * theta.to_radians().sin() / step).round() as usize).max(1);
        for k in 0..n {
            let phi = 360.0 * k as f64 / n as f64;
            dirs.push((if back { 180.0 - theta } else { theta }, phi));
        }
    };
    let rings = (layout.max_theta_deg / layout.coarse_step_deg).floor() as usize;
    let back = spec.truth.transmits();
    for i in 0..=rings {
        let theta = i as f64 * layout.coarse_step_deg;
        ring(theta, layout.coarse_step_deg, false);
        if back {
            ring(theta, layout.coarse_step_deg, true);
        }
    }
    // Dense patch: concentric rings around the peak out to 3 lobe widths.
    let mirror = spec.incidence.mirror_direction();
    let radius = (3.0 * spec.truth.lobe_width())
        .to_degrees()
        .clamp(2.0, 20.0);
    let (e1, e2) = frame(mirror);
    let steps = (radius / layout.fine_step_deg).ceil() as usize;
    for i in 1..=steps {
        let delta = (i as f64 * layout.fine_step_deg).to_radians();
        let n =
            ((2.0 * PI * delta.sin() / layout.fine_step_deg.to_radians()).round() as usize).max(6);
        for k in 0..n {
            let psi = 2.0 * PI * k as f64 / n as f64;
            let d = mirror * delta.cos() + (e1 * psi.cos() + e2 * psi.sin()) * delta.sin();
            for candidate in
                [d, DVec3::new(d.x, d.y, -d.z)]
                    .into_iter()
                    .take(if back { 2 } else { 1 })
            {
                let theta = candidate.z.clamp(-1.0, 1.0).acos().to_degrees();
                let front_theta = theta.min(180.0 - theta);
                if front_theta <= layout.max_theta_deg {
                    let phi = candidate
                        .y
                        .atan2(candidate.x)
                        .to_degrees()
                        .rem_euclid(360.0);
                    dirs.push((theta, if phi >= 360.0 { 0.0 } else { phi }));
                }
            }
        }
    }
    dirs.push((spec.incidence.mirror_theta(), spec.incidence.mirror_phi()));
    dirs
}

impl Incidence {
    fn mirror_theta(&self) -> f64 {
        self.theta_deg
    }

    fn mirror_phi(&self) -> f64 {
        (self.phi_deg + 180.0).rem_euclid(360.0)
    }
}

/// A synthetic measurement of `spec` (BSDF, with file-style solid angles).
pub fn synthesize(spec: &SynthSpec) -> Measurement {
    let mut rng = Rng::from_state(spec.seed ^ 0xB5F0_2A11_u64);
    let instrument = &spec.instrument;
    let light = spec.incidence.direction();
    let lights = cone_directions(
        light,
        instrument.source_aperture_deg,
        instrument.aperture_rays,
    );
    let blind_cos = instrument.blind_spot_deg.to_radians().cos();
    let gap_phi = (spec.incidence.phi_deg + 90.0).rem_euclid(360.0);
    let mut samples = Vec::new();
    for (theta, phi) in layout_directions(spec) {
        let v = direction(theta, phi);
        if instrument.blind_spot_deg > 0.0 && v.dot(light) > blind_cos {
            continue;
        }
        let front_theta = theta.min(180.0 - theta);
        let dphi = ((phi - gap_phi + 540.0).rem_euclid(360.0) - 180.0).abs();
        if instrument.holder_gap && front_theta > 80.0 && dphi < 10.0 {
            continue;
        }
        let views = cone_directions(
            v,
            instrument.detector_aperture_deg,
            instrument.aperture_rays,
        );
        let mut mean = [0.0; 3];
        for l in &lights {
            for d in &views {
                let f = spec.truth.eval(*l, *d);
                for c in 0..3 {
                    mean[c] += f[c];
                }
            }
        }
        let n = (lights.len() * views.len()) as f64;
        let noisy = |value: f64, rng: &mut Rng| {
            value * (1.0 + instrument.noise_relative * rng.normal())
                + instrument.noise_floor * rng.normal()
        };
        // The file holds what its colorimetry header says: CIE Y, or CIE
        // XYZ, of the material's Radiance RGB.
        let relative = (phi - spec.incidence.phi_deg - 270.0 + 540.0).rem_euclid(360.0) - 180.0;
        let shadowed = instrument.holder_shadow && front_theta >= 73.5 && relative.abs() <= 45.0;
        let rgb = mean.map(|m| m / n * if shadowed { 0.01 } else { 1.0 });
        let values = match spec.channels {
            Channels::Y => [noisy(brtf_model::luminance(rgb), &mut rng), 0.0, 0.0],
            Channels::Xyz => {
                let k = 1.0 + instrument.noise_relative * rng.normal();
                let floor = [rng.normal(), rng.normal(), rng.normal()];
                let xyz = brtf_model::rgb_to_xyz(rgb);
                [0, 1, 2].map(|c| xyz[c] * k + instrument.noise_floor * floor[c])
            }
        };
        samples.push(Sample::new(theta, phi, values));
    }
    if instrument.back_rows && !spec.truth.transmits() {
        // Opaque sample: the back detector sees only its own noise.
        let step = 2.0 * spec.layout.coarse_step_deg;
        let rings = (spec.layout.max_theta_deg / step).floor() as usize;
        for i in 0..=rings {
            let theta = 180.0 - i as f64 * step;
            let count =
                ((360.0 * (i as f64 * step).to_radians().sin() / step).round() as usize).max(1);
            for k in 0..count {
                let phi = 360.0 * k as f64 / count as f64;
                let noise = |rng: &mut Rng| instrument.noise_floor * rng.normal();
                let values = match spec.channels {
                    Channels::Y => [noise(&mut rng), 0.0, 0.0],
                    Channels::Xyz => [noise(&mut rng), noise(&mut rng), noise(&mut rng)],
                };
                samples.push(Sample::new(theta, phi, values));
            }
        }
    }
    let weights = compute_solid_angles(&samples);
    for (s, w) in samples.iter_mut().zip(weights) {
        s.solid_angle_sr = Some(w);
    }
    let mut m = Measurement::new(
        SourceFormat::Mpc,
        spec.incidence,
        Quantity::Bsdf,
        spec.channels,
        samples,
    );
    m.incidence_origin = IncidenceOrigin::Programmatic;
    m.sample_name = Some(spec.sample_name.clone());
    m
}

/// The header line that marks files brtf synth wrote (which it may
/// replace without `--force`).
pub const SYNTH_MARKER: &str = "synth (synthetic data, not a measurement)";

/// A set of synthetic files, one per incidence, as `brtf synth` writes
/// them: `<prefix>:<+θ><+φ>.mpc` (or `.txt` for Mountain).
#[derive(Clone, Debug)]
pub struct SynthSet {
    /// The ground truth.
    pub truth: GroundTruth,
    /// Incidences θ_in, degrees, one file each.
    pub theta_in: Vec<f64>,
    /// Incidence azimuth φ_in, degrees.
    pub phi_in: f64,
    /// Instrument effects.
    pub instrument: Instrument,
    /// Sampling layout.
    pub layout: Layout,
    /// CIE Y or CIE XYZ.
    pub channels: Channels,
    /// `.mpc` or Mountain.
    pub format: SourceFormat,
    /// Noise seed of the first file (each file adds its index).
    pub seed: u64,
    /// File-name prefix and sample name.
    pub prefix: String,
    /// Header lines of every file (after the marker line).
    pub header: Vec<String>,
}

impl SynthSet {
    /// Checks the set before anything is made: the options' ranges, one
    /// line of prefix without path separators, three channels only in
    /// Mountain files.
    pub fn validate(&self) -> Result<(), brtf_model::OptionError> {
        use brtf_model::OptionError;
        self.instrument.validate()?;
        self.layout.validate()?;
        OptionError::check("--phi-in", self.phi_in, self.phi_in.is_finite(), "finite")?;
        for &theta in &self.theta_in {
            let ok = (0.0..90.0).contains(&theta);
            OptionError::check("--theta-in", theta, ok, "0 ≤ θ_in < 90 degrees")?;
        }
        let p = &self.prefix;
        if p.is_empty() || p.contains(['/', '\\']) || p.contains(char::is_control) {
            return Err(OptionError {
                option: "--prefix",
                value: format!("{p:?}"),
                allowed: "one line without / or \\ (it names files and the sample)",
            });
        }
        if self.format == SourceFormat::KlemsXml {
            return Err(OptionError {
                option: "--format",
                value: self.format.to_string(),
                allowed: "mpc or mountain",
            });
        }
        if self.format == SourceFormat::Mpc && self.channels == Channels::Xyz {
            return Err(OptionError {
                option: "--channels",
                value: "3".into(),
                allowed: "1 for .mpc files, which hold one value per row (3 needs --format mountain)",
            });
        }
        Ok(())
    }

    /// The file name of incidence `theta`.
    pub fn file_name(&self, theta: f64) -> String {
        let ext = match self.format {
            SourceFormat::Mpc => "mpc",
            SourceFormat::Mountain => "txt",
            SourceFormat::KlemsXml => "xml",
        };
        format!("{}:{theta:+}{:+}.{ext}", self.prefix, self.phi_in)
    }

    /// The text of file `index` (of `theta_in[index]`) and its sample count.
    pub fn file_text(&self, index: usize) -> Result<(String, usize), String> {
        let spec = SynthSpec {
            truth: self.truth.clone(),
            incidence: Incidence::new(self.theta_in[index], self.phi_in),
            instrument: self.instrument.clone(),
            layout: self.layout.clone(),
            channels: self.channels,
            seed: self.seed.wrapping_add(index as u64),
            sample_name: self.prefix.clone(),
        };
        let mut m = synthesize(&spec);
        m.format = self.format;
        m.header = vec![format!(
            "#generated by brtf {} {SYNTH_MARKER}",
            env!("CARGO_PKG_VERSION")
        )];
        // The apertures the values were averaged over, as `.mpc` states them.
        let apertures = crate::Apertures {
            source_deg: Some(self.instrument.source_aperture_deg),
            detector_deg: Some(self.instrument.detector_aperture_deg),
        };
        m.header.extend(apertures.header_lines());
        // One header line each, whatever they hold.
        m.header
            .extend(self.header.iter().map(|h| h.replace(char::is_control, " ")));
        let text = match self.format {
            SourceFormat::Mpc => crate::to_mpc_string(&m)?,
            SourceFormat::Mountain => crate::to_mountain_string(&m),
            SourceFormat::KlemsXml => {
                return Err("brtf synth writes .mpc or Mountain files, not Klems XML".into());
            }
        };
        Ok((text, m.samples.len()))
    }
}
