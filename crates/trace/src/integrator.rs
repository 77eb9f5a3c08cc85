//! Radiance along a ray, following Radiance's equation (1):
//!
//! `R = Σ_sources ∫_{Ω_i} f(q, v) L_i |q·n| dω  +  ∫ f_s(q, v) R(q) |q·n| dω  +  ∫ f_d(q, v) R(q) |q·n| dω`
//!
//! * **Direct term.** Each source is sampled uniformly over its solid angle
//!   `Ω_i` seen from the point (`pdf = 1/ω_i`), with the whole BSDF `f` and a
//!   shadow ray.
//! * **Specular rays.** The rough reflected and transmitted lobes are
//!   importance-sampled ([`crate::sampling`]; a lobe sum's lobes as a
//!   mixture) and weighted by the specular part `f_s = f − f_d`. Such
//!   rays ignore the sources (the direct term has them) and recurse up to
//!   [`Settings::max_depth`]. Roughness-0
//!   surfaces trace their mirror and straight-through rays instead, with
//!   the delta coefficients; those rays *do* see sources.
//! * **Diffuse bounce** (optional, [`Settings::diffuse_samples`] > 0):
//!   cosine-distributed rays weighted by `f_d`; the point they hit gets its
//!   direct term only (one bounce, like rtrace's `-ab 1`).
//!
//! Everything the tracer computes is counted in [`RayCounts`].

use brtf_model::Rgb;
use glam::DVec3;

use crate::sampling::cosine_hemisphere;
use crate::scene::{Hit, PreparedSource, RAY_EPSILON, Ray, Scene};
use brtf_model::Rng;

use crate::sampling::{LobeMix, ReflectionLobe, TransmissionLobe};

/// The rough specular lobes of one side to sample (a mixture for a lobe sum).
#[derive(Debug, Clone, Copy)]
enum SpecularLobe<'a> {
    Reflect(LobeMix<'a, ReflectionLobe>),
    Transmit(LobeMix<'a, TransmissionLobe>),
}

impl SpecularLobe<'_> {
    /// +1 for the front (reflection), −1 for the back.
    fn side(&self) -> f64 {
        match self {
            SpecularLobe::Reflect(_) => 1.0,
            SpecularLobe::Transmit(_) => -1.0,
        }
    }

    /// A direction and its density.
    #[inline]
    fn sample(&self, v: DVec3, u: [f64; 2]) -> (DVec3, f64) {
        match self {
            SpecularLobe::Reflect(lobes) => lobes.sample_with_pdf(v, u),
            SpecularLobe::Transmit(lobes) => lobes.sample_with_pdf(v, u),
        }
    }
}

/// Sample counts and depth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Shadow rays per source at a camera ray's hit (1 deeper down).
    pub source_samples: u32,
    /// Rays per rough specular lobe at a camera ray's hit (1 deeper down;
    /// 0 disables specular rays); a lobe sum's lobes of one side share
    /// them, each ray from the mixture.
    pub specular_samples: u32,
    /// One-bounce diffuse rays per diffuse part at a camera ray's hit (0: off).
    pub diffuse_samples: u32,
    /// Longest chain of specular (and delta) reflections.
    pub max_depth: u32,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            source_samples: 1,
            specular_samples: 1,
            diffuse_samples: 0,
            max_depth: 4,
        }
    }
}

impl Settings {
    /// Direct lighting only: no specular or diffuse rays (delta rays stay).
    pub fn direct_only() -> Settings {
        Settings {
            source_samples: 1,
            specular_samples: 0,
            diffuse_samples: 0,
            max_depth: 0,
        }
    }
}

/// Rays traced, by kind.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RayCounts {
    /// Camera (or detector) rays.
    pub primary: u64,
    /// Shadow rays of the direct term.
    pub shadow: u64,
    /// Specular, delta and diffuse rays.
    pub secondary: u64,
}

impl RayCounts {
    /// All rays.
    pub fn total(&self) -> u64 {
        self.primary + self.shadow + self.secondary
    }

    /// Adds another count.
    pub fn add(&mut self, other: &RayCounts) {
        self.primary += other.primary;
        self.shadow += other.shadow;
        self.secondary += other.secondary;
    }
}

/// Why a ray is traced: decides whether it sees sources.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    /// Camera or detector ray, or a roughness-0 delta ray: sees sources.
    Visible,
    /// Monte Carlo specular or diffuse ray: sources count 0 (already in
    /// the direct term).
    Sampled,
}

/// A ray tracer over one scene.
#[derive(Debug, Clone)]
pub struct Tracer<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// Sample counts.
    pub settings: Settings,
    /// The scene's sources with their per-source sampling constants
    /// worked out once (not per shadow ray).
    sources: Vec<PreparedSource>,
}

#[inline]
fn add_scaled(acc: &mut Rgb, w: Rgb, x: Rgb) {
    for k in 0..3 {
        acc[k] += w[k] * x[k];
    }
}

impl<'a> Tracer<'a> {
    /// A tracer for `scene`.
    pub fn new(scene: &'a Scene, settings: Settings) -> Tracer<'a> {
        Tracer {
            scene,
            settings,
            sources: scene.sources.iter().map(PreparedSource::new).collect(),
        }
    }

    /// Radiance arriving along a camera ray (towards `-ray.dir`).
    pub fn radiance(&self, ray: &Ray, rng: &mut Rng, counts: &mut RayCounts) -> Rgb {
        counts.primary += 1;
        self.trace(ray, Kind::Visible, 0, Some(None), true, rng, counts)
    }

    /// [`Self::radiance`] with the uniform numbers `source_u` for the first
    /// source sample at the first hit (for stratified sampling; with
    /// several sources or source samples the others draw from `rng`).
    pub fn radiance_with(
        &self,
        ray: &Ray,
        source_u: [f64; 2],
        rng: &mut Rng,
        counts: &mut RayCounts,
    ) -> Rgb {
        counts.primary += 1;
        self.trace(
            ray,
            Kind::Visible,
            0,
            Some(Some(source_u)),
            true,
            rng,
            counts,
        )
    }

    #[allow(clippy::too_many_arguments)]
    fn trace(
        &self,
        ray: &Ray,
        kind: Kind,
        depth: u32,
        first: Option<Option<[f64; 2]>>,
        diffuse_allowed: bool,
        rng: &mut Rng,
        counts: &mut RayCounts,
    ) -> Rgb {
        match self.scene.intersect(ray) {
            Hit::Light(radiance) => match kind {
                Kind::Visible => radiance,
                Kind::Sampled => [0.0; 3],
            },
            Hit::Escaped { source } => match (kind, source) {
                (Kind::Visible, Some(radiance)) => radiance,
                // A sampled ray that points into a distant source sees the
                // background behind it: the source itself is in the direct term.
                _ => self.scene.background,
            },
            Hit::Surface { t, object } => {
                let p = ray.origin + ray.dir * t;
                self.shade(
                    p,
                    object,
                    -ray.dir,
                    depth,
                    first,
                    diffuse_allowed,
                    rng,
                    counts,
                )
            }
        }
    }

    /// Outgoing radiance at `p` on `object` towards `v_world`. `first` is
    /// `Some` at a camera ray's hit, holding optional uniforms for its
    /// first source sample.
    #[allow(clippy::too_many_arguments)]
    fn shade(
        &self,
        p: DVec3,
        object: usize,
        v_world: DVec3,
        depth: u32,
        first: Option<Option<[f64; 2]>>,
        diffuse_allowed: bool,
        rng: &mut Rng,
        counts: &mut RayCounts,
    ) -> Rgb {
        let obj = &self.scene.objects[object];
        let shader = &self.scene.shaders[obj.shader];
        let mut n = obj.shape.normal_at(p);
        // Two-sided: turn the surface towards the viewer, as rtrace does.
        if n.dot(v_world) < 0.0 {
            n = -n;
        }
        let (frame, degenerate) = shader.frame(n);
        let v = frame.to_local(v_world);
        let v = DVec3::new(v.x, v.y, v.z.max(0.0));
        let mut out = [0.0; 3];
        let s = &self.settings;
        let mut given_u = first.flatten();
        let first = first.is_some();

        // Direct term: every source, sampled over its solid angle.
        let n_src = if first { s.source_samples.max(1) } else { 1 };
        for source in &self.sources {
            let mut sum = [0.0; 3];
            for _ in 0..n_src {
                let u = given_u.take().unwrap_or_else(|| rng.uniform2());
                let Some(sample) = source.sample(p, u) else {
                    continue;
                };
                let l = frame.to_local(sample.dir);
                let f = shader.eval(l, v, degenerate);
                if f == [0.0; 3] {
                    continue;
                }
                counts.shadow += 1;
                let side = if l.z >= 0.0 { n } else { -n };
                let shadow = Ray {
                    origin: p + side * RAY_EPSILON,
                    dir: sample.dir,
                };
                if self.scene.occluded(&shadow, sample.distance) {
                    continue;
                }
                let w = l.z.abs() * sample.omega;
                for k in 0..3 {
                    sum[k] += f[k] * w * sample.radiance[k];
                }
            }
            for k in 0..3 {
                out[k] += sum[k] / n_src as f64;
            }
        }

        // The lobes are only needed for delta, specular or diffuse rays
        // (not for direct light alone, the common case).
        let n_spec = if first {
            s.specular_samples
        } else {
            s.specular_samples.min(1)
        };
        let delta_rays = shader.has_delta() && depth < s.max_depth.max(1);
        let specular_rays = depth < s.max_depth && n_spec > 0;
        let diffuse_rays = diffuse_allowed && s.diffuse_samples > 0;
        if !(delta_rays || specular_rays || diffuse_rays) {
            return out;
        }
        let lobes = shader.lobes(v, degenerate);
        // Roughness 0: the mirror and straight-through rays.
        if let Some((mirror, through)) = lobes.delta
            && depth < s.max_depth.max(1)
        {
            for (coef, dir) in [(mirror, DVec3::new(-v.x, -v.y, v.z)), (through, -v)] {
                if coef.iter().all(|&c| c <= 0.0) {
                    continue;
                }
                let x = self.follow(
                    p,
                    n,
                    &frame,
                    dir,
                    Kind::Visible,
                    depth + 1,
                    diffuse_allowed,
                    rng,
                    counts,
                );
                add_scaled(&mut out, coef, x);
            }
        }

        // Rough specular lobes.
        if specular_rays {
            let reflect = lobes.reflect.map(SpecularLobe::Reflect);
            let transmit = lobes.transmit.map(SpecularLobe::Transmit);
            for lobe in [reflect, transmit].into_iter().flatten() {
                let side = lobe.side();
                let mut sum = [0.0; 3];
                for _ in 0..n_spec {
                    let (l, pdf) = lobe.sample(v, rng.uniform2());
                    if side * l.z <= 0.0 || pdf <= 0.0 {
                        continue;
                    }
                    let fs = shader.specular(l, v, degenerate);
                    if fs == [0.0; 3] {
                        continue;
                    }
                    let w = l.z.abs() / pdf;
                    let x = self.follow(
                        p,
                        n,
                        &frame,
                        l,
                        Kind::Sampled,
                        depth + 1,
                        diffuse_allowed,
                        rng,
                        counts,
                    );
                    for k in 0..3 {
                        sum[k] += fs[k] * w * x[k];
                    }
                }
                for k in 0..3 {
                    out[k] += sum[k] / n_spec as f64;
                }
            }
        }

        // One-bounce diffuse.
        if diffuse_rays {
            let n_diff = if first { s.diffuse_samples } else { 1 };
            for (present, side) in [(lobes.diffuse_reflect, 1.0), (lobes.diffuse_transmit, -1.0)] {
                if !present {
                    continue;
                }
                let mut sum = [0.0; 3];
                for _ in 0..n_diff {
                    let l = cosine_hemisphere(rng.uniform2(), side);
                    if l.z == 0.0 {
                        continue;
                    }
                    let fd = shader.diffuse(l, v);
                    if fd == [0.0; 3] {
                        continue;
                    }
                    // f_d |cos| / (|cos|/π) = π f_d. The hit gets its direct term only.
                    let x = self.follow(
                        p,
                        n,
                        &frame,
                        l,
                        Kind::Sampled,
                        s.max_depth,
                        false,
                        rng,
                        counts,
                    );
                    for k in 0..3 {
                        sum[k] += fd[k] * std::f64::consts::PI * x[k];
                    }
                }
                for k in 0..3 {
                    out[k] += sum[k] / n_diff as f64;
                }
            }
        }
        out
    }

    /// Traces a secondary ray leaving `p` in local direction `l`.
    #[allow(clippy::too_many_arguments)]
    fn follow(
        &self,
        p: DVec3,
        n: DVec3,
        frame: &crate::frame::Frame,
        l: DVec3,
        kind: Kind,
        depth: u32,
        diffuse_allowed: bool,
        rng: &mut Rng,
        counts: &mut RayCounts,
    ) -> Rgb {
        counts.secondary += 1;
        let dir = frame.to_world(l).normalize();
        let side = if l.z >= 0.0 { n } else { -n };
        let ray = Ray {
            origin: p + side * RAY_EPSILON,
            dir,
        };
        self.trace(&ray, kind, depth, None, diffuse_allowed, rng, counts)
    }
}

impl Tracer<'_> {
    /// True when every camera ray's radiance is its first hit's direct
    /// term alone (no specular, diffuse or delta rays) and every shader
    /// is one isotropic material (one primitive or a lobe sum), so that the row pipeline of
    /// [`crate::direct`] gives what [`Self::radiance`] gives (to the
    /// last bits of the batch BSDF, 1e-15 relative).
    pub(crate) fn direct_batch_applies(&self) -> bool {
        let s = &self.settings;
        let no_rays = (s.specular_samples == 0 || s.max_depth == 0) && s.diffuse_samples == 0;
        no_rays
            && self.scene.shaders.iter().all(|shader| {
                !shader.has_delta() && shader.part_bsdfs().is_some() && !shader.is_anisotropic()
            })
    }

    /// A distant source's cone frame, `1 − cos` of its half-angle and
    /// its solid angle (`None` for other sources).
    #[inline]
    pub(crate) fn distant_sampling(
        &self,
        source: usize,
    ) -> Option<(crate::frame::Frame, f64, f64)> {
        self.sources[source].distant()
    }
}

/// How to render a picture.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageOptions {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Camera rays per pixel.
    pub samples: u32,
    /// Jitter the rays inside each pixel (else: pixel centres, like
    /// `rpict -pj 0`; then all samples share the centre).
    pub jitter: bool,
    /// Random seed.
    pub seed: u64,
    /// Sample counts of the integrator.
    pub settings: Settings,
}

impl Default for ImageOptions {
    fn default() -> Self {
        ImageOptions {
            width: 320,
            height: 240,
            samples: 16,
            jitter: true,
            seed: 1,
            settings: Settings::default(),
        }
    }
}
