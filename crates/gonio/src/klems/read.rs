//! The Klems BSDF XML reader (roxmltree DOM; elements matched by local
//! name, so the `http://windows.lbl.gov` namespace may be present or not).
//!
//! Only the first `Optical/Layer` is read, as Radiance does. Errors carry
//! the file, the line of the element at fault and its name.

use std::path::Path;

use rayon::prelude::*;
use roxmltree::{Document, Node};

use super::ttree::TreeRank;
use super::{
    BsdfXml, KlemsBand, KlemsBasis, KlemsBsdf, KlemsDirection, KlemsHeader, KlemsMatrix, KlemsRing,
    NEGATIVE_LIMIT,
};
use crate::error::{KlemsProblem, ParseErrorKind, ReadError};
use crate::read::{check_text, parse_error, read_file};

/// Reads a Klems BSDF XML file.
pub fn read_path(path: &Path) -> Result<KlemsBsdf, ReadError> {
    let bytes = read_file(path)?;
    read_bytes(&bytes, path)
}

/// Parses in-memory bytes; `name` is used in errors.
pub fn read_bytes(bytes: &[u8], name: impl AsRef<Path>) -> Result<KlemsBsdf, ReadError> {
    let name = name.as_ref();
    let text = check_text(bytes, name)?;
    read_str(&text, name)
}

/// Reads a BSDF XML file of either kind: a Klems matrix file or a
/// tensor tree.
pub fn read_any_path(path: &Path) -> Result<BsdfXml, ReadError> {
    let bytes = read_file(path)?;
    read_any_bytes(&bytes, path)
}

/// [`read_any_path`] on in-memory bytes; `name` is used in errors.
pub fn read_any_bytes(bytes: &[u8], name: impl AsRef<Path>) -> Result<BsdfXml, ReadError> {
    let name = name.as_ref();
    let text = check_text(bytes, name)?;
    let doc = parse_document(&text, name)?;
    Reader { doc: &doc, name }.read_any()
}

/// Parses in-memory text as a Klems matrix file (a tensor tree is refused:
/// [`read_any_bytes`] reads both); `name` is used in errors.
pub fn read_str(text: &str, name: impl AsRef<Path>) -> Result<KlemsBsdf, ReadError> {
    let name = name.as_ref();
    let doc = parse_document(text, name)?;
    Reader { doc: &doc, name }.read()
}

/// The XML document, with the attribute guard.
fn parse_document<'t>(text: &'t str, name: &Path) -> Result<Document<'t>, ReadError> {
    if let Some((line, count)) = crowded_element(text) {
        return Err(parse_error(
            name,
            line,
            ParseErrorKind::Klems {
                element: "?xml".into(),
                problem: KlemsProblem::Xml(format!(
                    "an element with {count} attributes (at most {MAX_ATTRIBUTES} are read)"
                )),
            },
        ));
    }
    Document::parse(text).map_err(|e| {
        let line = (e.pos().row as usize).max(1);
        parse_error(
            name,
            line,
            ParseErrorKind::Klems {
                element: "?xml".into(),
                problem: KlemsProblem::Xml(e.to_string()),
            },
        )
    })
}

/// Attributes per element beyond which a file is refused: a BSDF file's
/// elements have a handful, and the XML parser's duplicate check costs
/// the square of their number (200 000 took over a minute).
const MAX_ATTRIBUTES: usize = 1000;

/// The line and attribute count of the first element with more than
/// [`MAX_ATTRIBUTES`] attributes, in one pass: `=` signs outside quotes
/// inside a start tag (comments, `<!…>` and `<?…?>` skipped; the text
/// between tags, most of a BSDF file, is skipped with `find`).
fn crowded_element(text: &str) -> Option<(usize, usize)> {
    let bytes = text.as_bytes();
    let mut at = 0;
    while let Some(found) = text[at..].find('<') {
        let start = at + found;
        if text[start..].starts_with("<!--") {
            at = text[start..]
                .find("-->")
                .map_or(text.len(), |end| start + end + 3);
            continue;
        }
        at = start + 1;
        if matches!(bytes.get(at), Some(b'!' | b'?')) {
            continue;
        }
        let (mut quote, mut count) = (None, 0);
        while at < bytes.len() {
            match (bytes[at], quote) {
                (b'"' | b'\'', None) => quote = Some(bytes[at]),
                (q, Some(open)) if q == open => quote = None,
                (b'=', None) => count += 1,
                (b'>', None) => break,
                _ => {}
            }
            at += 1;
        }
        if count > MAX_ATTRIBUTES {
            let line = 1 + bytes[..start].iter().filter(|&&b| b == b'\n').count();
            return Some((line, count));
        }
    }
    None
}

pub(super) struct Reader<'a, 'input> {
    pub(super) doc: &'a Document<'input>,
    pub(super) name: &'a Path,
}

/// Element children of `node` with local name `tag`.
pub(super) fn children<'a, 'input: 'a>(
    node: Node<'a, 'input>,
    tag: &'static str,
) -> impl Iterator<Item = Node<'a, 'input>> {
    node.children()
        .filter(move |c| c.is_element() && c.tag_name().name() == tag)
}

pub(super) fn child<'a, 'input>(
    node: Node<'a, 'input>,
    tag: &'static str,
) -> Option<Node<'a, 'input>> {
    children(node, tag).next()
}

/// The trimmed text of a child, `None` when absent or empty.
pub(super) fn child_text(node: Node<'_, '_>, tag: &'static str) -> Option<String> {
    let text = child(node, tag)?.text()?.trim();
    (!text.is_empty()).then(|| text.to_string())
}

impl<'a, 'input> Reader<'a, 'input> {
    pub(super) fn line_of(&self, node: Node<'_, '_>) -> usize {
        (self.doc.text_pos_at(node.range().start).row as usize).max(1)
    }

    pub(super) fn error(&self, node: Node<'_, '_>, problem: KlemsProblem) -> ReadError {
        parse_error(
            self.name,
            self.line_of(node),
            ParseErrorKind::Klems {
                element: node.tag_name().name().to_string(),
                problem,
            },
        )
    }

    pub(super) fn required(
        &self,
        parent: Node<'a, 'input>,
        tag: &'static str,
    ) -> Result<Node<'a, 'input>, ReadError> {
        child(parent, tag).ok_or_else(|| self.error(parent, KlemsProblem::Missing(tag)))
    }

    /// The first layer, its header, its `DataDefinition` and the
    /// `IncidentDataStructure` element with its trimmed text.
    #[allow(clippy::type_complexity)]
    fn layer(
        &self,
    ) -> Result<
        (
            Node<'a, 'input>,
            KlemsHeader,
            Node<'a, 'input>,
            Node<'a, 'input>,
            String,
        ),
        ReadError,
    > {
        let root = self.doc.root_element();
        if root.tag_name().name() != "WindowElement" {
            return Err(self.error(
                root,
                KlemsProblem::NotWindowElement(root.tag_name().name().to_string()),
            ));
        }
        let optical = self.required(root, "Optical")?;
        let layer = self.required(optical, "Layer")?;
        let mut header = child(layer, "Material")
            .map(material_header)
            .unwrap_or_default();
        header.file_type = child_text(root, "FileType");
        header.window_element_type = child_text(root, "WindowElementType");
        let definition = self.required(layer, "DataDefinition")?;
        let structure_node = self.required(definition, "IncidentDataStructure")?;
        let structure = structure_node.text().unwrap_or("").trim().to_string();
        Ok((layer, header, definition, structure_node, structure))
    }

    /// A Klems matrix file or a tensor tree, by `IncidentDataStructure`.
    fn read_any(&self) -> Result<BsdfXml, ReadError> {
        let (layer, header, _, _, structure) = self.layer()?;
        let rank = if structure.eq_ignore_ascii_case("tensortree3") {
            TreeRank::Isotropic
        } else if structure.eq_ignore_ascii_case("tensortree4") {
            TreeRank::Anisotropic
        } else {
            return self.read().map(BsdfXml::Klems);
        };
        super::ttree::read_tree(self, layer, header, rank).map(BsdfXml::TensorTree)
    }

    fn read(&self) -> Result<KlemsBsdf, ReadError> {
        let (layer, header, definition, structure_node, structure) = self.layer()?;
        let rows = if structure.eq_ignore_ascii_case("columns") {
            false
        } else if structure.eq_ignore_ascii_case("rows") {
            true
        } else if structure.to_ascii_lowercase().starts_with("tensortree") {
            return Err(self.error(structure_node, KlemsProblem::TensorTree(structure)));
        } else {
            return Err(self.error(structure_node, KlemsProblem::UnknownStructure(structure)));
        };
        let defined = children(definition, "AngleBasis")
            .map(|node| self.angle_basis(node))
            .collect::<Result<Vec<_>, _>>()?;

        // Check every block's structure first, in document order; then
        // parse the matrices (most of the work) in parallel, and report
        // the first error in document order, as a sequential read would.
        let mut basis: Option<KlemsBasis> = None;
        let mut pending: Vec<PendingMatrix<'a, 'input>> = Vec::new();
        let structure_error = self
            .collect_blocks(layer, &defined, &mut basis, &mut pending)
            .err();
        let parsed: Vec<Result<ParsedMatrix, ReadError>> = pending
            .par_iter()
            .map(|p| self.matrix(p.data_node, &p.what, p.n, rows))
            .collect();
        let mut matrices: Vec<KlemsMatrix> = Vec::with_capacity(pending.len());
        let mut lines = LineCounter::new(self.doc.input_text());
        for (p, m) in pending.into_iter().zip(parsed) {
            let m = m?;
            matrices.push(KlemsMatrix {
                band: p.band,
                direction: p.direction,
                n: m.n,
                values: m.values,
                clipped_negative: m.clipped,
                line: lines.line_at(p.data_node.range().start),
            });
        }
        if let Some(e) = structure_error {
            return Err(e);
        }
        let Some(basis) = basis else {
            return Err(self.error(layer, KlemsProblem::NoData));
        };
        Ok(KlemsBsdf {
            source: self.name.display().to_string(),
            header,
            incident_data_structure: if rows { "Rows" } else { "Columns" }.into(),
            basis,
            matrices,
        })
    }

    /// Checks every `WavelengthDataBlock` of `layer` in document order and
    /// queues its `ScatteringData` for parsing; stops at the first fault,
    /// keeping what was queued before it.
    fn collect_blocks(
        &self,
        layer: Node<'a, 'input>,
        defined: &[(String, Option<KlemsBasis>)],
        basis: &mut Option<KlemsBasis>,
        pending: &mut Vec<PendingMatrix<'a, 'input>>,
    ) -> Result<(), ReadError> {
        for data in children(layer, "WavelengthData") {
            let band_node = self.required(data, "Wavelength")?;
            let band = KlemsBand::parse(band_node.text().unwrap_or(""));
            for block in children(data, "WavelengthDataBlock") {
                let direction_node = self.required(block, "WavelengthDataDirection")?;
                let direction_text = direction_node.text().unwrap_or("").trim();
                let direction = KlemsDirection::parse(direction_text).ok_or_else(|| {
                    self.error(
                        direction_node,
                        KlemsProblem::UnknownDirection(direction_text.to_string()),
                    )
                })?;
                let what = format!("{band} {direction}");
                let column_node = self.required(block, "ColumnAngleBasis")?;
                let row_node = self.required(block, "RowAngleBasis")?;
                let column = self.resolve_basis(column_node, defined)?;
                let row = self.resolve_basis(row_node, defined)?;
                if !column.same_geometry(&row) {
                    return Err(self.error(
                        row_node,
                        KlemsProblem::MismatchedBases {
                            column: column.name,
                            row: row.name,
                        },
                    ));
                }
                if let Some(first) = &*basis
                    && !first.same_geometry(&column)
                {
                    return Err(self.error(
                        column_node,
                        KlemsProblem::MismatchedBases {
                            column: column.name,
                            row: first.name.clone(),
                        },
                    ));
                }
                if pending
                    .iter()
                    .any(|m| m.band == band && m.direction == direction)
                {
                    return Err(self.error(direction_node, KlemsProblem::Duplicate(what)));
                }
                let data_node = self.required(block, "ScatteringData")?;
                let n = column.len();
                basis.get_or_insert(column);
                pending.push(PendingMatrix {
                    band: band.clone(),
                    direction,
                    what,
                    n,
                    data_node,
                });
            }
        }
        Ok(())
    }

    /// One `AngleBasis`: its name and, when it has blocks, its rings.
    fn angle_basis(
        &self,
        node: Node<'a, 'input>,
    ) -> Result<(String, Option<KlemsBasis>), ReadError> {
        let name = child_text(node, "AngleBasisName").unwrap_or_default();
        let blocks: Vec<Node> = children(node, "AngleBasisBlock").collect();
        if blocks.is_empty() {
            return Ok((name, None));
        }
        let mut rings = Vec::with_capacity(blocks.len());
        for block in blocks {
            let number =
                |parent: Node<'a, 'input>, tag: &'static str| -> Result<Option<f64>, ReadError> {
                    let Some(n) = child(parent, tag) else {
                        return Ok(None);
                    };
                    let text = n.text().unwrap_or("").trim();
                    match text.parse::<f64>() {
                        Ok(v) if v.is_finite() => Ok(Some(v)),
                        _ => Err(self.error(
                            n,
                            KlemsProblem::BadValue {
                                expected: "a finite number",
                                text: shorten(text),
                            },
                        )),
                    }
                };
            let bounds = self.required(block, "ThetaBounds")?;
            let lower = number(bounds, "LowerTheta")?
                .ok_or_else(|| self.error(bounds, KlemsProblem::Missing("LowerTheta")))?;
            let upper = number(bounds, "UpperTheta")?
                .ok_or_else(|| self.error(bounds, KlemsProblem::Missing("UpperTheta")))?;
            let n_phis_node = self.required(block, "nPhis")?;
            let n_phis_text = n_phis_node.text().unwrap_or("").trim();
            let n_phis = n_phis_text.parse::<usize>().map_err(|_| {
                self.error(
                    n_phis_node,
                    KlemsProblem::BadValue {
                        expected: "a whole number of patches",
                        text: shorten(n_phis_text),
                    },
                )
            })?;
            // The polar cap is centred on the pole, other rings midway.
            let midpoint = if lower == 0.0 {
                0.0
            } else {
                0.5 * (lower + upper)
            };
            let theta = number(block, "Theta")?.unwrap_or(midpoint);
            rings.push(KlemsRing {
                theta_deg: theta,
                lower_theta_deg: lower,
                upper_theta_deg: upper,
                n_phis,
            });
        }
        let basis = KlemsBasis::from_rings(&name, rings).map_err(|reason| {
            self.error(
                node,
                KlemsProblem::BadBasis {
                    name: name.clone(),
                    reason,
                },
            )
        })?;
        Ok((name, Some(basis)))
    }

    /// The basis a `ColumnAngleBasis`/`RowAngleBasis` names: one the file
    /// defines with blocks, else a built-in one.
    fn resolve_basis(
        &self,
        node: Node<'a, 'input>,
        defined: &[(String, Option<KlemsBasis>)],
    ) -> Result<KlemsBasis, ReadError> {
        let name = node.text().unwrap_or("").trim();
        let from_file = defined
            .iter()
            .find(|(n, b)| b.is_some() && n.trim().eq_ignore_ascii_case(name))
            .and_then(|(_, b)| b.clone());
        from_file
            .or_else(|| KlemsBasis::built_in(name))
            .ok_or_else(|| self.error(node, KlemsProblem::UnknownBasis(shorten(name))))
    }

    /// The N × N values of a `ScatteringData` element, stored row-major by
    /// outgoing patch whatever the file's layout.
    fn matrix(
        &self,
        node: Node<'a, 'input>,
        what: &str,
        n: usize,
        rows: bool,
    ) -> Result<ParsedMatrix, ReadError> {
        let expected = n * n;
        let text = node.text().unwrap_or("");
        let mut values = Vec::with_capacity(expected);
        let mut clipped = 0;
        let mut found = 0;
        let bytes = text.as_bytes();
        let mut pos = 0;
        loop {
            while pos < bytes.len() && is_separator(bytes[pos]) {
                pos += 1;
            }
            if pos >= bytes.len() {
                break;
            }
            found += 1;
            // The gonio readers' exact fast path, straight on the text: a
            // number followed by a separator (or the end) is the whole
            // token, with the same bits as str::parse.
            let fast = crate::read::number::parse_prefix(&bytes[pos..])
                .filter(|&(_, used)| bytes.get(pos + used).is_none_or(|&b| is_separator(b)));
            let start = pos;
            pos = match fast {
                Some((_, used)) => pos + used,
                None => {
                    let mut end = pos;
                    while end < bytes.len() && !is_separator(bytes[end]) {
                        end += 1;
                    }
                    end
                }
            };
            if found > expected {
                continue; // count the rest for the message
            }
            let token = &text[start..pos];
            let parsed = match fast {
                Some((v, _)) => Ok(v),
                None => crate::read::number::parse_f64(token),
            };
            let value = match parsed {
                Ok(v) if v.is_finite() => v,
                _ => {
                    return Err(self.error_at_token(
                        node,
                        token,
                        KlemsProblem::NotANumber {
                            what: what.to_string(),
                            index: found,
                            text: shorten(token),
                        },
                    ));
                }
            };
            let value = if value >= 0.0 {
                value
            } else if value >= NEGATIVE_LIMIT {
                clipped += 1;
                0.0
            } else {
                let k = found - 1;
                return Err(self.error_at_token(
                    node,
                    token,
                    KlemsProblem::Negative {
                        what: what.to_string(),
                        value,
                        row: k / n + 1,
                        column: k % n + 1,
                    },
                ));
            };
            values.push(value);
        }
        if found != expected {
            return Err(self.error(
                node,
                KlemsProblem::TokenCount {
                    what: what.to_string(),
                    expected,
                    n,
                    found,
                },
            ));
        }
        if rows {
            // `Rows`: each text row is one incident patch; transpose to
            // Radiance's layout, row = outgoing patch.
            let mut transposed = vec![0.0; expected];
            for i in 0..n {
                for o in 0..n {
                    transposed[o * n + i] = values[i * n + o];
                }
            }
            values = transposed;
        }
        Ok(ParsedMatrix { n, values, clipped })
    }

    /// An error on the line of `token`, a slice of `node`'s text when the
    /// text is borrowed from the input (no entities); else on the element.
    fn error_at_token(&self, node: Node<'_, '_>, token: &str, problem: KlemsProblem) -> ReadError {
        let input = self.doc.input_text();
        let start = input.as_ptr() as usize;
        let at = token.as_ptr() as usize;
        let line = if at >= start && at < start + input.len() {
            let offset = at - start;
            input.as_bytes()[..offset]
                .iter()
                .filter(|&&b| b == b'\n')
                .count()
                + 1
        } else {
            self.line_of(node)
        };
        parse_error(
            self.name,
            line,
            ParseErrorKind::Klems {
                element: node.tag_name().name().to_string(),
                problem,
            },
        )
    }
}

/// Matrix values are separated by white space and commas (both ASCII, so
/// every token is a slice on a character boundary).
#[inline(always)]
fn is_separator(b: u8) -> bool {
    b.is_ascii_whitespace() || b == b','
}

/// A `ScatteringData` element whose block has been checked.
struct PendingMatrix<'a, 'input> {
    band: KlemsBand,
    direction: KlemsDirection,
    /// "band direction", for messages.
    what: String,
    n: usize,
    data_node: Node<'a, 'input>,
}

/// Line numbers of increasing byte offsets in one pass over the text
/// (roxmltree's `text_pos_at` scans from the start on every call).
struct LineCounter<'t> {
    text: &'t [u8],
    offset: usize,
    line: usize,
}

impl<'t> LineCounter<'t> {
    fn new(text: &'t str) -> LineCounter<'t> {
        LineCounter {
            text: text.as_bytes(),
            offset: 0,
            line: 1,
        }
    }

    /// The 1-based line of byte `offset` (offsets must not decrease).
    fn line_at(&mut self, offset: usize) -> usize {
        let offset = offset.min(self.text.len());
        if offset >= self.offset {
            // Byte counters over blocks of 255 (no overflow), which the
            // compiler vectorises.
            self.line += self.text[self.offset..offset]
                .chunks(255)
                .map(|block| block.iter().fold(0u8, |n, &b| n + u8::from(b == b'\n')) as usize)
                .sum::<usize>();
            self.offset = offset;
        }
        self.line
    }
}

struct ParsedMatrix {
    n: usize,
    values: Vec<f64>,
    clipped: usize,
}

pub(super) fn material_header(material: Node<'_, '_>) -> KlemsHeader {
    let mut header = KlemsHeader {
        manufacturer: child_text(material, "Manufacturer"),
        name: child_text(material, "Name"),
        thickness: child_text(material, "Thickness"),
        thickness_unit: child(material, "Thickness")
            .and_then(|n| n.attribute("unit"))
            .map(str::to_string),
        device_type: child_text(material, "DeviceType"),
        ..KlemsHeader::default()
    };
    for c in material.children().filter(Node::is_element) {
        let tag = c.tag_name().name();
        if matches!(tag, "Manufacturer" | "Name" | "Thickness" | "DeviceType") {
            continue;
        }
        if let Some(text) = c.text().map(str::trim).filter(|t| !t.is_empty()) {
            header.other.push((tag.to_string(), text.to_string()));
        }
    }
    header
}

/// At most 40 characters of `text`, for messages.
pub(super) fn shorten(text: &str) -> String {
    match text.char_indices().nth(40) {
        Some((cut, _)) => format!("{}...", &text[..cut]),
        None => text.to_string(),
    }
}
