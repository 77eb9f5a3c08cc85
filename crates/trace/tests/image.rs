//! Pictures: determinism, the output formats, and a sphere light with a
//! known answer.

use crate::common::{lobe_sums, mat, shader_of};
use brtf_model::{EvalOptions, MaterialKind};
use brtf_trace::hdr;
use brtf_trace::{Camera, ImageOptions, Scene, Settings, Shader, Shape, Source, render};
use brtf_trace::{auto_exposure, write_png};
use glam::DVec3;

fn scene() -> Scene {
    let mut scene = Scene::new();
    let material = mat(MaterialKind::Plastic, &[0.6, 0.5, 0.4, 0.05, 0.1]);
    let id = scene.add_shader(shader_of(&material, &EvalOptions::default()));
    scene.add(
        Shape::Disk {
            center: DVec3::ZERO,
            normal: DVec3::Z,
            radius: 5.0,
        },
        id,
    );
    scene.add(
        Shape::Sphere {
            center: DVec3::new(0.0, 0.0, 1.0),
            radius: 1.0,
        },
        id,
    );
    scene.sources.push(Source::distant(
        brtf_model::direction(40.0, 200.0),
        0.5,
        [1e5; 3],
    ));
    scene.background = [0.1; 3];
    scene
}

#[test]
fn pictures_are_deterministic_on_any_thread_count() {
    let scene = scene();
    let camera = Camera::look_at(
        DVec3::new(6.0, -6.0, 4.0),
        DVec3::new(0.0, 0.0, 0.7),
        30.0,
        4.0 / 3.0,
    );
    let options = ImageOptions {
        width: 40,
        height: 30,
        samples: 2,
        settings: Settings {
            diffuse_samples: 1,
            ..Settings::default()
        },
        ..ImageOptions::default()
    };
    let a = render(&scene, &camera, &options);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let b = pool.install(|| render(&scene, &camera, &options));
    assert_eq!(a.picture, b.picture);
    assert!(a.rays.primary == 40 * 30 * 2 && a.rays.shadow > 0 && a.rays.secondary > 0);
    // Something is lit and nothing is negative or NaN.
    assert!(
        a.picture
            .pixels
            .iter()
            .flatten()
            .all(|x| x.is_finite() && *x >= 0.0)
    );
    assert!(a.picture.pixels.iter().any(|p| p[0] > 0.01));

    let dir = tempfile::tempdir().unwrap();
    let mut hdr_bytes = Vec::new();
    hdr::write(&mut hdr_bytes, &a.picture, &[]).unwrap();
    let back = hdr::read(&mut &hdr_bytes[..]).unwrap();
    assert_eq!((back.width, back.height), (40, 30));
    let png_path = dir.path().join("x.png");
    write_png(
        std::fs::File::create(&png_path).unwrap(),
        &a.picture,
        auto_exposure(&a.picture),
    )
    .unwrap();
    let bytes = std::fs::read(&png_path).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
}

#[test]
fn lambertian_floor_under_a_sphere_light() {
    // Directly below a sphere light of radius r at height d, the
    // irradiance is E = L π (r/d)², so a Lambertian floor of reflectance ρ
    // has radiance ρ L (r/d)².
    let mut scene = Scene::new();
    let rho = 0.5;
    let material = mat(MaterialKind::Plastic, &[rho, rho, rho, 0.0, 0.0]);
    let id = scene.add_shader(shader_of(&material, &EvalOptions::default()));
    scene.add(
        Shape::Disk {
            center: DVec3::ZERO,
            normal: DVec3::Z,
            radius: f64::INFINITY,
        },
        id,
    );
    let (r, d, l) = (0.5, 4.0, 100.0);
    scene.sources.push(Source::Sphere {
        center: DVec3::new(0.0, 0.0, d),
        radius: r,
        radiance: [l; 3],
    });
    // Look straight down from beside the light.
    let camera = Camera::new(
        DVec3::new(0.0, 1.0, 2.0),
        DVec3::new(0.0, -0.5, -1.0),
        DVec3::Y,
        1.0,
        1.0,
    );
    let options = ImageOptions {
        width: 1,
        height: 1,
        samples: 4000,
        jitter: false,
        settings: Settings::direct_only(),
        ..ImageOptions::default()
    };
    let pic = render(&scene, &camera, &options).picture;
    let want = rho * l * (r / d) * (r / d);
    let got = pic.pixels[0][0] as f64;
    assert!((got - want).abs() < 0.01 * want, "{got} vs {want}");
    let _ = auto_exposure;
}

/// The direct-light rows (structure-of-arrays, one batch BSDF per row
/// and shader) give every pixel and every ray count of the per-ray
/// tracer: several shaders, a sphere light and a distant source, two
/// source samples and three jittered camera rays per pixel.
#[test]
fn batched_direct_rows_equal_the_per_ray_tracer() {
    let settings = Settings {
        source_samples: 2,
        ..Settings::direct_only()
    };
    let options = ImageOptions {
        width: 48,
        height: 36,
        samples: 3,
        jitter: true,
        seed: 7,
        settings,
    };
    direct_rows_equal_the_per_ray_tracer(&options, true);
}

/// The same with one centred camera ray per pixel, one source sample and
/// one material (the benchmark's case: the rows skip dividing by 1 and
/// evaluate the BSDF without gathering pairs by shader).
#[test]
fn batched_direct_rows_equal_the_per_ray_tracer_one_sample() {
    let options = ImageOptions {
        width: 64,
        height: 48,
        samples: 1,
        jitter: false,
        seed: 3,
        settings: Settings::direct_only(),
    };
    direct_rows_equal_the_per_ray_tracer(&options, false);
}

/// Lobe sums take the direct-light rows too (each lobe's batch, added up
/// with its weight): a three-lobe plastic alone, then beside a two-lobe
/// metal, every pixel and ray count equal to the per-ray tracer's.
#[test]
fn batched_direct_rows_equal_the_per_ray_tracer_for_lobe_sums() {
    let options = ImageOptions {
        width: 40,
        height: 30,
        samples: 2,
        jitter: true,
        seed: 5,
        settings: Settings::direct_only(),
    };
    let sums = lobe_sums();
    let (_, plastic) = sums.iter().find(|(n, _)| *n == "plastic ×3").unwrap();
    let (_, metal) = sums.iter().find(|(n, _)| *n == "metal ×2").unwrap();
    let shader = |m| Shader::new(m, &EvalOptions::default()).unwrap();
    let alone = Scene {
        shaders: vec![shader(plastic)],
        ..scene()
    };
    direct_rows_equal_the_per_ray_tracer_in(alone, &options, None);
    let beside = Scene {
        shaders: vec![shader(plastic)],
        ..scene()
    };
    direct_rows_equal_the_per_ray_tracer_in(beside, &options, Some(shader(metal)));
}

/// Renders the test scene with a third sphere (of a second, transmitting
/// material if `glass`, else of the first) and a sphere light, and
/// compares every pixel with [`Tracer::radiance`].
fn direct_rows_equal_the_per_ray_tracer(options: &ImageOptions, glass: bool) {
    // A second, transmitting material lit from behind.
    let glass = glass.then(|| {
        let glass = mat(MaterialKind::Trans, &[0.7, 0.8, 0.9, 0.04, 0.05, 0.6, 0.3]);
        shader_of(&glass, &EvalOptions::default())
    });
    direct_rows_equal_the_per_ray_tracer_in(scene(), options, glass);
}

/// [`direct_rows_equal_the_per_ray_tracer`] in `scene`, the third sphere
/// of `second` if given (else of the first material).
fn direct_rows_equal_the_per_ray_tracer_in(
    mut scene: Scene,
    options: &ImageOptions,
    second: Option<Shader>,
) {
    use brtf_model::Rng;
    use brtf_trace::RayCounts;
    use brtf_trace::Tracer;
    // A second material, and a sphere light.
    let id = match second {
        Some(shader) => scene.add_shader(shader),
        None => 0,
    };
    scene.add(
        Shape::Sphere {
            center: DVec3::new(1.5, -1.0, 0.6),
            radius: 0.6,
        },
        id,
    );
    scene.sources.push(Source::Sphere {
        center: DVec3::new(-2.0, 2.0, 4.0),
        radius: 0.5,
        radiance: [50.0, 40.0, 30.0],
    });
    let (w, h) = (options.width, options.height);
    let camera = Camera::look_at(
        DVec3::new(6.0, -6.0, 4.0),
        DVec3::new(0.0, 0.0, 0.7),
        40.0,
        w as f64 / h as f64,
    );
    let rendered = render(&scene, &camera, options);
    let tracer = Tracer::new(&scene, options.settings);
    let mut counts = RayCounts::default();
    let mut lit = 0;
    for j in 0..h {
        for i in 0..w {
            let mut rng = Rng::new(options.seed, (j * w + i) as u64);
            let mut sum = [0.0; 3];
            for _ in 0..options.samples {
                let (du, dv) = if options.jitter {
                    (rng.uniform(), rng.uniform())
                } else {
                    (0.5, 0.5)
                };
                let ray = camera.pixel_ray(i, j, w, h, du, dv);
                let l = tracer.radiance(&ray, &mut rng, &mut counts);
                for k in 0..3 {
                    sum[k] += l[k];
                }
            }
            let want = sum.map(|s| (s / options.samples as f64) as f32);
            let got = rendered.picture.pixels[j * w + i];
            for k in 0..3 {
                let tol = 1e-6 * want[k].abs().max(got[k].abs()) + 1e-30;
                assert!(
                    (got[k] - want[k]).abs() <= tol,
                    "pixel ({i}, {j}) channel {k}: batched {} vs per-ray {}",
                    got[k],
                    want[k]
                );
            }
            // Misses show the background, 0.1.
            lit += usize::from(want[1] > 0.2);
        }
    }
    assert_eq!(rendered.rays, counts);
    assert!(counts.shadow > 1000, "too few shadow rays: {counts:?}");
    assert!(lit > w * h / 4, "only {lit} lit pixels");
}
