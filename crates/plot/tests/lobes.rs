//! Lobe sums, fitted orientations and `--model auto`: the plots evaluate
//! the composite material (the RMS recomputed from the maps' model values
//! matches the fit's), the parameter chart names every flat argument, and
//! the report shows E1 and the candidates.

use crate::common::{links, percent_decode, repo};
use brtf_fit::{FitConfig, FitSetOptions, Recipe};
use brtf_model::MaterialKind;
use brtf_plot::PlotOptions;

/// Fits the data set with `config` (or `--model auto` from it).
fn fit(config: FitConfig, auto: bool) -> brtf_fit::FittedSet {
    let options = FitSetOptions {
        name: "alu-ggx".into(),
        recipe: Recipe::for_kind(config.kind),
        config,
        known_reflectance: None,
        interpolation: Default::default(),
        command_line: vec!["test".into()],
        adequacy: false,
        klems: Default::default(),
        auto,
    };
    let mut files: Vec<_> = std::fs::read_dir(repo().join("data/alu-ggx"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "mpc"))
        .collect();
    files.sort();
    brtf_fit::fit_set_with_data(&files, &options, &brtf_fit::NoProgress).expect("fits")
}

/// The text between `start` (included) and the next `end` after it.
fn between<'a>(text: &'a str, start: &str, end: &str) -> &'a str {
    let from = text
        .find(start)
        .unwrap_or_else(|| panic!("no {start} in the report"));
    let rest = &text[from..];
    &rest[..rest.find(end).expect("the end")]
}

#[test]
fn auto_lobe_sums_plot_the_composite_and_the_report_shows_e1_and_the_candidates() {
    let set = fit(FitConfig::new(MaterialKind::Metal), true);
    let result = &set.result;
    let auto = result.auto.as_ref().expect("the candidates");
    let shape = result.config.shape();
    assert!(shape.lobes > 1, "alu-ggx needs two lobes: {}", auto.reason);

    let from_files = tempfile::tempdir().unwrap();
    let from_fit = tempfile::tempdir().unwrap();
    let options = PlotOptions {
        search_dirs: vec![repo()],
        ..PlotOptions::default()
    };
    let read = brtf_plot::write_plots(from_files.path(), result, &options).unwrap();
    let handed =
        brtf_plot::write_plots_with_data(from_fit.path(), result, &set.prepared, &options).unwrap();
    // No warning: every incidence was read, and the RMS relative error
    // recomputed from the plotted model (the lobe sum) equals the fit's.
    assert!(read.warnings.is_empty(), "{:?}", read.warnings);
    assert!(handed.warnings.is_empty(), "{:?}", handed.warnings);
    for (a, b) in read.files.iter().zip(&handed.files) {
        if a.extension().is_some_and(|e| e == "svg" || e == "png") {
            let (x, y) = (std::fs::read(a).unwrap(), std::fs::read(b).unwrap());
            assert!(x == y, "{} differs", a.display());
        }
    }
    let plots = from_files.path().join("plots");
    for tag in ["t0", "t15", "t30", "t45", "t60"] {
        assert!(plots.join(format!("map-{tag}.svg")).is_file());
        assert!(plots.join(format!("cut-{tag}.png")).is_file());
    }
    // The parameter chart: every flat argument by its name.
    let params = std::fs::read_to_string(plots.join("params.svg")).unwrap();
    for name in shape.param_names().iter().skip(3) {
        assert!(params.contains(&format!("{name}: ")), "no {name} panel");
    }
    assert!(params.contains(&shape.label()), "the shape in the title");

    let html = std::fs::read_to_string(&read.report).unwrap();
    let percent = |e: f64| format!("{:.2}%", 100.0 * e);
    // The shape's label at the top and in the configuration.
    assert!(html.contains(&format!("Radiance <code>{}</code>", shape.label())));
    // E1 in the headline, in the table beside RMS rel., per incidence.
    let global = result.global.as_ref().unwrap().e1.expect("E1");
    let headline = between(&html, "<p id=\"headline\">", "</p>");
    assert!(headline.contains(&percent(global)), "{headline}");
    let table = between(&html, "<table id=\"param-table\">", "</table>");
    assert!(table.contains("<th>E1</th><th>RMS rel.</th>"), "{table}");
    assert_eq!(
        table.matches("<td class=\"e1\">").count(),
        result.incidences.len() + 1
    );
    for r in result.incidences.iter().chain(&result.global) {
        let cell = format!("<td class=\"e1\">{}</td>", percent(r.e1.unwrap()));
        assert!(table.contains(&cell), "{cell}");
    }
    let grey = result.config.gray || result.colour_measured() == Some(false);
    for name in shape.param_names() {
        let name = match name.as_str() {
            "red" if grey => "grey (R = G = B)".to_string(),
            "green" | "blue" if grey => continue,
            _ => name,
        };
        assert!(table.contains(&format!("<th>{name}</th>")), "column {name}");
    }
    assert!(
        html.contains("id=\"lobes\""),
        "what the lobes' arguments mean"
    );
    // The candidates, the chosen one marked, and the reason.
    assert!(links(&html).iter().any(|l| l == "#auto"));
    let candidates = between(&html, "<table id=\"auto-table\">", "</table>");
    for head in [
        "model",
        "parameters",
        "E1",
        "held-out E1",
        "peak offset [°]",
        "cost",
        "time [ms]",
        "collapsed",
    ] {
        assert!(candidates.contains(&format!(">{head}</th>")), "{head}");
    }
    let rows: Vec<&str> = candidates.split("<tr class=").skip(1).collect();
    assert_eq!(rows.len(), auto.candidates.len(), "{candidates}");
    for (i, (row, c)) in rows.iter().zip(&auto.candidates).enumerate() {
        assert_eq!(row.starts_with("\"chosen\""), i == auto.chosen, "{row}");
        assert!(row.contains(&c.model), "{row}");
        assert!(row.contains(&percent(c.e1_heldout)), "{row}");
    }
    let reason = auto.reason.replace('\'', "&#39;");
    assert!(html.contains(&reason), "the reason sentence");
    // The 3D view offers the chosen fit's surface, then every other
    // candidate's, each from its own fitted arguments.
    let view = crate::view::payload(&html);
    for inc in view["incidences"].as_array().unwrap() {
        let surfaces = inc["surfaces"].as_array().unwrap();
        let labels: Vec<&str> = surfaces
            .iter()
            .map(|s| s["label"].as_str().unwrap())
            .collect();
        let mut expected = vec![format!("{} (fitted)", shape.label())];
        for (i, c) in auto.candidates.iter().enumerate() {
            if i != auto.chosen {
                expected.push(c.model.clone());
            }
        }
        assert_eq!(labels, expected);
        let codes: Vec<&str> = surfaces
            .iter()
            .map(|s| s["codes"].as_str().unwrap())
            .collect();
        for other in &codes[1..] {
            assert_ne!(
                *other, codes[0],
                "a candidate's surface is the chosen one's"
            );
        }
    }
    for l in links(&html).iter().filter(|l| l.starts_with("plots/")) {
        assert!(from_files.path().join(percent_decode(l)).is_file(), "{l}");
    }
}

#[test]
fn a_fitted_orientation_has_its_own_axis_in_degrees() {
    let mut config = FitConfig::new(MaterialKind::Metal2);
    config.oriented = true;
    let set = fit(config, false);
    let dir = tempfile::tempdir().unwrap();
    let written = brtf_plot::write_plots_with_data(
        dir.path(),
        &set.result,
        &set.prepared,
        &PlotOptions::default(),
    )
    .unwrap();
    assert!(written.warnings.is_empty(), "{:?}", written.warnings);
    let params = std::fs::read_to_string(dir.path().join("plots/params.svg")).unwrap();
    assert!(params.contains("orient: orientation of u from +x [°]"));
    assert!(params.contains("rough_u: roughness along u [–]"));
    let html = std::fs::read_to_string(&written.report).unwrap();
    assert!(html.contains("<th>orient</th>"));
    assert!(html.contains("metal2 (orientation fitted)"));
    assert!(
        !html.contains("id=\"auto\""),
        "no candidates without --model auto"
    );
}
