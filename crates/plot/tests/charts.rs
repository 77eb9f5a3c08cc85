//! The chart files: every one exists, PNGs decode at the SVG's size, SVGs
//! carry their axis titles and one series per incidence, text is drawn.

use crate::common::{TAGS, decode_png, drawn, repo, svg_size};
use brtf_plot::PlotOptions;

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

/// `(x, y, width, height)` of every `<rect>` in `svg` filled `fill`.
fn rects(svg: &str, fill: &str) -> Vec<(f64, f64, f64, f64)> {
    svg.split("<rect")
        .skip(1)
        .map(|r| &r[..r.find("/>").unwrap()])
        .filter(|r| r.contains(&format!("fill=\"{fill}\"")))
        .map(|r| {
            let attr = |name: &str| -> f64 {
                let key = format!(" {name}=\"");
                let at = r.find(&key).unwrap() + key.len();
                r[at..at + r[at..].find('"').unwrap()].parse().unwrap()
            };
            (attr("x"), attr("y"), attr("width"), attr("height"))
        })
        .collect()
}

/// `(x, y)` of the `<text>` element whose text is `text`.
fn text_at(svg: &str, text: &str) -> (f64, f64) {
    let open = svg
        .split("<text")
        .skip(1)
        .map(|t| t.split_once('>').unwrap())
        .find(|(_, rest)| rest.split("</text>").next().unwrap().trim() == text)
        .unwrap_or_else(|| panic!("no `{text}`"))
        .0;
    let attr = |name: &str| -> f64 {
        let key = format!(" {name}=\"");
        let at = open.find(&key).unwrap() + key.len();
        open[at..at + open[at..].find('"').unwrap()]
            .parse()
            .unwrap()
    };
    (attr("x"), attr("y"))
}

#[test]
fn the_cut_legend_leaves_the_light_marker_visible() {
    for tag in TAGS {
        let cut = svg(&format!("cut-{tag}"));
        // The legend: the one white, slightly see-through rectangle.
        let legend = rects(&cut, "#FFFFFF");
        let legend: Vec<_> = legend.iter().filter(|r| r.2 < 900.0).collect();
        assert_eq!(legend.len(), 1, "cut-{tag}: {legend:?}");
        let (x, _, w, _) = *legend[0];
        // The light's label starts 1° right of its dashed line.
        let (light, _) = text_at(&cut, "light");
        assert!(
            light + 30.0 < x || light - 15.0 > x + w,
            "cut-{tag}: the light at {light} px under the legend over {x}..{}",
            x + w
        );
    }
}

#[test]
fn a_long_sample_name_is_shortened_so_that_no_title_runs_off_its_chart() {
    let long = "Golden_glossy_paper_measured_on_the_pgII_goniophotometer_at_EPFL_sample_0042_front";
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(
        repo().join("fits/alu-ggx/fit.json"),
        dir.path().join("fit.json"),
    )
    .unwrap();
    let mut result = brtf_plot::read_fit(dir.path()).unwrap();
    result.name = long.into();
    // Two incidences: the charts over θ_in are drawn too.
    result.incidences = vec![result.incidences[1].clone(), result.incidences[4].clone()];
    let options = PlotOptions {
        search_dirs: vec![repo()],
        ..PlotOptions::default()
    };
    let written = brtf_plot::write_plots(dir.path(), &result, &options).unwrap();
    let pngs: Vec<_> = written
        .files
        .iter()
        .filter(|f| f.extension().is_some_and(|e| e == "png"))
        .collect();
    assert_eq!(pngs.len(), 2 * 2 + 4, "{pngs:?}");
    for png in pngs {
        // No glyph in the outermost columns of the title's rows.
        let (w, _, pixels, channels) = decode_png(png);
        let dark = |x: u32, y: u32| {
            let at = (y * w + x) as usize * channels;
            pixels[at..at + 3].iter().all(|&c| c < 160)
        };
        for y in 0..30 {
            for x in (0..6).chain(w - 6..w) {
                assert!(!dark(x, y), "{}: text at ({x}, {y})", png.display());
            }
        }
        // Where the whole name does not fit, its start and end are kept
        // and its middle left out.
        let svg = std::fs::read_to_string(png.with_extension("svg")).unwrap();
        let title = svg
            .split("<text")
            .filter_map(|t| t.split_once('>'))
            .map(|(_, rest)| rest.split("</text>").next().unwrap().trim())
            .find(|t| t.starts_with("Golden"))
            .unwrap_or_else(|| panic!("{}: no title", png.display()));
        let stem = png.file_stem().unwrap().to_string_lossy();
        if title.contains(long) {
            assert!(!title.contains('…'), "{stem}: {title}");
            // The widest chart: there the title fits whole.
            assert_eq!(stem, "params", "{title}");
        } else {
            assert!(
                title.contains("Golden_glossy")
                    && title.contains("…")
                    && title.contains("_front (metal)"),
                "{stem}: {title}"
            );
        }
    }
}
