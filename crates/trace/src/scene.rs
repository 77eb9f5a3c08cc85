//! What the tracer renders: flat disks (or infinite planes) and spheres
//! with materials, light sources of finite solid angle, and a constant
//! background radiance.
//!
//! Sources follow Radiance: a distant [`Source::Distant`] (Radiance's
//! `source`) of given apex angle, and a spherical light
//! ([`Source::Sphere`], a `sphere` with a `light` material). Sources are
//! seen by camera rays and by the delta rays of roughness-0 surfaces; the
//! Monte Carlo specular and diffuse rays ignore them, because the direct
//! term has already counted them (equation (1)'s caveat, rtrace's
//! `badcomponent` rule).

use brtf_model::Rgb;
use glam::DVec3;

use crate::frame::Frame;
use crate::sampling::{cap_solid_angle, one_minus_cos, uniform_cone, uniform_cone_in};
use crate::shader::Shader;

/// A ray: origin and unit direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    /// Origin.
    pub origin: DVec3,
    /// Unit direction.
    pub dir: DVec3,
}

/// A geometric shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// A flat disk; `radius = ∞` makes an infinite plane.
    Disk {
        /// Centre.
        center: DVec3,
        /// Unit front normal.
        normal: DVec3,
        /// Radius.
        radius: f64,
    },
    /// A sphere (front normal outwards).
    Sphere {
        /// Centre.
        center: DVec3,
        /// Radius.
        radius: f64,
    },
}

impl Shape {
    /// Distance along `ray` to the nearest hit in `(t_min, t_max)`.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<f64> {
        match *self {
            Shape::Disk {
                center,
                normal,
                radius,
            } => {
                let denom = ray.dir.dot(normal);
                if denom == 0.0 {
                    return None;
                }
                let t = (center - ray.origin).dot(normal) / denom;
                if t <= t_min || t >= t_max {
                    return None;
                }
                if radius.is_finite() {
                    let p = ray.origin + ray.dir * t - center;
                    if p.length_squared() > radius * radius {
                        return None;
                    }
                }
                Some(t)
            }
            Shape::Sphere { center, radius } => sphere_hit(center, radius, ray, t_min, t_max),
        }
    }

    /// Unit front normal at a point on the surface.
    #[inline]
    pub fn normal_at(&self, p: DVec3) -> DVec3 {
        match *self {
            Shape::Disk { normal, .. } => normal,
            Shape::Sphere { center, .. } => (p - center).normalize(),
        }
    }
}

#[inline]
fn sphere_hit(center: DVec3, radius: f64, ray: &Ray, t_min: f64, t_max: f64) -> Option<f64> {
    let oc = ray.origin - center;
    let b = oc.dot(ray.dir);
    // Distance² from the centre to the ray's line, computed without the
    // cancellation of b² − c for distant origins.
    let perp = oc - ray.dir * b;
    let disc = radius * radius - perp.length_squared();
    if disc < 0.0 {
        return None;
    }
    let root = disc.sqrt();
    // The nearer root stably (Numerical Recipes form).
    let q = -b - root.copysign(b);
    let (t0, t1) = if q == 0.0 {
        (0.0, 0.0)
    } else {
        let c = oc.length_squared() - radius * radius;
        let (a, b) = (q, c / q);
        if a < b { (a, b) } else { (b, a) }
    };
    if t0 > t_min && t0 < t_max {
        Some(t0)
    } else if t1 > t_min && t1 < t_max {
        Some(t1)
    } else {
        None
    }
}

/// An object: a shape with a material (an index into [`Scene::shaders`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Object {
    /// The shape.
    pub shape: Shape,
    /// Index of its shader.
    pub shader: usize,
}

/// A light source of finite solid angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Source {
    /// A distant source (Radiance `source`): a cone of directions.
    Distant {
        /// Unit direction towards the source's centre.
        dir: DVec3,
        /// Half of the apex angle, radians.
        half_angle: f64,
        /// Radiance (W/sr/m² per channel).
        radiance: Rgb,
    },
    /// A spherical light (a `sphere` with a `light` material).
    Sphere {
        /// Centre.
        center: DVec3,
        /// Radius.
        radius: f64,
        /// Radiance.
        radiance: Rgb,
    },
}

/// One sample of a source seen from a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SourceSample {
    /// Unit direction towards the sample.
    pub dir: DVec3,
    /// Distance to the source along `dir` (∞ for distant sources).
    pub distance: f64,
    /// The source's solid angle seen from the point (1/pdf).
    pub omega: f64,
    /// Its radiance.
    pub radiance: Rgb,
}

impl Source {
    /// A distant source from a direction and the full apex angle in degrees.
    pub fn distant(dir: DVec3, apex_deg: f64, radiance: Rgb) -> Source {
        Source::Distant {
            dir: dir.normalize(),
            half_angle: 0.5 * apex_deg.to_radians(),
            radiance,
        }
    }

    /// A direction drawn uniformly over the source's solid angle seen from `p`.
    #[inline]
    pub fn sample(&self, p: DVec3, u: [f64; 2]) -> Option<SourceSample> {
        match *self {
            Source::Distant {
                dir,
                half_angle,
                radiance,
            } => Some(SourceSample {
                dir: uniform_cone(dir, half_angle, u),
                distance: f64::INFINITY,
                omega: cap_solid_angle(half_angle),
                radiance,
            }),
            Source::Sphere {
                center,
                radius,
                radiance,
            } => {
                let to = center - p;
                let d2 = to.length_squared();
                if d2 <= radius * radius {
                    return None;
                }
                let d = d2.sqrt();
                let axis = to / d;
                let sin_max = radius / d;
                let half_angle = sin_max.asin();
                let dir = uniform_cone(axis, half_angle, u);
                let ray = Ray { origin: p, dir };
                let distance =
                    sphere_hit(center, radius, &ray, 0.0, f64::INFINITY).unwrap_or(d - radius);
                Some(SourceSample {
                    dir,
                    distance,
                    omega: cap_solid_angle(half_angle),
                    radiance,
                })
            }
        }
    }
}

/// A source with the sampling constants that do not depend on the
/// shading point (a distant source's cone frame, `1 − cos`, solid angle),
/// so that a shadow ray does not pay two sines and a frame for them.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PreparedSource {
    source: Source,
    /// Distant sources: the frame around the cone's axis, `1 − cos` of
    /// its half-angle and its solid angle.
    distant: Option<(Frame, f64, f64)>,
}

impl PreparedSource {
    pub(crate) fn new(source: &Source) -> PreparedSource {
        let distant = match *source {
            Source::Distant {
                dir, half_angle, ..
            } => Some((
                Frame::from_z(dir),
                one_minus_cos(half_angle),
                cap_solid_angle(half_angle),
            )),
            Source::Sphere { .. } => None,
        };
        PreparedSource {
            source: *source,
            distant,
        }
    }

    /// A distant source's frame, `1 − cos` of its half-angle and its
    /// solid angle.
    #[inline]
    pub(crate) fn distant(&self) -> Option<(Frame, f64, f64)> {
        self.distant
    }

    /// [`Source::sample`], the same numbers.
    #[inline]
    pub(crate) fn sample(&self, p: DVec3, u: [f64; 2]) -> Option<SourceSample> {
        match (self.distant, self.source) {
            (Some((frame, one_minus_cos_half, omega)), Source::Distant { radiance, .. }) => {
                Some(SourceSample {
                    dir: uniform_cone_in(&frame, one_minus_cos_half, u),
                    distance: f64::INFINITY,
                    omega,
                    radiance,
                })
            }
            _ => self.source.sample(p, u),
        }
    }
}

/// What a ray met first.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Hit {
    /// A surface: distance, object index.
    Surface {
        /// Distance along the ray.
        t: f64,
        /// Index into [`Scene::objects`].
        object: usize,
    },
    /// A spherical light: its radiance.
    Light(Rgb),
    /// Nothing: a distant source's radiance if the ray points into one,
    /// else the background.
    Escaped {
        /// The distant source it points into, if any.
        source: Option<Rgb>,
    },
}

/// A scene: objects, their shaders, sources and a background.
#[derive(Debug, Clone)]
pub struct Scene {
    /// Surfaces.
    pub objects: Vec<Object>,
    /// Materials, referred to by index.
    pub shaders: Vec<Shader>,
    /// Light sources.
    pub sources: Vec<Source>,
    /// Radiance of everything else (a constant environment; 0 = the void).
    pub background: Rgb,
}

/// Rays start this far off a surface.
pub(crate) const RAY_EPSILON: f64 = 1e-7;

impl Scene {
    /// An empty scene with a black background.
    pub fn new() -> Scene {
        Scene {
            objects: Vec::new(),
            shaders: Vec::new(),
            sources: Vec::new(),
            background: [0.0; 3],
        }
    }

    /// Adds a shader and returns its index.
    pub fn add_shader(&mut self, shader: Shader) -> usize {
        self.shaders.push(shader);
        self.shaders.len() - 1
    }

    /// Adds an object.
    pub fn add(&mut self, shape: Shape, shader: usize) {
        self.objects.push(Object { shape, shader });
    }

    /// The first thing `ray` meets.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Hit {
        let mut best = f64::INFINITY;
        let mut hit = None;
        for (i, o) in self.objects.iter().enumerate() {
            if let Some(t) = o.shape.intersect(ray, RAY_EPSILON, best) {
                best = t;
                hit = Some(i);
            }
        }
        let mut light = None;
        for s in &self.sources {
            if let Source::Sphere {
                center,
                radius,
                radiance,
            } = *s
                && let Some(t) = sphere_hit(center, radius, ray, RAY_EPSILON, best)
            {
                best = t;
                light = Some(radiance);
            }
        }
        if let Some(radiance) = light {
            return Hit::Light(radiance);
        }
        if let Some(object) = hit {
            return Hit::Surface { t: best, object };
        }
        let source = self.sources.iter().find_map(|s| match *s {
            Source::Distant {
                dir,
                half_angle,
                radiance,
            } if 1.0 - dir.dot(ray.dir) <= one_minus_cos(half_angle) => Some(radiance),
            _ => None,
        });
        Hit::Escaped { source }
    }

    /// True if a surface blocks `ray` before `distance`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, distance: f64) -> bool {
        let t_max = distance * (1.0 - 1e-9);
        self.objects
            .iter()
            .any(|o| o.shape.intersect(ray, RAY_EPSILON, t_max).is_some())
    }
}

impl Default for Scene {
    fn default() -> Self {
        Scene::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_and_disk_hits() {
        let s = Shape::Sphere {
            center: DVec3::new(0.0, 0.0, 5.0),
            radius: 1.0,
        };
        let ray = Ray {
            origin: DVec3::ZERO,
            dir: DVec3::Z,
        };
        assert!((s.intersect(&ray, 1e-9, f64::INFINITY).unwrap() - 4.0).abs() < 1e-12);
        let inside = Ray {
            origin: DVec3::new(0.0, 0.0, 5.0),
            dir: DVec3::X,
        };
        assert!((s.intersect(&inside, 1e-9, f64::INFINITY).unwrap() - 1.0).abs() < 1e-12);
        let d = Shape::Disk {
            center: DVec3::new(0.0, 0.0, 2.0),
            normal: DVec3::Z,
            radius: 0.5,
        };
        assert!((d.intersect(&ray, 1e-9, f64::INFINITY).unwrap() - 2.0).abs() < 1e-12);
        let off = Ray {
            origin: DVec3::new(0.6, 0.0, 0.0),
            dir: DVec3::Z,
        };
        assert!(d.intersect(&off, 1e-9, f64::INFINITY).is_none());
    }

    #[test]
    fn prepared_sources_sample_the_same_bits() {
        let sources = [
            Source::distant(DVec3::new(0.5, -0.4, 0.7), 0.5, [1e5; 3]),
            Source::distant(DVec3::new(0.0, 0.0, -1.0), 30.0, [1.0; 3]),
            Source::Sphere {
                center: DVec3::new(0.0, 3.0, 10.0),
                radius: 2.0,
                radiance: [1.0; 3],
            },
        ];
        let mut rng = brtf_model::Rng::new(3, 4);
        for source in &sources {
            let prepared = PreparedSource::new(source);
            for _ in 0..1000 {
                let p = DVec3::new(rng.uniform(), rng.uniform(), rng.uniform());
                let u = rng.uniform2();
                assert_eq!(prepared.sample(p, u), source.sample(p, u));
            }
        }
    }

    #[test]
    fn sphere_light_samples_hit_the_sphere() {
        let src = Source::Sphere {
            center: DVec3::new(0.0, 0.0, 10.0),
            radius: 2.0,
            radiance: [1.0; 3],
        };
        let mut rng = brtf_model::Rng::new(0, 0);
        for _ in 0..100 {
            let s = src.sample(DVec3::ZERO, rng.uniform2()).unwrap();
            let p = s.dir * s.distance;
            assert!(((p - DVec3::new(0.0, 0.0, 10.0)).length() - 2.0).abs() < 1e-9);
            let expect = 2.0 * std::f64::consts::PI * (1.0 - (1.0 - 0.04f64).sqrt());
            assert!((s.omega - expect).abs() < 1e-12);
        }
    }
}
