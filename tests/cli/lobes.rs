//! Lobe sums (constant `mixfunc` trees of Ward-type primitives) against
//! real Radiance: what rtrace renders equals what brtf computes.
//!
//! * `hand_written_lobe_sums_match_live_rtrace`: `.rad` files written by
//!   hand (a two- and a three-lobe plastic, a two-lobe metal, two-lobe
//!   plastic2 and metal2 with their orientation at 30° in the surface
//!   plane, a lobe of roughness 0 and a mixture of two types), rendered by
//!   rtrace, equal `brtf eval` of the same file within 1e-4 relative on
//!   random directions around and away from the highlight.
//! * `exported_lobe_sum_fits_match_live_rtrace`: the static `<name>.rad` of
//!   two real fits, a two-lobe metal of `data/alu-ggx` and a two-lobe
//!   metal2 (orientation fitted) of a `brtf synth` scan of a metal2 lobe
//!   sum, rendered by rtrace, equal `brtf eval` of that file within 1e-4
//!   relative, and the file holds the fit's material.
//! * `theta_export_of_lobe_sum_fits_matches_live_rtrace`: the
//!   θ_in-dependent `<name>-theta.rad` + `.cal` of the same fits in rtrace
//!   equal brtf-model's lobe sum with the table's parameters at the light's
//!   θ_in, at a measured and an interpolated θ_in.
//!
//! The scene is `export::live`'s (a distant source of 0.01°, one polygon
//! per material), and brtf evaluates with the pyradiance Fresnel constant
//! and the source's solid angle. Run with `-- --nocapture` to see the worst
//! differences.

use crate::common::{self, brtf, close, s, temp_dir};
use crate::export::live::{self, Radiance};
use brtf_fit::FitResult;
use brtf_model::{CompositeBsdf, EvalOptions, Rng, Variant, cone_solid_angle, direction};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// Relative tolerance of every comparison here, and the absolute one for
/// values at or near 0.
const REL: f64 = 1e-4;
const ABS: f64 = 1e-9;

/// The worst differences of a comparison, and the first failures.
#[derive(Default)]
struct Stats {
    values: usize,
    nonzero: usize,
    worst_rel: f64,
    worst_at: String,
    failures: Vec<String>,
    n_failures: usize,
}

impl Stats {
    fn compare(&mut self, brtf: [f64; 3], rtrace: [f64; 3], at: &dyn Fn() -> String) {
        for c in 0..3 {
            let (m, r) = (brtf[c], rtrace[c]);
            self.values += 1;
            if r.abs() >= 1e-6 {
                self.nonzero += 1;
                let e = (m - r).abs() / r.abs();
                if e > self.worst_rel {
                    self.worst_rel = e;
                    self.worst_at = at();
                }
            }
            if !(m.is_finite() && r.is_finite() && close(m, r, REL, ABS)) {
                self.n_failures += 1;
                if self.failures.len() < 20 {
                    self.failures
                        .push(format!("{} channel {c}: brtf {m:e}, rtrace {r:e}", at()));
                }
            }
        }
    }

    #[track_caller]
    fn assert_ok(&self, test: &str) {
        println!(
            "[{test}] {} values ({} non-zero) compared; worst relative difference {:.2e} at {}",
            self.values, self.nonzero, self.worst_rel, self.worst_at
        );
        assert!(
            self.nonzero * 2 > self.values,
            "{test}: too few non-zero values ({} of {})",
            self.nonzero,
            self.values
        );
        assert!(
            self.n_failures == 0,
            "{test}: {} of {} values differ by more than {REL:e} relative and {ABS:e} \
             absolute:\n{}",
            self.n_failures,
            self.values,
            self.failures.join("\n")
        );
    }
}

/// `brtf eval` of `material` (its material `name`, or the file's top one)
/// for the light at (θ_in, φ_in) and the outgoing directions `dirs`.
fn brtf_eval(
    material: &Path,
    name: Option<&str>,
    (theta_in, phi_in): (f64, f64),
    omega: f64,
    dirs: &[(f64, f64)],
) -> Vec<[f64; 3]> {
    let mut args: Vec<String> = vec!["eval".into(), "--material".into(), s(material).into()];
    if let Some(name) = name {
        args.extend(["--name".into(), name.into()]);
    }
    args.extend([
        "--theta-in".into(),
        theta_in.to_string(),
        "--phi-in".into(),
        phi_in.to_string(),
        "--fresnel-k".into(),
        "pyradiance".into(),
        "--source-omega".into(),
        omega.to_string(),
    ]);
    let input: String = dirs.iter().map(|(t, p)| format!("{t},{p}\n")).collect();
    let csv = common::parse_csv(&brtf(&args, &input).ok());
    assert_eq!(csv.rows.len(), dirs.len(), "one row per direction");
    csv.rows.iter().map(|r| [r[2], r[3], r[4]]).collect()
}

/// Outgoing directions (θ_out, φ_out): `n` uniform over the sphere and
/// `n` within `width` radians of the mirror direction, none within 0.5°
/// of grazing.
fn directions(
    rng: &mut Rng,
    (theta_in, phi_in): (f64, f64),
    width: f64,
    n: usize,
) -> Vec<(f64, f64)> {
    let mut dirs = Vec::with_capacity(2 * n);
    while dirs.len() < n {
        let theta = (2.0 * rng.uniform() - 1.0).acos().to_degrees();
        if (theta - 90.0).abs() >= 0.5 {
            dirs.push((theta, 360.0 * rng.uniform()));
        }
    }
    let mirror = direction(theta_in, phi_in + 180.0);
    let (t1, t2) = mirror.any_orthonormal_pair();
    while dirs.len() < 2 * n {
        let (delta, psi) = (
            width * rng.uniform().sqrt(),
            std::f64::consts::TAU * rng.uniform(),
        );
        let v = mirror * delta.cos() + (t1 * psi.cos() + t2 * psi.sin()) * delta.sin();
        let theta = v.z.clamp(-1.0, 1.0).acos().to_degrees();
        if theta < 89.5 {
            dirs.push((theta, v.y.atan2(v.x).to_degrees().rem_euclid(360.0)));
        }
    }
    dirs
}

/// rtrace of the polygons carrying `names` (defined in `files`, in `dir`)
/// for the light at `incidence`, seen from `dirs[k]` for polygon k: the
/// BSDF per direction.
fn rtrace_bsdfs(
    radiance: &Radiance,
    dir: &Path,
    files: &[&str],
    names: &[String],
    incidence: (f64, f64),
    omega: f64,
    dirs: &[Vec<(f64, f64)>],
) -> Vec<Vec<[f64; 3]>> {
    let l = direction(incidence.0, incidence.1);
    std::fs::write(
        dir.join("scene.rad"),
        live::scene(l.to_array(), omega, names),
    )
    .unwrap();
    let mut inputs = files.to_vec();
    inputs.push("scene.rad");
    let warnings = radiance.oconv(dir, &inputs, "scene.oct");
    assert!(warnings.is_empty(), "oconv {inputs:?}: {warnings}");
    let rays: Vec<[f64; 6]> = dirs
        .iter()
        .enumerate()
        .flat_map(|(k, d)| {
            d.iter()
                .map(move |&(t, p)| live::ray(k, direction(t, p).to_array()))
        })
        .collect();
    let (values, stderr) = radiance.trace(dir, "scene.oct", &rays);
    assert!(stderr.is_empty(), "rtrace at {incidence:?}: {stderr}");
    let mut values = values.into_iter();
    dirs.iter()
        .map(|d| {
            d.iter()
                .map(|_| live::bsdf_from_radiance(values.next().unwrap(), omega, l.z))
                .collect()
        })
        .collect()
}

/// The hand-written lobe sums: name, widest roughness, and text. The
/// trees are written in several ways (brtf's nesting, the other order,
/// separate lines or one), as a user might.
const HAND_WRITTEN: &[(&str, f64, &str)] = &[
    (
        "plastic2lobes",
        0.25,
        "void plastic plastic2lobes.1 0 0 5 0.6 0.5 0.4 0.08 0.05
void plastic plastic2lobes.2 0 0 5 0.6 0.5 0.4 0.08 0.25
void mixfunc plastic2lobes
4 plastic2lobes.1 plastic2lobes.2 0.35 .
0
0
",
    ),
    (
        "metal2lobes",
        0.15,
        "# background first: 0.4 of the rough lobe, 0.6 of the sharp one
void metal sharp 0 0 5 0.9 0.8 0.6 0.9 0.03
void metal rough 0 0 5 0.9 0.8 0.6 0.9 0.15
void mixfunc metal2lobes 4 rough sharp 0.4 . 0 0
",
    ),
    (
        "plastic3lobes",
        0.3,
        "void plastic p3a 0 0 5 0.3 0.35 0.5 0.1 0.02
void plastic p3b 0 0 5 0.3 0.35 0.5 0.1 0.1
void plastic p3c 0 0 5 0.3 0.35 0.5 0.1 0.3
void mixfunc p3bc 4 p3b p3c 0.4 . 0 0
void mixfunc plastic3lobes 4 p3a p3bc 0.25 . 0 0
",
    ),
    (
        "aniso_plastic",
        0.2,
        "void plastic2 ap.1
4 0.8660254037844387 0.5 0 .
0
6 0.5 0.45 0.4 0.06 0.05 0.15
void plastic2 ap.2
4 0.8660254037844387 0.5 0 .
0
6 0.5 0.45 0.4 0.06 0.2 0.08
void mixfunc aniso_plastic
4 ap.1 ap.2 0.55 .
0
0
",
    ),
    (
        "aniso_metal",
        0.25,
        "void metal2 am.1
4 0.8660254037844387 0.5 0 .
0
6 0.95 0.7 0.5 0.92 0.03 0.09
void metal2 am.2
4 0.8660254037844387 0.5 0 .
0
6 0.95 0.7 0.5 0.92 0.25 0.12
void mixfunc aniso_metal
4 am.1 am.2 0.7 .
0
0
",
    ),
    (
        // A mirror-smooth lobe (Fresnel-reduced diffuse, its mirror a traced
        // ray that -dv- hides) beside a rough one.
        "smooth_and_rough",
        0.12,
        "void plastic sr.1 0 0 5 0.4 0.5 0.6 0.05 0
void plastic sr.2 0 0 5 0.4 0.5 0.6 0.05 0.12
void mixfunc smooth_and_rough 4 sr.1 sr.2 0.5 . 0 0
",
    ),
    (
        // Not a lobe sum of one type: any constant mixture of primitives.
        "plastic_and_metal2",
        0.2,
        "void plastic pm.1 0 0 5 0.2 0.6 0.3 0.04 0.08
void metal2 pm.2 4 0 1 0 . 0 6 0.8 0.8 0.9 0.95 0.05 0.2
void mixfunc plastic_and_metal2 4 pm.1 pm.2 0.3 . 0 0
",
    ),
];

#[test]
fn hand_written_lobe_sums_match_live_rtrace() {
    const TEST: &str = "hand_written_lobe_sums_match_live_rtrace";
    let Some(radiance) = live::radiance_or_skip(TEST) else {
        return;
    };
    let tmp = temp_dir();
    let text: String = HAND_WRITTEN.iter().map(|(_, _, t)| *t).collect();
    let file = common::write_file(tmp.path(), "lobes.rad", &text);
    let names: Vec<String> = HAND_WRITTEN.iter().map(|(n, _, _)| n.to_string()).collect();
    let omega = cone_solid_angle(live::SOURCE_APEX_DEG);
    let mut rng = Rng::from_state(0x10BE5);
    let mut stats = Stats::default();
    for incidence in [(0.0, 0.0), (25.0, 10.0), (48.0, 200.0), (70.0, 315.0)] {
        let dirs: Vec<Vec<(f64, f64)>> = HAND_WRITTEN
            .iter()
            .map(|(_, width, _)| directions(&mut rng, incidence, 3.0 * width, 24))
            .collect();
        let rtrace = rtrace_bsdfs(
            &radiance,
            tmp.path(),
            &["lobes.rad"],
            &names,
            incidence,
            omega,
            &dirs,
        );
        for (k, name) in names.iter().enumerate() {
            let ours = brtf_eval(&file, Some(name), incidence, omega, &dirs[k]);
            for (i, &(t, p)) in dirs[k].iter().enumerate() {
                stats.compare(ours[i], rtrace[k][i], &|| {
                    format!("`{name}` incidence {incidence:?} view ({t:.4}, {p:.4})")
                });
            }
        }
    }
    stats.assert_ok(TEST);
}

/// Two real lobe-sum fits, made once for the tests that need them.
struct LobeFits {
    /// `brtf fit data/alu-ggx/*.mpc --model metal --lobes 2`: `alu-ggx`.
    alu: PathBuf,
    /// `brtf fit` of `brtf synth --material` scans of a metal2 lobe sum at
    /// θ_in 20° and 50°, `--model metal2 --lobes 2` (orientation fitted):
    /// `brushed`.
    brushed: PathBuf,
}

/// The `.mpc` files of a folder, sorted.
fn mpc_files(dir: &Path) -> Vec<String> {
    let mut files: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "mpc"))
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    files.sort();
    files
}

fn lobe_fits() -> &'static LobeFits {
    static FITS: OnceLock<LobeFits> = OnceLock::new();
    FITS.get_or_init(|| {
        // Under cargo's scratch folder, one per test process.
        let scratch = Path::new(env!("CARGO_TARGET_TMPDIR"));
        let root = scratch.join(format!("lobe-fits-{}", std::process::id()));
        // Earlier runs' folders (a day old) go.
        for entry in std::fs::read_dir(scratch).into_iter().flatten().flatten() {
            let old = entry
                .metadata()
                .and_then(|m| m.modified())
                .ok()
                .and_then(|t| t.elapsed().ok())
                .is_some_and(|age| age.as_secs() > 86_400);
            if old
                && entry
                    .file_name()
                    .to_string_lossy()
                    .starts_with("lobe-fits-")
            {
                let _ = std::fs::remove_dir_all(entry.path());
            }
        }
        let _ = std::fs::remove_dir_all(&root);
        std::fs::create_dir_all(&root).unwrap();

        let alu = root.join("alu");
        let mut args = vec!["fit".to_string()];
        args.extend(mpc_files(&common::repo_path("data/alu-ggx")));
        args.extend(
            [
                "--model",
                "metal",
                "--lobes",
                "2",
                "--no-plots",
                "--out",
                s(&alu),
            ]
            .map(String::from),
        );
        brtf(&args, "").ok();

        let truth = common::write_file(
            &root,
            "brushed-truth.rad",
            "void metal2 brushed.1\n4 0.8660254037844387 0.5 0 .\n0\n6 0.9 0.85 0.8 0.9 0.04 0.12\n\
             void metal2 brushed.2\n4 0.8660254037844387 0.5 0 .\n0\n6 0.9 0.85 0.8 0.9 0.15 0.3\n\
             void mixfunc brushed\n4 brushed.1 brushed.2 0.6 .\n0\n0\n",
        );
        let scans = root.join("brushed-scans");
        brtf(
            &[
                "synth",
                "--material",
                s(&truth),
                "--theta-in",
                "20,50",
                "--prefix",
                "brushed",
                "--out",
                s(&scans),
            ],
            "",
        )
        .ok();
        let brushed = root.join("brushed");
        let mut args = vec!["fit".to_string()];
        args.extend(mpc_files(&scans));
        args.extend(
            [
                "--model",
                "metal2",
                "--lobes",
                "2",
                "--no-plots",
                "--out",
                s(&brushed),
            ]
            .map(String::from),
        );
        brtf(&args, "").ok();
        LobeFits { alu, brushed }
    })
}

#[test]
fn exported_lobe_sum_fits_match_live_rtrace() {
    const TEST: &str = "exported_lobe_sum_fits_match_live_rtrace";
    let Some(radiance) = live::radiance_or_skip(TEST) else {
        return;
    };
    let fits = lobe_fits();
    let omega = cone_solid_angle(live::SOURCE_APEX_DEG);
    let mut rng = Rng::from_state(0xF175);
    let mut stats = Stats::default();
    for (dir, name, lobes, oriented) in [
        (&fits.alu, "alu-ggx", 2, false),
        (&fits.brushed, "brushed", 2, true),
    ] {
        let result = FitResult::read(&dir.join("fit.json")).unwrap();
        let shape = result.config.shape();
        assert_eq!((shape.lobes, shape.oriented), (lobes, oriented), "{name}");
        // The file holds the fit's material: its primitives, then the
        // mixfunc named after it, last.
        let file = dir.join(format!("{name}.rad"));
        let text = std::fs::read_to_string(&file).unwrap();
        let primitives = brtf_radiance::parse_primitives(&text, s(&file)).unwrap();
        let last = primitives.last().unwrap();
        assert_eq!((last.kind.as_str(), last.name.as_str()), ("mixfunc", name));
        let (read_name, material) =
            brtf_radiance::select_composite(&primitives, None, s(&file)).unwrap();
        assert_eq!(read_name, name);
        let fitted = result.static_composite().unwrap();
        assert_eq!(material.components().len(), lobes);
        for ((w, m), (fw, fm)) in material.components().iter().zip(fitted.components()) {
            assert!((w - fw).abs() < 1e-12, "{name}: weight {w} vs {fw}");
            for (a, b) in m.args().iter().zip(fm.args()) {
                assert!(
                    (a - b).abs() < 1e-12,
                    "{name}: {:?} vs {:?}",
                    m.args(),
                    fm.args()
                );
            }
            assert!((m.orientation() - fm.orientation()).length() < 1e-12);
        }
        // The widest roughness (u or v) of any lobe.
        let width = material
            .components()
            .iter()
            .flat_map(|(_, m)| m.args()[4..m.kind().n_args()].to_vec())
            .fold(0.0, f64::max);
        let scene = temp_dir();
        std::fs::copy(&file, scene.path().join("material.rad")).unwrap();
        for incidence in [(0.0, 0.0), (30.0, 0.0), (45.0, 75.0), (65.0, 160.0)] {
            let dirs = vec![directions(&mut rng, incidence, 3.0 * width, 40)];
            let rtrace = rtrace_bsdfs(
                &radiance,
                scene.path(),
                &["material.rad"],
                &[name.to_string()],
                incidence,
                omega,
                &dirs,
            );
            let ours = brtf_eval(&file, None, incidence, omega, &dirs[0]);
            for (i, &(t, p)) in dirs[0].iter().enumerate() {
                stats.compare(ours[i], rtrace[0][i], &|| {
                    format!("{name}.rad incidence {incidence:?} view ({t:.4}, {p:.4})")
                });
            }
        }
    }
    stats.assert_ok(TEST);
}

#[test]
fn theta_export_of_lobe_sum_fits_matches_live_rtrace() {
    const TEST: &str = "theta_export_of_lobe_sum_fits_matches_live_rtrace";
    let Some(radiance) = live::radiance_or_skip(TEST) else {
        return;
    };
    let fits = lobe_fits();
    let omega = cone_solid_angle(live::SOURCE_APEX_DEG);
    let mut rng = Rng::from_state(0x7E7A);
    let mut stats = Stats::default();
    // A measured θ_in and one between two measured ones, each fit.
    for (dir, name, incidences) in [
        (&fits.alu, "alu-ggx", [(45.0, 0.0), (22.5, 30.0)]),
        (&fits.brushed, "brushed", [(50.0, 0.0), (35.0, 120.0)]),
    ] {
        let result = FitResult::read(&dir.join("fit.json")).unwrap();
        let table = result.table.as_ref().expect("a θ_in table");
        let theta_file = format!("{name}-theta.rad");
        let text = std::fs::read_to_string(dir.join(&theta_file)).unwrap();
        assert!(
            text.contains(&format!("void BRTDfunc {name}\n")),
            "{name}: one BRTDfunc sums the lobes:\n{text}"
        );
        let options = EvalOptions {
            source_omega: omega,
            flat: true,
            source_jitter: 0.0,
            ..result.config.options
        };
        assert_eq!(options.variant, Variant::Radiance);
        for incidence in incidences {
            let (material, clamped) = table.composite_at(incidence.0).unwrap();
            assert!(!clamped);
            let bsdf = CompositeBsdf::new(&material, &options);
            let dirs = vec![directions(&mut rng, incidence, 0.9, 40)];
            let rtrace = rtrace_bsdfs(
                &radiance,
                dir,
                &[&theta_file],
                &[name.to_string()],
                incidence,
                omega,
                &dirs,
            );
            let l = direction(incidence.0, incidence.1);
            for (i, &(t, p)) in dirs[0].iter().enumerate() {
                stats.compare(bsdf.eval(l, direction(t, p)), rtrace[0][i], &|| {
                    format!("{theta_file} incidence {incidence:?} view ({t:.4}, {p:.4})")
                });
            }
        }
    }
    stats.assert_ok(TEST);
}

/// A two-lobe plastic, its lobes separately addressable by name.
const TWO: &str = "void plastic two.1 0 0 5 0.6 0.5 0.4 0.08 0.04
void plastic two.2 0 0 5 0.6 0.5 0.4 0.08 0.2
void mixfunc two 4 two.1 two.2 0.3 . 0 0
";

/// `brtf albedo` of a lobe sum is its lobes' albedos weighted, spikes
/// included (a lobe of roughness 0 has a mirror spike).
#[test]
fn albedo_of_a_lobe_sum_weighs_its_lobes() {
    let tmp = temp_dir();
    let smooth = TWO.replace("0.08 0.04", "0.08 0");
    for text in [TWO.to_string(), smooth] {
        let file = common::write_file(tmp.path(), "two.rad", &text);
        let albedo = |name: Option<&str>| {
            let mut args = vec!["albedo", "--material", s(&file), "--theta-in", "0,45,75"];
            if let Some(name) = name {
                args.extend(["--name", name]);
            }
            common::parse_csv(&brtf(&args, "").ok())
        };
        let (whole, one, two) = (albedo(None), albedo(Some("two.1")), albedo(Some("two.2")));
        for column in ["rho_r", "rho_g", "rho_b", "rho_spike", "tau_r"] {
            let (w, a, b) = (whole.column(column), one.column(column), two.column(column));
            for k in 0..3 {
                let expected = 0.3 * a[k] + 0.7 * b[k];
                assert!(
                    (w[k] - expected).abs() <= 5e-5,
                    "{column} row {k}: {} vs {expected}",
                    w[k]
                );
            }
        }
        let spike = whole.column("rho_spike");
        assert_eq!(spike[0] > 0.0, text.contains("0.08 0\n"), "{spike:?}");
    }
}

/// `brtf export --klems --material` reads a mixfunc tree, and
/// `--klems-cal` writes the lobes' sum as one bsdf2klems function.
#[test]
fn klems_of_a_lobe_sum_file() {
    let tmp = temp_dir();
    let file = common::write_file(tmp.path(), "two.rad", TWO);
    let out = brtf(
        &[
            "export",
            "--klems",
            "quarter",
            "--material",
            s(&file),
            "--klems-samples",
            "8",
            "--klems-cal",
        ],
        "",
    )
    .ok();
    assert!(
        out.contains("two.xml") && out.contains("two-bsdf2klems.cal"),
        "{out}"
    );
    let xml = std::fs::read_to_string(tmp.path().join("two.xml")).unwrap();
    assert!(xml.contains("lobe sum (mixfunc of 2 primitives)"), "{xml}");
    let klems = brtf_gonio::klems::read_str(&xml, "two.xml").unwrap();
    assert_eq!(
        klems.matrices.len(),
        4,
        "front and back reflection, Visible and the default Solar"
    );
    let cal = std::fs::read_to_string(tmp.path().join("two-bsdf2klems.cal")).unwrap();
    assert!(
        cal.contains("side(ix,iy,iz,ox,oy,oz) = 2.99999999999999989e-1*side_1(ix,iy,iz,ox,oy,oz)\n    + 6.99999999999999956e-1*side_2("),
        "{cal}"
    );
}

/// `brtf export DIR --klems` of a lobe-sum fit: each incident patch's
/// column total (its hemispherical reflectance) equals the albedo of the
/// fit's lobe sum at the patch's θ_in, within 2 % (patch averaging).
#[test]
fn klems_of_a_lobe_sum_fit_follows_its_albedo() {
    let fits = lobe_fits();
    let tmp = temp_dir();
    brtf(
        &[
            "export",
            s(&fits.alu),
            "--klems",
            "quarter",
            "--out",
            s(tmp.path()),
        ],
        "",
    )
    .ok();
    let xml = std::fs::read_to_string(tmp.path().join("alu-ggx.xml")).unwrap();
    let klems = brtf_gonio::klems::read_str(&xml, "alu-ggx.xml").unwrap();
    let m = klems
        .matrix(
            &brtf_gonio::klems::KlemsBand::Visible,
            brtf_gonio::klems::KlemsDirection::ReflectionBack,
        )
        .unwrap();
    let lambda = klems.basis.projected_solid_angles();
    let result = FitResult::read(&fits.alu.join("fit.json")).unwrap();
    let table = result.table.as_ref().unwrap();
    let options = EvalOptions {
        source_omega: 0.0,
        ..result.config.options
    };
    let n = m.n;
    let mut checked = 0;
    let mut worst = 0.0f64;
    for (i, patch) in klems.basis.patches().iter().enumerate() {
        if patch.theta_deg > 60.0 {
            continue;
        }
        let total: f64 = (0..n).map(|o| m.values[o * n + i] * lambda[o]).sum();
        let (material, _) = table.composite_at(patch.theta_deg).unwrap();
        let bsdf = CompositeBsdf::new(&material, &options);
        let a = brtf_model::composite_albedo(&bsdf, direction(patch.theta_deg, 0.0), 1e-5);
        let rho = brtf_model::luminance(a.rho);
        assert!(
            (total - rho).abs() <= 0.02 * rho,
            "patch {i} (θ {}): Klems {total} vs albedo {rho}",
            patch.theta_deg
        );
        worst = worst.max((total - rho).abs() / rho);
        checked += 1;
    }
    println!(
        "Klems column totals of {checked} incident patches: worst {worst:.2e} from the albedo"
    );
    assert!(checked > 10);
}

/// `brtf synth --material` of a metal2 lobe sum, fitted back as one:
/// the truth's weights, roughnesses and orientation come back.
#[test]
fn synth_of_a_lobe_sum_fits_back_to_its_truth() {
    let fits = lobe_fits();
    let result = FitResult::read(&fits.brushed.join("fit.json")).unwrap();
    let m = result.static_composite().unwrap();
    let near = |a: f64, b: f64| (a - b).abs() <= 0.02 * b;
    let (w1, m1) = m.components()[0];
    let (w2, m2) = m.components()[1];
    assert!(near(m1.args()[3], 0.9), "spec {:?}", m1.args());
    // The lobes come ordered by roughness: the truth's 0.6 lobe first.
    assert!(near(w1, 0.6) && near(w2, 0.4), "weights {w1} {w2}");
    // u and v may swap with a quarter turn of the orientation.
    let o = m1.orientation();
    let turn = (o.y.atan2(o.x).to_degrees() - 30.0).rem_euclid(180.0);
    let swapped = (turn - 90.0).abs() < 0.5;
    assert!(
        swapped || !(0.5..=179.5).contains(&turn),
        "orientation {o:?}"
    );
    let (u, v) = if swapped { (5, 4) } else { (4, 5) };
    for (lobe, truth) in [(m1, [0.04, 0.12]), (m2, [0.15, 0.3])] {
        let a = lobe.args();
        assert!(
            near(a[u], truth[0]) && near(a[v], truth[1]),
            "{a:?} vs {truth:?}"
        );
    }
}
