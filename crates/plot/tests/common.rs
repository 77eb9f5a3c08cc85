//! Shared helpers: the data set's plots, drawn once, and small parsers.

use brtf_fit::FitResult;
use brtf_plot::{PlotOptions, Written};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The repository root.
pub(crate) fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The exported material the report must embed (a stand-in written by
/// the test; `brtf export` writes the real one).
pub(crate) const RAD_TEXT: &str = "# test stand-in for the exported material\n\
                            void metal alu-ggx\n0\n0\n5 0.93 0.93 0.93 0.78 0.118\n";

/// A fit folder with the data set's plots.
pub(crate) struct Drawn {
    pub dir: tempfile::TempDir,
    pub result: FitResult,
    pub written: Written,
}

impl Drawn {
    pub(crate) fn path(&self, relative: &str) -> PathBuf {
        self.dir.path().join(relative)
    }
}

/// Copies `fits/alu-ggx/fit.json` into a fresh folder with a stand-in
/// `.rad`, and draws every plot (once per test binary).
pub(crate) fn drawn() -> &'static Drawn {
    static CELL: OnceLock<Drawn> = OnceLock::new();
    CELL.get_or_init(|| {
        let dir = tempfile::Builder::new()
            .prefix("brtf-plot-test")
            .tempdir()
            .unwrap();
        std::fs::copy(
            repo().join("fits/alu-ggx/fit.json"),
            dir.path().join("fit.json"),
        )
        .unwrap();
        std::fs::write(dir.path().join("alu-ggx.rad"), RAD_TEXT).unwrap();
        let result = brtf_plot::read_fit(dir.path()).unwrap();
        let options = PlotOptions {
            search_dirs: vec![repo()],
            ..PlotOptions::default()
        };
        let written = brtf_plot::write_plots(dir.path(), &result, &options).unwrap();
        Drawn {
            dir,
            result,
            written,
        }
    })
}

/// The file tags of the data set's five incidences.
pub(crate) const TAGS: [&str; 5] = ["t0", "t15", "t30", "t45", "t60"];

/// Width and height declared on an SVG's root element.
pub(crate) fn svg_size(svg: &str) -> (u32, u32) {
    let open = &svg[svg.find("<svg").expect("an <svg> element")..];
    let open = &open[..open.find('>').unwrap()];
    let attr = |name: &str| -> u32 {
        let key = format!(" {name}=\"");
        let at = open
            .find(&key)
            .unwrap_or_else(|| panic!("no {name} in {open}"))
            + key.len();
        open[at..at + open[at..].find('"').unwrap()]
            .parse()
            .unwrap()
    };
    (attr("width"), attr("height"))
}

/// Decodes a PNG completely; returns (width, height, RGB(A) bytes, channels).
pub(crate) fn decode_png(path: &Path) -> (u32, u32, Vec<u8>, usize) {
    let file = std::fs::File::open(path).unwrap();
    let mut decoder = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .unwrap();
    let mut buf = vec![0; decoder.output_buffer_size().unwrap()];
    let info = decoder.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    let channels = info.color_type.samples();
    (info.width, info.height, buf, channels)
}

/// Every `href="…"` and `src="…"` value in `html`.
pub(crate) fn links(html: &str) -> Vec<String> {
    let mut out = Vec::new();
    for key in ["href=\"", "src=\""] {
        let mut rest = html;
        while let Some(at) = rest.find(key) {
            rest = &rest[at + key.len()..];
            let end = rest.find('"').unwrap();
            out.push(rest[..end].to_string());
            rest = &rest[end..];
        }
    }
    out
}

/// Undoes the report's %XX escapes.
pub(crate) fn percent_decode(s: &str) -> String {
    let bytes = s.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            let hex = std::str::from_utf8(&bytes[i + 1..i + 3]).unwrap();
            out.push(u8::from_str_radix(hex, 16).unwrap());
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).unwrap()
}
