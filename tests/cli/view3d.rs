//! The 3D view of report.html in headless Chromium with software WebGL
//! (SwiftShader): it draws in each mode (data, model, model ÷ data),
//! turns when dragged, shows a sample's values on hover, switches
//! incidence, says so when the browser has no WebGL2, and neither logs
//! an error nor fetches anything. The screenshots of each mode are saved
//! under the test's temporary folder (and, with `BRTF_VIEW_SHOTS=<dir>`,
//! there too: docs/images holds the golden_paper ones).

use crate::browser::{Driver, HEAVY, base64_decode, browser_and_driver, session, severe};
use crate::common::{brtf, repo_path, s, temp_dir};
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

/// WebDriver's key of an element reference.
const ELEMENT: &str = "element-6066-11e4-a52e-4f735466cecf";

/// What the canvas shows, after two frames: pixels that are not the white
/// background, a hash of the picture, the draw count and the view's state.
const MEASURE: &str = "
    const done = arguments[arguments.length - 1];
    const view = document.querySelector('.brtf-view');
    requestAnimationFrame(() => requestAnimationFrame(() => {
        const c = view.querySelector('canvas');
        if (!c) { done({ nogl: view.querySelector('.bv-nogl')?.textContent ?? null }); return; }
        const t = document.createElement('canvas');
        t.width = c.width; t.height = c.height;
        const g = t.getContext('2d');
        g.drawImage(c, 0, 0);
        const px = g.getImageData(0, 0, t.width, t.height).data;
        let drawn = 0, red = 0, blue = 0, hash = 0;
        for (let i = 0; i < px.length; i += 4) {
            const [r, gr, b] = [px[i], px[i + 1], px[i + 2]];
            if (r < 245 || gr < 245 || b < 245) drawn++;
            if (r > b + 60 && r > gr + 40) red++;
            if (b > r + 60) blue++;
            hash = (Math.imul(hash, 31) + r * 65536 + gr * 256 + b) >>> 0;
        }
        const hook = view.brtfView;
        done({ drawn, red, blue, hash, pixels: px.length / 4, draws: hook.draws,
               viewError: hook.error, incidence: hook.incidence ?? null,
               tip: view.querySelector('.bv-tip').hidden ? null : view.querySelector('.bv-tip').innerText,
               firstDraw: hook.firstDraw ?? null,
               loaded: performance.getEntriesByType('navigation')[0].loadEventEnd,
               fetched: performance.getEntriesByType('resource').map(e => e.name)
                   .filter(n => !n.startsWith('file:')) });
    }));";

struct Page<'a> {
    driver: &'a Driver,
    id: String,
}

impl Page<'_> {
    fn at(&self, p: &str) -> String {
        format!("/session/{}{p}", self.id)
    }

    fn open(&self, file: &Path) {
        let url = format!("file://{}", s(&std::fs::canonicalize(file).unwrap()));
        self.driver
            .must("POST", &self.at("/url"), Some(json!({ "url": url })));
        self.driver.must(
            "POST",
            &self.at("/execute/sync"),
            Some(json!({"args": [], "script":
                "document.querySelector('.brtf-view').scrollIntoView(); return 0;"})),
        );
    }

    fn measure(&self) -> Value {
        self.driver.must(
            "POST",
            &self.at("/execute/async"),
            Some(json!({ "args": [], "script": MEASURE })),
        )
    }

    fn element(&self, css: &str) -> String {
        let found = self.driver.must(
            "POST",
            &self.at("/element"),
            Some(json!({"using": "css selector", "value": css})),
        );
        found[ELEMENT].as_str().expect("an element").to_string()
    }

    fn click(&self, css: &str) {
        let e = self.element(css);
        self.driver.must(
            "POST",
            &self.at(&format!("/element/{e}/click")),
            Some(json!({})),
        );
    }

    /// Pointer actions on the canvas, from `(x, y)` off its centre.
    fn pointer(&self, x: i64, y: i64, then: Vec<Value>) {
        let canvas = self.element(".bv-canvas");
        let mut actions = vec![json!({"type": "pointerMove", "duration": 0,
            "origin": { ELEMENT: canvas }, "x": x, "y": y})];
        actions.extend(then);
        self.driver.must(
            "POST",
            &self.at("/actions"),
            Some(json!({"actions": [{"type": "pointer", "id": "mouse",
                "parameters": {"pointerType": "mouse"}, "actions": actions}]})),
        );
        self.driver.must("DELETE", &self.at("/actions"), None);
    }

    fn screenshot(&self, name: &str) {
        let e = self.element(".bv-stage");
        let shot = self
            .driver
            .must("GET", &self.at(&format!("/element/{e}/screenshot")), None);
        let png = base64_decode(shot.as_str().expect("base64"));
        assert!(png.starts_with(b"\x89PNG"));
        let mut dirs = vec![PathBuf::from(env!("CARGO_TARGET_TMPDIR"))];
        dirs.extend(std::env::var_os("BRTF_VIEW_SHOTS").map(PathBuf::from));
        for dir in dirs {
            std::fs::write(dir.join(format!("{name}.png")), &png).unwrap();
        }
    }

    fn errors(&self) -> Vec<Value> {
        let log = self.driver.must(
            "POST",
            &self.at("/se/log"),
            Some(json!({"type": "browser"})),
        );
        severe(&log).into_iter().cloned().collect()
    }
}

/// Checks the three modes of the view on the open page (saving
/// screenshots named `<name>-<mode>`); with `misfit` the fit is known to
/// put the model both above and below the data by more than the colour
/// scale's half. Returns the data mode's state.
fn modes(page: &Page, name: &str, misfit: bool) -> Value {
    let data = page.measure();
    assert_eq!(data["viewError"], Value::Null, "{data}");
    assert_eq!(data["fetched"], json!([]), "nothing is fetched: {data}");
    let pixels = data["pixels"].as_f64().unwrap();
    assert!(
        data["drawn"].as_f64().unwrap() > 0.02 * pixels,
        "{name} data: {data}"
    );
    page.screenshot(&format!("{name}-data"));

    page.click("input[value=model]");
    let model = page.measure();
    assert!(model["draws"].as_u64() > data["draws"].as_u64(), "{model}");
    assert!(
        model["drawn"].as_f64().unwrap() > 0.02 * pixels,
        "{name} model: {model}"
    );
    assert_ne!(
        model["hash"], data["hash"],
        "the model mode looks like the data"
    );
    page.screenshot(&format!("{name}-model"));

    page.click("input[value=residual]");
    let residual = page.measure();
    assert!(
        residual["drawn"].as_f64().unwrap() > 0.02 * pixels,
        "{residual}"
    );
    assert_ne!(residual["hash"], data["hash"]);
    // Model ÷ data: red where the model is above, blue where below.
    if misfit {
        assert!(
            residual["red"].as_f64().unwrap() > 1000.0,
            "{name}: {residual}"
        );
        assert!(
            residual["blue"].as_f64().unwrap() > 1000.0,
            "{name}: {residual}"
        );
        assert!(data["red"].as_f64().unwrap() < 0.2 * residual["red"].as_f64().unwrap());
    }
    page.screenshot(&format!("{name}-residual"));

    // Dragging turns the view: another picture.
    page.click("input[value=data]");
    let before = page.measure();
    page.pointer(
        0,
        0,
        vec![
            json!({"type": "pointerDown", "button": 0}),
            json!({"type": "pointerMove", "duration": 150, "origin": "pointer", "x": 160, "y": 50}),
            json!({"type": "pointerUp", "button": 0}),
        ],
    );
    let turned = page.measure();
    assert!(
        turned["draws"].as_u64() > before["draws"].as_u64(),
        "{turned}"
    );
    assert_ne!(turned["hash"], before["hash"], "dragging changed nothing");
    assert!(turned["drawn"].as_f64().unwrap() > 0.02 * pixels);
    data
}

#[test]
fn the_3d_view_draws_turns_and_switches_in_chromium() {
    let Some((browser, driver)) = browser_and_driver() else {
        return;
    };
    let dir = temp_dir();
    let golden = dir.path().join("golden");
    let scan = repo_path("../shared/data/rgl-epfl-pgII-raw/golden_paper.txt");
    brtf(
        &[
            "fit",
            s(&scan),
            "--model",
            "plastic",
            "--no-export",
            "--out",
            s(&golden),
        ],
        "",
    )
    .ok();
    let lobes = dir.path().join("alu-lobes");
    let mut args: Vec<String> = vec!["fit".into()];
    for t in [0, 15, 30, 45, 60] {
        args.push(s(&repo_path(&format!("data/alu-ggx/alu-ggx:+{t}+0.mpc"))).into());
    }
    for a in [
        "--model",
        "metal",
        "--lobes",
        "2",
        "--no-export",
        "--out",
        s(&lobes),
    ] {
        args.push(a.into());
    }
    brtf(&args, "").ok();

    let _alone = HEAVY.lock().unwrap_or_else(|e| e.into_inner());
    let driver = Driver::start(&driver);
    let page = Page {
        id: session(&driver, &browser, &dir.path().join("profile"), &[]),
        driver: &driver,
    };

    // golden_paper: 127k samples, one incidence.
    page.open(&golden.join("report.html"));
    let state = modes(&page, "view3d-golden", true);
    eprintln!(
        "golden_paper report: {} bytes, load event at {:.0} ms, first 3D frame at {:.0} ms",
        std::fs::metadata(golden.join("report.html")).unwrap().len(),
        state["loaded"].as_f64().unwrap(),
        state["firstDraw"].as_f64().unwrap()
    );
    // Hovering a sample shows its directions, values and gate.
    page.pointer(0, 40, vec![]);
    let hovered = page.measure();
    let tip = hovered["tip"].as_str().expect("a tooltip");
    assert!(
        tip.contains("θ_out") && tip.contains("data") && tip.contains("model"),
        "{tip}"
    );
    assert!(tip.contains("fitted") || tip.contains("removed"), "{tip}");

    // The two-lobe fit of alu-ggx: five incidences behind one picker.
    page.open(&lobes.join("report.html"));
    let first = modes(&page, "view3d-alu-lobes", false);
    assert_eq!(first["incidence"], json!(0));
    page.click(".bv-incidence option[value='4']");
    let switched = page.measure();
    assert_eq!(switched["incidence"], json!(4), "{switched}");
    assert_ne!(switched["hash"], first["hash"]);
    assert!(switched["drawn"].as_f64().unwrap() > 0.02 * switched["pixels"].as_f64().unwrap());
    let errors = page.errors();
    assert!(errors.is_empty(), "browser errors: {errors:#?}");
    let _ = driver.call("DELETE", &page.at(""), None);

    // Without WebGL the view says so, and the page has no error.
    let plain = Page {
        id: session(
            &driver,
            &browser,
            &dir.path().join("profile-nogl"),
            &["--disable-3d-apis"],
        ),
        driver: &driver,
    };
    plain.open(&lobes.join("report.html"));
    let none = plain.measure();
    assert!(
        none["nogl"].as_str().unwrap_or("").contains("no WebGL2"),
        "{none}"
    );
    let errors = plain.errors();
    assert!(errors.is_empty(), "browser errors: {errors:#?}");
    let _ = driver.call("DELETE", &plain.at(""), None);
}
