//! Direct-light pictures a row at a time, in structure-of-arrays form.
//!
//! When a picture has no specular, diffuse or delta rays and every shader
//! is one isotropic material, one primitive or a lobe sum
//! ([`Tracer::direct_batch_applies`]), a camera
//! ray's radiance is its first hit's direct term alone. Then a whole row
//! goes through the same stages together: camera rays, nearest hits (one
//! primitive against all rays at a time), shading frames, source samples,
//! one batch BSDF evaluation per shader, shadow rays (again one primitive
//! against all of them), sums. Each stage is a loop without data-dependent
//! branches over coordinate arrays, compiled through `pulp` for the widest
//! SIMD level of the CPU, so it vectorises.
//!
//! The numbers are those of [`Tracer::radiance`]: every stage does the
//! same floating-point operations in the same order as the per-ray code
//! (no fused multiply-add, which Rust never contracts), and every pixel
//! draws the same random numbers in the same order. Only the BSDF comes
//! from brtf-model's batch kernel (1e-15 relative to `eval`). The test
//! `batched_direct_rows_equal_the_per_ray_tracer` checks it pixel by pixel.

use brtf_model::Rgb;
use glam::DVec3;

use crate::camera::Camera;
use crate::frame::Frame;
use crate::integrator::{ImageOptions, RayCounts, Tracer};
use crate::sampling::sin_cos_turns;
use crate::scene::{RAY_EPSILON, Scene, Shape, Source};
use brtf_model::Rng;

/// A `Vec<f64>` per coordinate.
#[derive(Debug, Default)]
struct Vectors {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
}

impl Vectors {
    /// `n` entries (old values kept: every stage overwrites all it reads).
    fn resize(&mut self, n: usize) {
        for c in [&mut self.x, &mut self.y, &mut self.z] {
            c.resize(n, 0.0);
        }
    }

    /// The first `n` entries as three slices.
    fn xyz(&self, n: usize) -> Xyz<'_> {
        [&self.x[..n], &self.y[..n], &self.z[..n]]
    }

    fn xyz_mut(&mut self, n: usize) -> XyzMut<'_> {
        [&mut self.x[..n], &mut self.y[..n], &mut self.z[..n]]
    }

    #[inline(always)]
    fn get(&self, i: usize) -> DVec3 {
        DVec3::new(self.x[i], self.y[i], self.z[i])
    }

    #[inline(always)]
    fn set(&mut self, i: usize, v: DVec3) {
        self.x[i] = v.x;
        self.y[i] = v.y;
        self.z[i] = v.z;
    }
}

/// A stage of the row as a `pulp` operation: a struct of the arguments
/// of stage function `$f`, run by `Arch::dispatch` compiled for the
/// CPU's SIMD level. (A closure would be called through a `FnOnce` shim
/// that the compiler may leave out of line, without the target features.)
macro_rules! stage {
    ($name:ident { $($field:ident: $ty:ty),* $(,)? } => $f:ident) => {
        struct $name<'a> {
            $($field: $ty),*
        }

        impl pulp::WithSimd for $name<'_> {
            type Output = ();
            #[inline(always)]
            fn with_simd<S: pulp::Simd>(self, _: S) {
                $f($(self.$field),*)
            }
        }
    };
}

stage!(CameraRays {
    camera: &'a Camera,
    size: (usize, usize, usize),
    jitter: (&'a [f64], &'a [f64]),
    origins: XyzMut<'a>,
    dirs: XyzMut<'a>,
} => camera_rays);
stage!(Nearest {
    scene: &'a Scene,
    rays: (Xyz<'a>, Xyz<'a>),
    best: &'a mut [f64],
    t: &'a mut [f64],
    object: &'a mut [u32],
    light: &'a mut [u32],
} => nearest);
stage!(Shading {
    hit: (&'a [f64], &'a [bool], Xyz<'a>),
    rays: (Xyz<'a>, Xyz<'a>),
    out: [XyzMut<'a>; 5],
} => shading);
stage!(ConeSamples {
    frame: &'a Frame,
    one_minus_cos_half: f64,
    u: (&'a [f64], &'a [f64]),
    dirs: XyzMut<'a>,
} => cone_samples);
stage!(Locals {
    sample_dirs: Xyz<'a>,
    frames: (Xyz<'a>, Xyz<'a>, Xyz<'a>, Xyz<'a>),
    sources: (&'a [f64], &'a [f64]),
    lights: XyzMut<'a>,
    shadow_origins: XyzMut<'a>,
    weight: &'a mut [f64],
    t_max: &'a mut [f64],
} => locals);
stage!(Shadows {
    scene: &'a Scene,
    rays: (Xyz<'a>, Xyz<'a>),
    t_max: &'a [f64],
    t: &'a mut [f64],
    occluded: &'a mut [bool],
} => shadows);

type Xyz<'a> = [&'a [f64]; 3];
type XyzMut<'a> = [&'a mut [f64]; 3];

/// `v` cut to `n` entries: with every array's length known to be the
/// loop's, the compiler drops the bounds checks, which would otherwise
/// keep the loop from vectorising.
#[inline(always)]
fn cut(v: Xyz, n: usize) -> Xyz {
    [&v[0][..n], &v[1][..n], &v[2][..n]]
}

#[inline(always)]
fn cut_mut(v: XyzMut, n: usize) -> XyzMut {
    let [x, y, z] = v;
    [&mut x[..n], &mut y[..n], &mut z[..n]]
}

#[inline(always)]
fn at(v: &Xyz, i: usize) -> DVec3 {
    DVec3::new(v[0][i], v[1][i], v[2][i])
}

#[inline(always)]
fn put(v: &mut XyzMut, i: usize, x: DVec3) {
    v[0][i] = x.x;
    v[1][i] = x.y;
    v[2][i] = x.z;
}

/// `Shape::intersect` for a disk, without branches: the distance, or ∞
/// for a miss.
#[inline(always)]
fn disk_t(center: DVec3, normal: DVec3, radius: f64, ray: (DVec3, DVec3), t_max: f64) -> f64 {
    let (origin, dir) = ray;
    let denom = dir.dot(normal);
    let t = (center - origin).dot(normal) / denom;
    let mut hit = denom != 0.0 && t > RAY_EPSILON && t < t_max;
    if radius.is_finite() {
        let p = origin + dir * t - center;
        hit &= p.length_squared() <= radius * radius;
    }
    if hit { t } else { f64::INFINITY }
}

/// `sphere_hit` of the scene, without branches: the distance, or ∞.
#[inline(always)]
fn sphere_t(center: DVec3, radius: f64, ray: (DVec3, DVec3), t_max: f64) -> f64 {
    let (origin, dir) = ray;
    let oc = origin - center;
    let b = oc.dot(dir);
    let perp = oc - dir * b;
    let disc = radius * radius - perp.length_squared();
    let root = disc.sqrt();
    let q = -b - root.copysign(b);
    let c = oc.length_squared() - radius * radius;
    let other = c / q;
    let (near, far) = if q < other { (q, other) } else { (other, q) };
    let (near, far) = if q == 0.0 { (0.0, 0.0) } else { (near, far) };
    let t = if near > RAY_EPSILON && near < t_max {
        near
    } else if far > RAY_EPSILON && far < t_max {
        far
    } else {
        f64::INFINITY
    };
    if disc < 0.0 { f64::INFINITY } else { t }
}

/// The distance to `shape` along each ray of `origins`/`dirs` below
/// `t_max[i]`, or ∞: one primitive against all the rays.
#[inline(always)]
fn shape_t(shape: &Shape, origins: Xyz, dirs: Xyz, t_max: &[f64], t: &mut [f64]) {
    let n = t.len();
    let t_max = &t_max[..n];
    let (ox, oy, oz) = (&origins[0][..n], &origins[1][..n], &origins[2][..n]);
    let (dx, dy, dz) = (&dirs[0][..n], &dirs[1][..n], &dirs[2][..n]);
    match *shape {
        Shape::Disk {
            center,
            normal,
            radius,
        } => {
            for i in 0..n {
                let ray = (
                    DVec3::new(ox[i], oy[i], oz[i]),
                    DVec3::new(dx[i], dy[i], dz[i]),
                );
                t[i] = disk_t(center, normal, radius, ray, t_max[i]);
            }
        }
        Shape::Sphere { center, radius } => {
            for i in 0..n {
                let ray = (
                    DVec3::new(ox[i], oy[i], oz[i]),
                    DVec3::new(dx[i], dy[i], dz[i]),
                );
                t[i] = sphere_t(center, radius, ray, t_max[i]);
            }
        }
    }
}

/// Camera rays through pixels `(i, j)`, `i < w`, at `(du, dv)` inside.
#[inline(always)]
fn camera_rays(
    camera: &Camera,
    (j, w, h): (usize, usize, usize),
    (du, dv): (&[f64], &[f64]),
    origins: XyzMut,
    dirs: XyzMut,
) {
    let (du, dv) = (&du[..w], &dv[..w]);
    let (mut origins, mut dirs) = (cut_mut(origins, w), cut_mut(dirs, w));
    for i in 0..w {
        let ray = camera.pixel_ray(i, j, w, h, du[i], dv[i]);
        put(&mut origins, i, ray.origin);
        put(&mut dirs, i, ray.dir);
    }
}

/// Nearest hits: objects in order, then spherical lights (an index per
/// ray, `u32::MAX` for none), as `Scene::intersect` finds them.
#[inline(always)]
fn nearest(
    scene: &Scene,
    (origins, dirs): (Xyz, Xyz),
    best: &mut [f64],
    t: &mut [f64],
    object: &mut [u32],
    light: &mut [u32],
) {
    for (k, o) in scene.objects.iter().enumerate() {
        shape_t(&o.shape, origins, dirs, best, t);
        nearer(t, best, object, k as u32);
    }
    for (k, source) in scene.sources.iter().enumerate() {
        if let Source::Sphere { center, radius, .. } = *source {
            let shape = Shape::Sphere { center, radius };
            shape_t(&shape, origins, dirs, best, t);
            nearer(t, best, light, k as u32);
        }
    }
}

/// Shading point, normal turned towards the viewer, frame (x and y; z
/// is the normal) and local view direction of every hit.
#[inline(always)]
fn shading(
    (hit_t, hit_sphere, hit_point): (&[f64], &[bool], Xyz),
    (hit_origin, hit_dir): (Xyz, Xyz),
    out: [XyzMut; 5],
) {
    let hits = hit_t.len();
    let (hit_sphere, hit_point) = (&hit_sphere[..hits], cut(hit_point, hits));
    let (hit_origin, hit_dir) = (cut(hit_origin, hits), cut(hit_dir, hits));
    let [points, normals, frame_x, frame_y, views] = out;
    let mut points = cut_mut(points, hits);
    let mut normals = cut_mut(normals, hits);
    let mut frame_x = cut_mut(frame_x, hits);
    let mut frame_y = cut_mut(frame_y, hits);
    let mut views = cut_mut(views, hits);
    // Two loops, each small enough for the compiler to vectorise.
    for h in 0..hits {
        let dir = at(&hit_dir, h);
        let p = at(&hit_origin, h) + dir * hit_t[h];
        // A sphere's centre, or a disk's normal.
        let point = at(&hit_point, h);
        let radial = (p - point).normalize();
        let mut n = if hit_sphere[h] { radial } else { point };
        if n.dot(-dir) < 0.0 {
            n = -n;
        }
        put(&mut points, h, p);
        put(&mut normals, h, n);
    }
    for h in 0..hits {
        let v_world = -at(&hit_dir, h);
        let frame = Frame::from_z(at(&normals.each_ref().map(|c| &c[..]), h));
        let v = frame.to_local(v_world);
        let v = DVec3::new(v.x, v.y, v.z.max(0.0));
        put(&mut frame_x, h, frame.x);
        put(&mut frame_y, h, frame.y);
        put(&mut views, h, v);
    }
}

/// `uniform_cone_in` of a distant source for uniforms `(u0, u1)`.
#[inline(always)]
fn cone_samples(frame: &Frame, one_minus_cos_half: f64, (u0, u1): (&[f64], &[f64]), dirs: XyzMut) {
    let n = u0.len();
    let u1 = &u1[..n];
    let mut dirs = cut_mut(dirs, n);
    for k in 0..n {
        let cos_t = 1.0 - u0[k] * one_minus_cos_half;
        let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
        let (sp, cp) = sin_cos_turns(u1[k]);
        put(
            &mut dirs,
            k,
            frame.to_world(DVec3::new(sin_t * cp, sin_t * sp, cos_t)),
        );
    }
}

/// For one block of source samples (one per hit): the light in the
/// local frame, the shadow ray's origin and `t_max`, and `|cos| ω`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn locals(
    sample_dirs: Xyz,
    (points, normals, frame_x, frame_y): (Xyz, Xyz, Xyz, Xyz),
    (omega, distance): (&[f64], &[f64]),
    lights: XyzMut,
    shadow_origins: XyzMut,
    weight: &mut [f64],
    t_max: &mut [f64],
) {
    let hits = weight.len();
    let (omega, distance, t_max) = (&omega[..hits], &distance[..hits], &mut t_max[..hits]);
    let sample_dirs = cut(sample_dirs, hits);
    let (points, normals) = (cut(points, hits), cut(normals, hits));
    let (frame_x, frame_y) = (cut(frame_x, hits), cut(frame_y, hits));
    let (mut lights, mut shadow_origins) = (cut_mut(lights, hits), cut_mut(shadow_origins, hits));
    for h in 0..hits {
        let n = at(&normals, h);
        let frame = Frame {
            x: at(&frame_x, h),
            y: at(&frame_y, h),
            z: n,
        };
        let l = frame.to_local(at(&sample_dirs, h));
        let side = if l.z >= 0.0 { n } else { -n };
        put(&mut lights, h, l);
        put(&mut shadow_origins, h, at(&points, h) + side * RAY_EPSILON);
        weight[h] = l.z.abs() * omega[h];
        t_max[h] = distance[h] * (1.0 - 1e-9);
    }
}

/// Whether some object blocks each shadow ray before its `t_max`.
#[inline(always)]
fn shadows(
    scene: &Scene,
    (origins, dirs): (Xyz, Xyz),
    t_max: &[f64],
    t: &mut [f64],
    occluded: &mut [bool],
) {
    let n = t.len();
    let occluded = &mut occluded[..n];
    for o in &scene.objects {
        shape_t(&o.shape, origins, dirs, t_max, t);
        for i in 0..n {
            occluded[i] |= t[i] < f64::INFINITY;
        }
    }
}

/// The reusable buffers of one worker.
#[derive(Debug, Default)]
pub(crate) struct DirectRows {
    rngs: Vec<Rng>,
    /// Where in its pixel each camera ray goes (jitter).
    du: Vec<f64>,
    dv: Vec<f64>,
    /// Radiance of every camera ray of the row (`pixel × samples`).
    radiance: Vec<Rgb>,
    // Camera rays of one pass (one sample per pixel).
    origins: Vectors,
    dirs: Vectors,
    best: Vec<f64>,
    object: Vec<u32>,
    light: Vec<u32>,
    t: Vec<f64>,
    // Surface hits: the slot, distance, object, then the shading point,
    // normal, frame and local view direction.
    hit_pixel: Vec<usize>,
    hit_t: Vec<f64>,
    hit_object: Vec<u32>,
    hit_dir: Vectors,
    hit_origin: Vectors,
    /// A sphere's centre or a disk's normal.
    hit_point: Vectors,
    hit_sphere: Vec<bool>,
    points: Vectors,
    normals: Vectors,
    frame_x: Vectors,
    frame_y: Vectors,
    views: Vectors,
    // Source samples, laid out [source][sample][hit].
    u0: Vec<f64>,
    u1: Vec<f64>,
    sample_dirs: Vectors,
    distance: Vec<f64>,
    omega: Vec<f64>,
    valid: Vec<bool>,
    lights: Vectors,
    shadow_origins: Vectors,
    weight: Vec<f64>,
    t_max: Vec<f64>,
    occluded: Vec<bool>,
    f: Vectors,
    // Gathered pairs of one shader when a scene has several.
    gather_index: Vec<usize>,
    gather_l: brtf_model::Directions,
    gather_v: brtf_model::Directions,
    gather_f: brtf_model::RgbBatch,
    /// One lobe's values of a lobe sum.
    part: Vectors,
    gather_part: brtf_model::RgbBatch,
}

impl DirectRows {
    /// Row `j` of the picture into `out` (its `width` pixels): what the
    /// per-ray loop of [`crate::render`] gives, with the same ray counts.
    pub(crate) fn row(
        &mut self,
        tracer: &Tracer,
        camera: &Camera,
        options: &ImageOptions,
        j: usize,
        counts: &mut RayCounts,
        out: &mut [[f32; 3]],
    ) {
        let w = options.width;
        let n = options.samples.max(1) as usize;
        self.rngs.clear();
        self.rngs
            .extend((0..w).map(|i| Rng::new(options.seed, (j * w + i) as u64)));
        self.radiance.clear();
        self.radiance.resize(w * n, [0.0; 3]);
        for s in 0..n {
            self.pass(tracer, camera, options, j, s, counts);
        }
        if n == 1 {
            // x / 1 = x.
            for (pixel, l) in out.iter_mut().zip(&self.radiance) {
                *pixel = l.map(|s| (0.0 + s) as f32);
            }
            return;
        }
        for (pixel, samples) in out.iter_mut().zip(self.radiance.chunks_exact(n)) {
            let mut sum: Rgb = [0.0; 3];
            for l in samples {
                for k in 0..3 {
                    sum[k] += l[k];
                }
            }
            *pixel = sum.map(|s| (s / n as f64) as f32);
        }
    }

    /// Camera ray number `s` of every pixel of row `j`.
    fn pass(
        &mut self,
        tracer: &Tracer,
        camera: &Camera,
        options: &ImageOptions,
        j: usize,
        s: usize,
        counts: &mut RayCounts,
    ) {
        let (w, h) = (options.width, options.height);
        let n = options.samples.max(1) as usize;
        let scene = tracer.scene;
        let arch = pulp::Arch::new();

        // Camera rays (the jitter is the first draw of each pixel's stream;
        // without it every ray goes through its pixel's centre).
        if options.jitter {
            self.du.resize(w, 0.0);
            self.dv.resize(w, 0.0);
            for (i, rng) in self.rngs.iter_mut().enumerate() {
                self.du[i] = rng.uniform();
                self.dv[i] = rng.uniform();
            }
        } else {
            self.du.clear();
            self.du.resize(w, 0.5);
            self.dv.clear();
            self.dv.resize(w, 0.5);
        }
        self.origins.resize(w);
        self.dirs.resize(w);
        {
            let (du, dv) = (&self.du[..], &self.dv[..]);
            let (origins, dirs) = (self.origins.xyz_mut(w), self.dirs.xyz_mut(w));
            arch.dispatch(CameraRays {
                camera,
                size: (j, w, h),
                jitter: (du, dv),
                origins,
                dirs,
            });
        }
        counts.primary += w as u64;

        // Nearest hits: objects in order, then spherical lights.
        self.best.clear();
        self.best.resize(w, f64::INFINITY);
        self.object.clear();
        self.object.resize(w, u32::MAX);
        self.light.clear();
        self.light.resize(w, u32::MAX);
        self.t.resize(w, 0.0);
        {
            let rays = (self.origins.xyz(w), self.dirs.xyz(w));
            let (best, t) = (&mut self.best[..w], &mut self.t[..w]);
            let (object, light) = (&mut self.object[..w], &mut self.light[..w]);
            arch.dispatch(Nearest {
                scene,
                rays,
                best,
                t,
                object,
                light,
            });
        }

        // Lights and misses are done; surface hits go on.
        self.hit_pixel.clear();
        self.hit_t.clear();
        self.hit_object.clear();
        for i in 0..w {
            let slot = i * n + s;
            if self.light[i] != u32::MAX {
                if let Source::Sphere { radiance, .. } = scene.sources[self.light[i] as usize] {
                    self.radiance[slot] = radiance;
                }
            } else if self.object[i] == u32::MAX {
                let dir = self.dirs.get(i);
                let source = scene.sources.iter().enumerate().find_map(|(k, s)| {
                    match (*s, tracer.distant_sampling(k)) {
                        (
                            Source::Distant {
                                dir: axis,
                                radiance,
                                ..
                            },
                            Some((_, one_minus_cos_half, _)),
                        ) if 1.0 - axis.dot(dir) <= one_minus_cos_half => Some(radiance),
                        _ => None,
                    }
                });
                self.radiance[slot] = source.unwrap_or(scene.background);
            } else {
                self.hit_pixel.push(i);
                self.hit_t.push(self.best[i]);
                self.hit_object.push(self.object[i]);
            }
        }
        let hits = self.hit_pixel.len();
        if hits == 0 {
            return;
        }

        // Shading point, normal turned towards the viewer, frame, view.
        for v in [
            &mut self.hit_dir,
            &mut self.hit_origin,
            &mut self.hit_point,
            &mut self.points,
            &mut self.normals,
            &mut self.frame_x,
            &mut self.frame_y,
            &mut self.views,
        ] {
            v.resize(hits);
        }
        self.hit_sphere.resize(hits, false);
        for (h, &i) in self.hit_pixel.iter().enumerate() {
            self.hit_dir.set(h, self.dirs.get(i));
            self.hit_origin.set(h, self.origins.get(i));
            let (sphere, point) = match scene.objects[self.hit_object[h] as usize].shape {
                Shape::Disk { normal, .. } => (false, normal),
                Shape::Sphere { center, .. } => (true, center),
            };
            self.hit_sphere[h] = sphere;
            self.hit_point.set(h, point);
        }
        {
            let hit = (
                &self.hit_t[..hits],
                &self.hit_sphere[..hits],
                self.hit_point.xyz(hits),
            );
            let rays = (self.hit_origin.xyz(hits), self.hit_dir.xyz(hits));
            let out = [
                self.points.xyz_mut(hits),
                self.normals.xyz_mut(hits),
                self.frame_x.xyz_mut(hits),
                self.frame_y.xyz_mut(hits),
                self.views.xyz_mut(hits),
            ];
            arch.dispatch(Shading { hit, rays, out });
        }

        // Source samples: each pixel's stream draws them hit by hit,
        // source by source, as the per-ray tracer does.
        let n_src = tracer.settings.source_samples.max(1) as usize;
        let blocks = scene.sources.len() * n_src;
        let jobs = blocks * hits;
        self.u0.resize(jobs, 0.0);
        self.u1.resize(jobs, 0.0);
        for (h, &i) in self.hit_pixel.iter().enumerate() {
            let rng = &mut self.rngs[i];
            for b in 0..blocks {
                let [a, c] = rng.uniform2();
                self.u0[b * hits + h] = a;
                self.u1[b * hits + h] = c;
            }
        }
        for v in [
            &mut self.sample_dirs,
            &mut self.lights,
            &mut self.shadow_origins,
            &mut self.f,
        ] {
            v.resize(jobs);
        }
        for c in [
            &mut self.distance,
            &mut self.omega,
            &mut self.weight,
            &mut self.t_max,
        ] {
            c.resize(jobs, 0.0);
        }
        self.valid.clear();
        self.valid.resize(jobs, true);
        for (source_index, source) in scene.sources.iter().enumerate() {
            let range = source_index * n_src * hits..(source_index + 1) * n_src * hits;
            match tracer.distant_sampling(source_index) {
                Some((frame, one_minus_cos_half, omega)) => {
                    let u = (&self.u0[range.clone()], &self.u1[range.clone()]);
                    let [x, y, z] = &mut self.sample_dirs.xyz_mut(jobs);
                    let dirs = [
                        &mut x[range.clone()],
                        &mut y[range.clone()],
                        &mut z[range.clone()],
                    ];
                    arch.dispatch(ConeSamples {
                        frame: &frame,
                        one_minus_cos_half,
                        u,
                        dirs,
                    });
                    self.distance[range.clone()].fill(f64::INFINITY);
                    self.omega[range].fill(omega);
                }
                None => {
                    for k in range {
                        let h = k % hits;
                        match source.sample(self.points.get(h), [self.u0[k], self.u1[k]]) {
                            Some(sample) => {
                                self.sample_dirs.set(k, sample.dir);
                                self.distance[k] = sample.distance;
                                self.omega[k] = sample.omega;
                            }
                            None => {
                                self.sample_dirs.set(k, DVec3::Z);
                                self.valid[k] = false;
                            }
                        }
                    }
                }
            }
        }

        // Local light directions, shadow-ray origins, weights.
        for b in 0..blocks {
            let r = b * hits..(b + 1) * hits;
            let sample_dirs = [
                &self.sample_dirs.x[r.clone()],
                &self.sample_dirs.y[r.clone()],
                &self.sample_dirs.z[r.clone()],
            ];
            let frames = (
                self.points.xyz(hits),
                self.normals.xyz(hits),
                self.frame_x.xyz(hits),
                self.frame_y.xyz(hits),
            );
            let sources = (&self.omega[r.clone()], &self.distance[r.clone()]);
            let lights = [
                &mut self.lights.x[r.clone()],
                &mut self.lights.y[r.clone()],
                &mut self.lights.z[r.clone()],
            ];
            let shadow_origins = [
                &mut self.shadow_origins.x[r.clone()],
                &mut self.shadow_origins.y[r.clone()],
                &mut self.shadow_origins.z[r.clone()],
            ];
            let (weight, t_max) = (&mut self.weight[r.clone()], &mut self.t_max[r.clone()]);
            arch.dispatch(Locals {
                sample_dirs,
                frames,
                sources,
                lights,
                shadow_origins,
                weight,
                t_max,
            });
        }

        // The BSDF values, one batch per source sample and shader.
        self.evaluate(tracer, blocks, hits);
        for k in 0..jobs {
            if !self.valid[k] {
                self.f.set(k, DVec3::ZERO);
            }
        }

        // Shadow rays: every object against all of them.
        self.occluded.clear();
        self.occluded.resize(jobs, false);
        self.t.resize(jobs, 0.0);
        {
            let rays = (self.shadow_origins.xyz(jobs), self.sample_dirs.xyz(jobs));
            let (t_max, t) = (&self.t_max[..jobs], &mut self.t[..jobs]);
            let occluded = &mut self.occluded[..jobs];
            arch.dispatch(Shadows {
                scene,
                rays,
                t_max,
                t,
                occluded,
            });
        }

        // Sums, in the per-ray tracer's order.
        let n_src_f = n_src as f64;
        for (h, &i) in self.hit_pixel.iter().enumerate() {
            let mut out = [0.0; 3];
            for (source_index, source) in scene.sources.iter().enumerate() {
                let radiance = source_radiance(source);
                let mut sum = [0.0; 3];
                for sample in 0..n_src {
                    let k = (source_index * n_src + sample) * hits + h;
                    let f = [self.f.x[k], self.f.y[k], self.f.z[k]];
                    if f == [0.0; 3] {
                        continue;
                    }
                    counts.shadow += 1;
                    if self.occluded[k] {
                        continue;
                    }
                    for c in 0..3 {
                        sum[c] += f[c] * self.weight[k] * radiance[c];
                    }
                }
                // x / 1 = x: skip the division (it is most of this loop).
                if n_src == 1 {
                    for c in 0..3 {
                        out[c] += sum[c];
                    }
                } else {
                    for c in 0..3 {
                        out[c] += sum[c] / n_src_f;
                    }
                }
            }
            self.radiance[i * n + s] = out;
        }
    }

    /// `f` of every (light, view) pair: per block of source samples, one
    /// batch evaluation per shader (gathered when the scene has several),
    /// and per lobe of a lobe sum, added up with its weight in the
    /// per-ray tracer's order.
    fn evaluate(&mut self, tracer: &Tracer, blocks: usize, hits: usize) {
        let scene = tracer.scene;
        let single = scene.shaders.len() == 1;
        for b in 0..blocks {
            let range = b * hits..(b + 1) * hits;
            if single {
                let shader = &scene.shaders[0];
                let l = [
                    &self.lights.x[range.clone()],
                    &self.lights.y[range.clone()],
                    &self.lights.z[range.clone()],
                ];
                let v = [
                    &self.views.x[..hits],
                    &self.views.y[..hits],
                    &self.views.z[..hits],
                ];
                let (fx, fy, fz) = (&mut self.f.x, &mut self.f.y, &mut self.f.z);
                let f = [
                    &mut fx[range.clone()],
                    &mut fy[range.clone()],
                    &mut fz[range.clone()],
                ];
                if let Some(bsdf) = shader.single_bsdf() {
                    bsdf.eval_soa(l, v, f);
                    continue;
                }
                for c in f {
                    c.fill(0.0);
                }
                self.part.resize(hits);
                for (w, bsdf) in shader.part_bsdfs().expect("one material") {
                    bsdf.eval_soa(l, v, self.part.xyz_mut(hits));
                    for (c, part) in [(&mut *fx, &self.part.x), (&mut *fy, &self.part.y)]
                        .into_iter()
                        .chain([(&mut *fz, &self.part.z)])
                    {
                        for (x, y) in c[range.clone()].iter_mut().zip(&part[..hits]) {
                            *x += w * y;
                        }
                    }
                }
                continue;
            }
            for (shader_index, shader) in scene.shaders.iter().enumerate() {
                self.gather_index.clear();
                self.gather_l.clear();
                self.gather_v.clear();
                for h in 0..hits {
                    let object = self.hit_object[h] as usize;
                    if scene.objects[object].shader == shader_index {
                        self.gather_index.push(range.start + h);
                        self.gather_l.push(self.lights.get(range.start + h));
                        self.gather_v.push(self.views.get(h));
                    }
                }
                if self.gather_index.is_empty() {
                    continue;
                }
                match shader.single_bsdf() {
                    Some(bsdf) => {
                        bsdf.eval_batch(&self.gather_l, &self.gather_v, &mut self.gather_f)
                    }
                    None => {
                        self.gather_f.resize(self.gather_index.len());
                        for (w, bsdf) in shader.part_bsdfs().expect("one material") {
                            bsdf.eval_batch(&self.gather_l, &self.gather_v, &mut self.gather_part);
                            self.gather_f.add_scaled(w, &self.gather_part);
                        }
                    }
                }
                for (g, &k) in self.gather_index.iter().enumerate() {
                    let f = self.gather_f.get(g);
                    self.f.set(k, DVec3::from_array(f));
                }
            }
        }
    }
}

/// Where `t[i]` is nearer than `best[i]`: the new best and its index.
#[inline(always)]
fn nearer(t: &[f64], best: &mut [f64], index: &mut [u32], k: u32) {
    let n = t.len();
    let (best, index) = (&mut best[..n], &mut index[..n]);
    for i in 0..n {
        let closer = t[i] < best[i];
        best[i] = if closer { t[i] } else { best[i] };
        index[i] = if closer { k } else { index[i] };
    }
}

fn source_radiance(source: &Source) -> Rgb {
    match *source {
        Source::Distant { radiance, .. } | Source::Sphere { radiance, .. } => radiance,
    }
}
