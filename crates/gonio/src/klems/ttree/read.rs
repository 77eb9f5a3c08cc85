//! Reading the `WavelengthData` blocks of a tensor-tree file (the header
//! and the XML document are the Klems reader's).

use roxmltree::Node;

use super::parse::{MAX_DEPTH, TreeFault, parse_tree};
use super::{TensorTree, TreeBlock, TreeRank};
use crate::error::{KlemsProblem, ParseErrorKind, ReadError, TreeProblem};
use crate::klems::read::{Reader, children};
use crate::klems::{KlemsBand, KlemsDirection, KlemsHeader};
use crate::read::parse_error;

/// The blocks of `layer`, each `ScatteringData` parsed as a tree of
/// `rank`. Bands other than Visible are read too (Radiance reads only
/// Visible, CIE-u and CIE-v).
pub(in crate::klems) fn read_tree(
    reader: &Reader<'_, '_>,
    layer: Node<'_, '_>,
    header: KlemsHeader,
    rank: TreeRank,
) -> Result<TensorTree, ReadError> {
    let mut blocks: Vec<TreeBlock> = Vec::new();
    for data in children(layer, "WavelengthData") {
        let band_node = reader.required(data, "Wavelength")?;
        let band = KlemsBand::parse(band_node.text().unwrap_or(""));
        for block in children(data, "WavelengthDataBlock") {
            let direction_node = reader.required(block, "WavelengthDataDirection")?;
            let direction_text = direction_node.text().unwrap_or("").trim();
            let direction = KlemsDirection::parse(direction_text).ok_or_else(|| {
                reader.error(
                    direction_node,
                    KlemsProblem::UnknownDirection(direction_text.to_string()),
                )
            })?;
            let what = format!("{band} {direction}");
            let basis_node = reader.required(block, "AngleBasis")?;
            let basis = basis_node.text().unwrap_or("").trim();
            if !basis.eq_ignore_ascii_case("LBNL/Shirley-Chiu") {
                let shown = crate::klems::read::shorten(basis);
                return Err(reader.error(basis_node, KlemsProblem::TreeBasis(shown)));
            }
            if blocks
                .iter()
                .any(|b| b.band == band && b.direction == direction)
            {
                return Err(reader.error(direction_node, KlemsProblem::Duplicate(what)));
            }
            let data_node = reader.required(block, "ScatteringData")?;
            let text = data_node.text().unwrap_or("");
            let parsed = parse_tree(text, rank.dimensions()).map_err(|(offset, fault)| {
                let problem = match fault {
                    TreeFault::Syntax(s) => TreeProblem::Syntax(s),
                    TreeFault::Count(found) => TreeProblem::ValueCount {
                        found,
                        rank: rank.dimensions(),
                    },
                    TreeFault::NotANumber(t) => TreeProblem::NotANumber(t),
                    TreeFault::Negative(v) => TreeProblem::Negative(v),
                    TreeFault::TooDeep => TreeProblem::TooDeep(MAX_DEPTH),
                };
                parse_error(
                    reader.name,
                    line_in_text(reader, data_node, text, offset),
                    ParseErrorKind::Klems {
                        element: "ScatteringData".into(),
                        problem: KlemsProblem::Tree {
                            what: what.clone(),
                            problem,
                        },
                    },
                )
            })?;
            blocks.push(TreeBlock {
                band: band.clone(),
                direction,
                cells: parsed.cells,
                depth: parsed.depth,
                clipped_negative: parsed.clipped,
                line: reader.line_of(data_node),
            });
        }
    }
    if blocks.is_empty() {
        return Err(reader.error(layer, KlemsProblem::NoData));
    }
    Ok(TensorTree {
        source: reader.name.display().to_string(),
        header,
        rank,
        blocks,
    })
}

/// The line of byte `offset` of `text`, the text of `node`: counted in the
/// input when the text is borrowed from it (no entities), else the
/// element's line.
fn line_in_text(reader: &Reader<'_, '_>, node: Node<'_, '_>, text: &str, offset: usize) -> usize {
    let input = reader.doc.input_text();
    let start = input.as_ptr() as usize;
    let at = text.as_ptr() as usize + offset.min(text.len());
    if at >= start && at <= start + input.len() {
        1 + input.as_bytes()[..at - start]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
    } else {
        reader.line_of(node)
    }
}
