//! Lobe sums as Radiance text: constant mixfunc trees read into a
//! `Composite` (`select_composite`) and written back
//! (`composite_primitives`), and the located errors of trees brtf cannot
//! read.

use brtf_model::{Composite, Material, MaterialKind, Shape};
use brtf_radiance::{
    MAX_MIXTURE_PARTS, Primitive, composite_primitives, format_primitive, parse_primitives,
    select_composite,
};
use glam::DVec3;

/// The text of `primitives`, one blank line between them.
fn text_of(primitives: &[Primitive]) -> String {
    primitives
        .iter()
        .map(format_primitive)
        .collect::<Vec<_>>()
        .join("\n")
}

/// Asserts two materials have the same weighted primitives to 1e-12.
#[track_caller]
fn assert_same(a: &Composite, b: &Composite) {
    assert_eq!(a.components().len(), b.components().len(), "{a:?}\n{b:?}");
    for ((wa, ma), (wb, mb)) in a.components().iter().zip(b.components()) {
        assert!((wa - wb).abs() <= 1e-12, "weights {wa} {wb}");
        assert_eq!(ma.kind(), mb.kind());
        for (x, y) in ma.args().iter().zip(mb.args()) {
            assert!((x - y).abs() <= 1e-12, "{:?} vs {:?}", ma.args(), mb.args());
        }
        assert!((ma.orientation() - mb.orientation()).length() <= 1e-12);
    }
}

fn shape(kind: MaterialKind, lobes: usize, oriented: bool) -> Shape {
    Shape::new(kind, lobes, oriented).unwrap()
}

#[test]
fn lobe_sums_round_trip_through_text() {
    let o = Some(DVec3::new(0.3, 1.0, 0.0));
    let cases: Vec<(Composite, usize)> = vec![
        (
            Composite::new(
                shape(MaterialKind::Plastic, 2, false),
                &[0.6, 0.5, 0.4, 0.08, 0.35, 0.05, 0.25],
                None,
            )
            .unwrap(),
            3,
        ),
        (
            Composite::new(
                shape(MaterialKind::Metal, 3, false),
                &[0.9, 0.8, 0.6, 0.9, 0.1 + 0.2, 1.0 / 3.0, 0.02, 0.1, 0.3],
                None,
            )
            .unwrap(),
            5,
        ),
        (
            Composite::new(
                shape(MaterialKind::Plastic2, 2, false),
                &[0.5, 0.45, 0.4, 0.06, 0.55, 0.05, 0.15, 0.2, 0.08],
                o,
            )
            .unwrap(),
            3,
        ),
        // Weights 1 and 0: both lobes stay in the file and come back.
        (
            Composite::new(
                shape(MaterialKind::Metal, 2, false),
                &[0.9, 0.9, 0.9, 0.95, 1.0, 0.05, 0.2],
                None,
            )
            .unwrap(),
            3,
        ),
        (
            Composite::new(
                shape(MaterialKind::Plastic, 1, false),
                &[0.5, 0.4, 0.3, 0.05, 0.1],
                None,
            )
            .unwrap(),
            1,
        ),
    ];
    for (material, count) in cases {
        let primitives = composite_primitives(&material, "m");
        assert_eq!(primitives.len(), count);
        // The material itself is defined last, under its own name.
        let last = primitives.last().unwrap();
        assert_eq!(last.name, "m");
        let text = text_of(&primitives);
        let parsed = parse_primitives(&text, "m.rad").unwrap();
        let (name, again) = select_composite(&parsed, None, "m.rad").unwrap();
        assert_eq!(name, "m");
        assert_same(&again, &material);
        // Recognised as the same shape, its arguments to 1e-12.
        assert_eq!(again.shape(), material.shape(), "{text}");
        for (x, y) in again.args().unwrap().iter().zip(material.args().unwrap()) {
            assert!((x - y).abs() <= 1e-12, "{x} {y}");
        }
    }
}

#[test]
fn three_lobes_nest_as_the_splits_say() {
    let material = Composite::new(
        shape(MaterialKind::Plastic, 3, false),
        &[0.3, 0.35, 0.5, 0.1, 0.25, 0.4, 0.02, 0.1, 0.3],
        None,
    )
    .unwrap();
    let text = text_of(&composite_primitives(&material, "p3"));
    let expected = "void mixfunc p3.mix2\n4 p3.2 p3.3 0.4 .\n0\n0\n\n\
                    void mixfunc p3\n4 p3.1 p3.mix2 0.25 .\n0\n0\n";
    assert!(text.ends_with(expected), "{text}");
    assert!(text.starts_with("void plastic p3.1\n0\n0\n5 0.3 0.35 0.5 0.1 0.02\n"));
    let weights: Vec<f64> = material.components().iter().map(|(w, _)| *w).collect();
    assert_eq!(weights, [0.25, 0.75 * 0.4, 0.75 * 0.6]);
}

#[test]
fn an_oriented_lobe_sum_comes_back_as_its_primitives() {
    // The fitted angle is not in the file: the primitives carry its vector.
    let material = Composite::new(
        shape(MaterialKind::Metal2, 2, true),
        &[0.95, 0.7, 0.5, 0.92, 0.7, 0.03, 0.09, 0.25, 0.12, 30.0],
        None,
    )
    .unwrap();
    let text = text_of(&composite_primitives(&material, "brushed"));
    let parsed = parse_primitives(&text, "b.rad").unwrap();
    let (_, again) = select_composite(&parsed, None, "b.rad").unwrap();
    assert_same(&again, &material);
    let o = again.components()[0].1.orientation();
    assert!((o - DVec3::new(0.75f64.sqrt(), 0.5, 0.0)).length() < 1e-15);
    assert_eq!(again.shape(), Some(shape(MaterialKind::Metal2, 2, false)));
}

#[test]
fn any_mixture_of_primitives_round_trips() {
    let plastic = Material::new(MaterialKind::Plastic, &[0.2, 0.6, 0.3, 0.04, 0.08], None).unwrap();
    let metal2 = Material::new(
        MaterialKind::Metal2,
        &[0.8, 0.8, 0.9, 0.95, 0.05, 0.2],
        Some(DVec3::Y),
    )
    .unwrap();
    let trans = Material::new(
        MaterialKind::Trans,
        &[0.6, 0.7, 0.8, 0.05, 0.1, 0.5, 0.6],
        None,
    )
    .unwrap();
    let mixture = Composite::mixture(vec![(0.2, plastic), (0.5, metal2), (0.3, trans)]).unwrap();
    assert_eq!(mixture.shape(), None);
    let text = text_of(&composite_primitives(&mixture, "mix"));
    let parsed = parse_primitives(&text, "x.rad").unwrap();
    let (_, again) = select_composite(&parsed, Some("mix"), "x.rad").unwrap();
    assert_same(&again, &mixture);
}

const SCENE: &str = "# a lobe sum with a light and a surface around it
void light lamp 0 0 3 10 10 10
void plastic shiny.1 0 0 5 0.5 0.5 0.5 0.05 0.05
void plastic shiny.2 0 0 5 0.5 0.5 0.5 0.05 0.2
void alias shiny.rough shiny.2
void mixfunc shiny 4 shiny.1 shiny.rough 0.25 . 0 0
shiny polygon floor 0 0 12 0 0 0 1 0 0 1 1 0 0 1 0
";

#[test]
fn the_top_material_is_chosen_and_names_pick_any() {
    let prims = parse_primitives(SCENE, "s.rad").unwrap();
    let (name, m) = select_composite(&prims, None, "s.rad").unwrap();
    assert_eq!(name, "shiny");
    let weights: Vec<f64> = m.components().iter().map(|(w, _)| *w).collect();
    assert_eq!(weights, [0.25, 0.75]);
    assert_eq!(m.components()[1].1.args()[4], 0.2, "through the alias");
    assert_eq!(m.shape(), Some(shape(MaterialKind::Plastic, 2, false)));
    // A leaf by name: one primitive.
    let (name, leaf) = select_composite(&prims, Some("shiny.1"), "s.rad").unwrap();
    assert_eq!(name, "shiny.1");
    assert_eq!(leaf.single().unwrap().args()[4], 0.05);
    // A second top material makes the choice ambiguous.
    let two = format!("{SCENE}void metal other 0 0 5 0.9 0.9 0.9 0.9 0.1\n");
    let prims = parse_primitives(&two, "s.rad").unwrap();
    let err = select_composite(&prims, None, "s.rad").unwrap_err();
    assert_eq!(err.line, 8);
    assert!(
        err.to_string().contains("several materials (shiny, other)"),
        "{err}"
    );
    let err = select_composite(&prims, Some("lamp"), "s.rad").unwrap_err();
    assert!(err.to_string().starts_with("s.rad:2: "), "{err}");
    assert!(err.to_string().contains("is a light"), "{err}");
    let err = select_composite(&prims, Some("nothing"), "s.rad").unwrap_err();
    assert!(err.to_string().contains("no primitive named `nothing`"));
}

#[test]
fn names_refer_to_the_last_definition_before_their_use() {
    // `a` is redefined after the mixfunc: the mixture keeps the first.
    let text = "void plastic a 0 0 5 0.5 0.5 0.5 0.05 0.1
void plastic b 0 0 5 0.5 0.5 0.5 0.05 0.3
void mixfunc m 4 a b 0.5 . 0 0
void plastic a 0 0 5 0.1 0.1 0.1 0.05 0.1
";
    let prims = parse_primitives(text, "r.rad").unwrap();
    let (_, m) = select_composite(&prims, Some("m"), "r.rad").unwrap();
    assert_eq!(m.components()[0].1.args()[0], 0.5);
}

#[test]
fn unreadable_trees_fail_with_file_line_and_reason() {
    let leaves = "void plastic a 0 0 5 0.5 0.5 0.5 0.05 0.1\n\
                  void plastic b 0 0 5 0.5 0.5 0.5 0.05 0.3\n";
    let cases: Vec<(String, &str, &str)> = vec![
        (
            format!("{leaves}void mixfunc m 4 a b x/2 . 0 0\n"),
            "t.rad:3:",
            "mixfunc `m`: the coefficient `x/2` is not a number: brtf reads only constant",
        ),
        (
            format!("{leaves}void mixfunc m 4 a b .5 mix.cal 0 0\n"),
            "t.rad:3:",
            "function file `mix.cal`",
        ),
        (
            format!("{leaves}void mixfunc m 5 a b .5 . -rz 0 0\n"),
            "t.rad:3:",
            "takes 4 string arguments",
        ),
        (
            format!("{leaves}void mixfunc m 4 a b .5 . 0 1 2\n"),
            "t.rad:3:",
            "0 integer and 0 real arguments, found 0 and 1",
        ),
        (
            format!("{leaves}\nvoid mixfunc m 4 a b 1.5 . 0 0\n"),
            "t.rad:4:",
            "the coefficient 1.5 is outside [0, 1]",
        ),
        (
            format!("{leaves}void mixfunc m 4 a c .5 . 0 0\n"),
            "t.rad:3:",
            "no material `c` before it",
        ),
        (
            format!("{leaves}void glass g 0 0 3 .9 .9 .9\nvoid mixfunc m 4 a g .5 . 0 0\n"),
            "t.rad:3:",
            "`g` is a glass, not one of plastic",
        ),
        (
            format!("{leaves}void mixfunc m 4 void b .5 . 0 0\n"),
            "t.rad:3:",
            "`void` (no material) cannot be part of a mixture",
        ),
        (
            format!("{leaves}void mixfunc m 4 a c .5 . 0 0\nvoid plastic c 0 0 5 .5 .5 .5 0 0\n"),
            "t.rad:3:",
            "`c` is defined only after it (line 4)",
        ),
        (
            format!(
                "{leaves}void mixfunc x 4 a y .5 . 0 0\nvoid mixfunc y 4 b x .5 . 0 0\n\
                 void mixfunc m 4 a y .5 . 0 0\n"
            ),
            "t.rad:3:",
            "its materials refer back to it (x -> y -> x)",
        ),
        (
            "void metal a 0 0 5 .9 .9 .9 .9 .1\nvoid metal b 0 0 4 .9 .9 .9 .9\n\
             void mixfunc m 4 a b .5 . 0 0\n"
                .into(),
            "t.rad:2:",
            "metal `b` takes 5 real arguments, found 4",
        ),
    ];
    for (text, location, problem) in cases {
        let err = parse_primitives(&text, "t.rad")
            .and_then(|p| select_composite(&p, Some("m"), "t.rad"))
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with(location) && err.contains(problem),
            "{text}\ngot `{err}`, expected `{location}` … `{problem}`"
        );
    }
}

#[test]
fn a_tree_that_expands_too_far_is_refused() {
    // Each level uses the previous one twice: 2^8 leaves.
    let mut text = String::from("void plastic l0 0 0 5 .5 .5 .5 .05 .1\n");
    for k in 1..=8 {
        text += &format!("void mixfunc l{k} 4 l{} l{} .5 . 0 0\n", k - 1, k - 1);
    }
    let prims = parse_primitives(&text, "deep.rad").unwrap();
    let err = select_composite(&prims, None, "deep.rad").unwrap_err();
    assert!(
        err.to_string()
            .contains(&format!("more than {MAX_MIXTURE_PARTS} primitives")),
        "{err}"
    );
    // Five levels (32 leaves) are fine: the same plastic, weights summing to 1.
    let prims = parse_primitives(&text, "deep.rad").unwrap();
    let (_, m) = select_composite(&prims, Some("l5"), "deep.rad").unwrap();
    assert_eq!(m.components().len(), 32);
    let sum: f64 = m.components().iter().map(|(w, _)| w).sum();
    assert!((sum - 1.0).abs() < 1e-15);
}
