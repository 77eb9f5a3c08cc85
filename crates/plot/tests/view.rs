//! The 3D view's data block: every sample of every incidence, its values
//! quantised within the stated precision, the fitted and removed samples
//! told apart, and the model surfaces where the scan has samples.

use crate::common::{drawn, repo};
use brtf_plot::PlotOptions;
use brtf_plot::bench::load;
use serde_json::Value;

/// The JSON block of the first view in `html`.
pub(crate) fn payload(html: &str) -> Value {
    let start = html.find("class=\"bv-data\">").expect("a view") + "class=\"bv-data\">".len();
    let end = start + html[start..].find("</script>").unwrap();
    serde_json::from_str(&html[start..end].replace("<\\/", "</")).expect("JSON")
}

fn base64_decode(text: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {c}"),
    };
    let mut out = Vec::new();
    for chunk in text.as_bytes().chunks(4) {
        let digits: Vec<u8> = chunk
            .iter()
            .filter(|&&c| c != b'=')
            .map(|&c| value(c))
            .collect();
        let n = digits
            .iter()
            .enumerate()
            .fold(0u32, |n, (k, d)| n | u32::from(*d) << (18 - 6 * k));
        for k in 0..digits.len() - 1 {
            out.push((n >> (16 - 8 * k)) as u8);
        }
    }
    out
}

fn u16s(bytes: &[u8]) -> Vec<u16> {
    bytes
        .chunks(2)
        .map(|b| u16::from_le_bytes([b[0], b[1]]))
        .collect()
}

#[test]
fn the_view_holds_every_sample_within_its_precision() {
    let d = drawn();
    let html = std::fs::read_to_string(d.path("report.html")).unwrap();
    let view = payload(&html);
    let incidences = view["incidences"].as_array().unwrap();
    assert_eq!(incidences.len(), d.result.incidences.len());
    for (k, inc) in incidences.iter().enumerate() {
        let loaded = load(&d.result, k, String::new(), &repo(), &[]).unwrap();
        let n = loaded.samples.len();
        assert_eq!(inc["n"].as_u64().unwrap() as usize, n);
        let bytes = base64_decode(inc["samples"].as_str().unwrap());
        assert_eq!(bytes.len(), 9 * n);
        let (lo, hi) = (inc["lo"].as_f64().unwrap(), inc["hi"].as_f64().unwrap());
        let data = u16s(&bytes[4 * n..6 * n]);
        let model = u16s(&bytes[6 * n..8 * n]);
        let flags = &bytes[8 * n..];
        let value = |code: u16| {
            if code == 0 {
                0.0
            } else {
                10f64.powf(lo + f64::from(code - 1) / 65533.0 * (hi - lo))
            }
        };
        // Half a step of the log scale: 9 decades in 65533 steps.
        let tolerance = 10f64.powf(0.5 * (hi - lo) / 65533.0) - 1.0 + 1e-12;
        assert!(tolerance < 2e-4, "{tolerance}");
        let floor = 10f64.powf(lo);
        let mut fitted = 0;
        for (s, sample) in loaded.samples.iter().enumerate() {
            for (code, truth) in [(data[s], sample.data), (model[s], sample.model)] {
                if truth > floor {
                    let got = value(code);
                    assert!(
                        (got / truth - 1.0).abs() <= tolerance,
                        "incidence {k} sample {s}: {got} for {truth}"
                    );
                } else if truth.is_nan() || truth <= 0.0 {
                    assert_eq!(code, 0, "incidence {k} sample {s}: {truth}");
                }
            }
            let gate = flags[s] & 127;
            assert_eq!(gate == 0, sample.used(), "incidence {k} sample {s}");
            assert_eq!(flags[s] >= 128, sample.dir.z < 0.0);
            if gate > 0 {
                assert_eq!(usize::from(gate - 1), sample.removed_by.unwrap());
            }
            fitted += usize::from(gate == 0);
        }
        assert_eq!(fitted, d.result.incidences[k].n_points);
        assert_eq!(inc["fitted"].as_u64().unwrap() as usize, fitted);
        // The fitted model's surface: a code for the model where samples
        // are, none outside the disk.
        let surfaces = inc["surfaces"].as_array().unwrap();
        assert_eq!(surfaces.len(), 1, "no --model auto candidates here");
        let grid = inc["grid"].as_u64().unwrap() as usize;
        let codes = u16s(&base64_decode(surfaces[0]["codes"].as_str().unwrap()));
        assert_eq!(codes.len(), grid * grid);
        assert_eq!(codes[0], u16::MAX, "a corner is outside the disk");
        let centre = codes[grid * grid / 2];
        let at_normal = loaded.model_at(glam::DVec3::Z);
        assert!(
            (value(centre) / at_normal - 1.0).abs() <= tolerance,
            "incidence {k}: centre code {centre} = {} for {at_normal}",
            value(centre)
        );
    }
}

#[test]
fn a_view_on_its_own_has_its_styles_and_an_id_of_its_own() {
    let d = drawn();
    let options = PlotOptions {
        search_dirs: vec![repo()],
        ..PlotOptions::default()
    };
    let a = brtf_plot::view_html(d.dir.path(), &d.result, &options).unwrap();
    let b = brtf_plot::view_html(d.dir.path(), &d.result, &options).unwrap();
    assert!(a.starts_with("<style>"));
    let id = |html: &str| {
        let start = html.find("class=\"brtf-view\" id=\"").unwrap() + 22;
        html[start..start + html[start..].find('"').unwrap()].to_string()
    };
    assert_ne!(id(&a), id(&b));
    assert_eq!(payload(&a)["incidences"], payload(&b)["incidences"]);
}
