//! The chart files: every one exists, PNGs decode at the SVG's size, SVGs
//! carry their axis titles and one series per incidence, text is drawn.

use crate::common::{TAGS, decode_png, drawn, svg_size};

/// Stems of every chart of the data set and their sizes in pixels.
fn expected() -> Vec<(String, (u32, u32))> {
    let mut v = Vec::new();
    for tag in TAGS {
        v.push((format!("map-{tag}"), (990, 684)));
        v.push((format!("cut-{tag}"), (1000, 640)));
    }
    v.push(("params".into(), (1300, 924)));
    v.push(("rho".into(), (1000, 640)));
    v.push(("rms".into(), (1000, 560)));
    v.push(("cuts".into(), (1000, 640)));
    v
}

fn svg(stem: &str) -> String {
    std::fs::read_to_string(drawn().path(&format!("plots/{stem}.svg"))).unwrap()
}

#[test]
fn every_chart_exists_as_svg_and_png_and_nothing_else_is_left() {
    let d = drawn();
    let mut names: Vec<String> = std::fs::read_dir(d.path("plots"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let mut want: Vec<String> = expected()
        .iter()
        .flat_map(|(s, _)| [format!("{s}.png"), format!("{s}.svg")])
        .collect();
    want.sort();
    assert_eq!(
        names, want,
        "plots/ holds exactly the charts (no temporary files)"
    );
    assert!(d.path("report.html").is_file());
    assert_eq!(d.written.report, d.path("report.html"));
    assert_eq!(d.written.files.len(), want.len() + 1);
    assert!(d.written.warnings.is_empty(), "{:?}", d.written.warnings);
}

#[test]
fn pngs_decode_at_the_size_of_their_svg() {
    for (stem, size) in expected() {
        let (w, h, pixels, channels) = decode_png(&drawn().path(&format!("plots/{stem}.png")));
        assert_eq!((w, h), size, "{stem}.png");
        assert_eq!(svg_size(&svg(&stem)), size, "{stem}.svg");
        assert_eq!(pixels.len(), (w * h) as usize * channels);
    }
}

#[test]
fn png_text_is_drawn_with_the_embedded_font() {
    // The title occupies the top rows: dark anti-aliased glyph pixels there.
    for stem in ["rms", "map-t30", "cut-t30"] {
        let (w, _, pixels, channels) = decode_png(&drawn().path(&format!("plots/{stem}.png")));
        let dark = pixels[..(w as usize * 30 * channels)]
            .chunks(channels)
            .filter(|p| p[..3].iter().all(|&c| c < 90))
            .count();
        assert!(
            dark > 200,
            "{stem}: only {dark} dark pixels in the title rows"
        );
    }
}

#[test]
fn svgs_carry_their_axis_titles() {
    for tag in TAGS {
        let cut = svg(&format!("cut-{tag}"));
        for text in [
            "θ_out in the plane of incidence [°]",
            "BSDF [1/sr]",
            "mirror",
            "masked range (not fitted)",
            "model f",
        ] {
            assert!(cut.contains(text), "cut-{tag}.svg lacks `{text}`");
        }
        let map = svg(&format!("map-{tag}"));
        for text in [
            "model ÷ data",
            "front hemisphere (reflection)",
            "not fitted (masked)",
            "beam mask (3°)",
            "θ cap (85°)",
            "data:image/png;base64,",
        ] {
            assert!(map.contains(text), "map-{tag}.svg lacks `{text}`");
        }
        assert!(
            !map.contains("fill=\"#0102"),
            "map-{tag}.svg kept a raster placeholder"
        );
    }
    for (stem, texts) in [
        (
            "params",
            &[
                "θ_in [°]",
                "colour (red, green, blue) [–]",
                "spec: specularity [–]",
                "rough: roughness (RMS slope) [–]",
                "PCHIP interpolation",
            ][..],
        ),
        (
            "rho",
            &[
                "θ_in [°]",
                "ρ_dh",
                "ρ data, ∫ over the directions of the fitted samples",
            ][..],
        ),
        ("rms", &["θ_in [°]", "relative error [–]"][..]),
        ("cuts", &["θ_in = 0°", "BSDF [1/sr]"][..]),
    ] {
        let text = svg(stem);
        for t in texts {
            assert!(text.contains(t), "{stem}.svg lacks `{t}`");
        }
    }
}

#[test]
fn overview_svgs_have_one_series_per_incidence() {
    let d = drawn();
    assert_eq!(d.result.incidences.len(), TAGS.len());
    // The cuts chart names every incidence in its legend, once.
    let cuts = svg("cuts");
    for r in &d.result.incidences {
        let label = format!("θ_in = {}°", r.theta_in);
        assert_eq!(cuts.matches(&label).count(), 1, "`{label}` in cuts.svg");
    }
    // One model curve per incidence in the cuts, and one marker per
    // incidence in the error chart.
    assert!(cuts.matches("<polyline").count() >= TAGS.len());
    let rms = svg("rms");
    let circles = rms.matches("<circle").count();
    assert!(
        circles >= TAGS.len(),
        "rms.svg has {circles} markers for {} incidences",
        TAGS.len()
    );
}
