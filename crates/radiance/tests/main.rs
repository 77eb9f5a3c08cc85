//! brtf-radiance integration tests: primitives here, exports in `export`.

mod composite;
mod export;
mod klems;
mod primitive;

use brtf_model::MaterialKind;
use brtf_radiance::{
    format_primitive, material_from_primitive, parse_primitives, primitive_from_material,
    select_material,
};

const SCENE: &str = "# a comment line
void metal alu 0 0 5 .8 .8 .8 .7 .15   # trailing comment

void plastic2 painted
4 1 0 0 .
0
6 0.5 0.4 0.3 0.05 0.02 0.1
void light lamp 0 0 3 100 100 100
";

#[test]
fn parses_materials_with_comments_and_several_primitives() {
    let prims = parse_primitives(SCENE, "scene.rad").unwrap();
    assert_eq!(prims.len(), 3);
    assert_eq!(prims[1].line, 4);
    let alu = material_from_primitive(&prims[0], "scene.rad").unwrap();
    assert_eq!(alu.kind(), MaterialKind::Metal);
    assert_eq!(alu.args(), &[0.8, 0.8, 0.8, 0.7, 0.15]);
    let painted = material_from_primitive(&prims[1], "scene.rad").unwrap();
    assert_eq!(painted.kind(), MaterialKind::Plastic2);
    assert_eq!(painted.orientation(), glam::DVec3::X);
}

#[test]
fn selects_by_name_or_refuses_ambiguity() {
    let prims = parse_primitives(SCENE, "scene.rad").unwrap();
    let (name, m) = select_material(&prims, Some("painted"), "scene.rad").unwrap();
    assert_eq!(
        (name.as_str(), m.kind()),
        ("painted", MaterialKind::Plastic2)
    );
    let err = select_material(&prims, None, "scene.rad").unwrap_err();
    assert!(err.to_string().contains("alu, painted"), "{err}");
    let err = select_material(&prims, Some("lamp"), "scene.rad").unwrap_err();
    assert!(err.to_string().contains("is a light"), "{err}");
}

#[test]
fn round_trips_through_text() {
    let prims = parse_primitives(SCENE, "scene.rad").unwrap();
    for p in &prims[..2] {
        let m = material_from_primitive(p, "x").unwrap();
        let text = format_primitive(&primitive_from_material(&m, &p.name));
        let again = parse_primitives(&text, "x").unwrap();
        assert_eq!(material_from_primitive(&again[0], "x").unwrap(), m);
    }
    insta::assert_snapshot!(format_primitive(&prims[0]), @r"
    void metal alu
    0
    0
    5 0.8 0.8 0.8 0.7 0.15
    ");
}

#[test]
fn errors_name_file_line_and_problem() {
    let cases = [
        (
            "void metal a 0 0 4 .8 .8 .8 .7\n",
            "m.rad:1:",
            "takes 5 real arguments, found 4",
        ),
        (
            "\nvoid metal a 0 0 5 .8 .8 x .7 .1\n",
            "m.rad:2:",
            "real argument `x` is not a number",
        ),
        (
            "void metall a 0 0 5 .8 .8 .8 .7 .1\n",
            "m.rad:1:",
            "unknown primitive type `metall`",
        ),
        (
            "void metal a 0 0 5 .8 .8\n",
            "m.rad:1:",
            "declares 5 real arguments",
        ),
        (
            "void metal a\n0\n0\nfive\n",
            "m.rad:4:",
            "number of real arguments",
        ),
        (
            "void metal2 b 4 1 0 0 . 0 5 .8 .8 .8 .7 .1\n",
            "m.rad:1:",
            "takes 6 real arguments",
        ),
        (
            "void metal2 b 4 A B C . 0 6 .8 .8 .8 .7 .1 .1\n",
            "m.rad:1:",
            "numeric constant",
        ),
        ("!gensurf a b\n", "m.rad:1:", "inline commands"),
    ];
    for (text, location, problem) in cases {
        let err = parse_primitives(text, "m.rad")
            .and_then(|p| material_from_primitive(&p[0], "m.rad").map(|_| ()))
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with(location) && err.contains(problem),
            "{text:?}: got `{err}`"
        );
    }
}
