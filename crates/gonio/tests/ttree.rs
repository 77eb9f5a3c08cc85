//! Tensor trees: real files written by Radiance's `bsdf2ttree` from a
//! known function (`fixtures/ttree/asym.cal`), read back leaf by leaf, and
//! the reader's errors.

use std::path::{Path, PathBuf};

use brtf_gonio::klems::ttree::square::square_to_disk;
use brtf_gonio::klems::{self, BsdfXml, KlemsBand, KlemsDirection, Side, TensorTree, TreeRank};
use brtf_gonio::{KlemsProblem, ParseErrorKind, TreeProblem};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/ttree")
        .join(name)
}

fn tree(name: &str) -> TensorTree {
    match klems::read_any_path(&fixture(name)).unwrap() {
        BsdfXml::TensorTree(t) => t,
        BsdfXml::Klems(_) => panic!("{name} read as a Klems matrix"),
    }
}

/// The function of `asym.cal`: i towards the source, o towards the viewer.
fn asym(i: [f64; 3], o: [f64; 3]) -> f64 {
    if i[2] * o[2] > 0.0 {
        1.0 + 0.5 * i[0] + 0.25 * o[1]
    } else {
        2.0 + 0.5 * i[1] + 0.25 * o[0]
    }
}

fn on_side(d: [f64; 2], z_sign: f64) -> [f64; 3] {
    let z = (1.0 - d[0] * d[0] - d[1] * d[1]).max(0.0).sqrt();
    [d[0], d[1], z_sign * z]
}

/// Each finest leaf of the anisotropic transmission tree holds the
/// function at its centre: input square point p is the incident direction
/// −disk(p) (towards the source), output square point q is disk(q).
#[test]
fn anisotropic_leaves_hold_the_function_at_their_centres() {
    let t = tree("asym-t4-g3.xml");
    assert_eq!(t.rank, TreeRank::Anisotropic);
    let block = t
        .block(&KlemsBand::Visible, KlemsDirection::TransmissionBack)
        .unwrap();
    let finest = 0.5f64.powi(block.depth as i32);
    let mut checked = 0;
    let mut worst: f64 = 0.0;
    for c in block.cells.iter().filter(|c| c.size == finest) {
        let h = 0.5 * c.size;
        let d_in = square_to_disk(c.min[0] + h, c.min[1] + h);
        let i = on_side([-d_in[0], -d_in[1]], 1.0);
        let o = on_side(square_to_disk(c.min[2] + h, c.min[3] + h), -1.0);
        let expected = asym(i, o);
        worst = worst.max((c.value - expected).abs());
        checked += 1;
    }
    eprintln!("{checked} leaves, worst difference {worst:.2e}");
    assert!(
        checked > 100 && worst < 2e-3,
        "{checked} leaves, worst {worst}"
    );
}

/// The isotropic tree: input x₀ = ½ − ½ sin θ_in with the source at
/// φ = 180°, the outgoing square not turned.
#[test]
fn isotropic_leaves_hold_the_function_at_their_centres() {
    let t = tree("asym-t3-g4.xml");
    assert_eq!(t.rank, TreeRank::Isotropic);
    for (direction, z_sign) in [
        (KlemsDirection::ReflectionBack, 1.0),
        (KlemsDirection::TransmissionBack, -1.0),
    ] {
        let block = t.block(&KlemsBand::Visible, direction).unwrap();
        let finest = 0.5f64.powi(block.depth as i32);
        let mut worst: f64 = 0.0;
        let mut checked = 0;
        for c in block
            .cells
            .iter()
            .filter(|c| c.size == finest && c.min[0] < 0.5)
        {
            let h = 0.5 * c.size;
            let s = 1.0 - 2.0 * (c.min[0] + h);
            let i = [-s, 0.0, (1.0 - s * s).sqrt()];
            let o = on_side(square_to_disk(c.min[1] + h, c.min[2] + h), z_sign);
            worst = worst.max((c.value - asym(i, o)).abs());
            checked += 1;
        }
        eprintln!("{direction}: {checked} leaves, worst difference {worst:.2e}");
        // bsdf2ttree puts the incident direction ±1/32 off the plane in y.
        assert!(checked > 100 && worst < 0.02, "{direction}: worst {worst}");
    }
}

/// The totals Radiance's `checkBSDF` printed for these two files (Radiance
/// 6.0a, pyradiance 1.3.1): per component the Lambertian part and the
/// largest directional total, each to 0.1 %.
#[test]
fn totals_match_check_bsdf() {
    for (name, direction, lambertian, max_total) in [
        (
            "asym-t4-g3.xml",
            KlemsDirection::ReflectionBack,
            1.093,
            4.268,
        ),
        (
            "asym-t4-g3.xml",
            KlemsDirection::TransmissionBack,
            0.0,
            7.410,
        ),
        (
            "asym-t3-g4.xml",
            KlemsDirection::ReflectionBack,
            0.934,
            2.945,
        ),
        (
            "asym-t3-g4.xml",
            KlemsDirection::TransmissionBack,
            0.0,
            6.291,
        ),
    ] {
        let t = tree(name);
        let block = t.block(&KlemsBand::Visible, direction).unwrap();
        let (l, m) = (block.lambertian(t.rank), block.max_total(t.rank));
        eprintln!(
            "{name} {direction}: Lambertian {l:.4} ({lambertian}), max total {m:.4} ({max_total})"
        );
        assert!((l - lambertian).abs() <= 1e-3, "{name} {direction}: {l}");
        assert!((m - max_total).abs() <= 1e-3, "{name} {direction}: {m}");
    }
}

/// A one-sided tree made with the function's +z front: the front side only.
#[test]
fn sides_blocks_and_measurements() {
    let t = tree("asym-t3-g4.xml");
    assert_eq!(t.sides_present(), vec![Side::Front]);
    let (m, places) = t.measurement(Side::Front, 30.0, 0.0).unwrap();
    assert_eq!(m.samples.len(), places.len());
    // The incidence moves to the centre of its finest input cell (x₀ in
    // sixteenths: sin θ in eighths).
    let s = m.incidence.theta_deg.to_radians().sin();
    assert!((s - 0.4375).abs() < 1e-6, "{}", m.incidence.theta_deg);
    // Σ value · dΩ · cos θ over the samples gives the block totals.
    let (rho, tau) = t.totals(Side::Front, m.incidence.theta_deg, 0.0);
    let sum = |transmitted: bool| -> f64 {
        m.samples
            .iter()
            .filter(|s| (s.theta_deg > 90.0) == transmitted)
            .map(|s| s.values[0] * s.solid_angle_sr.unwrap() * s.abs_cos_theta())
            .sum()
    };
    assert!((sum(false) - rho.unwrap()).abs() < 1e-9);
    assert!((sum(true) - tau.unwrap()).abs() < 1e-9);
    assert!(t.measurement(Side::Back, 30.0, 0.0).is_none());
}

/// The error of reading `text` as `name`: message, line and problem.
fn tree_error(text: &str, name: &str) -> (String, usize, KlemsProblem) {
    let e = klems::read_any_bytes(text.as_bytes(), name).unwrap_err();
    let line = e.line().unwrap();
    let Some(ParseErrorKind::Klems { problem, .. }) = e.kind() else {
        panic!("not a Klems error: {e}");
    };
    (e.to_string(), line, problem.clone())
}

#[test]
fn bad_trees_are_refused_with_file_line_and_problem() {
    let text = std::fs::read_to_string(fixture("asym-t3-g4.xml")).unwrap();
    // A value on its own line, the first leaf grid's.
    let (index, line) = text
        .lines()
        .enumerate()
        .find(|(_, l)| l.trim_start().starts_with("{ ") && l.trim_end().ends_with(" }"))
        .unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let first = line.split_whitespace().nth(1).unwrap().to_string();
    lines[index] = line.replacen(&first, "oops", 1);
    let (message, at, problem) = tree_error(&lines.join("\n"), "bad.xml");
    assert_eq!(at, index + 1, "{message}");
    assert!(
        message.starts_with(&format!(
            "bad.xml:{}: <ScatteringData>: Visible Reflection Back: `oops`",
            index + 1
        )),
        "{message}"
    );
    assert!(matches!(
        problem,
        KlemsProblem::Tree {
            problem: TreeProblem::NotANumber(_),
            ..
        }
    ));

    lines[index] = line.replacen(&first, "-0.5", 1);
    let (message, at, _) = tree_error(&lines.join("\n"), "bad.xml");
    assert_eq!(at, index + 1, "{message}");
    assert!(message.contains("value -0.5 is negative"), "{message}");

    lines[index] = line.replacen(&first, "", 1);
    let (message, _, problem) = tree_error(&lines.join("\n"), "bad.xml");
    assert!(
        matches!(
            problem,
            KlemsProblem::Tree {
                problem: TreeProblem::ValueCount { rank: 3, .. },
                ..
            }
        ),
        "{message}"
    );

    let cut = text.rfind('}').unwrap();
    let (message, _, problem) =
        tree_error(&format!("{}{}", &text[..cut], &text[cut + 1..]), "cut.xml");
    assert!(
        matches!(
            problem,
            KlemsProblem::Tree {
                problem: TreeProblem::Syntax(_),
                ..
            }
        ),
        "{message}"
    );

    let other = text.replacen("LBNL/Shirley-Chiu", "LBNL/Klems Full", 1);
    let (message, _, problem) = tree_error(&other, "basis.xml");
    assert_eq!(
        problem,
        KlemsProblem::TreeBasis("LBNL/Klems Full".into()),
        "{message}"
    );

    // The matrix reader names the kind instead of misreading it.
    let e = klems::read_bytes(text.as_bytes(), "t.xml").unwrap_err();
    assert!(
        e.to_string().contains("a tensor tree (`TensorTree3`)"),
        "{e}"
    );
}
