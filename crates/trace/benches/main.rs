//! brtf-trace benchmarks: shading and sampling costs, the virtual
//! gonio-photometer, picture rendering in rays per second, and a
//! head-to-head against real `rtrace` on the same scene and view.
//!
//! `cargo bench -p brtf-trace --bench trace` runs everything; give a
//! filter (`-- vs_rtrace`, `-- shader` ...) to run a part. The rtrace
//! comparison looks for Radiance in `$RADIANCE_BIN`, on `PATH`, then in
//! the repository's `.venv` (pyradiance), and is skipped with a message
//! if there is none.
//!
//! The comparison scene: a ring floor and a sphere with
//! `plastic 0.5 0.5 0.5 0.05 0.1` under a 0.5° distant source; direct
//! light only, one shadow ray per hit (`rtrace -ab 0 -ds 0 -dj 0 -dv- -st 1`
//! vs brtf-trace `Settings::direct_only()`), one ray through each pixel
//! centre of an 800 × 600 view. brtf-trace runs on one thread, rtrace is
//! one process. Rays = camera rays + shadow rays, counted by brtf-trace
//! (rtrace traces the same ones).

use brtf_model::Rng;
use brtf_model::{Composite, EvalOptions, Material, MaterialKind};
use brtf_trace::GonioSetup;
use brtf_trace::RayCounts;
use brtf_trace::{Camera, ImageOptions, Scene, Settings, Shader, Shape, Source, VirtualGonio};
use brtf_trace::{ReflectionLobe, TransmissionLobe};
use criterion::{BenchmarkId, Criterion, Throughput};
use glam::DVec3;
use std::hint::black_box;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

fn plastic() -> Material {
    Material::new(MaterialKind::Plastic, &[0.5, 0.5, 0.5, 0.05, 0.1], None).unwrap()
}

/// The shader of one primitive.
fn shader_of(material: &Material, options: &EvalOptions) -> Shader {
    Shader::new(&Composite::from_material(material), options).unwrap()
}

/// The comparison scene (also written as Radiance text below).
fn scene() -> Scene {
    let mut scene = Scene::new();
    let id = scene.add_shader(shader_of(&plastic(), &EvalOptions::default()));
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
    scene
        .sources
        .push(Source::distant(DVec3::new(0.5, -0.4, 0.7), 0.5, [1e5; 3]));
    scene
}

const SCENE_RAD: &str = "void light sun 0 0 3 1e5 1e5 1e5\n\
sun source s 0 0 4 0.5 -0.4 0.7 0.5\n\
void plastic m 0 0 5 0.5 0.5 0.5 0.05 0.1\n\
m ring floor 0 0 8 0 0 0 0 0 1 0 5\n\
m sphere ball 0 0 4 0 0 1 1\n";

fn camera(width: usize, height: usize) -> Camera {
    Camera::look_at(
        DVec3::new(6.0, -6.0, 4.0),
        DVec3::new(0.0, 0.0, 0.7),
        30.0,
        width as f64 / height as f64,
    )
}

fn bench_shading(c: &mut Criterion) {
    let options = EvalOptions::default();
    let shader = shader_of(&plastic(), &options);
    let mut rng = Rng::new(1, 1);
    let dirs: Vec<(DVec3, DVec3)> = (0..1024)
        .map(|_| {
            let l = brtf_trace::cosine_hemisphere(rng.uniform2(), 1.0);
            let v = brtf_trace::cosine_hemisphere(rng.uniform2(), 1.0);
            (l, v)
        })
        .collect();
    let mut g = c.benchmark_group("shader");
    g.throughput(Throughput::Elements(dirs.len() as u64));
    g.bench_function("eval plastic", |b| {
        b.iter(|| {
            let mut s = 0.0;
            for &(l, v) in &dirs {
                s += shader.eval(l, v, false)[0];
            }
            black_box(s)
        })
    });
    g.bench_function("diffuse part plastic", |b| {
        b.iter(|| {
            let mut s = 0.0;
            for &(l, v) in &dirs {
                s += shader.diffuse(l, v)[0];
            }
            black_box(s)
        })
    });
    let reflect = ReflectionLobe::isotropic(0.1);
    let transmit = TransmissionLobe { beta: 0.01 };
    g.bench_function("sample+pdf reflection lobe", |b| {
        b.iter(|| {
            let mut s = 0.0;
            for (i, &(_, v)) in dirs.iter().enumerate() {
                let u = [(i as f64 + 0.5) / 1024.0, 0.37];
                let l = reflect.sample(v, u);
                s += reflect.pdf(v, l);
            }
            black_box(s)
        })
    });
    g.bench_function("sample+pdf transmission lobe", |b| {
        b.iter(|| {
            let mut s = 0.0;
            for (i, &(_, v)) in dirs.iter().enumerate() {
                let u = [(i as f64 + 0.5) / 1024.0, 0.37];
                let l = transmit.sample(v, u);
                s += transmit.pdf(v, l);
            }
            black_box(s)
        })
    });
    g.finish();
}

fn bench_gonio(c: &mut Criterion) {
    let options = EvalOptions::default();
    let setup = GonioSetup {
        theta_in: 30.0,
        phi_in: 0.0,
        source_omega: brtf_model::cone_solid_angle(1.0),
        detector_omega: brtf_model::cone_solid_angle(1.0),
        samples: 256,
        seed: 1,
    };
    let gonio = VirtualGonio::new(shader_of(&plastic(), &options), setup);
    let v = brtf_model::direction(30.0, 180.0);
    let mut g = c.benchmark_group("gonio");
    g.throughput(Throughput::Elements(256));
    g.bench_function("one direction, 256 samples", |b| {
        b.iter(|| {
            let mut counts = RayCounts::default();
            black_box(gonio.read(black_box(v), 0, &mut counts))
        })
    });
    g.finish();
}

fn bench_image(c: &mut Criterion) {
    let scene = scene();
    let mut g = c.benchmark_group("image");
    for (name, settings) in [
        ("direct only", Settings::direct_only()),
        (
            "specular + diffuse bounce",
            Settings {
                source_samples: 1,
                specular_samples: 1,
                diffuse_samples: 1,
                max_depth: 3,
            },
        ),
    ] {
        let options = ImageOptions {
            width: 160,
            height: 120,
            samples: 1,
            jitter: false,
            seed: 1,
            settings,
        };
        let cam = camera(160, 120);
        let rays = brtf_trace::render(&scene, &cam, &options).rays.total();
        g.throughput(Throughput::Elements(rays));
        g.bench_with_input(BenchmarkId::new("160x120 rays", name), &options, |b, o| {
            b.iter(|| black_box(brtf_trace::render(&scene, &cam, o)))
        });
    }
    g.finish();
}

// ---------------------------------------------------------------------------
// brtf-trace against rtrace
// ---------------------------------------------------------------------------

fn find_radiance() -> Option<(PathBuf, Option<String>)> {
    let has = |d: &Path| d.join("rtrace").is_file() && d.join("oconv").is_file();
    if let Some(d) = std::env::var_os("RADIANCE_BIN").map(PathBuf::from)
        && has(&d)
    {
        return Some((d, None));
    }
    if let Some(path) = std::env::var_os("PATH")
        && let Some(d) = std::env::split_paths(&path).find(|d| has(d))
    {
        return Some((d, None));
    }
    let lib = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../.venv/lib");
    for entry in std::fs::read_dir(lib).ok()?.flatten() {
        let bin = entry.path().join("site-packages/pyradiance/bin");
        if has(&bin) {
            let raypath = format!(".:{}", bin.parent()?.join("lib").display());
            return Some((bin, Some(raypath)));
        }
    }
    None
}

fn vs_rtrace() {
    let Some((bin, raypath)) = find_radiance() else {
        eprintln!("vs_rtrace: Radiance not found (RADIANCE_BIN, PATH, .venv); skipped");
        return;
    };
    let (w, h) = (800usize, 600usize);
    let scene = scene();
    let cam = camera(w, h);
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(dir.path().join("scene.rad"), SCENE_RAD).unwrap();
    let cmd = |program: &str| {
        let mut c = Command::new(bin.join(program));
        c.current_dir(dir.path());
        if let Some(rp) = &raypath {
            c.env("RAYPATH", rp);
        }
        c
    };
    let oct = cmd("oconv").arg("scene.rad").output().expect("oconv");
    assert!(oct.status.success(), "oconv failed");
    std::fs::write(dir.path().join("scene.oct"), &oct.stdout).unwrap();
    let mut input = Vec::with_capacity(w * h * 48);
    for j in 0..h {
        for i in 0..w {
            let r = cam.pixel_ray(i, j, w, h, 0.5, 0.5);
            for x in [
                r.origin.x, r.origin.y, r.origin.z, r.dir.x, r.dir.y, r.dir.z,
            ] {
                input.extend_from_slice(&x.to_ne_bytes());
            }
        }
    }
    // brtf-trace on one thread.
    let options = ImageOptions {
        width: w,
        height: h,
        samples: 1,
        jitter: false,
        seed: 1,
        settings: Settings::direct_only(),
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    // Alternate the two, five runs each, and keep the best of each, so
    // that other load on the machine hits both alike.
    let mut best_ours = f64::INFINITY;
    let mut best_rtrace = f64::INFINITY;
    let mut rays = RayCounts::default();
    for _ in 0..5 {
        let r = pool.install(|| brtf_trace::render(&scene, &cam, &options));
        best_ours = best_ours.min(r.elapsed.as_secs_f64());
        rays = r.rays;

        let start = Instant::now();
        let mut child = cmd("rtrace")
            .args([
                "-h-",
                "-fdd",
                "-ab",
                "0",
                "-ds",
                "0",
                "-dj",
                "0",
                "-dv-",
                "-st",
                "1",
                "scene.oct",
            ])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .expect("rtrace");
        let mut stdin = child.stdin.take().unwrap();
        let data = input.clone();
        let writer = std::thread::spawn(move || stdin.write_all(&data));
        let mut out = Vec::new();
        child.stdout.take().unwrap().read_to_end(&mut out).unwrap();
        child.wait().unwrap();
        writer.join().unwrap().unwrap();
        best_rtrace = best_rtrace.min(start.elapsed().as_secs_f64());
        assert_eq!(out.len(), w * h * 24, "rtrace output");
    }
    let total = rays.total() as f64;
    let ours = total / best_ours;
    let theirs = total / best_rtrace;
    println!(
        "vs_rtrace: {w}x{h} view, {} camera + {} shadow rays\n  \
         brtf-trace (1 thread): {:.3} s, {:.2} M rays/s\n  \
         rtrace     (1 process): {:.3} s, {:.2} M rays/s\n  \
         ratio brtf-trace / rtrace: {:.2}",
        rays.primary,
        rays.shadow,
        best_ours,
        ours / 1e6,
        best_rtrace,
        theirs / 1e6,
        ours / theirs
    );
}

fn main() {
    let filter: Option<String> = std::env::args().skip(1).find(|a| !a.starts_with('-'));
    let wants = |name: &str| {
        filter
            .as_deref()
            .is_none_or(|f| name.contains(f) || f.contains(name))
    };
    let mut c = Criterion::default().configure_from_args();
    bench_shading(&mut c);
    bench_gonio(&mut c);
    bench_image(&mut c);
    c.final_summary();
    if wants("vs_rtrace") {
        vs_rtrace();
    }
}
