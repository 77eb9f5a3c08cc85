//! Radiance text printed by brtf parses back to the same primitives.

use brtf_radiance::{format_primitive, parse_primitives};

#[test]
fn printed_primitives_parse_back_aliases_included() {
    let text = "void plastic red 0 0 5 0.5 0.1 0.1 0 0\nvoid alias shiny red\nred sphere ball 0 0 4 0 0 1 1\n";
    let prims = parse_primitives(text, "a.rad").unwrap();
    let printed: String = prims.iter().map(format_primitive).collect();
    assert!(printed.contains("void alias shiny red\n"), "{printed}");
    let again = parse_primitives(&printed, "b.rad").unwrap();
    assert_eq!(again.len(), prims.len());
    for (a, b) in prims.iter().zip(&again) {
        assert_eq!(
            (&a.modifier, &a.kind, &a.name, &a.strings, &a.ints, &a.reals),
            (&b.modifier, &b.kind, &b.name, &b.strings, &b.ints, &b.reals)
        );
    }
}
