//! report.html: every plot referenced, no broken link, the tables, the
//! material and the provenance; a missing measurement file is a warning.

use crate::common::{RAD_TEXT, TAGS, drawn, links, percent_decode, repo};
use brtf_plot::PlotOptions;

#[test]
fn the_report_references_every_plot_and_has_no_broken_link() {
    let d = drawn();
    let html = std::fs::read_to_string(d.path("report.html")).unwrap();
    let links = links(&html);
    for l in &links {
        if let Some(anchor) = l.strip_prefix('#') {
            assert!(
                html.contains(&format!("id=\"{anchor}\"")),
                "anchor #{anchor} has no target"
            );
        } else if l.starts_with("data:") {
            continue;
        } else {
            assert!(!l.contains("://"), "{l}: the report must work offline");
            let path = d.dir.path().join(percent_decode(l));
            assert!(path.is_file(), "broken link {l}");
        }
    }
    for f in d
        .written
        .files
        .iter()
        .filter(|f| f.starts_with(d.path("plots")))
    {
        let rel = format!("plots/{}", f.file_name().unwrap().to_string_lossy());
        assert!(
            links.iter().any(|l| percent_decode(l) == rel),
            "report.html does not reference {rel}"
        );
    }
    // SVGs are shown, PNGs linked.
    for tag in TAGS {
        assert!(html.contains(&format!("src=\"plots/map-{tag}.svg\"")));
        assert!(html.contains(&format!("href=\"plots/cut-{tag}.png\"")));
    }
    // One inlined script, the 3D view's; nothing is fetched.
    assert_eq!(html.matches("<script>").count(), 1);
    assert!(!html.contains("<script src"));
    assert!(!html.contains("import("));
}

#[test]
fn the_report_shows_the_table_material_and_provenance() {
    let d = drawn();
    let html = std::fs::read_to_string(d.path("report.html")).unwrap();
    let table = &html[html.find("<table id=\"param-table\">").expect("the table")..];
    let table = &table[..table.find("</table>").unwrap()];
    assert_eq!(
        table.matches("<tr class=\"incidence\">").count(),
        d.result.incidences.len()
    );
    assert_eq!(table.matches("<tr class=\"global\">").count(), 1);
    // A grey fit's colour is one column.
    let grey = d.result.config.gray || d.result.colour_measured() == Some(false);
    let colours: &[&str] = if grey {
        &["grey (R = G = B)"]
    } else {
        &["red", "green", "blue"]
    };
    for name in colours.iter().chain(&["spec", "rough", "E1", "RMS rel."]) {
        assert!(table.contains(&format!("<th>{name}</th>")), "column {name}");
    }
    assert_eq!(table.contains("<th>green</th>"), !grey);
    let rough = d.result.incidences[2].value("rough").unwrap();
    assert!(table.contains(&format!("{rough:.6}")));
    // The exported material, escaped, and linked.
    assert!(html.contains("<pre class=\"material\">"));
    assert!(html.contains("void metal alu-ggx"));
    assert!(RAD_TEXT.lines().all(|l| html.contains(l)));
    assert!(html.contains("href=\"alu-ggx.rad\""));
    // Provenance: every input with its hash, and the command line.
    for input in &d.result.provenance.inputs {
        assert!(html.contains(&input.sha256));
        let escaped = input
            .path
            .replace('&', "&amp;")
            .replace('<', "&lt;")
            .replace('>', "&gt;")
            .replace('"', "&quot;")
            .replace('\'', "&#39;");
        assert!(html.contains(&escaped));
    }
    assert!(html.contains("brtf"));
    assert!(html.contains("href=\"fit.json\""));
}

#[test]
fn a_missing_measurement_file_skips_its_plots_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(
        repo().join("fits/alu-ggx/fit.json"),
        dir.path().join("fit.json"),
    )
    .unwrap();
    let mut result = brtf_plot::read_fit(dir.path()).unwrap();
    // One input moved away: an absolute path that does not exist.
    let gone = "/nonexistent/brtf-plot-test/alu-ggx:+30+0.mpc".to_string();
    result.provenance.inputs[2].path = gone.clone();
    result.incidences[2].source = gone.clone();
    let options = PlotOptions {
        search_dirs: vec![repo()],
        ..PlotOptions::default()
    };
    let written = brtf_plot::write_plots(dir.path(), &result, &options).unwrap();
    assert_eq!(written.warnings.len(), 1, "{:?}", written.warnings);
    assert!(written.warnings[0].contains(&gone) && written.warnings[0].contains("not found"));
    let plots = dir.path().join("plots");
    assert!(!plots.join("map-t30.svg").exists() && !plots.join("cut-t30.png").exists());
    assert!(plots.join("map-t15.svg").exists() && plots.join("params.png").exists());
    let html = std::fs::read_to_string(dir.path().join("report.html")).unwrap();
    assert!(html.contains("Read this first") && html.contains("not found"));
    assert!(
        !html.contains("plots/map-t30.svg"),
        "no link to a plot not drawn"
    );
    for l in links(&html).iter().filter(|l| l.starts_with("plots/")) {
        assert!(
            dir.path().join(percent_decode(l)).is_file(),
            "broken link {l}"
        );
    }
}

#[test]
fn a_changed_file_or_a_different_selection_is_flagged() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(
        repo().join("fits/alu-ggx/fit.json"),
        dir.path().join("fit.json"),
    )
    .unwrap();
    let mut result = brtf_plot::read_fit(dir.path()).unwrap();
    result.provenance.inputs[0].sha256 = "0".repeat(64);
    result.incidences[1].n_points += 1;
    result.incidences[3].rms_rel *= 1.5;
    let options = PlotOptions {
        search_dirs: vec![repo()],
        ..PlotOptions::default()
    };
    let written = brtf_plot::write_plots(dir.path(), &result, &options).unwrap();
    let all = written.warnings.join("\n");
    assert!(all.contains("changed since the fit"), "{all}");
    assert!(all.contains("the fit used"), "{all}");
    assert!(all.contains("RMS relative error recomputed"), "{all}");
    assert_eq!(written.warnings.len(), 3, "{all}");
}

#[test]
fn no_incidence_is_an_error_and_a_bad_fit_json_names_its_line() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(
        repo().join("fits/alu-ggx/fit.json"),
        dir.path().join("fit.json"),
    )
    .unwrap();
    let mut result = brtf_plot::read_fit(dir.path()).unwrap();
    result.incidences.clear();
    let err = brtf_plot::write_plots(dir.path(), &result, &PlotOptions::default()).unwrap_err();
    assert!(err.to_string().contains("no incidences"), "{err}");
    std::fs::write(dir.path().join("fit.json"), "{\n  \"name\": 3\n}\n").unwrap();
    let err = brtf_plot::read_fit(dir.path()).unwrap_err().to_string();
    assert!(err.contains("schema version 1"), "{err}");
    std::fs::write(
        dir.path().join("fit.json"),
        "{\n  \"schema\": 2,\n  \"name\": 3\n}\n",
    )
    .unwrap();
    let err = brtf_plot::read_fit(dir.path()).unwrap_err().to_string();
    assert!(err.contains("fit.json:3:"), "{err}");
    let err = brtf_plot::read_fit(&dir.path().join("nowhere"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("cannot read"), "{err}");
}

/// The data handed over draw byte for byte the plots of the files read
/// again: the same model values, and the nearest-sample grids made from the
/// fitted data (beside the model values) equal the ones made from the
/// incidence.
#[test]
fn the_fits_own_data_draw_the_same_plots_as_the_files() {
    let kind = brtf_model::MaterialKind::Metal;
    let options = brtf_fit::FitSetOptions {
        name: "alu-ggx".into(),
        config: brtf_fit::FitConfig::new(kind),
        recipe: brtf_fit::Recipe::for_kind(kind),
        known_reflectance: None,
        interpolation: Default::default(),
        command_line: vec!["test".into()],
        adequacy: false,
        klems: Default::default(),
        auto: false,
    };
    let mut files: Vec<_> = std::fs::read_dir(repo().join("data/alu-ggx"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "mpc"))
        .collect();
    files.sort();
    let set = brtf_fit::fit_set_with_data(&files, &options, &brtf_fit::NoProgress).expect("fits");
    assert_eq!(set.prepared.len(), set.result.incidences.len());
    let from_files = tempfile::tempdir().unwrap();
    let from_fit = tempfile::tempdir().unwrap();
    let plot_options = PlotOptions::default();
    let read = brtf_plot::write_plots(from_files.path(), &set.result, &plot_options).unwrap();
    let handed = brtf_plot::write_plots_with_data(
        from_fit.path(),
        &set.result,
        &set.prepared,
        &plot_options,
    )
    .unwrap();
    assert!(read.warnings.is_empty() && handed.warnings.is_empty());
    assert_eq!(read.files.len(), handed.files.len());
    // Maps and cuts of all five incidences, the overview charts, the report.
    assert!(read.files.len() > 2 * 2 * 5, "{:?}", read.files);
    for (a, b) in read.files.iter().zip(&handed.files) {
        let relative = a.strip_prefix(from_files.path()).unwrap();
        assert_eq!(relative, b.strip_prefix(from_fit.path()).unwrap());
        let (a, b) = (std::fs::read(a).unwrap(), std::fs::read(b).unwrap());
        if relative.ends_with("report.html") {
            // The report names its folder.
            let text = |bytes: Vec<u8>, dir: &std::path::Path| {
                String::from_utf8(bytes)
                    .unwrap()
                    .replace(&dir.display().to_string(), "DIR")
            };
            assert_eq!(text(a, from_files.path()), text(b, from_fit.path()));
        } else {
            assert!(a == b, "{} differs", relative.display());
        }
    }
}

/// The charts of a whole fit: over θ_in, and every cut in one.
const OVERVIEW: [&str; 4] = ["params", "rho", "rms", "cuts"];

#[test]
fn one_incidence_draws_no_chart_over_theta_and_the_report_says_why() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(
        repo().join("fits/alu-ggx/fit.json"),
        dir.path().join("fit.json"),
    )
    .unwrap();
    let mut result = brtf_plot::read_fit(dir.path()).unwrap();
    let options = PlotOptions {
        search_dirs: vec![repo()],
        ..PlotOptions::default()
    };
    let plots = dir.path().join("plots");
    let report = dir.path().join("report.html");
    let note = "One incidence fitted: the charts over θ_in need two or more.";
    // Two incidences: every chart over θ_in, no note.
    result
        .incidences
        .retain(|r| [15.0, 60.0].contains(&r.theta_in));
    let written = brtf_plot::write_plots(dir.path(), &result, &options).unwrap();
    assert_eq!(written.files.len(), 2 * 2 * 2 + 2 * 4 + 1);
    let html = std::fs::read_to_string(&report).unwrap();
    for stem in OVERVIEW {
        assert!(plots.join(format!("{stem}.png")).is_file(), "{stem}");
        assert!(
            html.contains(&format!("src=\"plots/{stem}.svg\"")),
            "{stem}"
        );
    }
    assert!(!html.contains("theta-note") && !html.contains(note));

    // One: its map and cut only (the earlier run's charts over θ_in go),
    // and one line in their place.
    result.incidences.truncate(1);
    let written = brtf_plot::write_plots(dir.path(), &result, &options).unwrap();
    assert!(written.warnings.is_empty(), "{:?}", written.warnings);
    let mut names: Vec<String> = std::fs::read_dir(&plots)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        ["cut-t15.png", "cut-t15.svg", "map-t15.png", "map-t15.svg"]
    );
    assert_eq!(written.files.len(), 5, "{:?}", written.files);
    let html = std::fs::read_to_string(&report).unwrap();
    let theta = &html[html.find("<section id=\"theta\">").expect("the section")..];
    let theta = &theta[..theta.find("</section>").unwrap()];
    assert!(theta.contains(note), "{theta}");
    assert!(!theta.contains("<figure"), "{theta}");
    for stem in OVERVIEW {
        assert!(!html.contains(&format!("plots/{stem}.")), "{stem}");
    }
    let images: Vec<String> = links(&html)
        .into_iter()
        .filter(|l| l.starts_with("plots/"))
        .collect();
    assert_eq!(images.len(), 2 * 2 * 2, "{images:?}");
    for l in &images {
        assert!(dir.path().join(percent_decode(l)).is_file(), "{l}");
    }
}
